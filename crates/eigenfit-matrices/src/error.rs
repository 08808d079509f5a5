//! Errors of the matrices plugin: each names the file, and the entry or table, at fault.

use std::path::{Path, PathBuf};
use thiserror::Error;

/// Why a matrices model could not be read or used.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum MatricesError {
    /// A file could not be read.
    #[error("{}: {source}", path.display())]
    Io { path: PathBuf, source: std::io::Error },
    /// A file is not a regular file, is too large, or cannot be read (the message names it).
    #[error("{detail}")]
    Unreadable { detail: String },
    /// The model TOML is malformed (syntax, unknown key, wrong type).
    #[error("{}: {detail}", path.display())]
    Toml { path: PathBuf, detail: String },
    /// A Matrix Market file is malformed or its matrix unusable.
    #[error("{}: {detail}", path.display())]
    Matrix { path: PathBuf, detail: String },
    /// A table of the model file is inconsistent (bounds, names, sizes).
    #[error("{}: {detail}", path.display())]
    Invalid { path: PathBuf, detail: String },
}

impl MatricesError {
    pub(crate) fn invalid(path: &Path, detail: impl Into<String>) -> Self {
        Self::Invalid { path: path.to_path_buf(), detail: detail.into() }
    }
}
