//! Measures of the interaction loops against their stated targets. The gesture loop, on
//! labelled synthetic sequences ([`super::synthetic`]): whether each held gesture is recognised
//! and how long after its pose is reached, events during idle motion, and the retargeting error
//! against the true angles. The manipulation loop, on scripted grasps
//! ([`super::grasp_script`]): success, skin penetration, slip, release latency, tunnelling and
//! time per frame; on a free hand ([`super::grasp_script::sweep`]), lag and jitter. `dqhand gesture-bench` and `dqhand grasp-bench` report them and the tests
//! hold the loops to them, through this one implementation.

mod angle_error;
mod distribution;
mod lag_score;
mod manipulation_score;
mod recognition_score;
mod retarget_score;

pub use angle_error::AngleError;
pub use distribution::Distribution;
pub use lag_score::{lag, LagScore};
pub use manipulation_score::{depth, score, FlatMesh, RunScore, HELD_DEPTH_M, MESH_DEPTH_RANGE_M, PLACE_TOLERANCE_M};
pub use recognition_score::{HoldOutcome, LoggedEvent, RecognitionScore, RECOGNITION_DEADLINE_S, NO_GESTURE};
pub use retarget_score::{close_pinch, thumb_index_gap, RetargetScore, CLOSED_GAPS_M, CONTACT_GAP_M};
