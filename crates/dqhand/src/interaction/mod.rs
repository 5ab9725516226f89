//! The interaction loops on top of the engine step (paper Figure 1, bottom). Gesture
//! interaction: records from the user's hand drive the virtual hand (what you see is what you
//! do) and its gestures, recognised on the virtual hand, act as commands.

pub mod benchmark;
mod command_table;
mod gesture_loop;
mod manipulation_loop;
pub mod grasp_script;
pub mod synthetic;

pub use command_table::{CommandRow, CommandTable};
pub use gesture_loop::GestureLoop;
pub use manipulation_loop::ManipulationLoop;
