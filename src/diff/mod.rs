//! Two evaluations compared over time, bone by bone and vertex by vertex: two files (an export and its source, a
//! bake and what it baked), or one file under two sets of modes.
//!
//! Bones are paired by name ([`match_bones`]), conversion nodes left out; at every time both poses are evaluated, in
//! one unit (B's lengths measured in A's: [`Evaluation::measured_in`]), and each pair's model matrices `W_a`, `W_b`
//! are compared through their polar decompositions:
//! - **position**: the distance between the two origins;
//! - **probe**: the largest distance of a point of the bone's frame — its origin and one point on each of its axes,
//!   [`PROBE_FRACTION`] of the rig's size from the origin — between where A and B put it, each in its own pose
//!   (rotation and shear errors show here, in model units; a scale in the scale ratio and the skin);
//! - **orientation**: the angle between the two polar rotations `R`;
//! - **scale**: the largest ratio between corresponding stretch factors `K` (sorted, so the frame does not matter);
//! - **stretch**: the angle between the two stretch frames `U`, ignoring turns that leave `U·K·Uᵀ` the same.
//!
//! Two files need not give a bone the same frame: exporters choose their own axes for a node (Blender's FBX turns
//! every object a quarter about X, its glTF export does not), and BVH gives its joints none. Where the pairs are
//! compared [`Frames::UpToConvention`], the constant turn between each pair's frames is found at the first time
//! compared (`M = R_b⁻¹·R_a` of the two polar rotations there), reported once ([`Convention`]), and B's matrix is
//! read in A's frame (`W_b·M`) from then on, A's in B's (`W_a·M⁻¹`) for the probe points seen from B: the probes,
//! orientations and stretches measure what moves, and the origins, scales and the skin are as they are. Either
//! file may be A: the turn found the other way is `M⁻¹`.
//!
//! Meshes are paired by name and vertex count; each pair is skinned on both sides and the vertex distances kept
//! (largest, and mean over every vertex and time). Every largest value comes with the first time it happens.
//!
//! Two files or two sets of modes compare the same whichever is A: the rig's size is the larger of the two sides'
//! and each side's probe points lie along its own axes, so a tolerance passes or fails whatever the argument order.

mod matching;
mod report;

pub use matching::{
    BoneMatching, HELPER_SUFFIX, helpers, loose_name, match_bones, match_bones_mapped, match_clips, match_meshes,
    standing, standing_apart, usd_identifier,
};
pub use report::{Align, AnimationDiff, Clips, FileDiff, FileSide, MissingClip, chosen_clips, diff_files};

use std::sync::atomic::{AtomicBool, Ordering};

use glam::{DMat4, DQuat, DVec3};

use crate::analysis::{Components, Tolerances};
use crate::eval::skinning::Skinner;
use crate::eval::{Beside, BonesEvaluator, Evaluation, ModelPose, Pose, Reach, Reference, Variant, over_runs};
use crate::math::{AffineParts, angle_between, decompose, decompose_all};
use crate::model::{MAX_FRAMES, Rig, sample_times};

/// How many times a second two evaluations are compared between their keys, unless a user says otherwise.
pub const DEFAULT_RATE: f64 = 60.0;

/// How far along each axis the probe points lie, as a fraction of the rig's size.
pub const PROBE_FRACTION: f64 = 0.1;

/// The largest value of a quantity over time, and the first time it happens.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct Extreme {
    pub max: f64,
    pub time: f64,
}

impl Extreme {
    /// Starting from `floor` (no difference) at `time`, the first time compared.
    fn from(floor: f64, time: f64) -> Self {
        Extreme { max: floor, time }
    }

    pub(crate) fn add(&mut self, value: f64, time: f64) {
        // NaN (a degenerate matrix) counts as the largest difference there is.
        if value > self.max || (value.is_nan() && !self.max.is_nan()) {
            *self = Extreme { max: value, time };
        }
    }

    /// Combines an earlier stretch of time with a later one (ties keep the earlier time).
    pub fn merge(mut self, later: Extreme) -> Self {
        self.add(later.max, later.time);
        self
    }
}

/// One pair of bones over the compared times.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct BoneDifference {
    /// The bone in A and in B.
    pub a: usize,
    pub b: usize,
    pub name: String,
    /// B's name where it differs from A's.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub name_b: Option<String>,
    /// Distance between the origins, model units.
    pub position: Extreme,
    /// Largest distance between the origins and the probe points on the axes, model units.
    pub probe: Extreme,
    /// Angle between the polar rotations, degrees.
    pub orientation_deg: Extreme,
    /// Largest ratio between corresponding stretch factors (1: equal).
    pub scale_ratio: Extreme,
    /// Angle between the stretch frames, degrees.
    pub stretch_deg: Extreme,
    /// How B's frame differs from A's at the first time compared, taken out of everything above but the position,
    /// where the pairs are compared up to conventions and it differs.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub convention: Option<Convention>,
}

/// The constant turn between a pair's frames: B's axes against A's at the first time compared (two exporters' axis
/// conventions, a joint that BVH gives no orientation).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Convention {
    /// The turn's angle, degrees, and its axis in B's frame.
    pub turn_deg: f64,
    pub axis: DVec3,
}

impl Convention {
    /// B's frame against A's, from the `map` that reads B's in A's ([`FrameMaps`]: B's is A's turned by its
    /// inverse), where they differ by more than rounding.
    fn of(map: DQuat) -> Option<Self> {
        let (axis, angle) = map.inverse().to_axis_angle();
        let turn_deg = angle.to_degrees();
        (turn_deg > CONVENTION_DEG).then_some(Convention { turn_deg, axis })
    }
}

/// The smallest turn between two frames reported as a convention, degrees.
const CONVENTION_DEG: f64 = 1e-3;

impl BoneDifference {
    /// No difference yet, from `start`, the first time compared.
    fn new((a, b): (usize, usize), (name, name_b): (&str, &str), start: f64) -> Self {
        let none = Extreme::from(0.0, start);
        BoneDifference {
            a,
            b,
            name: name.to_owned(),
            name_b: (name != name_b).then(|| name_b.to_owned()),
            position: none,
            probe: none,
            orientation_deg: none,
            scale_ratio: Extreme::from(1.0, start),
            stretch_deg: none,
            convention: None,
        }
    }

    fn merge(self, later: BoneDifference) -> Self {
        BoneDifference {
            position: self.position.merge(later.position),
            probe: self.probe.merge(later.probe),
            orientation_deg: self.orientation_deg.merge(later.orientation_deg),
            scale_ratio: self.scale_ratio.merge(later.scale_ratio),
            stretch_deg: self.stretch_deg.merge(later.stretch_deg),
            ..self
        }
    }
}

/// One pair of meshes over the compared times.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct MeshDifference {
    pub a: usize,
    pub b: usize,
    pub name: String,
    pub vertices: usize,
    /// The largest distance between a vertex in A and the same vertex in B, model units.
    pub distance: Extreme,
    /// The mean of that distance over every vertex and time.
    pub mean: f64,
    /// The sum behind `mean` (merged across workers before dividing).
    #[serde(skip)]
    sum: f64,
}

impl MeshDifference {
    fn merge(self, later: MeshDifference) -> Self {
        MeshDifference { distance: self.distance.merge(later.distance), sum: self.sum + later.sum, ..self }
    }
}

/// What is compared: the pairs of bones and meshes.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Pairs {
    pub bones: BoneMatching,
    pub meshes: Vec<MeshPair>,
    pub measure: Measure,
    pub frames: Frames,
}

/// How a pair of bones' frames are compared.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Frames {
    /// As they are: both sides should give each bone one frame (a bake and its source, a rig under two modes).
    #[default]
    Same,
    /// Up to the constant map between them at the first time compared: two files, whose exporters may choose each
    /// node's axes ([`Convention`]).
    UpToConvention,
}

/// What a comparison measures of each pair of bones.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Measure {
    /// Distances (positions and probes) and the polar parts' differences (orientation, scale, stretch).
    #[default]
    Everything,
    /// The distances alone, the meshes' means among them (what a bake's report prints): no polar decomposition, the
    /// parts' differences left at none.
    Distances,
    /// The largest distances alone (what a change costs, [`crate::explain`]): no polar decomposition, the parts'
    /// differences and the meshes' means left at none. Between two evaluations of one rig, a time at which a mesh's
    /// vertices provably lie no further apart than the largest distance already found ([`Reach`]) is not skinned.
    Largest,
}

/// A mesh of A and its partner in B (the same vertex count), and the vertices compared: every one (`None`), or
/// those a comparison knows may differ (`explain`'s of a change below one bone: the vertices weighted to its
/// subtree), the only ones skinned.
#[derive(Clone, Debug, PartialEq)]
pub struct MeshPair {
    pub a: usize,
    pub b: usize,
    pub vertices: Option<Vec<u32>>,
}

impl MeshPair {
    fn whole((a, b): (usize, usize)) -> Self {
        MeshPair { a, b, vertices: None }
    }
}

impl Pairs {
    /// The size a comparison is measured against: the larger of the two sides' sizes ([`Evaluation::size_of`]) over
    /// what both sides show, the paired bones that are of the figure in both and the paired meshes. Swapping A and
    /// B changes nothing, and what one side shows and the other lacks (a camera a bake wrote as a plain node) does
    /// not count.
    pub fn size(&self, a: &Evaluation, b: &Evaluation, times: &[f64]) -> f64 {
        let (figure_a, figure_b) = (a.skeleton().character(), b.skeleton().character());
        let (mut shown_a, mut shown_b) = (vec![false; figure_a.len()], vec![false; figure_b.len()]);
        for &(i, j) in &self.bones.pairs {
            let shown = figure_a[i] && figure_b[j];
            shown_a[i] = shown;
            shown_b[j] = shown;
        }
        let (meshes_a, meshes_b): (Vec<usize>, Vec<usize>) = self.meshes.iter().map(|m| (m.a, m.b)).unzip();
        a.size_of(times, &shown_a, &meshes_a).max(b.size_of(times, &shown_b, &meshes_b))
    }

    /// Bones by name and meshes by name and vertex count, their frames compared as they are.
    pub fn by_name(a: &Evaluation, b: &Evaluation) -> Self {
        let bones = match_bones(a.rig, b.rig);
        let meshes = match_meshes(&a.rig.meshes, &b.rig.meshes).into_iter().map(MeshPair::whole).collect();
        Pairs { bones, meshes, measure: Measure::Everything, frames: Frames::Same }
    }

    /// [`Pairs::by_name`] after the explicit bone pairs of `map` (`--map`), which must name bones, their frames
    /// compared as `frames` says.
    pub fn mapped(a: &Evaluation, b: &Evaluation, map: &[(String, String)], frames: Frames) -> Result<Self, DiffError> {
        let bones = match_bones_mapped(a.rig, b.rig, map)?;
        let meshes = match_meshes(&a.rig.meshes, &b.rig.meshes).into_iter().map(MeshPair::whole).collect();
        Ok(Pairs { bones, meshes, measure: Measure::Everything, frames })
    }
}

/// Why two files cannot be compared as asked.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum DiffError {
    /// An explicit pair names a bone that is not there (or is already paired).
    #[error("--map {map}: no unmatched bone `{name}` in the {file} file")]
    NoBone { map: String, name: String, file: &'static str },
    /// What a side evaluates does not fit its file.
    #[error("{file}: {error}")]
    Setup { file: String, error: crate::eval::SetupError },
    /// Both files have clips and none pairs with the other's by name: nothing would be compared.
    #[error(
        "no animation of the first file pairs with one of the second by name (first: {}; second: {}): choose them \
         with --anim-a and --anim-b",
        listed(a),
        listed(b)
    )]
    NoClipPairs { a: Vec<String>, b: Vec<String> },
}

/// Names in backquotes, separated by commas; `none` for none.
fn listed(names: &[String]) -> String {
    if names.is_empty() {
        return "none".to_owned();
    }
    names.iter().map(|n| format!("`{n}`")).collect::<Vec<_>>().join(", ")
}

/// The result of comparing two evaluations.
#[derive(Clone, Debug, PartialEq)]
pub struct Comparison {
    /// How many times were compared.
    pub samples: usize,
    /// The size of A's rig ([`Evaluation::size`]), which relative figures are fractions of.
    pub rig_size: f64,
    /// One per pair of bones, in A's bone order.
    pub bones: Vec<BoneDifference>,
    pub meshes: Vec<MeshDifference>,
}

impl Comparison {
    /// The worse of two comparisons of the same pairs at the same times (one side played two ways): per bone and
    /// mesh the larger of each difference, and of the mean vertex distances.
    pub fn worse(self, other: Comparison) -> Comparison {
        let bones = self.bones.into_iter().zip(other.bones).map(|(x, y)| x.merge(y)).collect();
        let meshes = self
            .meshes
            .into_iter()
            .zip(other.meshes)
            .map(|(x, y)| MeshDifference { distance: x.distance.merge(y.distance), mean: x.mean.max(y.mean), ..x })
            .collect();
        Comparison { bones, meshes, ..self }
    }

    /// The largest probe distance of any bone and vertex distance of any mesh: how far anything moved.
    pub fn worst_distance(&self) -> Extreme {
        let bones = self.bones.iter().map(|b| b.probe);
        let meshes = self.meshes.iter().map(|m| m.distance);
        bones.chain(meshes).fold(Extreme::default(), Extreme::merge)
    }
}

/// The times two evaluations are compared at: every key time of either where both play (the overlap of their spans,
/// each on its own clock, a delay included: [`Evaluation::delayed`]), and `rate` times a second over it (sorted,
/// near-duplicates counted once); empty where they never play at once.
pub fn comparison_times(a: &Evaluation, b: &Evaluation, rate: f64) -> Vec<f64> {
    let Some(both) = a.span().overlap(b.span()) else { return Vec::new() };
    let keys = a.key_times().into_iter().chain(b.key_times());
    sample_times(keys, both.start, both.end, rate, MAX_FRAMES).times
}

/// Compares `a` and `b` at `times` (sorted), in the units each is measured in: to compare two files, measure `b` in
/// `a`'s rig's unit first ([`Evaluation::measured_in`]), so that lengths are in A's unit. The rig's size is the larger
/// of the two's over `times` ([`Pairs::size`]), so that swapping the two changes nothing.
pub fn compare(a: &Evaluation, b: &Evaluation, pairs: &Pairs, times: &[f64]) -> Comparison {
    compare_at_size(a, b, pairs, times, pairs.size(a, b, times))
}

/// [`compare`] at a rig size already known.
pub fn compare_at_size(a: &Evaluation, b: &Evaluation, pairs: &Pairs, times: &[f64], rig_size: f64) -> Comparison {
    compare_each(a, &[(b, pairs)], times, rig_size).pop().expect("one comparison per side")
}

/// `a` compared with each of `sides` (an evaluation and its pairs with `a`) at `times`, the rig's size there being
/// `rig_size`: [`compare_at_size`] of each, in one pass over time that evaluates, decomposes and skins A once per
/// time for all of them (one evaluation weighed against many changes of it).
pub fn compare_each(a: &Evaluation, sides: &[(&Evaluation, &Pairs)], times: &[f64], rig_size: f64) -> Vec<Comparison> {
    let sides: Vec<_> = sides.iter().map(|&(b, pairs)| (b, pairs, f64::INFINITY)).collect();
    let compared = compare_each_within(a, &sides, times, rig_size);
    compared.into_iter().map(|c| c.expect("no distance passes an infinite limit")).collect()
}

/// [`compare_at_size`], given up (`None`) as soon as a probe point or a vertex lies further apart than `limit`:
/// what a search for the cheapest of several changes needs of all but the cheapest.
pub fn compare_within(
    a: &Evaluation,
    b: &Evaluation,
    pairs: &Pairs,
    times: &[f64],
    rig_size: f64,
    limit: f64,
) -> Option<Comparison> {
    compare_each_within(a, &[(b, pairs, limit)], times, rig_size).pop().flatten()
}

/// [`compare_each`] of `sides` (an evaluation, its pairs with `a`, and a limit), each side given up (`None`) once a
/// probe point or a vertex lies further apart than its limit.
pub fn compare_each_within(
    a: &Evaluation,
    sides: &[(&Evaluation, &Pairs, f64)],
    times: &[f64],
    rig_size: f64,
) -> Vec<Option<Comparison>> {
    let (compared, _) = compare_sides(a, sides, times, rig_size, None::<&Unseen>).expect("nothing beside");
    compared
}

/// [`compare_each`] of `sides`, each a variant of `a` ([`Variant`]), and in the same pass `beside` given A's pose and
/// each side's at every time, in the runs of samples of [`over_runs`] (what it kept of each run, in time order): a
/// variant evaluated once for both. `None`, before any work, where a side is not evaluated from A's pose (another
/// clip, layers, morph targets).
pub fn compare_each_beside<B: Beside>(
    a: &Evaluation,
    sides: &[(&Evaluation, &Pairs)],
    times: &[f64],
    rig_size: f64,
    beside: &B,
) -> Option<(Vec<Comparison>, Vec<B::Run>)> {
    let sides: Vec<_> = sides.iter().map(|&(b, pairs)| (b, pairs, f64::INFINITY)).collect();
    let (compared, runs) = compare_sides(a, &sides, times, rig_size, Some(beside))?;
    Some((compared.into_iter().map(|c| c.expect("no distance passes an infinite limit")).collect(), runs))
}

/// Nothing beside a comparison.
struct Unseen;

impl Beside for Unseen {
    type Run = ();

    fn bones(&self) -> &[usize] {
        &[]
    }

    fn run(&self, _: usize) {}

    fn reference(&self, (): &mut (), _: &Pose) {}

    fn variant(&self, (): &mut (), _: usize, _: usize, _: f64, _: &Pose, _: &ModelPose) {}
}

/// What one comparison pass found: each side's comparison (`None` where given up), and what a [`Beside`] kept of each
/// run of samples.
type Passed<R> = (Vec<Option<Comparison>>, Vec<R>);

/// [`compare_each_within`], and `beside` where given ([`compare_each_beside`]: `None` where a side is no variant).
fn compare_sides<B: Beside>(
    a: &Evaluation,
    sides: &[(&Evaluation, &Pairs, f64)],
    times: &[f64],
    rig_size: f64,
    beside: Option<&B>,
) -> Option<Passed<B::Run>> {
    let probe_length = rig_size * PROBE_FRACTION;
    let reaches: Vec<Vec<Option<Reach>>> = sides.iter().map(|&(b, pairs, _)| reaches(a, b, pairs)).collect();
    let fresh = || {
        let sides = sides.iter().zip(&reaches);
        let start = times.first().copied().unwrap_or_default();
        sides
            .map(|(&(b, pairs, _), reaches)| Differences::new(a, b, pairs, reaches, (rig_size, start)))
            .collect::<Vec<_>>()
    };
    let plan_a = Plan::new(
        a,
        sides.iter().flat_map(|(_, pairs, _)| pairs.bones.pairs.iter().map(|p| p.0)),
        sides.iter().flat_map(|(_, pairs, _)| pairs.meshes.iter().map(|m| (m.a, m.vertices.as_deref()))),
        sides.iter().any(|(_, pairs, _)| pairs.measure == Measure::Everything),
    );
    let plans: Vec<Plan> = sides
        .iter()
        .map(|&(b, pairs, _)| {
            let meshes = pairs.meshes.iter().map(|m| (m.b, m.vertices.as_deref()));
            Plan::new(b, pairs.bones.pairs.iter().map(|p| p.1), meshes, pairs.measure == Measure::Everything)
        })
        .collect();
    // A side that differs from A only below one bone is evaluated from A's pose: A then evaluates what it needs,
    // and every variant's bones with what they hang from.
    let variants: Vec<Option<Variant>> =
        plans.iter().map(|plan| Variant::of(a, plan.evaluation).filter(|_| !plan.morphs && !plan_a.morphs)).collect();
    if beside.is_some() && variants.iter().any(Option::is_none) {
        return None;
    }
    let reference = variants.iter().any(Option::is_some).then(|| {
        let held = variants.iter().zip(&plans).filter(|(v, _)| v.is_some()).map(|(_, plan)| &plan.needed);
        let seen = beside.map_or(&[][..], |beside| beside.bones());
        let bones: Vec<usize> = plan_a.needed.iter().chain(held.flatten()).chain(seen).copied().collect();
        let hanging_from: Vec<usize> = variants.iter().flatten().filter_map(|v| a.skeleton().parent(v.top)).collect();
        (a.skeleton().with_ancestors(&bones), hanging_from)
    });
    // Each side's turn from B's frames onto A's, found once at the first time (by bone of B; none where compared as
    // is).
    let frames: Vec<Vec<DQuat>> = sides
        .iter()
        .zip(&plans)
        .map(|(&(_, pairs, _), plan)| match (pairs.frames, times.first()) {
            (Frames::UpToConvention, Some(&first)) => frame_turns(&plan_a, plan, &pairs.bones.pairs, first),
            _ => Vec::new(),
        })
        .collect();
    // A side given up in one run is given up: its comparison is `None` whatever the other runs find, so they stop it.
    let given_up: Vec<AtomicBool> = sides.iter().map(|_| AtomicBool::new(false)).collect();
    let runs = over_runs(times, |run| {
        let reference = reference.as_ref().and_then(|(bones, hanging_from)| Reference::new(a, bones, hanging_from));
        let mut side_a = match reference {
            Some(reference) => Side::new(&plan_a, Posing::Reference(Box::new(reference))),
            None => Side::alone(&plan_a),
        };
        let mut others: Vec<Side> = plans
            .iter()
            .zip(&variants)
            .zip(&frames)
            .map(|((plan, variant), frames)| {
                let side = match variant {
                    Some(variant) => Side::new(plan, Posing::variant(variant.clone(), plan)),
                    None => Side::alone(plan),
                };
                side.in_frames(frames)
            })
            .collect();
        let mut differences = fresh();
        let mut kept = beside.map(|beside| beside.run(run.len()));
        for (sample, &time) in run.iter().enumerate() {
            if given_up.iter().all(|given_up| given_up.load(Ordering::Relaxed)) {
                break;
            }
            side_a.evaluate(time);
            let mut seen = beside.zip(kept.as_mut());
            if let Some((beside, seen)) = &mut seen {
                beside.reference(seen, side_a.posing.pose());
            }
            let compared = others.iter_mut().zip(&mut differences).zip(sides.iter().zip(&given_up)).enumerate();
            for (k, ((side_b, found), (&(.., limit), given_up))) in
                compared.filter(|(_, (_, (_, given_up)))| !given_up.load(Ordering::Relaxed))
            {
                side_b.evaluate_beside(time, &side_a);
                if let Some((beside, seen)) = &mut seen {
                    beside.variant(seen, k, sample, time, side_a.posing.pose(), &side_b.posing.pose().model);
                }
                found.add(&mut side_a, side_b, probe_length, time);
                if found.largest > limit {
                    given_up.store(true, Ordering::Relaxed);
                }
            }
        }
        (differences, kept)
    });
    let (differences, kept): (Vec<_>, Vec<_>) = runs.into_iter().unzip();
    let totals = differences
        .into_iter()
        .reduce(|earlier, later| earlier.into_iter().zip(later).map(|(x, y)| x.merge(y)).collect());
    let count = times.len().max(1) as f64;
    let finish = |(found, &(.., limit)): (Differences, &(&Evaluation, &Pairs, f64))| {
        if found.largest > limit {
            return None;
        }
        let mean = |m: MeshDifference| MeshDifference { mean: m.sum / (count * m.vertices.max(1) as f64), ..m };
        let meshes = found.meshes.into_iter().map(mean).collect();
        Some(Comparison { samples: times.len(), rig_size, bones: found.bones, meshes })
    };
    let totals = totals.unwrap_or_else(fresh).into_iter().zip(&frames).map(|(mut found, frames)| {
        for bone in &mut found.bones {
            bone.convention = frames.get(bone.b).copied().and_then(Convention::of);
        }
        found
    });
    let compared = totals.zip(sides).map(finish).collect();
    Some((compared, kept.into_iter().flatten().collect()))
}

/// Per bone of B, the turn `M = R_b⁻¹·R_a` that reads its frame in its partner's: the polar rotations of both model
/// matrices at `time`; the identity where unpaired, or where the two are alike to rounding ([`Convention::of`]).
fn frame_turns(plan_a: &Plan, plan_b: &Plan, pairs: &[(usize, usize)], time: f64) -> Vec<DQuat> {
    let (mut a, mut b) = (Side::alone(plan_a), Side::alone(plan_b));
    a.evaluate(time);
    b.evaluate(time);
    let (model_a, model_b) = (&a.posing.pose().model.model, &b.posing.pose().model.model);
    let mut turns = vec![DQuat::IDENTITY; model_b.len()];
    for &(i, j) in pairs {
        let turn = decompose(&model_b[j]).rotation.inverse() * decompose(&model_a[i]).rotation;
        if turn.is_finite() && Convention::of(turn).is_some() {
            turns[j] = turn.normalize();
        }
    }
    turns
}

/// The differences found over some of the times.
struct Differences<'p> {
    bones: Vec<BoneDifference>,
    meshes: Vec<MeshDifference>,
    /// The mesh pairs, with the vertices compared, and how far each pair's vertices can lie apart where that is
    /// known from the joints alone ([`reaches`]).
    pairs: &'p [MeshPair],
    reaches: &'p [Option<Reach>],
    measure: Measure,
    /// The largest probe or vertex distance found.
    largest: f64,
    /// What a bound must stay under the largest distance by to skip skinning: rounding, at the rig's size.
    margin: f64,
}

impl<'p> Differences<'p> {
    /// No difference yet between the pairs, of a rig of `rig_size`, from `start`, the first time compared.
    fn new(
        a: &Evaluation,
        b: &Evaluation,
        pairs: &'p Pairs,
        reaches: &'p [Option<Reach>],
        (rig_size, start): (f64, f64),
    ) -> Self {
        let (sa, sb) = (&a.rig.skeleton, &b.rig.skeleton);
        let names = |i: usize, j: usize| (sa.bone(i).name.as_str(), sb.bone(j).name.as_str());
        let bones = pairs.bones.pairs.iter().map(|&(i, j)| BoneDifference::new((i, j), names(i, j), start));
        let meshes = pairs.meshes.iter().map(|pair| {
            let mesh = &a.rig.meshes[pair.a];
            let (distance, sum) = (Extreme::from(0.0, start), 0.0);
            let vertices = pair.vertices.as_ref().map_or(mesh.positions.len(), Vec::len);
            MeshDifference { a: pair.a, b: pair.b, name: mesh.name.clone(), vertices, distance, mean: 0.0, sum }
        });
        let (bones, meshes, measure) = (bones.collect(), meshes.collect(), pairs.measure);
        let margin = 1e-12 * rig_size;
        Differences { bones, meshes, pairs: &pairs.meshes, reaches, measure, largest: 0.0, margin }
    }

    fn merge(self, later: Differences) -> Self {
        let bones = self.bones.into_iter().zip(later.bones).map(|(x, y)| x.merge(y)).collect();
        let meshes = self.meshes.into_iter().zip(later.meshes).map(|(x, y)| x.merge(y)).collect();
        let largest = self.largest.max(later.largest);
        Differences { bones, meshes, largest, ..self }
    }

    fn add(&mut self, a: &mut Side, b: &mut Side, probe_length: f64, time: f64) {
        for difference in &mut self.bones {
            let turn = b.frames.get(difference.b).map(|&turn| DMat4::from_quat(turn));
            // A's probe points are found once per time, for every side compared with it.
            let offsets_a = match turn {
                None => *a.probe_offsets(difference.a, probe_length),
                Some(_) => [DVec3::ZERO; 3],
            };
            let (wa, wb) = (&a.posing.pose().model.model[difference.a], &b.posing.pose().model.model[difference.b]);
            difference.position.add((wa.w_axis - wb.w_axis).truncate().length(), time);
            let probe = match turn {
                // Each seen from the other's frame, so that either file may be A.
                Some(turn) => probe_distance(wa, &(*wb * turn), probe_length).max(probe_distance(
                    wb,
                    &(*wa * turn.inverse()),
                    probe_length,
                )),
                None => probe_distance_along(wa, &offsets_a, wb, probe_length),
            };
            difference.probe.add(probe, time);
            self.largest = self.largest.max(probe);
            if self.measure != Measure::Everything {
                continue;
            }
            let (pa, pb) = (&a.parts[difference.a], &b.parts[difference.b]);
            difference.orientation_deg.add(angle_between(pa.rotation, pb.rotation).to_degrees(), time);
            difference.scale_ratio.add(scale_ratio(pa.scale, pb.scale), time);
            difference.stretch_deg.add(stretch_difference_deg(pa, pb), time);
        }
        let skins = &a.plan.evaluation.rig.skins;
        for ((difference, pair), reach) in self.meshes.iter_mut().zip(self.pairs).zip(self.reaches) {
            let (model_a, model_b) = (&a.posing.pose().model.model, &b.posing.pose().model.model);
            let bound = reach.as_ref().map(|reach| reach.bound(skins, model_a, model_b));
            if bound.is_some_and(|bound| bound * (1.0 + 1e-9) + self.margin < difference.distance.max) {
                continue;
            }
            a.skin(difference.a);
            b.skin(difference.b);
            let (va, vb) = (&a.skinned[difference.a].0, &b.skinned[difference.b].0);
            let mut largest: f64 = 0.0;
            let means = self.measure != Measure::Largest;
            let mut add = |p: &DVec3, q: &DVec3| {
                let d = p.distance(*q);
                largest = largest.max(d);
                if means {
                    difference.sum += d;
                }
            };
            match &pair.vertices {
                Some(vertices) => vertices.iter().map(|&v| v as usize).for_each(|v| add(&va[v], &vb[v])),
                None => va.iter().zip(vb).for_each(|(p, q)| add(p, q)),
            }
            difference.distance.add(largest, time);
            self.largest = self.largest.max(largest);
        }
    }
}

/// Per mesh pair of `pairs`, how far its vertices can lie apart, known from the joints alone where both sides are
/// evaluations of one rig skinning alike and only the largest distances are measured ([`Measure::Largest`]: the
/// means need every vertex at every time).
fn reaches(a: &Evaluation, b: &Evaluation, pairs: &Pairs) -> Vec<Option<Reach>> {
    let alike = pairs.measure == Measure::Largest && std::ptr::eq(a.rig, b.rig) && a.skinning == b.skinning;
    let reach = |pair: &MeshPair| {
        let rig = a.rig;
        let mesh = rig.meshes.get(pair.a).filter(|_| alike && pair.a == pair.b)?;
        Reach::of(mesh, &rig.skins, a.skinning, pair.vertices.as_deref())
    };
    pairs.meshes.iter().map(reach).collect()
}

/// What one side of a comparison evaluates at each time, found once: the bones compared (sorted, each once), the
/// meshes compared with the vertices to skin (every one for `None`), and the bones that takes: those bones, the
/// bones the meshes hang from and the joints of those vertices, with every ancestor; every bone where a compared
/// mesh has morph targets, whose weights only whole poses carry; and whether the bones' polar parts are wanted.
struct Plan<'p> {
    bones: Vec<usize>,
    decompose: bool,
    /// Whether a compared mesh has morph targets: their weights come with whole poses.
    morphs: bool,
    meshes: Vec<(usize, Option<Vec<u32>>)>,
    needed: Vec<usize>,
    evaluation: &'p Evaluation<'p>,
}

impl<'p> Plan<'p> {
    fn new<'v>(
        evaluation: &'p Evaluation<'p>,
        bones: impl Iterator<Item = usize>,
        meshes: impl Iterator<Item = (usize, Option<&'v [u32]>)>,
        decompose: bool,
    ) -> Self {
        let mut bones: Vec<usize> = bones.collect();
        bones.sort_unstable();
        bones.dedup();
        let meshes = union_of_vertices(meshes);
        let rig = evaluation.rig;
        let morphs = meshes.iter().any(|(m, _)| !rig.meshes[*m].morph_targets.is_empty());
        let needed = if morphs {
            (0..rig.skeleton.len()).collect()
        } else {
            let joints = meshes.iter().flat_map(|(m, vertices)| mesh_bones(rig, *m, vertices.as_deref()));
            rig.skeleton.with_ancestors(&bones.iter().copied().chain(joints).collect::<Vec<_>>())
        };
        Plan { bones, decompose, morphs, meshes, needed, evaluation }
    }
}

/// Each mesh once, with the union of the vertices asked for (every one where any asks for every one).
fn union_of_vertices<'v>(meshes: impl Iterator<Item = (usize, Option<&'v [u32]>)>) -> Vec<(usize, Option<Vec<u32>>)> {
    let mut union: Vec<(usize, Option<Vec<u32>>)> = Vec::new();
    for (mesh, vertices) in meshes {
        match union.iter_mut().find(|(m, _)| *m == mesh) {
            Some((_, slot)) => match (slot.as_mut(), vertices) {
                (Some(all), Some(more)) => all.extend_from_slice(more),
                _ => *slot = None,
            },
            None => union.push((mesh, vertices.map(<[u32]>::to_vec))),
        }
    }
    for (_, vertices) in &mut union {
        if let Some(list) = vertices {
            list.sort_unstable();
            list.dedup();
        }
    }
    union
}

/// The bones mesh `mesh` of `rig` moves with at `vertices` (every vertex for `None`): the bone it hangs from, the
/// node its skin follows, and the joints those vertices are weighted to.
fn mesh_bones<'r>(rig: &'r Rig, mesh: usize, vertices: Option<&'r [u32]>) -> impl Iterator<Item = usize> + 'r {
    let mesh = &rig.meshes[mesh];
    let skin = mesh.skin.and_then(|s| rig.skins.get(s));
    let joints = skin.map_or(&[][..], |skin| &skin.joints[..]);
    let node = skin.and_then(|skin| skin.node_bind).map(|node| node.bone);
    let all = 0..mesh.joints.len() as u32;
    let chosen: Box<dyn Iterator<Item = u32> + 'r> = match vertices {
        Some(list) => Box::new(list.iter().copied()),
        None => Box::new(all),
    };
    let weighted =
        chosen.filter_map(move |v| Some(mesh.joints.get(v as usize)?.iter().zip(mesh.weights.get(v as usize)?)));
    let bones =
        weighted.flatten().filter(|(_, w)| **w != 0.0).filter_map(move |(&j, _)| joints.get(usize::from(j)).copied());
    std::iter::once(mesh.bone).chain(node).chain(bones)
}

/// One side of a comparison as one thread evaluates it, one time after another: the bones its [`Plan`] needs, the
/// polar parts of the bones compared (the identity's elsewhere) and the meshes compared, skinned where asked (by
/// mesh index; empty elsewhere).
struct Side<'e, 'a> {
    posing: Posing<'e, 'a>,
    plan: &'e Plan<'a>,
    parts: Vec<AffineParts>,
    length_scales: Vec<f64>,
    /// Per bone, the turn that reads its frame in its partner's ([`frame_turns`]); empty where read as it is.
    frames: &'e [DQuat],
    /// Per mesh, what skins the vertices the plan compares (`None` for a mesh not compared), and where they are,
    /// with the evaluation they were skinned at.
    skinners: Vec<Option<Skinner>>,
    skinned: Vec<(Vec<DVec3>, u64)>,
    /// Per bone, its probe points' offsets ([`probe_offsets`]) and the evaluation they were found at: A's are read
    /// by every side compared with it.
    probes: Vec<([DVec3; 3], u64)>,
    /// How many times the side was evaluated: what is found once per time is marked with it.
    evaluations: u64,
}

/// How a side's poses are found.
enum Posing<'e, 'a> {
    /// Evaluated on its own.
    Alone(BonesEvaluator<'e, 'a>),
    /// A's, as the reference its variants are evaluated from.
    Reference(Box<Reference<'e>>),
    /// A variant of A, evaluated from A's pose.
    Variant(Box<FromA<'e, 'a>>),
}

/// A variant of A and its pose: its own bones, and the others it needs (`borrowed`) as A has them.
struct FromA<'e, 'a> {
    variant: Variant<'e, 'a>,
    pose: Pose,
    borrowed: Vec<usize>,
}

impl<'e, 'a> Posing<'e, 'a> {
    /// `variant` (of A), needing the bones of `plan`.
    fn variant(variant: Variant<'e, 'a>, plan: &Plan) -> Self {
        let borrowed = plan.needed.iter().copied().filter(|b| variant.bones.binary_search(b).is_err()).collect();
        Posing::Variant(Box::new(FromA { variant, pose: Pose::default(), borrowed }))
    }

    fn pose(&self) -> &Pose {
        match self {
            Posing::Alone(evaluator) => evaluator.pose(),
            Posing::Reference(reference) => reference.pose(),
            Posing::Variant(from_a) => &from_a.pose,
        }
    }
}

impl<'e, 'a> Side<'e, 'a> {
    /// The side of `plan`, evaluated on its own.
    fn alone(plan: &'e Plan<'a>) -> Self {
        Side::new(plan, Posing::Alone(BonesEvaluator::new(plan.evaluation, &plan.needed)))
    }

    fn new(plan: &'e Plan<'a>, posing: Posing<'e, 'a>) -> Self {
        let rig = plan.evaluation.rig;
        let mut skinners = vec![None; rig.meshes.len()];
        for (mesh, vertices) in &plan.meshes {
            skinners[*mesh] = Some(Skinner::new(&rig.meshes[*mesh], &rig.skins, vertices.clone()));
        }
        let skinned = vec![(Vec::new(), u64::MAX); skinners.len()];
        let length_scales = plan.evaluation.length_scales();
        let (parts, probes) = (Vec::new(), Vec::new());
        Side { posing, plan, parts, length_scales, frames: &[], skinners, skinned, probes, evaluations: 0 }
    }

    /// The same side with its frames read in its partner's through `frames` ([`frame_turns`]).
    fn in_frames(self, frames: &'e [DQuat]) -> Self {
        Side { frames, ..self }
    }

    /// Evaluates the side's bones at `time` (its meshes are skinned when asked: [`Side::skin`]); a variant is
    /// evaluated beside A ([`Side::evaluate_beside`]).
    fn evaluate(&mut self, time: f64) {
        match &mut self.posing {
            Posing::Alone(evaluator) => _ = evaluator.evaluate(time),
            Posing::Reference(reference) => _ = reference.evaluate(time),
            Posing::Variant(_) => unreachable!("a variant is evaluated beside A"),
        }
        self.evaluated();
    }

    /// [`Side::evaluate`] of side B, `a` (side A) evaluated at `time`: a variant of A from A's pose.
    fn evaluate_beside(&mut self, time: f64, a: &Side) {
        let Posing::Variant(from_a) = &mut self.posing else {
            return self.evaluate(time);
        };
        let FromA { variant, pose, borrowed } = &mut **from_a;
        let Posing::Reference(reference) = &a.posing else {
            unreachable!("A is the reference of its variants");
        };
        let held = &reference.pose().model.model;
        pose.model.model.resize(held.len(), DMat4::IDENTITY);
        for &bone in borrowed.iter() {
            pose.model.model[bone] = held[bone];
        }
        reference.evaluate_variant(variant, &mut pose.model);
        self.evaluated();
    }

    /// What follows an evaluation: the compared bones' polar parts where asked for, no mesh skinned yet.
    fn evaluated(&mut self) {
        let model = &self.posing.pose().model.model;
        if self.plan.decompose {
            self.parts = decompose_bones(model, &self.plan.bones);
            for &bone in &self.plan.bones {
                self.parts[bone] = self.parts[bone].authored(self.length_scales[bone]);
                // `W·M` turns the polar rotation and the stretch frame alike and leaves the scales.
                if let Some(&turn) = self.frames.get(bone) {
                    let parts = &mut self.parts[bone];
                    (parts.rotation, parts.stretch) = (parts.rotation * turn, turn.inverse() * parts.stretch);
                }
            }
        }
        self.evaluations += 1;
    }

    /// Bone `bone`'s probe offsets ([`probe_offsets`]) at the time evaluated, found once.
    fn probe_offsets(&mut self, bone: usize, probe_length: f64) -> &[DVec3; 3] {
        let model = &self.posing.pose().model.model;
        self.probes.resize(model.len(), ([DVec3::ZERO; 3], u64::MAX));
        let (offsets, found_at) = &mut self.probes[bone];
        if *found_at != self.evaluations {
            (*offsets, *found_at) = (probe_offsets(&model[bone], probe_length), self.evaluations);
        }
        offsets
    }

    /// Skins mesh `mesh` (its vertices the plan compares) at the time evaluated, once.
    fn skin(&mut self, mesh: usize) {
        let (skinned, skinned_at) = &mut self.skinned[mesh];
        if std::mem::replace(skinned_at, self.evaluations) == self.evaluations {
            return;
        }
        let Some(skinner) = &mut self.skinners[mesh] else { return };
        let (evaluation, pose) = (self.plan.evaluation, self.posing.pose());
        let (rig, posed) = (evaluation.rig, (&pose.model.model[..], &pose.morph));
        skinner.skin(&rig.meshes[mesh], &rig.skins, posed, evaluation.skinning, skinned);
    }
}

/// The polar parts of the matrices of `bones` (the identity's at every other bone): every matrix at once where all
/// are asked for ([`decompose_all`], less time per matrix), else only theirs.
fn decompose_bones(model: &[DMat4], bones: &[usize]) -> Vec<AffineParts> {
    if bones.len() == model.len() {
        return decompose_all(model);
    }
    let mut parts = vec![AffineParts::IDENTITY; model.len()];
    for &bone in bones {
        parts[bone] = decompose(&model[bone]);
    }
    parts
}

/// The model-space components of `bones` of `side` at `times`, one curve per bone: a second file's curves beside the
/// first's (the app plots a compared file dashed).
pub fn model_curves(evaluation: &Evaluation, bones: &[usize], times: &[f64]) -> Vec<Vec<Components>> {
    let chunks: Vec<Vec<Vec<Components>>> = over_runs(times, |run| {
        let mut evaluator = evaluation.evaluator();
        let mut starts = vec![DQuat::IDENTITY; bones.len()];
        let mut curves = vec![Vec::with_capacity(run.len()); bones.len()];
        for &time in run {
            let pose = evaluator.evaluate(time);
            for ((curve, start), &bone) in curves.iter_mut().zip(&mut starts).zip(bones) {
                let components = Components::of_matrix(&pose.model.model[bone], *start);
                *start = components.stretch.as_dquat();
                curve.push(components);
            }
        }
        curves
    });
    (0..bones.len()).map(|b| chunks.iter().flat_map(|chunk| chunk[b].iter().copied()).collect()).collect()
}

/// The largest distance between the points of a bone's frame in the two poses, each placed in its own pose: the
/// origins, and for each axis the point `probe_length` along it (`o + ℓ·c/|c|` of the axis's column `c`; at the
/// origin for an axis of no length, or of no finite one). How far a point a tenth of the rig out along the bone
/// moved, whatever scale either frame carries: a scale differs in the scale ratio and in the skin.
fn probe_distance(wa: &DMat4, wb: &DMat4, probe_length: f64) -> f64 {
    probe_distance_along(wa, &probe_offsets(wa, probe_length), wb, probe_length)
}

/// [`probe_distance`], A's probe points given as their offsets from its origin ([`probe_offsets`]): found once per
/// time for all the sides compared with A.
fn probe_distance_along(wa: &DMat4, offsets_a: &[DVec3; 3], wb: &DMat4, probe_length: f64) -> f64 {
    let origins = (wa.w_axis - wb.w_axis).truncate();
    let offsets_b = probe_offsets(wb, probe_length);
    // Compared squared, the root of the largest being the largest root.
    let axes = (0..3).map(|axis| (origins + offsets_a[axis] - offsets_b[axis]).length_squared());
    axes.fold(origins.length_squared(), f64::max).sqrt()
}

/// The offsets of a frame's probe points from its origin: `ℓ·c/|c|` of each axis's column `c` (none for an axis of
/// no length, or of no finite one).
fn probe_offsets(w: &DMat4, probe_length: f64) -> [DVec3; 3] {
    std::array::from_fn(|axis| w.col(axis).truncate().normalize_or_zero() * probe_length)
}

/// The largest ratio between corresponding stretch factors, sorted (≥ 1; infinite where one is zero and the other
/// not).
fn scale_ratio(a: DVec3, b: DVec3) -> f64 {
    let sorted = |v: DVec3| {
        let mut k = v.to_array();
        k.sort_by(f64::total_cmp);
        k
    };
    let (ka, kb) = (sorted(a), sorted(b));
    (0..3)
        .map(|i| if ka[i] == kb[i] { 1.0 } else { (ka[i] / kb[i]).max(kb[i] / ka[i]) })
        .fold(1.0, |worst, r| if r.is_nan() { f64::INFINITY } else { worst.max(r) })
}

/// The angle between the stretch frames, up to the turns that change neither side's `U·K·Uᵀ` (axis permutations,
/// free turns between equal factors), seen from both sides: a sheared bone against an unsheared one differs by its
/// own stretch angle.
fn stretch_difference_deg(a: &AffineParts, b: &AffineParts) -> f64 {
    let relative = a.stretch.conjugate() * b.stretch;
    if relative.xyz().length() <= NEARLY_SAME_FRAME {
        // Frames this close: their angle (the symmetries could only make it smaller), free of the inverse
        // cosine's loss of precision near 0.
        return angle_between(DQuat::IDENTITY, relative).to_degrees();
    }
    let seen_from = |relative: DQuat, parts: &AffineParts| {
        // Factors the findings count as equal leave the frame free between them, so its turn is no difference.
        AffineParts { stretch: relative, ..*parts }.stretch_angle_deg_within(Tolerances::default().min_anisotropy)
    };
    seen_from(relative, b).max(seen_from(relative.conjugate(), a))
}

/// The sine of half the angle below which two stretch frames are compared directly (about 1e-4°).
const NEARLY_SAME_FRAME: f64 = 1e-6;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::import::demo_rig;
    use crate::model::{Bone, InheritMode, Rig, Skeleton, Transform};

    #[test]
    fn a_file_against_itself_differs_by_nothing() {
        let rig = demo_rig();
        let side = Evaluation::declared(&rig, rig.clips.first());
        let pairs = Pairs::by_name(&side, &side);
        // Every node is paired: the skinned tube hangs on the shoulder, a joint with bones below it.
        assert!(pairs.bones.skinned_a.is_empty());
        assert_eq!(pairs.bones.pairs.len(), rig.skeleton.len());
        let times = comparison_times(&side, &side, 30.0);
        let comparison = compare(&side, &side, &pairs, &times);
        assert_eq!(comparison.samples, times.len());
        assert!(comparison.worst_distance().max < 1e-15);
        for bone in &comparison.bones {
            assert!(bone.orientation_deg.max < 1e-12 && bone.stretch_deg.max < 1e-12, "{bone:?}");
            assert_eq!(bone.scale_ratio.max, 1.0);
        }
        assert_eq!(comparison.meshes.len(), rig.meshes.len());
    }

    /// The demo rig's bones with every frame turned a quarter about X (`W·Q`), as another exporter might give them:
    /// a root's local transform times `Q`, every other's `Q⁻¹·L·Q` (its scale's Y and Z swapped), its clip's keys
    /// likewise (the maps are linear, so cubic tangents map as values do); no meshes.
    fn turned_demo() -> Rig {
        use crate::model::{Clip, Track};
        let rig = demo_rig();
        let q = DQuat::from_rotation_x(std::f64::consts::FRAC_PI_2);
        let swap = |s: DVec3| DVec3::new(s.x, s.z, s.y);
        let roots: Vec<bool> = rig.skeleton.bones().iter().map(|b| b.parent.is_none()).collect();
        let turn = |bone: usize, r: DQuat| if roots[bone] { r * q } else { q.inverse() * r * q };
        let carry = |bone: usize, t: DVec3| if roots[bone] { t } else { q.inverse() * t };
        let bones = rig.skeleton.bones().iter().enumerate().map(|(i, b)| {
            let rest = Transform::from_trs(carry(i, b.rest.translation), turn(i, b.rest.rotation), swap(b.rest.scale));
            Bone { rest, ..b.clone() }
        });
        let remap = |clip: &Clip| {
            let tracks = clip.tracks().iter().map(|t| {
                let mut out = t.clone();
                let values = |track: &Track<glam::Vec3>, f: &dyn Fn(DVec3) -> DVec3| {
                    let values: Vec<glam::Vec3> = track.values().iter().map(|v| f(v.as_dvec3()).as_vec3()).collect();
                    Track::new(track.times().into(), values, track.interpolation()).unwrap()
                };
                out.translation = t.translation.as_ref().map(|tr| values(tr, &|v| carry(t.bone, v)));
                out.scale = t.scale.as_ref().map(|tr| values(tr, &swap));
                out.rotation = t.rotation.as_ref().map(|tr| {
                    let values: Vec<glam::Quat> =
                        tr.values().iter().map(|r| turn(t.bone, r.as_dquat()).as_quat()).collect();
                    Track::new(tr.times().into(), values, tr.interpolation()).unwrap()
                });
                out
            });
            Clip::new(clip.index, clip.name.clone(), tracks.collect(), vec![])
        };
        let skeleton = Skeleton::new(bones.collect()).unwrap();
        Rig { skeleton, clips: rig.clips.iter().map(remap).collect(), skins: vec![], meshes: vec![], ..rig }
    }

    #[test]
    fn a_turn_of_every_frame_is_a_convention_reported_once_and_taken_out() {
        let (rig, turned) = (demo_rig(), turned_demo());
        let (a, b) = (every_bone(&rig, InheritMode::Full), every_bone(&turned, InheritMode::Full));
        let times = comparison_times(&a, &b, 30.0);
        // The turn is real: each frame is W·Q, the origins where they were.
        let (wa, wb) = (a.pose_at(0.7).model.model, b.pose_at(0.7).model.model);
        let q = DMat4::from_rotation_x(std::f64::consts::FRAC_PI_2);
        assert!(wa.iter().zip(&wb).all(|(x, y)| (*x * q).abs_diff_eq(*y, 1e-6)));
        let as_is = compare(&a, &b, &Pairs::by_name(&a, &b), &times);
        let up_to = compare(&a, &b, &Pairs::mapped(&a, &b, &[], Frames::UpToConvention).unwrap(), &times);
        for (same, conventional) in as_is.bones.iter().zip(&up_to.bones) {
            assert!((same.orientation_deg.max - 90.0).abs() < 1e-4, "{same:?}");
            assert!(same.convention.is_none());
            let c = conventional.convention.expect("every frame turned");
            assert!((c.turn_deg - 90.0).abs() < 1e-4 && c.axis.abs_diff_eq(DVec3::X, 1e-6), "{c:?}");
            assert!(conventional.orientation_deg.max < 1e-4, "{conventional:?}");
            assert!(conventional.probe.max < 1e-6, "the points of each frame, each in its own pose: {conventional:?}");
            assert_eq!(conventional.position, same.position, "origins are compared as they are");
        }
    }

    /// The demo's clip with every bone under `mode`.
    fn every_bone(rig: &Rig, mode: InheritMode) -> Evaluation<'_> {
        Evaluation::new(rig, rig.clips.first(), &vec![mode; rig.skeleton.len()]).unwrap()
    }

    #[test]
    fn two_modes_differ_where_the_shear_goes() {
        // The demo's forearm shears under full inheritance and not under segment scale compensate.
        let rig = demo_rig();
        let [full, compensated] =
            [InheritMode::Full, InheritMode::SegmentCompensate].map(|mode| every_bone(&rig, mode));
        let pairs = Pairs::by_name(&full, &compensated);
        let comparison = compare(&full, &compensated, &pairs, &comparison_times(&full, &compensated, 30.0));
        let root = &comparison.bones[0];
        assert_eq!(root.probe.max, 0.0, "the root is the same in every mode");
        let forearm = comparison.bones.iter().find(|b| b.name == "forearm").unwrap();
        assert!(forearm.stretch_deg.max > 1.0 && forearm.scale_ratio.max > 1.01, "{forearm:?}");
        assert!(comparison.meshes[0].distance.max > 0.0 && comparison.meshes[0].mean > 0.0);
    }

    #[test]
    fn a_comparison_within_a_limit_is_the_whole_comparison_or_given_up() {
        // The demo under two modes at 600 samples a second, in runs on three threads: a limit at the largest
        // distance keeps the whole comparison; one just under it gives it up, whichever run finds the distance.
        let rig = demo_rig();
        let [full, compensated] =
            [InheritMode::Full, InheritMode::SegmentCompensate].map(|mode| every_bone(&rig, mode));
        let pairs = Pairs { measure: Measure::Largest, ..Pairs::by_name(&full, &compensated) };
        let times = comparison_times(&full, &compensated, 600.0);
        let pool = rayon::ThreadPoolBuilder::new().num_threads(3).build().unwrap();
        pool.install(|| {
            let whole = compare_at_size(&full, &compensated, &pairs, &times, 1.0);
            let largest =
                whole.worst_distance().max.max(whole.meshes.iter().map(|m| m.distance.max).fold(0.0, f64::max));
            assert!(largest > 0.0 && times.len() > 2 * crate::eval::run_length(times.len()), "several runs");
            let within = compare_within(&full, &compensated, &pairs, &times, 1.0, largest);
            assert!(within.as_ref() == Some(&whole), "within its own largest distance, the whole comparison");
            assert!(compare_within(&full, &compensated, &pairs, &times, 1.0, largest * (1.0 - 1e-9)).is_none());
            // In one pass each side keeps its own limit: the side given up stops no other.
            let aligned = every_bone(&rig, InheritMode::BlenderAligned);
            let aligned_pairs = Pairs { measure: Measure::Largest, ..Pairs::by_name(&full, &aligned) };
            let sides = [
                (&compensated, &pairs, largest * (1.0 - 1e-9)),
                (&aligned, &aligned_pairs, f64::INFINITY),
                (&compensated, &pairs, largest),
            ];
            let each = compare_each_within(&full, &sides, &times, 1.0);
            assert!(each[0].is_none(), "given up past its limit");
            assert!(each[1] == Some(compare_at_size(&full, &aligned, &aligned_pairs, &times, 1.0)));
            assert!(each[2].as_ref() == Some(&whole), "the same side within its largest distance");
        });
    }

    #[test]
    fn positions_and_orientations_of_a_scaled_chain() {
        // root scaled (2, 1, 1); mid 1 along X, turned 45° about Z, scaled (1, 2, 1); tip 1 along X, turned 30°.
        // Unscaled-parent drops every ancestor's scale: tip at Rz(45°)·(1, 0, 0) + (1, 0, 0), turned 75°.
        // Full: tip at diag(2,1,1)·[(1, 0, 0) + Rz(45°)·diag(1,2,1)·(1, 0, 0)] = (2 + 2c, c, 0) with c = cos 45°,
        // and the linear part M = S0·Rz(45°)·S1·Rz(30°), whose closest rotation turns about Z by
        // atan2(m10 − m01, m00 + m11) (the 2-D polar rotation; computed here without the decomposition code).
        let rz = |deg: f64| Transform::from_trs(DVec3::X, DQuat::from_rotation_z(deg.to_radians()), DVec3::ONE);
        let root = Transform::from_trs(DVec3::ZERO, DQuat::IDENTITY, DVec3::new(2.0, 1.0, 1.0));
        let mid = Transform { scale: DVec3::new(1.0, 2.0, 1.0), ..rz(45.0) };
        let bone = |name: &str, parent, rest| Bone::joint(name, parent, rest);
        let bones = vec![bone("root", None, root), bone("mid", Some(0), mid), bone("tip", Some(1), rz(30.0))];
        let rig = Rig { skeleton: Skeleton::new(bones).unwrap(), ..Rig::default() };
        let unscaled = Evaluation::new(&rig, None, &[InheritMode::UnscaledParent; 3]).unwrap();
        let full = Evaluation::new(&rig, None, &[InheritMode::Full; 3]).unwrap();
        let result =
            compare(&unscaled, &full, &Pairs::by_name(&unscaled, &full), &comparison_times(&unscaled, &full, 60.0));
        assert_eq!(result.samples, 1);
        let c = std::f64::consts::FRAC_1_SQRT_2;
        let tip = &result.bones[2];
        let unscaled_tip = DVec3::new(1.0 + c, c, 0.0);
        let full_tip = DVec3::new(2.0 + 2.0 * c, c, 0.0);
        assert!((tip.position.max - (full_tip - unscaled_tip).length()).abs() < 1e-12, "{tip:?}");
        let m = glam::DMat2::from_diagonal(glam::DVec2::new(2.0, 1.0))
            * glam::DMat2::from_angle(45f64.to_radians())
            * glam::DMat2::from_diagonal(glam::DVec2::new(1.0, 2.0))
            * glam::DMat2::from_angle(30f64.to_radians());
        let full_angle = (m.x_axis.y - m.y_axis.x).atan2(m.x_axis.x + m.y_axis.y).to_degrees();
        assert!((tip.orientation_deg.max - (75.0 - full_angle).abs()).abs() < 1e-9, "{tip:?}");
        assert!(tip.orientation_deg.max > 1.0, "the two scales around a rotation turn the tip");
        let root = &result.bones[0];
        assert_eq!((root.position.max, root.orientation_deg.max), (0.0, 0.0), "roots agree in every mode");
    }

    #[test]
    fn measures_of_hand_made_matrices() {
        // B turns A a quarter about Z and moves it 1 along X. Probes 2 along each axis: X's (2, 0, 0) goes to
        // (1, 2, 0) and Y's (0, 2, 0) to (−1, 0, 0), both √5 away; Z's and the origin move 1.
        let a = DMat4::IDENTITY;
        let b = DMat4::from_rotation_translation(DQuat::from_rotation_z(std::f64::consts::FRAC_PI_2), DVec3::X);
        assert!((probe_distance(&a, &b, 2.0) - 5f64.sqrt()).abs() < 1e-12);
        // Each point in its own pose: B scaled 1000 along its axes moves none of them (the scale ratio says it).
        let scaled = b * DMat4::from_scale(DVec3::splat(1000.0));
        assert!((probe_distance(&a, &scaled, 2.0) - 5f64.sqrt()).abs() < 1e-12);
        // An axis of no length, or of an infinite one, has its point at the origin: A's flat Y and B's infinite Y
        // both stay there (1 apart, as the origins), while X still finds √5.
        let flat = DMat4::from_cols(glam::DVec4::X, glam::DVec4::ZERO, glam::DVec4::Z, glam::DVec4::W);
        let mut infinite = b;
        infinite.y_axis = glam::DVec4::new(f64::INFINITY, 0.0, 0.0, 0.0);
        assert!((probe_distance(&flat, &infinite, 2.0) - 5f64.sqrt()).abs() < 1e-12);
        assert!(probe_distance(&flat, &infinite, 2.0).is_finite());
        assert!((angle_between(DQuat::IDENTITY, DQuat::from_rotation_y(0.3)) - 0.3).abs() < 1e-15);
        assert_eq!(scale_ratio(DVec3::new(1.0, 2.0, 4.0), DVec3::new(4.0, 1.0, 2.0)), 1.0, "order does not matter");
        assert!((scale_ratio(DVec3::new(1.0, 2.0, 4.0), DVec3::new(1.0, 2.5, 4.0)) - 1.25).abs() < 1e-15);
        assert_eq!(scale_ratio(DVec3::ZERO, DVec3::ONE), f64::INFINITY);
    }
}
