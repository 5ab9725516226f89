//! The viewer stream: the engine's side of the live viewer, independent of any transport.
//!
//! A [`Session`] holds one viewer's pose and view, applies the [`Command`]s the page sends
//! and writes each frame in the binary format of [`frame`]; the `dqhand` server carries
//! these messages over a WebSocket.

pub mod frame;
mod command;
mod live_input;
mod session;

pub use command::Command;
pub use frame::{FrameHeader, FrameView, FrameWriter, Topology};
pub use live_input::{InputUpdate, InputView, LiveInput, SCENE_PERIOD, STEP_PERIOD};
pub use session::{Applied, Session, GESTURE_SECONDS};
