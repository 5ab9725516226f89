//! The viewer stream: the engine's side of dqhand's live viewer, independent of any transport.
//!
//! A [`Session`] holds one viewer's pose and view, applies the [`Command`]s the page sends
//! and writes each frame in the binary format of [`frame`]; [`LiveInput`] is the one gesture
//! or manipulation loop every viewer follows, and carries out the viewer's gesture
//! [`Action`]s. The `dqhand` server carries these messages over a WebSocket. None of this is
//! part of the engine (`dqhand`), which knows nothing of viewers.

mod action;
mod command;
mod engine_settings;
mod error;
pub mod frame;
mod frame_rate;
mod live_input;
mod session;

pub use action::{Action, ViewerAction};
pub use command::{Command, LearnRequest, MAX_COMMAND_BYTES};
pub use engine_settings::EngineSettings;
pub use error::{Error, Result};
pub use frame::{FrameHeader, FrameView, FrameWriter, Topology};
pub use frame_rate::FrameRate;
pub use live_input::{InputUpdate, InputView, LiveInput, SCENE_PERIOD, STEP_PERIOD};
pub use session::{Applied, Session, GESTURE_SECONDS};
