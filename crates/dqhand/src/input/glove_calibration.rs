//! Glove calibration: each sensor's raw values at the calibration poses, which turn raw
//! values into the normalised readings a [`MappingTable`] maps (0 = flat open hand, 1 = fist
//! for flexion sensors; 0 = fingers together, 1 = spread hand for abduction sensors). Sensor
//! gain and offset differ between gloves and between wearers, so every session needs one.
//!
//! Saved as JSON, one object per sensor of the table, keyed by sensor name; raw units:
//! ```json
//! {
//!   "glove": "5dt-14",
//!   "sensors": {
//!     "thumb_near":  { "flat": 812,  "fist": 3100 },
//!     "thumb_index": { "flat": 1500, "spread": 3000 }
//!   }
//! }
//! ```
//! A flexion sensor needs `flat` and `fist`, an abduction sensor `flat` and `spread`; either
//! may run downward (`fist` < `flat`) for a sensor wired that way. The extra value is
//! refused, so a mistyped kind shows up.

use std::collections::BTreeMap;
use std::path::Path;

use serde::{Deserialize, Serialize};

use super::glove_layout::RAW_MAX;
use super::{GloveSample, MappingTable, SensorKind};
use crate::math::quantile;
use crate::{Error, Result};

/// Least spread of a sensor's values (raw units, 5th to 95th percentile) over a calibration
/// recording for [`Calibration::derive`] to trust it: 5 % of the 12-bit range, well above
/// the noise of a held pose.
pub const MIN_MOVEMENT: f32 = 200.0;

/// Fewest frames of each held pose (flat, fist) [`Calibration::derive`] needs.
pub const MIN_HOLD_FRAMES: usize = 5;

/// Least difference between a sensor's two extremes: closer ones would amplify noise into
/// wild angles.
const MIN_SPAN: f32 = 1.0;

/// A flexion reading (0–1 between the recording's 5th and 95th percentiles) at most this is
/// "near the low extreme", at least `1 −` this "near the high extreme".
const NEAR_EXTREME: f32 = 0.25;

/// One sensor's raw values at the calibration poses.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SensorCalibration {
    /// Raw value with the hand flat and open, fingers together (reading 0).
    pub flat: f32,
    /// Raw value in a fist (reading 1 of a flexion sensor).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fist: Option<f32>,
    /// Raw value with the fingers spread (reading 1 of an abduction sensor).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub spread: Option<f32>,
}

/// The calibration of one glove: per sensor, the raw values of the calibration poses.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Calibration {
    /// The table's name ([`MappingTable::name`]) this calibration is for.
    pub glove: String,
    /// Per sensor name, its calibration.
    pub sensors: BTreeMap<String, SensorCalibration>,
}

impl Calibration {
    /// The calibration of an uncalibrated glove: raw 0 is the flat hand, 4095 the fist or
    /// the spread hand. Good enough to see a glove move before calibrating it.
    #[must_use]
    pub fn default_for(table: &MappingTable) -> Self {
        let sensors = table.layout().sensors().iter().map(|s| (s.name.clone(), calibration_between(s.kind, 0.0, RAW_MAX)));
        Self { glove: table.name().to_owned(), sensors: sensors.collect() }
    }

    /// Reads a calibration file.
    ///
    /// # Errors
    /// [`Error::Io`], or [`Error::File`] naming the file around an [`Error::Calibration`].
    pub fn load(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path).map_err(Error::io(path))?;
        Self::from_json(&text).map_err(|e| e.in_file(path))
    }

    /// Writes the calibration file.
    ///
    /// # Errors
    /// [`Error::Io`].
    pub fn save(&self, path: &Path) -> Result<()> {
        std::fs::write(path, self.to_json()).map_err(Error::io(path))
    }

    /// Parses a calibration (checked against its table when a [`GloveMapper`](super::GloveMapper)
    /// uses it).
    ///
    /// # Errors
    /// [`Error::Calibration`] for text that is not a calibration.
    pub fn from_json(text: &str) -> Result<Self> {
        serde_json::from_str(text).map_err(|e| Error::Calibration(format!("not a valid glove calibration: {e}")))
    }

    /// The calibration as pretty JSON (the format of [`Self::load`]; values round-trip exactly).
    #[must_use]
    pub fn to_json(&self) -> String {
        let mut text = serde_json::to_string_pretty(self).expect("a calibration is plain data");
        text.push('\n');
        text
    }

    /// Derives a calibration from a recording of the calibration poses, held in any order
    /// with movement between them: flat open hand (fingers together), fist, and, for gloves
    /// with abduction sensors, flat hand with the fingers spread.
    ///
    /// Robust to noise, transitions and hold lengths: per flexion sensor, readings are
    /// placed between the recording's 5th (0) and 95th (1) percentiles; flat frames are
    /// those in which every flexion sensor reads ≤ 0.25, fist frames those in which every
    /// one reads ≥ 0.75; `flat` and `fist` are the medians over them. An abduction sensor's
    /// values over the flat frames (fingers straight: the flat and spread holds) are split
    /// at the middle of their 5th–95th percentile range; `flat` is the median of the lower
    /// group, `spread` of the upper. So raw values must grow with flexion and spread, as
    /// the 5DT and CyberGlove sensors' do and the default calibration assumes; calibrate a
    /// glove wired the other way by hand. Frames with a non-finite or out-of-range value
    /// are ignored.
    ///
    /// # Errors
    /// [`Error::Calibration`] for a sample with another number of values than the table
    /// has sensors, sensors whose 5th–95th percentile range is under [`MIN_MOVEMENT`]
    /// (naming them), or fewer than [`MIN_HOLD_FRAMES`] flat or fist frames.
    pub fn derive(table: &MappingTable, samples: &[GloveSample]) -> Result<Self> {
        let layout = table.layout();
        if let Some((i, s)) = samples.iter().enumerate().find(|(_, s)| s.values().len() != layout.len()) {
            return Err(Error::Calibration(format!(
                "calibration sample {i}: {} values; glove {} has {} sensors",
                s.values().len(),
                table.name(),
                layout.len()
            )));
        }
        let frames: Vec<&[f32]> =
            samples.iter().map(GloveSample::values).filter(|v| v.iter().all(|x| (0.0..=RAW_MAX).contains(x))).collect();
        if frames.len() < 2 * MIN_HOLD_FRAMES {
            return Err(Error::Calibration(format!(
                "calibration recording: {} usable frames; hold each calibration pose for at least {MIN_HOLD_FRAMES}",
                frames.len()
            )));
        }
        let column = |sensor: usize, frames: &[&[f32]]| frames.iter().map(|f| f[sensor]).collect::<Vec<f32>>();
        let flexion: Vec<usize> = (0..layout.len()).filter(|&i| layout.sensors()[i].kind == SensorKind::Flexion).collect();

        // Each flexion sensor's 5th and 95th percentiles: its open and closed ends.
        let mut still = Vec::new();
        let bands: Vec<(f32, f32)> = flexion
            .iter()
            .map(|&i| {
                let mut v = column(i, &frames);
                let band = (percentile(&mut v, 0.05), percentile(&mut v, 0.95));
                if band.1 - band.0 < MIN_MOVEMENT {
                    still.push(layout.sensors()[i].name.as_str());
                }
                band
            })
            .collect();
        refuse_still(&still)?;
        let reading = |f: &[f32], k: usize| (f[flexion[k]] - bands[k].0) / (bands[k].1 - bands[k].0);
        let flat: Vec<&[f32]> = frames.iter().copied().filter(|f| (0..flexion.len()).all(|k| reading(f, k) <= NEAR_EXTREME)).collect();
        let fist: Vec<&[f32]> = frames.iter().copied().filter(|f| (0..flexion.len()).all(|k| reading(f, k) >= 1.0 - NEAR_EXTREME)).collect();
        for (pose, held) in [("flat hand", &flat), ("fist", &fist)] {
            if held.len() < MIN_HOLD_FRAMES {
                return Err(Error::Calibration(format!(
                    "calibration recording: {} frames of a {pose} (every flexion sensor near its extreme); hold it for at least {MIN_HOLD_FRAMES}",
                    held.len()
                )));
            }
        }

        let mut sensors = BTreeMap::new();
        for (i, sensor) in layout.sensors().iter().enumerate() {
            let mut at_flat = column(i, &flat);
            let calibration = match sensor.kind {
                SensorKind::Flexion => calibration_between(sensor.kind, median(&mut at_flat), median(&mut column(i, &fist))),
                SensorKind::Abduction => {
                    let (low, high) = (percentile(&mut at_flat, 0.05), percentile(&mut at_flat, 0.95));
                    if high - low < MIN_MOVEMENT {
                        still.push(sensor.name.as_str());
                        continue;
                    }
                    let middle = 0.5 * (low + high);
                    // Both groups hold a percentile, so neither is empty.
                    let (mut together, mut spread): (Vec<f32>, Vec<f32>) = at_flat.iter().partition(|&&v| v <= middle);
                    calibration_between(sensor.kind, median(&mut together), median(&mut spread))
                }
            };
            sensors.insert(sensor.name.clone(), calibration);
        }
        refuse_still(&still)?;
        Ok(Self { glove: table.name().to_owned(), sensors })
    }

    /// Per sensor of `table`, in layout order, the raw values of readings 0 and 1.
    ///
    /// # Errors
    /// [`Error::Calibration`] for a calibration of another glove, a sensor missing or
    /// unknown to the table, a missing or extra extreme for the sensor's kind, a value
    /// outside 0–4095 or not finite, or extremes less than one raw unit apart.
    pub(super) fn extremes(&self, table: &MappingTable) -> Result<Vec<(f32, f32)>> {
        if self.glove != table.name() {
            return Err(Error::Calibration(format!("calibration of glove {:?} used with glove table {:?}", self.glove, table.name())));
        }
        if let Some(name) = self.sensors.keys().find(|n| table.layout().index_of(n).is_none()) {
            return Err(Error::Calibration(format!("calibration sensor {name:?}: glove {} has no such sensor; valid: {}", table.name(), table.layout().names())));
        }
        table
            .layout()
            .sensors()
            .iter()
            .map(|s| {
                let c = self.sensors.get(&s.name).ok_or_else(|| Error::Calibration(format!("sensor {}: not in the calibration", s.name)))?;
                let (high, pose, extra, other) = match s.kind {
                    SensorKind::Flexion => (c.fist, "fist", c.spread, "spread"),
                    SensorKind::Abduction => (c.spread, "spread", c.fist, "fist"),
                };
                let high = high.ok_or_else(|| Error::Calibration(format!("sensor {} ({}): no {pose} value", s.name, s.kind.as_str())))?;
                if extra.is_some() {
                    return Err(Error::Calibration(format!("sensor {} ({}): has a {other} value; it takes flat and {pose}", s.name, s.kind.as_str())));
                }
                let usable = |v: f32| v.is_finite() && (0.0..=RAW_MAX).contains(&v);
                if !usable(c.flat) || !usable(high) || (high - c.flat).abs() < MIN_SPAN {
                    return Err(Error::Calibration(format!(
                        "sensor {}: flat {} and {pose} {high} must be distinct raw values in 0–4095",
                        s.name, c.flat
                    )));
                }
                Ok((c.flat, high))
            })
            .collect()
    }
}

/// A sensor calibration with readings 0 at `flat` and 1 at `high` (the fist or the spread
/// hand, by kind).
fn calibration_between(kind: SensorKind, flat: f32, high: f32) -> SensorCalibration {
    match kind {
        SensorKind::Flexion => SensorCalibration { flat, fist: Some(high), spread: None },
        SensorKind::Abduction => SensorCalibration { flat, fist: None, spread: Some(high) },
    }
}

fn refuse_still(still: &[&str]) -> Result<()> {
    if still.is_empty() {
        return Ok(());
    }
    Err(Error::Calibration(format!(
        "calibration recording: sensors {} moved less than {MIN_MOVEMENT} raw units; hold the flat hand, the fist and the spread hand in turn",
        still.join(", ")
    )))
}

/// The `p` quantile (0–1) of `values` ([`quantile`]); sorts `values`. `values` is not empty.
fn percentile(values: &mut [f32], p: f32) -> f32 {
    quantile(values, f64::from(p)).expect("not empty")
}

fn median(values: &mut [f32]) -> f32 {
    percentile(values, 0.5)
}
