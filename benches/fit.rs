//! `fit` of a 200-bone × 6,000-frame dump against its source: the generated glTF of the loading benchmarks
//! (`support/generated_gltf.rs`: 200 bones, 6,000 frames at 60 Hz, every 25th bone squashing), evaluated under
//! `componentwise` at every key time and written as a pose dump (JSON), then read back and fitted under every mode.
//!
//! `cargo bench --locked --bench fit`; figures in BENCHMARKS.md. `load dump` is `import::load_bytes` of the dump
//! (parsing, local matrices, their decomposition into tracks), `fit` the fit itself (the source under `declared`
//! and nine modes, each against the dump at its 6,000 times).

#[allow(dead_code)]
#[path = "support/generated_gltf.rs"]
mod generated_gltf;

use std::path::Path;
use std::time::Duration;

use bonescope::eval::Evaluation;
use bonescope::export::DumpWriter;
use bonescope::fit::{DEFAULT_TOLERANCE, fit};
use bonescope::import::dump::{DumpHeader, Syntax};
use bonescope::import::{self, load_bytes};
use bonescope::model::{InheritMode, Rig};
use criterion::{Criterion, criterion_group, criterion_main};

/// `rig`'s first clip under `mode` at its key times, as a JSON pose dump.
fn dump(rig: &Rig, mode: InheritMode) -> Vec<u8> {
    let evaluation = Evaluation::new(rig, rig.clips.first(), &vec![mode; rig.skeleton.len()]).unwrap();
    let header = DumpHeader { unit: rig.unit, ..DumpHeader::default() };
    let mut writer = DumpWriter::new(Vec::new(), Syntax::Json, header, &rig.skeleton).unwrap();
    let mut evaluator = evaluation.evaluator();
    for time in evaluation.key_times() {
        writer.frame(time, &evaluator.evaluate(time).model.model).unwrap();
    }
    writer.finish().unwrap()
}

fn fitting(c: &mut Criterion) {
    let glb = generated_gltf::glb(generated_gltf::Squashes::Sparse);
    let source = import::load_bytes(Path::new("generated_200x6000.glb"), &glb).unwrap();
    let bytes = dump(&source, InheritMode::Componentwise);
    let dumped = load_bytes(Path::new("generated.dump.json"), &bytes).unwrap();
    let evaluation = Evaluation::declared(&source, source.clips.first());
    let mut group = c.benchmark_group("generated_200x6000");
    group.sample_size(10).measurement_time(Duration::from_secs(20));
    group.bench_function("load dump", |b| b.iter(|| load_bytes(Path::new("generated.dump.json"), &bytes).unwrap()));
    group.bench_function("fit", |b| b.iter(|| fit(&evaluation, &dumped, |size| DEFAULT_TOLERANCE * size).unwrap()));
    group.finish();
}

criterion_group!(bench, fitting);
criterion_main!(bench);
