//! Turning files into a [`Rig`]: one module per format and one [`load`] entry that picks the format by content.

mod demo;
mod gltf;

pub use demo::{demo_rig, stress_rig};

use std::fmt;
use std::path::{Path, PathBuf};

use crate::model::Rig;

/// A file that could not be loaded: which file, where in it, and what is wrong.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub struct ImportError {
    pub path: PathBuf,
    /// Where in the file, in the format's own terms (`animations[0].samplers[2]`, `line 12`), when known.
    pub place: Option<String>,
    pub message: String,
}

impl fmt::Display for ImportError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: ", self.path.display())?;
        if let Some(place) = &self.place {
            write!(f, "{place}: ")?;
        }
        f.write_str(&self.message)
    }
}

impl ImportError {
    pub fn new(path: &Path, place: Option<String>, message: impl Into<String>) -> Self {
        ImportError { path: path.to_owned(), place, message: message.into() }
    }
}

/// The formats bonescope reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// glTF 2.0, JSON (`.gltf`) or binary (`.glb`).
    Gltf,
}

/// Recognises a format from the first bytes of a file.
pub fn detect(bytes: &[u8]) -> Option<Format> {
    let text_start = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
    let first = text_start.iter().find(|b| !b.is_ascii_whitespace());
    if bytes.starts_with(b"glTF") || first == Some(&b'{') { Some(Format::Gltf) } else { None }
}

/// Reads and parses the file at `path`, whatever its format.
pub fn load(path: &Path) -> Result<Rig, ImportError> {
    let bytes = std::fs::read(path).map_err(|e| ImportError::new(path, None, format!("cannot read the file: {e}")))?;
    match detect(&bytes) {
        Some(Format::Gltf) => gltf::load(path, &bytes),
        None => Err(ImportError::new(path, None, "not a recognised animation file (expected glTF 2.0: .gltf or .glb)")),
    }
}
