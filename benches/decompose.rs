//! Per-matrix cost and accuracy of `bonescope::math::decompose` (one call per matrix) and `decompose_all` (a whole
//! set at once) beside nalgebra's SVD-based polar decomposition.
//!
//! Three sets of 1024 matrices, all from one fixed seed:
//! - `shear_free`: `T·R·diag(s)` with scale factors in [0.25, 4] (the common case; `decompose` takes its shortcut);
//! - `sheared`: `T·R·U·K·Uᵀ` with random `R`, `U` and factors in [0.25, 4] (shear from non-uniform scale under a
//!   rotated child, the case the tool exists for);
//! - `sheared_extreme`: as `sheared`, the largest/smallest factor ratio 10^e with e uniform in [0, 6] and an overall
//!   magnitude in [1e-2, 1e2].
//!
//! And the matrices an animation really gives: every model matrix of a clip at every 30 Hz sample time, for the
//! generated `stress_rig` (a non-uniformly scaled bone in each chain of ten, the bones below it sheared) and for
//! Blender's `stretchy_full.glb` from `../shared/assets` (skipped when missing).
//!
//! nalgebra gets the same matrices, already converted to `Matrix3<f64>` outside the timed loop. Accuracy, and the
//! fastest of many interleaved passes on the sheared sets, are measured once in the setup and printed to stderr (see
//! `BENCHMARKS.md`).

// The repeated mocap walk is for the benchmarks of long clips.
#[allow(dead_code)]
#[path = "support/shared_assets.rs"]
mod shared_assets;

use std::f64::consts::TAU;
use std::hint::black_box;
use std::time::{Duration, Instant};

use bonescope::eval::Evaluation;
use bonescope::import::stress_rig;
use bonescope::math::{AffineParts, decompose, decompose_all, decompose_near};
use bonescope::model::Rig;
use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use glam::{DMat3, DMat4, DQuat, DVec3};
use nalgebra::Matrix3;
use rand::{RngExt, SeedableRng};
use rand_xorshift::XorShiftRng;

const BATCH: usize = 1024;
const SEED: u64 = 0x5EED_B0E5_C0DE_2026;

/// Uniform on the rotation group (Shoemake's subgroup algorithm).
fn random_rotation(rng: &mut XorShiftRng) -> DQuat {
    let (u1, u2, u3) = (rng.random::<f64>(), rng.random_range(0.0..TAU), rng.random_range(0.0..TAU));
    let (a, b) = ((1.0 - u1).sqrt(), u1.sqrt());
    DQuat::from_xyzw(a * u2.sin(), a * u2.cos(), b * u3.sin(), b * u3.cos()).normalize()
}

/// Each component uniform in [lo, hi).
fn random_vec3(rng: &mut XorShiftRng, lo: f64, hi: f64) -> DVec3 {
    DVec3::new(rng.random_range(lo..hi), rng.random_range(lo..hi), rng.random_range(lo..hi))
}

/// `T·R·U·K·Uᵀ`.
fn sheared_matrix(rng: &mut XorShiftRng, k: DVec3) -> DMat4 {
    let (r, u) = (DMat3::from_quat(random_rotation(rng)), DMat3::from_quat(random_rotation(rng)));
    let m = r * u * DMat3::from_diagonal(k) * u.transpose();
    let t = random_vec3(rng, -1.0, 1.0);
    DMat4::from_cols(m.x_axis.extend(0.0), m.y_axis.extend(0.0), m.z_axis.extend(0.0), t.extend(1.0))
}

fn shear_free_set(rng: &mut XorShiftRng) -> Vec<DMat4> {
    (0..BATCH)
        .map(|_| {
            let s = random_vec3(rng, 0.25, 4.0);
            DMat4::from_scale_rotation_translation(s, random_rotation(rng), random_vec3(rng, -1.0, 1.0))
        })
        .collect()
}

fn sheared_set(rng: &mut XorShiftRng) -> Vec<DMat4> {
    (0..BATCH)
        .map(|_| {
            let k = random_vec3(rng, 0.25, 4.0);
            sheared_matrix(rng, k)
        })
        .collect()
}

/// Factors `c·[1, ratio^-a, ratio^-1]` in a random order (the order is irrelevant under a random `U`).
fn factors_with_ratio(rng: &mut XorShiftRng, ratio: f64) -> DVec3 {
    let c = 10f64.powf(rng.random_range(-2.0..2.0));
    c * DVec3::new(1.0, ratio.powf(-rng.random::<f64>()), 1.0 / ratio)
}

fn extreme_set(rng: &mut XorShiftRng) -> Vec<DMat4> {
    (0..BATCH)
        .map(|_| {
            let ratio = 10f64.powf(rng.random_range(0.0..6.0));
            let k = factors_with_ratio(rng, ratio);
            sheared_matrix(rng, k)
        })
        .collect()
}

fn to_nalgebra(m: &DMat4) -> Matrix3<f64> {
    Matrix3::from_column_slice(&DMat3::from_mat4(*m).to_cols_array())
}

fn from_nalgebra(m: &Matrix3<f64>) -> DMat3 {
    DMat3::from_cols_slice(m.as_slice())
}

fn frobenius(m: &DMat3) -> f64 {
    (m.x_axis.length_squared() + m.y_axis.length_squared() + m.z_axis.length_squared()).sqrt()
}

/// The worst errors over a set of matrices.
#[derive(Default)]
struct Errors {
    /// `‖A − recomposed‖_F / ‖A‖_F`.
    recompose: f64,
    /// `‖QᵀQ − I‖_F` of the orthogonal factor.
    orthogonality: f64,
    /// `|k_min − k_min,true| / k_min,true`: the smallest stretch factor against the one the matrix was built from.
    smallest_factor: f64,
    /// Matrices whose recomposition error exceeds 1e-12.
    bad: usize,
}

impl Errors {
    fn add(&mut self, a: &DMat3, recomposed: &DMat3, q: &DMat3, smallest: f64, smallest_true: f64) {
        let recompose = frobenius(&(*a - *recomposed)) / frobenius(a);
        self.recompose = self.recompose.max(recompose);
        self.orthogonality = self.orthogonality.max(frobenius(&(q.transpose() * *q - DMat3::IDENTITY)));
        self.smallest_factor = self.smallest_factor.max((smallest - smallest_true).abs() / smallest_true);
        self.bad += usize::from(recompose > 1e-12 || recompose.is_nan());
    }
}

fn ours(m: &DMat4) -> (DMat3, DMat3, f64) {
    ours_from(m, &decompose(m))
}

/// The recomposed matrix, the orthogonal factor and the smallest factor of `parts`.
fn ours_from(m: &DMat4, parts: &AffineParts) -> (DMat3, DMat3, f64) {
    assert_eq!(parts.translation, m.w_axis.truncate());
    let q = DMat3::from_quat(parts.rotation) * parts.sign;
    (DMat3::from_mat4(parts.matrix()), q, parts.scale.min_element())
}

/// nalgebra's `polar()` is the left form `A = P·U` with `P = U_svd·Σ·U_svdᵀ` and `U = U_svd·V_svdᵀ`.
fn theirs(m: &DMat4) -> (DMat3, DMat3, f64) {
    let a = to_nalgebra(m);
    let (p, u) = a.polar();
    let smallest = a.singular_values().min();
    (from_nalgebra(&(p * u)), from_nalgebra(&u), smallest)
}

/// Accuracy of ours (one matrix at a time and all at once) and nalgebra's on matrices of one largest/smallest
/// ratio, printed as one table row.
fn accuracy_row(label: &str, set: &[(DMat4, f64)]) {
    let (mut one, mut all, mut theirs_errors) = (Errors::default(), Errors::default(), Errors::default());
    let matrices: Vec<DMat4> = set.iter().map(|(m, _)| *m).collect();
    for ((m, smallest_true), parts) in set.iter().zip(decompose_all(&matrices)) {
        let m3 = DMat3::from_mat4(*m);
        let (r, q, s) = ours(m);
        one.add(&m3, &r, &q, s, *smallest_true);
        let (r, q, s) = ours_from(m, &parts);
        all.add(&m3, &r, &q, s, *smallest_true);
        let (r, q, s) = theirs(m);
        theirs_errors.add(&m3, &r, &q, s, *smallest_true);
    }
    let columns = |e: &Errors| {
        format!("{:>9.2e} {:>9.2e} {:>9.2e} {:>4}", e.recompose, e.orthogonality, e.smallest_factor, e.bad)
    };
    eprintln!("{label:<22} | {} | {} | {}", columns(&one), columns(&all), columns(&theirs_errors));
}

fn print_accuracy() {
    let mut rng = XorShiftRng::seed_from_u64(SEED ^ 0xACC);
    eprintln!("accuracy over {BATCH} matrices per row (worst case; `bad` = recomposition error > 1e-12)");
    let header = format!("{:>9} {:>9} {:>9} {:>4}", "recompose", "orthog", "k_min", "bad");
    eprintln!("{:<22} | {header} | {header} | {header}", "set");
    eprintln!(
        "{:<22} | {:<34} | {:<34} | {:<34}",
        "", "bonescope decompose", "bonescope decompose_all", "nalgebra polar (SVD)"
    );
    let shear_free: Vec<(DMat4, f64)> = (0..BATCH)
        .map(|_| {
            let s = random_vec3(&mut rng, 0.25, 4.0);
            (
                DMat4::from_scale_rotation_translation(s, random_rotation(&mut rng), random_vec3(&mut rng, -1.0, 1.0)),
                s.min_element(),
            )
        })
        .collect();
    accuracy_row("shear-free", &shear_free);
    let sheared: Vec<(DMat4, f64)> = (0..BATCH)
        .map(|_| {
            let k = random_vec3(&mut rng, 0.25, 4.0);
            (sheared_matrix(&mut rng, k), k.min_element())
        })
        .collect();
    accuracy_row("sheared, ratio <= 16", &sheared);
    for decade in 1..=6 {
        let ratio = 10f64.powi(decade);
        let set: Vec<(DMat4, f64)> = (0..BATCH)
            .map(|_| {
                let k = factors_with_ratio(&mut rng, ratio);
                (sheared_matrix(&mut rng, k), k.min_element())
            })
            .collect();
        accuracy_row(&format!("sheared, ratio 1e{decade}"), &set);
    }
    let mirrored: Vec<(DMat4, f64)> = (0..BATCH)
        .map(|_| {
            let k = random_vec3(&mut rng, 0.25, 4.0);
            (sheared_matrix(&mut rng, k) * DMat4::from_scale(DVec3::new(1.0, 1.0, -1.0)), k.min_element())
        })
        .collect();
    accuracy_row("sheared, mirrored", &mirrored);
}

/// One `decompose` call per matrix.
fn one_call_each(set: &[DMat4]) {
    for m in set {
        black_box(decompose(black_box(m)));
    }
}

/// The whole set in one `decompose_all`.
fn all_at_once(set: &[DMat4]) {
    black_box(decompose_all(black_box(set)));
}

fn nalgebra_each(set: &[Matrix3<f64>]) {
    for m in set {
        black_box(black_box(*m).polar());
    }
}

fn bench_set(c: &mut Criterion, name: &str, set: &[DMat4]) {
    let converted: Vec<Matrix3<f64>> = set.iter().map(to_nalgebra).collect();
    let mut group = c.benchmark_group(name);
    group.throughput(Throughput::Elements(set.len() as u64));
    group.bench_function("bonescope", |b| b.iter(|| one_call_each(set)));
    group.bench_function("bonescope_all", |b| b.iter(|| all_at_once(set)));
    group.bench_function("nalgebra_polar", |b| b.iter(|| nalgebra_each(&converted)));
    group.finish();
}

/// Interleaved passes for [`print_fastest_passes`].
const PASSES: usize = 300;

/// The fastest of [`PASSES`] interleaved passes of the three over `set`, per matrix, and the ratios: what each costs
/// undisturbed. On a machine shared with other work criterion's estimates drift by 10–20 % between runs, and ours
/// and nalgebra's not together; the fastest pass is steadier (see `BENCHMARKS.md` §1).
fn print_fastest_passes(name: &str, set: &[DMat4]) {
    let converted: Vec<Matrix3<f64>> = set.iter().map(to_nalgebra).collect();
    let timed = |work: &dyn Fn()| {
        let start = Instant::now();
        work();
        start.elapsed().as_secs_f64()
    };
    let mut fastest = [f64::INFINITY; 3];
    for _ in 0..PASSES {
        let passes = [timed(&|| one_call_each(set)), timed(&|| all_at_once(set)), timed(&|| nalgebra_each(&converted))];
        fastest = std::array::from_fn(|i| fastest[i].min(passes[i]));
    }
    let [one, all, theirs] = fastest.map(|seconds| seconds * 1e9 / set.len() as f64);
    eprintln!(
        "{name}: fastest of {PASSES} interleaved passes, per matrix: decompose {one:.0} ns, decompose_all {all:.0} ns, \
         nalgebra {theirs:.0} ns: {:.2}x / {:.2}x",
        theirs / one,
        theirs / all
    );
}

/// Every model matrix of the rig's first clip at every 30 Hz sample time (with the key times).
fn clip_set(rig: &Rig) -> Vec<DMat4> {
    let evaluation = Evaluation::declared(rig, rig.clips.first());
    let mut evaluator = evaluation.evaluator();
    let mut set = Vec::new();
    for time in evaluation.times(30.0) {
        set.extend_from_slice(&evaluator.evaluate(time).model.model);
    }
    set
}

/// One sheared bone over consecutive frames: a rotation and a parent's squash-and-stretch that change a little each
/// frame, as a whole-clip scan meets them.
fn animated_set() -> Vec<DMat4> {
    (0..1000)
        .map(|frame| {
            let t = f64::from(frame) / 30.0;
            let squash = 1.0 + 0.4 * (t * 2.0).sin();
            let parent = DMat4::from_quat(DQuat::from_rotation_z(0.3 * t.sin()))
                * DMat4::from_scale(DVec3::new(squash, 1.0 / squash, 1.0));
            parent * DMat4::from_quat(DQuat::from_euler(glam::EulerRot::XYZ, 0.3 * t.cos(), 0.5, 0.2 + 0.1 * t))
        })
        .collect()
}

/// The same sequence decomposed cold, and warm: each search starting from the previous frame's stretch frame.
fn bench_sequence(c: &mut Criterion, set: &[DMat4]) {
    let mut group = c.benchmark_group("decompose/sheared_sequence");
    group.throughput(Throughput::Elements(set.len() as u64));
    group.bench_function("cold", |b| {
        b.iter(|| {
            for m in set {
                black_box(decompose(black_box(m)));
            }
        })
    });
    group.bench_function("warm (previous frame's stretch)", |b| {
        b.iter(|| {
            let mut previous = DQuat::IDENTITY;
            for m in set {
                previous = black_box(decompose_near(black_box(m), previous)).stretch;
            }
        })
    });
    group.finish();
}

fn benches(c: &mut Criterion) {
    print_accuracy();
    let mut rng = XorShiftRng::seed_from_u64(SEED);
    let shear_free = shear_free_set(&mut rng);
    let sheared = sheared_set(&mut rng);
    let extreme = extreme_set(&mut rng);
    // The sets must exercise the paths they are named after.
    assert!(shear_free.iter().all(|m| decompose(m).stretch == DQuat::IDENTITY), "shear-free set took the full path");
    assert!(sheared.iter().all(|m| decompose(m).stretch != DQuat::IDENTITY), "sheared set took the shortcut");
    print_fastest_passes("sheared", &sheared);
    print_fastest_passes("sheared_extreme", &extreme);
    bench_set(c, "decompose/shear_free", &shear_free);
    bench_set(c, "decompose/sheared", &sheared);
    bench_set(c, "decompose/sheared_extreme", &extreme);
    bench_sequence(c, &animated_set());
    bench_set(c, "decompose/clip_stress_rig", &clip_set(&stress_rig(50, 200, 5)));
    let stretchy = shared_assets::asset("blender/stretchy_full.glb");
    match bonescope::import::load(&stretchy) {
        Ok(rig) => bench_set(c, "decompose/clip_stretchy_full", &clip_set(&rig)),
        Err(e) => eprintln!("skipping decompose/clip_stretchy_full: {e}"),
    }
}

criterion_group! {
    name = decompose_benches;
    config = Criterion::default().warm_up_time(Duration::from_secs(1)).measurement_time(Duration::from_secs(3));
    targets = benches
}
criterion_main!(decompose_benches);
