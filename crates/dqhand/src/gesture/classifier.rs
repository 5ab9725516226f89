//! A learned classifier of hand shapes: one hidden layer of rectified units over standardised
//! [`HandFeatures`], a softmax over named classes. Thresholds written by hand fit the hands
//! they were written on; people make a fist with the thumb over the fingers, along the index
//! or across the palm, and a network trained on all of those ([`train`](super::train)) tells
//! the gestures apart by what differs between them. 23 inputs, 32 hidden units and a dozen
//! classes are about 1,200 multiply–adds: a microsecond per record.
//!
//! In gesture definitions (`gestures.json`) it is the object `classifier` (and a gesture's own
//! `model`, for gestures learned from a recording):
//!
//! ```json
//! { "classes": ["none", "fist", "…"], "inputs": ["thumb.curl", "…"],
//!   "mean": [0.4, …], "scale": [0.3, …],
//!   "hidden": { "weights": [[…], …], "bias": […] }, "output": { "weights": [[…], …], "bias": […] },
//!   "start": 0.6, "hold": 0.35 }
//! ```
//!
//! Input i is `(feature_i − mean_i) / scale_i`; `hidden.weights` has one row of inputs per
//! hidden unit, `output.weights` one row of hidden units per class. A gesture tied to a class
//! starts when that class's probability exceeds `start` and holds while it exceeds `hold`
//! (hysteresis on the classifier's output, as on a condition's feature).

use serde::{Deserialize, Serialize};

use super::{Feature, HandFeatures};
use crate::GestureProblem;

/// A dense layer: `outputs × inputs` weights, row-major, and a bias per output.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Layer {
    pub(crate) inputs: usize,
    pub(crate) weights: Vec<f32>,
    pub(crate) bias: Vec<f32>,
}

impl Layer {
    /// `out = W · x + b`.
    pub(crate) fn apply(&self, x: &[f32], out: &mut [f32]) {
        for ((o, row), b) in out.iter_mut().zip(self.weights.chunks_exact(self.inputs)).zip(&self.bias) {
            *o = b + row.iter().zip(x).map(|(w, x)| w * x).sum::<f32>();
        }
    }

    pub(crate) fn outputs(&self) -> usize {
        self.bias.len()
    }
}

/// A trained classifier (module docs).
#[derive(Clone, Debug, PartialEq)]
pub struct Classifier {
    pub(crate) classes: Vec<String>,
    pub(crate) inputs: Vec<Feature>,
    pub(crate) mean: Vec<f32>,
    pub(crate) scale: Vec<f32>,
    pub(crate) hidden: Layer,
    pub(crate) output: Layer,
    pub(crate) start: f32,
    pub(crate) hold: f32,
}

/// Buffers for one evaluation, so that classifying allocates nothing.
#[derive(Clone, Debug, Default)]
pub struct ClassifierScratch {
    input: Vec<f32>,
    hidden: Vec<f32>,
    probabilities: Vec<f32>,
}

impl Classifier {
    /// The class names, in output order.
    #[must_use]
    pub fn classes(&self) -> &[String] {
        &self.classes
    }

    /// The features it reads, in input order.
    #[must_use]
    pub fn inputs(&self) -> &[Feature] {
        &self.inputs
    }

    /// The index of class `name`.
    #[must_use]
    pub fn class_index(&self, name: &str) -> Option<usize> {
        self.classes.iter().position(|c| c == name)
    }

    /// The probability a class must exceed for its gesture to start, and to hold once started.
    #[must_use]
    pub fn thresholds(&self) -> (f32, f32) {
        (self.start, self.hold)
    }

    /// Buffers sized for this classifier.
    #[must_use]
    pub fn scratch(&self) -> ClassifierScratch {
        ClassifierScratch { input: vec![0.0; self.inputs.len()], hidden: vec![0.0; self.hidden.outputs()], probabilities: vec![0.0; self.classes.len()] }
    }

    /// The probability of each class for `features` (NaN features give NaN, which exceed no
    /// threshold). Allocates nothing with a scratch from [`Self::scratch`].
    pub fn classify<'s>(&self, features: &HandFeatures, scratch: &'s mut ClassifierScratch) -> &'s [f32] {
        for ((x, f), (m, s)) in scratch.input.iter_mut().zip(&self.inputs).zip(self.mean.iter().zip(&self.scale)) {
            *x = (features.get(*f) - m) / s;
        }
        self.probabilities_of(scratch)
    }

    /// The probabilities of standardised inputs already in `scratch.input`.
    fn probabilities_of<'s>(&self, scratch: &'s mut ClassifierScratch) -> &'s [f32] {
        self.hidden.apply(&scratch.input, &mut scratch.hidden);
        for h in &mut scratch.hidden {
            *h = h.max(0.0);
        }
        self.output.apply(&scratch.hidden, &mut scratch.probabilities);
        softmax(&mut scratch.probabilities);
        &scratch.probabilities
    }

    /// Its JSON form (module docs).
    #[must_use]
    pub(crate) fn to_json(&self) -> ClassifierJson {
        let layer = |l: &Layer| LayerJson { weights: l.weights.chunks_exact(l.inputs).map(<[f32]>::to_vec).collect(), bias: l.bias.clone() };
        ClassifierJson {
            classes: self.classes.clone(),
            inputs: self.inputs.iter().map(|f| f.name()).collect(),
            mean: self.mean.clone(),
            scale: self.scale.clone(),
            hidden: layer(&self.hidden),
            output: layer(&self.output),
            start: self.start,
            hold: self.hold,
        }
    }

    /// Checks and builds the JSON form: `what` names it in errors (`classifier`, or a gesture's
    /// `model`).
    pub(crate) fn from_json(json: ClassifierJson, what: &str) -> Result<Self, GestureProblem> {
        let bad = |why: String| GestureProblem::Classifier { what: what.to_owned(), problem: why };
        let inputs = json
            .inputs
            .iter()
            .map(|n| Feature::from_name(n).ok_or_else(|| bad(format!("unknown input feature {n:?}; valid: {}", Feature::ALL.map(Feature::name).join(", ")))))
            .collect::<Result<Vec<_>, _>>()?;
        let n = inputs.len();
        if n == 0 || json.classes.len() < 2 {
            return Err(bad("needs at least one input and two classes".into()));
        }
        if json.mean.len() != n || json.scale.len() != n {
            return Err(bad(format!("mean and scale need {n} values each, one per input")));
        }
        if json.scale.iter().any(|s| !(s.is_finite() && *s > 0.0)) {
            return Err(bad("every scale must be a finite number > 0".into()));
        }
        for (i, c) in json.classes.iter().enumerate() {
            if json.classes[..i].contains(c) {
                return Err(bad(format!("class {c:?} is listed twice")));
            }
        }
        let hidden = json.hidden.into_layer(n).map_err(|e| bad(format!("hidden: {e}")))?;
        let output = json.output.into_layer(hidden.outputs()).map_err(|e| bad(format!("output: {e}")))?;
        if output.outputs() != json.classes.len() {
            return Err(bad(format!("output has {} rows for {} classes", output.outputs(), json.classes.len())));
        }
        if !(json.hold.is_finite() && json.start.is_finite() && 0.0 < json.hold && json.hold <= json.start && json.start < 1.0) {
            return Err(bad(format!("start {} and hold {} must satisfy 0 < hold ≤ start < 1", json.start, json.hold)));
        }
        let finite = |v: &[f32]| v.iter().all(|x| x.is_finite());
        if !(finite(&json.mean) && finite(&hidden.weights) && finite(&hidden.bias) && finite(&output.weights) && finite(&output.bias)) {
            return Err(bad("a weight, bias or mean is not a finite number".into()));
        }
        Ok(Self { classes: json.classes, inputs, mean: json.mean, scale: json.scale, hidden, output, start: json.start, hold: json.hold })
    }
}

/// Turns scores into probabilities in place, shifted by the largest for range.
pub(crate) fn softmax(v: &mut [f32]) {
    let top = v.iter().copied().fold(f32::NEG_INFINITY, f32::max);
    let mut sum = 0.0;
    for x in v.iter_mut() {
        *x = libm::expf(*x - top);
        sum += *x;
    }
    for x in v.iter_mut() {
        *x /= sum;
    }
}

/// The JSON form of a [`Classifier`].
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct ClassifierJson {
    classes: Vec<String>,
    inputs: Vec<String>,
    mean: Vec<f32>,
    scale: Vec<f32>,
    hidden: LayerJson,
    output: LayerJson,
    start: f32,
    hold: f32,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct LayerJson {
    weights: Vec<Vec<f32>>,
    bias: Vec<f32>,
}

impl LayerJson {
    fn into_layer(self, inputs: usize) -> Result<Layer, String> {
        if self.weights.is_empty() || self.weights.len() != self.bias.len() {
            return Err(format!("{} rows of weights for {} biases (need one row per bias, at least one)", self.weights.len(), self.bias.len()));
        }
        if let Some(row) = self.weights.iter().find(|r| r.len() != inputs) {
            return Err(format!("a row has {} weights, expected {inputs}", row.len()));
        }
        Ok(Layer { inputs, weights: self.weights.concat(), bias: self.bias })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The network written out from its definition, with nothing shared but the numbers.
    fn by_definition(c: &Classifier, x: &[f32]) -> Vec<f64> {
        let z: Vec<f64> = (0..x.len()).map(|i| (f64::from(x[i]) - f64::from(c.mean[i])) / f64::from(c.scale[i])).collect();
        let h: Vec<f64> = (0..c.hidden.bias.len())
            .map(|j| (f64::from(c.hidden.bias[j]) + (0..z.len()).map(|i| f64::from(c.hidden.weights[j * z.len() + i]) * z[i]).sum::<f64>()).max(0.0))
            .collect();
        let o: Vec<f64> = (0..c.output.bias.len()).map(|k| f64::from(c.output.bias[k]) + (0..h.len()).map(|j| f64::from(c.output.weights[k * h.len() + j]) * h[j]).sum::<f64>()).collect();
        let total: f64 = o.iter().map(|v| v.exp()).sum();
        o.iter().map(|v| v.exp() / total).collect()
    }

    #[test]
    fn classify_is_the_network_of_its_definition() {
        let json = r#"{"classes": ["none", "a", "b"], "inputs": ["index.curl", "thumb.across"], "mean": [0.5, 0.1], "scale": [0.25, 0.2],
            "hidden": {"weights": [[1.0, -2.0], [0.5, 0.25], [-1.5, 1.0]], "bias": [0.1, -0.2, 0.3]},
            "output": {"weights": [[1.0, 0.0, -1.0], [0.0, 2.0, 0.5], [-0.5, 1.0, 1.5]], "bias": [0.0, -0.1, 0.2]}, "start": 0.6, "hold": 0.4}"#;
        let c = Classifier::from_json(serde_json::from_str(json).unwrap(), "classifier").unwrap();
        let mut f = crate::gesture::HandFeatures::from_positions(&[glam::Vec3::ZERO; 25], crate::kinematics::Side::Right);
        let mut scratch = c.scratch();
        for (curl, across) in [(0.9, -0.3), (0.1, 0.4), (0.5, 0.1)] {
            f.curl[1] = curl;
            f.thumb_tip[0] = across;
            let p = c.classify(&f, &mut scratch).to_vec();
            let expected = by_definition(&c, &[curl, across]);
            for (a, b) in p.iter().zip(&expected) {
                assert!((f64::from(*a) - b).abs() < 1e-6, "{p:?} vs {expected:?}");
            }
        }
        let written = serde_json::to_string(&c.to_json()).unwrap();
        assert_eq!(Classifier::from_json(serde_json::from_str(&written).unwrap(), "classifier").unwrap(), c, "written and read back equal");
    }

    #[test]
    fn a_malformed_classifier_names_what_is_wrong() {
        let base = serde_json::json!({"classes": ["none", "a"], "inputs": ["index.curl"], "mean": [0.5], "scale": [0.25],
            "hidden": {"weights": [[1.0]], "bias": [0.0]}, "output": {"weights": [[1.0], [2.0]], "bias": [0.0, 0.0]}, "start": 0.6, "hold": 0.4});
        for (field, value, message) in [
            ("inputs", serde_json::json!(["index.kurl"]), "unknown input feature \"index.kurl\""),
            ("scale", serde_json::json!([0.0]), "scale"),
            ("hold", serde_json::json!(0.7), "0 < hold ≤ start < 1"),
            ("classes", serde_json::json!(["a", "a"]), "class \"a\" is listed twice"),
            ("output", serde_json::json!({"weights": [[1.0, 2.0]], "bias": [0.0]}), "output: a row has 2 weights, expected 1"),
        ] {
            let mut json = base.clone();
            json[field] = value;
            let e = Classifier::from_json(serde_json::from_value(json).unwrap(), "classifier").unwrap_err().to_string();
            assert!(e.starts_with("classifier: ") && e.contains(message), "{field}: {e}");
        }
    }
}
