//! Whole-clip analysis: every key time plus a fixed rate, every bone, in parallel. Summarised per bone for the
//! whole rig (cheap to keep for any rig); full component curves only for the bones asked for (plotted ones).

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

use glam::{DMat4, DQuat, DVec3, Quat, Vec3};
use rayon::prelude::*;

use super::findings::{Judge, Verdict};
use super::stretch::Stretch;
use super::{Assessment, Tolerances};
use crate::eval::{ClipCursor, Hierarchy, LayerStack, Pose};
use crate::math::{angle_of_half_cosine, shear_deg_of_cosine};
use crate::model::{BoneTracks, Clip, InheritMode, Rig, Skeleton};

/// How a clip is scanned.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ScanOptions {
    /// Samples per second on top of the key times (default 60).
    pub rate: f64,
    pub tolerances: Tolerances,
}

impl Default for ScanOptions {
    fn default() -> Self {
        ScanOptions { rate: 60.0, tolerances: Tolerances::default() }
    }
}

/// One bone over a whole clip. Times are in seconds.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct BoneSummary {
    pub index: usize,
    pub worst_shear_deg: f64,
    /// When the worst shear happens (the first such time).
    pub worst_shear_time: f64,
    /// The largest angle of the stretch rotation among stretched samples (see [`Assessment::stretch_deg`]).
    pub worst_stretch_deg: f64,
    /// Samples where the bone is stretched.
    pub flagged_samples: usize,
    /// The first time it is stretched.
    pub first_flagged_time: Option<f64>,
    pub non_uniform_samples: usize,
    pub mirrored_samples: usize,
    pub degenerate_samples: usize,
    /// The worst shear and stretch as the cosines of [`Verdict`], turned into angles once at the end.
    #[serde(skip)]
    worst_shear_cosine: f64,
    #[serde(skip)]
    worst_stretch_half_cosine: f64,
}

impl BoneSummary {
    fn new(index: usize) -> Self {
        BoneSummary {
            index,
            worst_shear_deg: 0.0,
            worst_shear_time: 0.0,
            worst_stretch_deg: 0.0,
            flagged_samples: 0,
            first_flagged_time: None,
            non_uniform_samples: 0,
            mirrored_samples: 0,
            degenerate_samples: 0,
            worst_shear_cosine: 0.0,
            worst_stretch_half_cosine: 1.0,
        }
    }

    /// Adds one sample. The worst angles are kept as cosines until [`BoneSummary::finish`].
    fn add(&mut self, time: f64, verdict: &Verdict) {
        if verdict.shear_cosine > self.worst_shear_cosine {
            self.worst_shear_cosine = verdict.shear_cosine;
            self.worst_shear_time = time;
        }
        let f = verdict.findings;
        if f.stretched {
            self.worst_stretch_half_cosine = self.worst_stretch_half_cosine.min(verdict.stretch_half_cosine);
            self.flagged_samples += 1;
            self.first_flagged_time.get_or_insert(time);
        }
        self.non_uniform_samples += usize::from(f.non_uniform);
        self.mirrored_samples += usize::from(f.mirrored);
        self.degenerate_samples += usize::from(f.degenerate);
    }

    /// Combines the summary of an earlier stretch of time with that of a later one.
    fn merge(&mut self, later: &BoneSummary) {
        if later.worst_shear_cosine > self.worst_shear_cosine {
            self.worst_shear_cosine = later.worst_shear_cosine;
            self.worst_shear_time = later.worst_shear_time;
        }
        self.worst_stretch_half_cosine = self.worst_stretch_half_cosine.min(later.worst_stretch_half_cosine);
        self.flagged_samples += later.flagged_samples;
        self.first_flagged_time = self.first_flagged_time.or(later.first_flagged_time);
        self.non_uniform_samples += later.non_uniform_samples;
        self.mirrored_samples += later.mirrored_samples;
        self.degenerate_samples += later.degenerate_samples;
    }

    /// Adds `count` more samples with the same verdict as the last one added (at later times).
    fn repeat(&mut self, count: usize, verdict: &Verdict) {
        let f = verdict.findings;
        self.flagged_samples += count * usize::from(f.stretched);
        self.non_uniform_samples += count * usize::from(f.non_uniform);
        self.mirrored_samples += count * usize::from(f.mirrored);
        self.degenerate_samples += count * usize::from(f.degenerate);
    }

    /// Turns the worst cosines into angles.
    fn finish(&mut self) {
        self.worst_shear_deg = shear_deg_of_cosine(self.worst_shear_cosine);
        self.worst_stretch_deg = angle_of_half_cosine(self.worst_stretch_half_cosine);
    }

    pub fn stretched(&self) -> bool {
        self.flagged_samples > 0
    }
}

/// The result of scanning one clip.
#[derive(Clone, Debug, PartialEq)]
pub struct ClipScan {
    pub samples: usize,
    /// One per bone, in bone order.
    pub bones: Vec<BoneSummary>,
}

/// The decomposed parts of one matrix at one sample, in single precision (plots need no more, and long clips
/// stay small).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Components {
    pub translation: Vec3,
    pub rotation: Quat,
    pub scale: Vec3,
    pub stretch: Quat,
    pub sign: f32,
    pub shear_deg: f32,
}

impl Components {
    fn of(assessment: &Assessment) -> Self {
        let p = &assessment.parts;
        Components {
            translation: p.translation.as_vec3(),
            rotation: p.rotation.as_quat(),
            scale: p.scale.as_vec3(),
            stretch: p.stretch.as_quat(),
            sign: p.sign as f32,
            shear_deg: assessment.shear_deg as f32,
        }
    }

    /// The translation in double precision, for callers that compare positions.
    pub fn position(&self) -> DVec3 {
        self.translation.as_dvec3()
    }
}

/// One bone's components at every sample time.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Curves {
    pub local: Vec<Components>,
    pub model: Vec<Components>,
    /// The model-space components under the ghost modes, when asked for.
    pub ghost_model: Vec<Components>,
}

/// What a whole-clip analysis computes besides the per-bone summaries.
#[derive(Clone, Copy, Debug, Default)]
pub struct CurveRequest<'a> {
    /// Bones whose full curves are kept.
    pub bones: &'a [usize],
    /// A second evaluation of those bones, kept as their ghost curves.
    pub ghost: Option<GhostRequest<'a>>,
}

/// How the ghost curves are evaluated: under other modes, and with or without the analysis's layers.
#[derive(Clone, Copy, Debug)]
pub struct GhostRequest<'a> {
    pub hierarchy: &'a Hierarchy,
    /// The clip as authored, without the layers (for comparing a layer's result with its input).
    pub unlayered: bool,
}

/// A whole clip analysed: per-bone summaries, per-bone per-sample stretched flags, and curves of chosen bones.
#[derive(Clone, Debug, PartialEq)]
pub struct ClipAnalysis {
    pub times: Vec<f64>,
    pub scan: ClipScan,
    /// Bit `s` of bone `b`'s row: stretched at sample `s`. Rows of `words_per_bone` words.
    stretched_bits: Vec<u64>,
    words_per_bone: usize,
    /// Bit `s`: some bone is stretched at sample `s`.
    any_stretched_bits: Vec<u64>,
    /// `(bone, curves)` for the requested bones, in request order.
    pub curves: Vec<(usize, Curves)>,
}

impl ClipAnalysis {
    /// Whether `bone` is stretched at sample `sample`.
    pub fn stretched_at(&self, bone: usize, sample: usize) -> bool {
        let word = self.stretched_bits.get(bone * self.words_per_bone + sample / 64).copied().unwrap_or(0);
        word >> (sample % 64) & 1 == 1
    }

    /// Whether any bone is stretched at sample `sample`.
    pub fn any_stretched_at(&self, sample: usize) -> bool {
        self.any_stretched_bits.get(sample / 64).is_some_and(|word| word >> (sample % 64) & 1 == 1)
    }

    /// The time spans in which `bone` (or, for `None`, any bone) is stretched: from the first flagged sample to
    /// the first sample after it that is not (or the last sample).
    pub fn stretched_spans(&self, bone: Option<usize>) -> Vec<(f64, f64)> {
        let flagged = |s: usize| bone.map_or_else(|| self.any_stretched_at(s), |b| self.stretched_at(b, s));
        let mut spans = Vec::new();
        let mut start = None;
        for (sample, &time) in self.times.iter().enumerate() {
            match (start, flagged(sample)) {
                (None, true) => start = Some(time),
                (Some(from), false) => {
                    spans.push((from, time));
                    start = None;
                }
                _ => {}
            }
        }
        if let (Some(from), Some(&last)) = (start, self.times.last()) {
            spans.push((from, last));
        }
        spans
    }

    pub fn curves_of(&self, bone: usize) -> Option<&Curves> {
        self.curves.iter().find(|(b, _)| *b == bone).map(|(_, c)| c)
    }
}

/// The times a scan visits: every key time, plus `0, 1/rate, 2/rate, …` up to the duration, plus the duration;
/// sorted, without duplicates. Just `[0]` without a clip.
pub fn sample_times(clip: Option<&Clip>, rate: f64) -> Vec<f64> {
    let Some(clip) = clip else { return vec![0.0] };
    let mut times = clip.key_times();
    add_grid(&mut times, clip.duration(), rate);
    times
}

/// The times a layered scan visits: [`sample_times`] of the main clip, unless the layers change the timeline (a
/// synced blend plays a cycle of another length, a crossfade runs on into the incoming clip): then the grid
/// `0, 1/rate, …` over the layered duration, plus its end.
pub fn layered_sample_times(rig: &Rig, clip: Option<&Clip>, layers: &LayerStack, rate: f64) -> Vec<f64> {
    let duration = layers.duration(rig, clip);
    if layers.synced_cycle(rig, clip).is_none() && duration == clip.map_or(0.0, Clip::duration) {
        return sample_times(clip, rate);
    }
    let mut times = Vec::new();
    add_grid(&mut times, duration, rate);
    times
}

/// Adds `0, 1/rate, …` up to `duration`, `0` and `duration` to `times`, then sorts them and drops duplicates.
fn add_grid(times: &mut Vec<f64>, duration: f64, rate: f64) {
    if rate > 0.0 && rate.is_finite() && duration.is_finite() {
        let steps = (duration * rate).floor() as usize;
        times.extend((0..=steps).map(|i| i as f64 / rate));
    }
    times.push(0.0);
    times.push(duration);
    times.sort_by(f64::total_cmp);
    times.dedup();
}

/// A rig evaluated through layers: what [`scan_layered`] and [`analyze_layered`] sample.
#[derive(Clone, Copy, Debug)]
pub struct Layered<'a> {
    pub rig: &'a Rig,
    /// Built for `rig`; each worker thread evaluates its own copy.
    pub layers: &'a LayerStack,
}

/// What an analysis evaluates at each sample time: a skeleton's clip (the rest pose for `None`), directly or through
/// layers.
#[derive(Clone, Copy, Debug)]
pub struct Subject<'a> {
    pub skeleton: &'a Skeleton,
    pub clip: Option<&'a Clip>,
    pub layered: Option<Layered<'a>>,
}

impl<'a> Subject<'a> {
    /// The clip as sampled.
    pub fn clip(skeleton: &'a Skeleton, clip: Option<&'a Clip>) -> Self {
        Subject { skeleton, clip, layered: None }
    }

    /// The clip through layers (`clip` is their main clip).
    pub fn layered(layered: Layered<'a>, clip: Option<&'a Clip>) -> Self {
        Subject { skeleton: &layered.rig.skeleton, clip, layered: Some(layered) }
    }
}

impl Subject<'_> {
    /// A worker's own copy of the layers (`None` without layers).
    fn worker_layers(&self) -> Option<LayerStack> {
        self.layered.map(|l| l.layers.clone())
    }

    fn evaluate(&self, pose: &mut Pose, hierarchy: &Hierarchy, layers: &mut Option<LayerStack>, time: f64) {
        match (self.layered, layers) {
            (Some(layered), Some(stack)) => pose.evaluate_layered(layered.rig, self.clip, hierarchy, stack, time),
            _ => pose.evaluate(self.skeleton, self.clip, hierarchy, time),
        }
    }

    fn times(&self, rate: f64) -> Vec<f64> {
        match self.layered {
            Some(l) => layered_sample_times(l.rig, self.clip, l.layers, rate),
            None => sample_times(self.clip, rate),
        }
    }
}

/// Words of 64 sample flags per parallel work item, at most: long enough to amortise a worker's buffers, and
/// short enough for every thread to get several.
const MAX_CHUNK_WORDS: usize = 16;

/// What one chunk of samples produced.
struct ChunkResult {
    summaries: Vec<BoneSummary>,
    /// `words` words of flags per bone.
    bits: Vec<u64>,
    words: usize,
    curves: Vec<Curves>,
}

/// Scans `subject` under `hierarchy`'s modes. `progress(done, total)` is called from worker threads as samples
/// complete.
pub fn scan(
    subject: Subject,
    hierarchy: &Hierarchy,
    options: &ScanOptions,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> ClipScan {
    let never = AtomicBool::new(false);
    analyze(subject, hierarchy, CurveRequest::default(), options, progress, &never)
        .expect("an analysis that is never cancelled completes")
        .scan
}

/// The whole-clip analysis behind [`scan`] and the app's plots. Returns `None` when `cancel` was set.
pub fn analyze(
    subject: Subject,
    hierarchy: &Hierarchy,
    request: CurveRequest,
    options: &ScanOptions,
    progress: &(dyn Fn(usize, usize) + Sync),
    cancel: &AtomicBool,
) -> Option<ClipAnalysis> {
    let skeleton = subject.skeleton;
    let times = subject.times(options.rate);
    let plan = Plan::new(subject, hierarchy, request.bones);
    let done = AtomicUsize::new(0);
    let words = times.len().div_ceil(64);
    let chunk_words = (words / (4 * rayon::current_num_threads())).clamp(1, MAX_CHUNK_WORDS);
    let chunks: Vec<Option<ChunkResult>> = times
        .par_chunks(64 * chunk_words)
        .map(|chunk| {
            if cancel.load(Ordering::Relaxed) {
                return None;
            }
            let result = analyze_chunk(subject, &plan, request, options, chunk);
            progress(done.fetch_add(chunk.len(), Ordering::Relaxed) + chunk.len(), times.len());
            Some(result)
        })
        .collect();
    let chunks: Vec<ChunkResult> = chunks.into_iter().collect::<Option<_>>()?;
    Some(assemble(skeleton.len(), times, request, chunks))
}

fn analyze_chunk(subject: Subject, plan: &Plan, request: CurveRequest, options: &ScanOptions, chunk: &[f64]) -> ChunkResult {
    let bones = subject.skeleton.len();
    let words = chunk.len().div_ceil(64);
    let mut result = ChunkResult {
        summaries: (0..bones).map(BoneSummary::new).collect(),
        bits: vec![0; bones * words],
        words,
        curves: vec![Curves::default(); request.bones.len()],
    };
    let mut evaluation = Evaluation::new(subject, plan);
    let judge = Judge::new(&options.tolerances);
    let mut ghost_pose = Pose::default();
    // Every bone at the first sample; then only those whose stretch can change.
    let mut judged: Vec<usize> = (0..bones).collect();
    let (mut first, mut fixed) = (vec![None; bones], vec![false; bones]);
    // Where each plotted bone's decomposition starts: its stretch frame at the previous sample.
    let mut curve_starts = vec![DQuat::IDENTITY; request.bones.len()];
    for (sample, &time) in chunk.iter().enumerate() {
        evaluation.seek(time);
        for &bone in &judged {
            let verdict = evaluation.stretch(bone).verdict(&judge);
            result.summaries[bone].add(time, &verdict);
            result.bits[bone * words + sample / 64] |= u64::from(verdict.findings.stretched) << (sample % 64);
            if sample == 0 {
                first[bone] = Some(verdict);
            }
        }
        if sample == 0 {
            fixed = evaluation.fixed_bones();
            judged.retain(|&bone| !fixed[bone]);
        }
        for ((curves, &bone), start) in result.curves.iter_mut().zip(request.bones).zip(&mut curve_starts) {
            let (local, model) = evaluation.matrices(bone);
            let assessment = Assessment::near(&model, &options.tolerances, *start);
            *start = assessment.parts.stretch;
            curves.model.push(Components::of(&assessment));
            curves.local.push(Components::of(&Assessment::of(&local, &options.tolerances)));
        }
        if let Some(ghost) = request.ghost {
            match ghost.unlayered {
                true => ghost_pose.evaluate(subject.skeleton, subject.clip, ghost.hierarchy, time),
                false => subject.evaluate(&mut ghost_pose, ghost.hierarchy, &mut evaluation.layers, time),
            }
            for (curves, &bone) in result.curves.iter_mut().zip(request.bones) {
                let assessment = Assessment::of(&ghost_pose.model.model[bone], &options.tolerances);
                curves.ghost_model.push(Components::of(&assessment));
            }
        }
    }
    // Fixed bones were judged once: the rest of the chunk repeats that verdict.
    let repeats = chunk.len() - 1;
    for bone in (0..bones).filter(|&b| fixed[b]) {
        let verdict = first[bone].expect("every bone is judged at the first sample");
        result.summaries[bone].repeat(repeats, &verdict);
        if verdict.findings.stretched {
            set_bits(&mut result.bits[bone * words..][..words], chunk.len());
        }
    }
    result
}

/// Sets the first `count` bits of `words`.
fn set_bits(words: &mut [u64], count: usize) {
    for (w, word) in words.iter_mut().enumerate() {
        let bits = count.saturating_sub(64 * w).min(64);
        *word |= if bits == 64 { u64::MAX } else { (1 << bits) - 1 };
    }
}

/// What the workers need to know about the subject, found once per analysis.
struct Plan<'a> {
    hierarchy: &'a Hierarchy,
    /// Read the clip channel by channel (a clip without layers on a fully inheriting rig), not pose by pose.
    by_channel: bool,
    /// The plotted bones and their ancestors, parents first: their local and model matrices are evaluated.
    modelled: Vec<usize>,
    /// Whether the clip changes each bone's scale, and its rotation, over time (constant tracks do not).
    varying_scale: Vec<bool>,
    varying_rotation: Vec<bool>,
}

impl<'a> Plan<'a> {
    fn new(subject: Subject, hierarchy: &'a Hierarchy, plotted: &[usize]) -> Self {
        let skeleton = subject.skeleton;
        let all_full = hierarchy.modes().iter().all(|&m| m == InheritMode::Full);
        let clip = subject.clip.filter(|_| subject.layered.is_none() && all_full);
        let varying = |track: fn(&BoneTracks) -> bool| -> Vec<bool> {
            (0..skeleton.len()).map(|b| clip.and_then(|c| c.tracks_of(b)).is_some_and(track)).collect()
        };
        Plan {
            hierarchy,
            by_channel: clip.is_some(),
            modelled: with_ancestors(skeleton, plotted),
            varying_scale: varying(|t| t.scale.as_ref().is_some_and(|s| !s.is_constant())),
            varying_rotation: varying(|t| t.rotation.as_ref().is_some_and(|r| !r.is_constant())),
        }
    }
}

/// One worker's evaluation of the subject, one sample time after another: every bone's [`Stretch`] for the
/// verdicts, and the local and model matrices of the bones whose curves are kept.
///
/// A clip without layers on a fully inheriting rig is read channel by channel: only the channels the stretches
/// need (scales everywhere, rotations below non-uniform scale), and all of them only for the plotted bones and their
/// ancestors. Layers, or any other inheritance mode, evaluate the whole pose.
struct Evaluation<'a> {
    subject: Subject<'a>,
    plan: &'a Plan<'a>,
    /// This worker's copy of the layers.
    layers: Option<LayerStack>,
    source: Source<'a>,
    stretches: Vec<Stretch>,
    /// Each bone's stretch frame at the previous sample, where a decomposition starts its search.
    previous: Vec<DQuat>,
}

enum Source<'a> {
    /// Every bone evaluated.
    Pose(Pose),
    /// Channels read on demand; full local and model matrices for the plan's `modelled` bones.
    Channels { cursor: ClipCursor<'a>, local: Vec<DMat4>, model: Vec<DMat4> },
}

impl<'a> Evaluation<'a> {
    fn new(subject: Subject<'a>, plan: &'a Plan<'a>) -> Self {
        let bones = subject.skeleton.len();
        let source = match subject.clip {
            Some(clip) if plan.by_channel => Source::Channels {
                cursor: ClipCursor::new(subject.skeleton, clip),
                local: vec![DMat4::IDENTITY; bones],
                model: vec![DMat4::IDENTITY; bones],
            },
            _ => Source::Pose(Pose::default()),
        };
        Evaluation {
            subject,
            plan,
            layers: subject.worker_layers(),
            source,
            stretches: vec![Stretch::NONE; bones],
            previous: vec![DQuat::IDENTITY; bones],
        }
    }

    /// Evaluates the sample at `time`; then [`Evaluation::stretch`] each bone in order.
    fn seek(&mut self, time: f64) {
        match &mut self.source {
            Source::Pose(pose) => self.subject.evaluate(pose, self.plan.hierarchy, &mut self.layers, time),
            Source::Channels { cursor, local, model } => {
                cursor.seek(time);
                for &bone in &self.plan.modelled {
                    local[bone] = cursor.local(bone).matrix();
                    model[bone] = match self.subject.skeleton.parent(bone) {
                        Some(parent) => model[parent] * local[bone],
                        None => local[bone],
                    };
                }
            }
        }
    }

    /// The stretch of `bone`'s model matrix at this sample; its parent's must have been asked for first.
    fn stretch(&mut self, bone: usize) -> Stretch {
        let parent = self.subject.skeleton.parent(bone);
        let start = self.previous[bone];
        let inherits = parent.is_none() || self.plan.hierarchy.modes()[bone] == InheritMode::Full;
        let above = parent.map_or(Stretch::NONE, |p| self.stretches[p]);
        let stretch = match &mut self.source {
            Source::Pose(pose) if inherits => above.child(bone, &mut pose.local.as_slice(), start),
            Source::Pose(pose) => Stretch::of_matrix(&pose.model.model[bone], start),
            Source::Channels { cursor, .. } => above.child(bone, cursor, start),
        };
        self.stretches[bone] = stretch;
        self.previous[bone] = stretch.frame;
        stretch
    }

    /// The bones whose stretch is the same at every sample, once every bone's stretch has been asked for: read
    /// channel by channel, a bone the clip neither scales nor, below non-uniform scale, turns, under such bones.
    fn fixed_bones(&self) -> Vec<bool> {
        let (skeleton, plan) = (self.subject.skeleton, self.plan);
        let mut fixed = vec![false; skeleton.len()];
        if !plan.by_channel {
            return fixed;
        }
        for bone in 0..skeleton.len() {
            let above = skeleton.parent(bone).map_or(Some(Stretch::NONE), |p| fixed[p].then(|| self.stretches[p]));
            fixed[bone] = above.is_some_and(|above| {
                !plan.varying_scale[bone] && (!plan.varying_rotation[bone] || above.is_uniform())
            });
        }
        fixed
    }

    /// The local and model matrices of a plotted bone at this sample.
    fn matrices(&self, bone: usize) -> (DMat4, DMat4) {
        match &self.source {
            Source::Pose(pose) => (pose.local[bone].matrix(), pose.model.model[bone]),
            Source::Channels { local, model, .. } => (local[bone], model[bone]),
        }
    }
}

/// `bones` and all their ancestors, sorted (so parents come first).
fn with_ancestors(skeleton: &Skeleton, bones: &[usize]) -> Vec<usize> {
    let mut wanted = vec![false; skeleton.len()];
    for &bone in bones.iter().filter(|&&b| b < skeleton.len()) {
        let mut next = Some(bone);
        while let Some(b) = next.filter(|&b| !wanted[b]) {
            wanted[b] = true;
            next = skeleton.parent(b);
        }
    }
    (0..skeleton.len()).filter(|&b| wanted[b]).collect()
}

fn assemble(bones: usize, times: Vec<f64>, request: CurveRequest, chunks: Vec<ChunkResult>) -> ClipAnalysis {
    let words_per_bone = times.len().div_ceil(64);
    let mut summaries: Vec<BoneSummary> = (0..bones).map(BoneSummary::new).collect();
    let mut stretched_bits = vec![0u64; bones * words_per_bone];
    let mut any_stretched_bits = vec![0u64; words_per_bone];
    let mut curves: Vec<(usize, Curves)> = request.bones.iter().map(|&b| (b, Curves::default())).collect();
    let mut first_word = 0;
    for chunk in chunks {
        let words = first_word..first_word + chunk.words;
        for (bone, (summary, bits)) in chunk.summaries.iter().zip(chunk.bits.chunks(chunk.words)).enumerate() {
            summaries[bone].merge(summary);
            stretched_bits[bone * words_per_bone..][words.clone()].copy_from_slice(bits);
            for (any, word) in any_stretched_bits[words.clone()].iter_mut().zip(bits) {
                *any |= word;
            }
        }
        for ((_, all), part) in curves.iter_mut().zip(chunk.curves) {
            all.local.extend(part.local);
            all.model.extend(part.model);
            all.ghost_model.extend(part.ghost_model);
        }
        first_word = words.end;
    }
    summaries.iter_mut().for_each(BoneSummary::finish);
    ClipAnalysis {
        scan: ClipScan { samples: times.len(), bones: summaries },
        times,
        stretched_bits,
        words_per_bone,
        any_stretched_bits,
        curves,
    }
}
