//! The files a scan covers, from what the command line names.
//!
//! - A file is scanned as named, whatever its content (a file that is not an animation then fails to load, which
//!   the report says).
//! - A folder is walked recursively (symbolic links followed, loops detected by walkdir) and the files in it with an
//!   animation's extension (a format's, [`Format::extensions`], any case) or, without one, an unmistakable signature in
//!   their first 64 KiB (GLB or FBX magic, FBX's ASCII header, BVH's `HIERARCHY`, JSON whose top-level `asset`
//!   states a `version`: [`recognised`]) are scanned: a broken export is an error in the report, never passed over,
//!   and a library's other files (manifests, reports, a test suite's `assets.json`) are left out;
//!   `--include`/`--exclude` globs narrow that down by path relative to the folder (a pattern without a `/`
//!   matches the file name, as `*.fbx`).
//! - A pattern with glob characters that names nothing as written (`'exports/**/*.fbx'`, quoted so the shell left it)
//!   is expanded.
//! - `-` reads one path per line from standard input (each as above).
//!
//! Unreadable entries, symlink loops and names that match nothing are problems the scan reports, not reasons to stop.
//! A folder named that gives no file is listed apart ([`Inputs::empty_folders`]): a scan pointed at the wrong folder
//! would otherwise pass with an empty report.
//! The files come out sorted and without duplicates, so reports do not depend on the order the file system or the
//! threads deliver them in.

use std::io::Read;
use std::path::{Path, PathBuf};

use crate::import::Format;

/// How much of a file is read to recognise its format.
const SNIFF_BYTES: u64 = 64 * 1024;

/// Which files found in folders are scanned.
#[derive(Clone, Debug, Default)]
pub struct Filter {
    include: Vec<glob::Pattern>,
    exclude: Vec<glob::Pattern>,
}

impl Filter {
    /// From `--include` and `--exclude` patterns; an invalid pattern is an error naming it.
    pub fn new(include: &[String], exclude: &[String]) -> Result<Self, String> {
        let parse = |patterns: &[String]| {
            patterns
                .iter()
                .map(|p| glob::Pattern::new(p).map_err(|e| format!("invalid pattern `{p}`: {e}")))
                .collect::<Result<Vec<_>, _>>()
        };
        Ok(Filter { include: parse(include)?, exclude: parse(exclude)? })
    }

    /// Whether `relative` (a path below a walked folder) passes: some include pattern matches (or there is none),
    /// and no exclude pattern does.
    fn admits(&self, relative: &Path) -> bool {
        let matches = |pattern: &glob::Pattern| {
            let name = relative.file_name().map(Path::new).unwrap_or(relative);
            let options = glob::MatchOptions { case_sensitive: false, ..glob::MatchOptions::new() };
            let subject = if pattern.as_str().contains('/') { relative } else { name };
            pattern.matches_path_with(subject, options)
        };
        (self.include.is_empty() || self.include.iter().any(matches)) && !self.exclude.iter().any(matches)
    }
}

/// Something the inputs could not give: a path and what went wrong.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct InputProblem {
    pub path: PathBuf,
    pub message: String,
}

/// One file to scan, and the name that places it in a shard: its path below the folder it was found in, or the
/// path as given (the same on every machine that checks out the library, wherever it lies).
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub struct Found {
    pub path: PathBuf,
    pub key: String,
    /// A path named that cannot be opened (missing, say): in every shard, so that each fails on it as the whole scan
    /// does, rather than all but one passing (the merged report keeps it once).
    pub every_shard: bool,
}

/// The files to scan, sorted by path and distinct, and what could not be read on the way.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Inputs {
    pub files: Vec<Found>,
    pub problems: Vec<InputProblem>,
    /// The folders named (on the command line or in a list, not found by a glob) that gave no file to scan.
    pub empty_folders: Vec<PathBuf>,
}

impl Inputs {
    /// The paths of the files.
    pub fn paths(&self) -> Vec<PathBuf> {
        self.files.iter().map(|f| f.path.clone()).collect()
    }

    /// The paths of the `part`-th of `parts` (1-based) stable parts: a file belongs to part `1 + crc32(key) mod
    /// parts`, so machines scanning the same library agree without talking, and the parts partition it; a path
    /// named that cannot be opened belongs to every part.
    pub fn shard(&self, part: usize, parts: usize) -> Vec<PathBuf> {
        let of = |f: &&Found| f.every_shard || (crc32fast::hash(f.key.as_bytes()) as usize % parts.max(1)) + 1 == part;
        self.files.iter().filter(of).map(|f| f.path.clone()).collect()
    }
}

/// The files `names` stand for (see the module's rules); `stdin` is read for a `-`.
pub fn collect(names: &[PathBuf], filter: &Filter, stdin: &mut dyn Read) -> Inputs {
    let mut inputs = Inputs::default();
    for name in names {
        if name.as_os_str() == "-" {
            let mut list = String::new();
            if let Err(e) = stdin.read_to_string(&mut list) {
                inputs.problem(name, format!("cannot read the list of paths: {e}"));
            }
            for line in list.lines().map(str::trim).filter(|l| !l.is_empty()) {
                inputs.add(Path::new(line), filter);
            }
        } else {
            inputs.add(name, filter);
        }
    }
    inputs.files.sort();
    inputs.files.dedup_by(|a, b| a.path == b.path);
    inputs
}

impl Inputs {
    /// A file named (or listed, or matched by a glob): its key is the path as given.
    fn push_named(&mut self, path: &Path) {
        self.files.push(Found { path: path.to_owned(), key: key_of(path), every_shard: !opens(path) });
    }

    fn problem(&mut self, path: &Path, message: String) {
        self.problems.push(InputProblem { path: path.to_owned(), message });
    }

    /// One name: a folder, a file, or a glob.
    fn add(&mut self, name: &Path, filter: &Filter) {
        if name.is_dir() {
            let before = self.files.len();
            self.walk(name, filter);
            if self.files.len() == before {
                self.empty_folders.push(name.to_owned());
            }
        } else if name.exists() || !is_glob(name) {
            // A file as named; a missing one fails to load in the report, naming it.
            self.push_named(name);
        } else {
            self.expand(name, filter);
        }
    }

    fn expand(&mut self, pattern: &Path, filter: &Filter) {
        let text = pattern.to_string_lossy();
        match glob::glob(&text) {
            Err(e) => self.problem(pattern, format!("invalid pattern: {e}")),
            Ok(paths) => {
                let before = self.files.len();
                for path in paths {
                    match path {
                        Ok(path) if path.is_dir() => self.walk(&path, filter),
                        Ok(path) => self.push_named(&path),
                        Err(e) => self.problem(e.path(), format!("cannot read: {}", e.error())),
                    }
                }
                if self.files.len() == before {
                    self.problem(pattern, "matches no file".to_owned());
                }
            }
        }
    }

    fn walk(&mut self, folder: &Path, filter: &Filter) {
        for entry in walkdir::WalkDir::new(folder).follow_links(true).sort_by_file_name() {
            match entry {
                Err(e) => {
                    let path = e.path().map_or_else(|| folder.to_owned(), Path::to_owned);
                    let message = if e.loop_ancestor().is_some() {
                        "a symbolic link loop: not followed".to_owned()
                    } else {
                        format!("cannot read: {}", e.io_error().map_or_else(|| e.to_string(), ToString::to_string))
                    };
                    self.problem(&path, message);
                }
                Ok(entry) if !entry.file_type().is_dir() => {
                    let relative = entry.path().strip_prefix(folder).unwrap_or(entry.path());
                    // Pipes and devices are never opened here: with an animation's name they fail to load, naming
                    // themselves; without one they are not animations.
                    let animation = Format::named_by(entry.path()).is_some()
                        || (entry.file_type().is_file() && recognised(entry.path()));
                    if filter.admits(relative) && animation {
                        let key = key_of(relative);
                        self.files.push(Found { path: entry.into_path(), key, every_shard: false });
                    }
                }
                Ok(_) => {}
            }
        }
    }
}

/// A path as a shard key: its components joined by `/`, whatever the platform writes.
fn key_of(path: &Path) -> String {
    path.components().map(|c| c.as_os_str().to_string_lossy()).collect::<Vec<_>>().join("/")
}

/// Whether `path` can be opened for reading: a regular file is opened (and closed); anything else that exists counts
/// as openable, since opening a pipe would wait for its writer.
fn opens(path: &Path) -> bool {
    match std::fs::metadata(path) {
        Ok(meta) if meta.is_file() => std::fs::File::open(path).is_ok(),
        Ok(_) => true,
        Err(_) => false,
    }
}

/// Whether `path` has glob characters.
fn is_glob(path: &Path) -> bool {
    path.to_string_lossy().contains(['*', '?', '['])
}

/// Whether a file not named as an animation carries a signature that cannot be mistaken, as a pipeline tells its
/// files apart: GLB's magic, FBX's binary magic or ASCII header, BVH's `HIERARCHY`, USD's `#usda` or `PXR-USDC`, or JSON whose top-level `asset`
/// states a `version` (every glTF's does; a manifest's `{"asset": {"generator": …}}`, a test suite's `assets.json` or
/// a tool's report does not). JSON larger than what is read cannot show that whole, and is left out.
fn recognised(path: &Path) -> bool {
    let mut head = Vec::new();
    let read = std::fs::File::open(path).and_then(|f| f.take(SNIFF_BYTES).read_to_end(&mut head));
    match (read, crate::import::detect(&head)) {
        (Ok(_), Some(Format::Gltf)) if !head.starts_with(b"glTF") => {
            (head.len() as u64) < SNIFF_BYTES && states_gltf_version(&head)
        }
        (Ok(_), format) => format.is_some(),
        (Err(_), _) => false,
    }
}

/// Whether `json` is an object whose `asset` states a `version`.
fn states_gltf_version(json: &[u8]) -> bool {
    let value: Option<serde_json::Value> = serde_json::from_slice(json).ok();
    value.is_some_and(|v| v.get("asset").and_then(|asset| asset.get("version")).is_some())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A folder of exports: animations in sub-folders, a text file, and an FBX named `.txt`.
    fn library() -> tempfile::TempDir {
        let dir = tempfile::tempdir().unwrap();
        let root = dir.path();
        std::fs::create_dir_all(root.join("chars/hero")).unwrap();
        std::fs::create_dir_all(root.join("mocap")).unwrap();
        std::fs::write(root.join("chars/hero/run.fbx"), b"; FBX 7.4.0 project file\n").unwrap();
        std::fs::write(root.join("chars/hero/walk.glb"), b"glTF\x02\0\0\0").unwrap();
        std::fs::write(root.join("mocap/take1.bvh"), b"HIERARCHY\nROOT hips\n").unwrap();
        std::fs::write(root.join("mocap/notes.txt"), b"not an animation").unwrap();
        std::fs::write(root.join("mocap/renamed.txt"), b"Kaydara FBX Binary  \0rest").unwrap();
        std::fs::write(root.join("mocap/report.json"), b"{ \"issues\": [] }").unwrap();
        std::fs::write(root.join("chars/hero/idle.gltf"), b"{ \"asset\": { \"version\": \"2.0\" } }").unwrap();
        dir
    }

    fn names(inputs: &Inputs, root: &Path) -> Vec<String> {
        inputs.files.iter().map(|f| f.path.strip_prefix(root).unwrap().to_string_lossy().replace('\\', "/")).collect()
    }

    #[test]
    fn shards_partition_the_library_by_relative_path() {
        let dir = tempfile::tempdir().unwrap();
        for i in 0..40 {
            std::fs::write(dir.path().join(format!("take{i:02}.bvh")), b"HIERARCHY\n").unwrap();
        }
        let inputs = collect(&[dir.path().to_owned()], &Filter::default(), &mut std::io::empty());
        let parts: Vec<Vec<PathBuf>> = (1..=3).map(|k| inputs.shard(k, 3)).collect();
        let mut union: Vec<PathBuf> = parts.concat();
        union.sort();
        assert_eq!(union, inputs.paths(), "every file in exactly one part");
        assert!(parts.iter().all(|p| !p.is_empty()), "{:?}", parts.iter().map(Vec::len).collect::<Vec<_>>());
        // The same library elsewhere (another checkout) gives the same parts: keys are relative.
        let elsewhere = tempfile::tempdir().unwrap();
        for i in 0..40 {
            std::fs::write(elsewhere.path().join(format!("take{i:02}.bvh")), b"HIERARCHY\n").unwrap();
        }
        let there = collect(&[elsewhere.path().to_owned()], &Filter::default(), &mut std::io::empty());
        let file_names =
            |paths: Vec<PathBuf>| paths.iter().map(|p| p.file_name().unwrap().to_owned()).collect::<Vec<_>>();
        assert_eq!(file_names(there.shard(2, 3)), file_names(inputs.shard(2, 3)));
    }

    #[test]
    fn a_named_path_that_cannot_be_opened_is_in_every_shard() {
        let dir = library();
        let missing = dir.path().join("missing");
        let inputs = collect(&[dir.path().to_owned(), missing.clone()], &Filter::default(), &mut std::io::empty());
        let parts: Vec<Vec<PathBuf>> = (1..=8).map(|k| inputs.shard(k, 8)).collect();
        assert!(parts.iter().all(|p| p.contains(&missing)), "{parts:?}");
        let found: usize = parts.iter().map(|p| p.iter().filter(|&path| path != &missing).count()).sum();
        assert_eq!(found, inputs.files.len() - 1, "the folder's files still in one part each");
    }

    #[test]
    fn folders_give_their_animations_by_content_sorted() {
        let dir = library();
        let root = dir.path();
        std::fs::write(root.join("mocap/manifest.json"), br#"{"asset": {"generator": "x"}}"#).unwrap();
        std::fs::write(root.join("mocap/assets.json"), br#"[{"asset": {"version": "2.0"}}]"#).unwrap();
        std::fs::write(root.join("mocap/model.json"), br#"{"asset": {"version": "2.0"}, "nodes": []}"#).unwrap();
        let inputs = collect(&[dir.path().to_owned()], &Filter::default(), &mut std::io::empty());
        let expected = [
            "chars/hero/idle.gltf",
            "chars/hero/run.fbx",
            "chars/hero/walk.glb",
            "mocap/model.json",
            "mocap/renamed.txt",
            "mocap/take1.bvh",
        ];
        // Not the JSON report, nor a manifest whose `asset` states no version, nor a list of assets.
        assert_eq!(names(&inputs, dir.path()), expected);
        assert!(inputs.problems.is_empty(), "{:?}", inputs.problems);
    }

    #[test]
    fn files_named_as_animations_are_scanned_whatever_their_content() {
        let dir = library();
        let root = dir.path();
        std::fs::write(root.join("mocap/bad_magic.glb"), b"glTX\x02\0\0\0").unwrap();
        std::fs::write(root.join("mocap/empty.GLTF"), b"").unwrap();
        std::fs::write(root.join("mocap/stl.gltf"), b"solid cube\n").unwrap();
        std::fs::write(root.join("mocap/readme.md"), b"solid cube\n").unwrap();
        let inputs = collect(&[root.to_owned()], &Filter::default(), &mut std::io::empty());
        let names = names(&inputs, root);
        for name in ["mocap/bad_magic.glb", "mocap/empty.GLTF", "mocap/stl.gltf"] {
            assert!(names.contains(&name.to_owned()), "{name} in {names:?}");
        }
        assert!(!names.iter().any(|n| n.ends_with("readme.md") || n.ends_with("notes.txt")), "{names:?}");
    }

    #[test]
    fn include_and_exclude_narrow_the_walk() {
        let dir = library();
        let only_fbx = Filter::new(&["*.FBX".into()], &[]).unwrap();
        let inputs = collect(&[dir.path().to_owned()], &only_fbx, &mut std::io::empty());
        assert_eq!(names(&inputs, dir.path()), ["chars/hero/run.fbx"], "case-insensitive, by name");
        let no_mocap = Filter::new(&[], &["mocap/*".into()]).unwrap();
        let inputs = collect(&[dir.path().to_owned()], &no_mocap, &mut std::io::empty());
        let chars = ["chars/hero/idle.gltf", "chars/hero/run.fbx", "chars/hero/walk.glb"];
        assert_eq!(names(&inputs, dir.path()), chars, "by relative path");
        assert!(Filter::new(&["[".into()], &[]).unwrap_err().contains("invalid pattern `[`"));
    }

    #[test]
    fn globs_lists_and_files_as_named() {
        let dir = library();
        let root = dir.path();
        let pattern = root.join("**/*.bvh");
        let list = format!("{}\n\n{}\n", root.join("chars/hero/run.fbx").display(), root.join("mocap").display());
        let named = [pattern, PathBuf::from("-"), root.join("mocap/notes.txt"), root.join("missing/*.fbx")];
        let inputs = collect(&named, &Filter::default(), &mut list.as_bytes());
        // The glob's BVH, the listed FBX and folder (its animations), the text file named on its own.
        let expected = ["chars/hero/run.fbx", "mocap/notes.txt", "mocap/renamed.txt", "mocap/take1.bvh"];
        assert_eq!(names(&inputs, root), expected);
        assert_eq!(inputs.problems.len(), 1);
        assert_eq!(inputs.problems[0].message, "matches no file");
    }

    #[test]
    fn named_folders_that_give_no_file_are_listed() {
        let dir = library();
        let root = dir.path();
        std::fs::create_dir(root.join("empty")).unwrap();
        // `mocap` has animations, none named `*.fbx`; a folder a glob finds is not named, nor listed.
        let named = [root.join("mocap"), root.join("chars"), root.join("empty"), root.join("e*")];
        let only_fbx = Filter::new(&["*.fbx".into()], &[]).unwrap();
        let inputs = collect(&named, &only_fbx, &mut std::io::empty());
        assert_eq!(inputs.empty_folders, [root.join("mocap"), root.join("empty")]);
        assert_eq!(names(&inputs, root), ["chars/hero/run.fbx"]);
    }

    #[cfg(unix)]
    #[test]
    fn symlink_loops_are_reported_not_followed() {
        let dir = library();
        std::os::unix::fs::symlink(dir.path(), dir.path().join("mocap/back")).unwrap();
        let inputs = collect(&[dir.path().to_owned()], &Filter::default(), &mut std::io::empty());
        assert_eq!(names(&inputs, dir.path()).len(), 5);
        assert_eq!(inputs.problems.len(), 1, "{:?}", inputs.problems);
        assert!(inputs.problems[0].message.contains("loop"));
    }
}
