//! Retargeting measured on synthetic sequences with their true poses: the angle error
//! against the truth, and whether a contact the user makes (thumb and index tips within
//! [`CONTACT_GAP_M`]) is kept on the virtual hand. Records go straight to the
//! [`Retargeter`], without the pipeline's filters, so the error is the solver's alone.
//!
//! The generator's pinch and ok leave the tips about 15 mm apart (its poses are our hand's,
//! which does not close them on other proportions), so contacts are made from them: every
//! record whose tracked tips are within [`CONTACT_FADE`] is also retargeted with the tracked
//! thumb tip moved to each of [`CLOSED_GAPS_M`] from the index tip ([`close_pinch`]), as a
//! tracker reports a user's closed pinch.

use std::sync::Arc;

use glam::Vec3;

use super::AngleError;
use crate::input::{HandData, Retargeter, CONTACT_FADE, JOINT_COUNT};
use crate::interaction::synthetic::Synthetic;
use crate::kinematics::{HandKinematics, JointModel, JointPositions, Pose};
use crate::model::Model;
use crate::Result;

/// Tracked thumb–index tip gap at or below which the virtual gap must be as small (the
/// target: 5 mm), metres.
pub const CONTACT_GAP_M: f32 = 0.005;

/// Tracked gaps a near pinch is closed to, metres: touching, to the target's edge.
pub const CLOSED_GAPS_M: [f32; 3] = [0.001, 0.003, CONTACT_GAP_M];

/// WebXR indices of the thumb and index fingertips.
const THUMB_TIP: usize = 4;
const INDEX_TIP: usize = 9;

/// Distance between the thumb and index fingertips of 25 WebXR joint positions, metres.
#[must_use]
pub fn thumb_index_gap(positions: &[Vec3; JOINT_COUNT]) -> f32 {
    positions[THUMB_TIP].distance(positions[INDEX_TIP])
}

/// `tracked` with the thumb tip moved along the line from the index tip to `gap` metres from
/// it: the user closing a pinch.
#[must_use]
pub fn close_pinch(tracked: &[Vec3; JOINT_COUNT], gap: f32) -> [Vec3; JOINT_COUNT] {
    let mut closed = *tracked;
    let index = tracked[INDEX_TIP];
    closed[THUMB_TIP] = index + (tracked[THUMB_TIP] - index).normalize_or(Vec3::X) * gap;
    closed
}

/// Retargeting scored over one or more sequences.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RetargetScore {
    /// Records retargeted.
    pub records: usize,
    /// Records the retargeter refused (degenerate joints).
    pub refused: usize,
    /// Solved angles against the true ones, over the retargeted records.
    pub angles: AngleError,
    /// Contacts checked: records whose tracked thumb–index gap is at most [`CONTACT_GAP_M`],
    /// and near pinches closed to each of [`CLOSED_GAPS_M`].
    pub contacts: usize,
    /// Largest virtual thumb–index gap over those contacts, metres (0 without any).
    pub max_contact_gap_m: f32,
    /// Largest amount by which a contact's virtual gap exceeds its tracked gap, metres.
    pub max_contact_excess_m: f32,
}

impl RetargetScore {
    /// Retargets every record of `sequences` (joints or landmarks; their truth in the `full`
    /// joint model) onto `model` and compares with the truth.
    ///
    /// # Errors
    /// As [`Model::hand_kinematics`] and [`Retargeter::new`] for a model without the WebXR
    /// joints; [`crate::Error::Sequence`] for a record without joints or landmarks (a glove's).
    pub fn measure(model: Arc<Model>, sequences: &[Synthetic]) -> Result<Self> {
        let mut hand = model.hand_kinematics(JointModel::Full)?;
        let rig = hand.rig().clone();
        let mut retargeter = Retargeter::new(&rig)?;
        let joints = JointPositions::new(hand.skeleton())?;
        let mut solved = Pose::rest(JointModel::Full.dof_count());
        let mut score = Self::default();
        for (record, truth) in sequences.iter().flat_map(|s| s.records.iter().zip(&s.truth)) {
            let mut tracked = [Vec3::ZERO; JOINT_COUNT];
            let read = match &record.hand {
                Some(HandData::Joints(set)) if set.is_complete() => {
                    for (p, q) in tracked.iter_mut().zip(set.positions().flatten()) {
                        *p = q;
                    }
                    true
                }
                Some(HandData::Joints(_)) => false,
                Some(HandData::Landmarks(landmarks)) => retargeter.landmark_joints(landmarks, &mut tracked).is_ok(),
                _ => return Err(crate::Error::Sequence(format!("record at t = {} s: no joints or landmarks to retarget", record.time))),
            };
            if !read || retargeter.solve(&tracked, record.side, &mut solved).is_err() {
                score.refused += 1;
                continue;
            }
            score.records += 1;
            score.angles.add(truth, &solved);
            let gap = thumb_index_gap(&tracked);
            if gap <= CONTACT_GAP_M {
                score.add_contact(&mut hand, &joints, &solved, gap);
            }
            if gap <= CONTACT_FADE {
                for closed_gap in CLOSED_GAPS_M {
                    if retargeter.solve(&close_pinch(&tracked, closed_gap), record.side, &mut solved).is_ok() {
                        score.add_contact(&mut hand, &joints, &solved, closed_gap);
                    }
                }
            }
        }
        Ok(score)
    }

    /// Counts a contact of `tracked_gap` (m) and the virtual gap of `solved` on `hand`.
    fn add_contact(&mut self, hand: &mut HandKinematics, joints: &JointPositions, solved: &Pose, tracked_gap: f32) {
        hand.pose(solved);
        let gap = thumb_index_gap(&joints.read(hand.world()));
        self.contacts += 1;
        self.max_contact_gap_m = self.max_contact_gap_m.max(gap);
        self.max_contact_excess_m = self.max_contact_excess_m.max(gap - tracked_gap);
    }
}
