//! What a page needs to run the engine `dqhand demo` runs: the hands' count and scene, the
//! joint model, the input configuration, the gestures and the glove's table and calibration.
//! The server writes them into `engine.json` ([`EngineSettings::to_json`]); the page builds its
//! WebAssembly engine from them and then follows the records the server relays, so that a
//! glove, a recording played or another device drives the page's engine exactly as it would
//! the server's own.
//!
//! ```json
//! {"hands": 1, "scene": null, "joint_model": "full", "config": {"filter": true, ...},
//!  "gestures": "{\"gestures\": [...]}", "glove": "5dt-14", "calibration": null,
//!  "source": "udp 127.0.0.1:9000", "announce": true}
//! ```
//!
//! `gestures` is a gesture file's text ([`GestureSet::to_json`]), `glove` a built-in table's
//! name or a table file's text, `calibration` as `dqhand calibrate` writes it (null: the
//! table's default); `scene` names a
//! built-in scene (a scene file's meshes are the server's files, which a page cannot read).

use dqhand::gesture::GestureSet;
use dqhand::input::{Calibration, GloveMapper, InputConfig, MappingTable};
use dqhand::kinematics::JointModel;
use serde::{Deserialize, Serialize};

use crate::{Error, Result};

/// The engine's setup, as a page rebuilds it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EngineSettings {
    /// Hands driven: 1, or 2 (a left and a right one, in a scene).
    pub hands: u8,
    /// A built-in scene's name, or none.
    pub scene: Option<String>,
    /// `full` or `paper`: the retargeted poses' and the glove mapping's DOF.
    pub joint_model: String,
    /// The input pipeline's filters and the gestures' commands.
    pub config: InputConfig,
    /// The gestures recognised: a gesture file's text.
    pub gestures: String,
    /// The glove's mapping table: a built-in name or a table file's text.
    pub glove: String,
    /// The glove's calibration; none: the table's default (raw 0 flat, 4095 fist).
    #[serde(default)]
    pub calibration: Option<Calibration>,
    /// The live input, as the server's hello names it (`udp 127.0.0.1:9000`, a recording's path).
    pub source: String,
    /// Whether viewers are told of the input from the start (a recording played, a UDP port)
    /// rather than with its first record.
    pub announce: bool,
}

impl Default for EngineSettings {
    /// One right hand, no scene, the full joint model, the default configuration, the
    /// built-in gestures, and the 5DT 14-sensor glove at its default calibration: `dqhand
    /// demo` with no options.
    fn default() -> Self {
        let glove = MappingTable::BUILTIN[0];
        Self {
            hands: 1,
            scene: None,
            joint_model: JointModel::Full.as_str().to_owned(),
            config: InputConfig::default(),
            gestures: GestureSet::builtin().to_json(),
            glove: glove.to_owned(),
            calibration: None,
            source: "this page (camera or WebXR)".to_owned(),
            announce: false,
        }
    }
}

impl EngineSettings {
    /// Reads settings.
    ///
    /// # Errors
    /// [`Error::Settings`] for text that is not settings, naming the field.
    pub fn from_json(text: &str) -> Result<Self> {
        let settings: Self = serde_json::from_str(text).map_err(|e| Error::Settings(e.to_string()))?;
        if !(1..=2).contains(&settings.hands) {
            return Err(Error::Settings(format!("hands: {} is neither 1 nor 2", settings.hands)));
        }
        settings.joint_model()?;
        Ok(settings)
    }

    /// The settings as one line of JSON.
    #[must_use]
    pub fn to_json(&self) -> String {
        serde_json::to_string(self).expect("settings are plain data")
    }

    /// The joint model named.
    ///
    /// # Errors
    /// [`Error::Settings`] for a name that is not a joint model.
    pub fn joint_model(&self) -> Result<JointModel> {
        self.joint_model.parse().map_err(|e| Error::Settings(format!("joint_model: {e}")))
    }

    /// The glove's table.
    ///
    /// # Errors
    /// The table's, for a name that is not built in and text that is not a table.
    pub fn table(&self) -> Result<MappingTable> {
        let text = self.glove.trim_start();
        Ok(if text.starts_with('{') { MappingTable::from_json(text)? } else { MappingTable::builtin(text)? })
    }

    /// The glove's mapper: its table with its calibration, for the joint model.
    ///
    /// # Errors
    /// The table's, or a calibration of another glove.
    pub fn mapper(&self) -> Result<GloveMapper> {
        let table = self.table()?;
        let calibration = self.calibration.clone().unwrap_or_else(|| Calibration::default_for(&table));
        Ok(GloveMapper::new(&table, &calibration, self.joint_model()?)?)
    }

    /// The glove's sensor names, in the order of its records' values.
    ///
    /// # Errors
    /// The table's.
    pub fn sensors(&self) -> Result<Vec<String>> {
        Ok(self.table()?.layout().sensors().iter().map(|s| s.name.clone()).collect())
    }

    /// The gestures recognised.
    ///
    /// # Errors
    /// The gesture file's.
    pub fn gesture_set(&self) -> Result<GestureSet> {
        Ok(GestureSet::from_json(&self.gestures, "settings' gestures")?)
    }
}
