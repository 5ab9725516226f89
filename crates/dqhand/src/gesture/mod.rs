//! Gestures (paper 4.5): the library of daily hand shapes used as commands and in the demo,
//! pose sequences that move between them, and their recognition from tracked joints:
//! joint positions → [`HandFeatures`] → a [`Recognizer`] of a [`GestureSet`] → [`Event`]s.

mod definitions;
mod features;
mod library;
mod recognizer;
mod sequence;

pub use definitions::{Comparison, Condition, GestureDefinition, GestureSet};
pub use features::{Feature, FeatureKind, Finger, HandFeatures};
pub use library::{gesture, Gesture, GESTURES};
pub use recognizer::{Event, EventKind, Events, Recognizer};
pub use sequence::{Keyframe, Sequence};
