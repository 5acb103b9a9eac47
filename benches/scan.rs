//! Whole-clip `scan` throughput in bone-samples per second, beside a bare local→model pass over the same clip.
//!
//! Both visit the same sample times (`Evaluation::times(60.0)`, what `scan` uses by default). The bare pass
//! is `Pose::evaluate` in a loop, single-threaded; `scan` runs once inside a 1-thread rayon pool (the like-for-like
//! comparison) and once on the default pool. Sub-benchmarks split the cost into the pool hand-over, sampling,
//! hierarchy, and the per-matrix assessment (decomposition plus verdicts).
//!
//! Rigs: a generated 100-bone rig (chains with branching, every bone animated, every tenth bone with a non-uniform
//! scale track so its descendants shear under full inheritance; 10 s at 30 keys/s), and Blender's
//! `stretchy_full.glb` from the shared assets when it is there and loads.

// The repeated mocap walk is for the benchmarks of long clips.
#[allow(dead_code)]
#[path = "support/shared_assets.rs"]
mod shared_assets;

use std::f64::consts::TAU;
use std::hint::black_box;
use std::sync::Arc;
use std::time::Duration;

use bonescope::analysis::{Assessment, ScanOptions, Tolerances, scan};
use bonescope::eval::{Evaluation, Hierarchy, Pose, sample_clip};
use bonescope::math::decompose;
use bonescope::model::{Bone, BoneTracks, Clip, InheritMode, Interpolation, NodeRole, Rig, Skeleton, Track, Transform};
use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use glam::{DMat4, DQuat, DVec3, Vec3};
use rand::{RngExt, SeedableRng};
use rand_xorshift::XorShiftRng;

const BONES: usize = 100;
const SPINE: usize = 10;
const KEYS_PER_SECOND: usize = 30;
const SECONDS: usize = 10;
const RATE: f64 = 60.0;

/// A unit axis, uniform on the sphere (a point of the unit ball, away from its centre, normalised).
fn random_axis(rng: &mut XorShiftRng) -> DVec3 {
    loop {
        let v = DVec3::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0));
        if (0.01..=1.0).contains(&v.length_squared()) {
            return v.normalize();
        }
    }
}

/// Parents-first bones: a spine of 10 from the root, then chains of 5–12 bones, each hanging off a random spine bone
/// (60 %) or a random bone already placed (40 %), like limbs, fingers, tails and props on a character.
fn generated_skeleton(rng: &mut XorShiftRng) -> Skeleton {
    let mut bones: Vec<Bone> = Vec::with_capacity(BONES);
    let add = |bones: &mut Vec<Bone>, rng: &mut XorShiftRng, parent: Option<usize>| {
        let index = bones.len();
        let rest = Transform::from_trs(
            DVec3::new(rng.random_range(-0.05..0.05), rng.random_range(0.1..0.4), rng.random_range(-0.05..0.05)),
            DQuat::from_axis_angle(random_axis(rng), rng.random_range(0.0..0.5)),
            DVec3::ONE,
        );
        bones.push(Bone {
            name: format!("bone{index}"),
            node: index,
            parent,
            rest,
            inherit: InheritMode::Full,
            role: NodeRole::Joint,
        });
        index
    };
    let mut parent = None;
    for _ in 0..SPINE {
        parent = Some(add(&mut bones, rng, parent));
    }
    while bones.len() < BONES {
        let length = rng.random_range(5..=12);
        let mut parent =
            if rng.random_bool(0.6) { rng.random_range(0..SPINE) } else { rng.random_range(0..bones.len()) };
        for _ in 0..length.min(BONES - bones.len()) {
            parent = add(&mut bones, rng, Some(parent));
        }
    }
    Skeleton::new(bones).expect("parents come first")
}

/// Which bones get a non-uniform scale track.
#[derive(Clone, Copy, Debug)]
enum Squash {
    /// Ten bones drawn at random outside the spine: some limbs shear below them.
    Limbs,
    /// The same ten, plus the first spine bone: everything above the pelvis shears (the worst case).
    Spine,
    /// No scale tracks: nothing shears (the best case).
    None,
}

impl Squash {
    fn scaled_bones(self, rng: &mut XorShiftRng) -> Vec<usize> {
        let mut bones = Vec::new();
        while bones.len() < BONES / 10 {
            let bone = SPINE + rng.random_range(0..BONES - SPINE);
            if !bones.contains(&bone) {
                bones.push(bone);
            }
        }
        match self {
            Squash::Limbs => bones,
            Squash::Spine => {
                bones.push(1);
                bones
            }
            Squash::None => vec![],
        }
    }
}

/// Every bone: linear rotation (a swing of up to ±0.8 rad about a random axis) and translation tracks; the bones in
/// `scaled` also a non-uniform scale track (squash and stretch along their own X/Y axes).
fn generated_clip(rng: &mut XorShiftRng, skeleton: &Skeleton, scaled: &[usize]) -> Clip {
    let keys = KEYS_PER_SECOND * SECONDS + 1;
    let times: Arc<[f64]> = (0..keys).map(|i| i as f64 / KEYS_PER_SECOND as f64).collect();
    let tracks = skeleton
        .bones()
        .iter()
        .enumerate()
        .map(|(index, bone)| {
            let (axis, amplitude) = (random_axis(rng), rng.random_range(0.2..0.8));
            let (frequency, phase) = (rng.random_range(0.2..1.5), rng.random_range(0.0..TAU));
            let wave = |t: f64| (TAU * frequency * t + phase).sin();
            let rotation: Vec<_> = times
                .iter()
                .map(|&t| (bone.rest.rotation * DQuat::from_axis_angle(axis, amplitude * wave(t))).as_quat())
                .collect();
            let offset =
                DVec3::new(rng.random_range(-0.05..0.05), rng.random_range(-0.05..0.05), rng.random_range(-0.05..0.05));
            let translation: Vec<_> =
                times.iter().map(|&t| (bone.rest.translation + offset * wave(t)).as_vec3()).collect();
            let mut tracks = BoneTracks::new(index);
            tracks.rotation = Some(Track::new(times.clone(), rotation, Interpolation::Linear).unwrap());
            tracks.translation = Some(Track::new(times.clone(), translation, Interpolation::Linear).unwrap());
            if scaled.contains(&index) {
                let scale: Vec<_> = times
                    .iter()
                    .map(|&t| Vec3::new(1.0 + 0.4 * wave(t) as f32, 1.0 - 0.25 * wave(t) as f32, 1.0))
                    .collect();
                tracks.scale = Some(Track::new(times.clone(), scale, Interpolation::Linear).unwrap());
            }
            tracks
        })
        .collect();
    Clip::new(0, Some("generated".into()), tracks, vec![])
}

struct Case {
    name: String,
    /// The skeleton and its one clip.
    rig: Rig,
    hierarchy: Hierarchy,
}

impl Case {
    fn new(name: String, skeleton: Skeleton, clip: Clip, hierarchy: Hierarchy) -> Self {
        Case { name, rig: Rig { skeleton, clips: vec![clip], ..Rig::default() }, hierarchy }
    }

    fn evaluation(&self) -> Evaluation<'_> {
        Evaluation::new(&self.rig, self.rig.clips.first(), self.hierarchy.modes()).unwrap()
    }
}

fn generated_case(squash: Squash) -> Case {
    let mut rng = XorShiftRng::seed_from_u64(0x5CA7_2026_1122_0001);
    let skeleton = generated_skeleton(&mut rng);
    let scaled = squash.scaled_bones(&mut rng);
    let clip = generated_clip(&mut rng, &skeleton, &scaled);
    let hierarchy = Hierarchy::new(&skeleton, &skeleton.declared_modes()).unwrap();
    let name = match squash {
        Squash::Limbs => "generated_100".into(),
        Squash::Spine => "generated_100_spine_squash".into(),
        Squash::None => "generated_100_no_scale".into(),
    };
    Case::new(name, skeleton, clip, hierarchy)
}

/// `generated_100` with every bone in Maya's segment scale compensate: no stretch passes down the hierarchy, every
/// bone is judged from its decomposed model matrix.
fn compensating_case() -> Case {
    let case = generated_case(Squash::Limbs);
    let hierarchy =
        Hierarchy::new(&case.rig.skeleton, &vec![InheritMode::SegmentCompensate; case.rig.skeleton.len()]).unwrap();
    Case { name: "generated_100_compensate".into(), hierarchy, ..case }
}

fn blender_case() -> Option<Case> {
    let path = shared_assets::asset("blender/stretchy_full.glb");
    if !path.exists() {
        eprintln!("skipping the Blender rig: {} is missing", path.display());
        return None;
    }
    let rig = match bonescope::import::load(&path) {
        Ok(rig) => rig,
        Err(e) => {
            eprintln!("skipping the Blender rig: {e}");
            return None;
        }
    };
    let clip = rig.find_clip("squash_stretch").or(rig.clips.first())?.clone();
    let hierarchy = Hierarchy::new(&rig.skeleton, &rig.skeleton.declared_modes()).unwrap();
    Some(Case::new("stretchy_full".into(), rig.skeleton, clip, hierarchy))
}

/// Model matrices of every bone at every time, concatenated.
fn all_model_matrices(case: &Case, times: &[f64]) -> Vec<DMat4> {
    let mut pose = Pose::default();
    let mut out = Vec::with_capacity(times.len() * case.rig.skeleton.len());
    for &t in times {
        sample_clip(&case.rig.skeleton, &case.rig.clips[0], t, &mut pose.local);
        case.hierarchy.evaluate(&pose.local, &mut pose.model);
        out.extend_from_slice(&pose.model.model);
    }
    out
}

/// Whether `decompose` can take its shear-free shortcut: a copy of the test in `math::polar::shortcut`
/// (columns non-zero, within a ratio of 1e6, pairwise cosines at most 2e-13).
fn shortcut_eligible(m: &DMat4) -> bool {
    let cols = [m.x_axis.truncate(), m.y_axis.truncate(), m.z_axis.truncate()];
    let lengths = cols.map(|c| c.length());
    let (min, max) =
        (lengths.iter().copied().fold(f64::INFINITY, f64::min), lengths.iter().copied().fold(0.0, f64::max));
    min > 0.0
        && min >= max * 1e-6
        && [(0, 1), (1, 2), (0, 2)].iter().all(|&(i, j)| cols[i].dot(cols[j]).abs() <= 2e-13 * lengths[i] * lengths[j])
}

fn percent(part: usize, whole: usize) -> f64 {
    100.0 * part as f64 / whole as f64
}

/// One line on the workload: how many bone-samples are sheared for real and how many can take the shortcut.
fn describe(case: &Case, times: &[f64], models: &[DMat4]) {
    let summary = scan(&case.evaluation(), &ScanOptions::default(), &|_, _| {});
    let stretched_bones = summary.bones.iter().filter(|b| b.stretched()).count();
    let stretched_samples: usize = summary.bones.iter().map(|b| b.flagged_samples).sum();
    let n = models.len();
    eprintln!(
        "{}: {} bones, clip {:.3} s, {} sample times, {n} bone-samples; {stretched_bones} bones / {:.1}% of bone-samples \
         flagged stretched; {:.1}% of bone-samples take the decompose shortcut",
        case.name,
        case.rig.skeleton.len(),
        case.rig.clips[0].span().length(),
        times.len(),
        percent(stretched_samples, n),
        percent(models.iter().filter(|m| shortcut_eligible(m)).count(), n),
    );
}

/// `parts`: also the sub-benchmarks that split the cost.
fn bench_case(c: &mut Criterion, case: &Case, parts: bool) {
    let evaluation = case.evaluation();
    let times = evaluation.times(RATE);
    let models = all_model_matrices(case, &times);
    describe(case, &times, &models);
    let locals: Vec<Vec<Transform>> = times
        .iter()
        .map(|&t| {
            let mut local = Vec::new();
            sample_clip(&case.rig.skeleton, &case.rig.clips[0], t, &mut local);
            local
        })
        .collect();
    let options = ScanOptions::default();
    let tolerances = Tolerances::default();
    let one_thread = rayon::ThreadPoolBuilder::new().num_threads(1).build().expect("a 1-thread pool");
    let (skeleton, clip, hierarchy) = (&case.rig.skeleton, case.rig.clips.first(), &case.hierarchy);

    let mut group = c.benchmark_group(format!("scan/{}", case.name));
    group.throughput(Throughput::Elements(models.len() as u64));
    group.bench_function("bare_pose_evaluate", |b| {
        let mut pose = Pose::default();
        b.iter(|| {
            for &t in &times {
                pose.evaluate(skeleton, clip, hierarchy, black_box(t));
                black_box(&pose.model.model);
            }
        })
    });
    group.bench_function("scan_1_thread", |b| {
        b.iter(|| one_thread.install(|| black_box(scan(&evaluation, &options, &|_, _| {}))))
    });
    group.bench_function("scan_parallel", |b| b.iter(|| black_box(scan(&evaluation, &options, &|_, _| {}))));
    if !parts {
        return group.finish();
    }
    // Where the time goes.
    // What `scan_1_thread` pays per call before any work: handing a closure to the 1-thread pool and back.
    group.bench_function("part_pool_install", |b| b.iter(|| one_thread.install(|| black_box(0))));
    group.bench_function("part_sample_times", |b| b.iter(|| black_box(black_box(&evaluation).times(RATE))));
    group.bench_function("part_sample_clip", |b| {
        let mut local = Vec::new();
        b.iter(|| {
            for &t in &times {
                sample_clip(skeleton, &case.rig.clips[0], black_box(t), &mut local);
                black_box(&local);
            }
        })
    });
    group.bench_function("part_hierarchy", |b| {
        let mut pose = Pose::default();
        b.iter(|| {
            for local in &locals {
                hierarchy.evaluate(black_box(local), &mut pose.model);
                black_box(&pose.model.model);
            }
        })
    });
    group.bench_function("part_decompose", |b| {
        b.iter(|| {
            for m in &models {
                black_box(decompose(black_box(m)));
            }
        })
    });
    group.bench_function("part_assess", |b| {
        b.iter(|| {
            for m in &models {
                black_box(Assessment::of(black_box(m), &tolerances));
            }
        })
    });
    group.finish();
}

fn benches(c: &mut Criterion) {
    bench_case(c, &generated_case(Squash::Limbs), true);
    bench_case(c, &generated_case(Squash::Spine), false);
    bench_case(c, &generated_case(Squash::None), false);
    bench_case(c, &compensating_case(), false);
    if let Some(case) = blender_case() {
        bench_case(c, &case, true);
    }
}

criterion_group! {
    name = scan_benches;
    config = Criterion::default().warm_up_time(Duration::from_secs(1)).measurement_time(Duration::from_secs(3));
    targets = benches
}
criterion_main!(scan_benches);
