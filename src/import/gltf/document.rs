//! The container (JSON text or GLB) and the document inside it.
//!
//! GLB framing is read here rather than by the `gltf` crate, because the crate refuses what the specification
//! allows (chunks of unknown types, which a loader must skip) and panics on a header length below 12. The JSON chunk
//! is read from the [`Source`]; the `BIN` chunk is only located, its bytes read when accessors need them. The JSON is
//! deserialized into [`schema::Root`], which declares only what bonescope reads; an error names its place as a
//! JSON path (`accessors[3].count`). Extensions listed in `extensionsRequired` are refused unless bonescope
//! evaluates them or they only change what bonescope neither reads nor draws (materials, textures, lights).

use std::borrow::Cow;

use super::schema::Root;
use super::source::{Region, Source};
use super::{Failure, Result};

const GLB_MAGIC: &[u8] = b"glTF";
const GLB_HEADER_LEN: usize = 12;
const CHUNK_HEADER_LEN: usize = 8;
const CHUNK_JSON: u32 = 0x4E4F_534A;
const CHUNK_BIN: u32 = 0x004E_4942;

/// Extensions bonescope evaluates.
const EVALUATED: &[&str] = &[
    "KHR_mesh_quantization",
    "KHR_animation_pointer",
    "EXT_meshopt_compression",
    "KHR_draco_mesh_compression",
    "EXT_mesh_gpu_instancing",
];
/// Prefixes of extensions that only touch materials (`KHR_techniques_webgl`: shaders, and `KHR_technique_webgl`, its
/// draft's singular name, which old exporters still write), textures, images or lights, which bonescope does not draw.
const NOT_DRAWN: &[&str] = &[
    "KHR_materials_",
    "KHR_techniques_",
    "KHR_technique_",
    "KHR_texture_",
    "EXT_texture_",
    "KHR_lights_",
    "EXT_lights_",
];

/// The parsed document with the GLB `BIN` chunk, if any.
pub(super) struct Parsed<'a> {
    pub root: Root,
    pub blob: Option<Region<'a>>,
    /// Facts worth telling the user (required extensions ignored, say).
    pub notes: Vec<String>,
}

pub(super) fn parse(source: Source<'_>) -> Result<Parsed<'_>> {
    let glb = read(source, 0, GLB_MAGIC.len().min(source.len()))? == GLB_MAGIC;
    let (json, blob) = if glb { split_glb(source)? } else { (read(source, 0, source.len())?, None) };
    // A JSON file may start with a byte order mark (a GLB's JSON chunk may not).
    let json = if glb { &json[..] } else { json.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(&json) };
    let root = deserialize(json)?;
    check_version(&root)?;
    let notes = check_required_extensions(&root)?;
    Ok(Parsed { root, blob, notes })
}

/// `len` bytes of the file from `start` (which the caller has checked it holds).
fn read(source: Source<'_>, start: usize, len: usize) -> Result<Cow<'_, [u8]>> {
    source.read(start..start + len).map_err(|e| Failure::whole(format!("cannot read the file: {e}")))
}

/// The JSON chunk and the first `BIN` chunk of a GLB; chunks of other types are skipped, as the spec asks.
fn split_glb(source: Source<'_>) -> Result<(Cow<'_, [u8]>, Option<Region<'_>>)> {
    let header = |message: String| Failure::at("GLB header", message);
    let file_len = source.len();
    let Some(bytes) = (file_len >= GLB_HEADER_LEN).then(|| read(source, 0, GLB_HEADER_LEN)).transpose()? else {
        return Err(header(format!("truncated: {file_len} of 12 bytes")));
    };
    let word = |at: usize| u32::from_le_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]]);
    let (version, length) = (word(4), word(8) as usize);
    if version != 2 {
        return Err(header(format!("version {version}, expected 2")));
    }
    if length < GLB_HEADER_LEN {
        return Err(header(format!("declares a total length of {length} bytes")));
    }
    if length > file_len {
        return Err(header(format!("declares {length} bytes but the file has {file_len} (truncated?)")));
    }
    let mut chunks = Chunks { source, at: GLB_HEADER_LEN, end: length, index: 0 };
    let json = match chunks.next().transpose()? {
        Some((CHUNK_JSON, json)) => read(source, json.start, json.len)?,
        Some(_) => return Err(Failure::at("GLB chunks[0]", "is not the JSON chunk (JSON must come first)")),
        None => return Err(Failure::at("GLB chunks", "no JSON chunk")),
    };
    for chunk in chunks {
        if let (CHUNK_BIN, bin) = chunk? {
            return Ok((json, Some(bin)));
        }
    }
    Ok((json, None))
}

/// The chunks of a GLB body, from `at` to `end`: `(type, where its data lies)`.
struct Chunks<'a> {
    source: Source<'a>,
    at: usize,
    end: usize,
    index: usize,
}

impl<'a> Iterator for Chunks<'a> {
    type Item = Result<(u32, Region<'a>)>;

    fn next(&mut self) -> Option<Self::Item> {
        if self.at >= self.end {
            return None;
        }
        let place = format!("GLB chunks[{}]", self.index);
        self.index += 1;
        let (at, remaining) = (self.at, self.end - self.at);
        self.at = self.end;
        if remaining < CHUNK_HEADER_LEN {
            return Some(Err(Failure::at(place, "truncated chunk header")));
        }
        let header = match read(self.source, at, CHUNK_HEADER_LEN) {
            Ok(header) => header,
            Err(failure) => return Some(Err(failure)),
        };
        let length = u32::from_le_bytes([header[0], header[1], header[2], header[3]]) as usize;
        let kind = u32::from_le_bytes([header[4], header[5], header[6], header[7]]);
        let start = at + CHUNK_HEADER_LEN;
        let available = remaining - CHUNK_HEADER_LEN;
        if length > available {
            let message = format!("declares {length} bytes but only {available} remain (truncated?)");
            return Some(Err(Failure::at(place, message)));
        }
        self.at = start + length;
        Some(Ok((kind, Region { source: self.source, start, len: length })))
    }
}

/// The JSON as [`Root`]; a syntax error is placed by line and column, a schema error by its JSON path.
fn deserialize(json: &[u8]) -> Result<Root> {
    let mut deserializer = serde_json::Deserializer::from_slice(json);
    let root = serde_path_to_error::deserialize(&mut deserializer).map_err(|e| {
        let path = e.path().to_string();
        let inner = e.into_inner();
        if inner.is_syntax() || inner.is_eof() || path == "." {
            json_failure(&inner)
        } else {
            Failure::at(path, strip_position(&inner))
        }
    })?;
    deserializer.end().map_err(|e| json_failure(&e))?;
    Ok(root)
}

/// serde_json's message without its ` at line L column C` suffix, which the place says instead.
fn strip_position(e: &serde_json::Error) -> String {
    let full = e.to_string();
    let suffix = format!(" at line {} column {}", e.line(), e.column());
    full.strip_suffix(&suffix).unwrap_or(&full).to_owned()
}

fn json_failure(e: &serde_json::Error) -> Failure {
    let message = format!("malformed JSON: {}", strip_position(e));
    if e.line() == 0 {
        Failure::whole(message)
    } else {
        Failure::at(format!("JSON line {}, column {}", e.line(), e.column()), message)
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

/// Refuses the first required extension that could change what bonescope shows; notes the ones it may ignore.
fn check_required_extensions(root: &Root) -> Result<Vec<String>> {
    let mut ignored: Vec<&str> = Vec::new();
    for (i, name) in root.extensions_required.iter().enumerate() {
        if EVALUATED.contains(&name.as_str()) {
            continue;
        }
        if !NOT_DRAWN.iter().any(|prefix| name.starts_with(prefix)) {
            let message = format!("the file requires the extension `{name}`, which bonescope does not implement");
            return Err(Failure::at(format!("extensionsRequired[{i}]"), message));
        }
        if !ignored.contains(&name.as_str()) {
            ignored.push(name);
        }
    }
    Ok(match ignored[..] {
        [] => vec![],
        _ => {
            let names = ignored.iter().map(|e| format!("`{e}`")).collect::<Vec<_>>().join(", ");
            vec![format!("required extensions that change only materials, textures or lights, not drawn: {names}")]
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn glb(chunks: &[(u32, &[u8])]) -> Vec<u8> {
        let mut body = Vec::new();
        for (kind, data) in chunks {
            body.extend((data.len() as u32).to_le_bytes());
            body.extend(kind.to_le_bytes());
            body.extend(*data);
        }
        let mut out = b"glTF".to_vec();
        out.extend(2u32.to_le_bytes());
        out.extend(((GLB_HEADER_LEN + body.len()) as u32).to_le_bytes());
        out.extend(body);
        out
    }

    #[test]
    fn glb_chunks_of_unknown_types_are_skipped() {
        let bytes = glb(&[(CHUNK_JSON, b"{}  "), (0x1234, b"xxxx"), (CHUNK_BIN, b"\x01\x02\x03\x04")]);
        let (json, bin) = split_glb(Source::Memory(&bytes)).unwrap();
        assert_eq!(&json[..], b"{}  ");
        assert_eq!(&bin.unwrap().read(0..4).unwrap()[..], b"\x01\x02\x03\x04");
        assert!(split_glb(Source::Memory(&glb(&[(CHUNK_JSON, b"{}  ")]))).unwrap().1.is_none());
    }

    #[test]
    fn broken_glb_framing_is_placed() {
        let place = |bytes: &[u8]| split_glb(Source::Memory(bytes)).unwrap_err().place.unwrap();
        assert_eq!(place(b"glTF\x02\0\0\0\x04\0\0\0"), "GLB header");
        assert_eq!(place(&glb(&[(CHUNK_BIN, b"")])), "GLB chunks[0]");
        let mut truncated = glb(&[(CHUNK_JSON, b"{}  "), (CHUNK_BIN, b"abcd")]);
        let n = truncated.len();
        truncated[n - 12] = 40; // the BIN chunk claims 40 bytes
        assert_eq!(place(&truncated), "GLB chunks[1]");
    }

    #[test]
    fn schema_errors_name_their_json_path() {
        let failure = deserialize(br#"{"asset": {"version": "2.0"}, "accessors": [{"count": "many"}]}"#).unwrap_err();
        assert_eq!(failure.place.as_deref(), Some("accessors[0].count"));
        let failure = deserialize(b"{\"asset\": ").unwrap_err();
        assert!(failure.message.starts_with("malformed JSON"), "{failure:?}");
    }

    #[test]
    fn required_extensions_are_refused_unless_evaluated_or_not_drawn() {
        let root = |required: &str| {
            deserialize(format!(r#"{{"asset": {{"version": "2.0"}}, "extensionsRequired": {required}}}"#).as_bytes())
                .unwrap()
        };
        assert!(check_required_extensions(&root(r#"["KHR_mesh_quantization"]"#)).unwrap().is_empty());
        let notes = check_required_extensions(&root(r#"["KHR_texture_basisu", "KHR_texture_basisu"]"#)).unwrap();
        assert_eq!(notes.len(), 1);
        // The techniques draft under its singular name (assimp's `BoxTextured-glTF-techniqueWebGL`) only shades.
        let shaded = check_required_extensions(&root(r#"["KHR_technique_webgl"]"#)).unwrap();
        assert_eq!(shaded.len(), 1, "{shaded:?}");
        let refused = check_required_extensions(&root(r#"["KHR_texture_basisu", "EXT_unknown_geometry"]"#));
        let failure = refused.unwrap_err();
        assert_eq!(failure.place.as_deref(), Some("extensionsRequired[1]"));
        assert!(failure.message.contains("EXT_unknown_geometry"));
    }
}
