//! `bonescope diff` and `bonescope bake` as a user runs them: how bones pair up, what the reports hold, exit codes,
//! and what a failed bake leaves behind (nothing).

mod common;

use std::path::Path;
use std::sync::Arc;

use bonescope::diff::{Align, Clips, FileSide, diff_files};
use bonescope::eval::Setup;
use bonescope::eval::layers::RotationInterpolation;
use bonescope::model::{Bone, BoneTracks, Clip, Interpolation, Rig, Skeleton, Track, Transform};
use common::{asset, bonescope, json};
use glam::Quat;
use serde_json::Value;

fn path(p: &Path) -> String {
    p.display().to_string()
}

/// `rigged_simple.gltf` with its nodes renamed by `rename` (the names of the original's nodes in, new names out).
fn renamed(folder: &Path, rename: impl Fn(&str) -> String) -> String {
    let mut gltf: Value =
        serde_json::from_slice(&std::fs::read(asset("gltf-khronos/rigged_simple.gltf")).unwrap()).unwrap();
    for node in gltf["nodes"].as_array_mut().unwrap() {
        let name = node["name"].as_str().unwrap().to_owned();
        node["name"] = Value::from(rename(&name));
    }
    let out = folder.join("renamed.gltf");
    std::fs::write(&out, serde_json::to_vec(&gltf).unwrap()).unwrap();
    path(&out)
}

fn names(list: &Value) -> Vec<&str> {
    list.as_array().unwrap().iter().map(|v| v.as_str().unwrap()).collect()
}

#[test]
fn a_file_against_itself_differs_by_nothing() {
    let file = path(&asset("blender/stretchy_full.glb"));
    let out = bonescope(&["diff", &file, &file, "--format", "json", "--fail-above", "0"]);
    assert_eq!(out.status.code(), Some(0));
    let report = json(&out);
    let keys: Vec<&str> = report.as_object().unwrap().keys().map(String::as_str).collect();
    let all = [
        "a",
        "animations",
        "b",
        "clips_only_a",
        "clips_only_b",
        "inherit_a",
        "inherit_b",
        "interp_a",
        "interp_b",
        "rate",
        "unit_a",
        "unit_b",
    ];
    assert_eq!(keys, all);
    let animations = report["animations"].as_array().unwrap();
    assert_eq!(animations.len(), 2, "both clips, paired by name");
    for animation in animations {
        assert_eq!(animation["a"], animation["b"]);
        assert_eq!(animation["worst"]["max"], 0.0);
        assert_eq!(animation["bones"].as_array().unwrap().len(), 8, "10 nodes, the armature and mesh nodes aside");
        assert_eq!(animation["meshes"][0]["vertices"], 648);
        let bone = &animation["bones"][4];
        let fields: Vec<&str> = bone.as_object().unwrap().keys().map(String::as_str).collect();
        assert_eq!(fields, ["a", "b", "name", "orientation_deg", "position", "probe", "scale_ratio", "stretch_deg"]);
    }
}

#[test]
fn two_modes_of_one_file_differ_where_the_modes_do_and_fail_the_gate() {
    // Segment scale compensate moves every bone below the squashing spine.
    let file = path(&asset("blender/stretchy_full.glb"));
    let diff = |more: &[&str]| {
        let modes = ["diff", &file, &file, "--inherit-b", "segment-compensate", "--anim-a", "squash_stretch"];
        bonescope(&[&modes[..], more].concat())
    };
    let out = diff(&["--fail-above", "1e-6"]);
    assert_eq!(out.status.code(), Some(1), "{}", String::from_utf8_lossy(&out.stderr));
    let table = String::from_utf8(out.stdout).unwrap();
    assert!(
        table.contains("inherit: segment-compensate") && table.contains("`squash_stretch` against `squash_stretch`")
    );
    assert_eq!(diff(&["--fail-above", "100%"]).status.code(), Some(0), "a limit of the whole rig's size passes");
    let report = json(&diff(&["--format", "json"]));
    let bones = report["animations"][0]["bones"].as_array().unwrap();
    let by_name = |n: &str| bones.iter().find(|b| b["name"] == n).unwrap();
    assert_eq!(by_name("hips")["probe"]["max"], 0.0, "above the squash nothing changes");
    assert!(by_name("hand")["probe"]["max"].as_f64().unwrap() > 1e-3);
}

#[test]
fn bones_pair_by_name_without_case_or_namespace_and_by_map() {
    let folder = tempfile::tempdir().unwrap();
    let original = path(&asset("gltf-khronos/rigged_simple.gltf"));
    // `Bone` becomes `mixamorig:BONE`, `Bone.001` becomes `Tip`, and the nodes that only turn the axes (`Z_UP`, a
    // quarter about X; `Armature`, a quarter about Z) and carry the mesh (`Cylinder`) get other names too.
    let other = renamed(folder.path(), |name| match name {
        "Bone" => "mixamorig:BONE".to_owned(),
        "Bone.001" => "Tip".to_owned(),
        "Z_UP" => "Y_UP".to_owned(),
        "Armature" => "Rig|armature".to_owned(),
        "Cylinder" => "Tube".to_owned(),
        other => other.to_owned(),
    });
    let report = json(&bonescope(&["diff", &original, &other, "--format", "json"]));
    let animation = &report["animations"][0];
    assert_eq!(names(&animation["only_a"]), ["Bone.001"]);
    assert_eq!(names(&animation["only_b"]), ["Tip"]);
    assert_eq!(names(&animation["conversion_a"]), ["Z_UP", "Armature", "Cylinder"]);
    assert_eq!(names(&animation["conversion_b"]), ["Y_UP", "Rig|armature", "Tube"], "by role, whatever the names");
    let bone = animation["bones"].as_array().unwrap().iter().find(|b| b["name"] == "Bone").unwrap();
    assert_eq!(bone["name_b"], "mixamorig:BONE");
    let mapped = json(&bonescope(&["diff", &original, &other, "--map", "Bone.001=Tip", "--format", "json"]));
    let animation = &mapped["animations"][0];
    assert!(names(&animation["only_a"]).is_empty() && names(&animation["only_b"]).is_empty());
    assert_eq!(animation["worst"]["max"], 0.0, "renaming moves nothing");
    // A map that names no bone is an error naming it.
    let out = bonescope(&["diff", &original, &other, "--map", "Nope=Tube"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("`Nope`"));
}

#[test]
fn a_missing_file_is_an_error_naming_it() {
    let out = bonescope(&["diff", "no-such-file.glb", &path(&asset("blender/stretchy_full.glb"))]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("no-such-file.glb"));
}

#[test]
fn bake_reports_json_and_diff_pairs_its_helpers_away() {
    // The demo arm under segment scale compensate: the forearm needs a helper node.
    let folder = tempfile::tempdir().unwrap();
    let out = path(&folder.path().join("demo.glb"));
    let report = json(&bonescope(&["bake", "--inherit", "segment-compensate", "--out", &out, "--format", "json"]));
    let keys: Vec<&str> = report.as_object().unwrap().keys().map(String::as_str).collect();
    assert_eq!(keys, ["animations", "engine", "helpers", "notes", "rig_size", "rotations", "strategy", "tolerance"]);
    // The default engine: safe everywhere, its keys checked under both interpolations.
    assert_eq!(report["engine"], "generic");
    assert_eq!(report["rotations"], serde_json::json!(["slerp", "nlerp"]));
    assert_eq!(names(&report["helpers"]), ["forearm"]);
    assert_eq!(report["strategy"], "exact");
    let animation = &report["animations"][0];
    let forearm = animation["bones"].as_array().unwrap().iter().find(|b| b["name"] == "forearm").unwrap();
    assert_eq!(forearm["nodes"], "helper");
    let worst = animation["worst"]["max"].as_f64().unwrap();
    assert!(worst < 1e-4 * report["rig_size"].as_f64().unwrap());
    // Against the demo's own evaluation the bake pairs every bone and leaves its helper out.
    let demo = folder.path().join("demo_source.glb");
    json(&bonescope(&[
        "bake",
        "--out",
        &path(&demo),
        "--inherit",
        "segment-compensate",
        "--tolerance",
        "0",
        "--format",
        "json",
    ]));
    let diff = json(&bonescope(&["diff", &path(&demo), &out, "--format", "json"]));
    let animation = &diff["animations"][0];
    assert_eq!(animation["helpers"], 2, "one helper node in each file");
    assert!(names(&animation["only_a"]).is_empty() && names(&animation["only_b"]).is_empty());
}

#[test]
fn bake_gates_on_the_largest_error_and_writes_the_file_anyway() {
    let folder = tempfile::tempdir().unwrap();
    let out = path(&folder.path().join("gate.glb"));
    let file = path(&asset("fbx-ufbx-data/maya_mixed_inherit_mode_7700_ascii.fbx"));
    let bake = |limit: &str| {
        let args =
            ["bake", &file, "--strategy", "trs", "--inherit", "unscaled-parent", "--out", &out, "--fail-above", limit];
        bonescope(&args)
    };
    let strict = bake("1e-9");
    assert_eq!(strict.status.code(), Some(1), "{}", String::from_utf8_lossy(&strict.stderr));
    assert!(Path::new(&out).exists(), "the file is written; the exit code is the gate");
    let table = String::from_utf8(strict.stdout).unwrap();
    assert!(table.contains("strategy: trs") && table.contains("Mid"));
    let loose = bake("50%");
    assert_eq!(loose.status.code(), Some(0));
}

#[test]
fn a_failed_bake_leaves_the_output_as_it_was() {
    let folder = tempfile::tempdir().unwrap();
    let out = folder.path().join("kept.glb");
    std::fs::write(&out, b"the previous bake").unwrap();
    let broken = folder.path().join("broken.gltf");
    std::fs::write(&broken, b"{\"asset\": {\"version\": \"2.0\"}, \"nodes\": [{\"children\": [0]}]}").unwrap();
    let run = bonescope(&["bake", &path(&broken), "--out", &path(&out)]);
    assert_eq!(run.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(stderr.contains("broken.gltf") && stderr.contains("nodes[0]"), "{stderr}");
    assert_eq!(std::fs::read(&out).unwrap(), b"the previous bake");
    let unwritable = bonescope(&["bake", "--out", &path(&folder.path().join("no/such/folder/x.glb"))]);
    assert_eq!(unwritable.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&unwritable.stderr).contains("cannot write"));
    let leftovers: Vec<_> = std::fs::read_dir(folder.path()).unwrap().map(|e| e.unwrap().file_name()).collect();
    assert_eq!(leftovers.len(), 2, "no temporary file left behind: {leftovers:?}");
}

#[test]
fn a_layered_bake_is_one_new_clip() {
    let folder = tempfile::tempdir().unwrap();
    let out = path(&folder.path().join("blend.glb"));
    let file = path(&asset("fbx-proanimationbank/locomotions.fbx"));
    let args = [
        "bake", &file, "--anim", "walk", "--blend", "run", "--weight", "0.5", "--sync", "--out", &out, "--format",
        "json",
    ];
    let report = json(&bonescope(&args));
    let animations = report["animations"].as_array().unwrap();
    assert_eq!(animations.len(), 1);
    assert!(animations[0]["name"].as_str().unwrap().starts_with("walk + blend `run` a = 0.5, synced"));
    let baked = json(&bonescope(&["inspect", &out, "--format", "json"]));
    assert!((baked["animation"]["duration"].as_f64().unwrap() - 1.0).abs() < 1e-6, "the synced cycle lasts 1 s");
}

#[test]
fn a_blender_fbx_export_pairs_with_its_gltf_take_by_take_conversion_nodes_aside() {
    // Blender names FBX takes `Armature|take`: they pair with the glTF's `take`. The FBX's armature and mesh nodes
    // are turned −90° about X to state its axes, the glTF's sit at identity: conversion nodes both, left out (they
    // differed by a quarter turn, a probe √2·10 % of the rig away, above every bone's 3.7 %).
    let (gltf, fbx) = (path(&asset("blender/stretchy_full.glb")), path(&asset("blender/stretchy_full.fbx")));
    let report = json(&bonescope(&["diff", &gltf, &fbx, "--format", "json"]));
    assert_eq!((report["unit_a"].as_f64(), report["unit_b"].as_f64()), (Some(1.0), Some(1.0)));
    let animations = report["animations"].as_array().unwrap();
    let pairs: Vec<(&str, &str)> =
        animations.iter().map(|a| (a["a"].as_str().unwrap(), a["b"].as_str().unwrap())).collect();
    assert_eq!(pairs, [("squash_stretch", "Stretchy|squash_stretch"), ("wave", "Stretchy|wave")]);
    for animation in animations {
        let conversion = ["Stretchy", "Stretchy_skin"];
        assert_eq!(
            (names(&animation["conversion_a"]), names(&animation["conversion_b"])),
            (conversion.into(), conversion.into())
        );
        let bones: Vec<&str> =
            animation["bones"].as_array().unwrap().iter().map(|b| b["name"].as_str().unwrap()).collect();
        assert_eq!(bones, ["hips", "spine", "chest", "upper_arm", "forearm", "hand", "neck", "head"]);
        assert!(names(&animation["only_a"]).is_empty() && names(&animation["only_b"]).is_empty(), "{animation}");
        // No quarter turn is left: what parts the exports is the arm's motion between keys, 16° at most.
        for bone in animation["bones"].as_array().unwrap() {
            assert!(bone["orientation_deg"]["max"].as_f64().unwrap() < 20.0, "{bone}");
        }
    }
}

#[test]
fn a_bvh_is_compared_in_the_unit_it_is_given() {
    // ProAnimationBank's run is in centimetres, converted to metres above the roots; the CMU walk states no unit. A
    // unit moves positions, never scale factors: every bone's scale ratio is 1 whatever unit the walk is given (both
    // rigs' authored scales are 1), while the walk's size follows its unit (CMU's 1/0.45 inch is 2.54 / 0.45 cm).
    let (run, walk) = (path(&asset("fbx-proanimationbank/run.fbx")), path(&asset("bvh/cmu_12_01_walk.bvh")));
    let diff = |unit: &[&str]| {
        let args = [&["diff", run.as_str(), walk.as_str(), "--anim-a", "0", "--anim-b", "0", "--format", "json"], unit]
            .concat();
        json(&bonescope(&args))
    };
    let scale_ratios = |report: &Value| -> Vec<f64> {
        let bones = report["animations"][0]["bones"].as_array().unwrap();
        bones.iter().map(|b| b["scale_ratio"]["max"].as_f64().unwrap()).collect()
    };
    let as_written = diff(&[]);
    assert_eq!(as_written["unit_b"], Value::Null);
    let centimetres = diff(&["--unit-b", "cm"]);
    assert_eq!((centimetres["unit_a"].as_f64(), centimetres["unit_b"].as_f64()), (Some(1.0), Some(0.01)));
    let cmu = diff(&["--unit-b", "cmu"]);
    for report in [&as_written, &centimetres, &cmu] {
        let ratios = scale_ratios(report);
        assert!(ratios.len() >= 20 && ratios.iter().all(|r| (r - 1.0).abs() < 1e-5), "{ratios:?}");
    }
    // The larger rig's size: the walk taken in metres is some 40 m tall; in centimetres both are human-sized.
    let rig_size = |report: &Value| report["animations"][0]["rig_size"].as_f64().unwrap();
    assert!(rig_size(&as_written) > 20.0 && (1.5..3.0).contains(&rig_size(&centimetres)), "{}", rig_size(&as_written));
    // The table states the unit given and the scale B's lengths took.
    let table = bonescope(&["diff", &run, &walk, "--anim-a", "0", "--anim-b", "0", "--unit-b", "cmu"]);
    let text = String::from_utf8_lossy(&table.stdout);
    assert!(text.contains("unit: CMU mocap units (1/0.45 in) (given; the file states none)"), "{text}");
    assert!(text.contains("B's lengths scaled by 0.0564444"), "{text}");
    // A file that states its unit takes no other.
    let refused = bonescope(&["diff", &run, &walk, "--unit-a", "cm"]);
    assert_eq!(refused.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&refused.stderr).contains("--unit-a: the file states its unit (metres)"));
}

#[test]
fn nlerp_playback_departs_from_slerp_as_its_formula_says() {
    // One bone turned from rest to 90° about Z over a second, two linear keys: compared with itself played by
    // nlerp, it is as far off as nlerp is from slerp. On the quaternion arc of φ = 45° between the keys nlerp is at
    // atan(t·sin φ / (1 − t + t·cos φ)) where slerp is at t·φ; the rotations part by twice that difference, largest
    // (0.91882°) at t = ½ ± √3/6: on the 60 Hz grid at 13/60 s and 47/60 s alike, 0.918805°.
    let bone = Bone::joint("b", None, Transform::IDENTITY);
    let mut tracks = BoneTracks::new(0);
    let keys = vec![Quat::IDENTITY, Quat::from_rotation_z(std::f32::consts::FRAC_PI_2)];
    tracks.rotation = Some(Track::new(Arc::from([0.0, 1.0].as_slice()), keys, Interpolation::Linear).unwrap());
    let clip = Clip::new(0, Some("turn".into()), vec![tracks], vec![]);
    let rig = Rig { skeleton: Skeleton::new(vec![bone]).unwrap(), clips: vec![clip], ..Rig::default() };
    let side = |rotation| {
        let mut setup = Setup::declared(&rig);
        setup.layers.interpolation.rotation = rotation;
        FileSide { file: "turn".into(), rig: &rig, setup }
    };
    let orientation = |interp| {
        let diff =
            diff_files(&side(RotationInterpolation::Slerp), &side(interp), Clips::ByName, &[], 60.0, Align::Clocks)
                .unwrap();
        assert_eq!(diff.interp_b, interp);
        diff.animations[0].bones[0].orientation_deg
    };
    assert_eq!(orientation(RotationInterpolation::Slerp).max, 0.0, "as authored");
    let nlerp = orientation(RotationInterpolation::Nlerp);
    assert!((nlerp.max - 0.918805).abs() < 1e-4, "{nlerp:?}");
    let at = |seconds: f64| (nlerp.time - seconds).abs() < 1e-9;
    assert!(at(13.0 / 60.0) || at(47.0 / 60.0), "nlerp leads, then lags by as much: {nlerp:?}");
}

#[test]
fn swapping_the_files_changes_nothing() {
    // Rig size, worst distance and every bone's figures are the same whichever file (or set of modes) is A, over
    // the shared files under pairs of modes, and two exports of one scene: a `--fail-above` gate cannot depend on
    // the order of the arguments (to 1e-12 of the rig).
    let blender = |name: &str| path(&asset(&format!("blender/{name}")));
    let maya = path(&asset("fbx-ufbx-data/maya_mixed_inherit_mode_7700_ascii.fbx"));
    let character = path(&asset("fbx-ufbx-corpus/maya_character_7500_binary.fbx"));
    let cases: Vec<[String; 4]> = vec![
        [blender("stretchy_full.glb"), blender("stretchy_full.glb"), "full".into(), "blender-none".into()],
        [
            blender("stretchy_full.fbx"),
            blender("stretchy_noinherit.fbx"),
            "segment-compensate".into(),
            "componentwise".into(),
        ],
        [
            blender("stretchy_full.glb"),
            blender("stretchy_full.fbx"),
            "blender-aligned".into(),
            "unscaled-parent".into(),
        ],
        [maya.clone(), maya, "declared".into(), "unscaled-parent".into()],
        [character.clone(), character, "segment-compensate".into(), "blender-none".into()],
    ];
    for [a, b, mode_a, mode_b] in cases {
        let diff = |a: &str, b: &str, mode_a: &str, mode_b: &str| {
            json(&bonescope(&["diff", a, b, "--inherit-a", mode_a, "--inherit-b", mode_b, "--format", "json"]))
        };
        let (forth, back) = (diff(&a, &b, &mode_a, &mode_b), diff(&b, &a, &mode_b, &mode_a));
        let what = format!("{a} ({mode_a}) against {b} ({mode_b})");
        for (x, y) in forth["animations"].as_array().unwrap().iter().zip(back["animations"].as_array().unwrap()) {
            let size = x["rig_size"].as_f64().unwrap();
            let same = |p: &Value, q: &Value| (p.as_f64().unwrap() - q.as_f64().unwrap()).abs() <= 1e-12 * size;
            assert!(
                same(&x["rig_size"], &y["rig_size"]),
                "{what}: rig size {} against {}",
                x["rig_size"],
                y["rig_size"]
            );
            assert!(
                same(&x["worst"]["max"], &y["worst"]["max"]),
                "{what}: worst {} against {}",
                x["worst"],
                y["worst"]
            );
            let bones = |report: &Value| -> Vec<(String, Value, Value)> {
                let mut bones: Vec<(String, Value, Value)> = report["bones"]
                    .as_array()
                    .unwrap()
                    .iter()
                    .map(|b| {
                        (
                            b["name"].as_str().unwrap().to_owned(),
                            b["position"]["max"].clone(),
                            b["probe"]["max"].clone(),
                        )
                    })
                    .collect();
                bones.sort_by(|p, q| p.0.cmp(&q.0));
                bones
            };
            let (bx, by) = (bones(x), bones(y));
            assert_eq!(bx.len(), by.len(), "{what}");
            for ((name, position, probe), (_, position_back, probe_back)) in bx.iter().zip(&by) {
                assert!(same(position, position_back) && same(probe, probe_back), "{what}: {name}");
            }
        }
    }
}

#[test]
fn a_z_up_bvh_stands_up_when_given_its_axis() {
    use bonescope::model::{InheritMode, UpAxis};
    // Blender writes its BVH in its own Z-up space: beside the same rig's glTF it lies on the floor.
    let (glb, bvh) = (asset("blender/stretchy_full.glb"), asset("blender/stretchy_full.bvh"));
    let (glb, bvh) = (glb.to_str().unwrap(), bvh.to_str().unwrap());
    let diff = |extra: &[&str]| {
        let args = [&["diff", glb, bvh, "--anim-a", "0", "--anim-b", "0", "--unit-b", "m", "--format", "json"], extra];
        bonescope(&args.concat())
    };
    let hips = |output: &std::process::Output| {
        let bones = json(output)["animations"][0]["bones"].as_array().unwrap().clone();
        let hips = bones.iter().find(|b| b["name"] == "hips").unwrap().clone();
        hips["position"]["max"].as_f64().unwrap()
    };
    let lying = diff(&[]);
    let note = String::from_utf8_lossy(&lying.stderr).into_owned();
    assert!(note.contains("A's skeleton stands along Y, B's along Z") && note.contains("give --up-b z"), "{note}");
    let standing = diff(&["--up-b", "z"]);
    assert!(String::from_utf8_lossy(&standing.stderr).is_empty(), "stood up, nothing to suggest");
    // The hips travel the same path in both files once B is turned (within the BVH's 4 decimals, 1 cm); lying down,
    // they are over a metre apart.
    assert!(hips(&lying) > 1.0 && hips(&standing) < 0.01, "{} {}", hips(&lying), hips(&standing));
    // The turn is the exporters': every joint of the stood-up rig at (x, z, −y) of where the file puts it.
    let rig = bonescope::import::load(&asset("blender/stretchy_full.bvh")).unwrap();
    let stood = rig.clone().stood_up(UpAxis::Z);
    assert!(stood.notes.iter().any(|n| n == "axes: given as up along Z, turned to Y up"), "{:?}", stood.notes);
    let pose = |rig: &Rig| {
        let modes = vec![InheritMode::Full; rig.skeleton.len()];
        let evaluation = bonescope::eval::Evaluation::new(rig, rig.clips.first(), &modes).unwrap();
        evaluation.pose_at(0.55).model.model
    };
    for (before, after) in pose(&rig).iter().zip(pose(&stood)) {
        let (p, q) = (before.w_axis, after.w_axis);
        assert!((q.truncate() - glam::DVec3::new(p.x, p.z, -p.y)).length() < 1e-9, "{p} → {q}");
    }
    // Turned back, it is the file's again.
    assert_eq!(stood.restood(UpAxis::Z, UpAxis::Y).skeleton.placement().conversion, glam::DMat4::IDENTITY);
}

/// A file of the corpus of Blender's scenes in three formats.
fn blender_io(name: &str) -> String {
    path(&asset("../corpus/blender-io").join(name))
}

#[test]
fn two_clocks_are_compared_at_equal_times_and_aligned_on_request() {
    // Blender's glb keys frame 1 at 1/30 s; its FBX starts each take at 0: one frame apart, and said so.
    let (glb, fbx) = (path(&asset("blender/stretchy_full.glb")), path(&asset("blender/stretchy_full.fbx")));
    let own = bonescope(&["diff", &glb, &fbx, "--anim-a", "squash_stretch"]);
    let table = String::from_utf8_lossy(&own.stdout);
    assert!(table.contains("B's clip starts 0.0333 s (1 frame at 30 fps) before A's on its own clock"), "{table}");
    let report = |align: &str| json(&bonescope(&["diff", &glb, &fbx, "--align", align, "--format", "json"]));
    let (clocks, aligned) = (report("clocks"), report("start"));
    let (a, b) = (&clocks["animations"][0], &aligned["animations"][0]);
    assert_eq!(a["span_a"]["start"], f64::from(1.0f32 / 30.0));
    assert_eq!((a["span_b"]["start"].as_f64(), a["delay_b"].as_f64()), (Some(0.0), Some(0.0)));
    assert_eq!(b["delay_b"], a["span_a"]["start"], "B played from A's start");
    let worst = |v: &Value| v["worst"]["max"].as_f64().unwrap();
    assert!(worst(b) < worst(a) / 10.0, "aligned {} against {}", worst(b), worst(a));
    // A delay in seconds is the same alignment.
    let delay = format!("{}", 1.0f32 / 30.0);
    let by_hand = json(&bonescope(&["diff", &glb, &fbx, "--align", &delay, "--format", "json"]));
    assert!((worst(&by_hand["animations"][0]) - worst(b)).abs() < 1e-9);
    assert_eq!(bonescope(&["diff", &glb, &fbx, "--align", "soon"]).status.code(), Some(2));
}

#[test]
fn a_diff_that_pairs_no_clip_fails_listing_the_clips() {
    let (glb, bvh) = (path(&asset("blender/stretchy_full.glb")), path(&asset("blender/stretchy_full.bvh")));
    let out = bonescope(&["diff", &glb, &bvh, "--up-b", "z"]);
    assert_eq!(out.status.code(), Some(2));
    let error = String::from_utf8_lossy(&out.stderr);
    assert!(error.contains("`squash_stretch`, `wave`") && error.contains("`animation 0`"), "{error}");
    // A name for A alone is looked up in B as names pair (Blender's FBX take `Stretchy|wave`); where B has none,
    // the error names B's file and the option that chooses B's clip.
    let fbx = path(&asset("blender/stretchy_full.fbx"));
    assert!(bonescope(&["diff", &glb, &fbx, "--anim-a", "wave"]).status.success());
    let missing = String::from_utf8_lossy(&bonescope(&["diff", &glb, &bvh, "--anim-a", "wave"]).stderr).into_owned();
    assert!(missing.contains(&format!("{bvh}: no animation named as --anim-a chose")), "{missing}");
    assert!(missing.contains("--anim-b"), "{missing}");
}

#[test]
fn one_file_under_two_modes_measures_points_each_in_its_own_pose() {
    // Maya's no-inherit rig, 2.9 m tall, its origins at most 2.76 m apart between full and compensated scale: a
    // probe point a tenth of the rig out along each axis moves no further than the origins and twice that tenth.
    let file = path(&asset("fbx-ufbx-data/maya_scale_no_inherit_7700_ascii.fbx"));
    let args = ["diff", &file, &file, "--inherit-a", "full", "--inherit-b", "segment-compensate", "--format", "json"];
    let report = json(&bonescope(&args));
    let animation = &report["animations"][0];
    let size = animation["rig_size"].as_f64().unwrap();
    for bone in animation["bones"].as_array().unwrap() {
        let (origin, probe) = (bone["position"]["max"].as_f64().unwrap(), bone["probe"]["max"].as_f64().unwrap());
        assert!(probe <= origin + 2.0 * 0.1 * size + 1e-9, "{}: {probe} against {origin}", bone["name"]);
        assert!(bone.get("convention").is_none(), "one file has one set of frames");
    }
    assert!(animation["worst"]["max"].as_f64().unwrap() < size, "{}", animation["worst"]);
}

#[test]
fn joints_pair_with_joints_meshes_with_meshes_and_usd_spellings_meet() {
    // RobotExpressive names its mesh objects after the bones they hang from; the glb skins `Hand.L`, whose node
    // places nothing. Blender's USD export spells `Bone.001` as `Bone_001`.
    let args =
        ["--anim-a", "Robot_Idle", "--anim-b", "RobotArmature|Robot_Idle", "--align", "start", "--format", "json"];
    let diff = |a: &str, b: &str, more: &[&str]| json(&bonescope(&[&["diff", a, b], more].concat()));
    let robot = diff(&blender_io("RobotExpressive.glb"), &blender_io("RobotExpressive.fbx"), &args);
    let animation = &robot["animations"][0];
    let bones = animation["bones"].as_array().unwrap();
    let mut seen = std::collections::HashSet::new();
    for bone in bones {
        assert!(seen.insert((bone["a"].as_u64(), "a")) && seen.insert((bone["b"].as_u64(), "b")), "{bone}");
    }
    assert!(names(&animation["skinned_a"]).contains(&"Hand.L"));
    let worst = animation["worst"]["max"].as_f64().unwrap() / animation["rig_size"].as_f64().unwrap();
    assert!(worst < 0.01, "{worst}");
    let extras = diff(&blender_io("00_extras.glb"), &blender_io("00_extras.usdc"), &["--format", "json"]);
    let animation = &extras["animations"][0];
    assert!(animation["only_a"].as_array().unwrap().is_empty() && animation["only_b"].as_array().unwrap().is_empty());
    let pair = animation["bones"].as_array().unwrap().iter().find(|b| b["name"] == "Bone.001").unwrap();
    assert_eq!(pair["name_b"], "Bone_001");
}

#[test]
fn a_usd_stage_clip_is_named_after_its_main_skel_animation() {
    let out = bonescope(&["inspect", &blender_io("RobotExpressive.usdc"), "--format", "json"]);
    let report = json(&out);
    assert_eq!(report["animation"]["name"], "Robot_Death");
    let notes: Vec<&str> = report["notes"].as_array().unwrap().iter().filter_map(Value::as_str).collect();
    assert!(notes.iter().any(|n| n.contains("2 SkelAnimations (Robot_Death, Anim)")), "{notes:?}");
    // Named so, the stage's clip pairs by name with the glb's action of that name.
    let diff =
        json(&bonescope(&["diff", &blender_io("00_extras.glb"), &blender_io("00_extras.usdc"), "--format", "json"]));
    assert_eq!(diff["animations"][0]["b"], "ArmatureAction");
}

#[test]
fn a_file_without_a_unit_bakes_in_metres_in_the_unit_its_figure_stands_in() {
    // Bandai Namco's capture states no unit; its figure stands about two hundred of them: centimetres, said so.
    let bvh = path(&asset("../corpus/realworld/bandai_dataset-2_run_normal_001.bvh"));
    let folder = tempfile::tempdir().unwrap();
    let out = path(&folder.path().join("run.glb"));
    let bake = |more: &[&str]| json(&bonescope(&[&["bake", &bvh, "--out", &out, "--format", "json"], more].concat()));
    let assumed = bake(&[]);
    let notes: Vec<&str> = assumed["notes"].as_array().unwrap().iter().filter_map(Value::as_str).collect();
    assert!(notes.iter().any(|n| n.starts_with("the file states no unit: read in centimetres")), "{notes:?}");
    let size = assumed["rig_size"].as_f64().unwrap();
    assert!((1.0..10.0).contains(&size), "a person running, in metres: {size}");
    let read = json(&bonescope(&["inspect", &out, "--format", "json"]));
    assert!(read["notes"].as_array().unwrap().iter().any(|n| n.as_str().unwrap().contains("metres")));
    // Given a unit, the bake takes it and says nothing of it; a file that states one refuses another.
    let given = bake(&["--unit", "mm"]);
    assert!((given["rig_size"].as_f64().unwrap() - size / 10.0).abs() < 1e-9 * size);
    let notes = given["notes"].as_array().unwrap();
    assert!(!notes.iter().any(|n| n.as_str().unwrap().contains("states no unit")));
    let glb = path(&asset("blender/stretchy_full.glb"));
    assert_eq!(bonescope(&["bake", &glb, "--out", &out, "--unit", "cm"]).status.code(), Some(2));
}

#[test]
fn figures_are_looked_at_as_they_play_for_which_way_they_stand() {
    // Blender's FBX rests its bones as they were edited, lying along Z, though every frame stands along Y as the
    // glb does: no note. A BVH that lies along Z still gets one.
    let (glb, fbx) = (blender_io("RobotExpressive.glb"), blender_io("RobotExpressive.fbx"));
    let robot = bonescope(&["diff", &glb, &fbx, "--anim-a", "Robot_Idle", "--anim-b", "RobotArmature|Robot_Idle"]);
    assert!(
        !String::from_utf8_lossy(&robot.stderr).contains("stands along"),
        "{}",
        String::from_utf8_lossy(&robot.stderr)
    );
    let (glb, bvh) = (path(&asset("blender/stretchy_full.glb")), path(&asset("blender/stretchy_full.bvh")));
    let lying = bonescope(&["diff", &glb, &bvh, "--anim-a", "squash_stretch", "--anim-b", "0"]);
    assert!(
        String::from_utf8_lossy(&lying.stderr).contains("B's along Z"),
        "{}",
        String::from_utf8_lossy(&lying.stderr)
    );
}
