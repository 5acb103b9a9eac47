//! The `inspect` and `scan` commands as a user runs them: output shape, numbers that must hold, exit codes.

use std::path::PathBuf;
use std::process::{Command, Output};

use glam::DMat4;
use serde_json::Value;

fn asset(path: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared/assets").join(path)
}

fn bonescope(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_bonescope")).args(args).output().expect("bonescope runs")
}

fn stretchy() -> String {
    asset("blender/stretchy_full.glb").display().to_string()
}

fn json(output: &Output) -> Value {
    assert!(output.status.success(), "stderr: {}", String::from_utf8_lossy(&output.stderr));
    serde_json::from_slice(&output.stdout).expect("valid JSON")
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
    assert_eq!(keys(&out), ["animation", "file", "inherit", "notes", "samples"]);
    assert_eq!(keys(&out["animation"]), ["duration", "index", "name"]);
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
    assert_eq!(out["inherit"], "segment-compensate");
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
    assert_eq!(bonescope(&["scan", &stretchy(), "--fail-on-stretch"]).status.code(), Some(1));
    let compensated = bonescope(&["scan", &stretchy(), "--fail-on-stretch", "--inherit", "segment-compensate"]);
    assert_eq!(compensated.status.code(), Some(0));
    let fox = asset("gltf-khronos/Fox.glb").display().to_string();
    assert_eq!(bonescope(&["scan", &fox, "--fail-on-stretch"]).status.code(), Some(0));
    // A missing file: exit 2, but the loadable file is still reported.
    let out = bonescope(&["scan", "no-such-file.glb", &stretchy(), "--format", "json"]);
    assert_eq!(out.status.code(), Some(2));
    let report: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!(report[0]["error"].as_str().unwrap().contains("no-such-file.glb"));
    assert_eq!(report[1]["error"], Value::Null);
    assert_eq!(report[1]["animations"].as_array().unwrap().len(), 2);
    assert!(String::from_utf8_lossy(&out.stderr).contains("no-such-file.glb"));
}

#[test]
fn scan_json_reports_the_stretched_bones_with_when_and_how_much() {
    let out = json(&bonescope(&["scan", &stretchy(), "--anim", "squash_stretch", "--format", "json"]));
    let scan = &out[0]["animations"][0];
    assert_eq!(scan["animation"]["name"], "squash_stretch");
    assert_eq!(scan["rate"], 60.0);
    let samples = scan["samples"].as_u64().unwrap();
    // 2.033 s at 60 Hz gives 123 grid times; the 61 key times at 30 fps add those off the 60 Hz grid.
    assert!(samples >= 123, "{samples}");
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
