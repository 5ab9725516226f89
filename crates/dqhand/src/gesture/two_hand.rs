//! Gestures of both hands: both palms open, the hands held together. Each is a pair of
//! one-hand gestures of the set each hand's recogniser knows (the left hand's and the right
//! hand's) and, optionally, how near the wrists are; the hands' own recognisers decide the
//! one-hand gestures, so a two-hand gesture is only as quick and as sure as theirs.
//!
//! Definitions are JSON, a list: `[{"name": "hands_together", "left": "open_palm", "right":
//! "open_palm", "within_m": 0.1}, …]`. The first that holds is the one recognised, so the more
//! particular come first.

use serde::Deserialize;

use super::GestureSet;
use crate::{Error, GestureProblem, Result};

/// A gesture made with both hands.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TwoHandGesture {
    /// Its name, in events.
    pub name: String,
    /// The left hand's gesture (a name in the one-hand set).
    pub left: String,
    /// The right hand's gesture.
    pub right: String,
    /// The wrists at most this far apart, m; `None`: anywhere.
    #[serde(default)]
    pub within_m: Option<f32>,
}

/// How much farther apart than `within_m` the wrists may draw before a gesture made together
/// ends: hands trembling at the threshold do not start and end it again and again.
const RELEASE_FACTOR: f32 = 1.25;

/// A two-hand gesture starting or ending: its index in [`TwoHandRecognizer::gestures`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TwoHandEvent {
    /// It began this frame.
    Start(usize),
    /// It ended this frame.
    End(usize),
}

/// Recognises two-hand gestures from each hand's current gesture, frame by frame.
#[derive(Clone, Debug)]
pub struct TwoHandRecognizer {
    gestures: Vec<TwoHandGesture>,
    current: Option<usize>,
}

impl TwoHandRecognizer {
    /// A recogniser of `gestures`, whose hands recognise `set`.
    ///
    /// # Errors
    /// [`Error::GestureDefinition`] (in `file`): a name given twice, a hand's gesture not in
    /// `set`, a distance that is not a finite number above 0.
    pub fn new(gestures: Vec<TwoHandGesture>, set: &GestureSet, file: &str) -> Result<Self> {
        let bad = |problem| Error::GestureDefinition { file: file.to_owned(), problem };
        let names: Vec<&str> = set.gestures().iter().map(super::GestureDefinition::name).collect();
        for (i, g) in gestures.iter().enumerate() {
            if gestures[..i].iter().any(|o| o.name == g.name) {
                return Err(bad(GestureProblem::DuplicateName(g.name.clone())));
            }
            if let Some(missing) = [&g.left, &g.right].into_iter().find(|n| !names.contains(&n.as_str())) {
                return Err(bad(GestureProblem::UnknownGesture { two_hand: g.name.clone(), gesture: missing.clone(), valid: names.join(", ") }));
            }
            if let Some(d) = g.within_m.filter(|d| !(d.is_finite() && *d > 0.0)) {
                return Err(bad(GestureProblem::BadSetting { name: format!("{}.within_m", g.name), value: f64::from(d) }));
            }
        }
        Ok(Self { gestures, current: None })
    }

    /// Definitions read from JSON `text` (from `file`, for errors).
    ///
    /// # Errors
    /// As [`Self::new`]; text that is not a list of definitions.
    pub fn from_json(text: &str, set: &GestureSet, file: &str) -> Result<Self> {
        let gestures = serde_json::from_str(text).map_err(|e| Error::GestureDefinition { file: file.to_owned(), problem: GestureProblem::Json(e.to_string()) })?;
        Self::new(gestures, set, file)
    }

    /// The built-in two: `hands_together` (both palms open, the wrists within 12 cm: palms
    /// pressed together put them a few centimetres apart) and `both_palms_open`.
    ///
    /// # Errors
    /// If `set` lacks `open_palm`.
    pub fn builtin(set: &GestureSet) -> Result<Self> {
        let open = |name: &str, within_m| TwoHandGesture { name: name.to_owned(), left: "open_palm".to_owned(), right: "open_palm".to_owned(), within_m };
        Self::new(vec![open("hands_together", Some(0.12)), open("both_palms_open", None)], set, "two-hand gestures (built-in)")
    }

    /// One frame: each hand's current gesture (`None`: none, or the hand is not tracked) and
    /// how far apart the wrists are (m). Returns what ended and what began, in that
    /// order. Allocates nothing.
    pub fn update(&mut self, left: Option<&str>, right: Option<&str>, apart_m: f32) -> [Option<TwoHandEvent>; 2] {
        let holds = |g: &TwoHandGesture, slack: f32| Some(g.left.as_str()) == left && Some(g.right.as_str()) == right && g.within_m.is_none_or(|d| apart_m <= d * slack);
        // The first that holds, the current one with its release margin.
        let next = self.gestures.iter().enumerate().position(|(i, g)| holds(g, if Some(i) == self.current { RELEASE_FACTOR } else { 1.0 }));
        if next == self.current {
            return [None, None];
        }
        let ended = self.current.take().map(TwoHandEvent::End);
        self.current = next;
        [ended, next.map(TwoHandEvent::Start)]
    }

    /// The gesture both hands make now, if any.
    #[must_use]
    pub fn current(&self) -> Option<&TwoHandGesture> {
        self.current.map(|i| &self.gestures[i])
    }

    /// The definitions, in order.
    #[must_use]
    pub fn gestures(&self) -> &[TwoHandGesture] {
        &self.gestures
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn together_before_apart_with_hysteresis_and_each_hand_its_own_gesture() {
        let mut r = TwoHandRecognizer::builtin(&GestureSet::builtin()).unwrap();
        let open = Some("open_palm");
        assert_eq!(r.update(open, Some("fist"), 0.05), [None, None], "one hand open is not both");
        assert_eq!(r.update(open, open, 0.5), [None, Some(TwoHandEvent::Start(1))], "both open, apart");
        assert_eq!(r.update(open, open, 0.11), [Some(TwoHandEvent::End(1)), Some(TwoHandEvent::Start(0))], "brought together");
        assert_eq!(r.update(open, open, 0.145), [None, None], "within the release margin");
        assert_eq!(r.current().unwrap().name, "hands_together");
        assert_eq!(r.update(open, open, 0.155), [Some(TwoHandEvent::End(0)), Some(TwoHandEvent::Start(1))], "drawn apart");
        assert_eq!(r.update(None, open, 0.155), [Some(TwoHandEvent::End(1)), None], "a hand lost");
        assert!(r.current().is_none());
    }

    #[test]
    fn definitions_naming_what_the_hands_do_not_know_are_refused() {
        let set = GestureSet::builtin();
        let e = TwoHandRecognizer::from_json(r#"[{"name": "clap", "left": "open_palm", "right": "jazz_hands"}]"#, &set, "mine.json").unwrap_err().to_string();
        assert!(e.starts_with("mine.json: two-hand gesture \"clap\": no gesture \"jazz_hands\""), "{e}");
        let e = TwoHandRecognizer::from_json(r#"[{"name": "a", "left": "fist", "right": "fist", "within_m": -1}]"#, &set, "mine.json").unwrap_err().to_string();
        assert!(e.contains("a.within_m -1"), "{e}");
        let e = TwoHandRecognizer::from_json(r#"[{"name": "a", "left": "fist", "right": "fist"}, {"name": "a", "left": "fist", "right": "point"}]"#, &set, "mine.json").unwrap_err().to_string();
        assert!(e.contains("\"a\" is defined twice"), "{e}");
        let e = TwoHandRecognizer::from_json(r#"{"name": "a"}"#, &set, "mine.json").unwrap_err().to_string();
        assert!(e.starts_with("mine.json: not valid gesture definitions"), "{e}");
    }
}
