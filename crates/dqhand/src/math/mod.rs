//! Maths on top of glam: the dual quaternion and its screw form, and point–segment distance.

mod dual_quat;
mod screw;
mod segment;

pub use dual_quat::DualQuat;
pub use screw::Screw;
pub use segment::segment_distance;
