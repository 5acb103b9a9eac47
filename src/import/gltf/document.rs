//! Parsing the container (JSON text or GLB) with the `gltf` crate, and validating the document.
//!
//! Two guards come first because the crate panics without them: a GLB header whose length field is below 12
//! (it subtracts the header size unchecked), and a primitive whose `POSITION` index is out of range (its
//! validation indexes the accessor list before checking). The crate's validation then checks every index and
//! enum (and, added here, animation channel targets, which it skips), so the `gltf::Document` wrappers used
//! afterwards cannot panic either.

use gltf::binary::{ChunkType, Error as GlbError};
use gltf::json::validation::{Error as ValidationError, Validate};
use gltf::json::{self, Path as JsonPath, Root};
use gltf::mesh::Semantic;

use super::{Failure, Result};

const GLB_HEADER_LEN: usize = 12;

/// A validated document with the GLB `BIN` chunk, if any.
pub(super) struct Parsed {
    pub document: gltf::Document,
    pub blob: Option<Vec<u8>>,
    /// Facts worth telling the user (extensions the file requires, say).
    pub notes: Vec<String>,
}

pub(super) fn parse(bytes: &[u8]) -> Result<Parsed> {
    let bytes = if bytes.starts_with(b"glTF") {
        check_glb_header(bytes)?
    } else {
        bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes)
    };
    let gltf = gltf::Gltf::from_slice_without_validation(bytes).map_err(parse_failure)?;
    let root = gltf.document.as_json();
    check_version(root)?;
    check_position_indices(root)?;
    let notes = validate(root)?;
    Ok(Parsed { document: gltf.document, blob: gltf.blob, notes })
}

/// Checks the 12-byte GLB header and returns the bytes it declares (trailing bytes are ignored).
fn check_glb_header(bytes: &[u8]) -> Result<&[u8]> {
    let header = Failure::at;
    let Some(fields) = bytes.get(4..GLB_HEADER_LEN) else {
        return Err(header("GLB header", format!("truncated: {} of 12 bytes", bytes.len())));
    };
    let word = |i: usize| u32::from_le_bytes([fields[i], fields[i + 1], fields[i + 2], fields[i + 3]]);
    let (version, length) = (word(0), word(4) as usize);
    if version != 2 {
        return Err(header("GLB header", format!("version {version}, expected 2")));
    }
    if length < GLB_HEADER_LEN {
        return Err(header("GLB header", format!("declares a total length of {length} bytes")));
    }
    bytes.get(..length).ok_or_else(|| {
        header("GLB header", format!("declares {length} bytes but the file has {} (truncated?)", bytes.len()))
    })
}

fn parse_failure(error: gltf::Error) -> Failure {
    match error {
        gltf::Error::Deserialize(e) => json_failure(&e),
        gltf::Error::Binary(e) => glb_failure(e),
        other => Failure::whole(other.to_string()),
    }
}

/// A JSON syntax or schema error, placed by line and column (serde_json's message without its suffix).
fn json_failure(e: &json::Error) -> Failure {
    let full = e.to_string();
    let suffix = format!(" at line {} column {}", e.line(), e.column());
    let message = full.strip_suffix(&suffix).unwrap_or(&full);
    if e.line() == 0 {
        Failure::whole(format!("malformed JSON: {message}"))
    } else {
        let place = format!("JSON line {}, column {}", e.line(), e.column());
        Failure::at(place, format!("malformed JSON: {message}"))
    }
}

fn glb_failure(e: GlbError) -> Failure {
    let chunk = |ty: ChunkType| match ty {
        ChunkType::Json => "GLB JSON chunk",
        ChunkType::Bin => "GLB BIN chunk",
    };
    match e {
        GlbError::ChunkLength { ty, length, length_read } => {
            Failure::at(chunk(ty), format!("declares {length} bytes but only {length_read} remain (truncated?)"))
        }
        GlbError::ChunkType(ty) => Failure::at(chunk(ty), "unexpected chunk (JSON must come first, then BIN)"),
        GlbError::Io(e) => Failure::at("GLB chunks", format!("truncated chunk header ({e})")),
        other => Failure::at("GLB chunks", other.to_string()),
    }
}

fn check_version(root: &Root) -> Result<()> {
    let version = &root.asset.version;
    if version.split('.').next() == Some("2") {
        Ok(())
    } else {
        Err(Failure::at("asset.version", format!("glTF {version} is not supported (expected 2.x)")))
    }
}

/// The `gltf` crate's validation indexes `accessors` by the `POSITION` attribute before checking the index.
fn check_position_indices(root: &Root) -> Result<()> {
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, primitive) in mesh.primitives.iter().enumerate() {
            let position = primitive.attributes.get(&json::validation::Checked::Valid(Semantic::Positions));
            if let Some(index) = position.filter(|i| i.value() >= root.accessors.len()) {
                return Err(Failure::at(
                    format!("meshes[{m}].primitives[{p}].attributes.POSITION"),
                    format!("accessor {} does not exist ({} accessors)", index.value(), root.accessors.len()),
                ));
            }
        }
    }
    Ok(())
}

/// Runs the crate's validation; the first problem becomes the error. Required extensions bonescope does not
/// implement become a note instead: most (materials, textures) do not touch what bonescope reads, and one that
/// does (mesh compression, quantization) fails later with an accessor error.
fn validate(root: &Root) -> Result<Vec<String>> {
    let mut problems: Vec<(JsonPath, ValidationError)> = Vec::new();
    let mut report = |path: &dyn Fn() -> JsonPath, error| problems.push((path(), error));
    root.validate(root, JsonPath::new, &mut report);
    // gltf-json 1.4 validates an animation's samplers but not its channels' targets.
    for (a, animation) in root.animations.iter().enumerate() {
        for (c, channel) in animation.channels.iter().enumerate() {
            let path = || JsonPath::new().field("animations").index(a).field("channels").index(c).field("target");
            channel.target.validate(root, path, &mut report);
        }
    }
    let (unsupported, problems): (Vec<_>, Vec<_>) =
        problems.into_iter().partition(|(_, e)| *e == ValidationError::Unsupported);
    if let Some((path, error)) = problems.first() {
        let more = match problems.len() {
            1 => String::new(),
            n => format!(" (and {} more problems)", n - 1),
        };
        return Err(Failure::at(path.as_str(), format!("{}{more}", describe(*error))));
    }
    let notes = if unsupported.is_empty() {
        vec![]
    } else {
        let names = root.extensions_required.iter().map(|e| format!("`{e}`")).collect::<Vec<_>>();
        vec![format!("the file requires extensions bonescope ignores: {}", names.join(", "))]
    };
    Ok(notes)
}

fn describe(error: ValidationError) -> &'static str {
    match error {
        ValidationError::IndexOutOfBounds => "index out of range",
        ValidationError::Invalid => "invalid value",
        ValidationError::Missing => "missing",
        ValidationError::Oversize => "too large for this system",
        ValidationError::Unsupported => "unsupported extension",
    }
}
