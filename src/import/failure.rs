//! What an importer found wrong, before the file's path is known to it: a place in the file (a JSON path, a line, a
//! node) and a message. [`Failure::with_path`] makes it the [`ImportError`] users see.

use std::path::Path;

use super::ImportError;

/// What went wrong, and where in the file.
#[derive(Clone, Debug)]
pub(super) struct Failure {
    pub place: Option<String>,
    pub message: String,
}

impl Failure {
    /// A problem with a named part of the file.
    pub fn at(place: impl Into<String>, message: impl Into<String>) -> Self {
        Failure { place: Some(place.into()), message: message.into() }
    }

    /// A problem with the file as a whole.
    pub fn whole(message: impl Into<String>) -> Self {
        Failure { place: None, message: message.into() }
    }

    /// The error naming `path`.
    pub fn with_path(self, path: &Path) -> ImportError {
        ImportError::new(path, self.place, self.message)
    }
}

pub(super) type Result<T> = std::result::Result<T, Failure>;
