//! What a held gesture does in the viewer: the input configuration's `actions`, resolved.

use dqhand::input::GestureAction;
use dqhand::interaction::CommandRow;

use crate::{Error, Result};

/// A viewer action a gesture can trigger.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Action {
    /// Show the next skinning method alone.
    NextMethod,
    /// Show all four methods side by side.
    SplitView,
    /// Toggle the distortion heat map.
    ToggleHeatmap,
}

impl core::str::FromStr for Action {
    type Err = Error;
    /// `next_method`, `split_view` or `toggle_heatmap`.
    fn from_str(s: &str) -> Result<Self> {
        match s {
            "next_method" => Ok(Self::NextMethod),
            "split_view" => Ok(Self::SplitView),
            "toggle_heatmap" => Ok(Self::ToggleHeatmap),
            _ => Err(Error::UnknownAction(s.to_owned())),
        }
    }
}

/// One row of the input configuration's `actions` with its action resolved.
#[derive(Clone, Debug, PartialEq)]
pub struct ViewerAction {
    /// The gesture held.
    pub gesture: String,
    /// Seconds it must be held.
    pub hold_s: f32,
    /// What it does.
    pub action: Action,
}

impl ViewerAction {
    /// Resolves each row's action name.
    ///
    /// # Errors
    /// [`Error::UnknownAction`] for a name that is no viewer action.
    pub fn resolve(rows: &[GestureAction]) -> Result<Vec<Self>> {
        rows.iter().map(|r| Ok(Self { gesture: r.gesture.clone(), hold_s: r.hold_s, action: r.action.parse()? })).collect()
    }
}

impl CommandRow for ViewerAction {
    type Command = Action;
    fn gesture(&self) -> &str {
        &self.gesture
    }
    fn hold_s(&self) -> f32 {
        self.hold_s
    }
    fn command(&self) -> Action {
        self.action
    }
}
