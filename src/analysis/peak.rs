//! A bone's worst shear between samples. Between keys a bone's curves are smooth, so the highest sampled peaks lie
//! beside the clip's true maximum: a search over the two sample intervals around each finds that maximum to well
//! under 0.001°, and every sampling rate (`scan --rate 30`, 60, 240, the app) reports one figure and one time.

/// Golden-section steps: each keeps 0.618 of the interval, so two sample intervals shrink below 10⁻⁶ of their
/// length (7 ns at 60 samples a second).
const STEPS: usize = 32;

/// A refined value replaces the sampled one only when it is larger by more than this fraction: rounding noise
/// between samples of a shear that holds still does not move its time.
const GAIN: f64 = 1e-12;

/// How many of a bone's highest sampled shear peaks are refined: the highest sample need not stand beside the
/// highest peak when the shear rises to several between keys.
const CANDIDATES: usize = 4;

/// A bone's highest local maxima of the sampled shear (as its cosine squared), found sample by sample.
#[derive(Clone, Debug, Default, PartialEq)]
pub(super) struct Peaks {
    /// The highest first, at most [`CANDIDATES`].
    highest: Vec<Peak>,
    /// The sample before the previous one, the previous sample, and whether the value rose to the latter.
    before: Option<f64>,
    last: Option<(f64, f64)>,
    rising: bool,
}

/// A sample higher than its neighbours.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Peak {
    pub time: f64,
    pub value: f64,
    /// How high the parabola through it and its neighbours reaches (its own value where one is unknown): a peak
    /// that reaches no higher than another's sample is not searched.
    pub reach: f64,
}

impl Peaks {
    /// Adds the next sample in time order.
    pub fn add(&mut self, time: f64, value: f64) {
        match self.last {
            Some((t, v)) => {
                if self.rising && value < v {
                    let reach = self.before.map_or(v, |p| v + vertex_gain(p, v, value));
                    self.offer(Peak { time: t, value: v, reach });
                }
                // A plateau keeps the way the values went.
                if value != v {
                    self.rising = value > v;
                }
            }
            // A run's first sample may be a peak whose rise lies in the run before.
            None => self.rising = true,
        }
        self.before = self.last.map(|(_, v)| v);
        self.last = Some((time, value));
    }

    /// The peaks of an earlier run of samples and a later one: a run's last sample counts as a peak where the
    /// value rose to it.
    pub fn merge(&mut self, later: &Peaks) {
        self.close();
        let mut later = later.clone();
        later.close();
        later.highest.iter().for_each(|&peak| self.offer(peak));
        (self.before, self.last, self.rising) = (None, None, false);
    }

    /// The peaks, the highest first, the run's end included where the value rose to it.
    pub fn highest(&self) -> Vec<Peak> {
        let mut closed = self.clone();
        closed.close();
        closed.highest
    }

    fn close(&mut self) {
        if let Some((time, value)) = self.last.take().filter(|_| self.rising) {
            self.offer(Peak { time, value, reach: value });
        }
    }

    fn offer(&mut self, peak: Peak) {
        let at = self.highest.partition_point(|p| p.value >= peak.value);
        if at < CANDIDATES {
            self.highest.insert(at, peak);
            self.highest.truncate(CANDIDATES);
        }
    }
}

/// How far above `v` the parabola through three evenly spaced samples `p`, `v`, `n` (`v` the highest) peaks.
fn vertex_gain(p: f64, v: f64, n: f64) -> f64 {
    let curvature = 2.0 * v - p - n;
    if curvature > 0.0 { (n - p) * (n - p) / (8.0 * curvature) } else { 0.0 }
}

/// The worst of a sampled shear (`worst`: its time and value) refined between the samples (`times`, sorted) beside
/// the highest of `peaks`, and beside those whose parabola reaches past it: the largest value of `f` found there,
/// where it passes the sampled one by more than [`GAIN`].
pub(super) fn refine(peaks: &Peaks, times: &[f64], worst: (f64, f64), mut f: impl FnMut(f64) -> f64) -> (f64, f64) {
    let peaks = peaks.highest();
    let highest = peaks.first().map_or(0.0, |p| p.value);
    let searched = peaks.iter().enumerate().filter(|(i, p)| *i == 0 || p.reach >= highest).map(|(_, p)| p.time);
    searched.fold(worst, |worst, sampled| {
        let (lo, hi) = around(times, sampled);
        let found = largest(lo, sampled, hi, &mut f);
        if gains(found.1, worst.1) { found } else { worst }
    })
}

/// Whether a value found between samples replaces the sampled `value`: larger by more than [`GAIN`].
pub(crate) fn gains(found: f64, value: f64) -> bool {
    found > value * (1.0 + GAIN)
}

/// The samples before and after the one at `time` (itself at either end of the clip).
pub(crate) fn around(times: &[f64], time: f64) -> (f64, f64) {
    let at = times.partition_point(|&t| t < time).min(times.len().saturating_sub(1));
    let before = times[at.saturating_sub(1)];
    let after = times.get(at + 1).copied().unwrap_or(times[at]);
    (before, after)
}

/// The largest value of `f` over `[lo, hi]` and where it is, from the sample at `mid` (the highest of the three):
/// successive parabolas through the best three points, each bracketing the peak (a peak between keys is smooth: a
/// few steps reach it), and a golden-section search where a parabola does not help (a kink on a key).
fn largest(lo: f64, mid: f64, hi: f64, mut f: impl FnMut(f64) -> f64) -> (f64, f64) {
    let [mut a, mut b, mut c] = [lo, mid, hi].map(|t| (t, f(t)));
    if !(a.0 < b.0 && b.0 < c.0 && b.1 >= a.1 && b.1 >= c.1) {
        let found = golden(lo, hi, f);
        return if found.1 > b.1 { found } else { b };
    }
    for _ in 0..PARABOLA_STEPS {
        let x = parabola_peak(a, b, c);
        if !x.is_finite() {
            // Three equal values: a shear that holds still.
            return b;
        }
        if !(x > a.0 && x < c.0) {
            break;
        }
        if (x - b.0).abs() <= 1e-9 * (hi - lo) {
            return b;
        }
        let at = (x, f(x));
        (a, b, c) = match (x < b.0, at.1 > b.1) {
            (true, true) => (a, at, b),
            (true, false) => (at, b, c),
            (false, true) => (b, at, c),
            (false, false) => (a, b, at),
        };
    }
    let found = golden(a.0, c.0, f);
    if found.1 > b.1 { found } else { b }
}

/// Parabola steps before the golden-section search takes over.
const PARABOLA_STEPS: usize = 12;

/// Where the parabola through three points peaks (not finite where they lie on a line).
fn parabola_peak((x0, y0): (f64, f64), (x1, y1): (f64, f64), (x2, y2): (f64, f64)) -> f64 {
    let (d0, d2) = (x1 - x0, x1 - x2);
    let (e0, e2) = ((y1 - y2) * d0, (y1 - y0) * d2);
    x1 - 0.5 * (d0 * e0 - d2 * e2) / (e0 - e2)
}

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
        let (time, value) = largest(0.0, 0.25, 0.5, |t| 2.0 - (t - 0.3) * (t - 0.3));
        assert!((time - 0.3).abs() < 1e-7, "{time}");
        assert!((value - 2.0).abs() < 1e-14, "{value}");
        // A smooth peak that is no parabola, and a kink (the peak of |·| on a key), are found as well.
        let (time, _) = largest(0.0, 0.5, 1.0, |t| (3.0 * t).sin());
        assert!((time - std::f64::consts::FRAC_PI_6).abs() < 1e-6, "{time}");
        let (time, _) = largest(0.0, 0.5, 1.0, |t| -(t - 0.75).abs());
        assert!((time - 0.75).abs() < 1e-6, "{time}");
    }

    #[test]
    fn peaks_are_the_highest_local_maxima_across_runs() {
        // 1 3 2 | 2 5 4 6: peaks 3 (t 1), 5 (t 4), and 6 at the end (the value rose to it).
        let (mut early, mut late) = (Peaks::default(), Peaks::default());
        [1.0, 3.0, 2.0].into_iter().enumerate().for_each(|(t, v)| early.add(t as f64, v));
        [2.0, 5.0, 4.0, 6.0].into_iter().enumerate().for_each(|(t, v)| late.add(3.0 + t as f64, v));
        early.merge(&late);
        let found: Vec<(f64, f64)> = early.highest().iter().map(|p| (p.time, p.value)).collect();
        assert_eq!(found, [(6.0, 6.0), (4.0, 5.0), (1.0, 3.0)]);
        // 2 5 4: the parabola through them, 2 + 4.5·x − 1.5·x² over x = 0, 1, 2, peaks at x = 1.5, 1/8 above 5.
        assert_eq!(early.highest()[1].reach, 5.125);
        // A run that only falls peaks at its start.
        let mut falling = Peaks::default();
        [4.0, 3.0, 1.0].into_iter().enumerate().for_each(|(t, v)| falling.add(t as f64, v));
        assert_eq!(falling.highest(), [Peak { time: 0.0, value: 4.0, reach: 4.0 }]);
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
