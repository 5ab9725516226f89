//! The skin around one joint, and how far it stays from the bones there (collapse, bulge,
//! candy wrapper).

use glam::{Affine3A, Vec3};

use crate::kinematics::Skeleton;
use crate::math::segment_distance;
use crate::skin::SkinnedMesh;
use crate::{Error, Result};

/// The vertices around a joint `J` between the bone `A → J` and the bone `J → C`.
///
/// They are the vertices whose heaviest influence is `A` or `J` and which lie within one
/// skin radius of `J` along the bone `J → C`; the skin radius is the median distance from the
/// bone axis of those vertices on the first half of `J → C`.
#[derive(Clone, Debug, PartialEq)]
pub struct JointRegion {
    /// The parent joint `A`, the joint `J` and the next joint `C` of the chain.
    pub joints: [usize; 3],
    /// The vertices of the region.
    pub vertices: Vec<usize>,
    /// The skin radius at the joint in the bind pose (m).
    pub radius: f32,
    /// The smallest distance of the region's vertices from the axis of `J → C` in the bind pose (m):
    /// the reference of [`Self::section_radius`] (less than `radius` where the section is
    /// not round).
    pub min_radius: f32,
}

impl JointRegion {
    /// The region around `joint`, whose next joint along the chain is `next`.
    ///
    /// * `bind_world` — #joints world transforms of the pose the mesh is bound in
    ///   ([`crate::model::Model::bind_world`]).
    ///
    /// # Errors
    /// [`Error::UnknownName`] if a joint is missing, [`Error::Skeleton`] if it has no parent,
    /// [`Error::NoSkin`] if no vertex is near it.
    pub fn new(skeleton: &Skeleton, bind_world: &[Affine3A], mesh: &SkinnedMesh, joint: &str, next: &str) -> Result<Self> {
        let j = skeleton.index_of(joint)?;
        let c = skeleton.index_of(next)?;
        let a = skeleton.joints()[j].parent.ok_or_else(|| Error::Skeleton(format!("joint {joint:?} has no parent bone")))?;
        let (pj, pc) = (Vec3::from(bind_world[j].translation), Vec3::from(bind_world[c].translation));
        let (dir, length) = ((pc - pj).normalize_or_zero(), pc.distance(pj));
        let candidates: Vec<(usize, f32, f32)> = (0..mesh.vertex_count())
            .filter(|&v| mesh.influences(v).next().is_some_and(|(h, _)| h == a || h == j))
            .map(|v| {
                let d = mesh.position(v) - pj;
                let t = d.dot(dir);
                (v, t, (d - t * dir).length())
            })
            .collect();
        let mut radial: Vec<f32> = candidates.iter().filter(|c| (0.0..0.5 * length).contains(&c.1)).map(|c| c.2).collect();
        radial.sort_by(f32::total_cmp);
        let radius = *radial.get(radial.len() / 2).ok_or_else(|| Error::NoSkin(joint.into()))?;
        let region: Vec<&(usize, f32, f32)> = candidates.iter().filter(|c| c.1.abs() <= radius).collect();
        let min_radius = region.iter().map(|c| c.2).fold(f32::MAX, f32::min);
        let vertices = region.iter().map(|c| c.0).collect();
        Ok(Self { joints: [a, j, c], vertices, radius, min_radius })
    }

    /// Smallest and largest ratio, over the region, of a vertex's distance to the two bones
    /// `A → J → C` posed (`world`, `positions`) to the same distance in the bind pose. Below
    /// 1: the skin collapses toward the bones; above 1: it bulges.
    ///
    /// * `bind_world`, `world` — #joints; `positions` — #V deformed.
    #[must_use]
    pub fn distance_ratios(&self, mesh: &SkinnedMesh, bind_world: &[Affine3A], world: &[Affine3A], positions: &[[f32; 3]]) -> (f32, f32) {
        let bones = |w: &[Affine3A]| self.joints.map(|i| Vec3::from(w[i].translation));
        let (r, p) = (bones(bind_world), bones(world));
        let distance = |b: &[Vec3; 3], x: Vec3| segment_distance(x, b[0], b[1]).min(segment_distance(x, b[1], b[2]));
        self.vertices.iter().fold((f32::MAX, f32::MIN), |(lo, hi), &v| {
            let ratio = distance(&p, Vec3::from(positions[v])) / distance(&r, mesh.position(v)).max(1e-9);
            (lo.min(ratio), hi.max(ratio))
        })
    }

    /// The smallest distance of the region's vertices from the axis of the bone `J → C`
    /// posed, relative to the same at rest: the candy-wrapper measure for a twisted joint.
    #[must_use]
    pub fn section_radius(&self, world: &[Affine3A], positions: &[[f32; 3]]) -> f32 {
        let (pj, pc) = (Vec3::from(world[self.joints[1]].translation), Vec3::from(world[self.joints[2]].translation));
        let dir = (pc - pj).normalize_or_zero();
        let min = self.vertices.iter().map(|&v| {
            let d = Vec3::from(positions[v]) - pj;
            (d - d.dot(dir) * dir).length()
        });
        min.fold(f32::MAX, f32::min) / self.min_radius.max(1e-9)
    }
}
