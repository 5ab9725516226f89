//! Gestures (paper 4.5): the library of daily hand shapes used as commands and in the demo.

mod library;

pub use library::{gesture, tour, Gesture, GESTURES};
