//! `bake` and `diff`, beside loading the same file: ProAnimationBank's `locomotions.fbx` (three takes, 76 nodes) and
//! the generated glTF of the loading benchmarks (`support/generated_gltf.rs`: 200 bones, 6,000 frames at 60 Hz, a
//! rotation key every frame on every bone, every 25th bone squashing), baked as the file declares and with every
//! bone under segment scale compensate (the squashing bones' children then need helper nodes and densely sampled
//! compensation).
//!
//! `cargo bench --locked --bench bake`; figures in BENCHMARKS.md (§8). `load` is `import::load` of the file; `bake`
//! the whole bake (sampling, keys, the GLB bytes), `bake_usdc` the same written as a UsdSkel crate file, `report` the bake read back and compared at every sampled time
//! (what `bonescope bake` prints), `diff` the source against the bake at its key times and 60 Hz (what `bonescope
//! diff` does).

// Shared with the loading benchmarks, which also load its base64 `.gltf` container.
#[allow(dead_code)]
#[path = "support/generated_gltf.rs"]
mod generated_gltf;
// The repeated mocap walk is for the benchmarks of long clips.
#[allow(dead_code)]
#[path = "support/shared_assets.rs"]
mod shared_assets;

use std::path::{Path, PathBuf};
use std::time::Duration;

use bonescope::bake::{self, Request, Strategy};
use bonescope::diff::{Pairs, compare, comparison_times};
use bonescope::eval::Evaluation;
use bonescope::import;
use bonescope::model::{InheritMode, Rig};
use criterion::{Criterion, criterion_group, criterion_main};

fn request(rig: &Rig, mode: Option<InheritMode>) -> Request<'_> {
    let modes = mode.map_or_else(|| rig.skeleton.declared_modes(), |m| vec![m; rig.skeleton.len()]);
    Request::every_clip(&Evaluation::new(rig, None, &modes).unwrap(), None, Strategy::Exact, bake::DEFAULT_TOLERANCE)
}

/// The source's first clip against the bake's, as `bonescope diff` compares them.
fn diff(source: &Request, baked: &Rig) {
    let a = source.clips()[0].source.clone();
    let b = Evaluation::declared(baked, baked.clips.first());
    let pairs = Pairs::by_name(&a, &b);
    compare(&a, &b, &pairs, &comparison_times(&a, &b, 60.0));
}

fn benches(c: &mut Criterion, name: &str, rig: &Rig, file: &Path, mode: Option<InheritMode>) {
    let mut group = c.benchmark_group(name);
    group.sample_size(10).measurement_time(Duration::from_secs(20));
    group.bench_function("load", |b| b.iter(|| import::load(file).unwrap()));
    let request = request(rig, mode);
    let baked = bake::bake(&request);
    let baked_rig = import::load_bytes(Path::new("baked.glb"), &baked.bytes).unwrap();
    group.bench_function("bake", |b| b.iter(|| bake::bake(&request)));
    // The same bake written as a UsdSkel crate file: within 1.5× the glTF's time.
    let usdc = bake::Output::Usd(bake::Encoding::Crate);
    group.bench_function("bake_usdc", |b| b.iter(|| bake::bake_to(&request, usdc).unwrap()));
    group.bench_function("report", |b| {
        b.iter(|| {
            let read = import::load_bytes(Path::new("baked.glb"), &baked.bytes).unwrap();
            bake::report(&request, &baked, &read)
        })
    });
    group.bench_function("diff", |b| b.iter(|| diff(&request, &baked_rig)));
    group.finish();
}

fn baking(c: &mut Criterion) {
    let locomotions = shared_assets::asset("fbx-proanimationbank/locomotions.fbx");
    let rig = import::load(&locomotions).expect("the shared assets are beside the repository");
    benches(c, "locomotions.fbx", &rig, &locomotions, None);
    let folder = tempfile::tempdir().unwrap();
    let file: PathBuf = folder.path().join("generated_200x6000.glb");
    std::fs::write(&file, generated_gltf::glb(generated_gltf::Squashes::Sparse)).unwrap();
    let generated = import::load(&file).unwrap();
    benches(c, "generated_200x6000", &generated, &file, None);
    benches(c, "generated_200x6000_compensate", &generated, &file, Some(InheritMode::SegmentCompensate));
}

criterion_group!(bench, baking);
criterion_main!(bench);
