//! Whole-clip analysis: every key time plus a fixed rate, every bone, in parallel. Summarised per bone for the
//! whole rig (cheap to keep for any rig), each bone's worst values refined between samples (`peak`); full component
//! curves only for the bones asked for (plotted ones).

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

use glam::DQuat;
use rayon::prelude::*;

use super::chunk::{ChunkResult, CurveSlices, Plan, analyze_chunk};
use super::clip_analysis::{BoneSummary, ClipAnalysis, ClipScan, Components, Curves};
use super::findings::{Judge, clearly_stretched};
use super::request::{CurveRequest, Judged, ScanOptions};
use super::stretch::Stretch;
use crate::eval::{BonesEvaluator, Evaluation, run_length};

/// Scans `evaluation` over its whole clip. `progress(done, total)` is called from worker threads as samples
/// complete.
pub fn scan(evaluation: &Evaluation, options: &ScanOptions, progress: &(dyn Fn(usize, usize) + Sync)) -> ClipScan {
    let never = AtomicBool::new(false);
    analyze(evaluation, CurveRequest::default(), options, progress, &never)
        .expect("an analysis that is never cancelled completes")
        .scan
}

/// [`scan`]'s analysis, with where each bone is flagged: what `explain` starts from.
pub fn scan_analysis(evaluation: &Evaluation, options: &ScanOptions) -> ClipAnalysis {
    let never = AtomicBool::new(false);
    analyze(evaluation, CurveRequest::default(), options, &|_, _| {}, &never)
        .expect("an analysis that is never cancelled completes")
}

/// The whole-clip analysis behind [`scan`] and the app's plots. Returns `None` when `cancel` was set.
pub fn analyze(
    evaluation: &Evaluation,
    request: CurveRequest,
    options: &ScanOptions,
    progress: &(dyn Fn(usize, usize) + Sync),
    cancel: &AtomicBool,
) -> Option<ClipAnalysis> {
    let skeleton = evaluation.skeleton();
    let times = evaluation.times(options.rate);
    let in_range: Vec<usize> = request.bones.iter().copied().filter(|&b| b < skeleton.len()).collect();
    let request = CurveRequest { bones: &in_range, ..request };
    let plan = Plan::new(evaluation, request.bones, request.judged);
    let done = AtomicUsize::new(0);
    // The runs of the one parallel driver (`over_runs`); each also fills its piece of every curve.
    let chunk_len = run_length(times.len());
    let mut curves: Vec<(usize, Curves)> =
        request.bones.iter().map(|&b| (b, Curves::for_samples(times.len(), request.ghost.is_some()))).collect();
    let chunks: Vec<Option<ChunkResult>> = times
        .par_chunks(chunk_len)
        .zip(split_curves(&mut curves, chunk_len, times.len().div_ceil(chunk_len)))
        .map(|(chunk, slices)| {
            if cancel.load(Ordering::Relaxed) {
                return None;
            }
            let result = analyze_chunk(evaluation, &plan, request, options, chunk, slices);
            progress(done.fetch_add(chunk.len(), Ordering::Relaxed) + chunk.len(), times.len());
            Some(result)
        })
        .collect();
    let chunks: Vec<ChunkResult> = chunks.into_iter().collect::<Option<_>>()?;
    let every: Vec<usize> = (0..skeleton.len()).collect();
    let mut analysis = assemble(skeleton.figure(), times, curves, chunks, &every);
    refine_shears(evaluation, &analysis.times, &mut analysis.scan.bones, &Judge::new(&options.tolerances));
    Some(analysis)
}

/// Refines each judged bone's worst shear in `summaries` (sampled at `times`, sorted) between samples: those whose
/// sampled shear passes the tolerance (a shear of rounding noise is left as sampled). The worst stretch angle stays
/// the sampled one: an angle of the stretch rotation jumps where two scale factors cross, so no search between
/// samples is sure to find its maximum.
pub(super) fn refine_shears(evaluation: &Evaluation, times: &[f64], summaries: &mut [BoneSummary], judge: &Judge) {
    let seen = |s: &&mut BoneSummary| judge.sees_shear(s.worst_shear_cosine_squared);
    summaries.par_iter_mut().filter(seen).for_each(|summary| {
        let bone = summary.index;
        let chain = evaluation.skeleton().with_ancestors(&[bone]);
        let mut evaluator = BonesEvaluator::new(evaluation, &chain);
        summary.refine_shear(times, |time| {
            let model = &evaluator.evaluate(time).model.model[bone];
            Stretch::of_matrix(model, DQuat::IDENTITY).verdict(judge).shear_cosine_squared
        });
    });
}

/// Whether `bone` is flagged at some sample of the run of [`analyze`]'s samples that holds `time`, from the run's
/// first sample to the one at `time` (or the first after it; the last sample for a later time): exactly what the
/// whole-clip analysis finds there, since a run is judged on its own from its first sample on, here for the bone's
/// chain alone. `times` are the analysis's, `evaluation.times(options.rate)` (found once by a caller asking many
/// times). A first look where a change is expected to leave a bone flagged where it was worst, and
/// [`clearly_flagged_at`] has not settled it from that sample alone.
pub fn flagged_in_run(evaluation: &Evaluation, bone: usize, time: f64, times: &[f64], options: &ScanOptions) -> bool {
    debug_assert_eq!(times, evaluation.times(options.rate), "the analysis's times");
    let Some(last) = times.len().checked_sub(1) else {
        return false;
    };
    let at = times.partition_point(|&t| t < time).min(last);
    let first = at - at % run_length(times.len());
    let request = CurveRequest { judged: Judged::Chain(bone), ..CurveRequest::default() };
    let plan = Plan::new(evaluation, request.bones, request.judged);
    analyze_chunk(evaluation, &plan, request, options, &times[first..=at], CurveSlices::default()).flagged(bone)
}

/// Whether `bone` is clearly flagged at the sample of `times` at `time` (or the first after it; the last sample for a
/// later time): its model matrix there, decomposed, is flagged under tolerances a millionth tighter and a millionth
/// looser alike, so that a whole-clip analysis flags it there whatever rounding it meets. `false` says nothing.
/// `times` are the analysis's ([`flagged_in_run`]).
pub fn clearly_flagged_at(
    evaluation: &Evaluation,
    bone: usize,
    time: f64,
    times: &[f64],
    options: &ScanOptions,
) -> bool {
    let Some(last) = times.len().checked_sub(1) else {
        return false;
    };
    let at = times.partition_point(|&t| t < time).min(last);
    let chain = evaluation.skeleton().with_ancestors(&[bone]);
    let model = BonesEvaluator::new(evaluation, &chain).evaluate(times[at]).model.model[bone];
    clearly_stretched(&model, &options.tolerances) == Some(true)
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

/// The chunks' results as one analysis; `figure` (one flag per bone) says which bones count for "any bone", and
/// `held` which bone each chunk's entries stand for (every bone of the rig, or a few; the others stay empty).
pub(super) fn assemble(
    figure: &[bool],
    times: Vec<f64>,
    curves: Vec<(usize, Curves)>,
    chunks: Vec<ChunkResult>,
    held: &[usize],
) -> ClipAnalysis {
    let bones = figure.len();
    let words_per_bone = times.len().div_ceil(64);
    let mut summaries: Vec<BoneSummary> = (0..bones).map(BoneSummary::new).collect();
    let mut stretched_bits = vec![0u64; bones * words_per_bone];
    let mut any_stretched_bits = vec![0u64; words_per_bone];
    let mut first_word = 0;
    for chunk in chunks {
        let words = first_word..first_word + chunk.words;
        for (&bone, (summary, bits)) in held.iter().zip(chunk.summaries.iter().zip(chunk.bits.chunks(chunk.words))) {
            summaries[bone].merge(summary);
            stretched_bits[bone * words_per_bone..][words.clone()].copy_from_slice(bits);
            if figure[bone] {
                for (any, word) in any_stretched_bits[words.clone()].iter_mut().zip(bits) {
                    *any |= word;
                }
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::import::demo_rig;
    use crate::model::InheritMode;

    #[test]
    fn a_run_is_judged_as_the_whole_clip_judges_it() {
        // The demo's arm judged bone by bone (full inheritance) and sample by sample (the forearm compensating):
        // every bone's verdict from the start of a run to a sample, looked up from that sample's time or from just
        // before it, equals the whole analysis's over those samples; where the sample alone says the bone is clearly
        // flagged, the whole analysis flags it there.
        let rig = demo_rig();
        let declared = Evaluation::declared(&rig, rig.clips.first());
        let mut modes = declared.modes().to_vec();
        modes[rig.skeleton.find("forearm").unwrap()] = InheritMode::SegmentCompensate;
        let compensating = declared.with_modes(&modes).unwrap();
        let options = ScanOptions { rate: 240.0, ..ScanOptions::default() };
        let never = AtomicBool::new(false);
        let (mut flagged_runs, mut clearly_flagged) = (0, 0);
        for evaluation in [&declared, &compensating] {
            let whole = analyze(evaluation, CurveRequest::default(), &options, &|_, _| {}, &never).unwrap();
            let times = &whole.times;
            let length = run_length(times.len());
            for bone in 0..rig.skeleton.len() {
                for (run, samples) in times.chunks(length).enumerate() {
                    let first = run * length;
                    for at in [0, samples.len() / 2, samples.len() - 1] {
                        let expected = (first..=first + at).any(|s| whole.stretched_at(bone, s));
                        for time in [samples[at], samples[at] - 1e-9] {
                            let found = flagged_in_run(evaluation, bone, time, times, &options);
                            assert_eq!(found, expected, "bone {bone}, run {run}, sample {at}, {time} s");
                            let clearly = clearly_flagged_at(evaluation, bone, time, times, &options);
                            assert!(!clearly || whole.stretched_at(bone, first + at), "bone {bone}, {time} s");
                            clearly_flagged += usize::from(clearly);
                        }
                        flagged_runs += usize::from(expected);
                    }
                }
            }
        }
        assert!(flagged_runs > 0 && clearly_flagged > 0, "the demo's forearm shears somewhere");
    }
}
