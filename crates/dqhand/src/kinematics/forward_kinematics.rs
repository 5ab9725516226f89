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
    forward_kinematics_of(skeleton, skeleton.order(), locals, world);
}

/// [`forward_kinematics`] of only the joints `joints` (each after its parent), whose parents
/// outside them keep their world transforms: one finger of a hand whose palm has not moved.
///
/// # Panics
/// If the slice lengths differ from the skeleton's joint count.
pub fn forward_kinematics_of(skeleton: &Skeleton, joints: &[usize], locals: &[Transform], world: &mut [Affine3A]) {
    assert_eq!(locals.len(), skeleton.len(), "locals: one transform per joint");
    assert_eq!(world.len(), skeleton.len(), "world: one transform per joint");
    let all = skeleton.joints();
    for &j in joints {
        let local = locals[j].to_affine();
        world[j] = match all[j].parent {
            Some(p) => world[p] * local,
            None => local,
        };
    }
}
