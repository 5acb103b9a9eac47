//! Loading the largest shared file of each format (and ProAnimationBank's locomotion set), and the generated glTF of
//! issue 13 (`support/generated_gltf.rs`: 200 bones, 6,000 frames, ~20 MB) as `.glb` and as `.gltf` with its buffer
//! in base64, beside reading the same bytes from disk; and the same rig as a binary USD layer written by Pixar's
//! usd-core (`support/generated_usd.py`, where `BONESCOPE_USD_PYTHON` names a Python with it), beside the time
//! usd-core itself takes to open it and compute every joint's world transform at every time code.
//!
//! `cargo bench --bench load`; figures in BENCHMARKS.md (`## 4. Loading`). Per file: `read` is `std::fs::read`,
//! `parse` is `import::load_bytes` on bytes already in memory, `load` is `import::load` (what `inspect` and `scan`
//! do: glTF and FBX are read from the file as they are parsed, the rest read whole first). The whole-process
//! comparison with assimp is `benches/compare_assimp.sh`.

// The rig whose every chain squashes is for the benchmarks of `explain`.
#[allow(dead_code)]
#[path = "support/generated_gltf.rs"]
mod generated_gltf;
// The repeated mocap walk is for the benchmarks of long clips.
#[allow(dead_code)]
#[path = "support/shared_assets.rs"]
mod shared_assets;

use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;

use bonescope::eval::Evaluation;
use bonescope::import;
use criterion::{Criterion, criterion_group, criterion_main};
use shared_assets::asset;

const FILES: &[&str] = &[
    "fbx-proanimationbank/skeleton.fbx",
    "fbx-proanimationbank/locomotions.fbx",
    "gltf-khronos/cesium_man.gltf",
    "bvh/cmu_12_01_walk.bvh",
];

/// The three ways of loading the file at `path`, as a group named `name`.
fn load_file(c: &mut Criterion, name: &str, path: &Path) {
    let bytes = std::fs::read(path).expect("the file is there");
    let mut group = c.benchmark_group(name);
    group.bench_function("read", |b| b.iter(|| std::fs::read(path).unwrap()));
    group.bench_function("parse", |b| b.iter(|| import::load_bytes(path, &bytes).unwrap()));
    group.bench_function("load", |b| b.iter(|| import::load(path).unwrap()));
    group.finish();
}

fn shared_files(c: &mut Criterion) {
    for file in FILES {
        load_file(c, file, &asset(file));
    }
}

fn generated(c: &mut Criterion) {
    let folder = tempfile::tempdir().expect("a temporary folder");
    for (extension, bytes) in [
        ("glb", generated_gltf::glb(generated_gltf::Squashes::Sparse)),
        ("gltf", generated_gltf::gltf_embedded(generated_gltf::Squashes::Sparse)),
    ] {
        let path = folder.path().join(format!("generated_200x6000.{extension}"));
        std::fs::write(&path, bytes).expect("the temporary folder is writable");
        load_file(c, &format!("generated_200x6000.{extension}"), &path);
    }
}

/// The generated rig as a `.usdc` written by usd-core, its load measured beside usd-core's own (printed).
fn generated_usd(c: &mut Criterion) {
    let Some(python) = std::env::var_os("BONESCOPE_USD_PYTHON").map(PathBuf::from) else {
        eprintln!("generated_200x6000.usdc: set BONESCOPE_USD_PYTHON to a Python with usd-core to measure it");
        return;
    };
    let folder = tempfile::tempdir().expect("a temporary folder");
    let [glb, data, usdc] = ["glb", "data", "usdc"].map(|e| folder.path().join(format!("generated_200x6000.{e}")));
    std::fs::write(&glb, generated_gltf::glb(generated_gltf::Squashes::Sparse))
        .expect("the temporary folder is writable");
    write_poses(&import::load(&glb).expect("the generated glTF loads"), &data);
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("benches/support/generated_usd.py");
    let written = Command::new(&python).arg(&script).arg(&usdc).arg(&data).status().expect("python runs");
    assert!(written.success(), "usd-core wrote the layer");
    let usd_core = Command::new(&python).arg(&script).arg("--time").arg(&usdc).output().expect("python runs");
    let seconds = String::from_utf8_lossy(&usd_core.stdout);
    println!("usd-core: open generated_200x6000.usdc and compute its joints' world transforms: {} s", seconds.trim());
    load_file(c, "generated_200x6000.usdc", &usdc);
}

/// Every joint's local transform at rest and at each frame of the rig's clip, as `generated_usd.py` reads them.
fn write_poses(rig: &bonescope::model::Rig, path: &Path) {
    let clip = &rig.clips[0];
    let frames = (clip.span().length() * clip.frame_rate()).round() as usize + 1;
    let joints: Vec<String> = (0..rig.skeleton.len()).map(|b| rig.skeleton.path(b)).collect();
    let header = serde_json::json!({"joints": joints, "frames": frames, "rate": clip.frame_rate()});
    let mut out = std::io::BufWriter::new(std::fs::File::create(path).expect("writable"));
    writeln!(out, "{header}").unwrap();
    let mut write = |locals: &[bonescope::model::Transform]| {
        for local in locals {
            let (t, r, s) = (local.translation.as_vec3(), local.rotation.as_quat(), local.scale.as_vec3());
            for value in [t.x, t.y, t.z, r.x, r.y, r.z, r.w, s.x, s.y, s.z] {
                out.write_all(&value.to_le_bytes()).unwrap();
            }
        }
    };
    write(&rig.skeleton.rest_pose());
    let evaluation = Evaluation::declared(rig, Some(clip));
    let mut evaluator = evaluation.evaluator();
    for k in 0..frames {
        write(&evaluator.evaluate(k as f64 / clip.frame_rate()).local);
    }
}

criterion_group! {
    name = benches;
    // The generated files take 10–70 ms a load: fewer samples keep the run short.
    config = Criterion::default().sample_size(20);
    targets = shared_files, generated, generated_usd
}
criterion_main!(benches);
