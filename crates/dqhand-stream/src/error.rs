//! The stream's errors: a viewer's bad command or message, or the engine's own.

/// What went wrong in the viewer stream; each message starts with the bad input.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A viewer command has a value out of range.
    #[error("{0}")]
    Command(String),
    /// A message of the viewer stream's binary format is malformed.
    #[error("stream message: {0}")]
    Frame(String),
    /// A page's engine settings (`engine.json`) are not settings.
    #[error("engine settings: {0}")]
    Settings(String),
    /// A gesture action names no action of the viewer.
    #[error("actions: {0:?} is not a viewer action (next_method, split_view, toggle_heatmap)")]
    UnknownAction(String),
    /// The engine refused (a model without the hand's joints, an unknown name).
    #[error(transparent)]
    Engine(#[from] dqhand::Error),
}

/// A result of the stream.
pub type Result<T, E = Error> = std::result::Result<T, E>;
