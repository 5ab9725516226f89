//! Gestures (paper 4.5): the library of daily hand shapes used as commands and in the demo,
//! pose sequences that move between them, and their recognition from tracked joints:
//! joint positions → [`HandFeatures`] → a [`Recognizer`] of a [`GestureSet`] (conditions on
//! features, and a [`Classifier`] learned by [`train`]) → [`Event`]s; and gestures of both
//! hands from the two hands' ([`TwoHandRecognizer`]).

mod classifier;
mod definitions;
mod features;
mod library;
mod recognizer;
mod sequence;
mod training;
mod two_hand;

pub use classifier::{Classifier, ClassifierScratch};
pub use definitions::{Comparison, Condition, GestureDefinition, GestureSet};
pub use features::{Feature, FeatureKind, Finger, HandFeatures, PalmAxis};
pub use library::{gesture, Gesture, GESTURES};
pub use recognizer::{Event, EventKind, Events, Recognizer};
pub use sequence::{Keyframe, Sequence};
pub use training::{train, Example, TrainingParams};
pub use two_hand::{TwoHandEvent, TwoHandGesture, TwoHandRecognizer};
