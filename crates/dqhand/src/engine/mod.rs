//! The engine: the paper's Figure 1 as two stages, which every caller drives (the viewer's
//! sessions, `dqhand bench`, `dqhand metrics`, `dqhand skin`, the interaction loops).
//!
//! ```text
//!  pose source ──> kinematics layer ──┬──> skin layer (LB | QB | DQB) ──> renderer
//!  (edits, timeline,  (rig, one FK pass,│
//!   live input)      skinning transforms└──> collision (proxies, CCD) ──> interaction
//!                    + dual quaternions)                                 (grasp, gestures)
//! ```
//!
//! The stages are [`crate::kinematics::HandKinematics`] (or
//! [`crate::kinematics::KinematicsLayer`] for any skeleton) and [`crate::skin::SkinLayer`];
//! [`Engine`] holds one of each for a hand. The layers are modules, and each imports only
//! those below it (see ARCHITECTURE.md).

mod interaction_cycle;
#[cfg(all(feature = "gltf", feature = "hand"))]
mod model_source;

pub use interaction_cycle::Engine;
#[cfg(all(feature = "gltf", feature = "hand"))]
pub use model_source::ModelSource;
