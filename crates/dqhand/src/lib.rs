//! dqhand: a dual quaternion virtual hand (Chen, Zhu, Wan, Feng, "Dual quaternion based
//! virtual hand interaction modeling", Sci China Inf Sci 56:032103, 2013).
//!
//! Layers, as in the paper's Figure 1:
//! * [`math`] — dual quaternions and screws on top of glam;
//! * [`kinematics`] — skeleton, joint models (`paper` 18 DOF, `full`), limits, poses, FK;
//! * [`skin`] — the skinned mesh and the LB, QB and DQB deformers;
//! * [`collision`] — collision proxies per bone (paper 4.2);
//! * [`hand`] — the built-in anatomical hand;
//! * [`io`] — glTF 2.0 in and out, PLY and OBJ out, pose files;
//! * [`model`] — a skeleton and its skinned mesh, posed frame by frame;
//! * [`stream`] — the engine side of the live viewer: sessions, commands, binary frames.
//!
//! Conventions: metres, seconds and radians; right-handed, +Y up (glTF); quaternions in files
//! are `[x, y, z, w]`; joints carry WebXR hand joint names.

mod error;
pub mod collision;
pub mod gesture;
pub mod hand;
pub mod io;
pub mod kinematics;
pub mod math;
pub mod metrics;
pub mod model;
pub mod skin;
pub mod stream;

pub use error::{Error, Result};
