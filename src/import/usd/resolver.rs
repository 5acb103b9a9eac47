//! Finding the assets a stage names (sublayers, references, payloads) as USD's default resolver does, but only
//! inside the root layer's folder: a file may not make bonescope read anything outside it. Only regular files are
//! read (a pipe would block, a device never end), and a text layer nested deeper than any scene is refused before
//! it is parsed (the parser recurses into each level: a hundred thousand of them overflow the stack).

use std::io::{self, Read, Seek};
use std::path::{Path, PathBuf};

use openusd::ar::{Asset, DefaultResolver, ResolvedPath, Resolver};

/// USD's default resolver confined to one folder.
pub struct FolderResolver {
    inner: DefaultResolver,
    folder: PathBuf,
}

impl FolderResolver {
    /// The resolver for the stage whose root layer is `file`: its folder, canonical.
    pub fn for_file(file: &Path) -> io::Result<Self> {
        let folder = file.canonicalize()?.parent().map(Path::to_owned).unwrap_or_default();
        Ok(FolderResolver { inner: DefaultResolver::with_search_paths([folder.clone()]), folder })
    }

    /// Whether `resolved` (a file, or an entry of a package `pkg.usdz[inner]`) is inside the folder.
    fn inside(&self, resolved: &ResolvedPath) -> bool {
        let text = resolved.to_string_lossy();
        let outer = text.split_once('[').map_or(&*text, |(package, _)| package);
        Path::new(outer).canonicalize().is_ok_and(|path| path.starts_with(&self.folder))
    }
}

impl Resolver for FolderResolver {
    fn create_identifier(&self, asset_path: &str, anchor: Option<&ResolvedPath>) -> String {
        self.inner.create_identifier(asset_path, anchor)
    }

    fn resolve(&self, asset_path: &str) -> Option<ResolvedPath> {
        self.inner.resolve(asset_path).filter(|resolved| self.inside(resolved))
    }

    /// bonescope writes no USD.
    fn resolve_for_new_asset(&self, _asset_path: &str) -> Option<ResolvedPath> {
        None
    }

    fn open_asset(&self, resolved: &ResolvedPath) -> io::Result<Box<dyn Asset>> {
        let text = resolved.to_string_lossy();
        if !self.inside(resolved) {
            let message = format!("{text} is outside the file's folder: not read");
            return Err(io::Error::new(io::ErrorKind::PermissionDenied, message));
        }
        let outer = text.split_once('[').map_or(&*text, |(package, _)| package);
        if !std::fs::metadata(outer)?.is_file() {
            return Err(io::Error::new(io::ErrorKind::InvalidInput, format!("{outer} is not a regular file")));
        }
        let mut asset = self.inner.open_asset(resolved)?;
        let mut magic = [0u8; 5];
        let read = asset.read(&mut magic)?;
        asset.seek(io::SeekFrom::Start(0))?;
        if magic[..read] != *b"#usda" {
            return Ok(asset);
        }
        let mut text = Vec::new();
        asset.read_to_end(&mut text)?;
        check_nesting(&text).map_err(|message| io::Error::new(io::ErrorKind::InvalidData, message))?;
        Ok(Box::new(io::Cursor::new(text)))
    }

    fn identity(&self) -> String {
        format!("bonescope folder {}", self.folder.display())
    }
}

/// How deep a text layer's brackets may nest: a prim is one level, its metadata and values a few more.
const MAX_NESTING: usize = 256;

/// Refuses a text layer whose `{`, `(` and `[` nest deeper than [`MAX_NESTING`] (outside strings, asset paths and
/// comments), naming the line.
fn check_nesting(text: &[u8]) -> Result<(), String> {
    let (mut depth, mut line, mut i) = (0usize, 1usize, 0usize);
    while let Some(&byte) = text.get(i) {
        match byte {
            b'\n' => line += 1,
            b'{' | b'(' | b'[' => {
                depth += 1;
                if depth > MAX_NESTING {
                    return Err(format!("line {line}: brackets nested deeper than {MAX_NESTING} levels"));
                }
            }
            b'}' | b')' | b']' => depth = depth.saturating_sub(1),
            b'#' => {
                // On to the line's end, which is counted as any other.
                i = skip_past(text, i, b"\n").saturating_sub(1).max(i + 1);
                continue;
            }
            b'"' | b'\'' | b'@' => {
                let quote = &text[i..i + if text[i..].starts_with(&[byte; 3]) { 3 } else { 1 }];
                let end = skip_past(text, i + quote.len(), quote);
                line += text[i..end.min(text.len())].iter().filter(|&&b| b == b'\n').count();
                i = end.saturating_sub(1);
            }
            _ => {}
        }
        i += 1;
    }
    Ok(())
}

/// The index just past the first `end` at or after `from` (a backslash escapes the byte after it); the text's length
/// where there is none.
fn skip_past(text: &[u8], from: usize, end: &[u8]) -> usize {
    let mut i = from;
    while i < text.len() {
        if text[i] == b'\\' && end != b"\n" {
            i += 2;
        } else if text[i..].starts_with(end) {
            return i + end.len();
        } else {
            i += 1;
        }
    }
    text.len()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nesting_counts_brackets_outside_strings_paths_and_comments() {
        let deep = |n: usize| format!("#usda 1.0\n{}{}", "def X {\n".repeat(n), "}\n".repeat(n));
        assert!(check_nesting(deep(MAX_NESTING).as_bytes()).is_ok());
        assert_eq!(
            check_nesting(deep(MAX_NESTING + 1).as_bytes()),
            Err(format!("line {}: brackets nested deeper than {MAX_NESTING} levels", MAX_NESTING + 2))
        );
        let quoted = "#usda 1.0 {{{\ndef X \"{{{{\" ( doc = \"\"\"{{\n\\\"\"\"\" ) { asset a = @{{@ }\n# {{{{\n";
        let inside = quoted.replace("{{", &"{".repeat(MAX_NESTING));
        assert!(check_nesting(inside.as_bytes()).is_ok(), "{inside}");
    }
}
