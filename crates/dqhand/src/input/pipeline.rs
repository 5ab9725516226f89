//! The input pipeline: records in, poses of the engine step out. Each record is checked
//! (time order, rate, latency), turned into a pose (glove mapping and tracker, or
//! retargeting of tracked joints or landmarks), filtered, and shown; when good records stop
//! the hand holds its last pose, is marked "tracking lost" after the grace time, relaxes its
//! fingers to rest if they stay away (`rest_after_s`), and blends back smoothly when they
//! return.
//!
//! A live stream is timed by two clocks: the records' capture times and their local arrival.
//! The stream's clock offset is its fastest delivery (smallest `arrival − capture`); a record
//! slower than that by `max_latency_s` is late, one more than [`MAX_LEAD_S`] ahead of it is a
//! jump of the sender's clock and out of range. "Tracking lost" is judged on the arrival
//! clock, so no capture time can hold the hand in "tracking". Once lost, a record that does
//! not fit the old stream (out of order, late, ahead) starts a new one: a sender that
//! restarted with its clock at zero, or another sender, is taken after the grace time.
//!
//! The grace time is at least `grace_s`, and grows with a slow stream (records more than
//! `grace_s` / [`GRACE_INTERVALS`] apart): a camera inferring at 3 frames a second, or a
//! headset emulated in software, would otherwise be lost before every record and each record
//! would blend back from the held pose, leaving the hand frozen. [`GRACE_INTERVALS`] times
//! the median of the last [`INTERVALS`] intervals between records, once there are
//! [`MIN_INTERVALS`] of them, up to [`MAX_GRACE_S`]: the median passes over a dropout, so a
//! fast stream that stops is lost after `grace_s` as before.
//!
//! Every per-record buffer is made up front: [`InputPipeline::push`] allocates nothing.

use glam::Vec3;

use super::record::JOINT_COUNT;
use super::{GloveMapper, HandData, InputConfig, OneEuro, OneEuroRotation, OneEuroVec3, Record, RejectKind, Rejection, Rejections, Retargeter};
use crate::kinematics::Side;
use crate::kinematics::{HandRig, Pose};
use crate::math::DualQuat;

/// How far ahead of the stream's clock a live record may claim to be, seconds: beyond it the
/// sender's clock jumped (a faster delivery gains milliseconds, not a second).
pub const MAX_LEAD_S: f64 = 1.0;

/// A stream's grace time is at least this many of its typical intervals between records.
pub const GRACE_INTERVALS: f64 = 2.5;
/// How many of the last intervals between records the typical one is the median of.
pub const INTERVALS: usize = 8;
/// Intervals measured before the grace time follows the stream's rate.
pub const MIN_INTERVALS: usize = 4;
/// The longest grace time a slow stream earns, seconds (a longer `grace_s` is kept).
pub const MAX_GRACE_S: f64 = 2.0;

/// Whether the hand follows the user.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Tracking {
    /// No good record yet: the hand is at rest.
    Waiting,
    /// Good records are arriving.
    Tracking,
    /// No good record for longer than the grace time: the hand holds its last pose.
    Lost,
}

impl Tracking {
    /// `waiting`, `tracking` or `lost`.
    #[must_use]
    pub fn as_str(self) -> &'static str {
        match self {
            Tracking::Waiting => "waiting",
            Tracking::Tracking => "tracking",
            Tracking::Lost => "lost",
        }
    }
}

/// Records → poses for one rig (see the module docs).
#[derive(Clone, Debug)]
pub struct InputPipeline {
    config: InputConfig,
    retargeter: Retargeter,
    glove: Option<GloveMapper>,
    angle_filters: Vec<OneEuro>,
    position_filter: OneEuroVec3,
    rotation_filter: OneEuroRotation,
    /// Capture time of the last good record.
    last_time: Option<f64>,
    /// Arrival time of the last good live record.
    last_arrival: Option<f64>,
    /// Smallest `arrival − capture time` seen on a live stream: the stream's clock offset.
    clock_offset: Option<f64>,
    state: Tracking,
    /// When the hand started blending back from a held pose, and that pose.
    recovering: Option<f64>,
    held: Pose,
    solved: Pose,
    filtered: Pose,
    output: Pose,
    positions: [Vec3; JOINT_COUNT],
    rejections: Rejections,
    accepted: u64,
    /// The side of the last record taken, if it tracked joints or landmarks.
    side: Option<Side>,
    /// How much of the held pose a lost hand still shows (1 until it relaxes, 0 at rest).
    kept: f32,
    /// When the hand was marked lost (its clock: arrival when live).
    lost_at: f64,
    /// The last intervals between records of the stream (its clock), a ring, and how many
    /// were measured.
    intervals: [f64; INTERVALS],
    measured: usize,
}

impl InputPipeline {
    /// A pipeline posing `rig`, with a glove mapper when glove records are expected.
    ///
    /// # Errors
    /// As [`Retargeter::new`]; [`crate::Error::Config`] if the glove mapper is for another
    /// joint model than the rig's.
    pub fn new(rig: &HandRig, glove: Option<GloveMapper>, config: InputConfig) -> crate::Result<Self> {
        if let Some(g) = &glove {
            if g.joint_model() != rig.model() {
                return Err(crate::Error::Config(format!("the glove maps to the {} joint model, the hand is posed with {}", g.joint_model(), rig.model())));
            }
        }
        let n = rig.dofs().len();
        let rest = Pose::rest(n);
        Ok(Self {
            retargeter: Retargeter::new(rig)?,
            glove,
            angle_filters: vec![OneEuro::new(config.angle_filter); n],
            position_filter: OneEuroVec3::new(config.position_filter),
            rotation_filter: OneEuroRotation::new(config.rotation_filter),
            last_time: None,
            last_arrival: None,
            clock_offset: None,
            state: Tracking::Waiting,
            recovering: None,
            held: rest.clone(),
            solved: rest.clone(),
            filtered: rest.clone(),
            output: rest,
            positions: [Vec3::ZERO; JOINT_COUNT],
            rejections: Rejections::default(),
            accepted: 0,
            side: None,
            kept: 1.0,
            lost_at: 0.0,
            intervals: [0.0; INTERVALS],
            measured: 0,
            config,
        })
    }

    /// The pose to show now.
    #[must_use]
    pub fn pose(&self) -> &Pose {
        &self.output
    }

    /// Whether the hand follows the user.
    #[must_use]
    pub fn tracking(&self) -> Tracking {
        self.state
    }

    /// Seconds without a good record before the hand is lost: `grace_s`, or longer for a slow
    /// stream (see the module docs).
    #[must_use]
    pub fn grace(&self) -> f64 {
        if self.measured < MIN_INTERVALS {
            return self.config.grace_s;
        }
        let n = self.measured.min(INTERVALS);
        let mut sorted = self.intervals;
        let sorted = &mut sorted[..n];
        sorted.sort_unstable_by(f64::total_cmp);
        let median = if n % 2 == 1 { sorted[n / 2] } else { (sorted[n / 2 - 1] + sorted[n / 2]) / 2.0 };
        self.config.grace_s.max((GRACE_INTERVALS * median).min(MAX_GRACE_S))
    }

    /// The refused records so far, by kind.
    #[must_use]
    pub fn rejections(&self) -> &Rejections {
        &self.rejections
    }

    /// Records taken so far.
    #[must_use]
    pub fn accepted(&self) -> u64 {
        self.accepted
    }

    /// The side of the hand the last record taken tracked (`None` before the first, and for
    /// glove records): a viewer mirrors our hand back for a tracked hand of the other side.
    #[must_use]
    pub fn side(&self) -> Option<Side> {
        self.side
    }

    /// The configuration.
    #[must_use]
    pub fn config(&self) -> &InputConfig {
        &self.config
    }

    /// The retargeter (its rig, side, and the tracked positions of the last joints record).
    #[must_use]
    pub fn retargeter(&self) -> &Retargeter {
        &self.retargeter
    }

    /// The tracked joint positions of the last good joints or landmarks record (WebXR order).
    #[must_use]
    pub fn tracked_positions(&self) -> &[Vec3; JOINT_COUNT] {
        &self.positions
    }

    /// Counts a record refused before it got here (by a reader or a transport).
    pub fn reject(&mut self, rejection: Rejection) {
        self.rejections.add(rejection);
    }

    /// Marks the hand lost if no good record came for the [`Self::grace`] time before `now` (the local
    /// arrival clock of [`Self::push`] on a live stream, the records' clock for a file), and
    /// relaxes a hand lost for `rest_after_s` more: its angles ease to rest over `recover_s`,
    /// its wrist stays. Returns whether the pose to show changed. Allocates nothing.
    pub fn advance(&mut self, now: f64) -> bool {
        if self.state == Tracking::Tracking {
            let Some(last) = self.last_arrival.or(self.last_time) else { return false };
            let grace = self.grace();
            if now - last <= grace {
                return false;
            }
            (self.state, self.lost_at, self.kept) = (Tracking::Lost, last + grace, 1.0);
            self.held.clone_from(&self.output);
        }
        // Timed from the loss itself, not from the clocks of the records since.
        let relaxing = now - self.lost_at - self.config.rest_after_s;
        if self.state != Tracking::Lost || relaxing <= 0.0 {
            return false;
        }
        let s = (relaxing as f32 / self.config.recover_s.max(f32::EPSILON)).min(1.0);
        let keep = 1.0 - s * s * (3.0 - 2.0 * s);
        if keep == self.kept {
            return false;
        }
        self.kept = keep;
        for (o, h) in self.output.angles.iter_mut().zip(&self.held.angles) {
            *o = h * keep;
        }
        true
    }

    /// Takes one record: from a file without [`Record::arrival`], live (or recorded live) with
    /// its local arrival time (seconds, any origin, monotonic), which lateness and loss of
    /// tracking are judged on. The hand is first brought up to that time as by
    /// [`Self::advance`], so the pose it blends back from after a loss does not depend on
    /// when the caller last advanced it: a replay gives the poses the live input gave.
    ///
    /// # Errors
    /// The record's refusal (also counted in [`Self::rejections`]); the shown pose is kept.
    pub fn push(&mut self, record: &Record) -> Result<(), Rejection> {
        let arrival = record.arrival;
        self.advance(arrival.unwrap_or(record.time));
        let result = self.take(record, arrival);
        if let Err(r) = &result {
            self.rejections.add(r.clone());
        }
        result
    }

    fn take(&mut self, record: &Record, arrival: Option<f64>) -> Result<(), Rejection> {
        let t = record.time;
        // A lost hand's record that does not fit the old stream starts a new one, at a rate of
        // its own; its clocks are reset only once it is taken (a live recording keeps only the
        // records taken: a refused one must leave nothing that a replay would not).
        let new_stream = arrival.filter(|_| self.state == Tracking::Lost && self.fit(t, arrival).is_err());
        let fastest = match new_stream {
            Some(a) => Some(a - t),
            None => self.fit(t, arrival)?,
        };
        self.solve(record)?;
        if new_stream.is_some() {
            (self.last_time, self.last_arrival, self.measured) = (None, None, 0);
        }
        // The interval on the clock loss is judged on: arrival when live, capture from a file.
        let since = match arrival {
            Some(a) => self.last_arrival.map(|last| a - last),
            None => self.last_time.filter(|_| self.last_arrival.is_none()).map(|last| t - last),
        };
        if let Some(interval) = since {
            self.intervals[self.measured % INTERVALS] = interval;
            self.measured += 1;
        }
        self.clock_offset = fastest;
        self.last_arrival = arrival;
        let dt = self.last_time.map_or(0.0, |last| (t - last) as f32);
        let resume = self.state != Tracking::Tracking;
        self.filter(dt, resume);
        if self.state == Tracking::Lost {
            self.held.clone_from(&self.output);
            self.recovering = Some(t);
        }
        match self.recovering {
            Some(start) if t - start < f64::from(self.config.recover_s) => {
                let s = ((t - start) as f32 / self.config.recover_s).clamp(0.0, 1.0);
                let rest_wrist = self.retargeter.rig().rest_wrist();
                self.held.interpolate_into(&self.filtered, s * s * (3.0 - 2.0 * s), rest_wrist, &mut self.output);
            }
            _ => {
                self.recovering = None;
                self.output.clone_from(&self.filtered);
            }
        }
        self.state = Tracking::Tracking;
        self.last_time = Some(t);
        self.accepted += 1;
        // Only tracked joints are mirrored onto our hand; a glove drives its own angles.
        self.side = matches!(record.hand, Some(HandData::Joints(_) | HandData::Landmarks(_))).then_some(record.side);
        Ok(())
    }

    /// Whether a record captured at `t` (arriving at `arrival`, live) continues the stream:
    /// after the previous record and not faster than the rate bound, and live, neither late
    /// nor ahead. Returns the stream's clock offset with it.
    fn fit(&self, t: f64, arrival: Option<f64>) -> Result<Option<f64>, Rejection> {
        let at = |kind, what: String| Rejection::new(kind, format!("record at t = {t} s: {what}"));
        if let Some(last) = self.last_time {
            if t <= last {
                return Err(at(RejectKind::OutOfOrder, format!("not after the previous record ({last} s)")));
            }
            if t - last < 1.0 / self.config.max_rate_hz {
                return Err(at(RejectKind::Flood, format!("{:.2} ms after the previous record (at most {} per second)", (t - last) * 1e3, self.config.max_rate_hz)));
            }
        }
        let Some(arrival) = arrival else { return Ok(self.clock_offset) };
        let offset = arrival - t;
        let Some(fastest) = self.clock_offset else { return Ok(Some(offset)) };
        if offset - fastest > self.config.max_latency_s {
            return Err(at(RejectKind::Late, format!("arrived {:.0} ms late", (offset - fastest) * 1e3)));
        }
        if fastest - offset > MAX_LEAD_S {
            return Err(at(RejectKind::OutOfRange, format!("{:.1} s ahead of the stream's clock (the sender's clock jumped)", fastest - offset)));
        }
        Ok(Some(fastest.min(offset)))
    }

    /// The record's pose into `self.solved` (angles untouched by a tracker-only record).
    fn solve(&mut self, record: &Record) -> Result<(), Rejection> {
        match &record.hand {
            Some(HandData::Joints(set)) => {
                let mut p = [Vec3::ZERO; JOINT_COUNT];
                for (i, q) in p.iter_mut().enumerate() {
                    *q = set.get(i).ok_or_else(|| Rejection::new(RejectKind::Malformed, "joints: not all 25 joints"))?.position;
                }
                self.retargeter.solve(&p, record.side, &mut self.solved)?;
                self.positions = p;
            }
            Some(HandData::Landmarks(landmarks)) => {
                let mut p = [Vec3::ZERO; JOINT_COUNT];
                self.retargeter.landmark_joints(landmarks, &mut p)?;
                self.retargeter.solve(&p, record.side, &mut self.solved)?;
                self.positions = p;
            }
            Some(HandData::Glove(sample)) => {
                let glove = self.glove.as_ref().ok_or_else(|| Rejection::new(RejectKind::Malformed, "glove record, but no glove is configured"))?;
                glove.map(sample, &mut self.solved.angles)?;
            }
            None => {}
        }
        // A wrist tracker drives the wrist of glove and tracker-only records; tracked joints
        // carry their own wrist.
        if let (Some(tracker), None | Some(HandData::Glove(_))) = (record.tracker, &record.hand) {
            self.solved.wrist = Some(self.config.tracker_mount.wrist(tracker));
        }
        Ok(())
    }

    /// Filters `self.solved` into `self.filtered`; `resume` restarts the filters (after a
    /// dropout the old state would drag the hand from where it was).
    fn filter(&mut self, dt: f32, resume: bool) {
        if !self.config.filter {
            self.filtered.clone_from(&self.solved);
            return;
        }
        if resume {
            self.angle_filters.iter_mut().for_each(OneEuro::reset);
            self.position_filter.reset();
            self.rotation_filter.reset();
        }
        for ((out, a), f) in self.filtered.angles.iter_mut().zip(&self.solved.angles).zip(&mut self.angle_filters) {
            *out = f.filter(*a, dt);
        }
        self.filtered.wrist = self.solved.wrist.map(|w| {
            let (rotation, translation) = w.to_rotation_translation();
            DualQuat::from_rotation_translation(self.rotation_filter.filter(rotation, dt), self.position_filter.filter(translation, dt))
        });
    }
}
