//! The hand's collision proxies as persistent parry shapes, built once per hand: no query
//! builds a shape. Each knows which part of the hand it belongs to, because the contact
//! constraint moves the palm with the wrist and closes each finger on its own.

use glam::{Affine3A, Quat, Vec3};
use parry3d::bounding_volume::{Aabb, BoundingVolume};
use parry3d::math::Pose;
use parry3d::shape::{SharedShape, SupportMap};

use super::hull_support::HullSupport;
use super::{Proxy, ProxyShape};
use crate::kinematics::{HandPart, Skeleton};

/// One proxy as a parry shape.
#[derive(Clone)]
pub struct ProxyCollider {
    /// Index of the joint whose frame carries it.
    pub joint: usize,
    /// The shape in that frame.
    pub shape: SharedShape,
    /// Which part of the hand.
    pub part: HandPart,
    /// The largest distance of a point of the shape from the joint's origin (m): the radius
    /// of a sphere about the joint that holds the shape in any turn.
    pub extent: f32,
    /// The largest distance of a point of the shape's core from the joint's origin (m): a
    /// capsule's segment, a hull's vertices. A capsule's distance to anything is its
    /// segment's less its radius, so it falls no faster than the segment's points move:
    /// the lever of a turn is this, not [`Self::extent`].
    pub lever: f32,
    /// A hull's support function by hill climbing (parry's tries every vertex: 957 on the
    /// wrist's).
    hull: Option<HullSupport>,
    /// The shape's box in the joint's frame.
    local_aabb: Aabb,
}

impl ProxyCollider {
    /// The shape's support function, as GJK between two convex shapes asks it.
    #[must_use]
    pub fn support(&self) -> &(dyn SupportMap + Sync) {
        match &self.hull {
            Some(hull) => hull,
            None => self.shape.as_capsule().expect("a capsule"),
        }
    }

    /// A box holding the shape at `pose`: a hull's own box turned (a little loose), where
    /// parry's box of a hull transforms every vertex (957 on the wrist's: a third of the
    /// wrist stage's time on the teapot); a capsule's exact one.
    #[must_use]
    pub fn aabb(&self, pose: &Pose) -> Aabb {
        match self.hull {
            Some(_) => self.local_aabb.transform_by(pose),
            None => self.shape.compute_aabb(pose),
        }
    }

    /// A box holding the shape at `from` and at `to` (not the turn between them).
    #[must_use]
    pub fn swept_aabb(&self, from: &Pose, to: &Pose) -> Aabb {
        self.aabb(from).merged(&self.aabb(to))
    }
}

/// A rigid affine transform as a parry pose.
#[must_use]
pub fn pose_of(m: &Affine3A) -> Pose {
    let rotation = Quat::from_mat3a(&m.matrix3).normalize();
    Pose::from_parts(Vec3::from(m.translation), rotation)
}

/// The proxies of a hand as parry shapes.
#[derive(Clone)]
pub struct HandProxies {
    colliders: Vec<ProxyCollider>,
}

impl HandProxies {
    /// Shapes for `proxies` (fitted by [`super::fit_proxies`]) on `skeleton`'s joints.
    #[must_use]
    pub fn new(proxies: &[Proxy], skeleton: &Skeleton) -> Self {
        let joints = skeleton.joints();
        let colliders = proxies
            .iter()
            .filter_map(|p| {
                let (shape, lever, extent, hull) = match &p.shape {
                    ProxyShape::Capsule { start, end, radius } => {
                        let lever = start.length().max(end.length());
                        (SharedShape::capsule(*start, *end, *radius), lever, lever + radius, None)
                    }
                    ProxyShape::ConvexHull { points, triangles } => {
                        let extent = points.iter().map(|q| q.length()).fold(0.0, f32::max);
                        let shape = SharedShape::convex_mesh(points.clone(), triangles)?;
                        let hull = shape.as_convex_polyhedron().map(|h| HullSupport::new(h, 1.0));
                        (shape, extent, extent, hull)
                    }
                };
                let local_aabb = shape.compute_local_aabb();
                Some(ProxyCollider { joint: p.joint, shape, part: HandPart::of(&joints[p.joint].name), extent, lever, hull, local_aabb })
            })
            .collect();
        Self { colliders }
    }

    /// The proxies.
    #[must_use]
    pub fn colliders(&self) -> &[ProxyCollider] {
        &self.colliders
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_proxys_box_holds_its_shape_at_any_pose() {
        // The reference is parry's own box, from every vertex of a hull; the quick one may
        // only be larger.
        let model = crate::hand::build(&crate::hand::HandParams::default()).expect("the built-in hand");
        let proxies = HandProxies::new(&super::super::fit_proxies(&model, super::super::PROXY_MARGIN), &model.skeleton);
        let mut hulls = 0;
        for p in proxies.colliders() {
            hulls += usize::from(p.hull.is_some());
            for k in 0..12 {
                let turn = Quat::from_rotation_x(0.7 * k as f32) * Quat::from_rotation_z(0.3 * k as f32);
                let pose = Pose::from_parts(Vec3::new(0.1, -0.2, 0.05 * k as f32), turn);
                let (quick, exact) = (p.aabb(&pose), p.shape.compute_aabb(&pose));
                let holds = (quick.mins - exact.mins).max_element() <= 1e-6 && (exact.maxs - quick.maxs).max_element() <= 1e-6;
                assert!(holds, "joint {}: {quick:?} does not hold {exact:?}", p.joint);
            }
        }
        assert!(hulls >= 5, "{hulls} hulls");
    }
}
