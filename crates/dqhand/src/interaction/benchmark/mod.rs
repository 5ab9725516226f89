//! Measures of the gesture loop against the targets, on labelled synthetic sequences
//! ([`super::synthetic`]): whether each held gesture is recognised and how long after its pose
//! is reached, events during idle motion, and the retargeting error against the true angles.
//! `dqhand gesture-bench` reports them and the tests hold the loop to them, through this one
//! implementation.

mod angle_error;
mod distribution;
mod recognition_score;
mod retarget_score;

pub use angle_error::AngleError;
pub use distribution::Distribution;
pub use recognition_score::{HoldOutcome, LoggedEvent, RecognitionScore, RECOGNITION_DEADLINE_S};
pub use retarget_score::{close_pinch, thumb_index_gap, RetargetScore, CLOSED_GAPS_M, CONTACT_GAP_M};
