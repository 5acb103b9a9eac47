//! Stretch-quaternion storage (`docs/decomposition.md`) measured on a clip: which bones need the stretch channel, what
//! it costs in bytes, and how far from the evaluated pose a runtime lands with it and without it.
//!
//! **What is stored.** At every frame each bone stores its local components as decomp_affine finds them in the
//! matrix its DCC would export, `L = W_parent⁻¹ · W` from the evaluated model matrices (simply the bone's local
//! transform when it inherits scale fully and has no stretch rotation, since then `W = W_parent · L` exactly). A
//! bone is **marked** when that `L` is stretched at some frame (its stretch rotation `U` is not the identity, with
//! the scan's tolerances). Components are rounded to `f32`, as stored.
//!
//! **What the runtime rebuilds.** `L' = T·R·U·K·Uᵀ` for marked bones (in row-vector order: inverse stretch, scale,
//! stretch, rotation, position) and `T·R·K` for the others, chained as `W' = W'_parent · L'` (every child inherits
//! its parent's scale, as when no bone is flagged "don't inherit scale"). A TRS-only runtime drops `U` everywhere:
//! `T·R·K` for every bone.
//!
//! **Byte model.** Every bone stores every frame in `f32`: translation 3 + rotation 4 + scale 3 components = 40
//! bytes a key; a marked bone adds its stretch quaternion, 4 components = 16 bytes a key. No compression, no
//! headers.
//!
//! **Errors.** Distances in model units between where the evaluated and the rebuilt model matrices put probe
//! points: each bone's origin and the points `probe_distance` local units along its X, Y and Z axes, and every
//! vertex of every mesh skinned with both. Max and mean over all frames. Non-finite distances (a degenerate matrix)
//! are left out.

use glam::{DMat4, DQuat, DVec3};
use serde::Serialize;

use super::{Assessment, Tolerances};
use crate::eval::skinning::skin_positions;
use crate::eval::{Evaluation, Evaluator, over_runs};
use crate::model::{InheritMode, Rig, Transform};

/// `f32` components of one key: translation 3 + rotation 4 + scale 3.
pub const TRS_KEY_BYTES: u64 = 40;
/// The stretch quaternion of a marked bone's key: 4 `f32` components.
pub const STRETCH_KEY_BYTES: u64 = 16;

/// How a clip is measured.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StorageOptions {
    /// Frames per second on top of every key time (what `scan` samples; 0 for the key times alone).
    pub rate: f64,
    /// When a bone counts as stretched.
    pub tolerances: Tolerances,
    /// How far along each bone axis the probe points lie, in the bone's local units.
    pub probe_distance: f64,
}

impl Default for StorageOptions {
    fn default() -> Self {
        StorageOptions { rate: 60.0, tolerances: Tolerances::default(), probe_distance: 1.0 }
    }
}

/// The largest and the mean distance, in model units.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct ErrorStats {
    pub max: f64,
    pub mean: f64,
}

/// How far one runtime's matrices are from the evaluated ones.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct RuntimeError {
    /// At each bone's origin and along its axes.
    pub bone_axes: ErrorStats,
    /// At the skinned vertices; `None` for a rig without meshes.
    pub vertices: Option<ErrorStats>,
}

/// A bone that needs the stretch channel.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MarkedBone {
    pub index: usize,
    pub name: String,
    /// Frames at which its stored local matrix is stretched.
    pub stretched_frames: usize,
}

/// The storage report of one clip.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct StorageReport {
    pub frames: usize,
    pub bones: usize,
    pub marked: Vec<MarkedBone>,
    /// Every bone as plain TRS.
    pub bytes_trs: u64,
    /// With the stretch channel of the marked bones.
    pub bytes_with_stretch: u64,
    pub probe_distance: f64,
    /// The stretch-quaternion format, rebuilt.
    pub reconstruction: RuntimeError,
    /// A runtime that drops the stretch.
    pub trs_only: RuntimeError,
}

/// Measures the stretch-quaternion storage of `evaluation` over its whole clip.
pub fn storage_report(evaluation: &Evaluation, options: &StorageOptions) -> StorageReport {
    let rig = evaluation.rig;
    let bones = rig.skeleton.len();
    let times = evaluation.times(options.rate);
    let runtime = || Runtime::new(evaluation, options);
    let counts = over_runs(&times, |run| runtime().count_stretched(run));
    let stretched_frames =
        counts.into_iter().fold(vec![0; bones], |a, b| a.iter().zip(&b).map(|(x, y)| x + y).collect());
    let marks: Vec<bool> = stretched_frames.iter().map(|&n| n > 0).collect();
    let errors = over_runs(&times, |run| runtime().measure(run, &marks));
    let errors = errors.iter().fold(Errors::default(), |a, b| a.merge(b));
    let marked: Vec<MarkedBone> = stretched_frames
        .iter()
        .enumerate()
        .filter(|(_, n)| **n > 0)
        .map(|(index, &n)| MarkedBone { index, name: rig.skeleton.bone(index).name.clone(), stretched_frames: n })
        .collect();
    let keys = (times.len() * bones) as u64;
    let stretch_keys = (times.len() * marked.len()) as u64;
    let with_vertices = !rig.meshes.is_empty();
    StorageReport {
        frames: times.len(),
        bones,
        bytes_trs: keys * TRS_KEY_BYTES,
        bytes_with_stretch: keys * TRS_KEY_BYTES + stretch_keys * STRETCH_KEY_BYTES,
        marked,
        probe_distance: options.probe_distance,
        reconstruction: errors.seed.report(with_vertices),
        trs_only: errors.trs.report(with_vertices),
    }
}

/// One worker: the evaluated pose and the two rebuilt ones, with their buffers.
struct Runtime<'e, 'a> {
    rig: &'a Rig,
    evaluator: Evaluator<'e, 'a>,
    options: &'e StorageOptions,
    seed: Vec<DMat4>,
    trs: Vec<DMat4>,
    vertices: [Vec<DVec3>; 3],
}

impl<'e, 'a> Runtime<'e, 'a> {
    fn new(evaluation: &'e Evaluation<'a>, options: &'e StorageOptions) -> Self {
        Runtime {
            rig: evaluation.rig,
            evaluator: evaluation.evaluator(),
            options,
            seed: Vec::new(),
            trs: Vec::new(),
            vertices: Default::default(),
        }
    }

    fn evaluate(&mut self, time: f64) {
        self.evaluator.evaluate(time);
    }

    /// The local transform stored for `bone` at the evaluated pose, and whether it is stretched.
    fn stored(&self, bone: usize) -> (Transform, bool) {
        let pose = &self.evaluator.pose;
        let local = &pose.local[bone];
        let parent = self.rig.skeleton.parent(bone);
        let model = &pose.model.model;
        if local.is_trs() && (parent.is_none() || self.evaluator.evaluation().modes()[bone] == InheritMode::Full) {
            return (*local, false);
        }
        let exported = parent.map_or(model[bone], |p| model[p].inverse() * model[bone]);
        let assessment = Assessment::of(&exported, &self.options.tolerances);
        (assessment.parts.transform(), assessment.findings.stretched)
    }

    /// Per bone, at how many of `times` its stored local matrix is stretched.
    fn count_stretched(mut self, times: &[f64]) -> Vec<usize> {
        let mut counts = vec![0; self.rig.skeleton.len()];
        for &time in times {
            self.evaluate(time);
            for (bone, count) in counts.iter_mut().enumerate() {
                *count += usize::from(self.stored(bone).1);
            }
        }
        counts
    }

    /// The errors of both runtimes over `times`, `marks` saying which bones keep their stretch.
    fn measure(mut self, times: &[f64], marks: &[bool]) -> Errors {
        let mut errors = Errors::default();
        let d = self.options.probe_distance;
        let probes = [DVec3::ZERO, DVec3::X * d, DVec3::Y * d, DVec3::Z * d];
        for &time in times {
            self.evaluate(time);
            self.rebuild(marks);
            for ((evaluated, seed), trs) in self.evaluator.pose.model.model.iter().zip(&self.seed).zip(&self.trs) {
                for probe in probes {
                    let at = evaluated.transform_point3(probe);
                    errors.seed.bone_axes.add(seed.transform_point3(probe).distance(at));
                    errors.trs.bone_axes.add(trs.transform_point3(probe).distance(at));
                }
            }
            self.measure_vertices(&mut errors);
        }
        errors
    }

    /// Both runtimes' model matrices from the stored (rounded) components.
    fn rebuild(&mut self, marks: &[bool]) {
        let bones = self.rig.skeleton.len();
        self.seed.resize(bones, DMat4::IDENTITY);
        self.trs.resize(bones, DMat4::IDENTITY);
        for (bone, &marked) in marks.iter().enumerate().take(bones) {
            let stored = rounded(&self.stored(bone).0);
            let trs_local = Transform { stretch: DQuat::IDENTITY, ..stored }.matrix();
            let seed_local = if marked { stored.matrix() } else { trs_local };
            let parent = self.rig.skeleton.parent(bone);
            self.seed[bone] = parent.map_or(seed_local, |p| self.seed[p] * seed_local);
            self.trs[bone] = parent.map_or(trs_local, |p| self.trs[p] * trs_local);
        }
    }

    fn measure_vertices(&mut self, errors: &mut Errors) {
        let [evaluated, seed, trs] = &mut self.vertices;
        let pose = &self.evaluator.pose;
        for mesh in &self.rig.meshes {
            skin_positions(mesh, &self.rig.skins, &pose.model.model, &pose.morph, evaluated);
            skin_positions(mesh, &self.rig.skins, &self.seed, &pose.morph, seed);
            skin_positions(mesh, &self.rig.skins, &self.trs, &pose.morph, trs);
            for ((at, s), t) in evaluated.iter().zip(seed.iter()).zip(trs.iter()) {
                errors.seed.vertices.add(s.distance(*at));
                errors.trs.vertices.add(t.distance(*at));
            }
        }
    }
}

/// A transform as stored in `f32` (an identity stretch stays exactly the identity).
fn rounded(t: &Transform) -> Transform {
    let round = |v: DVec3| v.as_vec3().as_dvec3();
    Transform {
        translation: round(t.translation),
        rotation: t.rotation.as_quat().as_dquat(),
        scale: round(t.scale),
        stretch: t.stretch.as_quat().as_dquat(),
    }
}

/// Max, sum and count of distances.
#[derive(Clone, Copy, Debug, Default)]
struct Spread {
    max: f64,
    sum: f64,
    count: u64,
}

impl Spread {
    fn add(&mut self, distance: f64) {
        if distance.is_finite() {
            self.max = self.max.max(distance);
            self.sum += distance;
            self.count += 1;
        }
    }

    fn merge(&self, other: &Spread) -> Spread {
        Spread { max: self.max.max(other.max), sum: self.sum + other.sum, count: self.count + other.count }
    }

    fn stats(&self) -> ErrorStats {
        let mean = if self.count > 0 { self.sum / self.count as f64 } else { 0.0 };
        ErrorStats { max: self.max, mean }
    }
}

#[derive(Clone, Copy, Debug, Default)]
struct Spreads {
    bone_axes: Spread,
    vertices: Spread,
}

impl Spreads {
    fn merge(&self, other: &Spreads) -> Spreads {
        Spreads { bone_axes: self.bone_axes.merge(&other.bone_axes), vertices: self.vertices.merge(&other.vertices) }
    }

    fn report(&self, with_vertices: bool) -> RuntimeError {
        RuntimeError { bone_axes: self.bone_axes.stats(), vertices: with_vertices.then(|| self.vertices.stats()) }
    }
}

#[derive(Clone, Copy, Debug, Default)]
struct Errors {
    seed: Spreads,
    trs: Spreads,
}

impl Errors {
    fn merge(&self, other: &Errors) -> Errors {
        Errors { seed: self.seed.merge(&other.seed), trs: self.trs.merge(&other.trs) }
    }
}
