//! Typed errors of the library: each names the bad input and what is wrong with it.

use std::path::PathBuf;

/// What went wrong, with the input (file, joint, vertex) it concerns.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A file could not be read or written.
    #[error("{}: {reason}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The operating system's reason (part of the message, so not also a `source`).
        reason: std::io::Error,
    },
    /// A file was read but its content is malformed or unsupported.
    #[error("{}: {message}", path.display())]
    File {
        /// The file.
        path: PathBuf,
        /// What is wrong in it, lowercase, quoting the bad value.
        message: String,
    },
    /// A skeleton, mesh or pose is inconsistent (no file involved).
    #[error("{0}")]
    Invalid(String),
    /// A name (joint, DOF, node) is not known; lists the valid ones.
    #[error("unknown {kind} {name:?}; valid: {valid}")]
    UnknownName {
        /// What kind of name: "joint", "degree of freedom", "node".
        kind: &'static str,
        /// The name given.
        name: String,
        /// The valid names, comma-separated.
        valid: String,
    },
}

impl Error {
    /// A function that wraps an I/O error on `path` (for `map_err`).
    pub fn io(path: &std::path::Path) -> impl Fn(std::io::Error) -> Self + '_ {
        move |reason| Error::Io { path: path.into(), reason }
    }

    /// Attaches a file path to an `Invalid` error so that the message names the input.
    #[must_use]
    pub fn in_file(self, path: impl Into<PathBuf>) -> Self {
        match self {
            Error::Invalid(_) | Error::UnknownName { .. } => Error::File { path: path.into(), message: self.to_string() },
            other => other,
        }
    }
}

/// The library's result type.
pub type Result<T, E = Error> = std::result::Result<T, E>;
