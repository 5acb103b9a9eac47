//! The shared assets beside the repository (`../shared/assets`), for the benchmarks and examples that load them.

use std::path::{Path, PathBuf};

/// The shared assets' folder.
pub fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/assets")
}

/// A file of the shared assets (`FOLDER/NAME`).
pub fn asset(path: &str) -> PathBuf {
    root().join(path)
}
