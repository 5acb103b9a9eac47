//! `bake` against every shared asset under every inheritance mode, with `diff` and the Khronos glTF-Validator as
//! the judges: the baked glTF read back by bonescope's own importer must reproduce the source's evaluation (exactly
//! at the sampled times when every sample is kept, within the tolerance anywhere with the default key reduction),
//! its skinned vertices must equal the source's, Maya's own geometry must come out of the baked Maya file, and the
//! validator must find no error in any file written.
//!
//! Tolerances: "exact" is 1e-6 of the rig's size (glTF stores single precision: 6e-8 relative per number, a few
//! times that down a chain of bones); between samples the bake's own `--tolerance` (1e-4 of the rig's size).

mod common;

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::LazyLock;

use bonescope::bake::{self, Request, Strategy};
use bonescope::diff::{Pairs, compare, comparison_times};
use bonescope::eval::Evaluation;
use bonescope::eval::layers::RotationInterpolation;
use bonescope::import;
use bonescope::model::{Choice, InheritMode, Rig, Span};
use common::{ANIMATED, asset, bonescope, obj_positions, size};
use rayon::prelude::*;
use serde_json::Value;

/// The demo rig stands beside the files.
const DEMO: &str = "demo";

/// Exact: 1e-6 of the rig's size.
const EXACT: f64 = 1e-6;

/// A diff rate that visits the frames and their midpoints at 24, 30, 60 and 120 fps (and 25 times between).
const DENSE_RATE: f64 = 1200.0;

/// `None` is each bone's declared mode.
fn modes() -> Vec<Option<InheritMode>> {
    std::iter::once(None).chain(InheritMode::ALL.iter().copied().map(Some)).collect()
}

fn label(mode: Option<InheritMode>) -> &'static str {
    mode.map_or("declared", InheritMode::id)
}

static RIGS: LazyLock<HashMap<&'static str, Rig>> = LazyLock::new(|| {
    let mut rigs: HashMap<&str, Rig> = ANIMATED.par_iter().map(|&f| (f, import::load(&asset(f)).unwrap())).collect();
    rigs.insert(DEMO, import::demo_rig());
    rigs
});

fn sources() -> Vec<&'static str> {
    ANIMATED.iter().copied().chain([DEMO]).collect()
}

/// One bake of one source under one mode.
struct Baked {
    source: &'static str,
    mode: Option<InheritMode>,
    baked: bake::Baked,
    rig: Rig,
}

fn request(source: &'static str, mode: Option<InheritMode>, strategy: Strategy, tolerance: f64) -> Request<'static> {
    let rig = &RIGS[source];
    let modes = mode.map_or_else(|| rig.skeleton.declared_modes(), |m| vec![m; rig.skeleton.len()]);
    Request::every_clip(&Evaluation::new(rig, None, &modes).unwrap(), None, strategy, tolerance)
}

fn bake_all(strategy: Strategy, tolerance: f64) -> Vec<Baked> {
    let jobs: Vec<(&str, Option<InheritMode>)> =
        sources().into_iter().flat_map(|s| modes().into_iter().map(move |m| (s, m))).collect();
    jobs.into_par_iter()
        .map(|(source, mode)| {
            let baked = bake::bake(&request(source, mode, strategy, tolerance));
            let rig = import::load_bytes(Path::new("baked.glb"), &baked.bytes)
                .unwrap_or_else(|e| panic!("{source} ({}): the bake does not read back: {e}", label(mode)));
            Baked { source, mode, baked, rig }
        })
        .collect()
}

static DEFAULT: LazyLock<Vec<Baked>> = LazyLock::new(|| bake_all(Strategy::Exact, bake::DEFAULT_TOLERANCE));
static EVERY_SAMPLE: LazyLock<Vec<Baked>> = LazyLock::new(|| bake_all(Strategy::Exact, 0.0));
static TRS: LazyLock<Vec<Baked>> = LazyLock::new(|| bake_all(Strategy::Trs, 0.0));

/// The largest distance (bone probes and vertices) over every clip between the source and its bake played with
/// `rotation`, at the times `times` gives for each clip's pair of sides; with the rig size.
fn worst(
    b: &Baked,
    strategy: Strategy,
    rotation: RotationInterpolation,
    times: impl Fn(usize, &Evaluation, &Evaluation) -> Vec<f64>,
) -> (f64, f64) {
    let request = request(b.source, b.mode, strategy, 0.0);
    let mut worst: f64 = 0.0;
    for k in 0..request.clips().len() {
        let source = request.clips()[k].source.clone();
        let baked = Evaluation::declared(&b.rig, b.rig.clips.get(k)).played_with(rotation);
        let pairs = Pairs::by_name(&source, &baked);
        let added: Vec<&str> = pairs.bones.only_b.iter().map(|&i| b.rig.skeleton.bone(i).name.as_str()).collect();
        let common_root = b.baked.notes.iter().any(|n| n.contains("a new root"));
        assert!(pairs.bones.only_a.is_empty(), "{}: every source bone is in the bake", b.source);
        assert!(added.is_empty() || (common_root && added.len() == 1), "{}: only in the bake: {added:?}", b.source);
        assert_eq!(pairs.meshes.len(), request.rig().meshes.len(), "{}: every mesh pairs up", b.source);
        worst = worst.max(compare(&source, &baked, &pairs, &times(k, &source, &baked)).worst_distance().max);
    }
    (worst, b.baked.rig_size)
}

/// A dense grid: four times the clip's frame rate, at least 240 a second.
fn dense(source: &Evaluation) -> f64 {
    (4.0 * source.clip.map_or(30.0, |c| c.frame_rate())).max(240.0)
}

#[test]
fn every_sample_kept_is_exact() {
    let failures: Vec<String> = EVERY_SAMPLE
        .par_iter()
        .filter_map(|b| {
            let keys = |k: usize, _: &Evaluation, _: &Evaluation| b.baked.animations[k].times.clone();
            let (worst, size) = worst(b, Strategy::Exact, RotationInterpolation::Slerp, keys);
            (worst > EXACT * size)
                .then(|| format!("{} ({}): {:.2e} of the rig size", b.source, label(b.mode), worst / size))
        })
        .collect();
    assert!(failures.is_empty(), "not exact at the sampled times:\n{}", failures.join("\n"));
}

#[test]
fn default_keys_stay_within_the_tolerance_between_samples_under_slerp_and_nlerp() {
    // The dense grid holds every frame and half-frame; the bake is played as glTF says (slerp) and as Blender,
    // Unity and Unreal play it (nlerp).
    let jobs: Vec<(&Baked, RotationInterpolation)> = DEFAULT
        .iter()
        .flat_map(|b| [RotationInterpolation::Slerp, RotationInterpolation::Nlerp].map(|r| (b, r)))
        .collect();
    let failures: Vec<String> = jobs
        .par_iter()
        .filter_map(|&(b, rotation)| {
            let grid = |_, source: &Evaluation, baked: &Evaluation| comparison_times(source, baked, dense(source));
            let (worst, size) = worst(b, Strategy::Exact, rotation, grid);
            let relative = worst / size;
            (relative > bake::DEFAULT_TOLERANCE).then(|| {
                let (source, mode, played) = (b.source, label(b.mode), rotation.id());
                format!("{source} ({mode}, {played}): {relative:.2e} of the rig size on a dense grid")
            })
        })
        .collect();
    assert!(failures.is_empty(), "over the tolerance:\n{}", failures.join("\n"));
}

#[test]
fn reduction_keeps_far_fewer_keys_than_samples_on_smooth_mocap() {
    // The CMU walk at 120 Hz: every bone keyed every frame in the file.
    let b = DEFAULT.iter().find(|b| b.source == "bvh/cmu_12_01_walk.bvh" && b.mode.is_none()).unwrap();
    let animation = &b.baked.animations[0];
    let bones = RIGS[b.source].skeleton.len();
    let every_sample = animation.times.len() * bones * 3;
    assert!(animation.keys * 3 < every_sample, "{} keys of {every_sample} sample values", animation.keys);
}

#[test]
fn helpers_go_exactly_where_a_local_matrix_shears() {
    // Maya's file as declared: its compensating bones' parents scale along axes their rotations keep, so no local
    // matrix shears and no bone needs a helper; under unscaled-parent the middle bone's does.
    let maya = "fbx-ufbx-data/maya_mixed_inherit_mode_7700_ascii.fbx";
    let helpers = |mode: Option<InheritMode>| {
        let b = DEFAULT.iter().find(|b| b.source == maya && b.mode == mode).unwrap();
        let skeleton = &RIGS[maya].skeleton;
        b.baked
            .helpers
            .iter()
            .enumerate()
            .filter(|(_, h)| **h)
            .map(|(i, _)| skeleton.bone(i).name.clone())
            .collect::<Vec<_>>()
    };
    assert_eq!(helpers(None), Vec::<String>::new());
    assert_eq!(helpers(Some(InheritMode::UnscaledParent)), ["Mid"]);
    assert_eq!(helpers(Some(InheritMode::Full)), Vec::<String>::new(), "full inheritance is glTF's own");
    // The demo under segment scale compensate: the forearm's local matrix shears.
    let demo = DEFAULT.iter().find(|b| b.source == DEMO && b.mode == Some(InheritMode::SegmentCompensate)).unwrap();
    let forearm = RIGS[DEMO].skeleton.find("forearm").unwrap();
    assert!(demo.baked.helpers[forearm]);
    let helper_node = demo.rig.skeleton.find("forearm.stretch").expect("the helper node is in the file");
    assert_eq!(demo.rig.skeleton.parent(demo.rig.skeleton.find("forearm").unwrap()), Some(helper_node));
}

/// Writes every bake of `bakes` into `folder`, returns the paths.
fn write_all(bakes: &[Baked], folder: &Path, tag: &str) -> Vec<PathBuf> {
    bakes
        .iter()
        .map(|b| {
            let name = format!("{}_{}_{tag}.glb", b.source.replace('/', "_"), label(b.mode));
            let path = folder.join(name);
            bake::save(&path, &b.baked.bytes).unwrap();
            path
        })
        .collect()
}

/// The validator's report of each file, as JSON lines (`tests/gltf-validator/validate.mjs`); installs the npm
/// package first when it is missing.
fn validate(files: &[PathBuf]) -> Vec<Value> {
    let folder = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/gltf-validator");
    if !folder.join("node_modules/gltf-validator").exists() {
        let npm = Command::new("npm").args(["ci", "--no-audit", "--no-fund"]).current_dir(&folder).output();
        let npm = npm.expect("npm (Node.js) runs the glTF-Validator: install nodejs and npm");
        assert!(npm.status.success(), "npm ci failed: {}", String::from_utf8_lossy(&npm.stderr));
    }
    let mut reports = Vec::new();
    for chunk in files.chunks(64) {
        let out = Command::new("node").arg(folder.join("validate.mjs")).args(chunk).output().expect("node runs");
        assert!(out.status.success(), "the validator failed: {}", String::from_utf8_lossy(&out.stderr));
        let text = String::from_utf8(out.stdout).unwrap();
        reports.extend(text.lines().map(|line| serde_json::from_str::<Value>(line).unwrap()));
    }
    reports
}

#[test]
fn every_baked_file_passes_the_khronos_validator() {
    let folder = tempfile::tempdir().unwrap();
    let mut files = write_all(&DEFAULT, folder.path(), "exact");
    files.extend(write_all(&TRS, folder.path(), "trs"));
    let reports = validate(&files);
    assert_eq!(reports.len(), files.len());
    let failing: Vec<String> = reports
        .iter()
        .filter(|r| r["errors"].as_u64() != Some(0))
        .map(|r| format!("{}: {}", r["file"], r["messages"]))
        .collect();
    assert!(failing.is_empty(), "{} files with errors:\n{}", failing.len(), failing.join("\n"));
}

#[test]
fn a_mesh_without_faces_is_left_out_with_a_note_and_the_bake_validates() {
    // Blender's barbarian carries an empty placeholder mesh; Blender's weights scene three skinned meshes of one
    // vertex and no face. Written as they were, each gave accessors of count 0 with min/max of null.
    let folder = tempfile::tempdir().unwrap();
    let sources = [
        (asset("fbx-ufbx-corpus/blender_293_barbarian_7400_binary.fbx"), "Prop_Tree_Oak_1"),
        (common::corpus("blender-io/32_weights_influence_4.fbx"), "Plane, Plane.001, Plane.002"),
    ];
    let mut files = Vec::new();
    for (source, faceless) in sources {
        let rig = import::load(&source).unwrap_or_else(|e| panic!("{e}"));
        let request = Request::every_clip(&Evaluation::declared(&rig, None), None, Strategy::Exact, 1e-4);
        let baked = bake::bake(&request);
        let note = format!("meshes without faces left out (glTF has no empty mesh): {faceless}");
        assert!(baked.notes.contains(&note), "{}: {:?}", source.display(), baked.notes);
        let with_faces: Vec<&str> =
            rig.meshes.iter().filter(|m| !m.indices.is_empty()).map(|m| m.name.as_str()).collect();
        let back = import::load_bytes(Path::new("baked.glb"), &baked.bytes).unwrap();
        assert_eq!(back.meshes.iter().map(|m| m.name.as_str()).collect::<Vec<_>>(), with_faces);
        let path = folder.path().join(format!("{faceless}.glb"));
        bake::save(&path, &baked.bytes).unwrap();
        files.push(path);
    }
    for report in validate(&files) {
        assert_eq!(report["errors"], 0, "{}: {}", report["file"], report["messages"]);
    }
}

/// The vertices `bonescope export` writes for `file` at `time` of its first clip (a bake keeps the clips' order; the
/// clip a file opens on is the one keying the most channels, which a bake's keys change).
fn exported(file: &Path, time: f64, folder: &Path) -> Vec<glam::DVec3> {
    let out = folder.join(format!("{}_{time}.obj", file.file_stem().unwrap().to_string_lossy()));
    let run = bonescope(&[
        "export",
        &file.display().to_string(),
        "--anim",
        "0",
        "--time",
        &time.to_string(),
        "--out",
        &out.display().to_string(),
    ]);
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    obj_positions(&out)
}

#[test]
fn baked_skinned_vertices_equal_the_sources_in_export() {
    // Skinned meshes from each tool, at key times of their first clip, as `export` writes them.
    let folder = tempfile::tempdir().unwrap();
    for (source, time) in [
        ("fbx-ufbx-data/maya_mixed_inherit_mode_7700_ascii.fbx", 5.0 / 24.0),
        ("fbx-ufbx-data/max7_skin_5000_binary.fbx", 0.5),
        ("blender/stretchy_full.fbx", 1.0),
        ("gltf-khronos/cesium_man.gltf", 1.0),
        ("gltf-khronos/Fox.glb", 0.5),
    ] {
        let b = EVERY_SAMPLE.iter().find(|b| b.source == source && b.mode.is_none()).unwrap();
        let baked = folder.path().join(format!("{}.glb", source.replace('/', "_")));
        bake::save(&baked, &b.baked.bytes).unwrap();
        let theirs = exported(&asset(source), time, folder.path());
        let ours = exported(&baked, time, folder.path());
        assert_eq!(ours.len(), theirs.len(), "{source}: vertex count");
        // `export` writes the file's own units (FBX in centimetres here, the bake in metres).
        let scale = size(&theirs) / size(&ours);
        assert!((scale - 1.0).abs() < 1e-6 || (scale - 100.0).abs() < 1e-4, "{source}: units {scale}");
        let worst = ours.iter().zip(&theirs).map(|(a, b)| a.distance(*b / scale.round())).fold(0.0, f64::max);
        assert!(worst <= EXACT * size(&ours), "{source}: {worst:.2e} against a size of {:.3}", size(&ours));
    }
}

#[test]
fn the_baked_maya_file_gives_mayas_own_geometry() {
    // Maya's OBJ of frames 0–7 (24 fps, centimetres) against `export` of the baked glTF (metres).
    let maya = "fbx-ufbx-data/maya_mixed_inherit_mode_7700_ascii.fbx";
    let b = DEFAULT.iter().find(|b| b.source == maya && b.mode.is_none()).unwrap();
    let folder = tempfile::tempdir().unwrap();
    let baked = folder.path().join("maya.glb");
    bake::save(&baked, &b.baked.bytes).unwrap();
    for frame in 0..8 {
        let reference: Vec<glam::DVec3> =
            obj_positions(&asset(&format!("fbx-ufbx-data/maya_mixed_inherit_mode_{frame}.obj")))
                .iter()
                .map(|p| *p * 0.01)
                .collect();
        let ours = exported(&baked, f64::from(frame) / 24.0, folder.path());
        assert_eq!(ours.len(), reference.len());
        let worst = ours.iter().zip(&reference).map(|(a, b)| a.distance(*b)).fold(0.0, f64::max);
        assert!(worst <= 1e-4 * size(&reference), "frame {frame}: {:.2e} of the model", worst / size(&reference));
    }
}

/// `bonescope diff A B` as JSON, and the largest worst distance of its animations.
fn diff_worst(args: &[&str]) -> f64 {
    let out = bonescope(&[&["diff", "--format", "json"], args].concat());
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let json: Value = serde_json::from_slice(&out.stdout).unwrap();
    json["animations"].as_array().unwrap().iter().map(|a| a["worst"]["max"].as_f64().unwrap()).fold(0.0, f64::max)
}

#[test]
fn trs_reports_a_bound_of_what_diff_measures_and_never_more_than_the_local_trs() {
    let folder = tempfile::tempdir().unwrap();
    let cases = [
        ("fbx-ufbx-data/maya_mixed_inherit_mode_7700_ascii.fbx", None),
        ("fbx-ufbx-data/maya_mixed_inherit_mode_7700_ascii.fbx", Some(InheritMode::UnscaledParent)),
        ("blender/stretchy_noinherit.fbx", None),
        ("blender/stretchy_full.glb", Some(InheritMode::BlenderFixShear)),
        ("fbx-ufbx-data/maya_scale_no_inherit_7700_ascii.fbx", None),
    ];
    for (source, mode) in cases {
        let b = TRS.iter().find(|b| b.source == source && b.mode == mode).unwrap();
        let baked = folder.path().join("trs.glb");
        bake::save(&baked, &b.baked.bytes).unwrap();
        let report = bake::report(&request(source, mode, Strategy::Trs, 0.0), &b.baked, &b.rig);
        let reported = report.worst().max;
        // Every sample is a key at the clip's frames (and its keys); the report checks them, the midpoints between
        // and diff's own times, so diff at the clip's rate, at twice it (the midpoints) and at its default rate
        // finds no more, and a dense diff finds within 1% as much (the report is a bound, not a guess).
        let frame_rate = RIGS[source].clips[0].frame_rate();
        let (path, inherit) = (asset(source).display().to_string(), label(mode));
        // The report takes the worse of the engines' two ways to play rotation keys, slerp and nlerp.
        let measured = |rate: f64| {
            let (rate, baked) = (rate.to_string(), baked.display().to_string());
            let played = |interp: &str| {
                diff_worst(&[&path, &baked, "--inherit-a", inherit, "--rate", &rate, "--interp", interp])
            };
            played("slerp").max(played("nlerp"))
        };
        let slack = EXACT * b.baked.rig_size;
        for rate in [frame_rate, 2.0 * frame_rate, bonescope::diff::DEFAULT_RATE] {
            let found = measured(rate);
            assert!(found <= reported + slack, "{source} ({inherit}): reported {reported}, diff at {rate} Hz {found}");
        }
        let dense = measured(DENSE_RATE);
        assert!(
            reported <= 1.01 * dense + slack,
            "{source} ({inherit}): reported {reported}, diff at {DENSE_RATE} Hz {dense}"
        );
        // Keeping each bone's own local TRS is the source evaluated with glTF's full inheritance.
        let rate = (2.0 * frame_rate).to_string();
        let local_trs = diff_worst(&[&path, &path, "--inherit-a", inherit, "--inherit-b", "full", "--rate", &rate]);
        assert!(reported <= local_trs + EXACT * b.baked.rig_size, "{source} ({inherit}): {reported} > {local_trs}");
    }
}

/// `rig` baked exactly as it declares itself, with the default keys, and the bake read back.
fn baked_as_declared(rig: &Rig) -> (Request<'_>, bake::Baked, Rig) {
    let request = Request::every_clip(&Evaluation::declared(rig, None), None, Strategy::Exact, bake::DEFAULT_TOLERANCE);
    let baked = bake::bake(&request);
    let back = import::load_bytes(Path::new("baked.glb"), &baked.bytes).unwrap();
    (request, baked, back)
}

#[test]
fn normals_morph_targets_and_their_weights_travel_with_the_meshes() {
    // Maya's in-between blend shapes, animated: the baked file's morph targets and weights give the source's
    // vertices within the tolerance on a dense grid; its normals are the source's.
    let rig = import::load(&asset("fbx-ufbx-corpus/maya_blend_inbetween_7500_ascii.fbx")).unwrap();
    let (request, baked, back) = baked_as_declared(&rig);
    let (source, result) = (&rig.meshes[0], &back.meshes[0]);
    assert_eq!(result.morph_targets.len(), source.morph_targets.len());
    assert!(!source.normals.is_empty());
    for (a, b) in source.normals.iter().zip(&result.normals) {
        assert!(a.abs_diff_eq(*b, 1e-6), "{a} against {b}");
    }
    let a = request.clips()[0].source.clone();
    let b = Evaluation::declared(&back, back.clips.first());
    let pairs = Pairs::by_name(&a, &b);
    let comparison = compare(&a, &b, &pairs, &comparison_times(&a, &b, dense(&a)));
    let vertices = comparison.meshes[0].distance.max;
    assert!(vertices <= bake::DEFAULT_TOLERANCE * baked.rig_size, "{vertices:.2e} of {:.3}", baked.rig_size);
}

#[test]
fn a_dual_quaternion_skin_is_baked_linear_and_the_report_says_what_it_costs() {
    let rig = import::load(&asset("fbx-ufbx-corpus/maya_dual_quaternion_7500_ascii.fbx")).unwrap();
    let (request, baked, back) = baked_as_declared(&rig);
    assert!(baked.notes.iter().any(|n| n.contains("dual quaternions")), "{:?}", baked.notes);
    let report = bake::report(&request, &baked, &back);
    let animation = &report.animations[0];
    let bones = animation.bones.iter().map(|b| b.probe.max).fold(0.0, f64::max);
    assert!(bones <= bake::DEFAULT_TOLERANCE * baked.rig_size, "the joints are baked within the tolerance");
    // The twisted mesh is where linear blending pinches what dual quaternions keep: the report shows it.
    assert!(animation.meshes[0].distance.max > 0.01 * baked.rig_size, "{:?}", animation.meshes[0]);
}

/// `bonescope bake SOURCE --for ENGINE --format json` with `more` options, into `out`: the report.
fn bake_for(source: &str, engine: &str, out: &Path, more: &[&str]) -> Value {
    let path = asset(source).display().to_string();
    let args = [&["bake", &path, "--for", engine, "--out", &out.display().to_string(), "--format", "json"], more];
    let output = bonescope(&args.concat());
    assert!(output.status.success(), "{engine}: {}", String::from_utf8_lossy(&output.stderr));
    serde_json::from_slice(&output.stdout).unwrap()
}

#[test]
fn each_engine_plays_its_bake_within_the_tolerance_as_it_interpolates() {
    // Maya's mixed-inheritance file, where Blender played a slerp-only bake 3.9e-3 of the model off between frames:
    // each engine's bake, played as that engine interpolates rotations, on a grid of quarter frames (24 fps), stays
    // within the tolerance of the source, and its report says so.
    let source = "fbx-ufbx-data/maya_mixed_inherit_mode_7700_ascii.fbx";
    let folder = tempfile::tempdir().unwrap();
    for (engine, played) in [("generic", "nlerp"), ("generic", "slerp"), ("blender", "nlerp"), ("unity", "nlerp")]
        .into_iter()
        .chain([("three", "slerp"), ("godot", "slerp")])
    {
        let out = folder.path().join(format!("{engine}.glb"));
        let report = bake_for(source, engine, &out, &[]);
        assert_eq!((report["engine"].as_str(), report["strategy"].as_str()), (Some(engine), Some("exact")));
        let tolerance = report["tolerance"].as_f64().unwrap();
        assert!(report["animations"][0]["worst"]["max"].as_f64().unwrap() <= tolerance, "{engine}: reported");
        let (path, baked) = (asset(source).display().to_string(), out.display().to_string());
        let measured = diff_worst(&[&path, &baked, "--interp", played, "--rate", "96"]);
        assert!(measured <= tolerance, "{engine} played by {played}: {measured:e} > {tolerance:e}");
    }
}

#[test]
fn unreal_gets_one_trs_node_per_bone_and_its_report_bounds_what_diff_measures_under_nlerp() {
    // Maya's file with every bone under an unscaled parent, which shears; every sample a key (tolerance 0), so
    // diff at the clip's own rate visits exactly the sampled times.
    let source = "fbx-ufbx-data/maya_mixed_inherit_mode_7700_ascii.fbx";
    let folder = tempfile::tempdir().unwrap();
    let out = folder.path().join("unreal.glb");
    let inherit = InheritMode::UnscaledParent.id();
    let report = bake_for(source, "unreal", &out, &["--tolerance", "0", "--inherit", inherit]);
    assert_eq!(report["rotations"], serde_json::json!(["nlerp"]));
    let bones = report["animations"][0]["bones"].as_array().unwrap();
    assert!(bones.iter().all(|b| b["nodes"] == "trs"), "one TRS node per bone");
    assert!(report["helpers"].as_array().unwrap().is_empty());
    let reported = report["animations"][0]["worst"]["max"].as_f64().unwrap();
    let (path, baked) = (asset(source).display().to_string(), out.display().to_string());
    let measured = |rate: f64| {
        diff_worst(&[&path, &baked, "--inherit-a", inherit, "--interp", "nlerp", "--rate", &rate.to_string()])
    };
    // The report checks every key and the midpoints between: diff at the clip's rate and at twice it finds no
    // more, a dense diff within 1% as much.
    let frame_rate = RIGS[source].clips[0].frame_rate();
    let size = report["rig_size"].as_f64().unwrap();
    assert!(measured(frame_rate) <= reported + EXACT * size, "{reported} vs {}", measured(frame_rate));
    let at_midpoints = measured(2.0 * frame_rate);
    assert!(at_midpoints <= reported + EXACT * size, "{reported} vs {at_midpoints}");
    let dense = measured(DENSE_RATE);
    assert!(reported <= 1.01 * dense + EXACT * size, "{reported} vs {dense} at {DENSE_RATE} Hz");
    assert!(reported > bake::DEFAULT_TOLERANCE * size, "the shear is beyond a TRS: {reported:e}");
}

/// The worst `diff` at its default rate finds between `source` and the bake read back as `back`, over every clip.
fn diff_in_memory(source: &Rig, modes: &[InheritMode], back: &Rig) -> f64 {
    let mut worst: f64 = 0.0;
    for (k, clip) in source.clips.iter().enumerate() {
        let a = Evaluation::new(source, Some(clip), modes).unwrap();
        let b = Evaluation::declared(back, back.clips.get(k));
        let times = comparison_times(&a, &b, bonescope::diff::DEFAULT_RATE);
        worst = worst.max(compare(&a, &b, &Pairs::by_name(&a, &b), &times).worst_distance().max);
    }
    worst
}

#[test]
fn a_bake_reports_a_bound_of_what_diff_finds_and_a_bake_of_a_bake_changes_nothing() {
    // Every shared animation file (as declared) baked with the default keys, and that bake baked again: each bake's
    // report is at least what `diff` of its input and its output finds (the report checks the keys, the midpoints
    // between them and diff's own times), and the second bake stays within its tolerance of the first.
    let failures: Vec<String> = sources()
        .par_iter()
        .flat_map(|&source| {
            let rig = &RIGS[source];
            let once = bake::bake(&request(source, None, Strategy::Exact, bake::DEFAULT_TOLERANCE));
            let a = import::load_bytes(Path::new("a.glb"), &once.bytes).unwrap();
            let request_twice =
                Request::every_clip(&Evaluation::declared(&a, None), None, Strategy::Exact, bake::DEFAULT_TOLERANCE);
            let twice = bake::bake(&request_twice);
            let b = import::load_bytes(Path::new("b.glb"), &twice.bytes).unwrap();
            let mut failures = Vec::new();
            let reported =
                |request: &Request, baked: &bake::Baked, back: &Rig| bake::report(request, baked, back).worst().max;
            let first = (
                reported(&request(source, None, Strategy::Exact, bake::DEFAULT_TOLERANCE), &once, &a),
                diff_in_memory(rig, &rig.skeleton.declared_modes(), &a),
            );
            let second = (reported(&request_twice, &twice, &b), diff_in_memory(&a, &a.skeleton.declared_modes(), &b));
            for (which, (report, found), size) in
                [("bake", first, once.rig_size), ("bake of the bake", second, twice.rig_size)]
            {
                if found > report + EXACT * size {
                    failures.push(format!("{source}, {which}: reported {report:e}, diff finds {found:e}"));
                }
            }
            if second.1 > bake::DEFAULT_TOLERANCE * twice.rig_size {
                failures.push(format!("{source}: the bake of the bake is {:e} off, beyond its tolerance", second.1));
            }
            failures
        })
        .collect();
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn a_usd_bake_reports_a_bound_of_what_diff_finds() {
    // Every shared animation file (as declared) baked to a UsdSkel crate file, its first clip (a stage plays one):
    // the report is at least what `diff` of the source and the file read back finds.
    let usdc = bake::Output::Usd(bake::Encoding::Crate);
    let failures: Vec<String> = sources()
        .par_iter()
        .flat_map(|&source| {
            let rig = &RIGS[source];
            let clip = rig.clips.first();
            let request =
                Request::every_clip(&Evaluation::declared(rig, clip), clip, Strategy::Exact, bake::DEFAULT_TOLERANCE);
            let baked = bake::bake_to(&request, usdc).unwrap();
            let back = import::load_bytes(Path::new("baked.usdc"), &baked.bytes).unwrap();
            let report = bake::report(&request, &baked, &back);
            let a = &request.clips()[0].source;
            let b = Evaluation::declared(&back, back.clips.first()).delayed(a.delay());
            let pairs = Pairs::by_name(a, &b);
            let found = compare(a, &b, &pairs, &comparison_times(a, &b, bonescope::diff::DEFAULT_RATE));
            let (reported, found) = (report.worst().max, found.worst_distance().max);
            let missed = found > reported + EXACT * baked.rig_size;
            missed.then(|| format!("{source}: reported {reported:e}, diff finds {found:e}"))
        })
        .collect();
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn files_nobody_here_wrote_bake_within_the_bound_they_state_and_validate() {
    // The real-world files as the command line bakes them (exact, for every engine): the worst the report measures
    // on the file as written and read back is within the bound it states, in metres (a BVH in the unit its figure
    // stands a person's height in), and the validator finds no error. BrainStem is not here: its bake takes over ten
    // minutes in a test build; where its clocks meet, where it once went past its bound, it is baked below.
    let names = [
        "bandai_dataset-1_kick_normal_001.bvh",
        "bandai_dataset-2_run_normal_001.bvh",
        "godot_enemy.glb",
        "godot_mannequiny.glb",
        "godot_platformer_player.glb",
        "pymo_AV_8Walk_Meredith_HVHA_Rep1.bvh",
        "raylib_robot.glb",
        "tinyusdz_blendshape-and-animation-test-001.usda",
        "tinyusdz_skintest-blender-4.1.usda",
        "usdwg_CesiumMan.usdz",
    ];
    let folder = tempfile::tempdir().unwrap();
    let mut files = Vec::new();
    for name in names {
        let source = common::corpus(&format!("realworld/{name}")).display().to_string();
        let out = folder.path().join(format!("{name}.glb"));
        let output = bonescope(&["bake", &source, "--out", &out.display().to_string(), "--format", "json"]);
        assert!(output.status.success(), "{name}: {}", String::from_utf8_lossy(&output.stderr));
        let report: Value = serde_json::from_slice(&output.stdout).unwrap();
        let bound = report["tolerance"].as_f64().unwrap();
        let animations = report["animations"].as_array().unwrap();
        let worst = animations.iter().map(|a| a["worst"]["max"].as_f64().unwrap()).fold(0.0, f64::max);
        assert!(worst <= bound, "{name}: worst {worst:e} past the bound {bound:e}");
        let size = report["rig_size"].as_f64().unwrap();
        assert!((0.1..100.0).contains(&size), "{name}: a figure in metres, not {size}");
        files.push(out);
    }
    for report in validate(&files) {
        assert_eq!(report["errors"], 0, "{}: {}", report["file"], report["messages"]);
    }
}

#[test]
fn brainstem_where_its_two_clocks_meet_bakes_within_the_bound_it_states() {
    // BrainStem's tracks hold samples at 37 and at 37.5 a second, 0.39 ms apart where the clocks meet (23.9730 and
    // 23.9734 s; they coincide at 24 s): closer than a bake keys (a hundredth of a frame), so one of each pair is
    // baked. Its turns are at the 37.5 ones; baking the other cut the corner by 3.1e-4 m where it states 2.3e-4 m.
    // Its clip from 23 to 24.5 s, played under slerp and nlerp, compared with the source by `diff` at 1200 Hz and
    // the source's keys: within the tolerance stated, and so is what the report measured.
    let mut rig = import::load(&common::corpus("realworld/usdwg_BrainStem.usdz")).unwrap();
    rig.clips[0] = rig.clips[0].clone().with_span(Span::new(23.0, 24.5));
    let request = Request::of(&Evaluation::declared(&rig, None), None, Strategy::Exact, bake::DEFAULT_TOLERANCE);
    let baked = bake::bake(&request);
    let back = import::load_bytes(Path::new("b.glb"), &baked.bytes).unwrap();
    let source = &request.clips()[0].source;
    for rotation in [RotationInterpolation::Slerp, RotationInterpolation::Nlerp] {
        let played = Evaluation::declared(&back, back.clips.first()).played_with(rotation);
        let times = comparison_times(source, &played, DENSE_RATE);
        assert!(times.contains(&23.973360061645508), "the turn is among the times compared");
        let found = compare(source, &played, &Pairs::by_name(source, &played), &times).worst_distance();
        assert!(found.max <= baked.tolerance, "{}: {found:?} past {:e}", rotation.id(), baked.tolerance);
    }
    let reported = bake::report(&request, &baked, &back).worst();
    assert!(reported.max <= baked.tolerance, "reported {reported:?} past {:e}", baked.tolerance);
}

#[test]
fn a_take_that_starts_before_zero_is_written_from_zero_and_said_so() {
    // Maya's long-keyframe take runs from −166,666 s on its file's clock; glTF's clock starts at 0.
    let folder = tempfile::tempdir().unwrap();
    let out = folder.path().join("long.glb");
    let report = bake_for("fbx-ufbx-corpus/maya_long_keyframes_7700_ascii.fbx", "generic", &out, &[]);
    let notes: Vec<&str> = report["notes"].as_array().unwrap().iter().filter_map(Value::as_str).collect();
    assert!(notes.iter().any(|n| n.starts_with("`Take 001` starts at -166666.66")), "{notes:?}");
    let back = import::load(&out).unwrap_or_else(|e| panic!("{e}"));
    let span = back.clips[0].span();
    assert!(span.start >= 0.0 && span.length() > 333_000.0, "{span:?}");
    // At 333,333 s a single-precision time is kept to 2^(18 − 23) s: keys move, and the bake says so rather than
    // claim its tolerance.
    assert!(notes.iter().any(|n| n.contains("glTF's single-precision key times are 3.125e-2 s apart")), "{notes:?}");
    let (worst, tolerance) =
        (report["animations"][0]["worst"]["max"].as_f64().unwrap(), report["tolerance"].as_f64().unwrap());
    assert!(worst > tolerance, "{worst} within {tolerance}: the note would be wrong");
    let table = bonescope(&[
        "bake",
        &asset("fbx-ufbx-corpus/maya_long_keyframes_7700_ascii.fbx").display().to_string(),
        "--out",
        &out.display().to_string(),
    ]);
    let shows = String::from_utf8_lossy(&table.stdout).lines().nth(1).unwrap_or_default().to_owned();
    assert!(
        shows.contains(&format!("shows the source within {worst:.3e} at "))
            && shows.contains(&format!("past the {tolerance:.3e} asked")),
        "{shows}"
    );
}
