//! A bone's worst shear and stretch between samples. Between keys a bone's curves are smooth, so the largest sampled
//! value lies beside the clip's true maximum: a golden-section search over the two sample intervals around it finds
//! that maximum to well under 0.001°, and every sampling rate (the app's 30 fps, `scan`'s 60, `--rate 240`) reports
//! one figure and one time.

use glam::DQuat;
use rayon::prelude::*;

use super::chunk::with_ancestors;
use super::clip_analysis::BoneSummary;
use super::findings::{Judge, Verdict};
use super::stretch::Stretch;
use crate::eval::{BonesEvaluator, Evaluation};

/// Golden-section steps: each keeps 0.618 of the interval, so two sample intervals shrink below 10⁻¹⁰ of their
/// length.
const STEPS: usize = 48;

/// A refined value replaces the sampled one only when it is larger by more than this fraction: rounding noise
/// between samples of a shear that holds still does not move its time.
const GAIN: f64 = 1e-12;

/// How many of a bone's highest sampled shear peaks are refined: the highest sample need not stand beside the
/// highest peak when the shear rises to several between keys.
const CANDIDATES: usize = 4;

/// A bone's highest local maxima of the sampled shear (as its cosine squared), found sample by sample.
#[derive(Clone, Debug, Default, PartialEq)]
pub(super) struct Peaks {
    /// `(time, value)`, the highest first, at most [`CANDIDATES`].
    highest: Vec<(f64, f64)>,
    /// The previous sample, and whether the value rose to it.
    last: Option<(f64, f64)>,
    rising: bool,
}

impl Peaks {
    /// Adds the next sample in time order.
    pub fn add(&mut self, time: f64, value: f64) {
        match self.last {
            Some((t, v)) => {
                if self.rising && value < v {
                    self.offer(t, v);
                }
                // A plateau keeps the way the values went.
                if value != v {
                    self.rising = value > v;
                }
            }
            // A run's first sample may be a peak whose rise lies in the run before.
            None => self.rising = true,
        }
        self.last = Some((time, value));
    }

    /// The peaks of an earlier run of samples and a later one: a run's last sample counts as a peak where the
    /// value rose to it.
    pub fn merge(&mut self, later: &Peaks) {
        self.close();
        let mut later = later.clone();
        later.close();
        later.highest.iter().for_each(|&(t, v)| self.offer(t, v));
        (self.last, self.rising) = (None, false);
    }

    /// The peaks, the highest first, the run's end included where the value rose to it.
    pub fn highest(&self) -> Vec<(f64, f64)> {
        let mut closed = self.clone();
        closed.close();
        closed.highest
    }

    fn close(&mut self) {
        if let Some((t, v)) = self.last.take().filter(|_| self.rising) {
            self.offer(t, v);
        }
    }

    fn offer(&mut self, time: f64, value: f64) {
        let at = self.highest.partition_point(|&(_, v)| v >= value);
        if at < CANDIDATES {
            self.highest.insert(at, (time, value));
            self.highest.truncate(CANDIDATES);
        }
    }
}

/// Refines each judged bone's worst shear (around each of its highest sampled peaks) and worst stretch (around its
/// highest sample) in `summaries` (sampled at `times`, sorted) to the largest value between the samples beside it.
pub(super) fn refine(evaluation: &Evaluation, times: &[f64], summaries: &mut [BoneSummary], judge: &Judge) {
    summaries.par_iter_mut().filter(|s| s.worst_shear_cosine_squared > 0.0 || s.stretched()).for_each(|summary| {
        let chain = with_ancestors(evaluation.skeleton(), &[summary.index]);
        let mut evaluator = BonesEvaluator::new(evaluation, &chain);
        let mut verdict = |time: f64| {
            let model = &evaluator.evaluate(time).model.model[summary.index];
            Stretch::of_matrix(model, DQuat::IDENTITY).verdict(judge)
        };
        // The shear as its cosine squared (larger is worse); the stretch as its half-angle cosine where the bone is
        // stretched (smaller is worse), so both are maximised as a number that grows with the angle.
        let peaks = if summary.worst_shear_cosine_squared > 0.0 { summary.shear_peaks.highest() } else { Vec::new() };
        for (sampled, _) in peaks {
            let (lo, hi) = around(times, sampled);
            let (time, value) = largest(lo, hi, |t| verdict(t).shear_cosine_squared);
            if value > summary.worst_shear_cosine_squared * (1.0 + GAIN) {
                (summary.worst_shear_cosine_squared, summary.worst_shear_time) = (value, time);
            }
        }
        if summary.stretched() {
            let (lo, hi) = around(times, summary.worst_stretch_time);
            let turn = |v: Verdict| if v.findings.stretched { 1.0 - v.stretch_half_cosine } else { 0.0 };
            let (time, value) = largest(lo, hi, |t| turn(verdict(t)));
            if value > (1.0 - summary.worst_stretch_half_cosine) * (1.0 + GAIN) {
                (summary.worst_stretch_half_cosine, summary.worst_stretch_time) = (1.0 - value, time);
            }
        }
        summary.finish();
    });
}

/// The samples before and after the one at `time` (itself at either end of the clip).
fn around(times: &[f64], time: f64) -> (f64, f64) {
    let at = times.partition_point(|&t| t < time).min(times.len().saturating_sub(1));
    let before = times[at.saturating_sub(1)];
    let after = times.get(at + 1).copied().unwrap_or(times[at]);
    (before, after)
}

/// The largest value of `f` over `[lo, hi]` and where it is: the best of [`PROBES`] evenly spread times, then a
/// golden-section search between its neighbours (a stretch angle may rise to more than one peak between samples).
fn largest(lo: f64, hi: f64, mut f: impl FnMut(f64) -> f64) -> (f64, f64) {
    let step = (hi - lo) / PROBES as f64;
    let probe = |k: usize| lo + step * k as f64;
    let best =
        (0..=PROBES).map(|k| (k, f(probe(k)))).fold((0, f64::NEG_INFINITY), |a, b| if b.1 > a.1 { b } else { a });
    let (near_lo, near_hi) = (probe(best.0.saturating_sub(1)), probe((best.0 + 1).min(PROBES)));
    let found = golden(near_lo, near_hi, f);
    if found.1 >= best.1 { found } else { (probe(best.0), best.1) }
}

/// Evenly spread times [`largest`] first compares.
const PROBES: usize = 16;

/// The largest value of `f` over `[lo, hi]` and where it is, by golden-section search: for a function that rises
/// to one peak and falls, the peak.
fn golden(mut lo: f64, mut hi: f64, mut f: impl FnMut(f64) -> f64) -> (f64, f64) {
    let shrink = (5f64.sqrt() - 1.0) / 2.0;
    let (mut a, mut b) = (hi - shrink * (hi - lo), lo + shrink * (hi - lo));
    let (mut fa, mut fb) = (f(a), f(b));
    for _ in 0..STEPS {
        if fa >= fb {
            (hi, b, fb) = (b, a, fa);
            a = hi - shrink * (hi - lo);
            fa = f(a);
        } else {
            (lo, a, fa) = (a, b, fb);
            b = lo + shrink * (hi - lo);
            fb = f(b);
        }
    }
    if fa >= fb { (a, fa) } else { (b, fb) }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_search_finds_a_peak_between_samples() {
        // A parabola peaking at 0.3: sampled at 0.25 and 0.5, the search over (0, 0.5) finds 0.3.
        let (time, value) = largest(0.0, 0.5, |t| 2.0 - (t - 0.3) * (t - 0.3));
        assert!((time - 0.3).abs() < 1e-7, "{time}");
        assert!((value - 2.0).abs() < 1e-14, "{value}");
        // A kink (the peak of |·| on a key) is found as well.
        let (time, _) = largest(0.0, 1.0, |t| -(t - 0.75).abs());
        assert!((time - 0.75).abs() < 1e-9, "{time}");
    }

    #[test]
    fn peaks_are_the_highest_local_maxima_across_runs() {
        // 1 3 2 | 2 5 4 6: peaks 3 (t 1), 5 (t 4), and 6 at the end (the value rose to it).
        let (mut early, mut late) = (Peaks::default(), Peaks::default());
        [1.0, 3.0, 2.0].into_iter().enumerate().for_each(|(t, v)| early.add(t as f64, v));
        [2.0, 5.0, 4.0, 6.0].into_iter().enumerate().for_each(|(t, v)| late.add(3.0 + t as f64, v));
        early.merge(&late);
        assert_eq!(early.highest(), [(6.0, 6.0), (4.0, 5.0), (1.0, 3.0)]);
        // A run that only falls peaks at its start.
        let mut falling = Peaks::default();
        [4.0, 3.0, 1.0].into_iter().enumerate().for_each(|(t, v)| falling.add(t as f64, v));
        assert_eq!(falling.highest(), [(0.0, 4.0)]);
    }

    #[test]
    fn the_samples_beside_a_time_bound_the_search() {
        let times = [0.0, 0.1, 0.2, 0.3];
        assert_eq!(around(&times, 0.1), (0.0, 0.2));
        assert_eq!(around(&times, 0.0), (0.0, 0.1));
        assert_eq!(around(&times, 0.3), (0.2, 0.3));
        assert_eq!(around(&[0.0], 0.0), (0.0, 0.0));
    }
}
