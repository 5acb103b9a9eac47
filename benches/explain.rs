//! `explain` on long mocap: the CMU walk (`../shared/assets/bvh`, 120 Hz) repeated 40 times (175 s), a squash keyed
//! at every frame on the spine bone three levels above the first hand (1 + 0.3·sin t, 1 − 0.2·sin t, 1), so the hand
//! shears under it. Measured after the rig-wide analysis, as the app and `scan --explain` run it: the hand's
//! causes over the whole clip (the chain at its worst time, the main causes' time spans; target ≤ 50 ms), and the
//! whole explanation with every fix measured (no target).
//!
//! And on a production clip, the generated 200-bone rig whose every limb squashes (`support/generated_gltf.rs`,
//! 6,000 frames, 95 bones flagged): one bone's explanation, its best fix alone (what `scan --explain` does per
//! bone; and with the rig's scale measured beforehand, as the app measures it once the analysis flags a bone: the
//! app's first Why?, target ≤ 100 ms) and every fix (the app's full ranking, `explain`); and the bind check of the same rig resting at its first frame, off
//! its bind, so that it searches the clip for the frame that is the bind pose (what `inspect` pays for).

use std::hint::black_box;
use std::sync::Arc;

use bonescope::analysis::{BindTolerance, ScanOptions, check_bind, scan_analysis};
use bonescope::eval::Evaluation;
use bonescope::explain::{Costs, Question, Scale, causes, explain};
use bonescope::model::{BoneTracks, Interpolation, Rig, Track};
use criterion::{Criterion, criterion_group, criterion_main};
use glam::Vec3;

#[path = "support/shared_assets.rs"]
mod shared_assets;
// The loading benchmarks' variants of the generated rig are theirs.
#[allow(dead_code)]
#[path = "support/generated_gltf.rs"]
mod generated_gltf;

/// The repeated walk with a squash on the hand's third ancestor; the rig and the hand.
fn squashed_walk() -> (Rig, usize) {
    let mut rig = shared_assets::repeated_cmu_walk(40);
    let hand = rig.skeleton.bones().iter().position(|b| b.name.contains("Hand")).expect("a hand");
    let chain = rig.skeleton.chain(hand);
    let squashed = chain[chain.len() - 4];
    let clip = &rig.clips[0];
    let times: Arc<[f64]> = clip.key_times().into();
    let squash: Vec<Vec3> =
        times.iter().map(|&t| Vec3::new(1.0 + 0.3 * t.sin() as f32, 1.0 - 0.2 * t.sin() as f32, 1.0)).collect();
    let mut tracks: Vec<BoneTracks> = clip.tracks().to_vec();
    match tracks.iter_mut().find(|t| t.bone == squashed) {
        Some(track) => track.scale = Some(Track::new(times.clone(), squash, Interpolation::Linear).unwrap()),
        None => {
            let mut track = BoneTracks::new(squashed);
            track.scale = Some(Track::new(times.clone(), squash, Interpolation::Linear).unwrap());
            tracks.push(track);
        }
    }
    rig.clips[0] = bonescope::model::Clip::new(0, clip.name.clone(), tracks, Vec::new());
    (rig, hand)
}

fn explain_on_mocap(c: &mut Criterion) {
    let (rig, hand) = squashed_walk();
    let evaluation = Evaluation::declared(&rig, rig.clips.first());
    let options = ScanOptions { rate: 120.0, ..ScanOptions::default() };
    let before = scan_analysis(&evaluation, &options);
    let worst = &before.scan.bones[hand];
    assert!(worst.stretched(), "the squash shears the hand");
    eprintln!("squashed CMU walk ×40: {} samples, {} bones, hand {hand}", before.times.len(), rig.skeleton.len());
    let mut group = c.benchmark_group("explain");
    group.sample_size(10);
    group.bench_function("the hand's causes over 175 s at 120 Hz", |b| {
        b.iter(|| black_box(causes(&evaluation, &before, hand, worst.worst_shear_time, &options.tolerances)))
    });
    group.bench_function("the hand explained, every fix measured", |b| {
        let question = Question { bones: Some(&[hand]), ..Question::default() };
        b.iter(|| black_box(explain(&evaluation, &before, question, &options)))
    });
    group.finish();
}

/// The generated rig whose every limb squashes.
fn squashing_limbs() -> Rig {
    let glb = generated_gltf::glb(generated_gltf::Squashes::EveryLimb);
    bonescope::import::load_bytes(std::path::Path::new("limbs.glb"), &glb).expect("the generated glTF loads")
}

fn explain_on_a_production_clip(c: &mut Criterion) {
    let rig = squashing_limbs();
    let evaluation = Evaluation::declared(&rig, rig.clips.first());
    let options = ScanOptions::default();
    let before = scan_analysis(&evaluation, &options);
    let flagged = before.scan.stretched_worst_first();
    let bone = flagged.last().expect("the limbs shear").index;
    eprintln!("generated limbs: {} bones flagged; explained: {}", flagged.len(), rig.skeleton.bone(bone).name);
    let mut group = c.benchmark_group("explain a production clip");
    group.sample_size(10);
    let scale = Scale::of(&evaluation, options.rate);
    let asked = [
        ("one bone, its best fix", Costs::Best, None),
        (
            "one bone, its best fix, the scale measured after the analysis (the app's first Why?)",
            Costs::Best,
            Some(&scale),
        ),
        ("one bone, every fix", Costs::Every, None),
    ];
    for (name, costs, scale) in asked {
        let question = Question { bones: Some(&[bone]), costs, scale, ..Question::default() };
        group.bench_function(name, |b| b.iter(|| black_box(explain(&evaluation, &before, question, &options))));
    }
    group.finish();
}

fn bind_frame_search(c: &mut Criterion) {
    // Every joint rests at the clip's first frame, off its bind, as exporters that store the first frame as the rest
    // write it.
    let glb = generated_gltf::glb_posed(generated_gltf::Squashes::EveryLimb);
    let rig = bonescope::import::load_bytes(std::path::Path::new("posed.glb"), &glb).expect("the generated glTF loads");
    let evaluation = Evaluation::declared(&rig, rig.clips.first());
    let check = check_bind(&evaluation, &BindTolerance::default());
    assert!(!check.posed.is_empty(), "the rest is off the bind: the clip is searched");
    let mut group = c.benchmark_group("bind check");
    group.sample_size(10);
    group.bench_function("the generated rig resting at its first frame, 6,000 frames searched", |b| {
        b.iter(|| black_box(check_bind(&evaluation, &BindTolerance::default())))
    });
    group.finish();
}

criterion_group!(benches, explain_on_mocap, explain_on_a_production_clip, bind_frame_search);
criterion_main!(benches);
