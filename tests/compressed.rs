//! glTF as the web delivers it: shared files compressed by the tools that compress them — gltfpack (meshoptimizer's
//! `EXT_meshopt_compression`, keyframes included, with `KHR_mesh_quantization`) and glTF-Transform (Google's Draco,
//! `KHR_draco_mesh_compression`) — load, and evaluate as glTF-Transform's own decode of the same file (`copy`, which
//! runs meshoptimizer's and Google's decoders and writes the data plainly) to 1e-6 of the rig's size: bones and
//! every skinned vertex, at 30 samples a second. Against the uncompressed original, the bones stay within what
//! gltfpack's default quantisation allows (rotations in 12 bits, translations and scales in 16, keys resampled at
//! 30 Hz): 0.5 % of the rig's size and 0.5°. The npm packages are pinned in `tests/gltf-compressors` (installed by
//! `npm ci` there when missing).

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;

use bonescope::diff::{Pairs, compare, comparison_times};
use bonescope::eval::Evaluation;
use bonescope::import::load;
use bonescope::model::Rig;

const FILES: [&str; 3] = ["blender/stretchy_full.glb", "gltf-khronos/cesium_man.gltf", "gltf-khronos/Fox.glb"];

/// The folder of the pinned npm packages, installed first where they are missing.
fn tools() -> PathBuf {
    let folder = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/gltf-compressors");
    if !folder.join("node_modules/.bin/gltfpack").exists() {
        let npm = Command::new("npm")
            .args(["ci", "--no-audit", "--no-fund", "--ignore-scripts"])
            .current_dir(&folder)
            .output();
        let npm = npm.expect("npm (Node.js) runs gltfpack and glTF-Transform: install nodejs and npm");
        assert!(npm.status.success(), "npm ci failed: {}", String::from_utf8_lossy(&npm.stderr));
    }
    folder.join("node_modules/.bin")
}

/// Runs a tool of the npm packages.
fn run(tool: &str, args: &[&Path]) {
    let output = Command::new(tools().join(tool)).args(args).output().expect("node runs");
    assert!(output.status.success(), "{tool} {args:?}: {}", String::from_utf8_lossy(&output.stderr));
}

/// A `.glb`'s JSON, and where its binary chunk's data starts.
fn glb_json(bytes: &[u8]) -> (serde_json::Value, usize) {
    let length = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
    (serde_json::from_slice(&bytes[20..20 + length]).unwrap(), 20 + length + 8)
}

/// The extensions `file` (a `.glb`) requires.
fn required(file: &Path) -> Vec<String> {
    let (json, _) = glb_json(&std::fs::read(file).unwrap());
    json["extensionsRequired"].as_array().into_iter().flatten().map(|e| e.as_str().unwrap().to_owned()).collect()
}

/// How far apart two rigs' first clips are, over bones and skinned vertices, as a share of the rig's size.
fn apart(a: &Rig, b: &Rig) -> (f64, usize) {
    let (a, b) = (Evaluation::declared(a, a.clips.first()), Evaluation::declared(b, b.clips.first()));
    let pairs = Pairs::by_name(&a, &b);
    let compared = compare(&a, &b, &pairs, &comparison_times(&a, &b, 30.0));
    (compared.worst_distance().max / compared.rig_size, compared.meshes.len())
}

/// Compresses every file with `compress` (into `out`), checks it requires `extension`, and compares it with
/// glTF-Transform's decode of it.
fn compressed_as_decoded(extension: &str, compress: impl Fn(&Path, &Path)) -> Vec<(Rig, Rig)> {
    let folder = tempfile::tempdir().unwrap();
    let mut loaded = Vec::new();
    for file in FILES {
        let name = Path::new(file).file_stem().unwrap().to_string_lossy().into_owned();
        let (packed, unpacked) =
            (folder.path().join(format!("{name}.glb")), folder.path().join(format!("{name}.plain.glb")));
        compress(&common::asset(file), &packed);
        assert!(required(&packed).iter().any(|e| e == extension), "{file}: {:?}", required(&packed));
        run("gltf-transform", &[Path::new("copy"), &packed, &unpacked]);
        let (ours, theirs) = (load(&packed).unwrap(), load(&unpacked).unwrap());
        assert!(ours.notes.iter().all(|n| !n.contains("not drawn")), "{file}: {:?}", ours.notes);
        let (distance, meshes) = apart(&theirs, &ours);
        assert!(meshes >= 1, "{file}: its skinned mesh is compared");
        assert!(distance <= 1e-6, "{file}: {distance} of the rig's size from glTF-Transform's decode");
        loaded.push((load(&common::asset(file)).unwrap(), ours));
        scrambled_streams_leave_the_mesh_out(&packed, extension);
    }
    loaded
}

/// `packed` with its first mesh's position stream scrambled past its first eight bytes (the Draco stream, or the
/// meshopt-compressed view of `POSITION`) loads all the same: its animation whole, that mesh left out with a note.
fn scrambled_streams_leave_the_mesh_out(packed: &Path, extension: &str) {
    let mut bytes = std::fs::read(packed).unwrap();
    let (json, bin) = glb_json(&bytes);
    let primitive = &json["meshes"][0]["primitives"][0];
    let stream = match extension {
        "KHR_draco_mesh_compression" => {
            &json["bufferViews"][primitive["extensions"][extension]["bufferView"].as_u64().unwrap() as usize]
        }
        _ => {
            let position = &json["accessors"][primitive["attributes"]["POSITION"].as_u64().unwrap() as usize];
            &json["bufferViews"][position["bufferView"].as_u64().unwrap() as usize]["extensions"][extension]
        }
    };
    let start = bin + stream["byteOffset"].as_u64().unwrap_or(0) as usize;
    let end = start + stream["byteLength"].as_u64().unwrap() as usize;
    for byte in &mut bytes[start + 8..end] {
        *byte = byte.wrapping_mul(7).wrapping_add(13);
    }
    let scrambled = packed.with_extension("scrambled.glb");
    std::fs::write(&scrambled, bytes).unwrap();
    let rig = load(&scrambled).unwrap();
    assert!(!rig.clips.is_empty(), "the animation is read");
    assert!(rig.notes.iter().any(|n| n.contains("compressed geometry does not decode")), "{:?}", rig.notes);
}

#[test]
fn meshopt_compressed_files_evaluate_as_meshoptimizer_decodes_them() {
    let rigs = compressed_as_decoded("EXT_meshopt_compression", |from, to| {
        run("gltfpack", &[Path::new("-i"), from, Path::new("-o"), to, Path::new("-cc")])
    });
    // Bones against the original (gltfpack keeps bone names; the vertices it reorders are compared above).
    let (original, packed) = &rigs[0];
    let (a, b) =
        (Evaluation::declared(original, original.clips.first()), Evaluation::declared(packed, packed.clips.first()));
    let compared = compare(&a, &b, &Pairs::by_name(&a, &b), &comparison_times(&a, &b, 30.0));
    assert!(compared.bones.len() >= 8, "{} bones paired", compared.bones.len());
    for bone in &compared.bones {
        assert!(bone.probe.max <= 0.005 * compared.rig_size, "{}: {} apart", bone.name, bone.probe.max);
        assert!(bone.orientation_deg.max <= 0.5, "{}: turned {}°", bone.name, bone.orientation_deg.max);
    }
}

#[test]
fn draco_compressed_files_evaluate_as_googles_decoder_decodes_them() {
    compressed_as_decoded("KHR_draco_mesh_compression", |from, to| {
        run("gltf-transform", &[Path::new("draco"), from, to])
    });
}
