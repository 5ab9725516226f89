//! What the page sends back: user edits as small JSON messages, one per change.

use serde::Deserialize;

/// One message from a viewer, tagged by `"type"`.
///
/// ```json
/// {"type": "angle", "dof": "index-finger-phalanx-intermediate.flex", "deg": 90}
/// ```
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum Command {
    /// The page has taken frame `seq` (flow control: the server keeps few frames in flight).
    Ack {
        /// The frame's sequence number.
        seq: u32,
    },
    /// Which methods to show: one (single view) or several side by side (split view).
    View {
        /// `lb`, `qb`, `dqb`; 1 to 3, no repeats.
        methods: Vec<String>,
    },
    /// Switch the joint model (`paper` or `full`); the server answers with a new hello.
    JointModel {
        /// The model's name.
        name: String,
    },
    /// Set one DOF (stops the timeline).
    Angle {
        /// `"<bone>.<flex|abd>"`.
        dof: String,
        /// Degrees; clamped to the joint's range while limits are on.
        deg: f32,
    },
    /// Set the wrist pose (stops the timeline).
    Wrist {
        /// Metres.
        translation: [f32; 3],
        /// Rotation as X, Y, Z Euler angles in degrees (applied X first).
        rotation_deg: [f32; 3],
    },
    /// Move smoothly to a library gesture (stops the timeline).
    Gesture {
        /// The gesture's name.
        name: String,
        /// Length of the move; 0.6 s when absent.
        #[serde(default)]
        seconds: Option<f32>,
    },
    /// Play the timeline from its current time. (The commands without fields are empty
    /// structs, not unit variants: serde lets a unit variant of a tagged enum carry unknown
    /// fields unrefused.)
    Play {},
    /// Stop the timeline where it is.
    Pause {},
    /// Jump the timeline to a time (seconds) and show that pose.
    Seek {
        /// Seconds from the start.
        time: f32,
    },
    /// Send per-vertex distortion for the heat map, or stop sending it.
    Heatmap {
        /// On or off.
        on: bool,
    },
    /// Clamp angles to the anatomical ranges (on, the default) or allow ±180°.
    Limits {
        /// On or off.
        on: bool,
    },
    /// Every angle to zero and the wrist to rest (stops the timeline).
    Rest {},
    /// Start or stop recording the live input (the records every source sends, as the
    /// recording files `dqhand replay` plays) to a new file the server names. The session
    /// itself is unchanged: the transport owns the recording ([`super::Applied::Record`]).
    Record {
        /// Start (a new file) or stop.
        on: bool,
    },
}

impl Command {
    /// Parses one message.
    ///
    /// # Errors
    /// A one-line description of what is wrong with the JSON.
    pub fn parse(text: &str) -> Result<Self, String> {
        serde_json::from_str(text).map_err(|e| format!("not a valid command: {e}"))
    }
}
