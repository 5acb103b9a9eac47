//! glTF 2.0 import (`.gltf` with external or `data:` buffers, and `.glb`).
//!
//! The `gltf` crate parses the container and the JSON; everything that touches binary data goes through the
//! bounds-checked reader in [`accessor`], because the crate's own readers can panic or silently truncate on bad
//! ranges. Every check fails with a [`Failure`] that names the place in the document (`accessors[5]`,
//! `animations[0].samplers[2]`), which [`load`] turns into an [`ImportError`].

mod accessor;
mod animation;
mod buffers;
mod document;
mod mesh;
mod scene;

use std::path::Path;

use super::ImportError;
use crate::model::Rig;

use super::failure::{Failure, Result};

/// Reads a glTF 2.0 file (its bytes already in memory; external buffers are read from beside `path`).
pub fn load(path: &Path, bytes: &[u8]) -> std::result::Result<Rig, ImportError> {
    read(path, bytes).map_err(|f| f.with_path(path))
}

fn read(path: &Path, bytes: &[u8]) -> Result<Rig> {
    let parsed = document::parse(bytes)?;
    let mut notes = vec!["units: metres, Y-up (glTF)".to_owned()];
    notes.extend(parsed.notes);
    let doc = &parsed.document;
    let folder = path.parent().unwrap_or(Path::new(""));
    let buffers = buffers::load(doc, parsed.blob, folder)?;
    let scene = scene::read(doc, &mut notes)?;
    let skins = mesh::read_skins(doc, &buffers, &scene.bone_of_node)?;
    let meshes = mesh::read_meshes(doc, &buffers, &scene, &skins, &mut notes)?;
    let clips = animation::read_clips(doc, &buffers, &scene.bone_of_node, &mut notes)?;
    Ok(Rig { skeleton: scene.skeleton, clips, skins, meshes, notes })
}
