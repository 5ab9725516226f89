//! Forward kinematics down the node tree (paper 4.3): every child is driven by its parent.

use glam::Affine3A;

use super::{Skeleton, Transform};

/// World transforms from local ones: `world[j] = world[parent(j)] * local[j]`.
///
/// * `locals` — #joints local transforms (relative to each parent), in joint index order.
/// * `world` — #joints output, overwritten. Allocates nothing.
///
/// # Panics
/// If the slice lengths differ from the skeleton's joint count.
pub fn forward_kinematics(skeleton: &Skeleton, locals: &[Transform], world: &mut [Affine3A]) {
    assert_eq!(locals.len(), skeleton.len(), "locals: one transform per joint");
    assert_eq!(world.len(), skeleton.len(), "world: one transform per joint");
    let joints = skeleton.joints();
    for &j in skeleton.order() {
        let local = locals[j].to_affine();
        world[j] = match joints[j].parent {
            Some(p) => world[p] * local,
            None => local,
        };
    }
}
