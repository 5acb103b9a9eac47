//! three.js as a runtime: `examples/dump_threejs.mjs` plays the shared stretchy glTF rigs with GLTFLoader and
//! AnimationMixer and dumps every node's `matrixWorld`; `fit` must find `full` on every bone (three.js composes
//! full matrices, shear kept). Runs where `node` and the pinned three.js (`npm ci` in `tests/threejs`) are there;
//! skipped with a message otherwise.

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;

use common::{asset, bonescope, json};

/// The folder of the pinned three.js, where it and `node` are installed.
fn three() -> Option<PathBuf> {
    let folder = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/threejs");
    let node = Command::new("node").arg("--version").output().is_ok_and(|o| o.status.success());
    let installed = folder.join("node_modules/three/package.json").exists();
    if !(node && installed) {
        eprintln!("skipped: needs node and three.js (`npm ci` in tests/threejs)");
        return None;
    }
    Some(folder)
}

#[test]
fn three_js_plays_the_stretchy_rigs_as_full() {
    let Some(folder) = three() else { return };
    let out = tempfile::tempdir().unwrap();
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/dump_threejs.mjs");
    for (file, clip) in
        [("blender/stretchy_full.glb", "squash_stretch"), ("blender/stretchy_noinherit.glb", "squash_stretch")]
    {
        let source = asset(file);
        let dumped = Command::new("node").arg(&script).arg(&source).arg(clip).current_dir(&folder).output().unwrap();
        assert!(dumped.status.success(), "{}", String::from_utf8_lossy(&dumped.stderr));
        let dump = out.path().join("three.dump.json");
        std::fs::write(&dump, &dumped.stdout).unwrap();
        let report = json(&bonescope(&["fit", source.to_str().unwrap(), dump.to_str().unwrap(), "--format", "json"]));
        assert!(report["fits"].as_array().unwrap().iter().any(|f| f == "full"), "{file}: {report}");
        assert!(report["bones"].as_array().unwrap().len() >= 8, "{file}: every joint paired");
    }
}
