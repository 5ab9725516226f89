//! The engine: one step of the paper's Figure 1, which every caller drives (the viewer's
//! sessions, `dqhand bench`, `dqhand metrics`, `dqhand skin`).
//!
//! ```text
//!  pose source ──> kinematics ──┬──> skin (LB | QB | DQB) ──> renderer
//!  (edits, timeline,  (rig, FK, │
//!   live input)     one transform└──> collision (proxies, CCD) ──> interaction
//!                     per bone)                                    (grasp, gestures)
//! ```
//!
//! The layers are modules, and each imports only those below it (see ARCHITECTURE.md).

mod interaction_cycle;
mod model_source;

pub use interaction_cycle::Engine;
pub use model_source::ModelSource;
