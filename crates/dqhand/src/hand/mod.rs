//! The built-in anatomical hand: a parametric left or right hand from two measurements.
//!
//! The pipeline, one file each:
//! * `anthropometry`: the 20-bone skeleton (25 WebXR joints with the tips) and the finger
//!   breadths, as fractions of hand length and breadth from published anthropometry;
//! * `shape`: the skin as an implicit surface: anatomical parts per bone (phalanges with
//!   knuckles, pads and nails, metacarpals forming a palm that narrows to the wrist, thenar
//!   and hypothenar eminences) blended by smooth minima;
//! * `tessellation`: that surface meshed (surface nets), simplified to an exact vertex count
//!   (meshoptimizer), relaxed and projected back onto the surface: one closed, 2-manifold
//!   mesh, 8,668 vertices by default (the paper's Table 2);
//! * `weights`: skin weights from each bone's parts, at most four per vertex;
//! * `surface_regions`: which triangles are nail, palm and back, ordered by region;
//! * `skin_texture`: the back's and the palm's albedo and normal maps (creases, palm lines,
//!   knuckle wrinkles, nails, pores), drawn when asked for, not kept.
//!
//! UVs are a planar projection onto the palm plane (u across the hand, v along it), the same
//! for the back and the palm, each region drawn with its own maps: seamless, so glTF's vertex
//! count is the mesh's.

mod anthropometry;
mod shape;
mod skin_texture;
mod surface_regions;
mod tessellation;
mod weights;

use glam::{Affine3A, Vec3};

use crate::appearance::Appearance;
use crate::kinematics::{webxr, HandKinematics, JointModel};
use crate::model::Model;
use crate::skin::{MeshData, SkinnedMesh};
use crate::{Error, Result};
pub use anthropometry::measure;
/// The side of the hand to build (the kinematics layer's; re-exported for [`HandParams`]).
pub use crate::kinematics::Side;
use anthropometry::Anatomy;
use shape::HandShape;

/// The paper's vertex count (its Table 2), the built-in hand's default density.
pub const DEFAULT_VERTICES: usize = 8_668;
/// Densities [`build`] accepts.
pub const VERTEX_RANGE: core::ops::RangeInclusive<usize> = 1_000..=60_000;

/// What the user gives: two measurements, the side and the level of detail.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HandParams {
    /// Wrist crease to middle fingertip (m); adult default 0.19.
    pub length: f32,
    /// Across the metacarpal heads (m); adult default 0.085.
    pub breadth: f32,
    /// Left or right.
    pub side: Side,
    /// Vertices of the mesh, in [`VERTEX_RANGE`]; default [`DEFAULT_VERTICES`].
    pub vertices: usize,
}

impl Default for HandParams {
    fn default() -> Self {
        Self { length: 0.19, breadth: 0.085, side: Side::Right, vertices: DEFAULT_VERTICES }
    }
}

impl HandParams {
    /// Checks that the parameters describe a hand.
    ///
    /// # Errors
    /// [`Error::HandParameter`] naming the parameter: a measurement that is not positive and finite,
    /// a breadth outside 30–75 % of the length (hands measure 40–50 %), a vertex count
    /// outside [`VERTEX_RANGE`].
    pub fn validate(&self) -> Result<()> {
        let Self { length: l, breadth: b, vertices, .. } = *self;
        if !(l.is_finite() && l > 0.0) {
            return Err(Error::HandParameter(format!("hand length {l} m is not a positive length")));
        }
        if !(b.is_finite() && b > 0.0) {
            return Err(Error::HandParameter(format!("hand breadth {b} m is not a positive length")));
        }
        if !(0.3 * l..=0.75 * l).contains(&b) {
            return Err(Error::HandParameter(format!(
                "hand breadth {b} m is {:.0} % of the length {l} m; hands measure 40–50 % (30–75 % accepted)",
                100.0 * b / l
            )));
        }
        if !VERTEX_RANGE.contains(&vertices) {
            return Err(Error::HandParameter(format!(
                "{vertices} vertices is outside the supported density {}–{}",
                VERTEX_RANGE.start(),
                VERTEX_RANGE.end()
            )));
        }
        Ok(())
    }
}

/// The kinematics layer of the hand [`build`] makes, without meshing its surface (the
/// bulk of `build`'s time): what generates poses and joint positions needs, e.g. a synthetic
/// recording of a user's hand.
///
/// # Errors
/// As [`build`]: parameters out of range.
pub fn hand_kinematics(params: &HandParams, joint_model: JointModel) -> Result<HandKinematics> {
    let anatomy = anatomy(params)?;
    HandKinematics::new(&anatomy.skeleton()?, &inverse_bind(&anatomy), joint_model)
}

/// The checked parameters' anatomy.
fn anatomy(params: &HandParams) -> Result<Anatomy> {
    params.validate()?;
    let radial = Vec3::X * if params.side == Side::Right { -1.0 } else { 1.0 };
    Ok(Anatomy::new(params.length, params.breadth, radial))
}

/// The inverse of each joint's bind frame.
fn inverse_bind(anatomy: &Anatomy) -> Vec<Affine3A> {
    anatomy.frames.iter().map(Affine3A::inverse).collect()
}

/// Builds the hand: skeleton, skin mesh with normals and UVs, skin weights.
///
/// # Errors
/// [`Error::HandParameter`] for parameters [`HandParams::validate`] rejects, or [`Error::Tessellation`] (not expected at
/// supported densities) a surface that fails to mesh as a closed surface of that many vertices.
pub fn build(params: &HandParams) -> Result<Model> {
    let HandParams { length: l, breadth: b, side, vertices } = *params;
    let anatomy = anatomy(params)?;
    let skeleton = anatomy.skeleton()?;
    let shape = HandShape::new(&anatomy);
    let mut surface = tessellation::tessellate(&shape, vertices)?;
    let regions = surface_regions::sort_by_region(&shape, &surface.positions, &mut surface.indices);
    // Falloff lengths: short across the finger joints, long on the palm.
    let sigma: Vec<f32> = webxr::JOINT_NAMES.iter().map(|n| if n.contains("phalanx") { 0.016 * b } else { 0.04 * b }).collect();
    let (joints, weights) = weights::skin_weights(&shape, &surface.positions, &sigma);
    let plane = skin_texture::PalmPlane::new(&anatomy, &shape, l);
    let uvs = surface.positions.iter().map(|&p| plane.uv(p.into())).collect();
    let mut data = MeshData {
        positions: surface.positions,
        normals: surface.normals,
        uvs,
        stride: weights::INFLUENCES,
        joints,
        weights,
        indices: surface.indices,
        parts: Vec::new(),
        inverse_bind: inverse_bind(&anatomy),
    };
    data.sort_by_influence_count();
    let (mesh, warnings) = SkinnedMesh::new(data)?;
    Ok(Model {
        description: format!("anatomical {} hand, length {l} m, breadth {b} m, {vertices} vertices", side.name()),
        skeleton,
        mesh: std::sync::Arc::new(mesh),
        warnings,
        appearance: Some(std::sync::Arc::new(Appearance::new(regions, move || skin_texture::draw(&anatomy, &shape, l, plane)))),
    })
}
