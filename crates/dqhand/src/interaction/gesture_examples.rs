//! Labelled examples for training a gesture classifier: the features of the virtual hand as
//! the gesture loop sees them (after the input pipeline and retargeting, as it recognises),
//! frame by frame through generated sequences, with the class of the hold each frame is in.

use crate::gesture::{Example, Feature, FeatureKind};
use crate::interaction::synthetic::Synthetic;
use crate::interaction::GestureLoop;

/// The classes of the built-in classifier: `none` (no gesture) first; thumbs up and down are
/// one shape, `thumbs` (their conditions on `thumb.up` tell them apart).
pub const BUILTIN_CLASSES: [&str; 12] = ["none", "open_palm", "fist", "point", "victory", "three", "four", "rock", "call_me", "thumbs", "ok", "pinch"];

/// The class of a held gesture: its own name, but `thumbs` for thumbs up and down.
#[must_use]
pub fn class_of(gesture: &str) -> &str {
    match gesture {
        "thumbs_up" | "thumbs_down" => "thumbs",
        other => other,
    }
}

/// The features a classifier of shapes reads: all but the two directions to world up (a
/// shape is the same however the hand is turned; conditions on `thumb.up` tell thumbs up from
/// down).
#[must_use]
pub fn shape_features() -> Vec<Feature> {
    Feature::ALL.into_iter().filter(|f| f.kind() != FeatureKind::Direction).collect()
}

/// Seconds after a pose is reached before its frames are examples of it (the tremor of
/// arrival), and the middle share of a move whose frames are examples of no gesture.
const SETTLE_S: f64 = 0.05;
const MID_MOVE: (f64, f64) = (0.4, 0.6);

/// The examples of one sequence, every `every`-th record pushed through `hands` (a loop
/// without recognition, fresh or not): frames of a hold are its gesture's class, frames of
/// the idle stretch and of the middle of a move `none`. Gestures not in `classes` and other
/// frames give no example.
pub fn examples(hands: &mut GestureLoop, sequence: &Synthetic, classes: &[&str], every: usize) -> Vec<Example> {
    let none = classes.iter().position(|c| *c == "none");
    let mut out = Vec::new();
    let mut move_start = 0.0;
    let mut label = 0;
    for (k, record) in sequence.records.iter().enumerate() {
        if hands.push(record).is_err() || k % every.max(1) != 0 {
            continue;
        }
        let t = record.time;
        while label < sequence.labels.len() && t > sequence.labels[label].until {
            move_start = sequence.labels[label].until;
            label += 1;
        }
        let class = match sequence.labels.get(label) {
            Some(l) if t >= l.reached + SETTLE_S => classes.iter().position(|c| *c == class_of(&l.gesture)),
            Some(l) => {
                let s = (t - move_start) / (l.reached - move_start);
                if s > MID_MOVE.0 && s < MID_MOVE.1 { none } else { None }
            }
            None if t >= sequence.idle.0 => none,
            None => None,
        };
        if let Some(class) = class {
            out.push(Example { features: hands.features(), class });
        }
    }
    out
}
