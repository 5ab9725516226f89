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
//! A gesture can also name a `class` of the file's learned [`Classifier`] (the object
//! `classifier`), or carry a `model` of its own (a classifier learned from a recording by
//! `dqhand learn-gesture`, with a class of the gesture's name): it then matches when that
//! class's probability passes the classifier's `start` (`hold` once started) *and* all its
//! conditions hold. Conditions then only add what a hand's shape cannot tell, such as which
//! way the thumb points.
//!
//! Gestures are tried in file order, the first that matches wins: order is priority.
//! `min_hold_s` (seconds, ≥ 0) is how long a change must last before it is reported.
//!
//! The built-in set is the 11 library gestures plus `thumbs_down`, each a class of
//! a classifier trained by `dqhand train-gestures` on varied hands (`docs/gestures.md`):
//! thumbs up and down are one shape, told apart by `thumb.up`.

use std::path::Path;

use serde::{Deserialize, Serialize};

use super::classifier::ClassifierJson;
use super::{Classifier, ClassifierScratch, Feature, FeatureKind, HandFeatures};
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

/// The learned part of a gesture: a class of the set's classifier, or its own model's.
#[derive(Clone, Debug, PartialEq)]
enum Learned {
    /// Index of the class in the set's classifier.
    Class(usize),
    /// Its own classifier and the index of its class there.
    Model(Box<Classifier>, usize),
}

/// One named gesture: its learned class (if any) is probable enough and all of its
/// conditions hold.
#[derive(Clone, Debug, PartialEq)]
pub struct GestureDefinition {
    name: String,
    conditions: Vec<Condition>,
    /// The conditions as written, for writing the set back.
    when: Vec<String>,
    learned: Option<Learned>,
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

    /// The class of the set's classifier it needs, if any.
    #[must_use]
    pub fn class(&self) -> Option<usize> {
        match self.learned {
            Some(Learned::Class(c)) => Some(c),
            _ => None,
        }
    }

    /// Its own classifier (a gesture learned from a recording), if any.
    #[must_use]
    pub fn model(&self) -> Option<&Classifier> {
        match &self.learned {
            Some(Learned::Model(m, _)) => Some(m),
            _ => None,
        }
    }

    /// Whether it matches: every condition holds ([`Condition::holds`]) and its class is
    /// probable enough, by `shared` (the set's classifier's probabilities, empty without
    /// one, with `thresholds`) or by its own model (evaluated in `own`, a scratch of that
    /// model). Allocates nothing.
    #[must_use]
    pub fn matches(&self, features: &HandFeatures, shared: (&[f32], (f32, f32)), own: &mut ClassifierScratch, held: bool) -> bool {
        let pick = |(start, hold): (f32, f32)| if held { hold } else { start };
        let probable = match &self.learned {
            None => true,
            Some(Learned::Class(c)) => shared.0.get(*c).is_some_and(|&p| p > pick(shared.1)),
            Some(Learned::Model(model, c)) => model.classify(features, own)[*c] > pick(model.thresholds()),
        };
        probable && self.conditions.iter().all(|c| c.holds(features, held))
    }
}

/// The gestures a recogniser knows, in priority order, and how long a change must last.
#[derive(Clone, Debug, PartialEq)]
pub struct GestureSet {
    gestures: Vec<GestureDefinition>,
    min_hold_s: f64,
    hysteresis: HysteresisJson,
    classifier: Option<Classifier>,
}

/// The file as written.
#[derive(Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
struct FileJson {
    min_hold_s: f64,
    hysteresis: HysteresisJson,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    classifier: Option<ClassifierJson>,
    gestures: Vec<GestureJson>,
}

#[derive(Clone, Debug, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
struct HysteresisJson {
    curl: f64,
    flexion: f64,
    abduction: f64,
    opposition: f64,
    direction: f64,
}

#[derive(Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
struct GestureJson {
    name: String,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    class: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    model: Option<ClassifierJson>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
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
    /// on the wrong side; a malformed classifier or model, a class the classifier lacks.
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
        let classifier = json.classifier.map(|c| Classifier::from_json(c, "classifier")).transpose().map_err(bad)?;
        let mut gestures: Vec<GestureDefinition> = Vec::with_capacity(json.gestures.len());
        for g in json.gestures {
            if gestures.iter().any(|d| d.name == g.name) {
                return Err(bad(GestureProblem::DuplicateName(g.name)));
            }
            if g.when.is_empty() && g.class.is_none() && g.model.is_none() {
                return Err(bad(GestureProblem::NoCondition(g.name)));
            }
            let conditions = g.when.iter().map(|c| parse_condition(&g.name, c, margin)).collect::<Result<_, _>>().map_err(bad)?;
            let learned = match (g.class, g.model) {
                (Some(_), Some(_)) => return Err(bad(GestureProblem::Classifier { what: format!("gesture {:?}", g.name), problem: "has both a class and a model; give one".into() })),
                (Some(class), None) => {
                    let index = classifier.as_ref().and_then(|c| c.class_index(&class));
                    let valid = classifier.as_ref().map(|c| c.classes().join(", ")).unwrap_or_default();
                    Some(Learned::Class(index.ok_or_else(|| bad(GestureProblem::UnknownClass { gesture: g.name.clone(), class, valid }))?))
                }
                (None, Some(model)) => {
                    let what = format!("gesture {:?} model", g.name);
                    let model = Classifier::from_json(model, &what).map_err(bad)?;
                    let index = model.class_index(&g.name).ok_or_else(|| bad(GestureProblem::Classifier { what, problem: format!("has no class {:?}", g.name) }))?;
                    Some(Learned::Model(Box::new(model), index))
                }
                (None, None) => None,
            };
            gestures.push(GestureDefinition { name: g.name, conditions, when: g.when, learned });
        }
        Ok(Self { gestures, min_hold_s: json.min_hold_s, hysteresis: json.hysteresis, classifier })
    }

    /// The set as a definitions file ([`Self::from_json`] reads it back equal).
    #[must_use]
    pub fn to_json(&self) -> String {
        let classes = self.classifier.as_ref().map_or(&[][..], Classifier::classes);
        let gestures = self
            .gestures
            .iter()
            .map(|g| GestureJson {
                name: g.name.clone(),
                class: g.class().map(|c| classes[c].clone()),
                model: g.model().map(Classifier::to_json),
                when: g.when.clone(),
            })
            .collect();
        let file = FileJson { min_hold_s: self.min_hold_s, hysteresis: self.hysteresis.clone(), classifier: self.classifier.as_ref().map(Classifier::to_json), gestures };
        serde_json::to_string_pretty(&file).expect("gesture definitions serialise")
    }

    /// The set's classifier, if it has one.
    #[must_use]
    pub fn classifier(&self) -> Option<&Classifier> {
        self.classifier.as_ref()
    }

    /// Replaces the set's classifier; gestures keep their classes by name.
    ///
    /// # Errors
    /// [`Error::GestureDefinition`] naming a gesture whose class the new one lacks.
    pub fn set_classifier(&mut self, classifier: Classifier) -> Result<()> {
        let old = self.classifier.as_ref().map_or(&[][..], Classifier::classes).to_vec();
        for g in &mut self.gestures {
            if let Some(Learned::Class(c)) = &mut g.learned {
                *c = classifier.class_index(&old[*c]).ok_or_else(|| Error::GestureDefinition {
                    file: "the new classifier".into(),
                    problem: GestureProblem::UnknownClass { gesture: g.name.clone(), class: old[*c].clone(), valid: classifier.classes().join(", ") },
                })?;
            }
        }
        self.classifier = Some(classifier);
        Ok(())
    }

    /// Puts a gesture learned from examples first (it is the more specific: it wins over the
    /// others where both match), replacing any gesture of the same name.
    ///
    /// # Errors
    /// [`Error::GestureDefinition`] when `model` has no class called `name`.
    pub fn insert_learned(&mut self, name: &str, model: Classifier) -> Result<()> {
        let index = model.class_index(name).ok_or_else(|| Error::GestureDefinition {
            file: "the learned model".into(),
            problem: GestureProblem::Classifier { what: format!("gesture {name:?} model"), problem: format!("has no class {name:?}") },
        })?;
        self.gestures.retain(|g| g.name != name);
        self.gestures.insert(0, GestureDefinition { name: name.to_owned(), conditions: Vec::new(), when: Vec::new(), learned: Some(Learned::Model(Box::new(model), index)) });
        Ok(())
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
