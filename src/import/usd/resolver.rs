//! Finding the assets a stage names (sublayers, references, payloads) as USD's default resolver does, but only
//! inside the root layer's folder: a file may not make bonescope read anything outside it.

use std::io;
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
        if !self.inside(resolved) {
            let message = format!("{} is outside the file's folder: not read", resolved.to_string_lossy());
            return Err(io::Error::new(io::ErrorKind::PermissionDenied, message));
        }
        self.inner.open_asset(resolved)
    }

    fn identity(&self) -> String {
        format!("bonescope folder {}", self.folder.display())
    }
}
