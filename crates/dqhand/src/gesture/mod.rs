//! Gestures (paper 4.5): the library of daily hand shapes used as commands and in the demo,
//! and pose sequences that move between them.

mod library;
mod sequence;

pub use library::{gesture, Gesture, GESTURES};
pub use sequence::{Keyframe, Sequence};
