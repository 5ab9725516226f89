//! The skinning transform of each joint (paper 4.4, step 1).

use glam::Affine3A;

/// The skinning transform of each joint, `world · inverse_bind` (design.md): it carries a
/// vertex from bind space to where its joint has moved it.
///
/// * `world` — #joints world transforms from forward kinematics;
/// * `inverse_bind` — #joints, from the mesh;
/// * `out` — #joints, overwritten.
///
/// # Panics
/// If the lengths differ.
pub fn skinning_transforms(world: &[Affine3A], inverse_bind: &[Affine3A], out: &mut [Affine3A]) {
    assert!(world.len() == inverse_bind.len() && out.len() == world.len(), "one transform per joint");
    for ((o, w), ib) in out.iter_mut().zip(world).zip(inverse_bind) {
        *o = *w * *ib;
    }
}
