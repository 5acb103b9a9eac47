//! glTF 2.0 import (placeholder until the importer lands).

use std::path::Path;

use super::ImportError;
use crate::model::Rig;

pub fn load(path: &Path, _bytes: &[u8]) -> Result<Rig, ImportError> {
    Err(ImportError::new(path, None, "glTF import is not written yet"))
}
