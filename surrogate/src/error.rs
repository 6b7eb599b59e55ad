//! The one error type of the crate: every variant names the file or field at fault.

use std::path::PathBuf;

/// What went wrong, with the file or field it concerns.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A file could not be opened, read, written or renamed.
    #[error("{path}: {source}")]
    Io {
        /// The file concerned.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
    /// A file exists but its contents are not what this crate expects.
    #[error("{path}: {message}")]
    Format {
        /// The file concerned.
        path: PathBuf,
        /// What is wrong with it, naming the array or field.
        message: String,
    },
    /// An in-memory value (a dataset field, an option, an input) is invalid.
    #[error("{field}: {message}")]
    Invalid {
        /// The field or argument concerned, e.g. `Y` or `TrainOptions.epochs`.
        field: String,
        /// What is wrong with it.
        message: String,
    },
    /// A numerical step failed (e.g. a kernel matrix that is not positive definite).
    #[error("numerical failure in {context}: {message}")]
    Numerical {
        /// Where it happened.
        context: String,
        /// What happened.
        message: String,
    },
}

/// Result type of the crate.
pub type Result<T> = std::result::Result<T, Error>;

impl Error {
    pub(crate) fn io(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        Error::Io {
            path: path.into(),
            source,
        }
    }
    pub(crate) fn format(path: impl Into<PathBuf>, message: impl Into<String>) -> Self {
        Error::Format {
            path: path.into(),
            message: message.into(),
        }
    }
    pub(crate) fn invalid(field: impl Into<String>, message: impl Into<String>) -> Self {
        Error::Invalid {
            field: field.into(),
            message: message.into(),
        }
    }
    pub(crate) fn numerical(context: impl Into<String>, message: impl Into<String>) -> Self {
        Error::Numerical {
            context: context.into(),
            message: message.into(),
        }
    }
}
