//! The formats bonescope reads, as one table: each one's name and the extensions of its files, from which every list
//! of formats is made (a folder scan's, the file dialogs' filters, the command line's help and errors). What a file
//! is read as is decided by its content ([`super::detect`]); its name only picks files out of a folder.

use std::path::Path;

/// The formats bonescope reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// glTF 2.0, JSON (`.gltf`) or binary (`.glb`).
    Gltf,
    /// FBX, binary or ASCII, any version ufbx reads (5.x to 7.x).
    Fbx,
    /// Biovision Hierarchy motion capture.
    Bvh,
    /// OpenUSD (UsdSkel), text (`.usda`), binary (`.usdc`) or packaged (`.usdz`); `.usd` is either of the first two.
    Usd,
    /// A runtime's evaluated matrices, JSON or CSV (`docs/pose-dump.md`); recognised by content, named
    /// `.dump.json`/`.dump.csv` for folder scans.
    PoseDump,
}

impl Format {
    /// Every format, in the order lists name them.
    pub const ALL: [Format; 5] = [Format::Gltf, Format::Fbx, Format::Bvh, Format::Usd, Format::PoseDump];

    /// The name people know it by.
    pub fn name(self) -> &'static str {
        match self {
            Format::Gltf => "glTF",
            Format::Fbx => "FBX",
            Format::Bvh => "BVH",
            Format::Usd => "USD",
            Format::PoseDump => "pose dump",
        }
    }

    /// The extensions of its files, lower case, without the dot.
    pub fn extensions(self) -> &'static [&'static str] {
        match self {
            Format::Gltf => &["gltf", "glb"],
            Format::Fbx => &["fbx"],
            Format::Bvh => &["bvh"],
            Format::Usd => &["usd", "usda", "usdc", "usdz"],
            Format::PoseDump => &["dump.json", "dump.csv"],
        }
    }

    /// Every format's extensions.
    pub fn every_extension() -> impl Iterator<Item = &'static str> {
        Format::ALL.into_iter().flat_map(|format| format.extensions().iter().copied())
    }

    /// The format whose extension `path` has (any case; `walk.dump.json` has `dump.json`).
    pub fn named_by(path: &Path) -> Option<Format> {
        let name = path.file_name()?.to_str()?.to_ascii_lowercase();
        let named =
            |e: &&str| name.len() > e.len() + 1 && name.ends_with(e) && name[..name.len() - e.len()].ends_with('.');
        Format::ALL.into_iter().find(|format| format.extensions().iter().any(named))
    }

    /// Every format for people to read: its name, and its extensions where it has several
    /// (`glTF .gltf/.glb, FBX, BVH, USD .usd/.usda/.usdc/.usdz`).
    pub fn listed() -> String {
        let one = |format: Format| match format.extensions() {
            [_] => format.name().to_owned(),
            several => format!("{} .{}", format.name(), several.join("/.")),
        };
        Format::ALL.map(one).join(", ")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_file_s_extension_names_its_format_in_any_case() {
        assert_eq!(Format::named_by(Path::new("walk.GLB")), Some(Format::Gltf));
        assert_eq!(Format::named_by(Path::new("rig.usdz")), Some(Format::Usd));
        assert_eq!(Format::named_by(Path::new("a/b.Bvh")), Some(Format::Bvh));
        assert_eq!(Format::named_by(Path::new("notes.txt")), None);
        assert_eq!(Format::named_by(Path::new("fbx")), None, "a name without an extension");
        assert_eq!(Format::named_by(Path::new("three/Walk.Dump.JSON")), Some(Format::PoseDump));
        assert_eq!(Format::named_by(Path::new("log.dump.csv")), Some(Format::PoseDump));
        assert_eq!(Format::named_by(Path::new("report.json")), None, "JSON alone is no dump");
        assert_eq!(Format::named_by(Path::new(".glb")), None, "a hidden file named only by its extension");
        assert_eq!(Format::every_extension().count(), 10);
        assert_eq!(
            Format::listed(),
            "glTF .gltf/.glb, FBX, BVH, USD .usd/.usda/.usdc/.usdz, pose dump .dump.json/.dump.csv"
        );
    }
}
