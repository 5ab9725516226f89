//! Maths on top of glam: the dual quaternion and its screw form, point–segment distance, the
//! best-fit rigid motion of two point sets (with `interaction`: on nalgebra's SVD), and the
//! quantile rule of every report, and (with `interaction`) the seedable generator of generated
//! data and training.

mod dual_quat;
mod quantile;
#[cfg(feature = "interaction")]
mod rng;
#[cfg(feature = "interaction")]
mod rigid_fit;
mod screw;
mod segment;

pub use dual_quat::DualQuat;
pub use quantile::quantile;
#[cfg(feature = "interaction")]
pub use rng::Rng;
#[cfg(feature = "interaction")]
pub use rigid_fit::rigid_fit;
pub use screw::Screw;
pub use segment::{is_sliver, segment_closest, segment_distance, segment_segment_closest, segment_triangle_closest, triangle_closest};
