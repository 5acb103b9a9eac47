//! glTF 2.0 import (`.gltf` with external or `data:` buffers, and `.glb`).
//!
//! Read as leniently as the specification allows and exactly where it matters: [`document`] frames the GLB and
//! deserializes only the parts of the JSON bonescope uses ([`schema`]), so materials, textures and unknown
//! extensions can never stop a file from loading; references are checked where they are followed, and buffers are
//! read when an accessor first needs them (from a file on disk, only the bytes accessors read: [`source`]). Everything that touches binary data goes through the bounds-checked
//! reader in [`accessor`] (sparse accessors and accessors without a buffer view included). Every check fails with a
//! [`Failure`] that names the place in the document (`accessors[5]`, `animations[0].samplers[2]`), which [`load`]
//! turns into an [`ImportError`].

mod accessor;
mod animation;
mod buffers;
mod document;
mod draco;
mod estimate;
mod mesh;
mod meshopt;
mod scene;
mod schema;
mod source;
mod uri;

use std::fs::File;
use std::path::Path;

use super::ImportError;
use crate::model::{Rig, Unit};
use source::Source;

use super::failure::{Failure, Result};

/// Reads a glTF 2.0 file whose bytes are in memory (external buffers are read from beside `path`).
pub fn load(path: &Path, bytes: &[u8]) -> std::result::Result<Rig, ImportError> {
    read(path, Source::Memory(bytes)).map_err(|f| f.with_path(path))
}

/// Reads the glTF 2.0 file at `path`, open as `file`, reading only what it needs of it (see [`source`]).
pub fn load_file(path: &Path, file: &File) -> std::result::Result<Rig, ImportError> {
    let len = file.metadata().map_err(|e| ImportError::new(path, None, format!("cannot read the file: {e}")))?.len();
    let len = usize::try_from(len).unwrap_or(usize::MAX);
    read(path, Source::File { file, len }).map_err(|f| f.with_path(path))
}

fn read(path: &Path, source: Source<'_>) -> Result<Rig> {
    let parsed = document::parse(source)?;
    let mut notes = vec!["units: metres, Y-up (glTF)".to_owned()];
    notes.extend(parsed.notes);
    let root = &parsed.root;
    estimate::check(root)?;
    let folder = path.parent().unwrap_or(Path::new(""));
    let buffers = buffers::Buffers::new(&root.buffers, parsed.blob, folder);
    let accessors = accessor::Accessors::new(root, &buffers);
    let scene = scene::read(root, &mut notes)?;
    let skins = mesh::read_skins(root, &accessors, &scene.bone_of_node, &mut notes)?;
    let meshes = mesh::read_meshes(root, &accessors, &scene, &skins, &mut notes)?;
    let clips = animation::read_clips(root, &accessors, &scene.bone_of_node, &mut notes)?;
    Ok(Rig { skeleton: scene.skeleton, clips, skins, meshes, unit: Some(Unit::METRE), notes, tool: None })
}
