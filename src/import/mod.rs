//! Turning files into a [`Rig`]: one module per format and one [`load`] entry that picks the format by content.
//!
//! Formats: glTF 2.0 (`gltf`), FBX binary and ASCII through ufbx (`fbx`), BVH (`bvh`), OpenUSD's UsdSkel through
//! the `openusd` crate (`usd`), and a runtime's pose dump (`dump`, JSON or CSV). Every reader turns any
//! problem into an [`ImportError`] naming the file and the place in it; none may panic or allocate much more than
//! the file's size suggests, whatever the bytes (the fuzz targets in `fuzz/` and `examples/fuzz_import.rs` check).

pub mod budget;
mod bvh;
mod demo;
pub mod dump;
mod failure;
mod fbx;
mod format;
mod gltf;
mod magnitude;
pub mod text;
mod usd;

pub use demo::{demo_rig, stress_rig};
pub use format::Format;

use std::borrow::Cow;
use std::fmt;
use std::io::Read;
use std::path::{Path, PathBuf};

use crate::model::{Bone, Placement, Rig, Skeleton};

pub use fbx::{memory_limit as fbx_memory_limit, ufbx_load_opts as fbx_load_opts};

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
        write!(f, "{}: ", text::printable(&self.path.to_string_lossy()))?;
        if let Some(place) = &self.place {
            write!(f, "{place}: ")?;
        }
        f.write_str(&self.message)
    }
}

/// The most characters of an error's place and of its message: they may quote the file (a path of FBX records a
/// hundred thousand deep, a name thousands of characters long), and an error is one readable line.
const PLACE_CHARS: usize = 300;
const MESSAGE_CHARS: usize = 1000;

impl ImportError {
    /// The error, its place and message made printable and cut to a readable length ([`text`]).
    pub fn new(path: &Path, place: Option<String>, message: impl Into<String>) -> Self {
        let place = place.map(|p| text::printable_cut(&p, PLACE_CHARS));
        ImportError { path: path.to_owned(), place, message: text::printable_cut(&message.into(), MESSAGE_CHARS) }
    }
}

/// What every loaded rig goes through: refused when its numbers can overflow ([`magnitude`], noted when they grow
/// past what a runtime keeps), its names and notes made printable.
fn finish(path: &Path, mut rig: Rig) -> Result<Rig, ImportError> {
    let extreme = magnitude::check(&rig).map_err(|f| f.with_path(path))?;
    rig.notes.extend(extreme);
    Ok(with_conversion_nodes(printable_rig(rig)))
}

/// The rig with its conversion nodes ([`Rig::conversion_nodes`]) placed outside it, beside the file's conversion.
fn with_conversion_nodes(mut rig: Rig) -> Rig {
    let conversion_nodes = rig.conversion_nodes();
    if conversion_nodes.contains(&true) {
        let conversion = rig.skeleton.placement().conversion;
        let skeleton = std::mem::take(&mut rig.skeleton);
        rig.skeleton = skeleton.placed(Placement { conversion, conversion_nodes });
    }
    rig
}

/// The rig with every name and note from the file printable, and names cut to a readable length ([`text::name`]).
fn printable_rig(mut rig: Rig) -> Rig {
    let unprintable = |name: &str| name.chars().any(char::is_control) || name.chars().nth(text::NAME_CHARS).is_some();
    let tidy = |name: &mut String| {
        if unprintable(name) {
            *name = text::name(name);
        }
    };
    if rig.skeleton.bones().iter().any(|b| unprintable(&b.name)) {
        let bones = rig.skeleton.bones().iter().map(|b| Bone { name: text::name(&b.name), ..b.clone() }).collect();
        // The same bones in the same order: a skeleton already.
        if let Ok(skeleton) = Skeleton::new(bones) {
            rig.skeleton = skeleton.placed(rig.skeleton.placement().clone());
        }
    }
    rig.clips.iter_mut().filter_map(|c| c.name.as_mut()).for_each(tidy);
    rig.skins.iter_mut().filter_map(|s| s.name.as_mut()).for_each(tidy);
    for mesh in &mut rig.meshes {
        tidy(&mut mesh.name);
        mesh.morph_targets.iter_mut().for_each(|t| tidy(&mut t.name));
    }
    for note in &mut rig.notes {
        if let Cow::Owned(printable) = text::printable(note) {
            *note = printable;
        }
    }
    rig
}

/// The space the model matrices of a loaded rig live in.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Space {
    /// bonescope's own: right-handed, Y up, metres. FBX files are converted (and say so in the notes); glTF already
    /// is; BVH states no units or axes and is taken as written.
    #[default]
    YUpMetres,
    /// The file's own axes and units, as the authoring tool wrote them (what `export` writes, so its output can be
    /// compared with the tool's own export).
    File,
}

/// How to load a file.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Options {
    pub space: Space,
}

/// How far into a file the ASCII FBX marker is looked for.
const FBX_ASCII_LOOKAHEAD: usize = 64 * 1024;

/// Recognises a format from the content of a file (never from its name).
///
/// - glTF: binary `glTF` magic, or JSON (the first non-blank byte is `{`);
/// - FBX: the binary magic `Kaydara FBX Binary  \0`, or text that starts with `; FBX` or holds `FBXHeaderExtension`
///   in its first 64 KiB;
/// - BVH: text whose first word is `HIERARCHY`;
/// - USD: text that starts with `#usda`, the binary magic `PXR-USDC`, or a zip archive whose first entry is a USD
///   layer (`.usdz`);
/// - pose dump: CSV whose first line is `# bonescope-pose-dump`, or JSON naming `"bonescope-pose-dump"` in its first
///   64 KiB (before glTF, which is any other JSON).
pub fn detect(bytes: &[u8]) -> Option<Format> {
    if bytes.starts_with(b"#usda") || bytes.starts_with(b"PXR-USDC") || is_usdz(bytes) {
        return Some(Format::Usd);
    }
    let text = text_start(bytes);
    if dump::detect(text).is_some() {
        return Some(Format::PoseDump);
    }
    if bytes.starts_with(b"glTF") || text.first() == Some(&b'{') {
        return Some(Format::Gltf);
    }
    if bytes.starts_with(b"Kaydara FBX Binary  \0") || text.starts_with(b"; FBX") {
        return Some(Format::Fbx);
    }
    let head = &text[..text.len().min(FBX_ASCII_LOOKAHEAD)];
    if head.windows(b"FBXHeaderExtension".len()).any(|w| w == b"FBXHeaderExtension") {
        return Some(Format::Fbx);
    }
    let word_end = text.iter().position(|b| b.is_ascii_whitespace()).unwrap_or(text.len());
    if text[..word_end].eq_ignore_ascii_case(b"HIERARCHY") {
        return Some(Format::Bvh);
    }
    None
}

/// `bytes` from their first character that is not blank (after a UTF-8 byte-order mark).
fn text_start(bytes: &[u8]) -> &[u8] {
    let text = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
    let start = text.iter().position(|b| !b.is_ascii_whitespace()).unwrap_or(text.len());
    &text[start..]
}

/// Whether `bytes` start a zip archive whose first entry is a USD layer: a `.usdz` package.
fn is_usdz(bytes: &[u8]) -> bool {
    // A zip local file header: its magic, the name's length at byte 26, the name from byte 30.
    let Some(name_len) = bytes.get(26..28).map(|n| usize::from(u16::from_le_bytes([n[0], n[1]]))) else {
        return false;
    };
    let name = bytes.get(30..30 + name_len).unwrap_or_default();
    let layer = [b".usd".as_slice(), b".usda", b".usdc"].iter().any(|ext| name.to_ascii_lowercase().ends_with(ext));
    bytes.starts_with(b"PK\x03\x04") && layer
}

/// Reads and parses the file at `path`, whatever its format, into bonescope's space (Y-up metres).
pub fn load(path: &Path) -> Result<Rig, ImportError> {
    load_with(path, &Options::default())
}

/// Reads and parses the file at `path` with `options`.
///
/// glTF and FBX are read from the file as they are needed (of a binary glTF, only its JSON and the bytes of the
/// accessors that are decoded: `gltf::load_file`; FBX by ufbx through its own buffer: `fbx::load_file`), so a file
/// is not copied into memory whole before it is parsed; BVH is read whole first.
pub fn load_with(path: &Path, options: &Options) -> Result<Rig, ImportError> {
    let cannot_read = |e: std::io::Error| ImportError::new(path, None, format!("cannot read the file: {e}"));
    // A pipe would block the open, a device never end: only regular files are opened.
    if !std::fs::metadata(path).map_err(cannot_read)?.is_file() {
        return Err(ImportError::new(path, None, "not a regular file (a folder, a pipe or a device): not read"));
    }
    let mut file = std::fs::File::open(path).map_err(cannot_read)?;
    // As much as `detect` looks at; a recognised glTF or FBX file is read no further here.
    let mut bytes = Vec::new();
    (&mut file).take(FBX_ASCII_LOOKAHEAD as u64).read_to_end(&mut bytes).map_err(cannot_read)?;
    match detect(&bytes) {
        Some(Format::Gltf) => return gltf::load_file(path, &file).and_then(|rig| finish(path, rig)),
        Some(Format::Fbx) => return fbx::load_file(path, file, &bytes, options).and_then(|rig| finish(path, rig)),
        Some(Format::Usd) => return usd::load(path, options).and_then(|rig| finish(path, rig)),
        Some(Format::PoseDump) => {
            // Streamed from the bytes already read on: a dump is never held whole besides its keys.
            let size = file.metadata().map_or(0, |m| m.len());
            let reader = std::io::BufReader::new(std::io::Cursor::new(&bytes).chain(&file));
            return load_dump(path, reader, size, &bytes);
        }
        _ => {}
    }
    let size = file.metadata().map_or(0, |m| usize::try_from(m.len()).unwrap_or(0));
    bytes.reserve(size.saturating_sub(bytes.len()));
    file.read_to_end(&mut bytes).map_err(cannot_read)?;
    load_bytes_with(path, &bytes, options)
}

/// Parses a file already in memory; `path` names it in errors (and locates a glTF's external buffers).
pub fn load_bytes(path: &Path, bytes: &[u8]) -> Result<Rig, ImportError> {
    load_bytes_with(path, bytes, &Options::default())
}

/// [`load_bytes`] with `options`.
pub fn load_bytes_with(path: &Path, bytes: &[u8], options: &Options) -> Result<Rig, ImportError> {
    match detect(bytes) {
        Some(format) => load_bytes_as(format, path, bytes, options),
        None => Err(ImportError::new(
            path,
            None,
            format!("not a recognised animation file (expected one of {})", Format::listed()),
        )),
    }
}

/// Parses `bytes` as `format`, whatever they look like (the fuzz targets use it to reach each parser directly).
pub fn load_bytes_as(format: Format, path: &Path, bytes: &[u8], options: &Options) -> Result<Rig, ImportError> {
    let rig = match format {
        Format::Gltf => gltf::load(path, bytes),
        Format::Fbx => fbx::load(path, bytes, options),
        Format::Bvh => bvh::load(path, bytes),
        Format::Usd => usd::load_bytes(path, bytes, options),
        Format::PoseDump => return load_dump(path, bytes, bytes.len() as u64, bytes),
    };
    rig.and_then(|rig| finish(path, rig))
}

/// Reads the pose dump of `size` bytes from `reader`, whose first bytes are `head` (CSV where they do not show JSON).
fn load_dump(path: &Path, reader: impl std::io::BufRead, size: u64, head: &[u8]) -> Result<Rig, ImportError> {
    let syntax = dump::detect(text_start(head)).unwrap_or(dump::Syntax::Csv);
    dump::read(reader, size, syntax).map_err(|f| f.with_path(path)).and_then(|rig| finish(path, rig))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn formats_are_detected_by_content() {
        assert_eq!(detect(b"glTF\x02\0\0\0"), Some(Format::Gltf));
        assert_eq!(detect(b"\xEF\xBB\xBF  {\"asset\":{}}"), Some(Format::Gltf));
        assert_eq!(detect(b"Kaydara FBX Binary  \0\x1a\0"), Some(Format::Fbx));
        assert_eq!(detect(b"; FBX 7.7.0 project file\n"), Some(Format::Fbx));
        assert_eq!(detect(b"; exported\nFBXHeaderExtension:  {\n"), Some(Format::Fbx));
        assert_eq!(detect(b"\r\n\tHIERARCHY\r\nROOT Hips"), Some(Format::Bvh));
        assert_eq!(detect(b"hierarchy\n"), Some(Format::Bvh));
        assert_eq!(detect(b"HIERARCHYX\n"), None);
        assert_eq!(detect(b"Kaydara FBX Binary"), None, "a truncated magic is not FBX");
        assert_eq!(detect(b""), None);
        assert_eq!(detect(b"   "), None);
        assert_eq!(detect(b"#usda 1.0\n(\n)"), Some(Format::Usd));
        assert_eq!(detect(b"PXR-USDC\0\0"), Some(Format::Usd));
        let mut usdz = b"PK\x03\x04".to_vec();
        usdz.extend([0; 22]);
        usdz.extend(9u16.to_le_bytes());
        usdz.extend([0; 2]);
        usdz.extend(b"root.usdc");
        assert_eq!(detect(&usdz), Some(Format::Usd));
        usdz.truncate(30);
        usdz.extend(b"root.png\0");
        assert_eq!(detect(&usdz), None, "a zip of something else is no USD");
        assert_eq!(detect(b"\n{\"format\": \"bonescope-pose-dump\", \"version\": 1"), Some(Format::PoseDump));
        assert_eq!(detect(b"# bonescope-pose-dump 1 space=world\n"), Some(Format::PoseDump));
    }

    #[test]
    fn names_from_a_file_are_printable_and_readable_in_length() {
        let long = "y".repeat(1000);
        let json = format!(
            r#"{{"asset": {{"version": "2.0"}}, "scenes": [{{"nodes": [0]}}],
                "nodes": [{{"name": "a\u001b[2J\nb", "children": [1]}}, {{"name": "{long}"}}]}}"#
        );
        let rig = load_bytes(Path::new("names.gltf"), json.as_bytes()).unwrap();
        assert_eq!(rig.skeleton.bone(0).name, "a\\x1b[2J\\x0ab");
        assert_eq!(rig.skeleton.bone(1).name, format!("{}…", "y".repeat(text::NAME_CHARS)));
    }
}
