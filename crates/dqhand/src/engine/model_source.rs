//! Where a model comes from: the built-in hand, or a glTF file.

use std::path::PathBuf;

use crate::hand::{build, HandParams};
use crate::io::load_gltf;
use crate::model::Model;
use crate::Result;

/// A model to load, as written on a command line: `builtin` or a `.glb`/`.gltf` path.
#[derive(Clone, Debug, PartialEq)]
pub enum ModelSource {
    /// The built-in anatomical hand at these parameters.
    Builtin(HandParams),
    /// A skinned glTF 2.0 file.
    File(PathBuf),
}

impl ModelSource {
    /// Builds or reads the model.
    ///
    /// # Errors
    /// As [`build`] or [`load_gltf`].
    pub fn load(&self) -> Result<Model> {
        match self {
            ModelSource::Builtin(params) => build(params),
            ModelSource::File(path) => load_gltf(path),
        }
    }

    /// The source of a left hand: the built-in hand built as a left one; a file as it is
    /// (it must hold a left hand: a loop of two hands refuses two of one side).
    #[must_use]
    pub fn left(&self) -> ModelSource {
        match self {
            ModelSource::Builtin(params) => ModelSource::Builtin(HandParams { side: crate::hand::Side::Left, ..*params }),
            file => file.clone(),
        }
    }
}

impl core::str::FromStr for ModelSource {
    type Err = std::convert::Infallible;
    /// `builtin` is the built-in hand at its defaults; anything else is a file path.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Ok(if s == "builtin" { ModelSource::Builtin(HandParams::default()) } else { ModelSource::File(s.into()) })
    }
}

impl core::fmt::Display for ModelSource {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            ModelSource::Builtin(p) if *p == HandParams::default() => f.write_str("builtin"),
            ModelSource::Builtin(p) => write!(f, "builtin ({} hand, {} m by {} m, {} vertices)", p.side.name(), p.length, p.breadth, p.vertices),
            ModelSource::File(path) => write!(f, "{}", path.display()),
        }
    }
}
