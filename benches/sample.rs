//! An evaluation sampled into arrays (`analysis::sample`): every bone's local and model matrices and the model
//! matrix's parts at every time, what the Python module's `Rig.evaluate` hands to numpy. On the generated 200-bone ×
//! 6,000-frame rig (`support/generated_gltf.rs`) at its scan times (every key, 60 Hz): 1.2 million bone samples.
//! `python/bench/evaluate.py` times the same from Python on the file `write_generated_gltf` writes.

use std::hint::black_box;

use bonescope::analysis::{Tolerances, sample};
use bonescope::eval::Evaluation;
use criterion::{Criterion, criterion_group, criterion_main};

// Only the sparse rig and its binary form are sampled here.
#[allow(dead_code)]
#[path = "support/generated_gltf.rs"]
mod generated_gltf;

fn sample_the_generated_rig(c: &mut Criterion) {
    let glb = generated_gltf::glb(generated_gltf::Squashes::Sparse);
    let rig = bonescope::import::load_bytes(std::path::Path::new("generated.glb"), &glb).expect("it loads");
    let evaluation = Evaluation::declared(&rig, rig.clips.first());
    let times = evaluation.times(60.0);
    let tolerances = Tolerances::default();
    let mut group = c.benchmark_group("sample");
    group.sample_size(10);
    group.bench_function("the generated rig, every bone at its scan times", |b| {
        b.iter(|| black_box(sample(&evaluation, &times, &tolerances)))
    });
    group.finish();
}

criterion_group!(benches, sample_the_generated_rig);
criterion_main!(benches);
