//! The `inspect` and `scan` commands as a user runs them: output shape, numbers that must hold, exit codes.

mod common;

use std::path::{Path, PathBuf};

use base64::Engine;
use common::{asset, bonescope, json};
use glam::DMat4;
use serde_json::Value;

fn stretchy() -> String {
    asset("blender/stretchy_full.glb").display().to_string()
}

fn keys(v: &Value) -> Vec<&str> {
    let mut k: Vec<&str> = v.as_object().expect("an object").keys().map(String::as_str).collect();
    k.sort();
    k
}

fn matrix(v: &Value) -> DMat4 {
    let m: Vec<f64> = v.as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect();
    DMat4::from_cols_slice(&m)
}

#[test]
fn inspect_json_has_exactly_the_documented_shape() {
    let out = json(&bonescope(&["inspect", &stretchy(), "--time", "0.5", "--time", "1", "--format", "json"]));
    assert_eq!(keys(&out), ["animation", "bind_mismatches", "file", "inherit", "layers", "notes", "samples"]);
    assert_eq!(out["layers"]["bind_weight"], 1.0, "no layers: {}", out["layers"]);
    assert_eq!(out["layers"]["blend"], Value::Null);
    assert_eq!(keys(&out["animation"]), ["duration", "frame_rate", "index", "name", "start"]);
    // Blender's frame 1 on the glb's own clock, as glTF stores a time (single precision).
    assert_eq!(out["animation"]["start"], f64::from(1.0f32 / 30.0));
    assert_eq!(out["animation"]["index"], 0);
    assert_eq!(out["animation"]["name"], "squash_stretch");
    assert_eq!(out["inherit"], "declared");
    let samples = out["samples"].as_array().unwrap();
    assert_eq!(samples.len(), 2);
    assert_eq!(samples[1]["time"], 1.0);
    for bone in samples[0]["bones"].as_array().unwrap() {
        assert_eq!(
            keys(bone),
            ["index", "inherit", "local", "mirrored", "model", "name", "node", "parent", "shear_deg", "stretched"]
        );
        for space in ["local", "model"] {
            let parts = &bone[space];
            assert_eq!(keys(parts), ["matrix", "rotation", "scale", "sign", "stretch", "translation"]);
            assert_eq!(parts["matrix"].as_array().unwrap().len(), 16);
            assert_eq!(parts["rotation"].as_array().unwrap().len(), 4);
            assert_eq!(parts["stretch"].as_array().unwrap().len(), 4);
            assert!(parts["sign"] == 1 || parts["sign"] == -1);
        }
    }
}

#[test]
fn inspect_model_matrices_are_parent_times_local_under_full() {
    let out = json(&bonescope(&["inspect", &stretchy(), "--time", "0.55", "--inherit", "full", "--format", "json"]));
    let bones = out["samples"][0]["bones"].as_array().unwrap();
    let mut stretched = 0;
    for bone in bones {
        let local = matrix(&bone["local"]["matrix"]);
        let expected = match bone["parent"].as_u64() {
            Some(p) => matrix(&bones[p as usize]["model"]["matrix"]) * local,
            None => local,
        };
        assert!(matrix(&bone["model"]["matrix"]).abs_diff_eq(expected, 1e-12), "{}", bone["name"]);
        // Stretched bones shear; others do not.
        let shear = bone["shear_deg"].as_f64().unwrap();
        if bone["stretched"].as_bool().unwrap() {
            stretched += 1;
            assert!(shear > 0.01, "{} stretched with shear {shear}", bone["name"]);
        } else {
            assert!(shear < 0.01, "{} not stretched with shear {shear}", bone["name"]);
        }
    }
    // The README of the asset: the chest squashes while arm and neck rotate, so their descendants shear.
    assert!(stretched >= 2);
}

#[test]
fn inheritance_options_change_the_modes() {
    let out = json(&bonescope(&[
        "inspect",
        &stretchy(),
        "--time",
        "0.55",
        "--inherit",
        "segment-compensate",
        "--inherit-bone",
        "forearm=full",
        "--format",
        "json",
    ]));
    assert_eq!(out["inherit"], "mixed", "one bone has its own mode");
    for bone in out["samples"][0]["bones"].as_array().unwrap() {
        let expected = if bone["name"] == "forearm" { "full" } else { "segment-compensate" };
        assert_eq!(bone["inherit"], expected);
        // In a compensated chain no bone is stretched.
        if bone["name"] != "forearm" && bone["name"] != "hand" {
            assert_eq!(bone["stretched"], false, "{}", bone["name"]);
        }
    }
}

#[test]
fn inspect_table_marks_stretched_bones() {
    let out = bonescope(&["inspect", &stretchy(), "--time", "0.55"]);
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    let forearm = text.lines().find(|l| l.contains(" forearm ")).expect("a forearm row");
    assert!(forearm.trim_start().starts_with('*') && forearm.contains("stretched"), "{forearm}");
    let hips = text.lines().find(|l| l.contains(" hips ")).expect("a hips row");
    assert!(!hips.trim_start().starts_with('*'), "{hips}");
}

#[test]
fn inspect_picks_animations_by_name_or_index_and_names_the_missing_one() {
    let by_name = json(&bonescope(&["inspect", &stretchy(), "--anim", "wave", "--format", "json"]));
    let by_index = json(&bonescope(&["inspect", &stretchy(), "--anim", "1", "--format", "json"]));
    assert_eq!(by_name["animation"], by_index["animation"]);
    assert_eq!(by_name["animation"]["name"], "wave");
    let missing = bonescope(&["inspect", &stretchy(), "--anim", "jump"]);
    assert_eq!(missing.status.code(), Some(2));
    let err = String::from_utf8(missing.stderr).unwrap();
    assert!(err.contains("jump") && err.contains("squash_stretch") && err.contains("wave"), "{err}");
}

#[test]
fn unknown_modes_and_bones_are_usage_errors() {
    let bad_mode = bonescope(&["inspect", &stretchy(), "--inherit", "sheared"]);
    assert_eq!(bad_mode.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&bad_mode.stderr).contains("segment-compensate"), "lists the valid ids");
    let bad_bone = bonescope(&["inspect", &stretchy(), "--inherit-bone", "tail=full"]);
    assert_eq!(bad_bone.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&bad_bone.stderr).contains("tail"));
}

#[test]
fn a_broken_file_is_one_line_naming_it_and_exit_2() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("truncated.glb");
    let bytes = std::fs::read(asset("blender/stretchy_full.glb")).unwrap();
    std::fs::write(&path, &bytes[..bytes.len() / 2]).unwrap();
    let out = bonescope(&["inspect", path.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8(out.stderr).unwrap();
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    assert!(err.contains("truncated.glb"), "{err}");
}

#[test]
fn scan_exit_codes() {
    assert_eq!(bonescope(&["scan", &stretchy()]).status.code(), Some(0));
    assert_eq!(bonescope(&["scan", &stretchy(), "--fail-above"]).status.code(), Some(1));
    // The gate's angle: the worst shear of any stretched bone, read from the report, passes at itself and fails
    // just below; the old spelling is the gate at 0°.
    let report = json(&bonescope(&["scan", &stretchy(), "--format", "json"]));
    let shears = report[0]["animations"].as_array().unwrap().iter().flat_map(|a| a["stretched"].as_array().unwrap());
    let worst = shears.map(|b| b["worst_shear_deg"].as_f64().unwrap()).fold(0.0, f64::max);
    assert!(worst > 1.0, "{worst}");
    let gate = |limit: f64| bonescope(&["scan", &stretchy(), "--fail-above", &limit.to_string()]).status.code();
    assert_eq!((gate(worst), gate(0.999 * worst)), (Some(0), Some(1)));
    assert_eq!(bonescope(&["scan", &stretchy(), "--fail-on-stretch"]).status.code(), Some(1));
    assert_eq!(bonescope(&["scan", &stretchy(), "--fail-above", "-1"]).status.code(), Some(2), "no negative angle");
    let compensated = bonescope(&["scan", &stretchy(), "--fail-above", "--inherit", "segment-compensate"]);
    assert_eq!(compensated.status.code(), Some(0));
    let fox = asset("gltf-khronos/Fox.glb").display().to_string();
    assert_eq!(bonescope(&["scan", &fox, "--fail-above"]).status.code(), Some(0));
    // A missing file: exit 2, but the loadable file is still reported.
    let out = bonescope(&["scan", "no-such-file.glb", &stretchy(), "--format", "json"]);
    assert_eq!(out.status.code(), Some(2));
    let report: Value = serde_json::from_slice(&out.stdout).unwrap();
    // Files are reported in sorted order (the absolute asset path before the relative name).
    assert_eq!(report[0]["error"], Value::Null);
    assert_eq!(report[0]["animations"].as_array().unwrap().len(), 2);
    assert!(report[1]["error"].as_str().unwrap().contains("no-such-file.glb"));
    assert!(String::from_utf8_lossy(&out.stderr).contains("no-such-file.glb"));
}

#[test]
fn scan_json_reports_the_stretched_bones_with_when_and_how_much() {
    let out = json(&bonescope(&["scan", &stretchy(), "--anim", "squash_stretch", "--format", "json"]));
    let scan = &out[0]["animations"][0];
    assert_eq!(scan["animation"]["name"], "squash_stretch");
    assert_eq!(scan["rate"], 60.0);
    let samples = scan["samples"].as_u64().unwrap();
    // Frames 1 to 61 at 30 fps, 1/30 s to 61/30 s on the file's clock: 121 grid times at 60 Hz; the key times
    // add those off the 60 Hz grid.
    assert!(samples >= 121, "{samples}");
    let stretched = scan["stretched"].as_array().unwrap();
    let names: Vec<&str> = stretched.iter().map(|b| b["name"].as_str().unwrap()).collect();
    assert!(names.contains(&"forearm") && names.contains(&"neck"), "{names:?}");
    let worst: Vec<f64> = stretched.iter().map(|b| b["worst_shear_deg"].as_f64().unwrap()).collect();
    assert!(worst.windows(2).all(|w| w[0] >= w[1]), "sorted by worst shear: {worst:?}");
    for bone in stretched {
        let flagged = bone["flagged_samples"].as_u64().unwrap();
        assert!(flagged > 0 && flagged <= samples);
        assert!(bone["first_flagged_time"].as_f64().unwrap() <= bone["worst_shear_time"].as_f64().unwrap());
        assert!(bone["worst_stretch_deg"].as_f64().unwrap() > 0.01);
    }
    // The chest squashes along its own axes: non-uniform but not stretched.
    assert!(scan["non_uniform"].as_array().unwrap().iter().any(|n| n == "chest"));
}

#[test]
fn the_non_uniform_tolerance_is_an_option_of_its_own() {
    let file = stretchy();
    let scan = |tolerance: &str| {
        let args = ["scan", &file, "--anim", "squash_stretch", "--format", "json", "--min-non-uniform", tolerance];
        json(&bonescope(&args))[0]["animations"][0].clone()
    };
    let shears = |scan: &Value| -> Vec<Value> {
        scan["stretched"].as_array().unwrap().iter().map(|b| b["worst_shear_deg"].clone()).collect()
    };
    let (strict, lenient) = (scan("1e-3"), scan("100"));
    // The chest squashes along its own axes by far less than 100× and more than 0.1 %; the shears are the same.
    assert!(strict["non_uniform"].as_array().unwrap().iter().any(|n| n == "chest"), "{strict}");
    assert_eq!(lenient["non_uniform"], serde_json::json!([]));
    assert!(!shears(&strict).is_empty() && shears(&strict) == shears(&lenient));
    let err = stderr_of(&["scan", &file, "--min-non-uniform=-1"]);
    assert_eq!(err.trim_end(), "error: --min-non-uniform must be a finite number ≥ 0, got -1");
}

fn fbx(name: &str) -> String {
    asset(&format!("fbx-ufbx-data/{name}")).display().to_string()
}

#[test]
fn export_writes_the_evaluated_mesh_in_the_files_own_units() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("frame5.obj");
    let file = fbx("max_transformed_skin_7500_binary.fbx");
    let time = (5.0f64 / 30.0).to_string();
    let run = bonescope(&["export", &file, "--time", &time, "--format", "obj", "--out", out.to_str().unwrap()]);
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    assert!(String::from_utf8_lossy(&run.stdout).contains("wrote 1 meshes (90 vertices)"));
    let text = std::fs::read_to_string(&out).unwrap();
    assert!(text.starts_with("# bonescope export of "), "{text}");
    assert!(text.contains("# units and axes: the file's own (Z-up, centimetres)"), "{text}");
    let vertices: Vec<[f64; 3]> = text
        .lines()
        .filter_map(|l| l.strip_prefix("v "))
        .map(|l| {
            let v: Vec<f64> = l.split(' ').map(|x| x.parse().unwrap()).collect();
            [v[0], v[1], v[2]]
        })
        .collect();
    assert_eq!(vertices.len(), 90);
    // 3ds Max's own OBJ of frame 5 starts with `v  -22.5210 -13.3501 7.6475` (centimetres, Z up).
    let first = vertices[0];
    assert!((first[0] + 22.5210).abs() < 0.01 && (first[1] + 13.3501).abs() < 0.01 && (first[2] - 7.6475).abs() < 0.01);
    let faces = text.lines().filter(|l| l.starts_with("f ")).count();
    assert!(faces >= 88, "the 88 quads and triangles as triangles: {faces}");
}

#[test]
fn export_says_its_space_and_writes_bonescopes_on_request() {
    // The same frame in the file's centimetres with Z up, and in Y-up metres: (x, y, z) → (x, z, −y) / 100.
    let dir = tempfile::tempdir().unwrap();
    let file = fbx("max_transformed_skin_7500_binary.fbx");
    let export = |space: &str| {
        let out = dir.path().join(format!("{space}.obj"));
        let args =
            ["export", &file, "--time", "0.1", "--format", "obj", "--space", space, "--out", out.to_str().unwrap()];
        assert!(bonescope(&args).status.success());
        std::fs::read_to_string(out).unwrap()
    };
    let first = |text: &str| -> Vec<f64> {
        let line = text.lines().find_map(|l| l.strip_prefix("v ")).unwrap();
        line.split(' ').map(|x| x.parse().unwrap()).collect()
    };
    let (file_space, metres) = (export("file"), export("y-up-metres"));
    assert!(file_space.contains("# space: the file's own axes and units (centimetres); --space y-up-metres"));
    assert!(metres.contains("# space: Y up, metres, as inspect shows; --space file for the file's own"));
    let (p, q) = (first(&file_space), first(&metres));
    let expected = [p[0] / 100.0, p[2] / 100.0, -p[1] / 100.0];
    assert!(q.iter().zip(expected).all(|(a, b)| (a - b).abs() < 1e-9), "{p:?} → {q:?}");
}

#[test]
fn export_without_meshes_or_time_is_an_error() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("none.obj");
    let bvh = asset("bvh/rotation_first_root.bvh").display().to_string();
    let run = bonescope(&["export", &bvh, "--time", "0", "--out", out.to_str().unwrap()]);
    assert_eq!(run.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&run.stderr).contains("no meshes to export"));
    assert!(!out.exists());
    let no_time = bonescope(&["export", &bvh, "--out", out.to_str().unwrap()]);
    assert_eq!(no_time.status.code(), Some(2), "--time is required");
}

#[test]
fn compare_inherit_reports_every_bone_and_when() {
    // `scan --compare-inherit` is `diff` of each file against itself under the two sides' modes.
    let file = fbx("maya_mixed_inherit_mode_7700_ascii.fbx");
    let out = json(&bonescope(&["scan", &file, "--compare-inherit", "declared,full", "--format", "json"]));
    assert_eq!(keys(&out[0]), ["animations", "error", "file"]);
    let comparison = &out[0]["animations"][0];
    let diff_keys = [
        "a",
        "b",
        "bones",
        "conversion_a",
        "conversion_b",
        "delay_b",
        "frame_rate",
        "helpers",
        "meshes",
        "only_a",
        "only_b",
        "rig_size",
        "samples",
        "skinned_a",
        "skinned_b",
        "span_a",
        "span_b",
        "worst",
    ];
    assert_eq!(keys(comparison), diff_keys);
    assert_eq!(comparison["a"], comparison["b"], "a clip against itself");
    let bones = comparison["bones"].as_array().unwrap();
    // The cube's node, static at identity, only carries the mesh: a conversion node, not compared.
    assert_eq!(bones.len(), 6);
    assert_eq!(comparison["conversion_a"], serde_json::json!(["pCube1"]));
    let rig = bonescope::import::load(std::path::Path::new(&file)).unwrap();
    let declared = rig.skeleton.declared_modes();
    let full = vec![bonescope::model::InheritMode::Full; rig.skeleton.len()];
    for bone in bones {
        let index = bone["a"].as_u64().unwrap() as usize;
        assert_eq!(bone["b"], bone["a"], "each bone pairs with itself");
        // Past rounding: decompositions of the same matrix can differ in their last bits.
        let moved = bone["position"]["max"].as_f64().unwrap() > 1e-12
            || bone["orientation_deg"]["max"].as_f64().unwrap() > 1e-9;
        // A bone declared `full` above every compensating bone evaluates the same both ways.
        if declared[index] == full[index] && ["Root", "Mid", "Left"].contains(&bone["name"].as_str().unwrap()) {
            assert!(!moved, "{bone}");
        }
    }
    // The compensating tips do differ, and the table says so too.
    let right_tip = bones.iter().find(|b| b["name"] == "Right_Tip").unwrap();
    let bone = right_tip["a"].as_u64().unwrap() as usize;
    assert_eq!(declared[bone], bonescope::model::InheritMode::SegmentCompensate);
    assert!(right_tip["orientation_deg"]["max"].as_f64().unwrap() > 1.0, "{right_tip}");
    // The reported maximum is what the two evaluations give at the reported time.
    let time = right_tip["position"]["time"].as_f64().unwrap();
    let position = |modes: &[bonescope::model::InheritMode]| {
        let pose = bonescope::eval::Evaluation::new(&rig, rig.clips.first(), modes).unwrap().pose_at(time);
        pose.model.model[bone].w_axis.truncate()
    };
    let difference = position(&declared).distance(position(&full));
    let reported = right_tip["position"]["max"].as_f64().unwrap();
    assert!(reported > 0.01 && (difference - reported).abs() < 1e-12, "{difference} vs {reported}");
    let table = bonescope(&["scan", &file, "--compare-inherit", "declared,full"]);
    let text = String::from_utf8(table.stdout).unwrap();
    assert!(text.contains("inherit: declared against full") && text.contains("orientation°"), "{text}");
    // Identical sides differ nowhere.
    let same = json(&bonescope(&["scan", &file, "--compare-inherit", "full,full", "--format", "json"]));
    for bone in same[0]["animations"][0]["bones"].as_array().unwrap() {
        assert_eq!(bone["position"]["max"], 0.0);
        assert_eq!(bone["orientation_deg"]["max"], 0.0);
    }
}

#[test]
fn compare_inherit_usage_errors() {
    let file = fbx("maya_mixed_inherit_mode_7700_ascii.fbx");
    for args in [
        vec!["scan", &file, "--compare-inherit", "declared"],
        vec!["scan", &file, "--compare-inherit", "declared,sheared"],
        vec!["scan", &file, "--compare-inherit", "declared,full", "--inherit", "full"],
    ] {
        assert_eq!(bonescope(&args).status.code(), Some(2), "{args:?}");
    }
}

fn locomotions() -> String {
    asset("fbx-proanimationbank/locomotions.fbx").display().to_string()
}

fn stderr_of(args: &[&str]) -> String {
    let out = bonescope(args);
    assert_eq!(out.status.code(), Some(2), "{args:?} should be a usage error");
    String::from_utf8(out.stderr).unwrap()
}

#[test]
fn inspect_echoes_the_layers_it_evaluated_through() {
    let out = json(&bonescope(&[
        "inspect",
        &locomotions(),
        "--anim",
        "walk",
        "--blend",
        "run",
        "--weight",
        "0.25",
        "--sync",
        "--additive",
        "jog",
        "--additive-ref",
        "rest",
        "--additive-order",
        "global",
        "--additive-weight",
        "0.5",
        "--crossfade",
        "0",
        "--crossfade-at",
        "0.5",
        "--crossfade-duration",
        "0.25",
        "--shake",
        "LeftArm",
        "--shake-param",
        "speed=20",
        "--target",
        "Head=0,0,0,1@0.5",
        "--uniform-scale",
        "Spine",
        "--interp",
        "cubic",
        "--rot-interp",
        "nlerp",
        "--bind-weight",
        "0.75",
        "--time",
        "0.3",
        "--format",
        "json",
    ]));
    let layers = &out["layers"];
    let names = ["additive", "bind_weight", "blend", "crossfade", "interpolation", "shake", "targets", "uniform_scale"];
    assert_eq!(keys(layers), names);
    assert_eq!(layers["bind_weight"], 0.75);
    assert_eq!(layers["interpolation"]["keys"], "cubic");
    assert_eq!(layers["interpolation"]["rotation"], "nlerp");
    assert_eq!(layers["blend"]["clip"], 1, "run is the file's animation 1");
    assert_eq!((layers["blend"]["weight"].as_f64(), layers["blend"]["sync"].as_bool()), (Some(0.25), Some(true)));
    assert_eq!(layers["additive"]["reference"], "rest");
    assert_eq!(layers["additive"]["order"], "global");
    assert_eq!(layers["crossfade"]["duration"], 0.25);
    assert_eq!(layers["shake"]["params"]["speed"], 20.0);
    assert_eq!(layers["shake"]["params"]["amplitude"], 0.3, "the seed's default");
    assert_eq!(layers["targets"][0]["rotation"], serde_json::json!([0.0, 0.0, 0.0, 1.0]));
    assert_eq!(layers["targets"][0]["weight"], 0.5);
    assert_eq!(layers["uniform_scale"], serde_json::json!([11]), "Spine is bone 11");
}

#[test]
fn a_synced_blend_wraps_time_at_the_blended_cycle() {
    // walk 4/3 s, run 2/3 s, a = 0.5: the cycle lasts 1 s, so t = 0.25 and t = 1.25 are the same pose.
    let at = |t: &str| {
        let args = ["inspect", &locomotions(), "--anim", "walk", "--blend", "run", "--weight", "0.5", "--sync"];
        let out = json(&bonescope(&[&args[..], &["--time", t, "--format", "json"]].concat()));
        out["samples"][0]["bones"].as_array().unwrap().iter().map(|b| matrix(&b["model"]["matrix"])).collect::<Vec<_>>()
    };
    let (first, second) = (at("0.25"), at("1.25"));
    assert!(first.iter().zip(&second).all(|(a, b)| a.abs_diff_eq(*b, 1e-9)));
    let table = String::from_utf8(
        bonescope(&["inspect", &locomotions(), "--anim", "walk", "--blend", "run", "--weight", "0.5", "--sync"]).stdout,
    )
    .unwrap();
    assert!(table.contains("synced: cycle 1.0000 s, rates 1.3333 and 0.6667"), "{table}");
}

#[test]
fn layer_options_name_what_is_wrong() {
    let file = locomotions();
    let err = stderr_of(&["inspect", &file, "--blend", "sprint", "--weight", "0.5"]);
    assert!(err.contains("--blend: no animation `sprint` (available: 0 (jog), 1 (run), 2 (walk))"), "{err}");
    let err = stderr_of(&["inspect", &file, "--blend", "run", "--weight", "1.5"]);
    assert!(err.contains("--weight must be between 0 and 1, got 1.5"), "{err}");
    let err = stderr_of(&["inspect", &file, "--blend", "run"]);
    assert!(err.contains("--weight"), "--blend requires --weight: {err}");
    let err = stderr_of(&["inspect", &file, "--shake", "Tail"]);
    assert!(err.contains("--shake: no bone named `Tail`"), "{err}");
    let err = stderr_of(&["inspect", &file, "--shake", "Head", "--shake-param", "wobble=1"]);
    assert!(err.contains("no shake parameter `wobble`") && err.contains("attenuation"), "{err}");
    let err = stderr_of(&["inspect", &file, "--target", "Head=0,0,0"]);
    assert!(err.contains("four quaternion components"), "{err}");
    let err = stderr_of(&["inspect", &file, "--target", "Head=0,0,0,0"]);
    assert!(err.contains("non-zero quaternion"), "{err}");
    let err = stderr_of(&["inspect", &file, "--bind-weight", "NaN"]);
    assert!(err.contains("--bind-weight must be between 0 and 1"), "{err}");
    let err = stderr_of(&["inspect", &file, "--crossfade", "run", "--crossfade-at", "1"]);
    assert!(err.contains("--crossfade-duration"), "{err}");
}

#[test]
fn scan_evaluates_through_the_layers() {
    // Full bind weight 0 on stretchy: every sample is the bind pose, which shears nothing.
    let plain = json(&bonescope(&["scan", &stretchy(), "--anim", "0", "--format", "json"]));
    assert!(!plain[0]["animations"][0]["stretched"].as_array().unwrap().is_empty());
    let bound = json(&bonescope(&["scan", &stretchy(), "--anim", "0", "--bind-weight", "0", "--format", "json"]));
    assert!(bound[0]["animations"][0]["stretched"].as_array().unwrap().is_empty(), "{}", bound[0]["animations"][0]);
    let err = stderr_of(&["scan", &stretchy(), "--compare-inherit", "declared,full", "--bind-weight", "0.5"]);
    assert!(err.contains("no layer options"), "{err}");
}

#[test]
fn storage_reports_marked_bones_bytes_and_errors() {
    let args = ["storage", &stretchy(), "--anim", "squash_stretch", "--inherit", "segment-compensate"];
    let out = json(&bonescope(&[&args[..], &["--format", "json"]].concat()));
    let report = &out[0]["animations"][0];
    assert_eq!(
        keys(report),
        [
            "animation",
            "bones",
            "bytes_trs",
            "bytes_with_stretch",
            "frames",
            "inherit",
            "marked",
            "probe_distance",
            "rate",
            "reconstruction",
            "trs_only"
        ]
    );
    let marked: Vec<&str> = report["marked"].as_array().unwrap().iter().map(|m| m["name"].as_str().unwrap()).collect();
    assert_eq!(marked, ["forearm", "neck"]);
    let (frames, bones) = (report["frames"].as_u64().unwrap(), report["bones"].as_u64().unwrap());
    assert_eq!(report["bytes_trs"].as_u64().unwrap(), frames * bones * 40);
    assert_eq!(report["bytes_with_stretch"].as_u64().unwrap(), frames * bones * 40 + frames * 2 * 16);
    let max = |runtime: &str, at: &str| report[runtime][at]["max"].as_f64().unwrap();
    assert!(max("reconstruction", "bone_axes") < 1e-5 && max("reconstruction", "vertices") < 1e-5);
    assert!(max("trs_only", "bone_axes") > 1e-2 && max("trs_only", "vertices") > 1e-2);
    let table = String::from_utf8(bonescope(&args).stdout).unwrap();
    assert!(
        table.contains("marked (stretch channel): forearm (") && table.contains("TRS only (stretch dropped)"),
        "{table}"
    );
    let err = stderr_of(&["storage", &stretchy(), "--probe-distance", "0"]);
    assert!(err.contains("--probe-distance"), "{err}");
}

#[test]
fn scan_walks_folders_by_content_with_include_globs() {
    // A folder (not "Is a directory"): its animations by content, filtered, in sorted order.
    let folder = asset("blender").display().to_string();
    let output = bonescope(&["scan", &folder, "--include", "*.glb", "--format", "json"]);
    assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));
    let files: Vec<String> =
        json(&output).as_array().unwrap().iter().map(|f| f["file"].as_str().unwrap().to_owned()).collect();
    let names: Vec<&str> = files.iter().map(|f| f.rsplit('/').next().unwrap()).collect();
    assert_eq!(names, ["stretchy_full.glb", "stretchy_noinherit.glb"]);
    // A glob that matches nothing is a warning, and the other inputs are still scanned.
    let missing = asset("nowhere").join("*.fbx").display().to_string();
    let output = bonescope(&["scan", &folder, &missing, "--include", "*.bvh"]);
    assert!(output.status.success());
    assert!(String::from_utf8_lossy(&output.stderr).contains("matches no file"));
    assert!(String::from_utf8_lossy(&output.stdout).contains("stretchy_full.bvh"));
}

#[test]
fn a_folder_without_animations_fails_the_scan_unless_allowed() {
    // A CI job pointed at the wrong folder must not pass with an empty report.
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("notes.txt"), "not an animation").unwrap();
    let folder = dir.path().display().to_string();
    for command in ["scan", "storage"] {
        let out = bonescope(&[command, &folder]);
        assert_eq!(out.status.code(), Some(2), "{command}");
        assert_eq!(String::from_utf8_lossy(&out.stderr), format!("error: no animation files under {folder}\n"));
        assert!(out.stdout.is_empty(), "{command}");
        let allowed = bonescope(&[command, &folder, "--allow-empty", "--format", "json"]);
        assert_eq!(allowed.status.code(), Some(0), "{command}: {}", String::from_utf8_lossy(&allowed.stderr));
        assert_eq!(json(&allowed), serde_json::json!([]), "{command}");
    }
    // A folder with one file split in two shards: the shard without it passes.
    std::os::unix::fs::symlink(stretchy(), dir.path().join("stretchy_full.glb")).unwrap();
    for shard in ["1/2", "2/2"] {
        assert_eq!(bonescope(&["scan", &folder, "--shard", shard]).status.code(), Some(0), "{shard}");
    }
}

#[test]
fn bake_names_the_path_it_cannot_write_with_the_systems_reason() {
    // Not the temporary file it writes first: the user never named that.
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("missing/baked.glb").display().to_string();
    let folder = dir.path().join("folder.glb");
    std::fs::create_dir(&folder).unwrap();
    let folder = folder.display().to_string();
    for (out, reason) in
        [(&missing, "No such file or directory (os error 2)"), (&folder, "Is a directory (os error 21)")]
    {
        let run = bonescope(&["bake", &stretchy(), "--out", out]);
        assert_eq!(run.status.code(), Some(2), "{out}");
        assert_eq!(String::from_utf8_lossy(&run.stderr), format!("error: cannot write {out}: {reason}\n"));
    }
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1, "no temporary file left beside the folder");
}

#[test]
fn bake_refuses_an_output_it_does_not_write_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    for name in ["baked.fbx", "baked.gltf", "baked"] {
        let out = dir.path().join(name).display().to_string();
        let run = bonescope(&["bake", &stretchy(), "--out", &out]);
        assert_eq!(run.status.code(), Some(2), "{out}");
        let stderr = String::from_utf8_lossy(&run.stderr);
        let expected = format!("error: {out}: bake writes a file named `.glb`, `.usda`, `.usdc` or `.usdz` (got `");
        assert!(stderr.starts_with(&expected), "{stderr}");
        assert_eq!(stderr.lines().count(), 1, "{stderr}");
    }
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0, "nothing written");
}

/// Element names of an XML document, in order, with their attributes.
fn xml_elements(xml: &str) -> Vec<(String, std::collections::HashMap<String, String>)> {
    let mut reader = quick_xml::Reader::from_str(xml);
    let mut elements = Vec::new();
    loop {
        match reader.read_event().expect("well-formed XML") {
            quick_xml::events::Event::Start(e) | quick_xml::events::Event::Empty(e) => {
                let attributes = e
                    .attributes()
                    .map(|a| {
                        let a = a.unwrap();
                        (
                            String::from_utf8_lossy(a.key.as_ref()).into_owned(),
                            a.normalized_value(quick_xml::XmlVersion::Explicit1_0).unwrap().into_owned(),
                        )
                    })
                    .collect();
                elements.push((String::from_utf8_lossy(e.name().as_ref()).into_owned(), attributes));
            }
            quick_xml::events::Event::Eof => break,
            _ => {}
        }
    }
    elements
}

#[test]
fn scan_reports_for_ci_junit_and_json_lines() {
    let folder = asset("blender").display().to_string();
    let args = ["scan", folder.as_str(), "no-such-file.fbx", "--include", "*.glb"];
    // JUnit: a suite per file, a case per clip, a failure per stretched bone, the missing file an error.
    let junit = bonescope(&[&args[..], &["--format", "junit"]].concat());
    assert_eq!(junit.status.code(), Some(2), "a file did not load");
    let elements = xml_elements(&String::from_utf8(junit.stdout).unwrap());
    let count = |name: &str| elements.iter().filter(|(n, _)| n == name).count();
    assert_eq!((count("testsuites"), count("testsuite"), count("testcase")), (1, 3, 5));
    assert_eq!((count("failure"), count("error")), (8, 1));
    let total = &elements[0].1;
    assert_eq!((total["tests"].as_str(), total["failures"].as_str(), total["errors"].as_str()), ("5", "2", "1"));
    let failure = elements.iter().find(|(n, _)| n == "failure").unwrap();
    assert!(failure.1["message"].contains("stretched: worst shear"), "{:?}", failure.1);
    // JSON lines: one object per file, the same as the JSON array's elements.
    let lines = bonescope(&[&args[..], &["--format", "jsonl"]].concat());
    let array = bonescope(&[&args[..], &["--format", "json"]].concat());
    let array: Value = serde_json::from_slice(&array.stdout).unwrap();
    let lines: Vec<Value> =
        String::from_utf8(lines.stdout).unwrap().lines().map(|l| serde_json::from_str(l).unwrap()).collect();
    assert_eq!(Value::Array(lines), array);
}

#[test]
fn the_shards_of_a_folder_partition_it() {
    let folder = asset("bvh").display().to_string();
    let files = |extra: &[&str]| -> Vec<String> {
        let output = bonescope(&[&["scan", folder.as_str(), "--format", "jsonl"][..], extra].concat());
        let text = String::from_utf8(output.stdout).unwrap();
        text.lines().map(|l| serde_json::from_str::<Value>(l).unwrap()["file"].as_str().unwrap().to_owned()).collect()
    };
    let whole = files(&[]);
    let mut union: Vec<String> = (1..=3).flat_map(|k| files(&["--shard", &format!("{k}/3")])).collect();
    union.sort();
    assert_eq!(union, whole);
    let bad = bonescope(&["scan", &folder, "--shard", "4/3"]);
    assert_eq!(bad.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&bad.stderr).contains("expected K/N"));
}

/// A path named on the command line that does not exist fails every shard as it fails the whole scan (one line
/// naming it; the same error record in JSON lines and JUnit), beside a folder whose files the shards still split.
#[test]
fn a_missing_input_fails_every_shard() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("MISSING_FOLDER").display().to_string();
    let folder = asset("bvh").display().to_string();
    let scan = |extra: &[&str]| bonescope(&[&["scan", folder.as_str(), missing.as_str()][..], extra].concat());
    let records = |output: &std::process::Output| -> Vec<Value> {
        let text = String::from_utf8(output.stdout.clone()).unwrap();
        text.lines().map(|l| serde_json::from_str(l).unwrap()).collect()
    };
    let whole = records(&scan(&["--format", "jsonl"]));
    let error = whole.iter().find(|r| r["file"] == missing.as_str()).expect("the missing path's record").clone();
    let mut found = Vec::new();
    for k in 1..=8 {
        let shard = format!("{k}/8");
        let table = scan(&["--shard", &shard]);
        assert_eq!(table.status.code(), Some(2), "shard {shard}");
        let stderr = String::from_utf8_lossy(&table.stderr);
        assert_eq!(stderr.lines().filter(|l| l.starts_with("error: ") && l.contains(&missing)).count(), 1, "{stderr}");
        let lines = scan(&["--shard", &shard, "--format", "jsonl"]);
        assert_eq!(lines.status.code(), Some(2), "shard {shard}");
        let (errors, files): (Vec<Value>, Vec<Value>) = records(&lines).into_iter().partition(|r| *r == error);
        assert_eq!(errors.len(), 1, "shard {shard}: the unsharded scan's record");
        found.extend(files);
        let junit = String::from_utf8(scan(&["--shard", &shard, "--format", "junit"]).stdout).unwrap();
        assert!(xml_elements(&junit).iter().any(|(n, a)| n == "error" && a["message"].contains(&missing)), "{junit}");
    }
    let mut rest: Vec<Value> = whole.into_iter().filter(|r| *r != error).collect();
    let by_file = |r: &Value| r["file"].as_str().unwrap().to_owned();
    rest.sort_by_key(by_file);
    found.sort_by_key(by_file);
    assert_eq!(found, rest, "the folder's files, each in one shard");
}

/// The older spellings of the exit gates, `--max-error` (bake, diff) and `--fail-on-stretch` (scan, report), still
/// work, and gate exactly as `--fail-above`.
#[test]
fn the_old_gate_spellings_gate_as_fail_above() {
    let fbx = |name: &str| asset(&format!("blender/{name}.fbx")).display().to_string();
    let (full, noinherit) = (fbx("stretchy_full"), fbx("stretchy_noinherit"));
    let dir = tempfile::tempdir().unwrap();
    let baked = dir.path().join("baked.glb").display().to_string();
    let lines = dir.path().join("scan.jsonl");
    std::fs::write(&lines, bonescope(&["scan", &stretchy(), "--format", "jsonl"]).stdout).unwrap();
    let lines = lines.display().to_string();
    // A command, its old spelling, a limit it is over, one it is within: the scan's worst shear is 18.7°; the
    // files' worst distance 13.9 % of the rig; the TRS bake's 4e-6.
    let gates: [(&[&str], &str, &str, &str); 4] = [
        (&["scan", &stretchy()], "--fail-on-stretch", "0", "30"),
        (&["report", &lines], "--fail-on-stretch", "0", "30"),
        (&["diff", &full, &noinherit], "--max-error", "1%", "20%"),
        (&["bake", &full, "--for", "unreal", "--out", &baked], "--max-error", "0", "1%"),
    ];
    for (command, old, over, within) in gates {
        for (limit, code) in [(over, 1), (within, 0)] {
            for spelling in ["--fail-above", old] {
                let run = bonescope(&[command, &[spelling, limit]].concat());
                let stderr = String::from_utf8_lossy(&run.stderr);
                assert_eq!(run.status.code(), Some(code), "{command:?} {spelling} {limit}: {stderr}");
            }
        }
    }
}

#[test]
fn report_merges_the_shards_json_lines_into_the_whole_scan() {
    let folder = asset("blender").display().to_string();
    let dir = tempfile::tempdir().unwrap();
    let mut shards = Vec::new();
    for k in 1..=2 {
        let output =
            bonescope(&["scan", &folder, "--include", "*.glb", "--shard", &format!("{k}/2"), "--format", "jsonl"]);
        let path = dir.path().join(format!("shard{k}.jsonl"));
        std::fs::write(&path, output.stdout).unwrap();
        shards.push(path.display().to_string());
    }
    let whole = json(&bonescope(&["scan", &folder, "--include", "*.glb", "--format", "json"]));
    let merged = json(&bonescope(&["report", &shards[0], &shards[1], "--format", "json"]));
    assert_eq!(merged, whole, "the shards' reports, merged, are the whole scan's");
    let gate = bonescope(&["report", &shards[0], &shards[1], "--fail-above"]);
    assert_eq!(gate.status.code(), Some(1), "stretchy_full.glb has stretched bones");
    std::fs::write(dir.path().join("bad.jsonl"), "not json\n").unwrap();
    let bad = bonescope(&["report", &dir.path().join("bad.jsonl").display().to_string()]);
    assert_eq!(bad.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&bad.stderr).contains("bad.jsonl: line 1"));
}

#[test]
fn comparisons_and_storage_reports_come_as_junit_too() {
    let maya = asset("fbx-ufbx-data/maya_mixed_inherit_mode_7700_ascii.fbx").display().to_string();
    for command in [&["scan", "--compare-inherit", "declared,full"][..], &["storage"][..]] {
        let output = bonescope(&[command, &[maya.as_str(), "--format", "junit"][..]].concat());
        assert!(output.status.success(), "{command:?}: {}", String::from_utf8_lossy(&output.stderr));
        let elements = xml_elements(&String::from_utf8(output.stdout).unwrap());
        let count = |name: &str| elements.iter().filter(|(n, _)| n == name).count();
        assert_eq!((count("testcase"), count("failure"), count("system-out")), (1, 0, 1), "{command:?}");
    }
}

/// A build without the `gui` feature (`--no-default-features`) has every other command and says what it lacks.
#[cfg(not(feature = "gui"))]
#[test]
fn without_the_gui_the_app_and_render_say_they_need_it() {
    for args in [vec![], vec!["render", "--out", "x.png"]] {
        let run = bonescope(&args);
        assert_eq!(run.status.code(), Some(2), "{args:?}");
        let stderr = String::from_utf8_lossy(&run.stderr);
        assert!(stderr.contains("needs the `gui` feature") && stderr.lines().count() == 1, "{stderr}");
        // The install that exists: from a checkout, with the default features.
        assert!(stderr.contains("cargo install --path . --locked"), "{stderr}");
    }
}

#[test]
fn gltf_frame_rates_are_read_from_sparse_key_times() {
    // Blender's cubic-spline exports key every 10th to 30th frame of its 30 fps scene from frame 1, (1 + 10k)/30 s
    // and so on: 0.33 to 1 s apart, yet at 30 fps (the most common spacing read 2 and 3 fps).
    for anim in ["squash_stretch", "wave"] {
        let out = json(&bonescope(&["inspect", &stretchy(), "--anim", anim, "--format", "json"]));
        assert_eq!(out["animation"]["frame_rate"], 30.0, "{anim}");
    }
    let scan = json(&bonescope(&["scan", &stretchy(), "--format", "json"]));
    let rates: Vec<&Value> =
        scan[0]["animations"].as_array().unwrap().iter().map(|a| &a["animation"]["frame_rate"]).collect();
    assert_eq!(rates, [30.0, 30.0]);
}

/// A copy of Cesium Man in `dir` with skin joint `joint`'s inverse bind matrix translated by `offset` (in the
/// skin's bind space, metres), edited in the base64 buffer the file embeds; the path and the moved joint's node.
fn cesium_man_with_a_moved_bind(dir: &Path, joint: usize, offset: [f32; 3]) -> (PathBuf, u64) {
    let mut gltf: Value =
        serde_json::from_slice(&std::fs::read(asset("gltf-khronos/cesium_man.gltf")).unwrap()).unwrap();
    let skin = &gltf["skins"][0];
    let node = skin["joints"][joint].as_u64().unwrap();
    let accessor = &gltf["accessors"][skin["inverseBindMatrices"].as_u64().unwrap() as usize];
    let view = &gltf["bufferViews"][accessor["bufferView"].as_u64().unwrap() as usize];
    let offset_of = |v: &Value| v["byteOffset"].as_u64().unwrap_or(0) as usize;
    // Column-major 4×4 floats: the translation is floats 12 to 14 of the joint's matrix.
    let translation = offset_of(view) + offset_of(accessor) + 64 * joint + 4 * 12;
    let buffer = view["buffer"].as_u64().unwrap() as usize;
    let uri = gltf["buffers"][buffer]["uri"].as_str().unwrap().to_owned();
    let (prefix, data) = uri.split_once("base64,").unwrap();
    let base64 = base64::engine::general_purpose::STANDARD;
    let mut bytes = base64.decode(data).unwrap();
    for (k, delta) in offset.iter().enumerate() {
        let at = translation + 4 * k;
        let moved = f32::from_le_bytes(bytes[at..at + 4].try_into().unwrap()) + delta;
        bytes[at..at + 4].copy_from_slice(&moved.to_le_bytes());
    }
    gltf["buffers"][buffer]["uri"] = Value::from(format!("{prefix}base64,{}", base64.encode(bytes)));
    let path = dir.join("cesium_man_moved_bind.gltf");
    std::fs::write(&path, serde_json::to_vec(&gltf).unwrap()).unwrap();
    (path, node)
}

#[test]
fn inspect_warns_of_broken_skins_and_notes_stored_poses() {
    // Skins that render right, stored in another pose than their bind: a note, no bind mismatch.
    let skins = [
        ("blender/stretchy_full.fbx", "1 joint (forearm) is posed"),
        ("fbx-ufbx-data/max_transformed_skin_7500_binary.fbx", "3 joints (Bone002, Bone003, Bone004) are posed"),
        ("fbx-ufbx-corpus/maya_dual_quaternion_7500_ascii.fbx", "1 joint (joint2) is posed"),
    ];
    for (file, posed) in skins {
        let path = asset(file).display().to_string();
        let out = json(&bonescope(&["inspect", &path, "--format", "json"]));
        assert_eq!(out["bind_mismatches"], Value::Array(vec![]), "{file}");
        let notes: Vec<&str> = out["notes"].as_array().unwrap().iter().map(|n| n.as_str().unwrap()).collect();
        assert!(
            notes.iter().any(|n| n.starts_with("the stored pose is not the bind pose") && n.contains(posed)),
            "{notes:?}"
        );
        let table = String::from_utf8(bonescope(&["inspect", &path]).stdout).unwrap();
        assert!(table.contains(&format!("note: the stored pose is not the bind pose: {posed}")), "{table}");
        assert!(!table.contains("warning"), "{table}");
    }
    // Cesium Man with one joint's bind moved 5 cm (node16, above node17 which stays bound where it was): broken.
    let dir = tempfile::tempdir().unwrap();
    let (moved, node) = cesium_man_with_a_moved_bind(dir.path(), 5, [0.0, 0.05, 0.0]);
    let moved = moved.display().to_string();
    let out = json(&bonescope(&["inspect", &moved, "--format", "json"]));
    let name =
        out["samples"][0]["bones"].as_array().unwrap().iter().find(|b| b["node"] == node).unwrap()["name"].clone();
    let mismatches = out["bind_mismatches"].as_array().unwrap();
    assert_eq!(mismatches.iter().map(|m| &m["name"]).collect::<Vec<_>>(), [&name]);
    assert!((mismatches[0]["distance"].as_f64().unwrap() - 0.05).abs() < 1e-6, "{}", mismatches[0]);
    assert!(mismatches[0]["angle_deg"].as_f64().unwrap() < 1e-3, "{}", mismatches[0]);
    assert!(!out["notes"].as_array().unwrap().iter().any(|n| n.as_str().unwrap().contains("bind pose")));
    let table = String::from_utf8(bonescope(&["inspect", &moved]).stdout).unwrap();
    assert!(table.contains(&format!("warning: `{}` is bound 0.05", name.as_str().unwrap())), "{table}");
}

#[test]
fn a_reader_that_stops_early_ends_the_command_quietly() {
    // `bonescope explain … | head -c 1`: the reader goes before the report is written. The command stops as a
    // program stopped by the closed pipe does (status 141), with nothing on stderr: no panic, no error line.
    // The pipe's reading end is closed before the command starts: closed after, a fast command could write its whole
    // report into the pipe's buffer first and rightly exit 0.
    // Every command that writes a report to standard output, in each way it writes one.
    use std::os::unix::process::ExitStatusExt;
    use std::process::{Command, Stdio};
    let dir = tempfile::tempdir().unwrap();
    let (file, baked) = (stretchy(), dir.path().join("baked.glb").display().to_string());
    let file = file.as_str();
    let lines = dir.path().join("scan.jsonl");
    std::fs::write(&lines, bonescope(&["scan", file, "--format", "jsonl"]).stdout).unwrap();
    let lines = lines.display().to_string();
    for args in [
        vec!["explain", file, "--format", "json"],
        vec!["inspect", file, "--format", "table"],
        vec!["inspect", file, "--format", "json"],
        vec!["scan", file, "--format", "json"],
        vec!["scan", file, "--format", "jsonl"],
        vec!["diff", file, file, "--format", "json"],
        vec!["bake", file, "--out", &baked, "--format", "json"],
        vec!["report", &lines, "--format", "json"],
    ] {
        let (reader, writer) = std::io::pipe().expect("a pipe");
        drop(reader);
        let out = Command::new(env!("CARGO_BIN_EXE_bonescope"))
            .args(&args)
            .stdout(writer)
            .stderr(Stdio::piped())
            .output()
            .expect("bonescope runs");
        assert_eq!(out.status.code(), Some(141), "{args:?}: {:?}", out.status.signal());
        assert_eq!(String::from_utf8_lossy(&out.stderr), "", "{args:?}");
    }
}
