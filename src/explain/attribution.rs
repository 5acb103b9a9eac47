//! Whose scale shears a bone: every bone of its chain asked how much shear is left without its squash.

use std::sync::OnceLock;

use glam::{DMat3, DMat4, DQuat, DVec3};
use rayon::prelude::*;

use crate::analysis::{Assessment, SAME_SHEAR_DEG, Tolerances};
use crate::eval::layers::uniform_scale;
use crate::eval::{BonesEvaluator, Evaluation, Hierarchy, ModelPose, over_runs};
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
    /// The fewest bones of the chain whose scales, all made uniform, leave the bone unflagged (empty when it is
    /// not flagged). Contributions need not add up, since scales compound and cancel; this set is what suffices.
    pub sufficient: Vec<usize>,
}

impl Attribution {
    /// The bone whose squash causes the most shear, if any causes some.
    pub fn main_cause(&self) -> Option<&Link> {
        self.chain
            .iter()
            .filter(|l| l.contribution_deg > 0.0)
            .max_by(|a, b| a.contribution_deg.total_cmp(&b.contribution_deg))
    }
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
    let stretched = assessment.findings.stretched;
    let sufficient = if stretched { sufficient(&mut matrix, &mut local, &links, tolerances) } else { Vec::new() };
    Attribution { bone, time, shear_deg: shear, stretched, chain: links, sufficient }
}

/// Why `bone` shears over `times` (sorted) of `evaluation`, with the detail at `at` (the worst time for `None`).
pub fn causes(evaluation: &Evaluation, bone: usize, times: &[f64], at: Option<f64>, tolerances: &Tolerances) -> Causes {
    causes_each(evaluation, &[(bone, at)], times, tolerances).pop().expect("one bone asked")
}

/// How many bones' causes one pass over the clip finds ([`causes_each`]): each holds a sample per time while the
/// pass runs.
const TOGETHER: usize = 8;

/// [`causes`] of each of `bones` (each with the time to detail), in the order asked: a few at a time in bone
/// order (the bones of one chain lie together), the groups in parallel. A group's chains are evaluated once per time
/// for all its bones, and each squash on them made uniform once for every flagged bone below it.
pub fn causes_each(
    evaluation: &Evaluation,
    bones: &[(usize, Option<f64>)],
    times: &[f64],
    tolerances: &Tolerances,
) -> Vec<Causes> {
    let mut order: Vec<usize> = (0..bones.len()).collect();
    order.sort_by_key(|&i| bones[i].0);
    let groups: Vec<Vec<(usize, Causes)>> = order
        .par_chunks(TOGETHER)
        .map(|group| {
            let asked: Vec<usize> = group.iter().map(|&i| bones[i].0).collect();
            let samples = samples_of(evaluation, &asked, times, tolerances);
            let summarised = group.iter().zip(samples).map(|(&i, samples)| {
                let (bone, at) = bones[i];
                (i, summarised(evaluation, bone, &samples, times, at, tolerances))
            });
            summarised.collect()
        })
        .collect();
    let mut causes: Vec<(usize, Causes)> = groups.into_iter().flatten().collect();
    causes.sort_by_key(|(i, _)| *i);
    causes.into_iter().map(|(_, causes)| causes).collect()
}

/// `bone`'s causes from its `samples` at `times`, with the detail at `at` (the worst time for `None`).
fn summarised(
    evaluation: &Evaluation,
    bone: usize,
    samples: &[Sample],
    times: &[f64],
    at: Option<f64>,
    tolerances: &Tolerances,
) -> Causes {
    // The first flagged sample with the largest shear (the largest shear where none is flagged).
    let key = |s: &Sample| (s.stretched, s.shear_deg);
    let worst = (0..samples.len()).reduce(|w, s| if key(&samples[s]) > key(&samples[w]) { s } else { w });
    let worst = worst.map_or(0.0, |s| times[s]);
    let time = at.unwrap_or(worst);
    Causes {
        samples: samples.len(),
        stretched_samples: samples.iter().filter(|s| s.stretched).count(),
        at: attribute(evaluation, bone, time, tolerances),
        spans: spans(evaluation.skeleton(), samples, times),
    }
}

/// Each of `bones`' samples at `times`: its shear and verdict, and where it is flagged its main cause, the bone of its
/// chain, among those scaled unequally, whose uniform scale leaves the least shear (shears measured on the matrix,
/// without a decomposition).
fn samples_of(evaluation: &Evaluation, bones: &[usize], times: &[f64], tolerances: &Tolerances) -> Vec<Vec<Sample>> {
    let group = Group::new(evaluation.skeleton(), bones);
    let runs = over_runs(times, |run| {
        let mut source = BonesEvaluator::new(evaluation, &group.evaluated);
        let mut probe = Probe::new(&evaluation.hierarchy);
        let mut local = vec![Transform::IDENTITY; evaluation.skeleton().len()];
        let mut starts = vec![DQuat::IDENTITY; bones.len()];
        let mut samples: Vec<Vec<Sample>> = vec![Vec::with_capacity(run.len()); bones.len()];
        let mut now: Vec<AtTime> = Vec::with_capacity(bones.len());
        for &time in run {
            let pose = source.evaluate(time);
            group.evaluated.iter().for_each(|&b| local[b] = pose.local[b]);
            now.clear();
            now.extend(bones.iter().zip(&mut starts).map(|(&bone, start)| {
                let m = &pose.model.model[bone];
                let assessment = Assessment::near(m, tolerances, *start);
                *start = assessment.parts.stretch;
                AtTime { assessment, shear: column_shear(m), largest: 0.0, main_cause: None }
            }));
            group.find_main_causes(&mut probe, &mut local, &mut now, tolerances);
            for (samples, bone) in samples.iter_mut().zip(&now) {
                let AtTime { assessment, main_cause, .. } = bone;
                let (shear_deg, stretched) = (assessment.shear_deg, assessment.findings.stretched);
                samples.push(Sample { shear_deg, stretched, main_cause: *main_cause });
            }
        }
        samples
    });
    let mut each: Vec<Vec<Sample>> = vec![Vec::with_capacity(times.len()); bones.len()];
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
    /// The bones and their ancestors, parents first.
    evaluated: Vec<usize>,
    /// Per bone of the rig, the bones of the group below it (itself included), by their place in the group.
    below: Vec<Vec<usize>>,
    /// Per bone of the rig, found when its squash is first made uniform: the chains of the bones below it, parents
    /// first (what the squash made uniform needs evaluated).
    reach: Vec<OnceLock<Vec<usize>>>,
}

/// One bone of a group at one time: its verdict, its shear on the matrix, and the largest contribution to it found
/// so far with its bone.
struct AtTime {
    assessment: Assessment,
    shear: f64,
    largest: f64,
    main_cause: Option<usize>,
}

impl<'b> Group<'b> {
    fn new(skeleton: &Skeleton, bones: &'b [usize]) -> Self {
        let chains: Vec<Vec<usize>> = bones.iter().map(|&bone| skeleton.chain(bone)).collect();
        let mut below: Vec<Vec<usize>> = vec![Vec::new(); skeleton.len()];
        for (k, chain) in chains.iter().enumerate() {
            chain.iter().for_each(|&b| below[b].push(k));
        }
        let reach = (0..skeleton.len()).map(|_| OnceLock::new()).collect();
        Group { bones, chains, evaluated: skeleton.with_ancestors(bones), below, reach }
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

    /// Each flagged bone's main cause at one time (`local`, the group's bones' local transforms, and `now`): each
    /// squash of the chains made uniform once for every flagged bone below it, parents first, so that each bone meets
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
            if !below.iter().any(|&k| now[k].assessment.findings.stretched) {
                continue;
            }
            let models = probe.models(local, self.reach(squash), &[squash]);
            for &k in below {
                let bone = &mut now[k];
                if !bone.assessment.findings.stretched {
                    continue;
                }
                let contribution = bone.shear - column_shear(&models[self.bones[k]]);
                if contribution > bone.largest {
                    (bone.largest, bone.main_cause) = (contribution, Some(squash));
                }
            }
        }
    }
}

/// One sample of the explained bone over a clip.
#[derive(Clone, Copy, Debug)]
struct Sample {
    shear_deg: f64,
    stretched: bool,
    /// The chain bone whose uniform scale removes the most shear, when the bone is flagged.
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

/// `max|k|/min|k| − 1` (0 for a zero scale: nothing to compare).
fn anisotropy(scale: DVec3) -> f64 {
    let k = scale.abs();
    let (min, max) = (k.min_element(), k.max_element());
    if min > 0.0 { max / min - 1.0 } else { 0.0 }
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
