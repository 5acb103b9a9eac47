//! Loading the largest shared file of each format (and ProAnimationBank's locomotion set), and the generated glTF of
//! issue 13 (`support/generated_gltf.rs`: 200 bones, 6,000 frames, ~20 MB) as `.glb` and as `.gltf` with its buffer
//! in base64, beside reading the same bytes from disk.
//!
//! `cargo bench --bench load`; figures in BENCHMARKS.md (`## 4. Loading`). Per file: `read` is `std::fs::read`,
//! `parse` is `import::load_bytes` on bytes already in memory, `load` is `import::load` (what `inspect` and `scan`
//! do: glTF and FBX are read from the file as they are parsed, the rest read whole first). The whole-process
//! comparison with assimp is `benches/compare_assimp.sh`.

#[path = "support/generated_gltf.rs"]
mod generated_gltf;
// The repeated mocap walk is for the benchmarks of long clips.
#[allow(dead_code)]
#[path = "support/shared_assets.rs"]
mod shared_assets;

use std::path::Path;

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
    for (extension, bytes) in [("glb", generated_gltf::glb()), ("gltf", generated_gltf::gltf_embedded())] {
        let path = folder.path().join(format!("generated_200x6000.{extension}"));
        std::fs::write(&path, bytes).expect("the temporary folder is writable");
        load_file(c, &format!("generated_200x6000.{extension}"), &path);
    }
}

criterion_group! {
    name = benches;
    // The generated files take 10–70 ms a load: fewer samples keep the run short.
    config = Criterion::default().sample_size(20);
    targets = shared_files, generated
}
criterion_main!(benches);
