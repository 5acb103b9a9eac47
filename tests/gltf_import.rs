//! The glTF importer against the shared sample assets, small hand-built documents that break one rule each, and
//! mutated files that must fail cleanly instead of panicking.

mod common;
// The hostile corpus's glTF writer; this file uses a part of it.
#[allow(dead_code)]
#[path = "hostile/gltf.rs"]
mod gltf_writer;

use std::collections::{BTreeSet, HashSet};
use std::path::Path;

use base64::Engine as _;
use bonescope::eval::{Hierarchy, Pose};
use bonescope::import::{self, ImportError};
use bonescope::model::{Clip, Interpolation, NodeRole, Rig};
use common::{asset, assets, load_asset};
use glam::{DMat4, DQuat, DVec3, Quat, Vec3};
use rand::{RngExt, SeedableRng};
use rand_xorshift::XorShiftRng;
use serde_json::{Value, json};

// ---------------------------------------------------------------------------------------------------------------
// Sample assets

/// What a folder's MANIFEST.md or README.md states about one file.
struct Expected {
    file: &'static str,
    nodes: usize,
    skin_joints: &'static [usize],
    /// Durations in seconds; `(min, max)` pairs where the manifest gives a range for all clips.
    durations: &'static [f64],
    duration_range: Option<(f64, f64)>,
    clip_count: usize,
    clip_names: &'static [&'static str],
    interpolations: &'static [Interpolation],
    /// Animated properties, among "translation", "rotation", "scale".
    paths: &'static [&'static str],
    non_uniform_rest_scale: bool,
}

const LINEAR: &[Interpolation] = &[Interpolation::Linear];
const CUBIC: &[Interpolation] = &[Interpolation::CubicSpline];
const ALL_THREE: &[Interpolation] = &[Interpolation::Step, Interpolation::Linear, Interpolation::CubicSpline];

/// `gltf-khronos/MANIFEST.md` and `blender/README.md`. Blender's durations come from its "30 fps, frames 1–61,
/// first key at t = 1/30 s": 61/30 s and 41/30 s (the README rounds them to ≈2.03 and ≈1.37).
const EXPECTED: &[Expected] = &[
    Expected {
        file: "gltf-khronos/Fox.glb",
        nodes: 26,
        skin_joints: &[24],
        durations: &[3.417, 0.708, 1.158],
        duration_range: None,
        clip_count: 3,
        clip_names: &["Survey", "Walk", "Run"],
        interpolations: LINEAR,
        paths: &["rotation", "translation"],
        non_uniform_rest_scale: false,
    },
    Expected {
        file: "gltf-khronos/SimpleSkin.gltf",
        nodes: 3,
        skin_joints: &[2],
        durations: &[5.5],
        duration_range: None,
        clip_count: 1,
        clip_names: &[],
        interpolations: LINEAR,
        paths: &["rotation"],
        non_uniform_rest_scale: false,
    },
    Expected {
        file: "gltf-khronos/box_animated.gltf",
        nodes: 4,
        skin_joints: &[],
        durations: &[3.708],
        duration_range: None,
        clip_count: 1,
        clip_names: &[],
        interpolations: LINEAR,
        paths: &["rotation", "translation"],
        non_uniform_rest_scale: false,
    },
    Expected {
        file: "gltf-khronos/cesium_man.gltf",
        nodes: 22,
        skin_joints: &[19],
        durations: &[2.0],
        duration_range: None,
        clip_count: 1,
        clip_names: &[],
        interpolations: LINEAR,
        paths: &["rotation", "scale", "translation"],
        non_uniform_rest_scale: false,
    },
    Expected {
        file: "gltf-khronos/interpolation_test.gltf",
        nodes: 12,
        skin_joints: &[],
        durations: &[],
        duration_range: Some((1.667, 1.708)),
        clip_count: 9,
        clip_names: &[],
        interpolations: ALL_THREE,
        paths: &["rotation", "scale", "translation"],
        non_uniform_rest_scale: true,
    },
    Expected {
        file: "gltf-khronos/rigged_simple.gltf",
        nodes: 5,
        skin_joints: &[2],
        durations: &[2.083],
        duration_range: None,
        clip_count: 1,
        clip_names: &[],
        interpolations: LINEAR,
        paths: &["rotation", "scale", "translation"],
        non_uniform_rest_scale: false,
    },
    Expected {
        file: "blender/stretchy_full.glb",
        nodes: 10,
        skin_joints: &[8],
        durations: &[61.0 / 30.0, 41.0 / 30.0],
        duration_range: None,
        clip_count: 2,
        clip_names: &["squash_stretch", "wave"],
        interpolations: CUBIC,
        paths: &["rotation", "scale", "translation"],
        non_uniform_rest_scale: false,
    },
    Expected {
        file: "blender/stretchy_noinherit.glb",
        nodes: 10,
        skin_joints: &[8],
        durations: &[61.0 / 30.0, 41.0 / 30.0],
        duration_range: None,
        clip_count: 2,
        clip_names: &["squash_stretch", "wave"],
        interpolations: CUBIC,
        paths: &["rotation", "scale", "translation"],
        non_uniform_rest_scale: false,
    },
];

/// Every `.gltf` and `.glb` under the shared assets, as `folder/file`.
fn asset_files() -> Vec<String> {
    let mut files = Vec::new();
    for folder in std::fs::read_dir(assets()).expect("the shared assets folder") {
        let folder = folder.unwrap().path();
        for file in std::fs::read_dir(&folder).into_iter().flatten() {
            let file = file.unwrap().path();
            if matches!(file.extension().and_then(|e| e.to_str()), Some("gltf" | "glb")) {
                let name = |p: &Path| p.file_name().unwrap().to_string_lossy().into_owned();
                files.push(format!("{}/{}", name(&folder), name(&file)));
            }
        }
    }
    files.sort();
    files
}

#[test]
fn every_sample_asset_loads_as_its_manifest_says() {
    let files = asset_files();
    assert!(files.len() >= EXPECTED.len(), "found only {files:?}");
    for file in &files {
        let expected = EXPECTED.iter().find(|e| e.file == file).unwrap_or_else(|| panic!("{file} is not in EXPECTED"));
        let rig = load_asset(file);
        check_asset(&rig, expected);
    }
}

fn check_asset(rig: &Rig, e: &Expected) {
    let file = e.file;
    assert_eq!(rig.skeleton.len(), e.nodes, "{file}: bones");
    let mut nodes: Vec<usize> = rig.skeleton.bones().iter().map(|b| b.node).collect();
    nodes.sort();
    assert_eq!(nodes, (0..e.nodes).collect::<Vec<_>>(), "{file}: one bone per node");
    let joints: Vec<usize> = rig.skins.iter().map(|s| s.joints.len()).collect();
    assert_eq!(joints, e.skin_joints, "{file}: skin joints");
    for skin in &rig.skins {
        assert_eq!(skin.inverse_bind.len(), skin.joints.len(), "{file}");
    }
    assert_eq!(rig.clips.len(), e.clip_count, "{file}: animations");
    for (clip, &duration) in rig.clips.iter().zip(e.durations) {
        assert!((clip.span().end - duration).abs() < 1e-3, "{file}: {} lasts {}", clip.label(), clip.span().end);
    }
    if let Some((min, max)) = e.duration_range {
        for clip in &rig.clips {
            let d = clip.span().end;
            assert!(d > min - 1e-3 && d < max + 1e-3, "{file}: {} lasts {d}", clip.label());
        }
    }
    if !e.clip_names.is_empty() {
        let names: Vec<_> = rig.clips.iter().map(|c| c.name.as_deref().unwrap_or("")).collect();
        assert_eq!(names, e.clip_names, "{file}");
    }
    let (interpolations, paths) = animated(rig);
    assert_eq!(interpolations, e.interpolations.iter().copied().collect(), "{file}: sampler interpolations");
    assert_eq!(paths, e.paths.iter().copied().collect(), "{file}: channel paths");
    let non_uniform = rig.skeleton.bones().iter().any(|b| {
        let s = b.rest.scale.abs();
        (s.max_element() - s.min_element()) > 1e-6
    });
    assert_eq!(non_uniform, e.non_uniform_rest_scale, "{file}: non-uniform rest scale");
    for mesh in &rig.meshes {
        assert_eq!(mesh.indices.len() % 3, 0, "{file}");
        assert!(mesh.skin.is_none() || mesh.joints.len() == mesh.positions.len(), "{file}");
    }
}

/// The interpolations and animated properties used by any clip.
fn animated(rig: &Rig) -> (HashSet<Interpolation>, BTreeSet<&'static str>) {
    let (mut interpolations, mut paths) = (HashSet::new(), BTreeSet::new());
    for track in rig.clips.iter().flat_map(|c| c.tracks()) {
        if let Some(t) = &track.translation {
            interpolations.insert(t.interpolation());
            paths.insert("translation");
        }
        if let Some(t) = &track.rotation {
            interpolations.insert(t.interpolation());
            paths.insert("rotation");
        }
        if let Some(t) = &track.scale {
            interpolations.insert(t.interpolation());
            paths.insert("scale");
        }
    }
    (interpolations, paths)
}

#[test]
fn blender_clips_have_the_stated_channels_and_first_key() {
    let rig = import::load(&asset("blender/stretchy_full.glb")).unwrap();
    let channels = |name: &str| {
        let clip = rig.find_clip(name).unwrap();
        let count = |t: &bonescope::model::BoneTracks| {
            usize::from(t.translation.is_some()) + usize::from(t.rotation.is_some()) + usize::from(t.scale.is_some())
        };
        (clip.tracks().iter().map(count).sum::<usize>(), clip.key_times()[0])
    };
    let ((squash, squash_first), (wave, wave_first)) = (channels("squash_stretch"), channels("wave"));
    assert_eq!((squash, wave), (7, 2));
    assert!((squash_first - 1.0 / 30.0).abs() < 1e-6 && (wave_first - 1.0 / 30.0).abs() < 1e-6);
    let skinned = rig.meshes.iter().filter(|m| m.skin == Some(0)).count();
    assert_eq!(skinned, 1, "one skinned mesh node");
}

#[test]
fn cubic_spline_values_keep_the_file_order() {
    // interpolation_test.gltf: "CubicSpline Translation" stores in-tangent, value, out-tangent per key.
    let rig = import::load(&asset("gltf-khronos/interpolation_test.gltf")).unwrap();
    let clip = rig.find_clip("CubicSpline Translation").unwrap();
    let track = clip.tracks()[0].translation.as_ref().unwrap();
    assert_eq!(track.values().len(), 3 * track.times().len());
}

// ---------------------------------------------------------------------------------------------------------------
// Hand-built documents

/// A small valid document: `root → child` plus a skinned triangle on `mesh`, one clip (`move`) with a LINEAR
/// translation and a STEP normalized-i16 rotation sharing one time accessor. `bin` holds every accessor's bytes;
/// accessor `i` uses buffer view `i`.
struct Sample {
    json: Value,
    bin: Vec<u8>,
}

const TIMES: [f32; 3] = [0.0, 0.5, 1.0];
const TRANSLATIONS: [[f32; 3]; 3] = [[0.0, 1.0, 0.0], [0.0, 2.0, 0.0], [1.0, 2.0, 0.0]];
const ROTATIONS_I16: [[i16; 4]; 3] = [[0, 0, 0, 32767], [0, 0, 16384, 28378], [-32768, 0, 0, 0]];

fn bytes<T: Copy, const N: usize>(values: &[T], to_le: impl Fn(T) -> [u8; N]) -> Vec<u8> {
    values.iter().flat_map(|&v| to_le(v)).collect()
}

fn sample() -> Sample {
    let mut sample = Sample { json: json!({ "bufferViews": [], "buffers": [{ "byteLength": 0 }] }), bin: Vec::new() };
    sample.push_view(bytes(&TIMES, f32::to_le_bytes));
    sample.push_view(bytes(TRANSLATIONS.as_flattened(), f32::to_le_bytes));
    sample.push_view(bytes(ROTATIONS_I16.as_flattened(), i16::to_le_bytes));
    sample.push_view(bytes(&[0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0], f32::to_le_bytes));
    sample.push_view(vec![0, 1, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0]);
    sample.push_view(bytes(&[0.5f32, 0.5, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.5, 0.5, 0.0, 0.0], f32::to_le_bytes));
    sample.push_view(bytes(&[0u16, 1, 2], u16::to_le_bytes));
    sample.push_view(bytes(DMat4::IDENTITY.to_cols_array().map(|v| v as f32).repeat(2).as_slice(), f32::to_le_bytes));
    let json = json!({
        "asset": { "version": "2.0" },
        "scene": 0,
        "scenes": [{ "nodes": [0, 2] }],
        "nodes": [
            { "name": "root", "children": [1] },
            { "name": "child", "translation": [0.0, 1.0, 0.0] },
            { "name": "mesh", "mesh": 0, "skin": 0 },
        ],
        "meshes": [{ "name": "tri", "primitives": [{
            "attributes": { "POSITION": 3, "JOINTS_0": 4, "WEIGHTS_0": 5 },
            "indices": 6,
        }]}],
        "skins": [{ "joints": [0, 1], "inverseBindMatrices": 7 }],
        "animations": [{
            "name": "move",
            "samplers": [
                { "input": 0, "output": 1 },
                { "input": 0, "output": 2, "interpolation": "STEP" },
            ],
            "channels": [
                { "sampler": 0, "target": { "node": 1, "path": "translation" } },
                { "sampler": 1, "target": { "node": 1, "path": "rotation" } },
            ],
        }],
        "accessors": [
            { "bufferView": 0, "componentType": 5126, "count": 3, "type": "SCALAR", "min": [0.0], "max": [1.0] },
            { "bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC3" },
            { "bufferView": 2, "componentType": 5122, "normalized": true, "count": 3, "type": "VEC4" },
            { "bufferView": 3, "componentType": 5126, "count": 3, "type": "VEC3",
              "min": [0.0, 0.0, 0.0], "max": [1.0, 1.0, 0.0] },
            { "bufferView": 4, "componentType": 5121, "count": 3, "type": "VEC4" },
            { "bufferView": 5, "componentType": 5126, "count": 3, "type": "VEC4" },
            { "bufferView": 6, "componentType": 5123, "count": 3, "type": "SCALAR" },
            { "bufferView": 7, "componentType": 5126, "count": 2, "type": "MAT4" },
        ],
    });
    let fields = sample.json.as_object_mut().unwrap();
    fields.extend(json.as_object().unwrap().clone());
    sample
}

impl Sample {
    /// The `.gltf` text with the buffer as a `data:` URI.
    fn gltf(&self) -> Vec<u8> {
        let uri =
            format!("data:application/octet-stream;base64,{}", base64::prelude::BASE64_STANDARD.encode(&self.bin));
        self.gltf_with_uri(&uri)
    }

    fn gltf_with_uri(&self, uri: &str) -> Vec<u8> {
        let mut json = self.json.clone();
        json["buffers"][0]["uri"] = json!(uri);
        serde_json::to_vec_pretty(&json).unwrap()
    }

    /// The `.glb` file: header, JSON chunk, BIN chunk.
    fn glb(&self) -> Vec<u8> {
        glb(&serde_json::to_vec(&self.json).unwrap(), &self.bin)
    }
}

fn glb(json: &[u8], bin: &[u8]) -> Vec<u8> {
    let pad = |data: &[u8], with: u8| {
        let mut data = data.to_vec();
        data.resize(data.len().next_multiple_of(4), with);
        data
    };
    let (json, bin) = (pad(json, b' '), pad(bin, 0));
    let total = 12 + 8 + json.len() + 8 + bin.len();
    let mut out = Vec::with_capacity(total);
    out.extend(b"glTF");
    out.extend(2u32.to_le_bytes());
    out.extend((total as u32).to_le_bytes());
    out.extend((json.len() as u32).to_le_bytes());
    out.extend(b"JSON");
    out.extend(json);
    out.extend((bin.len() as u32).to_le_bytes());
    out.extend(b"BIN\0");
    out.extend(bin);
    out
}

/// Writes `bytes` as `dir/name` and loads it through the format-detecting entry.
fn load_file(dir: &Path, name: &str, bytes: &[u8]) -> Result<Rig, ImportError> {
    let path = dir.join(name);
    std::fs::write(&path, bytes).unwrap();
    import::load(&path)
}

fn load_gltf(sample: &Sample) -> Result<Rig, ImportError> {
    let dir = tempfile::tempdir().unwrap();
    load_file(dir.path(), "sample.gltf", &sample.gltf())
}

fn load_glb(sample: &Sample) -> Result<Rig, ImportError> {
    let dir = tempfile::tempdir().unwrap();
    load_file(dir.path(), "sample.glb", &sample.glb())
}

/// Checks that loading failed at `place` with a message containing `needle`, in one line naming the file.
#[track_caller]
fn assert_fails(result: Result<Rig, ImportError>, place: &str, needle: &str) {
    let error = match result {
        Ok(_) => panic!("loaded, expected an error at {place}"),
        Err(e) => e,
    };
    let text = error.to_string();
    assert_eq!(error.place.as_deref(), Some(place), "{text}");
    assert!(error.message.contains(needle), "{text} (expected `{needle}`)");
    assert!(text.starts_with(&error.path.display().to_string()) && !text.contains('\n'), "{text}");
}

/// A node's role: Cesium Man's nodes (unnamed: node 0 the Z-up root, 21 the armature, 2 to 20 the skin's joints,
/// 1 the skinned mesh); in a hand-written scene, a camera, a light, a node nothing refers to, one that an
/// animation moves and the nodes below it.
#[test]
fn nodes_have_the_role_of_what_refers_to_them() {
    let cesium = load_asset("gltf-khronos/cesium_man.gltf");
    let role = |rig: &Rig, name: &str| rig.skeleton.bones()[rig.skeleton.find(name).unwrap()].role;
    for node in [0].into_iter().chain(2..=21) {
        assert_eq!(role(&cesium, &format!("node{node}")), NodeRole::Joint, "node {node}");
    }
    assert_eq!(role(&cesium, "node1"), NodeRole::Mesh);

    let times = [0.0f32, 1.0];
    let translations = [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0];
    let bin: Vec<u8> = times.iter().chain(&translations).flat_map(|v| v.to_le_bytes()).collect();
    let uri =
        format!("data:application/octet-stream;base64,{}", base64::engine::general_purpose::STANDARD.encode(&bin));
    let document = json!({
        "asset": {"version": "2.0"},
        "extensionsUsed": ["KHR_lights_punctual"],
        "scenes": [{"nodes": [0, 1, 2, 3]}],
        "nodes": [
            {"name": "cam", "camera": 0},
            {"name": "lamp", "extensions": {"KHR_lights_punctual": {"light": 0}}},
            {"name": "empty"},
            {"name": "moved", "children": [4, 6]},
            {"name": "carried", "children": [5]},
            {"name": "carried_on"},
            {"name": "held_camera", "camera": 0}
        ],
        "cameras": [{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.1}}],
        "buffers": [{"byteLength": bin.len(), "uri": uri}],
        "bufferViews": [{"buffer": 0, "byteLength": 8}, {"buffer": 0, "byteOffset": 8, "byteLength": 24}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 2, "type": "SCALAR", "min": [0.0], "max": [1.0]},
            {"bufferView": 1, "componentType": 5126, "count": 2, "type": "VEC3"}
        ],
        "animations": [{"samplers": [{"input": 0, "output": 1}],
                        "channels": [{"sampler": 0, "target": {"node": 3, "path": "translation"}}]}]
    });
    let dir = tempfile::tempdir().unwrap();
    let rig = load_file(dir.path(), "roles.gltf", document.to_string().as_bytes()).unwrap_or_else(|e| panic!("{e}"));
    let expected = [("cam", NodeRole::Camera), ("lamp", NodeRole::Light), ("empty", NodeRole::Helper)];
    // A plain node below a joint carries the chain onward, however deep; a camera there stays a camera.
    let below = [("carried", NodeRole::Joint), ("carried_on", NodeRole::Joint), ("held_camera", NodeRole::Camera)];
    for (name, expected) in expected.into_iter().chain([("moved", NodeRole::Joint)]).chain(below) {
        assert_eq!(role(&rig, name), expected, "{name}");
    }
}

#[test]
fn channels_sharing_a_sampler_share_its_decoded_values() {
    // The translation sampler drives the root's translation and its scale too: one decode, two tracks.
    let mut sample = sample();
    let channels = sample.json["animations"][0]["channels"].as_array_mut().unwrap();
    channels.push(json!({ "sampler": 0, "target": { "node": 0, "path": "translation" } }));
    channels.push(json!({ "sampler": 0, "target": { "node": 0, "path": "scale" } }));
    let rig = load_glb(&sample).unwrap();
    let clip = rig.find_clip("move").unwrap();
    let (root, child) = (clip.tracks_of(0).unwrap(), clip.tracks_of(1).unwrap());
    let values = |track: &Option<bonescope::model::Track<Vec3>>| track.as_ref().unwrap().values().as_ptr();
    assert!(std::ptr::eq(values(&child.translation), values(&root.translation)));
    assert!(std::ptr::eq(values(&root.translation), values(&root.scale)));
    assert_eq!(root.scale.as_ref().unwrap().values(), TRANSLATIONS.map(Vec3::from_array));
}

#[test]
fn the_sample_loads_as_gltf_and_as_glb() {
    let sample = sample();
    for rig in [load_gltf(&sample).unwrap(), load_glb(&sample).unwrap()] {
        let names: Vec<&str> = rig.skeleton.bones().iter().map(|b| b.name.as_str()).collect();
        assert_eq!(names, ["root", "child", "mesh"]);
        assert_eq!(rig.skeleton.parent(1), Some(0));
        assert_eq!(rig.skeleton.bone(1).rest.translation, DVec3::Y);
        let clip = rig.find_clip("move").unwrap();
        assert_eq!(clip.span().end, 1.0);
        let tracks = clip.tracks_of(1).unwrap();
        let translation = tracks.translation.as_ref().unwrap();
        assert_eq!(translation.values(), TRANSLATIONS.map(Vec3::from_array));
        let rotation = tracks.rotation.as_ref().unwrap();
        assert_eq!(rotation.interpolation(), Interpolation::Step);
        assert!(std::ptr::eq(translation.times(), rotation.times()), "samplers sharing an input share its times");
        assert_eq!(rig.skins.len(), 1);
        assert_eq!(rig.skins[0].joints, [0, 1]);
        assert_eq!(rig.skins[0].inverse_bind, [DMat4::IDENTITY; 2]);
        let mesh = &rig.meshes[0];
        assert_eq!((mesh.name.as_str(), mesh.bone, mesh.skin), ("tri", 2, Some(0)));
        assert_eq!(mesh.joints, [[0, 1, 0, 0], [1, 0, 0, 0], [0, 1, 0, 0]]);
        assert_eq!(mesh.weights[0], [0.5, 0.5, 0.0, 0.0]);
        assert_eq!(mesh.indices, [0, 1, 2]);
        assert!(rig.notes.iter().any(|n| n.contains("Y-up")));
    }
}

#[test]
fn normalized_i16_rotations_are_decoded_per_spec() {
    let rig = load_glb(&sample()).unwrap();
    let rotation = rig.clips[0].tracks_of(1).unwrap().rotation.as_ref().unwrap();
    let decode = |c: i16| (f32::from(c) / 32767.0).max(-1.0);
    let expected = ROTATIONS_I16.map(|q| Quat::from_array(q.map(decode)));
    assert_eq!(rotation.values(), expected);
    assert_eq!(rotation.values()[2].x, -1.0, "−32768 clamps to −1");
    assert_eq!(rotation.values()[1].z, 16384.0 / 32767.0);
}

#[test]
fn truncated_glb_is_an_error() {
    let glb = sample().glb();
    let dir = tempfile::tempdir().unwrap();
    assert_fails(load_file(dir.path(), "t.glb", &glb[..glb.len() / 2]), "GLB header", "truncated");
    assert_fails(load_file(dir.path(), "t.glb", &glb[..7]), "GLB header", "truncated");
    // The header agrees with the cut file, but the BIN chunk does not fit.
    let mut cut = glb[..glb.len() - 10].to_vec();
    let length = (cut.len() as u32).to_le_bytes();
    cut[8..12].copy_from_slice(&length);
    assert_fails(load_file(dir.path(), "t.glb", &cut), "GLB chunks[1]", "truncated");
    let mut tiny = glb[..12].to_vec();
    tiny[8..12].copy_from_slice(&3u32.to_le_bytes());
    assert_fails(load_file(dir.path(), "t.glb", &tiny), "GLB header", "length");
}

#[test]
fn malformed_json_is_an_error() {
    let dir = tempfile::tempdir().unwrap();
    let text = b"{\n  \"asset\": { \"version\": \"2.0\" },\n  \"nodes\": [ { \"name\": } ]\n}";
    assert_fails(load_file(dir.path(), "t.gltf", text), "JSON line 3, column 24", "malformed JSON");
    let mut missing = sample().json;
    missing["accessors"][0].as_object_mut().unwrap().remove("count");
    let error = load_file(dir.path(), "t.gltf", &serde_json::to_vec(&missing).unwrap()).unwrap_err();
    assert!(error.message.contains("missing field `count`"), "{error}");
    let broken_glb = glb(b"{ \"asset\": ", &[]);
    let error = load_file(dir.path(), "t.glb", &broken_glb).unwrap_err();
    assert!(error.message.contains("malformed JSON"), "{error}");
}

#[test]
fn accessor_out_of_range_is_an_error() {
    let mut sample = sample();
    sample.json["accessors"][1]["count"] = json!(40);
    assert_fails(load_gltf(&sample), "accessors[1]", "do not fit in bufferViews[1]");
    let mut sample = self::sample();
    sample.json["accessors"][1]["byteOffset"] = json!(4);
    assert_fails(load_glb(&sample), "accessors[1]", "do not fit");
    let mut sample = self::sample();
    sample.json["bufferViews"][2]["byteLength"] = json!(100_000);
    assert_fails(load_glb(&sample), "bufferViews[2]", "outside buffers[0]");
    let mut sample = self::sample();
    sample.json["accessors"][2]["count"] = json!(u64::MAX / 2);
    assert_fails(load_glb(&sample), "accessors[2]", "do not fit");
}

#[test]
fn the_first_channel_that_fails_is_the_one_named() {
    // Outputs are decoded on every core before the channels are read in order: an output that does not decode is
    // named only where its channel comes first, and an earlier channel's own failure still comes first.
    let mut sample = sample();
    sample.json["accessors"][2]["normalized"] = json!(false);
    sample.json["animations"][0]["channels"][0]["sampler"] = json!(7);
    assert_fails(load_glb(&sample), "animations[0].channels[0].sampler", "refers to samplers[7]");
    sample.json["animations"][0]["channels"][0]["sampler"] = json!(1);
    sample.json["animations"][0]["channels"][0]["target"]["path"] = json!("rotation");
    sample.json["animations"][0]["channels"][1]["target"]["node"] = json!(0);
    assert_fails(load_glb(&sample), "accessors[2]", "rotation output must be VEC4");
}

#[test]
fn accessor_types_are_checked() {
    let mut sample = sample();
    sample.json["accessors"][2]["normalized"] = json!(false);
    assert_fails(load_glb(&sample), "accessors[2]", "rotation output must be VEC4 of FLOAT or normalized BYTE");
    let mut sample = self::sample();
    sample.json["accessors"][0]["type"] = json!("VEC2");
    assert_fails(load_glb(&sample), "accessors[0]", "keyframe times must be SCALAR of FLOAT");
    let mut sample = self::sample();
    sample.json["accessors"][4]["componentType"] = json!(5125);
    assert_fails(load_glb(&sample), "accessors[4]", "JOINTS_0");
}

impl Sample {
    /// Appends `data` to the buffer as a new buffer view; its index.
    fn push_view(&mut self, data: Vec<u8>) -> usize {
        self.bin.resize(self.bin.len().next_multiple_of(4), 0);
        let views = self.json["bufferViews"].as_array_mut().unwrap();
        views.push(json!({ "buffer": 0, "byteOffset": self.bin.len(), "byteLength": data.len() }));
        let index = views.len() - 1;
        self.bin.extend(data);
        self.json["buffers"][0]["byteLength"] = json!(self.bin.len());
        index
    }

    /// Appends an accessor; its index.
    fn push_accessor(&mut self, accessor: Value) -> usize {
        let accessors = self.json["accessors"].as_array_mut().unwrap();
        accessors.push(accessor);
        accessors.len() - 1
    }

    /// A sparse block replacing the elements at `indices` (u16) by `values` (f32).
    fn sparse(&mut self, indices: &[u16], values: &[f32]) -> Value {
        let index_view = self.push_view(bytes(indices, u16::to_le_bytes));
        let value_view = self.push_view(bytes(values, f32::to_le_bytes));
        json!({
            "count": indices.len(),
            "indices": { "bufferView": index_view, "componentType": 5123 },
            "values": { "bufferView": value_view },
        })
    }
}

#[test]
fn sparse_accessors_replace_the_elements_they_list() {
    let mut sample = sample();
    let sparse = sample.sparse(&[0, 2], &[7.0, 8.0, 9.0, -1.0, -2.0, -3.0]);
    sample.json["accessors"][1]["sparse"] = sparse;
    let rig = load_glb(&sample).unwrap();
    let translation = rig.clips[0].tracks_of(1).unwrap().translation.as_ref().unwrap();
    let expected = [[7.0, 8.0, 9.0], TRANSLATIONS[1], [-1.0, -2.0, -3.0]].map(Vec3::from_array);
    assert_eq!(translation.values(), expected, "elements 0 and 2 replaced, 1 kept from the buffer view");
}

#[test]
fn accessors_without_a_buffer_view_are_zeros_under_their_sparse_elements() {
    let mut sample = sample();
    // Scale keys: zeros but for key 1. Inverse bind matrices: zeros, both identities written sparse.
    let sparse = sample.sparse(&[1], &[1.0, 2.0, 3.0]);
    let scales = sample.push_accessor(json!({ "componentType": 5126, "count": 3, "type": "VEC3", "sparse": sparse }));
    let samplers = sample.json["animations"][0]["samplers"].as_array_mut().unwrap();
    samplers.push(json!({ "input": 0, "output": scales }));
    let channels = sample.json["animations"][0]["channels"].as_array_mut().unwrap();
    channels.push(json!({ "sampler": 2, "target": { "node": 0, "path": "scale" } }));
    let identity = DMat4::IDENTITY.to_cols_array().map(|v| v as f32);
    let sparse = sample.sparse(&[0, 1], &identity.repeat(2));
    let matrices = sample.push_accessor(json!({ "componentType": 5126, "count": 2, "type": "MAT4", "sparse": sparse }));
    sample.json["skins"][0]["inverseBindMatrices"] = json!(matrices);
    let rig = load_glb(&sample).unwrap();
    let scale = rig.clips[0].tracks_of(0).unwrap().scale.as_ref().unwrap();
    assert_eq!(scale.values(), [Vec3::ZERO, Vec3::new(1.0, 2.0, 3.0), Vec3::ZERO]);
    assert_eq!(rig.skins[0].inverse_bind, [DMat4::IDENTITY; 2]);
    // Without the sparse block the matrices are zeros: a valid file, but no inverse bind matrix.
    sample.json["accessors"][matrices].as_object_mut().unwrap().remove("sparse");
    assert_eq!(load_glb(&sample).unwrap().skins[0].inverse_bind, [DMat4::ZERO; 2]);
}

#[test]
fn broken_sparse_blocks_are_placed() {
    let mut sample = sample();
    let sparse = sample.sparse(&[2, 1], &[0.0; 6]);
    sample.json["accessors"][1]["sparse"] = sparse;
    assert_fails(load_glb(&sample), "accessors[1].sparse.indices", "must increase strictly");
    let mut sample = self::sample();
    let sparse = sample.sparse(&[3], &[0.0; 3]);
    sample.json["accessors"][1]["sparse"] = sparse;
    assert_fails(load_glb(&sample), "accessors[1].sparse.indices", "below count 3");
    let mut sample = self::sample();
    let mut sparse = sample.sparse(&[0], &[0.0; 3]);
    sparse["count"] = json!(5);
    sample.json["accessors"][1]["sparse"] = sparse;
    assert_fails(load_glb(&sample), "accessors[1].sparse", "count 5 is not in 1..=3");
    let mut sample = self::sample();
    let mut sparse = sample.sparse(&[0, 1], &[0.0; 3]);
    sparse["count"] = json!(2);
    sample.json["accessors"][1]["sparse"] = sparse;
    assert_fails(load_glb(&sample), "accessors[1].sparse.values", "do not fit");
}

#[test]
fn zero_accessors_are_capped() {
    let mut sample = sample();
    sample.json["accessors"][1] = json!({ "componentType": 5126, "count": 4_000_000_000u64, "type": "VEC3" });
    assert_fails(load_glb(&sample), "accessors[1]", "without a bufferView");
}

#[test]
fn animation_pointers_animate_nodes_and_mesh_weights_and_list_the_rest() {
    let mut sample = sample();
    let pointer = |p: &str| json!({ "path": "pointer", "extensions": { "KHR_animation_pointer": { "pointer": p } } });
    let samplers = sample.json["animations"][0]["samplers"].as_array_mut().unwrap();
    samplers.push(json!({ "input": 0, "output": 0 }));
    sample.json["animations"][0]["channels"] = json!([
        { "sampler": 0, "target": pointer("/nodes/0/translation") },
        { "sampler": 1, "target": pointer("/nodes/1/rotation") },
        { "sampler": 2, "target": pointer("/meshes/0/weights") },
        { "sampler": 2, "target": pointer("/materials/0/alphaCutoff") },
        { "sampler": 2, "target": pointer("/materials/1/alphaCutoff") },
    ]);
    let rig = load_glb(&sample).unwrap();
    let clip = &rig.clips[0];
    let translation = clip.tracks_of(0).unwrap().translation.as_ref().unwrap();
    assert_eq!(translation.values(), TRANSLATIONS.map(Vec3::from_array));
    assert_eq!(clip.tracks_of(1).unwrap().rotation.as_ref().unwrap().interpolation(), Interpolation::Step);
    assert_eq!(clip.morph().iter().map(|m| m.bone).collect::<Vec<_>>(), [2], "the node showing mesh 0");
    let note = "2 animation channels animate properties bonescope does not evaluate: `/materials/0/alphaCutoff`, \
                `/materials/1/alphaCutoff`";
    assert!(rig.notes.iter().any(|n| n == note), "{:?}", rig.notes);
    sample.json["animations"][0]["channels"][0]["target"] = pointer("/nodes/9/translation");
    assert_fails(load_glb(&sample), "animations[0].channels[0].target", "names no existing node");
}

#[test]
fn quantized_positions_are_decoded() {
    let mut sample = sample();
    let view = sample.push_view(bytes(&[0i16, 0, 0, 32767, 0, 0, -32767, 16384, 0], i16::to_le_bytes));
    let quantized =
        json!({ "bufferView": view, "componentType": 5122, "normalized": true, "count": 3, "type": "VEC3" });
    let accessor = sample.push_accessor(quantized);
    sample.json["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = json!(accessor);
    sample.json["extensionsUsed"] = json!(["KHR_mesh_quantization"]);
    sample.json["extensionsRequired"] = json!(["KHR_mesh_quantization"]);
    let rig = load_glb(&sample).unwrap();
    let expected = [Vec3::ZERO, Vec3::X, Vec3::new(-1.0, 16384.0 / 32767.0, 0.0)];
    assert_eq!(rig.meshes[0].positions, expected);
}

#[test]
fn required_extensions_bonescope_cannot_honour_are_refused_by_name() {
    let mut sample = sample();
    sample.json["extensionsRequired"] = json!(["KHR_texture_basisu", "EXT_unknown_geometry"]);
    assert_fails(load_glb(&sample), "extensionsRequired[1]", "`EXT_unknown_geometry`");
    sample.json["extensionsRequired"] = json!(["KHR_texture_basisu"]);
    let rig = load_glb(&sample).unwrap();
    assert!(rig.notes.iter().any(|n| n.contains("`KHR_texture_basisu`")), "{:?}", rig.notes);
}

#[test]
fn buffers_are_read_only_when_needed() {
    // An unused buffer that names the network, and one with no uri at all: both harmless.
    let mut sample = sample();
    let buffers = sample.json["buffers"].as_array_mut().unwrap();
    buffers.push(json!({ "uri": "http://example.com/unused.bin", "byteLength": 4 }));
    buffers.push(json!({ "byteLength": 4 }));
    assert!(load_glb(&sample).is_ok());
    // The mesh's positions in the uri-less buffer: the mesh is left out, said in the notes.
    sample.json["bufferViews"][3]["buffer"] = json!(2);
    let rig = load_glb(&sample).unwrap();
    assert!(rig.meshes.is_empty());
    assert!(rig.notes.iter().any(|n| n.contains("meshes[0].primitives[0] (buffers[2])")), "{:?}", rig.notes);
    // Animation data in it cannot be left out: refused, naming who needed it.
    sample.json["bufferViews"][1]["buffer"] = json!(2);
    assert_fails(load_glb(&sample), "accessors[1]", "needs buffers[2]: it has no uri");
    sample.json["bufferViews"][1]["buffer"] = json!(1);
    assert_fails(load_glb(&sample), "accessors[1]", "needs buffers[1]: unsupported URI scheme `http:`");
}

#[test]
fn integers_written_as_floats_and_optional_parts_are_accepted() {
    let mut sample = sample();
    sample.json["scene"] = json!(0.0);
    sample.json["nodes"][0]["children"] = json!([1.0]);
    sample.json["scenes"].as_array_mut().unwrap().push(json!({}));
    sample.json["materials"] = json!([{ "pbrMetallicRoughness": { "baseColorTexture": { "index": 5 } } }]);
    sample.json["textures"] = json!([{ "sampler": 0 }]);
    let rig = load_glb(&sample).unwrap();
    assert_eq!(rig.skeleton.parent(1), Some(0));
    sample.json["scene"] = json!(0.5);
    assert_fails(load_glb(&sample), "scene", "a non-negative integer");
}

#[test]
fn non_affine_inverse_bind_matrices_are_refused() {
    let mut sample = sample();
    let ibm_view = sample.json["accessors"][7]["bufferView"].as_u64().unwrap() as usize;
    let start = sample.json["bufferViews"][ibm_view]["byteOffset"].as_u64().unwrap() as usize;
    // Matrix 1, column 0, row 3.
    sample.bin[start + 64 + 12..start + 64 + 16].copy_from_slice(&1.0f32.to_le_bytes());
    assert_fails(load_glb(&sample), "skins[0]", "inverse bind matrix 1 is not affine");
}

#[test]
fn sampler_input_output_count_mismatch_is_an_error() {
    let mut sample = sample();
    sample.json["accessors"][1]["count"] = json!(2);
    assert_fails(load_gltf(&sample), "animations[0].samplers[0]", "2 output values for 3 keys");
}

#[test]
fn nan_in_a_keyframe_output_is_an_error() {
    let mut sample = sample();
    let second_value_y = 12 + 3 * 4 + 4;
    sample.bin[second_value_y..second_value_y + 4].copy_from_slice(&f32::NAN.to_le_bytes());
    assert_fails(load_gltf(&sample), "animations[0].samplers[0]", "output value 1 is not finite");
    let mut sample = self::sample();
    sample.bin[4..8].copy_from_slice(&f32::NAN.to_le_bytes());
    assert_fails(load_glb(&sample), "animations[0].samplers[0]", "key time 1");
}

#[test]
fn node_cycles_and_shared_children_are_errors() {
    let mut sample = sample();
    sample.json["nodes"][1]["children"] = json!([0]);
    assert_fails(load_glb(&sample), "nodes[0]", "cycle");
    let mut sample = self::sample();
    sample.json["nodes"][2]["children"] = json!([1]);
    assert_fails(load_glb(&sample), "nodes[1]", "two parents");
    let mut sample = self::sample();
    sample.json["nodes"][2]["children"] = json!([2]);
    assert_fails(load_glb(&sample), "nodes[2]", "cycle");
    let mut sample = self::sample();
    sample.json["scenes"][0]["nodes"] = json!([0, 1]);
    assert_fails(load_glb(&sample), "scenes[0]", "a child of nodes[0]");
}

#[test]
fn duplicate_channel_targets_are_an_error() {
    let mut sample = sample();
    sample.json["animations"][0]["channels"][1]["target"]["path"] = json!("translation");
    assert_fails(load_glb(&sample), "animations[0].channels[1]", "second channel for the translation of nodes[1]");
}

#[test]
fn validation_errors_name_the_json_path() {
    let mut sample = sample();
    sample.json["animations"][0]["channels"][0]["sampler"] = json!(7);
    assert_fails(load_glb(&sample), "animations[0].channels[0].sampler", "refers to samplers[7], which does not exist");
    let mut sample = self::sample();
    sample.json["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = json!(99);
    assert_fails(load_glb(&sample), "meshes[0].primitives[0].attributes.POSITION", "does not exist");
    let mut sample = self::sample();
    sample.json["animations"][0]["channels"][1]["target"]["node"] = json!(3);
    assert_fails(load_glb(&sample), "animations[0].channels[1].target.node", "does not exist");
    let mut sample = self::sample();
    sample.json["animations"][0]["channels"][1]["target"]["path"] = json!("colour");
    assert_fails(load_glb(&sample), "animations[0].channels[1].target.path", "unknown path `colour`");
    let mut sample = self::sample();
    sample.json["asset"]["version"] = json!("1.0");
    assert_fails(load_glb(&sample), "asset.version", "not supported");
}

#[test]
fn skins_and_meshes_are_checked() {
    let mut sample = sample();
    sample.json["skins"][0]["joints"] = json!([0, 1, 3]);
    sample.json["nodes"].as_array_mut().unwrap().push(json!({ "name": "loose" }));
    assert_fails(load_glb(&sample), "skins[0]", "joint nodes[3] is not in the scene");
    let mut sample = self::sample();
    sample.json["skins"][0]["joints"] = json!([0]);
    assert_fails(load_glb(&sample), "meshes[0].primitives[0]", "the skin has 1 joints");
    let mut sample = self::sample();
    sample.json["skins"][0]["joints"] = json!([0, 1, 2]);
    assert_fails(load_glb(&sample), "skins[0]", "2 inverse bind matrices for 3 joints");
    // An index past the vertices drops its triangle, with a note, and the file loads (assimp's
    // `IndexOutOfRange.gltf`): here the only triangle.
    let mut sample = self::sample();
    let third_index = sample.json["bufferViews"][6]["byteOffset"].as_u64().unwrap() as usize + 4;
    sample.bin[third_index] = 9;
    let rig = load_glb(&sample).unwrap_or_else(|e| panic!("{e}"));
    assert!(rig.meshes.iter().all(|m| m.indices.is_empty()), "the triangle that passes the vertices is left out");
    let note = "triangles whose indices pass their vertices left out: 1 in meshes[0].primitives[0]";
    assert!(rig.notes.iter().any(|n| n == note), "{:?}", rig.notes);
}

#[test]
fn nodes_outside_the_scene_become_notes_and_morph_channels_weight_tracks() {
    let mut sample = sample();
    let nodes = sample.json["nodes"].as_array_mut().unwrap();
    nodes.push(json!({}));
    let mirror = DMat4::from_scale(DVec3::new(2.0, 1.0, -1.0)).to_cols_array();
    nodes.push(json!({ "matrix": mirror }));
    sample.json["scenes"][0]["nodes"] = json!([0, 2, 3]);
    let animation = &mut sample.json["animations"][0];
    // Morph weights as one scalar per key: the time accessor will do.
    animation["samplers"].as_array_mut().unwrap().push(json!({ "input": 0, "output": 0 }));
    let channels = animation["channels"].as_array_mut().unwrap();
    channels.push(json!({ "sampler": 0, "target": { "node": 4, "path": "translation" } }));
    channels.push(json!({ "sampler": 2, "target": { "node": 2, "path": "weights" } }));
    let rig = load_glb(&sample).unwrap();
    assert_eq!(rig.skeleton.bone(3).name, "node3", "unnamed nodes are named by index");
    assert_eq!(rig.skeleton.find_node(4), None);
    assert!(rig.notes.iter().any(|n| n == "1 animation channels target nodes outside the scene, ignored"));
    assert!(rig.notes.iter().any(|n| n == "1 nodes outside the scene are not bones"));
    let morph = &rig.clips[0].morph()[0];
    assert_eq!((morph.bone, morph.weights.len()), (2, 1), "one weight per key: one target");
    assert_eq!(morph.weights[0].times(), [0.0, 0.5, 1.0]);
}

#[test]
fn matrix_nodes_are_decomposed() {
    let mut sample = sample();
    let m = DMat4::from_scale_rotation_translation(
        DVec3::new(1.0, 2.0, -0.5),
        DQuat::from_rotation_z(0.5),
        DVec3::new(1.0, 2.0, 3.0),
    );
    sample.json["nodes"][1] = json!({ "matrix": m.to_cols_array().map(|v| v as f32) });
    let rig = load_glb(&sample).unwrap();
    let rest = rig.skeleton.bone(1).rest;
    assert!(rest.matrix().abs_diff_eq(m, 1e-6), "{rest:?}");
    assert!(rest.scale.cmplt(DVec3::ZERO).all(), "a mirroring matrix puts its sign into the scale: {rest:?}");
    let mut projective = DMat4::IDENTITY;
    projective.x_axis.w = 1.0;
    sample.json["nodes"][1] = json!({ "matrix": projective.to_cols_array() });
    assert_fails(load_glb(&sample), "nodes[1]", "not affine");
}

#[test]
fn external_buffers_are_read_beside_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let sample = sample();
    std::fs::create_dir(dir.path().join("data")).unwrap();
    std::fs::write(dir.path().join("data/my buffer.bin"), &sample.bin).unwrap();
    let rig = load_file(dir.path(), "t.gltf", &sample.gltf_with_uri("data/my%20buffer.bin")).unwrap();
    assert_eq!(rig.clips.len(), 1);
}

#[test]
fn missing_external_buffer_is_an_error() {
    let dir = tempfile::tempdir().unwrap();
    let result = load_file(dir.path(), "t.gltf", &sample().gltf_with_uri("missing.bin"));
    // The place is the first accessor read (the inverse bind matrices), the buffer is named in the message.
    assert_fails(result, "accessors[7]", "needs buffers[0]: cannot open `missing.bin`");
}

#[test]
fn short_external_buffer_is_an_error() {
    let dir = tempfile::tempdir().unwrap();
    let sample = sample();
    std::fs::write(dir.path().join("short.bin"), &sample.bin[..10]).unwrap();
    let result = load_file(dir.path(), "t.gltf", &sample.gltf_with_uri("short.bin"));
    assert_fails(result, "accessors[7]", "needs buffers[0]: its byteLength is 304 but the data holds 10 bytes");
}

#[test]
fn uris_escaping_the_folder_are_refused() {
    let outer = tempfile::tempdir().unwrap();
    let sample = sample();
    // The file exists, one level up: the importer must refuse to look, not merely fail to find it.
    std::fs::write(outer.path().join("x.bin"), &sample.bin).unwrap();
    let inner = outer.path().join("inner");
    std::fs::create_dir(&inner).unwrap();
    for uri in ["../x.bin", "%2E%2E/x.bin", "sub/../../x.bin"] {
        assert_fails(load_file(&inner, "t.gltf", &sample.gltf_with_uri(uri)), "accessors[7]", "not a path inside");
    }
    let absolute = outer.path().join("x.bin");
    let result = load_file(&inner, "t.gltf", &sample.gltf_with_uri(&absolute.to_string_lossy()));
    assert!(result.is_err(), "absolute paths are refused");
}

#[test]
fn non_data_uri_schemes_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    for uri in ["http://example.com/x.bin", "file:///etc/passwd", "ftp://x/y.bin"] {
        assert_fails(load_file(dir.path(), "t.gltf", &sample().gltf_with_uri(uri)), "accessors[7]", "scheme");
    }
}

// ---------------------------------------------------------------------------------------------------------------
// Mutated files: any error is fine, a panic is not.

#[test]
fn prefixes_of_a_glb_never_panic() {
    let dir = tempfile::tempdir().unwrap();
    let glb = sample().glb();
    for len in 0..glb.len() {
        let mut prefix = glb[..len].to_vec();
        assert!(load_file(dir.path(), "p.glb", &prefix).is_err(), "prefix {len}");
        // With the header's length matching the cut, parsing gets as far as the chunks.
        if len >= 12 {
            prefix[8..12].copy_from_slice(&(len as u32).to_le_bytes());
            assert!(load_file(dir.path(), "p.glb", &prefix).is_err(), "patched prefix {len}");
        }
    }
    let text = sample().gltf();
    for len in (0..text.len()).step_by(7) {
        assert!(load_file(dir.path(), "p.gltf", &text[..len]).is_err(), "text prefix {len}");
    }
}

#[test]
fn random_byte_flips_never_panic() {
    let dir = tempfile::tempdir().unwrap();
    let mut rng = XorShiftRng::seed_from_u64(0x9E37_79B9_7F4A_7C15);
    for (name, original) in [("f.glb", sample().glb()), ("f.gltf", sample().gltf())] {
        for _ in 0..1500 {
            let mut bytes = original.clone();
            for _ in 0..1 + rng.random_range(0..4) {
                let at = rng.random_range(0..bytes.len());
                bytes[at] ^= 1 << rng.random_range(0..8);
            }
            // Any outcome but a panic is fine: a flip inside key data may well still load.
            let _ = load_file(dir.path(), name, &bytes);
        }
    }
}

/// Numbers are where a structurally valid file hides bad ranges, counts and indices.
#[test]
fn random_json_numbers_never_panic() {
    const INTERESTING: [f64; 14] =
        [0.0, 1.0, 2.0, 3.0, 4.0, 7.0, 64.0, 255.0, 4095.0, -1.0, 0.5, 2147483648.0, 4294967297.0, 1e19];
    let dir = tempfile::tempdir().unwrap();
    let mut rng = XorShiftRng::seed_from_u64(0xD1B5_4A32_D192_ED03);
    let original = sample();
    let slots = count_numbers(&original.json);
    for i in 0..1500 {
        let mut sample = self::sample();
        for _ in 0..1 + rng.random_range(0..3) {
            let value = INTERESTING[rng.random_range(0..INTERESTING.len())];
            set_number(&mut sample.json, &mut rng.random_range(0..slots), value);
        }
        let bytes = if i % 2 == 0 { sample.glb() } else { sample.gltf() };
        let _ = load_file(dir.path(), if i % 2 == 0 { "n.glb" } else { "n.gltf" }, &bytes);
    }
}

fn count_numbers(value: &Value) -> usize {
    match value {
        Value::Number(_) => 1,
        Value::Array(items) => items.iter().map(count_numbers).sum(),
        Value::Object(fields) => fields.values().map(count_numbers).sum(),
        _ => 0,
    }
}

/// Replaces the `skip`-th number (depth-first) with `new`.
fn set_number(value: &mut Value, skip: &mut usize, new: f64) -> bool {
    match value {
        Value::Number(_) if *skip == 0 => {
            *value = if new.fract() == 0.0 && new >= 0.0 { json!(new as u64) } else { json!(new) };
            true
        }
        Value::Number(_) => {
            *skip -= 1;
            false
        }
        Value::Array(items) => items.iter_mut().any(|v| set_number(v, skip, new)),
        Value::Object(fields) => fields.values_mut().any(|v| set_number(v, skip, new)),
        _ => false,
    }
}

#[test]
fn morph_targets_displace_vertices_with_their_default_and_animated_weights() {
    // Two targets on the triangle: "up" moves every vertex +1 in Z, "out" moves vertex 1 by +2 in X. Default weights
    // (0.5, 0) on the mesh; the node's weights animate them from (0, 0) over (1, 1) at 0.5 s to (1, 0.5) at 1 s,
    // one accessor holding both targets' weights per key.
    let mut sample = sample();
    let up = sample.push_view(bytes(&[0.0f32, 0.0, 1.0].repeat(3), f32::to_le_bytes));
    let out = sample.push_view(bytes(&[0.0f32, 0.0, 0.0, 2.0, 0.0, 0.0, 0.0, 0.0, 0.0], f32::to_le_bytes));
    let up = sample.push_accessor(json!({ "bufferView": up, "componentType": 5126, "count": 3, "type": "VEC3" }));
    let out = sample.push_accessor(json!({ "bufferView": out, "componentType": 5126, "count": 3, "type": "VEC3" }));
    let weights = sample.push_view(bytes(&[0.0f32, 0.0, 1.0, 1.0, 1.0, 0.5], f32::to_le_bytes));
    let weights =
        sample.push_accessor(json!({ "bufferView": weights, "componentType": 5126, "count": 6, "type": "SCALAR" }));
    let mesh = &mut sample.json["meshes"][0];
    mesh["primitives"][0]["targets"] = json!([{ "POSITION": up }, { "POSITION": out }]);
    mesh["weights"] = json!([0.5, 0.0]);
    let animation = &mut sample.json["animations"][0];
    animation["samplers"].as_array_mut().unwrap().push(json!({ "input": 0, "output": weights }));
    let channels = animation["channels"].as_array_mut().unwrap();
    channels.push(json!({ "sampler": 2, "target": { "node": 2, "path": "weights" } }));
    let rig = load_glb(&sample).unwrap();
    assert_eq!(rig.meshes[0].morph_targets.len(), 2);
    assert_eq!(rig.meshes[0].morph_weights, [0.5, 0.0]);
    let hierarchy = Hierarchy::new(&rig.skeleton, &rig.skeleton.declared_modes()).unwrap();
    let positions = |clip: Option<&Clip>, time: f64| {
        let mut pose = Pose::default();
        pose.evaluate(&rig.skeleton, clip, &hierarchy, time);
        // Only the morph, not the skinning: the weights alone.
        pose.morph.positions(&rig.meshes[0]).into_owned()
    };
    let base = [Vec3::ZERO, Vec3::X, Vec3::Y];
    let expect = |[up, out]: [f32; 2]| {
        let mut moved = base.map(|p| p + Vec3::Z * up);
        moved[1] += Vec3::X * 2.0 * out;
        moved.to_vec()
    };
    assert_eq!(positions(None, 0.0), expect([0.5, 0.0]), "the mesh's default weights at rest");
    let clip = Some(&rig.clips[0]);
    assert_eq!(positions(clip, 0.25), expect([0.5, 0.5]), "halfway to the second key");
    assert_eq!(positions(clip, 0.75), expect([1.0, 0.75]));
    assert_eq!(positions(clip, 2.0), expect([1.0, 0.5]), "the last key holds");
}

#[test]
fn gpu_instances_are_each_a_mesh_where_their_transform_puts_it() {
    // A triangle drawn twice by `EXT_mesh_gpu_instancing` under a node 1 m up: once moved 2 m along X, once turned a
    // quarter about Z and scaled 3×. Hand-derived: (1, 0, 0) lands at (3, 1, 0) and at (0, 4, 0).
    let mut g = gltf_writer::Gltf::new();
    let position = g.triangle_positions();
    let mesh = g.mesh(json!({"attributes": {"POSITION": position}}));
    let h = std::f32::consts::FRAC_1_SQRT_2;
    let translation = g.floats(&[2.0, 0.0, 0.0, 0.0, 0.0, 0.0], "VEC3", 3);
    let rotation = g.floats(&[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, h, h], "VEC4", 4);
    let scale = g.floats(&[1.0, 1.0, 1.0, 3.0, 3.0, 3.0], "VEC3", 3);
    let attributes = json!({"TRANSLATION": translation, "ROTATION": rotation, "SCALE": scale});
    g.node(json!({"mesh": mesh, "translation": [0.0, 1.0, 0.0], "extensions": {"EXT_mesh_gpu_instancing": {"attributes": attributes}}}));
    g.json["extensionsRequired"] = json!(["EXT_mesh_gpu_instancing"]);
    let dir = tempfile::tempdir().unwrap();
    let rig = load_file(dir.path(), "instanced.glb", &g.glb()).unwrap();
    assert_eq!(rig.meshes.len(), 2);
    let evaluation = bonescope::eval::Evaluation::declared(&rig, None);
    let pose = evaluation.pose_at(0.0);
    let corner = |mesh: usize| {
        let mut points = Vec::new();
        evaluation.skin(&pose, mesh, &mut points);
        points[1]
    };
    assert!(corner(0).distance(DVec3::new(3.0, 1.0, 0.0)) < 1e-6, "{}", corner(0));
    assert!(corner(1).distance(DVec3::new(0.0, 4.0, 0.0)) < 1e-6, "{}", corner(1));
}

#[test]
fn a_key_time_before_zero_is_refused_as_the_validator_refuses_it() {
    // glTF's clock starts at 0 (the validator's ACCESSOR_ANIMATION_INPUT_NEGATIVE), though other formats' may not.
    let file = asset("gltf-validator-tests/base/data/animation_data/invalid_input_values.gltf");
    assert_fails(import::load(&file), "animations[0].samplers[0]", "key time 0 (-1) is negative");
}
