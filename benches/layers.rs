//! Layered evaluation and the storage report, against their targets (figures in BENCHMARKS.md, `## Layers`).
//!
//! `cargo bench --bench layers`. Rigs are `import::stress_rig`: chains of ten bones off a root, a rotation key per
//! frame on every bone, a non-uniform scale key on every tenth.
//!
//! - `layers_500/single_clip` samples one clip of a 500-bone rig (`sample_clip`, local pose only);
//!   `layers_500/blend_sync_additive` evaluates the same rig with a synced two-clip blend (a = 0.4) plus an
//!   additive layer (weight 0.7, local order, first-frame reference). Target: at most 3× `single_clip`. Both at the
//!   same 64 times spread over the cycle; `_nlerp` blends rotations by nlerp instead of slerp; the `_model`
//!   variants add the local→model pass to both sides.
//! - `storage/100_bones_10000_frames_*`: the storage report of a 100-bone clip of 10,000 frames (10,001 key times,
//!   rate 0) under full inheritance (locals stored as they are) and with every bone compensating its parent's scale
//!   (every child of a scaled bone stretched: inverse, decomposition and stretch channel on the hot path).
//!   Target: under 1 s.

use std::hint::black_box;
use std::time::Duration;

use bonescope::analysis::storage::{StorageOptions, storage_report};
use bonescope::eval::layers::{Additive, AdditiveOrder, AdditiveReference, Blend, RotationBlend};
use bonescope::eval::{Evaluation, Hierarchy, LayerStack, Layers, Pose, sample_clip};
use bonescope::import::stress_rig;
use bonescope::model::{InheritMode, Rig};
use criterion::{Criterion, criterion_group, criterion_main};

const TIMES: usize = 64;

/// 500 bones and three clips of 40, 20 and 60 frames (a walk, a run and an additive clip, say).
fn three_clip_rig(bones: usize) -> Rig {
    let mut rig = stress_rig(bones, 40, 1);
    for (index, frames) in [(1, 20), (2, 60)] {
        let mut clip = stress_rig(bones, frames, 1).clips.remove(0);
        clip.index = index;
        rig.clips.push(clip);
    }
    rig
}

fn layered_evaluation(c: &mut Criterion) {
    let rig = three_clip_rig(500);
    let main = &rig.clips[0];
    let blend = Blend { clip: 1, weight: 0.4, sync: true, rotation: RotationBlend::Slerp };
    let additive = Additive { clip: 2, reference: AdditiveReference::First, order: AdditiveOrder::Local, weight: 0.7 };
    let layers = Layers { blend: Some(blend), additive: Some(additive), ..Layers::default() };
    let mut stack = LayerStack::new(&rig, &layers).expect("the layers fit the rig");
    let cycle = stack.synced_cycle(&rig, Some(main)).expect("a synced blend").length;
    let times: Vec<f64> = (0..TIMES).map(|i| cycle * i as f64 / TIMES as f64).collect();
    let hierarchy = Hierarchy::new(&rig.skeleton, &rig.skeleton.declared_modes()).unwrap();
    let mut group = c.benchmark_group("layers_500");
    let mut local = Vec::new();
    group.bench_function("single_clip", |b| {
        b.iter(|| {
            for &t in &times {
                sample_clip(&rig.skeleton, main, black_box(t), &mut local);
                black_box(&local);
            }
        })
    });
    group.bench_function("blend_sync_additive", |b| {
        b.iter(|| {
            for &t in &times {
                stack.evaluate(&rig, Some(main), black_box(t), &mut local);
                black_box(&local);
            }
        })
    });
    // Where the time goes: the same stack with rotations blended by nlerp, and each layer alone.
    let variants = [
        ("blend_sync_additive_nlerp", Blend { rotation: RotationBlend::Nlerp, ..blend }, Some(additive)),
        ("part_blend_sync", blend, None),
    ];
    for (name, blend, additive) in variants {
        let mut variant = LayerStack::new(&rig, &Layers { blend: Some(blend), additive, ..Layers::default() })
            .expect("the layers fit the rig");
        group.bench_function(name, |b| {
            b.iter(|| {
                for &t in &times {
                    variant.evaluate(&rig, Some(main), black_box(t), &mut local);
                    black_box(&local);
                }
            })
        });
    }
    group.bench_function("part_three_clips_sampled", |b| {
        b.iter(|| {
            for &t in &times {
                for clip in &rig.clips {
                    sample_clip(&rig.skeleton, clip, black_box(t), &mut local);
                    black_box(&local);
                }
            }
        })
    });
    let mut pose = Pose::default();
    group.bench_function("single_clip_model", |b| {
        b.iter(|| {
            for &t in &times {
                pose.evaluate(&rig.skeleton, Some(main), &hierarchy, black_box(t));
                black_box(&pose.model.model);
            }
        })
    });
    group.bench_function("blend_sync_additive_model", |b| {
        b.iter(|| {
            for &t in &times {
                pose.evaluate_layered(&rig, Some(main), &hierarchy, &mut stack, black_box(t));
                black_box(&pose.model.model);
            }
        })
    });
    group.finish();
}

fn storage(c: &mut Criterion) {
    let rig = stress_rig(100, 10_000, 1);
    let options = StorageOptions { rate: 0.0, ..StorageOptions::default() };
    let mut group = c.benchmark_group("storage");
    group.sample_size(10);
    for (name, mode) in [("full", InheritMode::Full), ("compensate", InheritMode::SegmentCompensate)] {
        let evaluation = Evaluation::new(&rig, rig.clips.first(), &vec![mode; rig.skeleton.len()]).unwrap();
        let report = storage_report(&evaluation, &options);
        assert_eq!(report.frames, 10_001);
        println!(
            "storage {name}: {} marked bones, bytes {} / {}",
            report.marked.len(),
            report.bytes_trs,
            report.bytes_with_stretch
        );
        group.bench_function(format!("100_bones_10000_frames_{name}"), |b| {
            b.iter(|| storage_report(&evaluation, &options))
        });
    }
    group.finish();
}

criterion_group! {
    name = layer_benches;
    config = Criterion::default().warm_up_time(Duration::from_secs(1)).measurement_time(Duration::from_secs(3));
    targets = layered_evaluation, storage
}
criterion_main!(layer_benches);
