//! Glove samples to joint angles: a [`MappingTable`] and a [`Calibration`] resolved once
//! against a joint model, then applied per record without allocating (the gesture loop's
//! per-record path).

use super::glove_layout::check_raw;
use super::{Calibration, GloveSample, MappingTable, RejectKind, Rejection};
use crate::kinematics::JointModel;
use crate::Result;

/// A sensor's calibration, ready to normalise: reading = (raw − flat) · inv_span.
#[derive(Clone, Debug)]
struct SensorScale {
    name: String,
    flat: f32,
    inv_span: f32,
}

/// An entry with indices and radians.
#[derive(Clone, Copy, Debug)]
struct Entry {
    sensor: usize,
    dof: usize,
    gain_rad: f32,
    offset_rad: f32,
}

/// A coupling with indices.
#[derive(Clone, Copy, Debug)]
struct Coupling {
    dof: usize,
    from: usize,
    ratio: f32,
}

/// Maps samples of one glove, calibrated, to angles of one joint model.
#[derive(Clone, Debug)]
pub struct GloveMapper {
    glove: String,
    model: JointModel,
    dof_count: usize,
    sensors: Vec<SensorScale>,
    entries: Vec<Entry>,
    couplings: Vec<Coupling>,
}

impl GloveMapper {
    /// Resolves `table` and `calibration` against `model`. Entries and couplings naming a
    /// DOF that `model` lacks (the `paper` model's missing thumb CMC) are skipped.
    ///
    /// # Errors
    /// [`crate::Error::Calibration`] when `calibration` does not fit `table` (another glove,
    /// missing sensors, degenerate extremes).
    pub fn new(table: &MappingTable, calibration: &Calibration, model: JointModel) -> Result<Self> {
        let extremes = calibration.extremes(table)?;
        let sensors = table
            .layout()
            .sensors()
            .iter()
            .zip(extremes)
            .map(|(s, (flat, high))| SensorScale { name: s.name.clone(), flat, inv_span: 1.0 / (high - flat) })
            .collect();
        let layout = table.layout();
        let entries = table
            .entries()
            .iter()
            .filter_map(|e| {
                Some(Entry {
                    sensor: layout.index_of(&e.sensor)?,
                    dof: model.dof_index(&e.dof).ok()?,
                    gain_rad: e.gain_deg.to_radians(),
                    offset_rad: e.offset_deg.to_radians(),
                })
            })
            .collect();
        let couplings = table
            .couplings()
            .iter()
            .filter_map(|c| Some(Coupling { dof: model.dof_index(&c.dof).ok()?, from: model.dof_index(&c.from).ok()?, ratio: c.ratio }))
            .collect();
        Ok(Self { glove: table.name().to_owned(), model, dof_count: model.dof_count(), sensors, entries, couplings })
    }

    /// The joint model the angles are for.
    #[must_use]
    pub fn joint_model(&self) -> JointModel {
        self.model
    }

    /// Writes the angles (radians, [`JointModel::dofs`] order) of `sample` into
    /// `angles_rad`: entries first, then couplings in table order; DOFs with neither are 0.
    /// Normalised readings may go a little past 0–1 and angles are not clamped (the
    /// engine clamps to joint limits). Allocates nothing unless it rejects.
    ///
    /// # Errors
    /// A [`Rejection`] naming the sensor: [`RejectKind::NonFinite`] or
    /// [`RejectKind::OutOfRange`] (outside 0–4095); [`RejectKind::Malformed`] for a sample
    /// with another number of values than the glove has sensors. `angles_rad` is then
    /// unchanged.
    ///
    /// # Panics
    /// If `angles_rad` is not as long as the joint model has DOFs.
    pub fn map(&self, sample: &GloveSample, angles_rad: &mut [f32]) -> Result<(), Rejection> {
        assert_eq!(angles_rad.len(), self.dof_count, "angles_rad: one angle per DOF of the {} model", self.model);
        let values = sample.values();
        if values.len() != self.sensors.len() {
            return Err(Rejection::new(
                RejectKind::Malformed,
                format!("{} sensor values; glove {} has {} sensors", values.len(), self.glove, self.sensors.len()),
            ));
        }
        for (s, &v) in self.sensors.iter().zip(values) {
            check_raw(&s.name, v)?;
        }
        angles_rad.fill(0.0);
        for e in &self.entries {
            let s = &self.sensors[e.sensor];
            let reading = (values[e.sensor] - s.flat) * s.inv_span;
            angles_rad[e.dof] = e.offset_rad + e.gain_rad * reading;
        }
        for c in &self.couplings {
            angles_rad[c.dof] = c.ratio * angles_rad[c.from];
        }
        Ok(())
    }
}
