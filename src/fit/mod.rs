//! Which scale inheritance a pose dump implements: the source evaluated under every mode choice (`declared` and the
//! nine modes), each compared with the dump bone by bone at every time it holds.
//!
//! Bones pair by name as in `diff` ([`match_bones`]); the source is measured in the dump's unit where both state
//! one. At each of the dump's times, for each pair, the distance between the source's model matrix `W` and the
//! dump's `D` is the largest of how far their origins lie apart and how far a point [`PROBE_FRACTION`] of the rig's
//! size out along each of the dump's axes lands apart (`|(W − D)·e_k| · ℓ / |D·e_k|`): unlike `diff`'s probes it
//! sees a scale too, which is what the modes differ by. A mode *fits* a bone when that distance stays within the
//! tolerance at every time: [`DEFAULT_TOLERANCE`] of the rig's size (the dump's, over its first, middle and last
//! times), or the caller's.
//!
//! A bone that every choice fits is `any` (nothing above it scales where the modes differ). The choices that fit
//! every bone are the dump's answer. Where none does, the first bone (parents first) that no choice fits, and the
//! first time its closest choice misses, are examined ([`Residual`]): the dump's local matrix there against the
//! source's own `T·R·S`, and its shear against the closest mode's.

use glam::{DMat3, DMat4, DVec3};

use crate::diff::{BoneMatching, Extreme, PROBE_FRACTION, match_bones};
use crate::eval::{Evaluation, HierarchyError, ModelPose, over_runs};
use crate::math::{affine_inverse, decompose, shear_deg};
use crate::model::{Choice, InheritMode, ModeChoice, Modes, Rig, Transform};

/// The tolerance, as a fraction of the rig's size, unless the caller gives one: 0.01 %, 0.17 mm on a 1.7 m
/// figure. Single-precision dumps of a few products are a hundred times closer; the modes, where they differ at all,
/// much further apart.
pub const DEFAULT_TOLERANCE: f64 = 1e-4;

/// Shear, in degrees, that counts as kept (or dropped) in a residual: well above single-precision rounding.
const SHEAR_DEG: f64 = 0.05;

/// How close, relative to its size, the dump's local matrix must be to a shape for the residual to have it.
const SHAPE_TOLERANCE: f64 = 1e-3;

/// What a fit found.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Fit {
    /// How many of the dump's times were compared.
    pub times: usize,
    /// The rig's size the tolerance is a fraction of (model units, the dump's).
    pub rig_size: f64,
    /// The largest distance a fitting mode may leave (model units).
    pub tolerance: f64,
    /// One per paired bone, in the source's bone order.
    pub bones: Vec<BoneFit>,
    /// The choices that fit every paired bone, in [`ModeChoice::ALL`]'s order.
    pub fits: Vec<ModeChoice>,
    /// Where no choice fits, the first bone and time, and what the dump does there.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub miss: Option<Miss>,
    /// Bones of either side without a partner, by name.
    pub only_source: Vec<String>,
    pub only_dump: Vec<String>,
}

/// One paired bone.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct BoneFit {
    pub name: String,
    /// Every choice fits: nothing above the bone scales where the modes differ.
    pub any: bool,
    /// The choices that fit it.
    pub fits: Vec<ModeChoice>,
    /// The choice closest to the dump, and its largest distance and when.
    pub closest: ModeChoice,
    pub distance: Extreme,
}

/// The first bone and time no choice fits.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Miss {
    pub bone: String,
    pub time: f64,
    /// The closest choice there, and its distance from the dump at that time.
    pub closest: ModeChoice,
    pub distance: f64,
    pub residual: Residual,
    /// The shear of the dump's matrix and of the closest choice's, degrees.
    pub dump_shear_deg: f64,
    pub closest_shear_deg: f64,
}

/// What the dump does where no mode fits, judged from its local matrix `L = D_parent⁻¹·D` against the source's own
/// local `T·R·S` and from its shear against the closest mode's.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Residual {
    /// `L ≈ T·R`, or the dump's matrix carries no scale where the closest mode's does: the runtime drops scale.
    ScaleDropped,
    /// `L ≈ T·S·R`: the bone's scale applied in its parent's axes, after the rotation.
    ScaleAfterRotation,
    /// The dump's matrix shears where the closest mode's does not.
    ShearKept,
    /// The closest mode's matrix shears where the dump's does not.
    ShearDropped,
    /// None of these.
    Other,
}

impl Residual {
    /// What it says for people.
    pub fn describe(self) -> &'static str {
        match self {
            Residual::ScaleDropped => "scale dropped: the dump's matrix carries no scale where the source's does",
            Residual::ScaleAfterRotation => "scale applied after the rotation (in the parent's axes: T·S·R)",
            Residual::ShearKept => "shear kept: the dump shears where the closest mode does not",
            Residual::ShearDropped => "shear dropped: the closest mode shears where the dump does not",
            Residual::Other => "none of scale dropped, scale after rotation, shear kept or dropped",
        }
    }
}

/// Why a fit cannot be made.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum FitError {
    #[error("no bone of the dump is named as a bone of the source (dump: {0})")]
    NoPairs(String),
    #[error("the dump holds no animation")]
    NoTimes,
    #[error(transparent)]
    Modes(#[from] HierarchyError),
}

/// One choice's source evaluation, or the earlier choice whose modes are the same (`declared` on a rig that declares
/// one mode throughout).
enum Candidate<'a> {
    Own(Box<Evaluation<'a>>),
    Same(usize),
}

/// A pair's distances under one choice over time.
#[derive(Clone, Copy, Debug)]
struct Tally {
    largest: Extreme,
    /// The first time the distance passed the tolerance.
    first_over: Option<f64>,
}

impl Tally {
    fn add(&mut self, distance: f64, time: f64, tolerance: f64) {
        self.largest.add(distance, time);
        if distance > tolerance && self.first_over.is_none() {
            self.first_over = Some(time);
        }
    }

    fn merge(self, later: Tally) -> Tally {
        Tally { largest: self.largest.merge(later.largest), first_over: self.first_over.or(later.first_over) }
    }
}

/// Fits `dump` to `source` (its clip, layers and unit as the caller chose; its modes replaced by each choice's),
/// within the distance `tolerance` gives for the rig's size (model units; [`DEFAULT_TOLERANCE`] of it, say).
pub fn fit(source: &Evaluation, dump: &Rig, tolerance: impl Fn(f64) -> f64) -> Result<Fit, FitError> {
    let dump_evaluation = Evaluation::declared(dump, dump.clips.first());
    let times = dump.clips.first().map(|clip| clip.key_times()).unwrap_or_default();
    if times.is_empty() {
        return Err(FitError::NoTimes);
    }
    let matching = match_bones(source.rig, dump);
    if matching.pairs.is_empty() {
        let names: Vec<&str> = dump.skeleton.bones().iter().take(5).map(|b| b.name.as_str()).collect();
        return Err(FitError::NoPairs(names.join(", ")));
    }
    let candidates = candidates(source, dump)?;
    let ends = [times[0], times[times.len() / 2], times[times.len() - 1]];
    let rig_size = dump_evaluation.size(&ends);
    let tolerance = tolerance(rig_size);
    let tallies = tally(&dump_evaluation, &candidates, &matching, &times, rig_size * PROBE_FRACTION, tolerance);
    let bones = bone_fits(source.rig, &matching, &candidates, &tallies, tolerance);
    let fits = (0..candidates.len()).filter(|&c| bones.iter().all(|b| b.fits.contains(&choice(c)))).map(choice);
    let fits: Vec<ModeChoice> = fits.collect();
    let miss = if fits.is_empty() {
        first_miss(&bones, &matching, &tallies, &candidates, &dump_evaluation, rig_size * PROBE_FRACTION)
    } else {
        None
    };
    let names = |rig: &Rig, bones: &[usize]| bones.iter().map(|&b| rig.skeleton.bone(b).name.clone()).collect();
    Ok(Fit {
        times: times.len(),
        rig_size,
        tolerance,
        bones,
        fits,
        miss,
        only_source: names(source.rig, &matching.only_a),
        only_dump: names(dump, &matching.only_b),
    })
}

/// The choice of candidate `c`: candidates follow [`ModeChoice::ALL`].
fn choice(c: usize) -> ModeChoice {
    ModeChoice::ALL[c]
}

/// The source under every choice, in the dump's unit; a choice that gives the same modes as an earlier one refers
/// to it.
fn candidates<'a>(source: &Evaluation<'a>, dump: &Rig) -> Result<Vec<Candidate<'a>>, FitError> {
    let resolved: Vec<Vec<InheritMode>> =
        ModeChoice::ALL.iter().map(|&c| Modes::all(c).resolve(&source.rig.skeleton)).collect();
    let mut candidates = Vec::with_capacity(resolved.len());
    for (c, modes) in resolved.iter().enumerate() {
        let candidate = match resolved[..c].iter().position(|earlier| earlier == modes) {
            Some(same) => Candidate::Same(same),
            None => Candidate::Own(Box::new(source.with_modes(modes)?.measured_in(dump.unit))),
        };
        candidates.push(candidate);
    }
    Ok(candidates)
}

/// Every pair's tally under every candidate of its own (`[candidate][pair]`; a [`Candidate::Same`]'s is empty), in
/// parallel over runs of time. The source is sampled once per time, by the first candidate (the layers are the
/// same for all), and its local pose combined under each candidate's modes.
fn tally(
    dump: &Evaluation,
    candidates: &[Candidate],
    matching: &BoneMatching,
    times: &[f64],
    probe: f64,
    tolerance: f64,
) -> Vec<Vec<Tally>> {
    let Some(Candidate::Own(first)) = candidates.first() else { return Vec::new() };
    let runs = over_runs(times, |run| {
        let fresh = Tally { largest: Extreme { max: 0.0, time: run[0] }, first_over: None };
        let pairs = |c: &Candidate| match c {
            Candidate::Own(_) => vec![fresh; matching.pairs.len()],
            Candidate::Same(_) => Vec::new(),
        };
        let mut tallies: Vec<Vec<Tally>> = candidates.iter().map(pairs).collect();
        let (mut dump_evaluator, mut sampler) = (dump.evaluator(), first.evaluator());
        let (mut other, mut reaches) = (ModelPose::default(), Vec::with_capacity(matching.pairs.len()));
        for &time in run {
            let dumped = &dump_evaluator.evaluate(time).model.model;
            reaches.clear();
            reaches.extend(matching.pairs.iter().map(|&(_, b)| reach(&dumped[b], probe)));
            sampler.evaluate(time);
            for (c, (candidate, tallies)) in candidates.iter().zip(&mut tallies).enumerate() {
                let Candidate::Own(evaluation) = candidate else { continue };
                let model = if c == 0 {
                    &sampler.pose.model
                } else {
                    sampler.model_under(&evaluation.hierarchy, &mut other);
                    &other
                };
                for ((tally, &(a, b)), &reach) in tallies.iter_mut().zip(&matching.pairs).zip(&reaches) {
                    tally.add(distance(&model.model[a], &dumped[b], reach), time, tolerance);
                }
            }
        }
        tallies
    });
    runs.into_iter()
        .reduce(|earlier, later| {
            let merge = |(e, l): (Vec<Tally>, Vec<Tally>)| e.into_iter().zip(l).map(|(e, l)| e.merge(l)).collect();
            earlier.into_iter().zip(later).map(merge).collect()
        })
        .unwrap_or_default()
}

/// How far a unit step along each of `d`'s axes must be taken to land `probe` out (`probe / |D·e_k|`; `probe` for
/// an axis of no length): the same for every mode compared with the dump's bone at one time.
fn reach(d: &DMat4, probe: f64) -> DVec3 {
    let length = |k: usize| d.col(k).truncate().length();
    DVec3::from_array([0, 1, 2].map(|k| if length(k) > 0.0 { probe / length(k) } else { probe }))
}

/// How far apart `w` (the source's) puts the dump's frame of `d`: the origins, and the point `reach` ([`reach`])
/// out along each of the dump's axes (scaled as `w` scales it, so that a scale difference shows).
fn distance(w: &DMat4, d: &DMat4, reach: DVec3) -> f64 {
    let origins = (w.w_axis - d.w_axis).truncate();
    let axis = |k: usize| (origins + (w.col(k) - d.col(k)).truncate() * reach[k]).length_squared();
    let largest = (0..3).map(axis).fold(origins.length_squared(), f64::max).sqrt();
    if largest.is_nan() { f64::INFINITY } else { largest }
}

/// Each pair's fitting choices and closest choice.
fn bone_fits(
    source: &Rig,
    matching: &BoneMatching,
    candidates: &[Candidate],
    tallies: &[Vec<Tally>],
    tolerance: f64,
) -> Vec<BoneFit> {
    let own = |c: usize| match candidates[c] {
        Candidate::Own(_) => c,
        Candidate::Same(same) => same,
    };
    matching
        .pairs
        .iter()
        .enumerate()
        .map(|(pair, &(a, _))| {
            let largest = |c: usize| tallies[own(c)][pair].largest;
            let fits: Vec<ModeChoice> =
                (0..candidates.len()).filter(|&c| largest(c).max <= tolerance).map(choice).collect();
            let closest = (0..candidates.len()).min_by(|&x, &y| largest(x).max.total_cmp(&largest(y).max)).unwrap_or(0);
            BoneFit {
                name: source.skeleton.bone(a).name.clone(),
                any: fits.len() == candidates.len(),
                fits,
                closest: choice(closest),
                distance: largest(closest),
            }
        })
        .collect()
}

/// The first bone no choice fits, at the first time its closest choice misses, and what the dump does there.
fn first_miss(
    bones: &[BoneFit],
    matching: &BoneMatching,
    tallies: &[Vec<Tally>],
    candidates: &[Candidate],
    dump: &Evaluation,
    probe: f64,
) -> Option<Miss> {
    let pair = bones.iter().position(|b| b.fits.is_empty())?;
    let bone = &bones[pair];
    let closest = ModeChoice::ALL.iter().position(|&c| c == bone.closest)?;
    let own = match candidates[closest] {
        Candidate::Own(_) => closest,
        Candidate::Same(same) => same,
    };
    let Candidate::Own(evaluation) = &candidates[own] else { return None };
    let time = tallies[own][pair].first_over.unwrap_or(bone.distance.time);
    let (a, b) = matching.pairs[pair];
    let (source_pose, dump_pose) = (evaluation.pose_at(time), dump.pose_at(time));
    let (w, d) = (source_pose.model.model[a], dump_pose.model.model[b]);
    let dump_parent = dump.skeleton().parent(b).map(|p| dump_pose.model.model[p]);
    let (dump_shear_deg, closest_shear_deg) = (shear_deg(&DMat3::from_mat4(d)), shear_deg(&DMat3::from_mat4(w)));
    let local = &source_pose.local[a];
    let residual = residual(&d, dump_parent.as_ref(), local, &w);
    Some(Miss {
        bone: bone.name.clone(),
        time,
        closest: bone.closest,
        distance: distance(&w, &d, reach(&d, probe)),
        residual,
        dump_shear_deg,
        closest_shear_deg,
    })
}

/// The shape of the dump's matrix `d` (under `parent`, the dump's parent matrix) against the source's local
/// transform `local` and the closest mode's matrix `w`.
fn residual(d: &DMat4, parent: Option<&DMat4>, local: &Transform, w: &DMat4) -> Residual {
    let dump_local = parent.and_then(affine_inverse).map(|inverse| DMat3::from_mat4(inverse * *d));
    let rotation = DMat3::from_quat(local.rotation);
    let scale = local.scale_matrix();
    let near = |m: &DMat3, shape: DMat3| {
        let size = m.to_cols_array().iter().fold(0.0f64, |s, v| s.max(v.abs())).max(f64::MIN_POSITIVE);
        (*m - shape).to_cols_array().iter().all(|v| v.abs() <= SHAPE_TOLERANCE * size)
    };
    let scaled = !scale.abs_diff_eq(DMat3::IDENTITY, SHAPE_TOLERANCE);
    let (dump_parts, closest_parts) = (decompose(d), decompose(w));
    let unscaled = |s: DVec3| s.abs_diff_eq(DVec3::ONE, SHAPE_TOLERANCE);
    let dump_shear = shear_deg(&DMat3::from_mat4(*d));
    let closest_shear = shear_deg(&DMat3::from_mat4(*w));
    match dump_local {
        Some(l) if scaled && near(&l, scale * rotation) && !near(&l, rotation * scale) => Residual::ScaleAfterRotation,
        Some(l) if scaled && near(&l, rotation) => Residual::ScaleDropped,
        _ if unscaled(dump_parts.scale) && !unscaled(closest_parts.scale) => Residual::ScaleDropped,
        _ if dump_shear > SHEAR_DEG && closest_shear <= SHEAR_DEG => Residual::ShearKept,
        _ if closest_shear > SHEAR_DEG && dump_shear <= SHEAR_DEG => Residual::ShearDropped,
        _ => Residual::Other,
    }
}
