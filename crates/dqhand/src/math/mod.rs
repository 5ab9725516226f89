//! Maths on top of glam: the dual quaternion and its screw form.

mod dual_quat;
mod screw;

pub use dual_quat::DualQuat;
pub use screw::Screw;
