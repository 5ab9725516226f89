//! Realism metrics: how LB, QB, DQB and CoR deform the same hand (the paper's claim, measured).
//!
//! Volume against rest, collapse and bulge near a bent joint, the candy wrapper of a twisted
//! joint, edge-length distortion, the continuity of sweeps, and self-intersections and
//! self-contact (how deep skin goes into skin, and the space it shares) in gesture poses, each
//! for the four methods.

mod distortion;
mod joint_region;
mod report;
mod self_contact;
mod self_intersection;

pub use distortion::{edge_distortion, VertexDistortion};
pub use joint_region::JointRegion;
pub use report::{format_value, hand_parts, measure, FrameMetrics, Report, Sweep};
pub use self_contact::{self_contact, SelfContact};
pub use self_intersection::count_self_intersections;
