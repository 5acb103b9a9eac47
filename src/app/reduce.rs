//! Reducing dense data to what the pixels can show, so that drawing costs follow the screen, not the clip: a curve
//! becomes its minimum and maximum per pixel column (as Rerun's time-series view does), time spans closer than a
//! pixel merge into one.

use std::ops::RangeInclusive;

/// A curve reduced to a pixel grid.
#[derive(Clone, Debug, PartialEq)]
pub enum Reduced {
    /// Few samples in view: every one of them, plus a neighbour either side so lines reach the edges.
    Points(Vec<[f64; 2]>),
    /// More samples than columns: per column, where it is and the smallest and largest value in it.
    Envelope { xs: Vec<f64>, lows: Vec<f64>, highs: Vec<f64> },
}

/// Reduces the samples (`times[i]`, `value(i)`) inside `x_range` to `columns` pixel columns.
pub fn reduce(times: &[f64], value: impl Fn(usize) -> f64, x_range: RangeInclusive<f64>, columns: usize) -> Reduced {
    let start = times.partition_point(|&t| t < *x_range.start()).saturating_sub(1);
    let end = (times.partition_point(|&t| t <= *x_range.end()) + 1).min(times.len());
    if start >= end || end - start <= 2 * columns.max(1) {
        return Reduced::Points((start..end).map(|s| [times[s], value(s)]).collect());
    }
    let (t0, t1) = (times[start], times[end - 1]);
    let width = (t1 - t0).max(f64::MIN_POSITIVE) / columns as f64;
    let (mut xs, mut lows, mut highs) =
        (Vec::with_capacity(columns + 1), Vec::with_capacity(columns + 1), Vec::with_capacity(columns + 1));
    let mut s = start;
    while s < end {
        let column = ((times[s] - t0) / width).floor();
        let (mut lo, mut hi) = (value(s), value(s));
        let mut next = s + 1;
        while next < end && ((times[next] - t0) / width).floor() == column {
            let v = value(next);
            lo = lo.min(v);
            hi = hi.max(v);
            next += 1;
        }
        xs.push((times[s] + times[next - 1]) * 0.5);
        lows.push(lo);
        highs.push(hi);
        s = next;
    }
    Reduced::Envelope { xs, lows, highs }
}

/// Sorted spans with gaps narrower than `min_gap` (and spans narrower than it) merged, so a strip of thousands of
/// short spans draws as the few bars a person can see.
pub fn merge_spans(spans: &[(f64, f64)], min_gap: f64) -> Vec<(f64, f64)> {
    let mut merged: Vec<(f64, f64)> = Vec::new();
    for &(from, to) in spans {
        match merged.last_mut() {
            Some(last) if from - last.1 < min_gap => last.1 = last.1.max(to),
            _ => merged.push((from, to)),
        }
    }
    merged
}

#[cfg(test)]
mod tests {
    use super::*;

    fn points(r: Reduced) -> Vec<[f64; 2]> {
        match r {
            Reduced::Points(p) => p,
            Reduced::Envelope { .. } => panic!("expected points"),
        }
    }

    #[test]
    fn a_dense_curve_becomes_an_envelope_that_keeps_every_extreme() {
        let times: Vec<f64> = (0..100_000).map(|i| i as f64 * 0.001).collect();
        // A spike at one sample must survive the reduction.
        let value = |s: usize| if s == 54_321 { 10.0 } else { (s as f64 * 0.01).sin() };
        let Reduced::Envelope { xs, lows, highs } = reduce(&times, value, 0.0..=100.0, 500) else {
            panic!("100,000 samples on 500 columns are dense")
        };
        assert!(xs.len() <= 501 && xs.len() == lows.len() && xs.len() == highs.len(), "{}", xs.len());
        assert_eq!(highs.iter().copied().fold(f64::MIN, f64::max), 10.0);
        assert!((lows.iter().copied().fold(f64::MAX, f64::min) + 1.0).abs() < 1e-6);
        assert!(xs.windows(2).all(|w| w[0] < w[1]), "in time order");
        assert!(lows.iter().zip(&highs).all(|(lo, hi)| lo <= hi));
    }

    #[test]
    fn a_few_samples_pass_through_with_a_neighbour_either_side() {
        let times: Vec<f64> = (0..100_000).map(|i| i as f64 * 0.001).collect();
        let few = points(reduce(&times, |s| s as f64, 1.0..=1.0045, 500));
        assert_eq!(few.len(), 7, "samples 1.000 to 1.004 and one either side");
        assert_eq!(few[0], [times[999], 999.0]);
        assert!(points(reduce(&[], |_| 0.0, 0.0..=1.0, 10)).is_empty());
    }

    #[test]
    fn spans_closer_than_a_pixel_merge() {
        let spans = [(0.0, 1.0), (1.05, 2.0), (3.0, 3.01), (3.02, 4.0), (6.0, 7.0)];
        assert_eq!(merge_spans(&spans, 0.1), [(0.0, 2.0), (3.0, 4.0), (6.0, 7.0)]);
        assert_eq!(merge_spans(&spans, 0.0), spans);
        assert!(merge_spans(&[], 1.0).is_empty());
    }
}
