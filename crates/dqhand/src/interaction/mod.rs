//! The interaction loops on top of the engine step (paper Figure 1, bottom). Gesture
//! interaction: records from the user's hand drive the virtual hand (what you see is what you
//! do) and its gestures, recognised on the virtual hand, act as commands. 3D manipulation:
//! the tracked hand drives a contact-constrained rendered hand that grasps the scene's
//! objects.
//!
//! With the `synthetic` feature (not a default one: tests, benchmarks and demos use it), also
//! the generators of labelled data made from the hand's own kinematics, `synthetic`
//! recordings (of the library's shapes, or of shapes varied as people make them:
//! `variation`) and `grasp_script`s, and the loops' `benchmark`s on them.

#[cfg(feature = "synthetic")]
pub mod benchmark;
mod command_table;
#[cfg(feature = "synthetic")]
pub mod gesture_examples;
mod gesture_loop;
#[cfg(feature = "synthetic")]
pub mod grasp_script;
mod manipulating_hand;
mod manipulation_loop;
mod manipulation_trace;
mod scene_shapes;
#[cfg(feature = "synthetic")]
pub mod synthetic;
#[cfg(feature = "synthetic")]
pub mod variation;

pub use command_table::{CommandRow, CommandTable};
pub use gesture_loop::GestureLoop;
pub use manipulating_hand::ManipulatingHand;
pub use manipulation_loop::{HandEvents, ManipulationLoop};
pub use manipulation_trace::frame_trace;
pub use scene_shapes::scene_shapes;
