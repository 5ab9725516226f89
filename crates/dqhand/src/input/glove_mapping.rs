//! The mapping table of a dataglove: its sensors, and how calibrated sensor readings become
//! joint angles of our joint models. Gloves differ in sensor count and placement, so the
//! table is data (a JSON file a user can edit for another glove), not code.
//!
//! ```json
//! {
//!   "glove": "my-glove",
//!   "notes": "why each gain was chosen",
//!   "sensors": [ { "name": "index_near", "kind": "flexion" }, … ],
//!   "entries": [ { "sensor": "index_near", "dof": "index-finger-phalanx-proximal.flex", "gain_deg": 90, "offset_deg": 0 } ],
//!   "couplings": [ { "dof": "index-finger-phalanx-distal.flex", "from": "index-finger-phalanx-intermediate.flex", "ratio": 0.6667 } ]
//! }
//! ```
//! An entry sets `angle_deg = offset_deg + gain_deg · n`, where `n` is the sensor's calibrated
//! reading ([`Calibration`](super::Calibration)): 0 for the flat open hand and 1 for the fist
//! (flexion sensors), 0 for fingers together and 1 for the spread hand (abduction sensors).
//! A coupling sets `angle(dof) = ratio · angle(from)` for a joint the glove has no sensor
//! for (DIP ≈ ⅔ PIP); couplings apply in file order after the entries, so they may chain.
//! Sensors without an entry are allowed (a CyberGlove's wrist sensors: the 6-DOF tracker
//! gives the wrist). DOF names are those of the `full` joint model; entries and couplings
//! naming a DOF the `paper` model lacks are skipped for that model.
//!
//! Three tables ship with the crate ([`MappingTable::BUILTIN`]), in `data/gloves/`; each
//! explains its choices in its `notes`:
//! * `5dt-14` — 5DT Data Glove 14 Ultra, sensors in 5DT SDK order: two flexion sensors per
//!   finger (near = MCP, far = PIP; thumb: MCP and IP) and four between-finger abduction
//!   sensors; DIP = ⅔ PIP;
//! * `5dt-5` — 5DT Data Glove 5 Ultra, one flexure sensor per finger driving MCP, with PIP
//!   and DIP coupled to it (a chain of couplings);
//! * `cyberglove-18` — CyberGlove II, 18 sensors (MCP and PIP per finger, thumb rotation,
//!   MCP, IP and abduction, three abduction sensors, palm arch, two wrist sensors left
//!   unmapped); DIP = ⅔ PIP.

use std::path::Path;

use serde::Deserialize;

use super::{GloveLayout, MAX_GLOVE_SENSORS};
use crate::kinematics::JointModel;
use crate::{Error, Result};

/// One sensor driving one DOF: `angle_deg = offset_deg + gain_deg · n`.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MappingEntry {
    /// The sensor's name in the table's layout.
    pub sensor: String,
    /// The DOF's name, `"<bone>.<flex|abd>"` ([`JointModel::dof_index`]).
    pub dof: String,
    /// Degrees per unit of calibrated reading (the angle at the fist or spread pose, less
    /// the offset).
    pub gain_deg: f32,
    /// Degrees at the flat hand (reading 0); 0 when absent.
    #[serde(default)]
    pub offset_deg: f32,
}

/// A DOF with no sensor of its own, following another: `angle(dof) = ratio · angle(from)`.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Coupling {
    /// The DOF set.
    pub dof: String,
    /// The DOF it follows (set by an entry or an earlier coupling).
    pub from: String,
    /// The factor.
    pub ratio: f32,
}

/// A glove's sensors and how they drive the joint models; valid by construction.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MappingTable {
    glove: String,
    #[serde(default)]
    notes: String,
    sensors: GloveLayout,
    entries: Vec<MappingEntry>,
    #[serde(default)]
    couplings: Vec<Coupling>,
}

/// Column names of a glove CSV that are not sensors ([`super::GloveCsvReader`]).
pub(super) const RESERVED_COLUMNS: [&str; 9] = ["t", "px", "py", "pz", "qx", "qy", "qz", "qw", "hand"];

impl MappingTable {
    /// The tables shipped with the crate, by name.
    pub const BUILTIN: [&'static str; 3] = ["5dt-14", "5dt-5", "cyberglove-18"];

    /// The shipped table called `name` (one of [`Self::BUILTIN`]).
    ///
    /// # Errors
    /// [`Error::UnknownName`] listing the shipped tables.
    pub fn builtin(name: &str) -> Result<Self> {
        let text = match name {
            "5dt-14" => include_str!("../../data/gloves/5dt-14.json"),
            "5dt-5" => include_str!("../../data/gloves/5dt-5.json"),
            "cyberglove-18" => include_str!("../../data/gloves/cyberglove-18.json"),
            _ => {
                return Err(Error::UnknownName { kind: "glove", name: name.to_owned(), valid: Self::BUILTIN.join(", ") });
            }
        };
        Self::from_json(text)
    }

    /// Reads a table file.
    ///
    /// # Errors
    /// [`Error::Io`], or [`Error::File`] naming the file around what [`Self::from_json`]
    /// returns.
    pub fn load(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path).map_err(Error::io(path))?;
        Self::from_json(&text).map_err(|e| e.in_file(path))
    }

    /// Parses and checks a table.
    ///
    /// # Errors
    /// [`Error::Glove`] for text that is not a table (unknown or missing fields);
    /// [`Error::GloveTable`] naming the table around [`Error::UnknownName`] for an entry's
    /// unknown sensor or DOF (listing the valid names), or around [`Error::Glove`] for no or
    /// too many sensors, a duplicate or unusable sensor name, a non-finite gain, offset or
    /// ratio, a DOF set twice, or a coupling that reads a DOF no entry or earlier coupling
    /// sets.
    pub fn from_json(text: &str) -> Result<Self> {
        let table: Self = serde_json::from_str(text).map_err(|e| Error::Glove(format!("not a valid glove table: {e}")))?;
        table.check().map_err(|problem| Error::GloveTable { table: table.glove.clone(), problem: Box::new(problem) })?;
        Ok(table)
    }

    /// The glove's name (`5dt-14`); calibrations name it too.
    #[must_use]
    pub fn name(&self) -> &str {
        &self.glove
    }

    /// The table's explanation of its choices.
    #[must_use]
    pub fn notes(&self) -> &str {
        &self.notes
    }

    /// The glove's sensors in device order.
    #[must_use]
    pub fn layout(&self) -> &GloveLayout {
        &self.sensors
    }

    /// Sensor-to-DOF entries, in file order.
    #[must_use]
    pub fn entries(&self) -> &[MappingEntry] {
        &self.entries
    }

    /// Couplings, in the order they apply.
    #[must_use]
    pub fn couplings(&self) -> &[Coupling] {
        &self.couplings
    }

    fn check(&self) -> Result<()> {
        let sensors = self.sensors.sensors();
        if sensors.is_empty() || sensors.len() > MAX_GLOVE_SENSORS {
            return Err(Error::Glove(format!("{} sensors; a glove has 1 to {MAX_GLOVE_SENSORS}", sensors.len())));
        }
        for (i, s) in sensors.iter().enumerate() {
            let usable = !s.name.is_empty() && s.name.chars().all(|c| c.is_ascii_alphanumeric() || "_-.".contains(c));
            if !usable || RESERVED_COLUMNS.contains(&s.name.as_str()) {
                return Err(Error::Glove(format!(
                    "sensor name {:?} is not usable as a CSV column (letters, digits, _ - . only; not {})",
                    s.name,
                    RESERVED_COLUMNS.join(", ")
                )));
            }
            if sensors[..i].iter().any(|t| t.name == s.name) {
                return Err(Error::Glove(format!("sensor {:?} is listed twice", s.name)));
            }
        }
        let model = JointModel::Full;
        let mut set = vec![false; model.dof_count()];
        for e in &self.entries {
            if self.sensors.index_of(&e.sensor).is_none() {
                return Err(Error::UnknownName { kind: "sensor", name: e.sensor.clone(), valid: self.sensors.names() });
            }
            let dof = model.dof_index(&e.dof)?;
            if !e.gain_deg.is_finite() || !e.offset_deg.is_finite() {
                return Err(Error::Glove(format!("entry {} → {}: gain {} or offset {} is not finite", e.sensor, e.dof, e.gain_deg, e.offset_deg)));
            }
            if std::mem::replace(&mut set[dof], true) {
                return Err(Error::Glove(format!("{} is set by more than one entry", e.dof)));
            }
        }
        for (i, c) in self.couplings.iter().enumerate() {
            let (dof, from) = (model.dof_index(&c.dof)?, model.dof_index(&c.from)?);
            if !c.ratio.is_finite() {
                return Err(Error::Glove(format!("coupling {} ← {}: ratio {} is not finite", c.dof, c.from, c.ratio)));
            }
            if !set[from] {
                return Err(Error::Glove(format!(
                    "{} is read by coupling {} but no entry or earlier coupling sets it",
                    c.from,
                    i + 1
                )));
            }
            if std::mem::replace(&mut set[dof], true) {
                return Err(Error::Glove(format!("{} is set by an entry or coupling before coupling {}", c.dof, i + 1)));
            }
        }
        Ok(())
    }
}
