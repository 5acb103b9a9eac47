//! Loading the largest shared FBX and BVH files, beside reading the same bytes from disk.
//!
//! `cargo bench --bench load`; figures in BENCHMARKS.md (`## Loading`). Per file: `read` is `std::fs::read`,
//! `parse` is `import::load_bytes` on bytes already in memory, `load` is `import::load` (both).

use std::path::{Path, PathBuf};

use bonescope::import;
use criterion::{Criterion, criterion_group, criterion_main};

const FILES: &[&str] =
    &["fbx-proanimationbank/skeleton.fbx", "fbx-proanimationbank/locomotions.fbx", "bvh/cmu_12_01_walk.bvh"];

fn asset(file: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/assets").join(file)
}

fn loading(c: &mut Criterion) {
    for file in FILES {
        let path = asset(file);
        let bytes = std::fs::read(&path).expect("the shared assets are beside the repository");
        let mut group = c.benchmark_group(*file);
        group.bench_function("read", |b| b.iter(|| std::fs::read(&path).unwrap()));
        group.bench_function("parse", |b| b.iter(|| import::load_bytes(&path, &bytes).unwrap()));
        group.bench_function("load", |b| b.iter(|| import::load(&path).unwrap()));
        group.finish();
    }
}

criterion_group!(benches, loading);
criterion_main!(benches);
