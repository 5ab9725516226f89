//! The One Euro filter (Casiez, Roussel, Vogel, "1 € Filter: A Simple Speed-based Low-pass
//! Filter for Noisy Input in Interactive Systems", CHI 2012): a low-pass filter whose cutoff
//! rises with speed, so a still hand does not jitter and a moving one does not lag.
//!
//! For a sample `x` after `dt` seconds (the paper's equations):
//! `α(fc) = 1 / (1 + τ/dt)`, `τ = 1 / (2π fc)`;
//! `dx̂ = α(d_cutoff)·(x − x̂_prev)/dt + (1 − α(d_cutoff))·dx̂_prev`;
//! `fc = min_cutoff + β·|dx̂|`; `x̂ = α(fc)·x + (1 − α(fc))·x̂_prev`.
//!
//! One [`OneEuroFilter`] serves three kinds of value ([`Filtered`]): [`OneEuro`] on a scalar
//! (a joint angle), [`OneEuroVec3`] on a position, and [`OneEuroRotation`] on an orientation,
//! filtered on the sphere (the step is a slerp toward the new sample, never a per-component
//! blend that would leave the unit sphere or take the long way round). For a position and an
//! orientation `dx̂` is the velocity *vector* (the angular velocity), low-passed per component,
//! and `|dx̂|` its length, so all axes share one cutoff: low-passing the *length* of each
//! step's velocity instead would never average a still hand's noise out (lengths are never
//! negative), and the cutoff of a still hand would rise with the noise, and with it the jitter.

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
    /// Defaults for the wrist position in metres: 1 Hz at rest, +20 Hz per m/s. On `dqhand
    /// grasp-bench`'s free-hand sweeps (1.5 mm joint noise) 4.9 mm behind at 0.5 m/s and
    /// 0.47 mm RMS tremble at rest, both within the targets (5 mm, 0.5 mm). A higher β lags
    /// less and trembles more (0.5 Hz, +40 Hz per m/s: 3.0 mm, 0.48 mm), but moved a fast
    /// hand's stop on the teapot by 0.4 mm, enough to lose two of its grasps at 10 m/s.
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

    /// One step of the velocity estimate and the speed-dependent smoothing factor.
    fn step<V: Velocity>(&self, velocity: V, velocity_prev: V, dt: f32) -> (V, f32) {
        let a = Self::alpha(self.d_cutoff, dt);
        let velocity_hat = velocity.scale(a).add(velocity_prev.scale(1.0 - a));
        (velocity_hat, Self::alpha(self.min_cutoff + self.beta * velocity_hat.length(), dt))
    }
}

/// A rate of change the filter low-passes: a scalar's, or a vector's per component.
pub trait Velocity: Copy {
    /// At rest.
    const ZERO: Self;
    fn scale(self, s: f32) -> Self;
    fn add(self, other: Self) -> Self;
    /// The speed: its absolute value, or length.
    fn length(self) -> f32;
}

impl Velocity for f32 {
    const ZERO: Self = 0.0;
    fn scale(self, s: f32) -> Self {
        self * s
    }
    fn add(self, other: Self) -> Self {
        self + other
    }
    fn length(self) -> f32 {
        self.abs()
    }
}

impl Velocity for Vec3 {
    const ZERO: Self = Vec3::ZERO;
    fn scale(self, s: f32) -> Self {
        self * s
    }
    fn add(self, other: Self) -> Self {
        self + other
    }
    fn length(self) -> f32 {
        Vec3::length(self)
    }
}

/// What the One Euro rule needs of a filtered value: its velocity from one sample to the
/// next, and the step of a low-pass toward a new sample.
pub trait Filtered: Copy {
    /// How its velocity is held: a scalar's signed rate, a position's velocity, an
    /// orientation's angular velocity.
    type Velocity: Velocity;
    /// The velocity from `prev` to `x` over `dt` seconds.
    fn velocity(prev: Self, x: Self, dt: f32) -> Self::Velocity;
    /// `prev` moved toward `x` by `alpha` in [0, 1].
    fn blend(prev: Self, x: Self, alpha: f32) -> Self;
}

impl Filtered for f32 {
    type Velocity = f32;
    fn velocity(prev: Self, x: Self, dt: f32) -> f32 {
        (x - prev) / dt
    }
    fn blend(prev: Self, x: Self, alpha: f32) -> Self {
        alpha * x + (1.0 - alpha) * prev
    }
}

impl Filtered for Vec3 {
    type Velocity = Vec3;
    fn velocity(prev: Self, x: Self, dt: f32) -> Vec3 {
        (x - prev) / dt
    }
    fn blend(prev: Self, x: Self, alpha: f32) -> Self {
        prev.lerp(x, alpha)
    }
}

impl Filtered for Quat {
    type Velocity = Vec3;
    /// The angular velocity (world axis × rad/s) of the shorter arc from the previous estimate.
    fn velocity(prev: Self, x: Self, dt: f32) -> Vec3 {
        let turn = x * prev.inverse();
        let turn = if turn.w < 0.0 { -turn } else { turn };
        turn.to_scaled_axis() / dt
    }
    /// A slerp along the shorter arc, staying on the unit sphere.
    fn blend(prev: Self, x: Self, alpha: f32) -> Self {
        prev.slerp(x, alpha).normalize()
    }
}

/// A One Euro filter on a value of type `T`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OneEuroFilter<T: Filtered> {
    params: OneEuroParams,
    /// The last estimate and its filtered velocity.
    state: Option<(T, T::Velocity)>,
}

/// A One Euro filter on one value (a joint angle).
pub type OneEuro = OneEuroFilter<f32>;
/// A One Euro filter on a position: one cutoff from the speed, applied to all three axes.
pub type OneEuroVec3 = OneEuroFilter<Vec3>;
/// A One Euro filter on an orientation, on the unit sphere of quaternions.
pub type OneEuroRotation = OneEuroFilter<Quat>;

impl<T: Filtered> OneEuroFilter<T> {
    /// A filter that passes its first sample through.
    #[must_use]
    pub fn new(params: OneEuroParams) -> Self {
        Self { params, state: None }
    }

    /// Forgets the past: the next sample passes through.
    pub fn reset(&mut self) {
        self.state = None;
    }

    /// Filters sample `x` taken `dt` seconds after the previous one (`dt` > 0; a sample at
    /// the same time leaves the estimate as it is).
    pub fn filter(&mut self, x: T, dt: f32) -> T {
        let (x_hat, velocity_hat) = match self.state {
            Some((prev, velocity_prev)) if dt > 0.0 => {
                let (velocity_hat, a) = self.params.step(T::velocity(prev, x, dt), velocity_prev, dt);
                (T::blend(prev, x, a), velocity_hat)
            }
            Some(state) => state,
            None => (x, T::Velocity::ZERO),
        };
        self.state = Some((x_hat, velocity_hat));
        x_hat
    }
}
