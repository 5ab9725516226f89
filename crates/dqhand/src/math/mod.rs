//! Maths on top of glam: the dual quaternion and its screw form, point–segment distance, and
//! the quantile rule of every report.

mod dual_quat;
mod quantile;
mod screw;
mod segment;

pub use dual_quat::DualQuat;
pub use quantile::quantile;
pub use screw::Screw;
pub use segment::segment_distance;
