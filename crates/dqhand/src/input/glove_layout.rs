//! A dataglove's sensors, in the order the device reports them: the one thing that gives a
//! [`GloveSample`](super::GloveSample)'s values their meaning, shared by the mapping table,
//! the calibration and the CSV files of one glove.

use serde::Deserialize;

use super::{RejectKind, Rejection};

/// Largest raw sensor value: the 12-bit range of 5DT Ultra gloves (0–4095); the CyberGlove's
/// 8-bit values fit inside it. Readers and the mapper refuse values outside `0..=RAW_MAX`.
pub const RAW_MAX: f32 = 4095.0;

/// What a sensor measures, which decides what its calibrated reading means.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum SensorKind {
    /// Bend of a joint: normalised 0 for the flat open hand, 1 for the fist.
    Flexion,
    /// Spread between two fingers (or of the thumb): normalised 0 for fingers together,
    /// 1 for the spread hand.
    Abduction,
}

impl SensorKind {
    /// `"flexion"` or `"abduction"`, as in table files.
    #[must_use]
    pub fn as_str(self) -> &'static str {
        match self {
            SensorKind::Flexion => "flexion",
            SensorKind::Abduction => "abduction",
        }
    }
}

/// One sensor of a glove.
#[derive(Clone, Debug, PartialEq, Eq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Sensor {
    /// Name, as in the glove's SDK and the CSV header (`thumb_near`, `index_pip`).
    pub name: String,
    /// Flexion or abduction.
    pub kind: SensorKind,
}

/// A glove's sensors in the order the device reports them.
///
/// Built only through [`MappingTable`](super::MappingTable), which checks that names are
/// unique, usable as CSV column names, and at most [`MAX_GLOVE_SENSORS`](super::MAX_GLOVE_SENSORS).
#[derive(Clone, Debug, PartialEq, Eq, Deserialize)]
#[serde(transparent)]
pub struct GloveLayout {
    sensors: Vec<Sensor>,
}

impl GloveLayout {
    /// The sensors, in device order.
    #[must_use]
    pub fn sensors(&self) -> &[Sensor] {
        &self.sensors
    }

    /// Number of sensors (the length of every sample of this glove).
    #[must_use]
    pub fn len(&self) -> usize {
        self.sensors.len()
    }

    /// Whether the glove has no sensor (never true of a layout from a valid table).
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.sensors.is_empty()
    }

    /// Position of the sensor called `name` in device order.
    #[must_use]
    pub fn index_of(&self, name: &str) -> Option<usize> {
        self.sensors.iter().position(|s| s.name == name)
    }

    /// The sensor names, comma-separated, for error messages.
    #[must_use]
    pub fn names(&self) -> String {
        self.sensors.iter().map(|s| s.name.as_str()).collect::<Vec<_>>().join(", ")
    }
}

/// Refuses a raw value of sensor `name` that is not finite or outside `0..=RAW_MAX`: the
/// one check every glove source applies, so their messages agree.
pub(super) fn check_raw(name: &str, value: f32) -> Result<(), Rejection> {
    if !value.is_finite() {
        return Err(Rejection::new(RejectKind::NonFinite, format!("sensor {name} = {value} is not finite")));
    }
    if !(0.0..=RAW_MAX).contains(&value) {
        return Err(Rejection::new(RejectKind::OutOfRange, format!("sensor {name} = {value} is outside 0–4095")));
    }
    Ok(())
}
