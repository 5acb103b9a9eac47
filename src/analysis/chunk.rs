//! One parallel work item of a whole-clip analysis: a run of consecutive sample times, every bone judged at each,
//! curves of the plotted bones.
//!
//! Verdicts come from each bone's [`Stretch`] passed down the hierarchy (see `stretch.rs`). A clip without layers
//! on a fully inheriting rig is judged bone by bone, each bone over the whole run before the next: only the
//! channels a stretch needs are read (scales everywhere, rotations below non-uniform scale), one track at a time,
//! and a bone whose stretch cannot change in the run is judged once. Layers, or bones that inherit otherwise, need
//! whole poses: those runs are judged sample by sample.

use glam::{DMat4, DQuat};

use super::clip_analysis::{BoneSummary, Components};
use super::findings::{Judge, Verdict};
use super::request::{CurveRequest, Judged, ScanOptions};
use super::stretch::{CursorAt, Stretch};
use crate::eval::{BoneCursor, BonesEvaluator, Chains, Evaluation, Hierarchy};
use crate::math::{decompose_near, decompose_with_stretch};
use crate::model::{BoneTracks, Clip, Transform};

/// What the workers need to know about the evaluation, found once per analysis.
pub(super) struct Plan<'a> {
    hierarchy: &'a Hierarchy,
    /// The clip, when it is judged bone by bone: no layers, every bone inheriting fully (or a root).
    by_bone: Option<&'a Clip>,
    /// Each bone's parent, and whether its stretch passes down from it ([`Stretch::child`]:
    /// [`Evaluation::inherits_fully`]) rather than coming from its model matrix.
    parents: Vec<Option<usize>>,
    inherits: Vec<bool>,
    /// How many children each bone has: a bone's stretches are dropped once they are all judged.
    children: Vec<usize>,
    /// What a root inherits: the stretch of the skeleton's unit conversion (a uniform scale).
    root: Run,
    /// Per bone, what its model scale factors are divided by to be the authored ones ([`Skeleton::length_scales`]).
    length_scales: Vec<f64>,
    /// Whether the clip changes each bone's scale, and its rotation, over time (constant tracks do not).
    varying_scale: Vec<bool>,
    varying_rotation: Vec<bool>,
    /// The plotted bones and their ancestors, parents first: their local and model matrices are evaluated.
    modelled: Vec<usize>,
    /// The bones judged, parents first: every bone, or the modelled ones ([`Judged`]).
    judged: Vec<usize>,
}

impl<'a> Plan<'a> {
    pub fn new(evaluation: &'a Evaluation, plotted: &[usize], judged: Judged) -> Self {
        let (skeleton, hierarchy) = (evaluation.skeleton(), &evaluation.hierarchy);
        let parents: Vec<Option<usize>> = (0..skeleton.len()).map(|b| skeleton.parent(b)).collect();
        let inherits: Vec<bool> = (0..skeleton.len()).map(|b| evaluation.inherits_fully(b)).collect();
        let by_bone = evaluation.clip.filter(|_| evaluation.layers().is_none() && inherits.iter().all(|&full| full));
        let varying = |track: fn(&BoneTracks) -> bool| -> Vec<bool> {
            (0..skeleton.len()).map(|b| by_bone.and_then(|c| c.tracks_of(b)).is_some_and(track)).collect()
        };
        let mut children = vec![0; parents.len()];
        parents.iter().flatten().for_each(|&p| children[p] += 1);
        Plan {
            hierarchy,
            by_bone,
            inherits,
            parents,
            children,
            root: Run::Fixed(Stretch::uniform(skeleton.placement().conversion_scale())),
            length_scales: skeleton.length_scales().to_vec(),
            varying_scale: varying(|t| t.scale.as_ref().is_some_and(|s| !s.is_constant())),
            varying_rotation: varying(|t| t.rotation.as_ref().is_some_and(|r| !r.is_constant())),
            modelled: skeleton.with_ancestors(plotted),
            judged: match judged {
                Judged::Every => (0..skeleton.len()).collect(),
                Judged::CurveChains => skeleton.with_ancestors(plotted),
                Judged::Subtree(top) => skeleton.with_ancestors(&skeleton.subtree(top)),
                Judged::Chain(bone) => skeleton.with_ancestors(&[bone]),
            },
        }
    }
}

/// What one chunk of samples produced, for each bone it holds (every bone of the rig, or a few: see
/// [`super::scan::assemble`]), by their place among them.
pub(super) struct ChunkResult {
    pub summaries: Vec<BoneSummary>,
    /// `words` words of flags per bone.
    pub bits: Vec<u64>,
    pub words: usize,
}

impl ChunkResult {
    pub fn new(bones: usize, samples: usize) -> Self {
        let words = samples.div_ceil(64);
        ChunkResult { summaries: (0..bones).map(BoneSummary::new).collect(), bits: vec![0; bones * words], words }
    }

    /// Whether `bone` is flagged at any of the chunk's samples.
    pub fn flagged(&self, bone: usize) -> bool {
        self.bits[bone * self.words..][..self.words].iter().any(|&word| word != 0)
    }

    pub fn add(&mut self, bone: usize, sample: usize, time: f64, verdict: &Verdict) {
        self.summaries[bone].add(time, verdict);
        self.bits[bone * self.words + sample / 64] |= u64::from(verdict.findings.stretched) << (sample % 64);
    }

    /// `verdict` for `bone` at every one of `times`.
    fn add_throughout(&mut self, bone: usize, times: &[f64], verdict: &Verdict) {
        self.add(bone, 0, times[0], verdict);
        self.summaries[bone].repeat(times.len() - 1, verdict);
        if verdict.findings.stretched {
            let words = &mut self.bits[bone * self.words..][..self.words];
            for (w, word) in words.iter_mut().enumerate() {
                let bits = times.len().saturating_sub(64 * w).min(64);
                *word = if bits == 64 { u64::MAX } else { (1 << bits) - 1 };
            }
        }
    }
}

/// The part of every requested curve that one chunk fills, one slice per plotted bone (none for the ghost
/// without one).
#[derive(Default)]
pub(super) struct CurveSlices<'a> {
    pub local: Vec<&'a mut [Components]>,
    pub model: Vec<&'a mut [Components]>,
    pub ghost_model: Vec<&'a mut [Components]>,
}

/// Analyses the samples at `times`, writing the plotted bones' components into `curves`.
pub(super) fn analyze_chunk(
    evaluation: &Evaluation,
    plan: &Plan,
    request: CurveRequest,
    options: &ScanOptions,
    times: &[f64],
    mut curves: CurveSlices,
) -> ChunkResult {
    let chunk = Chunk { evaluation, plan, request, judge: Judge::new(&options.tolerances), times };
    let mut result = ChunkResult::new(evaluation.skeleton().len(), times.len());
    match plan.by_bone {
        Some(clip) => {
            let plotted = chunk.judge_by_bone(clip, &mut result);
            chunk.plot_by_bone(clip, &plotted, &mut curves);
        }
        None => chunk.judge_by_pose(&mut BonesEvaluator::new(evaluation, &plan.judged), &mut result, &mut curves),
    }
    if let Some(ghost) = request.ghost {
        chunk.plot_ghost(ghost, &mut curves.ghost_model);
    }
    result
}

/// One bone's stretches over the run.
#[derive(Clone)]
enum Run {
    /// The same at every sample.
    Fixed(Stretch),
    /// One per sample.
    Varying(Vec<Stretch>),
    /// Dropped once every child was judged.
    Done,
}

impl Run {
    /// The stretch at `sample`.
    fn at(&self, sample: usize) -> Stretch {
        match self {
            Run::Varying(stretches) => stretches[sample],
            Run::Fixed(stretch) => *stretch,
            Run::Done => unreachable!("a bone's stretches are kept while they are needed"),
        }
    }
}

/// One chunk's work: the evaluation and what to compute at `times`.
struct Chunk<'a> {
    evaluation: &'a Evaluation<'a>,
    plan: &'a Plan<'a>,
    request: CurveRequest<'a>,
    judge: Judge,
    times: &'a [f64],
}

impl Chunk<'_> {
    /// Judges every bone of a fully inheriting rig, one bone over all the times before the next. Returns the
    /// plotted bones' stretches.
    fn judge_by_bone(&self, clip: &Clip, result: &mut ChunkResult) -> Vec<Run> {
        let (skeleton, plan, times) = (self.evaluation.skeleton(), self.plan, self.times);
        let mut runs: Vec<Run> = (0..skeleton.len()).map(|_| Run::Done).collect();
        let mut pending_children = plan.children.clone();
        let mut spare: Vec<Vec<Stretch>> = Vec::new();
        for &bone in &plan.judged {
            let mut cursor = BoneCursor::new(skeleton, clip, bone);
            let above = plan.parents[bone].map_or(&plan.root, |p| &runs[p]);
            // A bone the clip does not scale, under a fixed stretch that is uniform or with a rotation that does
            // not change, keeps one stretch throughout.
            let fixed = match above {
                Run::Fixed(above) if !plan.varying_scale[bone] => {
                    (above.is_uniform() || !plan.varying_rotation[bone]).then_some(*above)
                }
                _ => None,
            };
            let run = match fixed {
                Some(above) => {
                    let stretch = above.child(&mut CursorAt(&mut cursor, times[0]), DQuat::IDENTITY, &self.judge);
                    result.add_throughout(bone, times, &stretch.verdict(&self.judge));
                    Run::Fixed(stretch)
                }
                None => {
                    let mut stretches = spare.pop().unwrap_or_default();
                    stretches.clear();
                    let mut start = DQuat::IDENTITY;
                    for (sample, &time) in times.iter().enumerate() {
                        let stretch = above.at(sample).child(&mut CursorAt(&mut cursor, time), start, &self.judge);
                        start = stretch.frame();
                        result.add(bone, sample, time, &stretch.verdict(&self.judge));
                        stretches.push(stretch);
                    }
                    Run::Varying(stretches)
                }
            };
            runs[bone] = run;
            if let Some(parent) = plan.parents[bone] {
                pending_children[parent] -= 1;
                if pending_children[parent] == 0
                    && !self.request.bones.contains(&parent)
                    && let Run::Varying(stretches) = std::mem::replace(&mut runs[parent], Run::Done)
                {
                    spare.push(stretches);
                }
            }
        }
        self.request.bones.iter().map(|&b| runs[b].clone()).collect()
    }

    /// The curves of the plotted bones, from their local transforms and those of their ancestors.
    /// `stretches` are the plotted bones' (see [`Chunk::judge_by_bone`]).
    fn plot_by_bone(&self, clip: &Clip, stretches: &[Run], curves: &mut CurveSlices) {
        let (plan, bones) = (self.plan, self.request.bones);
        if bones.is_empty() {
            return;
        }
        let mut chains = Chains::new(self.evaluation.skeleton(), clip, &plan.modelled);
        let mut plot = Plotter::new(bones.len(), &self.plan.length_scales);
        for (sample, &time) in self.times.iter().enumerate() {
            let pose = chains.evaluate(time, plan.hierarchy);
            let stretches = stretches.iter().map(|run| run.at(sample));
            plot.put(sample, bones, &pose.local, &pose.model.model, stretches, curves);
        }
    }

    /// The ghost curves: the plotted bones as `ghost` (the same rig and clip) evaluates them. Without layers only
    /// the plotted bones and their ancestors are sampled and evaluated; through layers, whole poses.
    fn plot_ghost(&self, ghost: &Evaluation, curves: &mut [&mut [Components]]) {
        let bones = self.request.bones;
        let mut evaluator = BonesEvaluator::new(ghost, &self.plan.modelled);
        // Where each ghost curve's decomposition starts: its stretch frame at the previous sample.
        let mut starts = vec![DQuat::IDENTITY; bones.len()];
        for (sample, &time) in self.times.iter().enumerate() {
            let pose = evaluator.evaluate(time);
            for ((curve, &bone), start) in curves.iter_mut().zip(bones).zip(&mut starts) {
                let parts = decompose_near(&pose.model.model[bone], *start);
                let components =
                    Components::of_parts(&parts.authored(self.plan.length_scales[bone]), &pose.model.model[bone]);
                *start = components.stretch.as_dquat();
                curve[sample] = components;
            }
        }
    }

    /// Judges the bones from poses, one sample after another (layers, or bones that do not inherit fully): of the
    /// judged bones alone where the clip reads bone by bone, else whole. Keeps the plotted bones' curves on the way.
    fn judge_by_pose(&self, evaluator: &mut BonesEvaluator, result: &mut ChunkResult, curves: &mut CurveSlices) {
        let (plan, plotted) = (self.plan, self.request.bones);
        let bones = self.evaluation.skeleton().len();
        let mut stretches = vec![Stretch::NONE; bones];
        let mut plot = Plotter::new(plotted.len(), &plan.length_scales);
        for (sample, &time) in self.times.iter().enumerate() {
            let pose = evaluator.evaluate(time);
            for &bone in &plan.judged {
                let start = stretches[bone].frame();
                let stretch = match plan.parents[bone] {
                    _ if !plan.inherits[bone] => Stretch::of_matrix(&pose.model.model[bone], start),
                    Some(parent) => stretches[parent].child(&mut &pose.local[bone], start, &self.judge),
                    None => plan.root.at(sample).child(&mut &pose.local[bone], start, &self.judge),
                };
                stretches[bone] = stretch;
                result.add(bone, sample, time, &stretch.verdict(&self.judge));
            }
            let judged = plotted.iter().map(|&bone| stretches[bone]);
            plot.put(sample, plotted, &pose.local, &pose.model.model, judged, curves);
        }
    }
}

/// Writes the plotted bones' components, sample by sample.
struct Plotter<'a> {
    /// Where each plotted bone's decomposition starts: its stretch frame at the previous sample.
    starts: Vec<DQuat>,
    /// [`Plan::length_scales`].
    length_scales: &'a [f64],
}

impl<'a> Plotter<'a> {
    fn new(bones: usize, length_scales: &'a [f64]) -> Self {
        Plotter { starts: vec![DQuat::IDENTITY; bones], length_scales }
    }

    /// Sample `sample` of `bones`, given every bone's local transform and model matrix (only the plotted ones are
    /// read) and the plotted bones' judged stretches: dividing a stretch out of the model matrix gives its parts
    /// without an SVD (see [`decompose_with_stretch`]).
    fn put(
        &mut self,
        sample: usize,
        bones: &[usize],
        local: &[Transform],
        model: &[DMat4],
        stretches: impl Iterator<Item = Stretch>,
        out: &mut CurveSlices,
    ) {
        let curves = out.local.iter_mut().zip(&mut out.model);
        for ((((local_curve, model_curve), &bone), start), stretch) in
            curves.zip(bones).zip(&mut self.starts).zip(stretches)
        {
            let m = &model[bone];
            let parts = stretch
                .factors()
                .and_then(|(frame, scale, sign)| decompose_with_stretch(m, frame, scale, sign))
                .unwrap_or_else(|| decompose_near(m, *start));
            *start = parts.stretch;
            model_curve[sample] = Components::of_parts(&parts.authored(self.length_scales[bone]), m);
            local_curve[sample] = Components::of_matrix(&local[bone].matrix(), DQuat::IDENTITY);
        }
    }
}
