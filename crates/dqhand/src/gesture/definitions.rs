//! Static gestures defined as data, so that users add gestures by editing a JSON file
//! instead of code: [`GestureSet::builtin`] embeds `data/gestures.json`, [`GestureSet::load`]
//! reads another file of the same shape.
//!
//! ```json
//! {
//!   "min_hold_s": 0.1,
//!   "hysteresis": { "curl": 0.1, "flexion": 10, "abduction": 5, "opposition": 0.02, "direction": 10 },
//!   "gestures": [
//!     { "name": "fist", "when": ["thumb.curl > 0.5", "index.curl > 0.6", "…"] },
//!     { "name": "pinch", "when": ["index.opposition < 0.12 release 0.16", "…"] }
//!   ]
//! }
//! ```
//!
//! A gesture matches when all its conditions hold. A condition is
//! `<feature> <op> <number> [release <number>]`, separated by spaces:
//! * `<feature>`: one of `thumb.curl`, `index.curl`, `middle.curl`, `ring.curl`,
//!   `pinky.curl`, `thumb.flexion`, `index.flexion`, `middle.flexion`, `ring.flexion`,
//!   `pinky.flexion`, `thumb.abduction`, `index.abduction`, `middle.abduction`,
//!   `ring.abduction`, `index.opposition`, `middle.opposition`, `ring.opposition`,
//!   `pinky.opposition`, `palm.up`, `thumb.up` (units and definitions:
//!   [`HandFeatures`](super::HandFeatures));
//! * `<op>`: `<` (the feature must be below the number) or `>` (above it);
//! * the number is where the gesture starts. Once it has started (or is waiting out
//!   `min_hold_s`), the condition holds up to the number relaxed by the hysteresis margin of
//!   the feature's kind (`curl`, `flexion`, `abduction`, `opposition`, `direction`), or up to
//!   the explicit `release` number when one is given, which must lie on the relaxed side.
//!
//! Gestures are tried in file order, the first that matches wins: order is priority.
//! `min_hold_s` (seconds, ≥ 0) is how long a change must last before it is reported.
//!
//! The built-in set has the 11 library gestures plus `thumbs_down`. Its pinch and OK start
//! when the thumb and index tips are closer than 0.12 hand sizes and end beyond 0.16: 2.1 and
//! 2.8 cm on the built-in hand (hand size 0.176 m), since its tip joints are the fingertips'
//! ends, 1.6 cm apart when the pads touch; common SDKs start at 1.5 cm and end at 2.5 cm.

use std::path::Path;

use serde::Deserialize;

use super::{Feature, FeatureKind, HandFeatures};
use crate::{Error, GestureProblem, Result};

/// How a condition compares its feature with its thresholds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Comparison {
    /// `<`: the feature must be below the threshold.
    Below,
    /// `>`: the feature must be above the threshold.
    Above,
}

/// One parsed condition: a feature, a comparison, and where it starts and stops holding.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Condition {
    /// The feature compared.
    pub feature: Feature,
    /// `<` or `>`.
    pub comparison: Comparison,
    /// The strict threshold a gesture must pass to start, in the feature's unit.
    pub start: f32,
    /// The relaxed threshold it holds to once started: `release`, or `start` widened by the
    /// kind's hysteresis margin.
    pub hold: f32,
}

impl Condition {
    /// Whether `features` satisfy the condition: with the strict threshold, or with the
    /// relaxed one when `held` (the gesture is current or about to be). NaN satisfies neither.
    #[must_use]
    pub fn holds(&self, features: &HandFeatures, held: bool) -> bool {
        let value = features.get(self.feature);
        let threshold = if held { self.hold } else { self.start };
        match self.comparison {
            Comparison::Below => value < threshold,
            Comparison::Above => value > threshold,
        }
    }
}

/// One named gesture: all of its conditions must hold.
#[derive(Clone, Debug, PartialEq)]
pub struct GestureDefinition {
    name: String,
    conditions: Vec<Condition>,
}

impl GestureDefinition {
    /// The gesture's name.
    #[must_use]
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Its conditions, in file order.
    #[must_use]
    pub fn conditions(&self) -> &[Condition] {
        &self.conditions
    }

    /// Whether every condition holds ([`Condition::holds`]). Allocates nothing.
    #[must_use]
    pub fn matches(&self, features: &HandFeatures, held: bool) -> bool {
        self.conditions.iter().all(|c| c.holds(features, held))
    }
}

/// The gestures a recogniser knows, in priority order, and how long a change must last.
#[derive(Clone, Debug, PartialEq)]
pub struct GestureSet {
    gestures: Vec<GestureDefinition>,
    min_hold_s: f64,
}

/// The file as written.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FileJson {
    min_hold_s: f64,
    hysteresis: HysteresisJson,
    gestures: Vec<GestureJson>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct HysteresisJson {
    curl: f64,
    flexion: f64,
    abduction: f64,
    opposition: f64,
    direction: f64,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct GestureJson {
    name: String,
    when: Vec<String>,
}

impl GestureSet {
    /// The built-in definitions, `data/gestures.json`.
    ///
    /// # Panics
    /// Never: a test parses the embedded file.
    #[must_use]
    pub fn builtin() -> Self {
        Self::from_json(include_str!("../../data/gestures.json"), "gestures.json (built-in)").expect("the built-in gestures.json parses")
    }

    /// Reads definitions from a JSON file (see the module docs).
    ///
    /// # Errors
    /// [`Error::Io`] if the file cannot be read, else as [`Self::from_json`].
    pub fn load(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path).map_err(Error::io(path))?;
        Self::from_json(&text, &path.display().to_string())
    }

    /// Parses definitions; `file` names the source in error messages.
    ///
    /// # Errors
    /// [`Error::GestureDefinition`] naming `file` and, where there is one, the gesture and
    /// condition: JSON that is not of the documented shape, a negative or non-finite setting,
    /// a duplicate gesture name, a gesture without conditions, a condition that does not
    /// parse, names an unknown feature or operator, has a non-numeric threshold or a release
    /// on the wrong side.
    pub fn from_json(text: &str, file: &str) -> Result<Self> {
        let bad = |problem| Error::GestureDefinition { file: file.to_owned(), problem };
        let json: FileJson = serde_json::from_str(text).map_err(|e| bad(GestureProblem::Json(e.to_string())))?;
        let h = &json.hysteresis;
        let margins = [("curl", h.curl), ("flexion", h.flexion), ("abduction", h.abduction), ("opposition", h.opposition), ("direction", h.direction)];
        for (name, value) in margins.iter().map(|&(n, v)| (format!("hysteresis.{n}"), v)).chain([("min_hold_s".to_owned(), json.min_hold_s)]) {
            if !(value.is_finite() && value >= 0.0) {
                return Err(bad(GestureProblem::BadSetting { name, value }));
            }
        }
        let margin = |kind: FeatureKind| margins.iter().find(|(n, _)| *n == kind.name()).map_or(0.0, |m| m.1 as f32);
        let mut gestures: Vec<GestureDefinition> = Vec::with_capacity(json.gestures.len());
        for g in json.gestures {
            if gestures.iter().any(|d| d.name == g.name) {
                return Err(bad(GestureProblem::DuplicateName(g.name)));
            }
            if g.when.is_empty() {
                return Err(bad(GestureProblem::NoCondition(g.name)));
            }
            let conditions = g.when.iter().map(|c| parse_condition(&g.name, c, margin)).collect::<Result<_, _>>().map_err(bad)?;
            gestures.push(GestureDefinition { name: g.name, conditions });
        }
        Ok(Self { gestures, min_hold_s: json.min_hold_s })
    }

    /// The gestures, in priority (file) order.
    #[must_use]
    pub fn gestures(&self) -> &[GestureDefinition] {
        &self.gestures
    }

    /// How long a change must last before it is reported, seconds.
    #[must_use]
    pub fn min_hold_s(&self) -> f64 {
        self.min_hold_s
    }
}

/// Parses `<feature> <op> <number> [release <number>]`.
fn parse_condition(gesture: &str, condition: &str, margin: impl Fn(FeatureKind) -> f32) -> Result<Condition, GestureProblem> {
    let (gesture, cond) = (gesture.to_owned(), condition.to_owned());
    let words: Vec<&str> = condition.split_whitespace().collect();
    let (name, op, start, release) = match words[..] {
        [name, op, start] => (name, op, start, None),
        [name, op, start, "release", release] => (name, op, start, Some(release)),
        _ => return Err(GestureProblem::Syntax { gesture, condition: cond }),
    };
    let Some(feature) = Feature::from_name(name) else {
        let valid = Feature::ALL.map(Feature::name).join(", ");
        return Err(GestureProblem::UnknownFeature { gesture, condition: cond, feature: name.to_owned(), valid });
    };
    let comparison = match op {
        "<" => Comparison::Below,
        ">" => Comparison::Above,
        _ => return Err(GestureProblem::BadOperator { gesture, condition: cond, operator: op.to_owned() }),
    };
    let number = |value: &str| match value.parse::<f32>() {
        Ok(v) if v.is_finite() => Ok(v),
        _ => Err(GestureProblem::BadThreshold { gesture: gesture.clone(), condition: cond.clone(), value: value.to_owned() }),
    };
    let start = number(start)?;
    let relax = match comparison {
        Comparison::Below => 1.0,
        Comparison::Above => -1.0,
    };
    let hold = match release.map(number).transpose()? {
        Some(release) if (release - start) * relax < 0.0 => return Err(GestureProblem::BadRelease { gesture, condition: cond, release }),
        Some(release) => release,
        None => start + relax * margin(feature.kind()),
    };
    Ok(Condition { feature, comparison, start, hold })
}
