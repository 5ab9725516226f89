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
        /// `lb`, `qb`, `dqb`, `cor`; 1 to 4, no repeats.
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
    /// Learn a new gesture from the live input: record the hand for `seconds` (4 when
    /// absent, 2 to 10), then train it against the recognised gestures and recognise it from
    /// then on; with `not`, what is recorded is a pose that must not trigger `name` (kept
    /// for its learning). The transport owns the job ([`super::Applied::Learn`]).
    Learn {
        /// The new gesture's name: 1 to 32 letters, digits, `_` or `-`.
        name: String,
        /// Seconds to record.
        #[serde(default)]
        seconds: Option<f32>,
        /// Record a counter-example instead.
        #[serde(default)]
        not: bool,
    },
}

/// A checked [`Command::Learn`], for the transport.
#[derive(Clone, Debug, PartialEq)]
pub struct LearnRequest {
    /// The gesture's name.
    pub name: String,
    /// Seconds to record, 2 to 10.
    pub seconds: f32,
    /// A counter-example.
    pub not: bool,
}

impl LearnRequest {
    /// Seconds recorded when the command gives none.
    pub const SECONDS: f32 = 4.0;
    /// Longest name.
    const MAX_NAME: usize = 32;

    /// Checks a learn command's fields.
    ///
    /// # Errors
    /// A name that is empty, too long or not of letters, digits, `_` and `-`; seconds outside 2 to 10.
    pub fn new(name: &str, seconds: Option<f32>, not: bool) -> Result<Self, String> {
        if name.is_empty() || name.len() > Self::MAX_NAME || !name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-') {
            return Err(format!("learn: {name:?} is not a gesture name (1 to {} letters, digits, _ or -)", Self::MAX_NAME));
        }
        let seconds = seconds.unwrap_or(Self::SECONDS);
        if !(2.0..=10.0).contains(&seconds) {
            return Err(format!("learn: {seconds} seconds (2 to 10)"));
        }
        Ok(Self { name: name.to_owned(), seconds, not })
    }
}

/// Largest command a page may send (a server's socket or the page's own engine); larger ones
/// are answered with an error. The hello tells the page.
pub const MAX_COMMAND_BYTES: usize = 4 * 1024;

impl Command {
    /// Parses one message.
    ///
    /// # Errors
    /// A one-line description of what is wrong with the JSON.
    pub fn parse(text: &str) -> Result<Self, String> {
        serde_json::from_str(text).map_err(|e| format!("not a valid command: {e}"))
    }

    /// Parses one message of a page, refusing one longer than [`MAX_COMMAND_BYTES`].
    ///
    /// # Errors
    /// As [`Self::parse`], or the message's length.
    pub fn parse_bounded(text: &str) -> Result<Self, String> {
        if text.len() > MAX_COMMAND_BYTES {
            return Err(format!("message of {} bytes refused (at most {MAX_COMMAND_BYTES})", text.len()));
        }
        Self::parse(text)
    }
}
