//! Whose scale shears a bone: every bone of its chain asked how much shear is left without its squash.

use std::sync::OnceLock;

use glam::{DMat3, DMat4, DQuat, DVec3};
use rayon::prelude::*;

use crate::analysis::{Assessment, ClipAnalysis, SAME_SHEAR_DEG, Tolerances};
use crate::eval::layers::uniform_scale;
use crate::eval::{BoneCursor, BonesEvaluator, Evaluation, Hierarchy, ModelPose, over_runs_from};
use crate::math::{AffineParts, shear_deg};
use crate::model::{Skeleton, Transform};

/// One bone of the explained bone's chain (the explained bone included) at one time.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Link {
    pub bone: usize,
    pub name: String,
    /// Its local scale factors, signed.
    pub scale: DVec3,
    /// How unequal they are: `max|k|/min|k| − 1` (0: uniform, nothing to take out).
    pub anisotropy: f64,
    /// The smallest angle, in degrees, between this bone's scale axes and the explained bone's axes, as the local
    /// rotations of the chain below it turn them (up to swapping axes and merging factors within the anisotropy
    /// tolerance): a squash shears a bone below it only when the rotations between turn its axes off themselves.
    /// `None` for the explained bone.
    pub turn_deg: Option<f64>,
    /// The explained bone's shear, in degrees, with this bone's local scale made uniform and all else as evaluated.
    pub shear_left_deg: f64,
    /// The shear minus what is left: how much of it this bone's squash causes (negative where it counters another).
    pub contribution_deg: f64,
}

/// Why one bone shears at one time.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Attribution {
    pub bone: usize,
    pub time: f64,
    /// Its shear (the largest deviation from 90° between two of its model axes), in degrees.
    pub shear_deg: f64,
    /// Whether the analysis flags it: sheared beyond the tolerances.
    pub stretched: bool,
    /// The root first, the explained bone last.
    pub chain: Vec<Link>,
    /// The bone whose squash made uniform takes the most shear away, where one takes away more than half the shear
    /// tolerance (rounding moves a shear by far less).
    pub cause: Option<usize>,
    /// The fewest bones of the chain whose scales, all made uniform, leave the bone unflagged (empty when it is
    /// not flagged). Contributions need not add up, since scales compound and cancel; this set is what suffices.
    pub sufficient: Vec<usize>,
}

impl Attribution {
    /// The link of the bone whose squash causes the most shear ([`Attribution::cause`]).
    pub fn main_cause(&self) -> Option<&Link> {
        self.chain.iter().find(|l| Some(l.bone) == self.cause)
    }

    /// Where no one bone's squash causes the shear, the links of the fewest whose squashes together do (the
    /// [`Attribution::sufficient`] set); empty where one bone is the cause or none suffice.
    pub fn together(&self) -> Vec<&Link> {
        match self.cause {
            Some(_) => Vec::new(),
            None => self.chain.iter().filter(|l| self.sufficient.contains(&l.bone)).collect(),
        }
    }
}

/// Whether making a squash uniform takes `contribution` degrees of shear away as a cause does: more than half the
/// shear tolerance. Rounding moves a shear by far less; and a flagged bone (sheared past the tolerance) whose chain's
/// other scales can shear it by under half the tolerance has its one squash as its cause ([`Group::certain_causes`]).
fn contributes(contribution: f64, tolerances: &Tolerances) -> bool {
    contribution > 0.5 * tolerances.min_shear_deg
}

/// A stretch of time in which one bone's squash is the main cause of the shear.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct CauseSpan {
    pub bone: usize,
    pub name: String,
    /// From its first sample to the first sample after it with another main cause, or none (the last sample).
    pub from: f64,
    pub to: f64,
}

/// Why one bone shears over a clip.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Causes {
    pub samples: usize,
    /// Samples at which the bone is flagged.
    pub stretched_samples: usize,
    /// The attribution at the worst flagged sample (the worst shear where none is flagged), or at the time asked.
    pub at: Attribution,
    /// The main cause's time spans, in time order.
    pub spans: Vec<CauseSpan>,
}

/// Why `bone` shears at `time` in `evaluation`.
pub fn attribute(evaluation: &Evaluation, bone: usize, time: f64, tolerances: &Tolerances) -> Attribution {
    let skeleton = evaluation.skeleton();
    let chain = skeleton.chain(bone);
    let mut local = evaluation.pose_at(time).local;
    let mut probe = Probe::new(&evaluation.hierarchy);
    let mut matrix = |local: &mut [Transform], uniform: &[usize]| probe.models(local, &chain, uniform)[bone];
    let assessment = Assessment::of(&matrix(&mut local, &[]), tolerances);
    let shear = assessment.shear_deg;
    // The turn from each bone of the chain down to the explained bone: the local rotations below it, in order.
    let mut below = vec![DQuat::IDENTITY; chain.len()];
    for i in (0..chain.len().saturating_sub(1)).rev() {
        below[i] = local[chain[i + 1]].rotation * below[i + 1];
    }
    let links: Vec<Link> = chain
        .iter()
        .zip(&below)
        .map(|(&b, &turn)| {
            let shear_left = Assessment::of(&matrix(&mut local, &[b]), tolerances).shear_deg;
            let turn = (b != bone).then_some(turn);
            link(skeleton, b, &local[b], turn, shear, shear_left, tolerances)
        })
        .collect();
    let cause = links.iter().filter(|l| contributes(l.contribution_deg, tolerances));
    let cause = cause.max_by(|a, b| a.contribution_deg.total_cmp(&b.contribution_deg)).map(|l| l.bone);
    let stretched = assessment.findings.stretched;
    let sufficient = if stretched { sufficient(&mut matrix, &mut local, &links, tolerances) } else { Vec::new() };
    Attribution { bone, time, shear_deg: shear, stretched, chain: links, cause, sufficient }
}

/// Why `bone` shears over the clip `scanned` analysed (every bone judged, as `scan` judges them) of `evaluation`, with
/// the detail at `at`.
pub fn causes(
    evaluation: &Evaluation,
    scanned: &ClipAnalysis,
    bone: usize,
    at: f64,
    tolerances: &Tolerances,
) -> Causes {
    causes_each(evaluation, scanned, &[(bone, at)], tolerances).pop().expect("one bone asked")
}

/// How many bones' causes one pass over the clip finds ([`causes_each`]): each holds a sample per time while the
/// pass runs.
const TOGETHER: usize = 8;

/// [`causes`] of each of `bones` (each with the time to detail), in the order asked: a few at a time in bone
/// order (the bones of one chain lie together), the groups in parallel. Where a group's bones are flagged, their
/// main causes are read from the local scales where those settle them; elsewhere the group's chains are evaluated
/// once for all its bones, and each squash on them made uniform once for every flagged bone below it.
pub fn causes_each(
    evaluation: &Evaluation,
    scanned: &ClipAnalysis,
    bones: &[(usize, f64)],
    tolerances: &Tolerances,
) -> Vec<Causes> {
    let mut order: Vec<usize> = (0..bones.len()).collect();
    order.sort_by_key(|&i| bones[i].0);
    let groups: Vec<Vec<(usize, Causes)>> = order
        .par_chunks(TOGETHER)
        .map(|group| {
            let asked: Vec<usize> = group.iter().map(|&i| bones[i].0).collect();
            let samples = samples_of(evaluation, scanned, &asked, tolerances);
            let summarised = group.iter().zip(samples).map(|(&i, samples)| {
                let (bone, at) = bones[i];
                let causes = Causes {
                    samples: samples.len(),
                    stretched_samples: samples.iter().filter(|s| s.stretched).count(),
                    at: attribute(evaluation, bone, at, tolerances),
                    spans: spans(evaluation.skeleton(), &samples, &scanned.times),
                };
                (i, causes)
            });
            summarised.collect()
        })
        .collect();
    let mut causes: Vec<(usize, Causes)> = groups.into_iter().flatten().collect();
    causes.sort_by_key(|(i, _)| *i);
    causes.into_iter().map(|(_, causes)| causes).collect()
}

/// Each of `bones`' samples at the times `scanned` analysed: whether the analysis flags it, and where it does its
/// main cause, the bone of its chain, among those scaled unequally, whose uniform scale leaves the least shear
/// (shears measured on the matrix, without a decomposition). Only the flagged samples are looked at, and most of
/// those without evaluating a matrix ([`Group::certain_causes`]).
fn samples_of(
    evaluation: &Evaluation,
    scanned: &ClipAnalysis,
    bones: &[usize],
    tolerances: &Tolerances,
) -> Vec<Vec<Sample>> {
    let group = Group::new(evaluation, bones);
    let runs = over_runs_from(&scanned.times, |first, run| {
        let mut source: Option<BonesEvaluator> = None;
        let mut scales = group.scales(evaluation);
        let mut probe = Probe::new(&evaluation.hierarchy);
        let mut local = vec![Transform::IDENTITY; evaluation.skeleton().len()];
        let mut samples: Vec<Vec<Sample>> = vec![Vec::with_capacity(run.len()); bones.len()];
        let mut now: Vec<AtTime> = Vec::with_capacity(bones.len());
        for (sample, &time) in (first..).zip(run) {
            now.clear();
            now.extend(bones.iter().map(|&bone| AtTime::new(scanned.stretched_at(bone, sample))));
            if now.iter().any(|bone| bone.stretched) {
                if let Some(scales) = &mut scales {
                    group.certain_causes(scales.read(time), &mut now, tolerances);
                }
                if now.iter().any(|bone| bone.open) {
                    let source = source.get_or_insert_with(|| BonesEvaluator::new(evaluation, &group.evaluated));
                    let pose = source.evaluate(time);
                    group.evaluated.iter().for_each(|&b| local[b] = pose.local[b]);
                    for (bone, &b) in now.iter_mut().zip(bones).filter(|(bone, _)| bone.open) {
                        bone.shear = column_shear(&pose.model.model[b]);
                    }
                    group.find_main_causes(&mut probe, &mut local, &mut now, tolerances);
                }
            }
            for (samples, bone) in samples.iter_mut().zip(&now) {
                samples.push(Sample { stretched: bone.stretched, main_cause: bone.main_cause });
            }
        }
        samples
    });
    let mut each: Vec<Vec<Sample>> = vec![Vec::with_capacity(scanned.times.len()); bones.len()];
    for run in runs {
        each.iter_mut().zip(run).for_each(|(samples, run)| samples.extend(run));
    }
    each
}

/// Bones whose causes one pass finds: the bones evaluated for them, and what each squash made uniform changes.
struct Group<'b> {
    bones: &'b [usize],
    /// Each bone's chain, the root first.
    chains: Vec<Vec<usize>>,
    /// Per bone, whether every bone of its chain passes its stretch down as a product of local matrices (full
    /// inheritance, or a root): what [`Group::certain_causes`] reasons from.
    products: Vec<bool>,
    /// The bones and their ancestors, parents first.
    evaluated: Vec<usize>,
    /// Per bone of the rig, the bones of the group below it (itself included), by their place in the group.
    below: Vec<Vec<usize>>,
    /// Per bone of the rig, found when its squash is first made uniform: the chains of the bones below it, parents
    /// first (what the squash made uniform needs evaluated).
    reach: Vec<OnceLock<Vec<usize>>>,
}

/// The local scales of some bones, read from the clip one time after another.
struct Scales<'a> {
    cursors: Vec<(usize, BoneCursor<'a>)>,
    /// By bone: the scale at the time last read (the others' entries mean nothing).
    at: Vec<DVec3>,
}

impl Scales<'_> {
    fn read(&mut self, time: f64) -> &[DVec3] {
        for (b, cursor) in &mut self.cursors {
            self.at[*b] = cursor.scale(time);
        }
        &self.at
    }
}

/// One bone of a group at one time: whether it is flagged, whether its main cause is still to be found from the
/// matrices (`open`), its shear on the matrix there, and the largest contribution to it found so far with its bone.
struct AtTime {
    stretched: bool,
    open: bool,
    shear: f64,
    largest: f64,
    main_cause: Option<usize>,
}

impl AtTime {
    fn new(stretched: bool) -> Self {
        AtTime { stretched, open: stretched, shear: 0.0, largest: 0.0, main_cause: None }
    }
}

impl<'b> Group<'b> {
    fn new(evaluation: &Evaluation, bones: &'b [usize]) -> Self {
        let skeleton = evaluation.skeleton();
        let chains: Vec<Vec<usize>> = bones.iter().map(|&bone| skeleton.chain(bone)).collect();
        let products = chains.iter().map(|chain| chain.iter().all(|&b| evaluation.inherits_fully(b))).collect();
        let mut below: Vec<Vec<usize>> = vec![Vec::new(); skeleton.len()];
        for (k, chain) in chains.iter().enumerate() {
            chain.iter().for_each(|&b| below[b].push(k));
        }
        let reach = (0..skeleton.len()).map(|_| OnceLock::new()).collect();
        Group { bones, chains, products, evaluated: skeleton.with_ancestors(bones), below, reach }
    }

    /// The local scales of the bones the group evaluates, where the clip is read bone by bone (no layers, lengths in
    /// the rig's unit) and some chain is a product of local matrices: [`Group::certain_causes`] reads them alone.
    fn scales<'a>(&self, evaluation: &Evaluation<'a>) -> Option<Scales<'a>> {
        let clip = evaluation.clip.filter(|_| evaluation.reads_bone_by_bone() && self.products.contains(&true))?;
        let cursors = self.evaluated.iter().map(|&b| (b, BoneCursor::new(evaluation.skeleton(), clip, b))).collect();
        Some(Scales { cursors, at: vec![DVec3::ONE; evaluation.skeleton().len()] })
    }

    /// The main causes that the local scales alone settle (`scales`, by bone); `now`'s bones left open are not. A
    /// flagged bone whose chain holds no unequal scale has none; one whose chain holds one has it, wherever the
    /// chain's other scales are too near uniform to shear it by half the shear tolerance once that one is made
    /// uniform ([`largest_shear_deg`] of the product of their condition numbers), since a flagged bone shears by
    /// more than the tolerance: the squash made uniform takes shear away, as the matrices would say.
    fn certain_causes(&self, scales: &[DVec3], now: &mut [AtTime], tolerances: &Tolerances) {
        for (k, bone) in now.iter_mut().enumerate().filter(|(k, bone)| bone.stretched && self.products[*k]) {
            let (mut squashes, mut squash, mut others) = (0, None, 1.0);
            for &b in &self.chains[k] {
                if anisotropy(scales[b]) > tolerances.min_anisotropy {
                    (squashes, squash) = (squashes + 1, Some(b));
                } else {
                    others *= condition(scales[b]);
                }
            }
            if squashes == 0 || (squashes == 1 && largest_shear_deg(others) < 0.5 * tolerances.min_shear_deg) {
                (bone.main_cause, bone.open) = (squash, false);
            }
        }
    }

    /// What `squash` made uniform needs evaluated ([`Group::reach`]).
    fn reach(&self, squash: usize) -> &[usize] {
        self.reach[squash].get_or_init(|| {
            let mut bones: Vec<usize> =
                self.below[squash].iter().flat_map(|&k| self.chains[k].iter().copied()).collect();
            // Parents come first in bone order.
            bones.sort_unstable();
            bones.dedup();
            bones
        })
    }

    /// The main cause at one time (`local`, the group's bones' local transforms, and `now`) of each open bone: each
    /// squash of the chains made uniform once for every open bone below it, parents first, so that each bone meets
    /// the squashes of its chain in the chain's order.
    fn find_main_causes(
        &self,
        probe: &mut Probe,
        local: &mut [Transform],
        now: &mut [AtTime],
        tolerances: &Tolerances,
    ) {
        for &squash in &self.evaluated {
            if anisotropy(local[squash].scale) <= tolerances.min_anisotropy {
                continue;
            }
            let below = &self.below[squash];
            if !below.iter().any(|&k| now[k].open) {
                continue;
            }
            let models = probe.models(local, self.reach(squash), &[squash]);
            for &k in below {
                let bone = &mut now[k];
                if !bone.open {
                    continue;
                }
                let contribution = bone.shear - column_shear(&models[self.bones[k]]);
                if contribution > bone.largest && contributes(contribution, tolerances) {
                    (bone.largest, bone.main_cause) = (contribution, Some(squash));
                }
            }
        }
    }
}

/// One sample of the explained bone over a clip.
#[derive(Clone, Copy, Debug)]
struct Sample {
    stretched: bool,
    /// The chain bone whose uniform scale removes the most shear, when the bone is flagged and one removes more
    /// than rounding does ([`contributes`]).
    main_cause: Option<usize>,
}

/// The runs of samples with one main cause: each span reaches the next sample's time while that sample is still
/// in it or is the first one after it.
fn spans(skeleton: &Skeleton, samples: &[Sample], times: &[f64]) -> Vec<CauseSpan> {
    let mut spans: Vec<CauseSpan> = Vec::new();
    let mut open: Option<&mut CauseSpan> = None;
    for (sample, &time) in samples.iter().zip(times) {
        if let Some(span) = open.take() {
            span.to = time;
            open = (Some(span.bone) == sample.main_cause).then_some(span);
        }
        if open.is_none()
            && let Some(bone) = sample.main_cause
        {
            spans.push(CauseSpan { bone, name: skeleton.bone(bone).name.clone(), from: time, to: time });
            open = spans.last_mut();
        }
    }
    spans
}

/// Model matrices with some bones' scales made uniform.
struct Probe<'a> {
    hierarchy: &'a Hierarchy,
    model: ModelPose,
    /// The local transforms a call replaces, put back after it (kept: the call is made per sample and bone).
    saved: Vec<Transform>,
}

impl<'a> Probe<'a> {
    fn new(hierarchy: &'a Hierarchy) -> Self {
        Probe { hierarchy, model: ModelPose::default(), saved: Vec::new() }
    }

    /// The model matrices of `bones` (parents first, each with its ancestors; the other bones' entries mean nothing)
    /// with the scales of `uniform` made uniform in `local` (which is left as it was).
    fn models(&mut self, local: &mut [Transform], bones: &[usize], uniform: &[usize]) -> &[DMat4] {
        self.saved.clear();
        self.saved.extend(uniform.iter().map(|&b| local[b]));
        uniform.iter().for_each(|&b| uniform_scale(&mut local[b]));
        self.hierarchy.evaluate_bones(local, bones, &mut self.model);
        uniform.iter().zip(&self.saved).for_each(|(&b, t)| local[b] = *t);
        &self.model.model
    }
}

/// The shear of `m`'s columns in degrees.
fn column_shear(m: &DMat4) -> f64 {
    shear_deg(&DMat3::from_mat4(*m))
}

/// The largest shear, in degrees, of a matrix whose condition number is at most `condition`: it turns orthogonal
/// directions at most `asin((κ² − 1)/(κ² + 1))` off a right angle (Wielandt's inequality), and the condition number
/// of a product is at most the product of its factors'.
fn largest_shear_deg(condition: f64) -> f64 {
    (1.0 - 2.0 / (condition * condition + 1.0)).asin().to_degrees()
}

/// `max|k|/min|k|`, the condition number of a matrix scaling by `scale` (infinite for a zero scale).
fn condition(scale: DVec3) -> f64 {
    let k = scale.abs();
    let (min, max) = (k.min_element(), k.max_element());
    if min > 0.0 { max / min } else { f64::INFINITY }
}

/// `max|k|/min|k| − 1` (0 for a zero scale: nothing to compare).
fn anisotropy(scale: DVec3) -> f64 {
    if scale.abs().min_element() > 0.0 { condition(scale) - 1.0 } else { 0.0 }
}

/// The link of bone `bone`, whose local transform is `local` and whose chain down to the explained bone turns by
/// `below`.
fn link(
    skeleton: &Skeleton,
    bone: usize,
    local: &Transform,
    below: Option<DQuat>,
    shear: f64,
    shear_left: f64,
    tolerances: &Tolerances,
) -> Link {
    // The scale's axes seen from the explained bone: columns of `Rᵀ·U`; their angle to the child's own axes is that of a
    // stretch rotation, up to the symmetries of the factors.
    let turn = below.map(|rotation| {
        let seen = AffineParts {
            stretch: rotation.conjugate() * local.stretch,
            scale: local.scale.abs(),
            ..AffineParts::IDENTITY
        };
        seen.stretch_angle_deg_within(tolerances.min_anisotropy)
    });
    Link {
        bone,
        name: skeleton.bone(bone).name.clone(),
        scale: local.scale,
        anisotropy: anisotropy(local.scale),
        turn_deg: turn,
        shear_left_deg: shear_left,
        // A difference within rounding is none (and never prints as −0).
        contribution_deg: if (shear - shear_left).abs() < SAME_SHEAR_DEG { 0.0 } else { shear - shear_left },
    }
}

/// The most subsets searched for the fewest bones that suffice; past it, bones are added greedily.
const EXHAUSTIVE_CANDIDATES: usize = 12;

/// The fewest bones of `links` (among those scaled unequally) whose uniform scales together leave the bone
/// unflagged: every subset by size, or greedily by contribution for a long chain of squashes. `matrix` is the bone's
/// model matrix with some scales of `local` made uniform.
fn sufficient(
    matrix: &mut impl FnMut(&mut [Transform], &[usize]) -> DMat4,
    local: &mut [Transform],
    links: &[Link],
    tolerances: &Tolerances,
) -> Vec<usize> {
    let mut candidates: Vec<&Link> = links.iter().filter(|l| l.anisotropy > tolerances.min_anisotropy).collect();
    candidates.sort_by(|a, b| b.contribution_deg.total_cmp(&a.contribution_deg));
    let mut clears = |bones: &[usize]| !Assessment::of(&matrix(local, bones), tolerances).findings.stretched;
    let found = if candidates.len() <= EXHAUSTIVE_CANDIDATES {
        let mut masks: Vec<u32> = (1..1u32 << candidates.len()).collect();
        masks.sort_by_key(|m| m.count_ones());
        masks.into_iter().map(|mask| pick(&candidates, mask)).find(|bones| clears(bones))
    } else {
        (1..=candidates.len())
            .map(|n| candidates[..n].iter().map(|l| l.bone).collect::<Vec<_>>())
            .find(|bones| clears(bones))
    };
    let mut bones = found.unwrap_or_default();
    bones.sort_unstable();
    bones
}

/// The bones of the candidates whose bits are set in `mask`.
fn pick(candidates: &[&Link], mask: u32) -> Vec<usize> {
    candidates.iter().enumerate().filter(|(i, _)| mask >> i & 1 == 1).map(|(_, l)| l.bone).collect()
}

#[cfg(test)]
mod tests {
    use proptest::prelude::*;

    use super::*;
    use crate::math::strategies::unit_quat as quat;

    proptest! {
        /// A chain of turned, unequally scaled bones shears no more than the product of their scales' condition
        /// numbers allows, near uniform or far from it.
        #[test]
        fn a_chain_shears_at_most_as_its_scales_condition_allows(
            chain in prop::collection::vec((quat(), quat(), prop::array::uniform3(0.0..1.0f64)), 1..10),
            spread in prop_oneof![Just(1e-4), Just(1e-2), Just(1.0)],
        ) {
            let (mut model, mut condition) = (DMat4::IDENTITY, 1.0);
            for (rotation, stretch, scale) in &chain {
                let scale = DVec3::from_array(scale.map(|k| 1.0 + spread * k));
                let local = Transform { translation: DVec3::X, rotation: *rotation, scale, stretch: *stretch };
                model *= local.matrix();
                condition *= super::condition(scale);
            }
            let shear = column_shear(&model);
            prop_assert!(shear <= largest_shear_deg(condition) + 1e-9, "{shear} > {}", largest_shear_deg(condition));
        }
    }

    #[test]
    fn the_largest_shear_of_a_condition_number() {
        // diag(κ, 1) turned 45°: columns (κ+1, κ−1)/2 and (κ−1, κ+1)/2 meet at cos = (κ²−1)/(κ²+1), the bound.
        let kappa: f64 = 1.5;
        let m = DMat3::from_quat(DQuat::from_rotation_z(std::f64::consts::FRAC_PI_4))
            * DMat3::from_diagonal(DVec3::new(kappa, 1.0, 1.0))
            * DMat3::from_quat(DQuat::from_rotation_z(-std::f64::consts::FRAC_PI_4));
        let reached = column_shear(&DMat4::from_mat3(m));
        assert!((reached - largest_shear_deg(kappa)).abs() < 1e-12, "{reached} against {}", largest_shear_deg(kappa));
        assert_eq!(largest_shear_deg(1.0), 0.0);
        assert_eq!(largest_shear_deg(f64::INFINITY), 90.0, "a zero scale shears without bound");
    }
}
