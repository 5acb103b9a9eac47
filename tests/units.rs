//! Units and axes stand outside the rig: every inheritance mode gives the same answer whatever unit a file is written
//! in, and a file evaluated in its own space and then converted equals the file evaluated in bonescope's space.

mod common;

use std::path::Path;

use base64::Engine;
use bonescope::eval::Evaluation;
use bonescope::import::{self, Options, Space};
use bonescope::math::decompose;
use bonescope::model::{Bone, Choice, Clip, InheritMode, Placement, Rig, Skeleton, Span, Transform};
use common::{asset, bonescope, json};
use glam::{DMat4, DQuat, DVec3, Quat};
use serde_json::{Value, json as object};

/// Animated FBX files in centimetres and metres, from Maya, 3ds Max, Blender and MotionBuilder, Y-up and Z-up.
const FBX: &[&str] = &[
    "fbx-ufbx-corpus/maya_character_7500_binary.fbx",
    "fbx-ufbx-data/maya_mixed_inherit_mode_7700_ascii.fbx",
    "fbx-ufbx-data/maya_anim_no_inherit_scale_7700_ascii.fbx",
    "fbx-ufbx-data/maya_scale_no_inherit_7700_ascii.fbx",
    "fbx-ufbx-data/maya_advanced_skinned_pivot_7700_binary.fbx",
    "fbx-ufbx-data/max7_skin_5000_binary.fbx",
    "fbx-ufbx-data/max_transformed_skin_7500_binary.fbx",
    "fbx-ufbx-data/blender_293_half_skinned_7400_binary.fbx",
    "blender/stretchy_full.fbx",
    "blender/stretchy_noinherit.fbx",
    "fbx-proanimationbank/walk.fbx",
];

fn load(path: &Path, space: Space) -> Rig {
    import::load_with(path, &Options { space }).unwrap_or_else(|e| panic!("{e}"))
}

/// Three times of the first clip: its start, a time within, its end (0 for its rest pose where it has none).
fn times(rig: &Rig) -> Vec<f64> {
    let span = rig.clips.first().map_or(Span::at(0.0), Clip::span);
    vec![span.start, span.start + 0.37 * span.length(), span.end]
}

/// Every bone's model matrix and every skinned vertex of `modes` at `time`.
fn evaluated(rig: &Rig, modes: &[InheritMode], time: f64) -> (Vec<DMat4>, Vec<DVec3>) {
    let evaluation = Evaluation::new(rig, rig.clips.first(), modes).unwrap();
    let pose = evaluation.pose_at(time);
    let vertices = evaluation.skin_all(&pose).concat();
    (pose.model.model, vertices)
}

/// The largest distance between `expected` and `actual`, bones (their origins and unit points on their axes) and
/// vertices.
fn largest_distance(expected: &(Vec<DMat4>, Vec<DVec3>), actual: &(Vec<DMat4>, Vec<DVec3>)) -> f64 {
    let points = [DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z];
    let bones = expected
        .0
        .iter()
        .zip(&actual.0)
        .flat_map(|(e, a)| points.iter().map(move |&p| (e.transform_point3(p) - a.transform_point3(p)).length()));
    let vertices = expected.1.iter().zip(&actual.1).map(|(e, a)| (*e - *a).length());
    bones.chain(vertices).fold(0.0, f64::max)
}

/// `conversion · W` for every matrix and vertex evaluated in the file's own space.
fn converted(conversion: DMat4, (model, vertices): (Vec<DMat4>, Vec<DVec3>)) -> (Vec<DMat4>, Vec<DVec3>) {
    let model = model.into_iter().map(|m| conversion * m).collect();
    (model, vertices.into_iter().map(|v| conversion.transform_point3(v)).collect())
}

#[test]
fn every_mode_in_the_files_own_space_then_converted_equals_it_in_bonescopes_space() {
    // The oracle is the definition: the modes act in the file's space, and the unit and axes conversion is a
    // similarity applied after them. Tolerance 1e-9 of the rig (a few roundings of its size).
    for file in FBX {
        let (own, placed) = (load(&asset(file), Space::File), load(&asset(file), Space::YUpMetres));
        assert_eq!(own.skeleton.len(), placed.skeleton.len(), "{file}");
        let conversion = placed.skeleton.placement().conversion;
        let declared = placed.skeleton.declared_modes();
        let size = Evaluation::declared(&placed, placed.clips.first()).size(&times(&placed));
        let mut mode_sets: Vec<(String, Vec<InheritMode>)> =
            InheritMode::ALL.iter().map(|&m| (m.id().to_owned(), vec![m; declared.len()])).collect();
        // Each mode on one bone alone, on the bones with a parent (a few dozen of the big rigs').
        let step = declared.len().div_ceil(40);
        for bone in (1..declared.len()).step_by(step) {
            for &mode in InheritMode::ALL {
                let mut modes = declared.clone();
                modes[bone] = mode;
                mode_sets.push((format!("{} alone on bone {bone}", mode.id()), modes));
            }
        }
        for (what, modes) in &mode_sets {
            for time in times(&placed) {
                let expected = converted(conversion, evaluated(&own, modes, time));
                let distance = largest_distance(&expected, &evaluated(&placed, modes, time));
                assert!(distance <= 1e-9 * size, "{file} under {what} at {time} s: {distance} of a rig of {size}");
            }
        }
    }
}

/// The Maya file with its unit declared `factor` centimetres: the same numbers, each length `factor` times longer.
fn with_unit_scale_factor(folder: &Path, factor: f64) -> std::path::PathBuf {
    let text = std::fs::read_to_string(asset("fbx-ufbx-data/maya_mixed_inherit_mode_7700_ascii.fbx")).unwrap();
    let stated = "P: \"UnitScaleFactor\", \"double\", \"Number\", \"\",1\n";
    assert!(text.contains(stated));
    let out = folder.join(format!("unit_{factor}.fbx"));
    std::fs::write(
        &out,
        text.replace(stated, &format!("P: \"UnitScaleFactor\", \"double\", \"Number\", \"\",{factor}\n")),
    )
    .unwrap();
    out
}

#[test]
fn a_file_written_in_metres_or_centimetres_gives_one_answer_under_every_mode() {
    // The same FBX numbers stated in centimetres and in metres: every bone's position 100× as far (to 1e-12 of the
    // rig), every scale factor, shear and stretch the same, under every mode.
    let folder = tempfile::tempdir().unwrap();
    let (centimetres, metres) =
        (with_unit_scale_factor(folder.path(), 1.0), with_unit_scale_factor(folder.path(), 100.0));
    let (cm, m) = (load(&centimetres, Space::YUpMetres), load(&metres, Space::YUpMetres));
    for &mode in InheritMode::ALL {
        let modes = vec![mode; cm.skeleton.len()];
        let (ecm, em) = (
            Evaluation::new(&cm, cm.clips.first(), &modes).unwrap(),
            Evaluation::new(&m, m.clips.first(), &modes).unwrap(),
        );
        let size = em.size(&times(&m));
        let (scales_cm, scales_m) = (ecm.length_scales(), em.length_scales());
        for time in times(&m) {
            let (pcm, pm) = (ecm.pose_at(time), em.pose_at(time));
            for (bone, (wcm, wm)) in pcm.model.model.iter().zip(&pm.model.model).enumerate() {
                let name = &m.skeleton.bone(bone).name;
                let (a, b) = (100.0 * wcm.w_axis.truncate(), wm.w_axis.truncate());
                assert!((a - b).length() <= 1e-12 * size, "{name} under {} at {time}: {a} against {b}", mode.id());
                let (kcm, km) = (decompose(wcm).scale / scales_cm[bone], decompose(wm).scale / scales_m[bone]);
                assert!(kcm.abs_diff_eq(km, 1e-9), "{name} under {}: scale {kcm} against {km}", mode.id());
            }
        }
    }
}

/// A glTF rig of three joints (`hips` scaled (1, 1, 2) over time, `spine` turning, `head`), in metres, or in
/// centimetres under an `Armature` node of scale 0.01 as exporters write it.
fn three_joints(centimetres: bool) -> Value {
    let unit = if centimetres { 100.0 } else { 1.0 };
    let floats = |values: &[f32]| values.iter().flat_map(|v| v.to_le_bytes()).collect::<Vec<u8>>();
    let times: [f32; 3] = [0.0, 0.5, 1.0];
    let scales: [f32; 9] = [1.0, 1.0, 1.0, 1.0, 1.0, 2.0, 1.5, 1.0, 2.0];
    let turn = |deg: f32| Quat::from_rotation_z(deg.to_radians()).to_array();
    let rotations: Vec<f32> = [turn(0.0), turn(45.0), turn(90.0)].concat();
    let mut bytes = floats(&times);
    bytes.extend(floats(&scales));
    bytes.extend(floats(&rotations));
    let uri =
        format!("data:application/octet-stream;base64,{}", base64::engine::general_purpose::STANDARD.encode(&bytes));
    let view = |offset: usize, length: usize| object!({ "buffer": 0, "byteOffset": offset, "byteLength": length });
    let accessor = |view: usize, kind: &str, count: usize| object!({ "bufferView": view, "componentType": 5126, "count": count, "type": kind });
    let mut input = accessor(0, "SCALAR", 3);
    input["min"] = object!([0.0]);
    input["max"] = object!([1.0]);
    let at = |y: f64| object!([0.0, y * unit, 0.0]);
    let mut nodes = vec![
        object!({ "name": "hips", "translation": at(1.0), "children": [1] }),
        object!({ "name": "spine", "translation": at(0.5), "rotation": [0.0, 0.0, 0.38268343, 0.9238795], "children": [2] }),
        object!({ "name": "head", "translation": at(0.3) }),
    ];
    let (mut scene, mut offset) = (object!([0]), 0);
    if centimetres {
        for node in &mut nodes {
            if let Some(children) = node.get_mut("children") {
                *children =
                    object!(children.as_array().unwrap().iter().map(|c| c.as_u64().unwrap() + 1).collect::<Vec<_>>());
            }
        }
        nodes.insert(0, object!({ "name": "Armature", "scale": [0.01, 0.01, 0.01], "children": [1] }));
        scene = object!([0]);
        offset = 1;
    }
    object!({
        "asset": { "version": "2.0" },
        "scene": 0,
        "scenes": [{ "nodes": scene }],
        "nodes": nodes,
        "buffers": [{ "byteLength": bytes.len(), "uri": uri }],
        "bufferViews": [view(0, 12), view(12, 36), view(48, 48)],
        "accessors": [input, accessor(1, "VEC3", 3), accessor(2, "VEC4", 3)],
        "animations": [{
            "channels": [
                { "sampler": 0, "target": { "node": offset, "path": "scale" } },
                { "sampler": 1, "target": { "node": offset + 1, "path": "rotation" } },
            ],
            "samplers": [{ "input": 0, "output": 1 }, { "input": 0, "output": 2 }],
        }],
    })
}

#[test]
fn joints_in_centimetres_under_a_conversion_node_move_as_the_same_joints_in_metres() {
    let folder = tempfile::tempdir().unwrap();
    let write = |centimetres: bool| {
        let path = folder.path().join(if centimetres { "cm.gltf" } else { "m.gltf" });
        std::fs::write(&path, serde_json::to_vec(&three_joints(centimetres)).unwrap()).unwrap();
        load(&path, Space::YUpMetres)
    };
    let (m, cm) = (write(false), write(true));
    assert_eq!(cm.skeleton.placement().conversion_nodes, [true, false, false, false], "the Armature only converts");
    for &mode in InheritMode::ALL {
        let (em, ecm) = (
            Evaluation::new(&m, m.clips.first(), &[mode; 3]).unwrap(),
            Evaluation::new(&cm, cm.clips.first(), &[mode; 4]).unwrap(),
        );
        let scales_cm = ecm.length_scales();
        for time in [0.0, 0.25, 0.5, 0.8, 1.0] {
            let (pm, pcm) = (em.pose_at(time), ecm.pose_at(time));
            for bone in 0..3 {
                let (wm, wcm) = (pm.model.model[bone], pcm.model.model[bone + 1]);
                let (a, b) = (wm.w_axis.truncate(), wcm.w_axis.truncate());
                assert!((a - b).length() < 1e-12, "bone {bone} under {} at {time}: {a} against {b}", mode.id());
                let (km, kcm) = (decompose(&wm).scale, decompose(&wcm).scale / scales_cm[bone + 1]);
                assert!(km.abs_diff_eq(kcm, 1e-12), "bone {bone} under {} at {time}: {km} against {kcm}", mode.id());
            }
        }
    }
    // Under segment-compensate the spine compensates the hips' (1, 1, 2) and no unit: at 0.5 s its origin is half
    // a metre above the hips (1.5 m), whatever the file's unit.
    let modes = [InheritMode::SegmentCompensate; 4];
    let spine = Evaluation::new(&cm, cm.clips.first(), &modes).unwrap().pose_at(0.5).model.model[2].w_axis.truncate();
    assert!(spine.abs_diff_eq(DVec3::new(0.0, 1.5, 0.0), 1e-12), "{spine}");
}

#[test]
fn a_centimetre_root_scaled_one_one_two_is_all_a_compensating_child_compensates() {
    // Hand-derived: a rig in centimetres (converted by 0.01 above its root), the root scaled (1, 1, 2), a child
    // 10 cm along Z turned 90° about X and scaled (3, 1, 1), segment-compensating. Maya: the child's offset is
    // scaled by the root's (1, 1, 2) → (0, 0, 20) cm; its own scale is not → (3, 1, 1), and no unit is compensated.
    // In metres its origin is at (0, 0, 0.2), its axes (3, 1, 1) long in the file's unit, turned 90° about X.
    let root = Transform::from_trs(DVec3::ZERO, DQuat::IDENTITY, DVec3::new(1.0, 1.0, 2.0));
    let child = Transform::from_trs(
        DVec3::new(0.0, 0.0, 10.0),
        DQuat::from_rotation_x(90f64.to_radians()),
        DVec3::new(3.0, 1.0, 1.0),
    );
    let bones = vec![Bone::joint("root", None, root), Bone::joint("child", Some(0), child)];
    let conversion = DMat4::from_scale(DVec3::splat(0.01));
    let skeleton = Skeleton::new(bones).unwrap().placed(Placement { conversion, conversion_nodes: Vec::new() });
    let rig = Rig { skeleton, ..Rig::default() };
    let evaluation = Evaluation::new(&rig, None, &[InheritMode::Full, InheritMode::SegmentCompensate]).unwrap();
    let model = evaluation.pose_at(0.0).model.model;
    assert!(model[1].w_axis.truncate().abs_diff_eq(DVec3::new(0.0, 0.0, 0.2), 1e-15), "{}", model[1]);
    let expected_linear = glam::DMat3::from_quat(DQuat::from_rotation_x(90f64.to_radians()))
        * glam::DMat3::from_diagonal(DVec3::new(0.03, 0.01, 0.01));
    assert!(glam::DMat3::from_mat4(model[1]).abs_diff_eq(expected_linear, 1e-15), "{}", model[1]);
    assert_eq!(evaluation.length_scales(), [0.01, 0.01]);
    let authored = decompose(&model[1]).scale / evaluation.length_scales()[1];
    assert!(authored.abs_diff_eq(DVec3::new(3.0, 1.0, 1.0), 1e-12), "{authored}");
}

#[test]
fn a_change_of_units_moves_positions_not_scale_factors() {
    // One BVH (no unit stated) compared with itself, read in metres and in centimetres: every bone's scale ratio
    // is 1, its positions differ by the unit.
    let file = asset("bvh/cmu_12_01_walk.bvh").display().to_string();
    let out = bonescope(&["diff", &file, &file, "--unit-a", "m", "--unit-b", "cm", "--format", "json"]);
    let report = json(&out);
    let bones = report["animations"][0]["bones"].as_array().unwrap_or_else(|| panic!("{report}"));
    assert!(!bones.is_empty());
    for bone in bones {
        let ratio = bone["scale_ratio"]["max"].as_f64().unwrap();
        assert!((ratio - 1.0).abs() < 1e-9, "{}: scale ratio {ratio}", bone["name"]);
    }
}
