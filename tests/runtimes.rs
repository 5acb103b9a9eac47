//! Real runtimes as pose-dump writers, and what `fit` finds they do with each bone's inheritance:
//! `examples/dump_threejs.mjs` (three.js: GLTFLoader or FBXLoader + AnimationMixer), `examples/dump_babylonjs.mjs`
//! (Babylon.js: NullEngine + its glTF loader), `examples/dump_blender.py` (Blender's glTF and FBX importers) and
//! `examples/dump_godot.gd` (Godot 3.2's glTF importer + AnimationPlayer).
//!
//! - On glTF every runtime plays `full` on every bone (all compose full matrices, shear kept). Blender and Godot
//!   play cubic-spline keys as other curves, so a cubic-spline rig is judged through its bake there.
//! - On FBX each importer's handling of the declared inherit types is a finding, asserted bone by bone.
//! - `bake --for ENGINE` of an FBX, played by that engine, fits `declared`: the bake fixes what the runtime breaks.
//!
//! The node runtimes run where `node` and the pinned package (`npm ci` in `tests/threejs`, `tests/babylonjs`) are
//! there, Blender where `BONESCOPE_BLENDER_PYTHON` names a Python with its module, Godot where `godot3` and
//! `xvfb-run` are installed; each is skipped with a message otherwise.

mod common;

use std::collections::BTreeMap;
use std::ffi::OsStr;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use common::{asset, blender_python, bonescope, corpus};
use serde_json::Value;

const MAYA_MIXED: &str = "fbx-ufbx-data/maya_mixed_inherit_mode_7700_ascii.fbx";

/// A runtime that plays a file and writes what it computed as a pose dump.
enum Runtime {
    /// A Node script of `examples/`, run in the folder its pinned package is installed in; the dump on stdout.
    Node { script: &'static str, folder: PathBuf },
    /// `examples/dump_blender.py` run by a Python with Blender's module; the dump written to a file.
    Blender(PathBuf),
    /// `examples/dump_godot.gd` run by Godot 3 (`godot3`) in a project made for the file, under `xvfb-run`: its
    /// editor imports a file only with a display.
    Godot,
}

impl Runtime {
    /// The Node runtime pinned under `tests/FOLDER`, where it (its `package`) and `node` are installed.
    fn node(script: &'static str, folder: &str, package: &str) -> Option<Runtime> {
        let folder = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests").join(folder);
        let node = Command::new("node").arg("--version").output().is_ok_and(|o| o.status.success());
        if !(node && folder.join("node_modules").join(package).join("package.json").exists()) {
            eprintln!("skipped: needs node and {package} (`npm ci` in {})", folder.display());
            return None;
        }
        Some(Runtime::Node { script, folder })
    }

    fn three() -> Option<Runtime> {
        Runtime::node("dump_threejs.mjs", "threejs", "three")
    }

    fn blender() -> Option<Runtime> {
        blender_python().map(Runtime::Blender)
    }

    fn godot() -> Option<Runtime> {
        // `godot3 --version` exits 255 whatever it prints: a program is there when it runs at all.
        let there = |program: &str, arg: &str| Command::new(program).arg(arg).output().is_ok();
        if !(there("godot3", "--version") && there("xvfb-run", "--help")) {
            eprintln!("skipped: needs Godot 3 and Xvfb (`apt-get install godot3 xvfb`; .ci/run does)");
            return None;
        }
        Some(Runtime::Godot)
    }

    /// The runtime's run of its script on `file` (its animation `clip`, else the first), the dump going to `dump`.
    fn run(&self, file: &Path, clip: Option<&str>, dump: &Path) -> Output {
        let examples = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples");
        let run = match self {
            Runtime::Node { script, folder } => {
                Command::new("node").arg(examples.join(script)).arg(file).args(clip).current_dir(folder).output()
            }
            Runtime::Blender(python) => {
                Command::new(python).arg(examples.join("dump_blender.py")).arg(file).arg(dump).args(clip).output()
            }
            Runtime::Godot => {
                let (project, name) = godot_project(file, dump);
                let script = examples.join("dump_godot.gd");
                let args = [OsStr::new("--no-window"), OsStr::new("-s"), script.as_os_str(), name.as_os_str()];
                godot(&project, &args).arg(dump).args(clip).output()
            }
        };
        let run = run.unwrap();
        if run.status.success() && matches!(self, Runtime::Node { .. }) {
            std::fs::write(dump, &run.stdout).unwrap();
        }
        run
    }

    /// The dump of `file` (its animation `clip`, else the first), written in `folder`.
    fn dump(&self, file: &Path, clip: Option<&str>, folder: &Path) -> PathBuf {
        let dump = folder.join("runtime.dump.json");
        let run = self.run(file, clip, &dump);
        assert!(run.status.success(), "{}: {}", file.display(), String::from_utf8_lossy(&run.stderr));
        dump
    }
}

/// Godot 3 in `project` with `args`, under Xvfb, given two minutes (a script that fails leaves Godot running).
fn godot(project: &Path, args: &[&OsStr]) -> Command {
    let mut godot = Command::new("timeout");
    godot.args(["120", "xvfb-run", "-a", "godot3", "--path"]).arg(project).args(args);
    godot
}

/// A Godot project beside `dump` holding a copy of `file`, imported by Godot's editor; and the copy's name in it.
/// Godot's glTF importer resamples every track at its `animation/fps` (15 unless told) and thins the keys with its
/// optimizer (5 cm off by default): 120 fps and no optimizer keep what the file plays.
fn godot_project(file: &Path, dump: &Path) -> (PathBuf, PathBuf) {
    let project = dump.with_extension("godot");
    std::fs::create_dir_all(&project).unwrap();
    std::fs::write(project.join("project.godot"), "config_version=4\n").unwrap();
    let name = PathBuf::from(file.file_name().unwrap());
    std::fs::copy(file, project.join(&name)).unwrap();
    let options = "[remap]\nimporter=\"scene\"\ntype=\"PackedScene\"\n\n[params]\nanimation/fps=120\n\
                   animation/optimizer/enabled=false\n";
    std::fs::write(project.join(format!("{}.import", name.display())), options).unwrap();
    let imported = godot(&project, &[OsStr::new("--editor"), OsStr::new("--quit")]).output().unwrap();
    assert!(imported.status.success(), "{}: {}", file.display(), String::from_utf8_lossy(&imported.stderr));
    (project, name)
}

/// `bonescope fit SOURCE DUMP --format json` (its animation `clip`, else the dump's): the report, whether or not a
/// mode fits.
fn fit(source: &Path, dump: &Path, clip: Option<&str>) -> Value {
    let mut args = vec!["fit", source.to_str().unwrap(), dump.to_str().unwrap(), "--format", "json"];
    args.extend(clip.iter().flat_map(|clip| ["--anim", clip]));
    let out = bonescope(&args);
    assert!(matches!(out.status.code(), Some(0 | 1)), "fit: {}", String::from_utf8_lossy(&out.stderr));
    serde_json::from_slice(&out.stdout).expect("valid JSON")
}

/// The choices that fit every bone of a fit's report.
fn fits(report: &Value) -> Vec<&str> {
    report["fits"].as_array().unwrap().iter().map(|f| f.as_str().unwrap()).collect()
}

/// The choices that fit each bone of a fit's report, by name.
fn bone_fits(report: &Value) -> BTreeMap<&str, Vec<&str>> {
    let bones = report["bones"].as_array().unwrap().iter();
    bones
        .map(|b| (b["name"].as_str().unwrap(), b["fits"].as_array().unwrap().iter().flat_map(Value::as_str).collect()))
        .collect()
}

/// Plays `file` (its animation `clip`) by `runtime` and fits the dump to it; asserts that `full` fits every bone,
/// and that at least `paired` bones were paired.
fn plays_as_full(runtime: &Runtime, file: &Path, clip: Option<&str>, paired: usize) {
    let out = tempfile::tempdir().unwrap();
    let report = fit(file, &runtime.dump(file, clip, out.path()), clip);
    assert!(fits(&report).contains(&"full"), "{}: {report}", file.display());
    assert!(bone_fits(&report).len() >= paired, "{}: every joint paired: {report}", file.display());
}

/// `bake FILE --for ENGINE`, played by `runtime` and dumped, fits the source's `declared` modes on every bone (within
/// the fit's tolerance, 0.01 % of the rig: the bake's own bound is the same fraction of its rig).
fn bake_plays_as_declared(runtime: &Runtime, engine: &str, file: &str, clip: Option<&str>) {
    let out = tempfile::tempdir().unwrap();
    let (source, baked) = (asset(file), out.path().join("baked.glb"));
    let mut bake = vec!["bake", source.to_str().unwrap(), "--for", engine, "--out", baked.to_str().unwrap()];
    bake.extend(clip.iter().flat_map(|clip| ["--anim", clip]));
    let baked_run = bonescope(&bake);
    assert!(baked_run.status.success(), "{file}: {}", String::from_utf8_lossy(&baked_run.stderr));
    let report = fit(&source, &runtime.dump(&baked, None, out.path()), clip);
    assert!(fits(&report).contains(&"declared"), "{file} baked for {engine}: {report}");
}

#[test]
fn three_js_plays_the_stretchy_rigs_as_full() {
    if let Some(three) = Runtime::three() {
        for file in ["blender/stretchy_full.glb", "blender/stretchy_noinherit.glb"] {
            plays_as_full(&three, &asset(file), Some("squash_stretch"), 8);
        }
    }
}

#[test]
fn babylon_js_plays_the_stretchy_rigs_as_full() {
    if let Some(babylon) = Runtime::node("dump_babylonjs.mjs", "babylonjs", "@babylonjs/core") {
        for file in ["blender/stretchy_full.glb", "blender/stretchy_noinherit.glb"] {
            plays_as_full(&babylon, &asset(file), Some("squash_stretch"), 8);
        }
    }
}

/// three.js #14903, confirmed bone by bone: FBXLoader composes every bone's full matrix, whatever its inherit type.
/// Of Maya's mixed-inheritance file, the three joints that declare segment scale compensation (Rrs) fit `full`
/// alone (within 3e-6 of 22.4 cm), not what they declare; the file as a whole fits `full` only.
#[test]
fn three_js_fbx_loader_plays_segment_compensation_as_full() {
    let Some(three) = Runtime::three() else { return };
    let (out, source) = (tempfile::tempdir().unwrap(), asset(MAYA_MIXED));
    let report = fit(&source, &three.dump(&source, None, out.path()), None);
    assert_eq!(fits(&report), ["full"], "{report}");
    let bones = bone_fits(&report);
    for compensated in ["Left_Tip", "Right", "Right_Tip"] {
        assert_eq!(bones[compensated], ["full"], "{compensated}: {report}");
    }
}

/// three.js FBXLoader (r170) on Blender's FBX: no mode fits, and not for inheritance. Blender's exporter simplifies
/// each Euler curve on its own, and FBXLoader's `interpolateRotations` walks the X curve's keys and reads the Y and
/// Z curves at the same indices: `upper_arm`'s rotation track keeps 2 keys of 61, and it is the first bone no mode
/// fits (17 cm off on its way), its parents fitting every mode. Its bake, glTF, plays as declared (below).
#[test]
fn three_js_fbx_loader_misreads_blenders_euler_curves() {
    let Some(three) = Runtime::three() else { return };
    let (out, source, clip) =
        (tempfile::tempdir().unwrap(), asset("blender/stretchy_full.fbx"), "Stretchy|squash_stretch");
    let report = fit(&source, &three.dump(&source, Some(clip), out.path()), Some(clip));
    assert!(fits(&report).is_empty(), "{report}");
    assert_eq!(report["miss"]["bone"], "upper_arm", "{report}");
    let any = |name: &str| report["bones"].as_array().unwrap().iter().any(|b| b["name"] == name && b["any"] == true);
    assert!(["hips", "spine", "chest"].into_iter().all(any), "{report}");
}

/// The bakes for three.js, played by its GLTFLoader: the Maya file's segment compensation, which FBXLoader drops,
/// comes out as the source evaluates it.
#[test]
fn three_js_plays_its_bakes_as_declared() {
    if let Some(three) = Runtime::three() {
        bake_plays_as_declared(&three, "three", MAYA_MIXED, None);
        bake_plays_as_declared(&three, "three", "blender/stretchy_noinherit.fbx", None);
    }
}

/// Blender's glTF importer composes full matrices (its bones' `FULL` inherit scale). Godot's mannequin has linear
/// keys, which Blender keeps; the stretchy rigs' cubic-spline keys it turns into Bézier keys with automatic handles,
/// not the file's tangents, so between a channel's keys it plays another curve (up to 8 cm off on the stretchy
/// rig's hand): their glTF is judged through the bake, whose keys are linear, at every frame.
#[test]
fn blender_plays_gltf_as_full() {
    if let Some(blender) = Runtime::blender() {
        plays_as_full(&blender, &corpus("realworld/godot_mannequiny.glb"), None, 40);
    }
}

/// Blender's FBX importer never reads an FBX inherit type: every bone it makes inherits scale `FULL`. Blender's own
/// FBX files declare full inheritance on every bone (its exporter bakes "don't inherit scale" into the keys), and
/// Blender plays both as `full`, bone by bone. Maya's mixed-inheritance file is ASCII, which Blender's importer
/// refuses outright ("ASCII FBX files are not supported"): its inherit types never reach Blender.
#[test]
fn blender_plays_fbx_as_full() {
    let Some(blender) = Runtime::blender() else { return };
    for file in ["blender/stretchy_full.fbx", "blender/stretchy_noinherit.fbx"] {
        plays_as_full(&blender, &asset(file), None, 8);
    }
    let out = tempfile::tempdir().unwrap();
    let refused = blender.run(&asset(MAYA_MIXED), None, &out.path().join("runtime.dump.json"));
    let stderr = String::from_utf8_lossy(&refused.stderr);
    assert!(!refused.status.success() && stderr.contains("ASCII FBX files are not supported"), "{stderr}");
}

/// The bakes for Blender, played by its glTF importer: the Maya file's segment compensation and the stretchy rig's
/// cubic splines come out as their source evaluates them.
#[test]
fn blender_plays_its_bakes_as_declared() {
    if let Some(blender) = Runtime::blender() {
        bake_plays_as_declared(&blender, "blender", MAYA_MIXED, None);
        bake_plays_as_declared(&blender, "blender", "blender/stretchy_full.glb", Some("squash_stretch"));
        bake_plays_as_declared(&blender, "blender", "blender/stretchy_noinherit.fbx", None);
    }
}

/// Godot 3.2's Skeleton composes full transforms (a `Basis` keeps shear); the bakes for Godot, played by its glTF
/// importer and AnimationPlayer, come out as their source evaluates them. (Of the raw stretchy glTF Godot plays the
/// cubic-spline rotations as other curves, up to 12 cm off on the hand, and of Godot's own mannequin it renames the
/// bones, `spine_01` to `spine_1`, so that none pairs: both are left to the bake.)
#[test]
fn godot_plays_its_bakes_as_declared() {
    if let Some(godot) = Runtime::godot() {
        bake_plays_as_declared(&godot, "godot", MAYA_MIXED, None);
        bake_plays_as_declared(&godot, "godot", "blender/stretchy_full.glb", Some("squash_stretch"));
    }
}
