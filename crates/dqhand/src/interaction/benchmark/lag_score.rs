//! The manipulation loop's lag and jitter on a free hand ([`crate::interaction::grasp_script::sweep`]):
//! how far the rendered wrist trails the true one at a constant speed, and how much it
//! trembles when the hand is still, under the joint noise of the records. Both come from the
//! input's filters (the One Euro filter trades one for the other, Casiez et al. 2012) and
//! from anything later in the loop that holds the hand back.

use serde::Serialize;

use crate::interaction::grasp_script::Sweep;
use crate::interaction::ManipulationLoop;

/// What one sweep measured.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct LagScore {
    /// The sweep's speed, m/s.
    pub speed: f32,
    /// How far the rendered wrist trails the true one along the motion, mean over the steady
    /// stretch, m (negative: ahead).
    pub lag_m: f32,
    /// The same as a delay: `lag_m / speed`, s.
    pub lag_s: f32,
    /// How much the rendered wrist of a still hand trembles: its RMS distance from its own
    /// mean position over the still stretch, m.
    pub jitter_m: f32,
}

/// Plays `sweep` through `manip` (a record, then a frame at its time) and measures the
/// rendered wrist against the true one.
pub fn lag(manip: &mut ManipulationLoop, sweep: &Sweep) -> LagScore {
    let (mut lag, mut steady) = (0.0f64, 0usize);
    let (mut sum, mut square, mut still) = (glam::DVec3::ZERO, 0.0f64, 0usize);
    for (record, truth) in sweep.records.iter().zip(&sweep.truth) {
        if manip.push(record).is_err() {
            continue;
        }
        manip.step(record.time);
        let (Some(rendered), Some(true_wrist)) = (manip.hands()[0].constraint().rendered().wrist, truth.wrist) else { continue };
        let offset = true_wrist.to_rotation_translation().1 - rendered.to_rotation_translation().1;
        let t = record.time;
        if t >= sweep.steady.0 && t <= sweep.steady.1 {
            lag += f64::from(offset.dot(sweep.direction));
            steady += 1;
        }
        if t >= sweep.rest.0 && t <= sweep.rest.1 {
            let p = rendered.to_rotation_translation().1.as_dvec3();
            sum += p;
            square += p.length_squared();
            still += 1;
        }
    }
    let lag_m = (lag / steady.max(1) as f64) as f32;
    let n = still.max(1) as f64;
    let variance = square / n - (sum / n).length_squared();
    LagScore { speed: sweep.speed, lag_m, lag_s: if sweep.speed > 0.0 { lag_m / sweep.speed } else { 0.0 }, jitter_m: variance.max(0.0).sqrt() as f32 }
}
