//! Training a [`Classifier`] on labelled hand features: cross-entropy with each class weighted
//! by the inverse of its share (a class with few examples, such as a gesture recorded for a few
//! seconds among thousands of generated frames, counts as much as the others), minibatch Adam,
//! weight decay, and a seeded shuffle, so that the same examples give the same network.

use super::classifier::{softmax, Classifier, Layer};
use super::{Feature, HandFeatures};
use crate::math::Rng;
use crate::{Error, Result};

/// One labelled example: a hand's features and the index of its class.
#[derive(Clone, Copy, Debug)]
pub struct Example {
    /// The features, as the recogniser measures them.
    pub features: HandFeatures,
    /// Index into the classes being trained.
    pub class: usize,
}

/// How a classifier is trained.
#[derive(Clone, Debug)]
pub struct TrainingParams {
    /// Hidden units.
    pub hidden: usize,
    /// Passes over the examples.
    pub epochs: usize,
    /// Examples per step.
    pub batch: usize,
    /// Adam's step size (decayed linearly to a tenth over the epochs).
    pub learning_rate: f32,
    /// L2 penalty on the weights.
    pub weight_decay: f32,
    /// Seed of the initial weights and the shuffles.
    pub seed: u64,
    /// Probability a class must exceed to start its gesture ([`Classifier::thresholds`]).
    pub start: f32,
    /// Probability it must keep exceeding to hold.
    pub hold: f32,
}

impl Default for TrainingParams {
    fn default() -> Self {
        Self { hidden: 32, epochs: 30, batch: 64, learning_rate: 3e-3, weight_decay: 1e-4, seed: 1, start: 0.6, hold: 0.35 }
    }
}

/// Trains a classifier of `classes` on the features `inputs` of `examples`. Examples with a
/// feature that is not finite (a degenerate hand) are left out.
///
/// # Errors
/// [`Error::Training`] when there are fewer than two classes, no input, an example's class is
/// out of range, or a class has no (finite) example.
pub fn train(classes: Vec<String>, inputs: Vec<Feature>, examples: &[Example], params: &TrainingParams) -> Result<Classifier> {
    let bad = |why: String| Error::Training(why);
    if classes.len() < 2 || inputs.is_empty() || params.hidden == 0 || params.batch == 0 {
        return Err(bad(format!("needs two classes, an input, hidden units and a batch size (got {}, {}, {}, {})", classes.len(), inputs.len(), params.hidden, params.batch)));
    }
    let d = inputs.len();
    let mut x = Vec::with_capacity(examples.len() * d);
    let mut y = Vec::with_capacity(examples.len());
    for e in examples {
        if e.class >= classes.len() {
            return Err(bad(format!("an example has class {} of {}", e.class, classes.len())));
        }
        let values: Vec<f32> = inputs.iter().map(|f| e.features.get(*f)).collect();
        if values.iter().all(|v| v.is_finite()) {
            x.extend(values);
            y.push(e.class);
        }
    }
    let n = y.len();
    let mut counts = vec![0usize; classes.len()];
    for &c in &y {
        counts[c] += 1;
    }
    if let Some(c) = counts.iter().position(|&k| k == 0) {
        return Err(bad(format!("class {:?} has no example", classes[c])));
    }
    let class_weight: Vec<f32> = counts.iter().map(|&k| n as f32 / (classes.len() * k) as f32).collect();

    // Standardise each input over the examples.
    let mut mean = vec![0.0f64; d];
    let mut square = vec![0.0f64; d];
    for row in x.chunks_exact(d) {
        for i in 0..d {
            mean[i] += f64::from(row[i]);
            square[i] += f64::from(row[i]).powi(2);
        }
    }
    let mean: Vec<f32> = mean.iter().map(|m| (m / n as f64) as f32).collect();
    let scale: Vec<f32> = square.iter().zip(&mean).map(|(s, m)| ((s / n as f64 - f64::from(*m).powi(2)).max(0.0).sqrt() as f32).max(1e-3)).collect();
    for row in x.chunks_exact_mut(d) {
        for i in 0..d {
            row[i] = (row[i] - mean[i]) / scale[i];
        }
    }

    let (h, c) = (params.hidden, classes.len());
    let mut rng = Rng::new(params.seed);
    let mut net = Net {
        hidden: Layer { inputs: d, weights: (0..h * d).map(|_| rng.normal() * (2.0 / d as f32).sqrt()).collect(), bias: vec![0.0; h] },
        output: Layer { inputs: h, weights: (0..c * h).map(|_| rng.normal() * (1.0 / h as f32).sqrt()).collect(), bias: vec![0.0; c] },
    };
    let mut adam = Adam::new(&net);
    let mut grad = net.zeros();
    let (mut hidden, mut out) = (vec![0.0; h], vec![0.0; c]);
    let mut order: Vec<usize> = (0..n).collect();
    let steps = params.epochs * n.div_ceil(params.batch);
    let mut step = 0;
    for _ in 0..params.epochs {
        for i in (1..n).rev() {
            order.swap(i, rng.below(i + 1));
        }
        for batch in order.chunks(params.batch) {
            grad.clear();
            for &e in batch {
                let z = &x[e * d..(e + 1) * d];
                net.hidden.apply(z, &mut hidden);
                hidden.iter_mut().for_each(|v| *v = v.max(0.0));
                net.output.apply(&hidden, &mut out);
                softmax(&mut out);
                out[y[e]] -= 1.0;
                let w = class_weight[y[e]] / batch.len() as f32;
                for k in 0..c {
                    let g = out[k] * w;
                    grad.output.bias[k] += g;
                    for j in 0..h {
                        grad.output.weights[k * h + j] += g * hidden[j];
                    }
                }
                for j in 0..h {
                    if hidden[j] <= 0.0 {
                        continue;
                    }
                    let g: f32 = (0..c).map(|k| out[k] * w * net.output.weights[k * h + j]).sum();
                    grad.hidden.bias[j] += g;
                    for i in 0..d {
                        grad.hidden.weights[j * d + i] += g * z[i];
                    }
                }
            }
            let rate = params.learning_rate * (1.0 - 0.9 * step as f32 / steps as f32);
            step += 1;
            adam.step(&mut net, &mut grad, rate, params.weight_decay);
        }
    }
    Ok(Classifier { classes, inputs, mean, scale, hidden: net.hidden, output: net.output, start: params.start, hold: params.hold })
}

/// The two layers being trained (and, with the same shapes, their gradients and moments).
struct Net {
    hidden: Layer,
    output: Layer,
}

impl Net {
    fn zeros(&self) -> Self {
        let zero = |l: &Layer| Layer { inputs: l.inputs, weights: vec![0.0; l.weights.len()], bias: vec![0.0; l.bias.len()] };
        Self { hidden: zero(&self.hidden), output: zero(&self.output) }
    }

    fn clear(&mut self) {
        for v in self.values_mut() {
            v.fill(0.0);
        }
    }

    /// Every parameter vector: weights (even places, which decay), then biases.
    fn values_mut(&mut self) -> [&mut Vec<f32>; 4] {
        [&mut self.hidden.weights, &mut self.hidden.bias, &mut self.output.weights, &mut self.output.bias]
    }
}

/// Adam's first and second moments.
struct Adam {
    m: Net,
    v: Net,
    t: i32,
}

impl Adam {
    const BETA1: f32 = 0.9;
    const BETA2: f32 = 0.999;

    fn new(net: &Net) -> Self {
        Self { m: net.zeros(), v: net.zeros(), t: 0 }
    }

    /// One step along `grad` (borrowed mutably only to walk it beside the parameters).
    fn step(&mut self, net: &mut Net, grad: &mut Net, rate: f32, decay: f32) {
        self.t += 1;
        let (c1, c2) = (1.0 - Self::BETA1.powi(self.t), 1.0 - Self::BETA2.powi(self.t));
        let params = net.values_mut();
        let (ms, vs, gs) = (self.m.values_mut(), self.v.values_mut(), grad.values_mut());
        for (k, (((p, m), v), g)) in params.into_iter().zip(ms).zip(vs).zip(gs).enumerate() {
            let weights = k % 2 == 0;
            for i in 0..p.len() {
                let gi = g[i] + if weights { decay * p[i] } else { 0.0 };
                m[i] = Self::BETA1 * m[i] + (1.0 - Self::BETA1) * gi;
                v[i] = Self::BETA2 * v[i] + (1.0 - Self::BETA2) * gi * gi;
                p[i] -= rate * (m[i] / c1) / ((v[i] / c2).sqrt() + 1e-8);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::{train, Example, TrainingParams};
    use crate::gesture::{Feature, Finger, HandFeatures, PalmAxis};
    use crate::kinematics::Side;
    use crate::math::Rng;

    /// Three classes that no single threshold separates: "in" is a ring of the two inputs,
    /// "left" and "right" the two halves outside it.
    #[test]
    fn learns_classes_no_single_threshold_separates_and_generalises_to_new_draws() {
        let base = HandFeatures::from_positions(&[Vec3::ZERO; 25], Side::Right);
        let draw = |rng: &mut Rng| {
            let (a, b) = (rng.uniform(-1.0, 1.0) as f32, rng.uniform(-1.0, 1.0) as f32);
            let class = if a * a + b * b < 0.4 { 0 } else if a < 0.0 { 1 } else { 2 };
            let mut features = base;
            features.curl[1] = a;
            features.thumb_tip[0] = b;
            Example { features, class }
        };
        let mut rng = Rng::new(7);
        let examples: Vec<Example> = (0..1500).map(|_| draw(&mut rng)).collect();
        let inputs = vec![Feature::Curl(Finger::Index), Feature::ThumbTip(PalmAxis::Across)];
        let classes = vec!["in".to_owned(), "left".to_owned(), "right".to_owned()];
        let c = train(classes, inputs, &examples, &TrainingParams { hidden: 16, epochs: 40, ..TrainingParams::default() }).unwrap();
        let mut scratch = c.scratch();
        let held_out: Vec<Example> = (0..500).map(|_| draw(&mut rng)).collect();
        let right = held_out
            .iter()
            .filter(|e| {
                let p = c.classify(&e.features, &mut scratch);
                (0..3).max_by(|&a, &b| p[a].total_cmp(&p[b])) == Some(e.class)
            })
            .count();
        assert!(right >= 470, "{right} of 500 new draws classified right");
    }

    #[test]
    fn a_class_without_finite_examples_is_an_error() {
        let nan = HandFeatures::from_positions(&[Vec3::ZERO; 25], Side::Right);
        let features = HandFeatures { thumb_tip: [0.5; 3], ..nan };
        let inputs = vec![Feature::ThumbTip(PalmAxis::Across)];
        let e = train(vec!["a".into(), "b".into()], inputs, &[Example { features, class: 0 }, Example { features: nan, class: 1 }], &TrainingParams::default()).unwrap_err();
        assert!(e.to_string().contains("class \"b\" has no example"), "{e}");
    }
}
