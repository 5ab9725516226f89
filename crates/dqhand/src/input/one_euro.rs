//! The One Euro filter (Casiez, Roussel, Vogel, "1 € Filter: A Simple Speed-based Low-pass
//! Filter for Noisy Input in Interactive Systems", CHI 2012): a low-pass filter whose cutoff
//! rises with speed, so a still hand does not jitter and a moving one does not lag.
//!
//! For a sample `x` after `dt` seconds (the paper's equations):
//! `α(fc) = 1 / (1 + τ/dt)`, `τ = 1 / (2π fc)`;
//! `dx̂ = α(d_cutoff)·(x − x̂_prev)/dt + (1 − α(d_cutoff))·dx̂_prev`;
//! `fc = min_cutoff + β·|dx̂|`; `x̂ = α(fc)·x + (1 − α(fc))·x̂_prev`.
//!
//! Three filters share that rule: [`OneEuro`] on a scalar (a joint angle), [`OneEuroVec3`] on
//! a position (speed = the length of the velocity, so all axes share one cutoff), and
//! [`OneEuroRotation`] on an orientation, filtered on the sphere: the speed is the angular
//! speed and the step is a slerp toward the new sample, never a per-component blend that
//! would leave the unit sphere or take the long way round.

use glam::{Quat, Vec3};
use serde::{Deserialize, Serialize};

/// Parameters of a One Euro filter.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OneEuroParams {
    /// Cutoff at rest, Hz: lower removes more jitter from a still hand.
    pub min_cutoff: f32,
    /// Speed coefficient, cutoff Hz per unit of speed: higher removes more lag in motion.
    pub beta: f32,
    /// Cutoff of the speed estimate, Hz (the paper's 1 Hz).
    pub d_cutoff: f32,
}

impl OneEuroParams {
    /// Defaults for joint angles in radians: 1.5 Hz at rest; a finger closing at 5 rad/s gets
    /// ~6.5 Hz.
    pub const ANGLE: Self = Self { min_cutoff: 1.5, beta: 1.0, d_cutoff: 1.0 };
    /// Defaults for the wrist position in metres: 1 Hz at rest, +20 Hz per m/s.
    pub const POSITION: Self = Self { min_cutoff: 1.0, beta: 20.0, d_cutoff: 1.0 };
    /// Defaults for the wrist orientation in radians: 1 Hz at rest, +2 Hz per rad/s.
    pub const ROTATION: Self = Self { min_cutoff: 1.0, beta: 2.0, d_cutoff: 1.0 };

    /// Whether every parameter is finite and positive (β may be 0).
    #[must_use]
    pub fn is_valid(&self) -> bool {
        self.min_cutoff.is_finite() && self.min_cutoff > 0.0 && self.beta.is_finite() && self.beta >= 0.0 && self.d_cutoff.is_finite() && self.d_cutoff > 0.0
    }

    /// The smoothing factor for cutoff `fc` after `dt` seconds.
    fn alpha(fc: f32, dt: f32) -> f32 {
        let tau = 1.0 / (core::f32::consts::TAU * fc);
        1.0 / (1.0 + tau / dt)
    }

    /// One step of the speed estimate and the speed-dependent smoothing factor.
    fn step(&self, speed: f32, speed_prev: f32, dt: f32) -> (f32, f32) {
        let a = Self::alpha(self.d_cutoff, dt);
        let speed_hat = a * speed + (1.0 - a) * speed_prev;
        (speed_hat, Self::alpha(self.min_cutoff + self.beta * speed_hat.abs(), dt))
    }
}

/// A One Euro filter on one value.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OneEuro {
    params: OneEuroParams,
    state: Option<(f32, f32)>,
}

impl OneEuro {
    /// A filter that passes its first sample through.
    #[must_use]
    pub fn new(params: OneEuroParams) -> Self {
        Self { params, state: None }
    }

    /// Forgets the past: the next sample passes through.
    pub fn reset(&mut self) {
        self.state = None;
    }

    /// Filters sample `x` taken `dt` seconds after the previous one (`dt` > 0).
    pub fn filter(&mut self, x: f32, dt: f32) -> f32 {
        let (x_hat, dx_hat) = match self.state {
            Some((prev, dx_prev)) if dt > 0.0 => {
                let (dx_hat, a) = self.params.step((x - prev) / dt, dx_prev, dt);
                (a * x + (1.0 - a) * prev, dx_hat)
            }
            Some(state) => state,
            None => (x, 0.0),
        };
        self.state = Some((x_hat, dx_hat));
        x_hat
    }
}

/// A One Euro filter on a position: one cutoff from the speed, applied to all three axes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OneEuroVec3 {
    params: OneEuroParams,
    state: Option<(Vec3, f32)>,
}

impl OneEuroVec3 {
    /// A filter that passes its first sample through.
    #[must_use]
    pub fn new(params: OneEuroParams) -> Self {
        Self { params, state: None }
    }

    /// Forgets the past.
    pub fn reset(&mut self) {
        self.state = None;
    }

    /// Filters position `x` taken `dt` seconds after the previous one.
    pub fn filter(&mut self, x: Vec3, dt: f32) -> Vec3 {
        let (x_hat, speed_hat) = match self.state {
            Some((prev, speed_prev)) if dt > 0.0 => {
                let (speed_hat, a) = self.params.step((x - prev).length() / dt, speed_prev, dt);
                (prev.lerp(x, a), speed_hat)
            }
            Some(state) => state,
            None => (x, 0.0),
        };
        self.state = Some((x_hat, speed_hat));
        x_hat
    }
}

/// A One Euro filter on an orientation, on the unit sphere of quaternions.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OneEuroRotation {
    params: OneEuroParams,
    state: Option<(Quat, f32)>,
}

impl OneEuroRotation {
    /// A filter that passes its first sample through.
    #[must_use]
    pub fn new(params: OneEuroParams) -> Self {
        Self { params, state: None }
    }

    /// Forgets the past.
    pub fn reset(&mut self) {
        self.state = None;
    }

    /// Filters orientation `q` (unit) taken `dt` seconds after the previous one: the speed
    /// is the angle from the previous estimate over `dt`, the step a slerp by α along the
    /// shorter arc.
    pub fn filter(&mut self, q: Quat, dt: f32) -> Quat {
        let (q_hat, speed_hat) = match self.state {
            Some((prev, speed_prev)) if dt > 0.0 => {
                let (speed_hat, a) = self.params.step(prev.angle_between(q) / dt, speed_prev, dt);
                (prev.slerp(q, a).normalize(), speed_hat)
            }
            Some(state) => state,
            None => (q, 0.0),
        };
        self.state = Some((q_hat, speed_hat));
        q_hat
    }
}
