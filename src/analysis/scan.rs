//! Whole-clip analysis: every key time plus a fixed rate, every bone, in parallel. Summarised per bone for the
//! whole rig (cheap to keep for any rig); full component curves only for the bones asked for (plotted ones).

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

use glam::{DMat4, DQuat, DVec3, Quat, Vec3};
use rayon::prelude::*;

use super::Tolerances;
use super::chunk::{ChunkResult, CurveSlices, Plan, analyze_chunk};
use super::findings::{Verdict, shear_cosine};
use crate::eval::{Hierarchy, LayerStack, Pose};
use crate::math::{AffineParts, angle_of_half_cosine, decompose_near, shear_deg_of_cosine};
use crate::model::{Clip, Rig, Skeleton};

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
    worst_shear_cosine_squared: f64,
    #[serde(skip)]
    worst_stretch_half_cosine: f64,
}

impl BoneSummary {
    pub(super) fn new(index: usize) -> Self {
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
            worst_shear_cosine_squared: 0.0,
            worst_stretch_half_cosine: 1.0,
        }
    }

    /// Adds one sample. The worst angles are kept as cosines until [`BoneSummary::finish`].
    pub(super) fn add(&mut self, time: f64, verdict: &Verdict) {
        if verdict.shear_cosine_squared > self.worst_shear_cosine_squared {
            self.worst_shear_cosine_squared = verdict.shear_cosine_squared;
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

    /// Combines the summary of an earlier run of samples with that of a later one.
    fn merge(&mut self, later: &BoneSummary) {
        if later.worst_shear_cosine_squared > self.worst_shear_cosine_squared {
            self.worst_shear_cosine_squared = later.worst_shear_cosine_squared;
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
    pub(super) fn repeat(&mut self, count: usize, verdict: &Verdict) {
        let f = verdict.findings;
        self.flagged_samples += count * usize::from(f.stretched);
        self.non_uniform_samples += count * usize::from(f.non_uniform);
        self.mirrored_samples += count * usize::from(f.mirrored);
        self.degenerate_samples += count * usize::from(f.degenerate);
    }

    /// Turns the worst cosines into angles.
    fn finish(&mut self) {
        self.worst_shear_deg = shear_deg_of_cosine(self.worst_shear_cosine_squared.sqrt());
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
    /// A placeholder for a sample not computed yet.
    const UNSET: Components = Components {
        translation: Vec3::ZERO,
        rotation: Quat::IDENTITY,
        scale: Vec3::ZERO,
        stretch: Quat::IDENTITY,
        sign: 1.0,
        shear_deg: 0.0,
    };

    /// The components of `m`, its decomposition searching from `start` (see [`decompose_near`]; the previous
    /// sample's stretch makes a curve faster).
    pub(super) fn of_matrix(m: &DMat4, start: DQuat) -> Self {
        Components::of_parts(&decompose_near(m, start), m)
    }

    /// The components of `m` decomposed into `parts`.
    pub(super) fn of_parts(parts: &AffineParts, m: &DMat4) -> Self {
        let shear_deg = shear_deg_of_cosine(shear_cosine(parts, m));
        Components {
            translation: parts.translation.as_vec3(),
            rotation: parts.rotation.as_quat(),
            scale: parts.scale.as_vec3(),
            stretch: parts.stretch.as_quat(),
            sign: parts.sign as f32,
            shear_deg: shear_deg as f32,
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

impl Curves {
    /// Curves of `samples` samples (and ghost curves, or none), to be overwritten: the chunks of an analysis write
    /// their parts in place. Filled in parallel, so that long clips' hundreds of megabytes are not first touched
    /// on one thread.
    fn for_samples(samples: usize, ghost: bool) -> Self {
        let unset = || {
            let mut curve = Vec::new();
            rayon::iter::repeat_n(Components::UNSET, samples).collect_into_vec(&mut curve);
            curve
        };
        Curves { local: unset(), model: unset(), ghost_model: if ghost { unset() } else { Vec::new() } }
    }
}

/// What a whole-clip analysis computes besides the per-bone summaries.
#[derive(Clone, Copy, Debug, Default)]
pub struct CurveRequest<'a> {
    /// Bones whose full curves are kept (indices past the skeleton's end are left out).
    pub bones: &'a [usize],
    /// A second evaluation of those bones, kept as their ghost curves.
    pub ghost: Option<GhostRequest<'a>>,
    /// Which bones are judged.
    pub judged: Judged,
}

/// Which bones an analysis judges.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Judged {
    /// Every bone: the whole-clip summary of the rig.
    #[default]
    Every,
    /// Only the bones whose curves are asked for and their ancestors: the curves of a newly selected bone, without
    /// waiting for the rest of the rig (the other bones' summaries stay empty).
    CurveChains,
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

/// The most frames of the scan rate a clip is visited at every one of; a longer clip is visited at its key times and
/// a bounded number of times between sparse keys ([`crate::model::sample_times`]).
const MAX_FRAMES: usize = 1 << 20;

/// The times a scan visits: every key time, plus `0, 1/rate, 2/rate, …` up to the duration, plus the duration;
/// sorted, without duplicates (thinned between sparse keys for a clip of more than [`MAX_FRAMES`] frames). Just
/// `[0]` without a clip.
pub fn sample_times(clip: Option<&Clip>, rate: f64) -> Vec<f64> {
    let Some(clip) = clip else { return vec![0.0] };
    crate::model::sample_times(clip.key_times(), 0.0, clip.duration(), rate, MAX_FRAMES).times
}

/// The times a layered scan visits: [`sample_times`] of the main clip, unless the layers change the timeline (a
/// synced blend plays a cycle of another length, a crossfade runs on into the incoming clip): then the grid
/// `0, 1/rate, …` over the layered duration, plus its end.
pub fn layered_sample_times(rig: &Rig, clip: Option<&Clip>, layers: &LayerStack, rate: f64) -> Vec<f64> {
    let duration = layers.duration(rig, clip);
    if layers.synced_cycle(rig, clip).is_none() && duration == clip.map_or(0.0, Clip::duration) {
        return sample_times(clip, rate);
    }
    crate::model::sample_times([], 0.0, duration, rate, MAX_FRAMES).times
}

/// A rig evaluated through layers.
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
    pub(super) fn worker_layers(&self) -> Option<LayerStack> {
        self.layered.map(|l| l.layers.clone())
    }

    pub(super) fn evaluate(&self, pose: &mut Pose, hierarchy: &Hierarchy, layers: &mut Option<LayerStack>, time: f64) {
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
    let in_range: Vec<usize> = request.bones.iter().copied().filter(|&b| b < skeleton.len()).collect();
    let request = CurveRequest { bones: &in_range, ..request };
    let plan = Plan::new(subject, hierarchy, request.bones, request.judged);
    let done = AtomicUsize::new(0);
    let words = times.len().div_ceil(64);
    let chunk_len = 64 * (words / (4 * rayon::current_num_threads())).clamp(1, MAX_CHUNK_WORDS);
    let mut curves: Vec<(usize, Curves)> =
        request.bones.iter().map(|&b| (b, Curves::for_samples(times.len(), request.ghost.is_some()))).collect();
    let chunks: Vec<Option<ChunkResult>> = times
        .par_chunks(chunk_len)
        .zip(split_curves(&mut curves, chunk_len, times.len().div_ceil(chunk_len)))
        .map(|(chunk, slices)| {
            if cancel.load(Ordering::Relaxed) {
                return None;
            }
            let result = analyze_chunk(subject, &plan, request, options, chunk, slices);
            progress(done.fetch_add(chunk.len(), Ordering::Relaxed) + chunk.len(), times.len());
            Some(result)
        })
        .collect();
    let chunks: Vec<ChunkResult> = chunks.into_iter().collect::<Option<_>>()?;
    Some(assemble(skeleton.len(), times, curves, chunks))
}

/// Each curve cut into `count` pieces of `len` samples, gathered per piece: what each chunk writes.
fn split_curves(curves: &mut [(usize, Curves)], len: usize, count: usize) -> Vec<CurveSlices<'_>> {
    let mut slices: Vec<CurveSlices> = (0..count).map(|_| CurveSlices::default()).collect();
    for (_, curve) in curves {
        let parts =
            pieces(&mut curve.local, len).zip(pieces(&mut curve.model, len)).zip(pieces(&mut curve.ghost_model, len));
        for (slice, ((local, model), ghost)) in slices.iter_mut().zip(parts) {
            slice.local.extend(local);
            slice.model.extend(model);
            slice.ghost_model.extend(ghost);
        }
    }
    slices
}

/// `samples` in pieces of `len`, then `None` for ever (ghost curves are empty without a ghost).
fn pieces(samples: &mut [Components], len: usize) -> impl Iterator<Item = Option<&mut [Components]>> {
    samples.chunks_mut(len).map(Some).chain(std::iter::repeat_with(|| None))
}

fn assemble(bones: usize, times: Vec<f64>, curves: Vec<(usize, Curves)>, chunks: Vec<ChunkResult>) -> ClipAnalysis {
    let words_per_bone = times.len().div_ceil(64);
    let mut summaries: Vec<BoneSummary> = (0..bones).map(BoneSummary::new).collect();
    let mut stretched_bits = vec![0u64; bones * words_per_bone];
    let mut any_stretched_bits = vec![0u64; words_per_bone];
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
