//! The input configuration: filters, dropout handling, the tracker's mounting offset and the
//! table of gesture commands, one JSON file (`--config`), every field optional.
//!
//! ```json
//! {
//!   "angle_filter": {"min_cutoff": 1.5, "beta": 1.0, "d_cutoff": 1.0},
//!   "grace_s": 0.25,
//!   "actions": [{"gesture": "thumbs_up", "hold_s": 0.5, "action": "next_method"}]
//! }
//! ```

use std::path::Path;

use serde::{Deserialize, Serialize};

use super::{MountingOffset, OneEuroParams};
use crate::{Error, Result};

/// Settings of the input pipeline and of the gesture commands.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct InputConfig {
    /// Whether records are filtered at all (off: raw retargeted poses).
    pub filter: bool,
    /// One Euro filter on each joint angle (radians).
    pub angle_filter: OneEuroParams,
    /// One Euro filter on the wrist position (metres).
    pub position_filter: OneEuroParams,
    /// One Euro filter on the wrist orientation (on the sphere, radians).
    pub rotation_filter: OneEuroParams,
    /// Seconds without a good record before the hand is marked "tracking lost" (it holds its
    /// last good pose meanwhile); a slow stream (records more than `grace_s` / 2.5 apart) earns
    /// a longer grace, 2.5 of its intervals up to 2 s ([`super::InputPipeline::grace`]).
    pub grace_s: f64,
    /// Seconds over which the hand blends from the held pose back to the tracked one (and,
    /// lost, to rest).
    pub recover_s: f32,
    /// Seconds a lost hand holds its last pose before its fingers relax to rest (over
    /// `recover_s`, the wrist staying where it was lost): a hand gone from view for good is
    /// not left frozen mid-gesture, and a short dropout is not seen.
    pub rest_after_s: f64,
    /// A live record arriving more than this after its capture time (relative to the
    /// stream's fastest delivery) is late and refused, seconds.
    pub max_latency_s: f64,
    /// Records closer together than 1 / this are a flood and refused, per second.
    pub max_rate_hz: f64,
    /// The wrist tracker's mounting offset.
    pub tracker_mount: MountingOffset,
    /// Gestures as commands: which held gesture triggers which of the application's actions.
    pub actions: Vec<GestureAction>,
}

/// One row of the command table: holding `gesture` for `hold_s` triggers `action` once.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GestureAction {
    /// The gesture's name (as in the gesture definitions).
    pub gesture: String,
    /// How long the gesture must be held, seconds from its start event.
    #[serde(default)]
    pub hold_s: f32,
    /// The action, named as the application that carries it out defines it (the dqhand
    /// viewer's: `next_method`, `split_view`, `toggle_heatmap`).
    pub action: String,
}

impl Default for InputConfig {
    fn default() -> Self {
        Self {
            filter: true,
            angle_filter: OneEuroParams::ANGLE,
            position_filter: OneEuroParams::POSITION,
            rotation_filter: OneEuroParams::ROTATION,
            grace_s: 0.25,
            recover_s: 0.3,
            rest_after_s: 1.0,
            max_latency_s: 0.25,
            max_rate_hz: 1_000.0,
            tracker_mount: MountingOffset::default(),
            actions: vec![
                GestureAction { gesture: "thumbs_up".into(), hold_s: 0.5, action: "next_method".into() },
                GestureAction { gesture: "victory".into(), hold_s: 0.5, action: "split_view".into() },
                GestureAction { gesture: "rock".into(), hold_s: 0.8, action: "toggle_heatmap".into() },
            ],
        }
    }
}

impl InputConfig {
    /// Reads and checks a configuration file.
    ///
    /// # Errors
    /// [`Error::Io`], or [`Error::File`] around [`Error::Config`] for JSON errors and values
    /// out of range.
    pub fn load(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path).map_err(Error::io(path))?;
        Self::from_json(&text).map_err(|e| e.in_file(path))
    }

    /// Parses and checks a configuration.
    ///
    /// ```
    /// use dqhand::input::InputConfig;
    ///
    /// let config = InputConfig::from_json(r#"{"grace_s": 0.5, "filter": false}"#)?;
    /// assert_eq!((config.grace_s, config.filter), (0.5, false));
    /// assert_eq!(config.actions, InputConfig::default().actions, "fields left out keep their defaults");
    /// let err = InputConfig::from_json(r#"{"grace_s": -1}"#).unwrap_err();
    /// assert!(matches!(err, dqhand::Error::Config(_)));
    /// assert_eq!(err.to_string(), "input configuration: grace_s: must be a positive number of seconds");
    /// let err = InputConfig::from_json(r#"{"grace": 1}"#).unwrap_err().to_string();
    /// assert!(err.contains("unknown field `grace`"), "{err}");
    /// # Ok::<(), dqhand::Error>(())
    /// ```
    ///
    /// # Errors
    /// [`Error::Config`] naming the bad field.
    pub fn from_json(text: &str) -> Result<Self> {
        let config: Self = serde_json::from_str(text).map_err(|e| Error::Config(e.to_string()))?;
        config.check()?;
        Ok(config)
    }

    fn check(&self) -> Result<()> {
        let bad = |what: &str| Err(Error::Config(what.to_owned()));
        for (name, p) in [("angle_filter", &self.angle_filter), ("position_filter", &self.position_filter), ("rotation_filter", &self.rotation_filter)] {
            if !p.is_valid() {
                return bad(&format!("{name}: cutoffs must be positive and beta not negative"));
            }
        }
        if !(self.grace_s.is_finite() && self.grace_s > 0.0) {
            return bad("grace_s: must be a positive number of seconds");
        }
        if !(self.recover_s.is_finite() && self.recover_s >= 0.0) {
            return bad("recover_s: must be a number of seconds, 0 or more");
        }
        if !(self.rest_after_s.is_finite() && self.rest_after_s >= 0.0) {
            return bad("rest_after_s: must be a number of seconds, 0 or more");
        }
        if !(self.max_latency_s.is_finite() && self.max_latency_s > 0.0) {
            return bad("max_latency_s: must be a positive number of seconds");
        }
        if !(self.max_rate_hz.is_finite() && self.max_rate_hz > 0.0) {
            return bad("max_rate_hz: must be a positive rate");
        }
        if !self.tracker_mount.is_valid() {
            return bad("tracker_mount: p must be finite and q a unit quaternion");
        }
        if let Some(a) = self.actions.iter().find(|a| !(a.hold_s.is_finite() && a.hold_s >= 0.0)) {
            return bad(&format!("actions: {}: hold_s must be 0 or more seconds", a.gesture));
        }
        Ok(())
    }
}
