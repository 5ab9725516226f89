//! The 25 WebXR joints of a skeleton: their indices, resolved once per skeleton (for
//! retargeting), and their positions in a posed skeleton, copied each frame (the input of
//! the gesture features).

use glam::{Affine3A, Vec3};

use super::{webxr, Skeleton};
use crate::{Error, Result};

/// Where the WebXR joints sit in one skeleton.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct JointPositions {
    /// Skeleton index of each WebXR joint, in [`webxr::JOINT_NAMES`] order.
    indices: [usize; 25],
}

impl JointPositions {
    /// Resolves the 25 WebXR joints of `skeleton`.
    ///
    /// # Errors
    /// [`Error::MissingJoint`] naming the first WebXR joint the skeleton lacks.
    pub fn new(skeleton: &Skeleton) -> Result<Self> {
        let mut indices = [0; 25];
        for (slot, name) in indices.iter_mut().zip(webxr::JOINT_NAMES) {
            *slot = skeleton
                .find(name)
                .ok_or_else(|| Error::MissingJoint { joint: name.to_owned(), needed_for: "gesture features and retargeting need the 25 WebXR hand joints" })?;
        }
        Ok(Self { indices })
    }

    /// Skeleton index of each WebXR joint, in [`webxr::JOINT_NAMES`] order.
    #[must_use]
    pub fn indices(&self) -> &[usize; 25] {
        &self.indices
    }

    /// The joints' world positions, metres, from the skeleton's world transforms (e.g.
    /// the engine's). Allocates nothing.
    ///
    /// # Panics
    /// If `world` is shorter than the skeleton these indices were resolved on.
    #[must_use]
    pub fn read(&self, world: &[Affine3A]) -> [Vec3; 25] {
        self.indices.map(|i| world[i].translation.into())
    }
}
