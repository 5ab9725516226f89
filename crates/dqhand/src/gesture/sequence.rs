//! Pose sequences: keyframes in time, played back with eased angle interpolation and ScLERP
//! of the wrist, as the timeline of the viewer and the smooth move to a chosen gesture.

use crate::kinematics::{JointModel, Pose};
use crate::math::DualQuat;
use crate::{Error, Result};

use super::GESTURES;

/// One pose at one time.
#[derive(Clone, Debug, PartialEq)]
pub struct Keyframe {
    /// Seconds from the start of the sequence.
    pub time: f32,
    /// The pose, on the sequence's joint model.
    pub pose: Pose,
}

/// Keyframes of one joint model in ascending time.
#[derive(Clone, Debug, PartialEq)]
pub struct Sequence {
    name: String,
    model: JointModel,
    keys: Vec<Keyframe>,
}

/// How long the bundled gesture sequence holds each gesture, and how long it takes to reach the next.
const HOLD_SECONDS: f32 = 0.8;
const MOVE_SECONDS: f32 = 0.7;

impl Sequence {
    /// A sequence from keyframes.
    ///
    /// # Errors
    /// [`Error::Sequence`] naming the sequence if it has no keyframe, a time that is not finite
    /// or goes backwards, or a pose with another angle count than `model`'s.
    pub fn new(name: impl Into<String>, model: JointModel, keys: Vec<Keyframe>) -> Result<Self> {
        let name = name.into();
        let bad = |what: String| Error::Sequence(format!("sequence {name:?}: {what}"));
        if keys.is_empty() {
            return Err(bad("no keyframes".into()));
        }
        let mut last = 0.0f32;
        for (i, k) in keys.iter().enumerate() {
            if !k.time.is_finite() || k.time < last {
                return Err(bad(format!("keyframe {i} time {} is not finite or goes backwards", k.time)));
            }
            if k.pose.angles.len() != model.dof_count() {
                return Err(bad(format!("keyframe {i} has {} angles, the {model} model {}", k.pose.angles.len(), model.dof_count())));
            }
            last = k.time;
        }
        Ok(Self { name, model, keys })
    }

    /// The bundled demo sequence: every gesture of the library in turn, each held for
    /// 0.8 s and reached from the previous one in 0.7 s, ending back on the first.
    #[must_use]
    pub fn gestures(model: JointModel) -> Self {
        let mut keys = Vec::with_capacity(2 * GESTURES.len() + 1);
        let mut time = 0.0;
        for g in GESTURES.iter().chain(&GESTURES[..1]) {
            let key = |time| Keyframe { time, pose: g.pose(model) };
            keys.push(key(time));
            keys.push(key(time + HOLD_SECONDS));
            time += HOLD_SECONDS + MOVE_SECONDS;
        }
        keys.pop();
        Self { name: "gestures".into(), model, keys }
    }

    /// A move from `from` to `to` (a pose of `model`) in `seconds`.
    ///
    /// # Panics
    /// If a pose does not belong to `model`.
    #[must_use]
    pub fn transition(model: JointModel, from: &Pose, to: Pose, seconds: f32) -> Self {
        let keys = vec![Keyframe { time: 0.0, pose: from.clone() }, Keyframe { time: seconds.max(0.0), pose: to }];
        Self::new("transition", model, keys).expect("poses of the sequence's model")
    }

    /// The sequence's name.
    #[must_use]
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The joint model of its poses.
    #[must_use]
    pub fn model(&self) -> JointModel {
        self.model
    }

    /// The keyframes.
    #[must_use]
    pub fn keys(&self) -> &[Keyframe] {
        &self.keys
    }

    /// Time of the last keyframe, seconds.
    #[must_use]
    pub fn duration(&self) -> f32 {
        self.keys.last().map_or(0.0, |k| k.time)
    }

    /// The pose at `time` (clamped to the sequence) into `out`. Between two keys the weight
    /// eases in and out (smoothstep), so a hand starts and stops moving gently; angles are
    /// interpolated linearly in that weight and the wrist by ScLERP, a missing wrist standing
    /// for `rest_wrist` ([`Pose::interpolate`]). Allocates nothing.
    ///
    /// # Panics
    /// If `out` has another angle count than the sequence's model.
    pub fn sample(&self, time: f32, rest_wrist: DualQuat, out: &mut Pose) {
        let t = time.clamp(0.0, self.duration());
        let next = self.keys.partition_point(|k| k.time <= t);
        let a = &self.keys[next.saturating_sub(1)];
        let Some(b) = self.keys.get(next) else {
            a.pose.interpolate_into(&a.pose, 0.0, rest_wrist, out);
            return;
        };
        let span = b.time - a.time;
        let s = if span > 0.0 { ((t - a.time) / span).clamp(0.0, 1.0) } else { 1.0 };
        a.pose.interpolate_into(&b.pose, s * s * (3.0 - 2.0 * s), rest_wrist, out);
    }
}
