//! Real runtimes as pose-dump writers: `examples/dump_threejs.mjs` (three.js, GLTFLoader + AnimationMixer) and
//! `examples/dump_babylonjs.mjs` (Babylon.js, NullEngine + its glTF loader) play the shared stretchy glTF rigs and
//! dump every node's world matrix; `fit` must find `full` on every bone (both compose full matrices, shear kept).
//! Each runs where `node` and its pinned runtime (`npm ci` in `tests/threejs`, `tests/babylonjs`) are there, and is
//! skipped with a message otherwise.

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;

use common::{asset, bonescope, json};

/// The folder of a runtime pinned under `tests/FOLDER`, where it (its `package`) and `node` are installed.
fn installed(folder: &str, package: &str) -> Option<PathBuf> {
    let folder = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests").join(folder);
    let node = Command::new("node").arg("--version").output().is_ok_and(|o| o.status.success());
    if !(node && folder.join("node_modules").join(package).join("package.json").exists()) {
        eprintln!("skipped: needs node and {package} (`npm ci` in {})", folder.display());
        return None;
    }
    Some(folder)
}

/// Runs `script` (in `examples/`) in `folder` on each stretchy rig's `squash_stretch` and fits its dump.
fn plays_as_full(script: &str, folder: &Path) {
    let out = tempfile::tempdir().unwrap();
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples").join(script);
    for file in ["blender/stretchy_full.glb", "blender/stretchy_noinherit.glb"] {
        let source = asset(file);
        let run = Command::new("node").arg(&script).arg(&source).arg("squash_stretch").current_dir(folder).output();
        let dumped = run.unwrap();
        assert!(dumped.status.success(), "{file}: {}", String::from_utf8_lossy(&dumped.stderr));
        let dump = out.path().join("runtime.dump.json");
        std::fs::write(&dump, &dumped.stdout).unwrap();
        let report = json(&bonescope(&["fit", source.to_str().unwrap(), dump.to_str().unwrap(), "--format", "json"]));
        assert!(report["fits"].as_array().unwrap().iter().any(|f| f == "full"), "{file}: {report}");
        assert!(report["bones"].as_array().unwrap().len() >= 8, "{file}: every joint paired: {report}");
    }
}

#[test]
fn three_js_plays_the_stretchy_rigs_as_full() {
    if let Some(folder) = installed("threejs", "three") {
        plays_as_full("dump_threejs.mjs", &folder);
    }
}

#[test]
fn babylon_js_plays_the_stretchy_rigs_as_full() {
    if let Some(folder) = installed("babylonjs", "@babylonjs/core") {
        plays_as_full("dump_babylonjs.mjs", &folder);
    }
}
