//! Buffer bytes: the GLB `BIN` chunk (read where it lies, as accessors need its bytes), base64 `data:` URIs (decoded
//! as the JSON is read: [`Uri`]), or files beside the glTF file (read on first use).
//!
//! A buffer nothing reads is never opened, so a file whose unused buffer points at a missing file or an `http:` URI
//! still loads; a buffer that is read and cannot be had fails naming who needed it. A URI may name a file in the
//! glTF file's folder or below it, percent-encoded or not; absolute paths, `..` and every scheme but `data:` are
//! refused, and the path must still lie inside the folder once symbolic links are resolved and name a regular file,
//! so a downloaded file cannot make bonescope read elsewhere on disk, block on a pipe or reach the network. No buffer is
//! read beyond its declared `byteLength` (a GLB chunk may carry padding), an external file included, so memory
//! stays bounded by what the files actually hold.

use std::borrow::Cow;
use std::io::Read;
use std::ops::Range;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use super::schema::{self, Uint};
use super::source::Region;
use super::uri::Uri;
use super::{Failure, Result};

/// The document's buffers, loaded when first asked for.
pub(super) struct Buffers<'a> {
    declared: &'a [schema::Buffer],
    blob: Option<Region<'a>>,
    folder: &'a Path,
    loaded: Vec<OnceLock<std::result::Result<Data<'a>, String>>>,
}

/// A buffer's bytes: in memory (a `data:` URI's, decoded as the JSON was read, or a file's beside the glTF file), or
/// the GLB `BIN` chunk, read where it lies as accessors need it.
enum Data<'a> {
    Memory(Cow<'a, [u8]>),
    Blob(Region<'a>),
}

impl<'a> Buffers<'a> {
    pub fn new(declared: &'a [schema::Buffer], blob: Option<Region<'a>>, folder: &'a Path) -> Self {
        Buffers { declared, blob, folder, loaded: declared.iter().map(|_| OnceLock::new()).collect() }
    }

    /// The length of `buffers[index]` (its `byteLength`, which its data has been checked to hold); `user`
    /// (`bufferViews[2]`) names who needs it.
    pub fn len(&self, index: Uint, user: &str) -> Result<usize> {
        Ok(self.data(index, user)?.1.byte_length.0)
    }

    /// The bytes of `buffers[index]` in `range`, which must lie within [`Buffers::len`].
    pub fn read(&self, index: Uint, range: Range<usize>, user: &str) -> Result<Cow<'_, [u8]>> {
        let fail = |why: String| Failure::at(user, format!("needs buffers[{}]: {why}", index.0));
        match self.data(index, user)?.0 {
            Data::Memory(bytes) => bytes.get(range).map(Cow::Borrowed).ok_or_else(|| fail("out of range".into())),
            Data::Blob(region) => region.read(range).map_err(|e| fail(format!("cannot read the file: {e}"))),
        }
    }

    /// Whether `buffers[index]` has a source in the file: a uri, or the GLB `BIN` chunk. One without is valid glTF
    /// ("defined by the application"), and what it holds cannot be had here.
    pub fn has_source(&self, index: Uint) -> bool {
        self.declared.get(index.0).is_some_and(|b| b.uri.is_some()) || (index.0 == 0 && self.blob.is_some())
    }

    /// The loaded data of `buffers[index]` and its declaration.
    fn data(&self, index: Uint, user: &str) -> Result<(&Data<'a>, &'a schema::Buffer)> {
        let declared = schema::item(self.declared, index, "buffers", user)?;
        let loaded = self.loaded[index.0].get_or_init(|| self.load(index.0, declared));
        match loaded {
            Ok(data) => Ok((data, declared)),
            Err(why) => Err(Failure::at(user, format!("needs buffers[{}]: {why}", index.0))),
        }
    }

    fn load(&self, index: usize, declared: &'a schema::Buffer) -> std::result::Result<Data<'a>, String> {
        let length = declared.byte_length.0;
        let data = match (&declared.uri, self.blob) {
            (Some(Uri::Data(decoded)), _) => Data::Memory(Cow::Borrowed(decoded.as_deref().map_err(Clone::clone)?)),
            (Some(Uri::Reference(uri)), _) => Data::Memory(Cow::Owned(read_file(uri, self.folder, length)?)),
            (None, Some(blob)) if index == 0 => Data::Blob(blob),
            (None, _) if index == 0 => return Err("it has no uri, and the file has no GLB BIN chunk".into()),
            (None, _) => return Err("it has no uri (only buffers[0] can be the GLB BIN chunk)".into()),
        };
        let held = match &data {
            Data::Memory(bytes) => bytes.len(),
            Data::Blob(region) => region.len,
        };
        if held < length {
            return Err(format!("its byteLength is {length} but the data holds {held} bytes"));
        }
        Ok(data)
    }
}

/// At most `length` bytes of the file a buffer URI reference names: the path is resolved first (symbolic links
/// followed) and must lead to a regular file inside the glTF file's folder, so a link cannot make bonescope read
/// elsewhere, a pipe block it or a device (`/dev/zero`) feed it without end.
fn read_file(uri: &str, folder: &Path, length: usize) -> std::result::Result<Vec<u8>, String> {
    let folder = if folder.as_os_str().is_empty() { Path::new(".") } else { folder };
    let path = folder.join(relative_path(uri)?);
    let resolve =
        |path: &Path| path.canonicalize().map_err(|e| format!("cannot open `{uri}` ({}): {e}", path.display()));
    let (resolved, root) = (resolve(&path)?, resolve(folder)?);
    if !resolved.starts_with(&root) {
        return Err(format!("`{uri}` leads outside the glTF file's folder (through a symbolic link): not read"));
    }
    let regular = std::fs::metadata(&resolved).is_ok_and(|m| m.is_file());
    if !regular {
        return Err(format!("`{uri}` is not a regular file (a folder, a pipe or a device): not read"));
    }
    let file = std::fs::File::open(&resolved).map_err(|e| format!("cannot open `{uri}` ({}): {e}", path.display()))?;
    let mut data = Vec::new();
    file.take(length as u64)
        .read_to_end(&mut data)
        .map_err(|e| format!("cannot read `{uri}` ({}): {e}", path.display()))?;
    Ok(data)
}

/// A URI reference as a relative path inside the glTF file's folder.
pub(super) fn relative_path(uri: &str) -> std::result::Result<PathBuf, String> {
    if let Some(scheme) = scheme(uri) {
        return Err(format!("unsupported URI scheme `{scheme}:` in `{uri}` (only data: URIs and relative paths)"));
    }
    let decoded = percent_decode(uri).ok_or_else(|| format!("malformed percent-encoding in `{uri}`"))?;
    if decoded.starts_with(['/', '\\']) {
        return Err(format!("`{uri}` is an absolute path (only paths relative to the glTF file are read)"));
    }
    let mut path = PathBuf::new();
    for part in decoded.split(['/', '\\']).filter(|p| !p.is_empty() && *p != ".") {
        if part == ".." || part.contains(':') {
            return Err(format!("`{uri}` is not a path inside the glTF file's folder"));
        }
        path.push(part);
    }
    if path.as_os_str().is_empty() {
        return Err(format!("`{uri}` names no file"));
    }
    Ok(path)
}

/// The URI's scheme (RFC 3986: a letter, then letters, digits, `+`, `-`, `.`, then `:`), if it has one.
fn scheme(uri: &str) -> Option<&str> {
    let (scheme, _) = uri.split_once(':')?;
    let mut chars = scheme.chars();
    let valid = chars.next().is_some_and(|c| c.is_ascii_alphabetic())
        && chars.all(|c| c.is_ascii_alphanumeric() || matches!(c, '+' | '-' | '.'));
    valid.then_some(scheme)
}

/// `%XX` escapes decoded; `None` for a broken escape or a result that is not UTF-8.
fn percent_decode(s: &str) -> Option<String> {
    let mut bytes = Vec::with_capacity(s.len());
    let mut rest = s.as_bytes();
    while let Some((&byte, tail)) = rest.split_first() {
        if byte == b'%' {
            let hex = std::str::from_utf8(tail.get(..2)?).ok()?;
            bytes.push(u8::from_str_radix(hex, 16).ok()?);
            rest = &tail[2..];
        } else {
            bytes.push(byte);
            rest = tail;
        }
    }
    String::from_utf8(bytes).ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn relative_paths_are_percent_decoded() {
        assert_eq!(relative_path("my%20model.bin"), Ok(PathBuf::from("my model.bin")));
        assert_eq!(relative_path("./sub/a.bin"), Ok(Path::new("sub").join("a.bin")));
    }

    #[test]
    fn escapes_absolute_paths_and_schemes_are_refused() {
        for uri in ["../x.bin", "a/../../x.bin", "%2E%2E/x.bin", "..%2Fx.bin", "a\\..\\..\\x", "/etc/passwd"] {
            assert!(relative_path(uri).is_err(), "{uri}");
        }
        for uri in ["http://example.com/x.bin", "file:///x.bin", "C:/x.bin", "https:x"] {
            let err = relative_path(uri).unwrap_err();
            assert!(err.contains("scheme"), "{uri}: {err}");
        }
        assert!(relative_path("bad%zz").is_err() && relative_path("bad%4").is_err() && relative_path("%ff").is_err());
    }
}
