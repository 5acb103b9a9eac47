//! Sampling as densely as the source needs: wherever linear interpolation between two neighbouring samples misses
//! the source at their midpoint by more than the tolerance, the midpoint's neighbours are sampled in turn.
//!
//! Frames and key times are not always enough. A parent whose scale doubles within a frame, under a child that
//! compensates it, needs the child's local scale to follow `1/s(t)`, a curve no straight line between two frames
//! follows (4 % off at the middle, in Maya's mixed-inheritance test file). So every interval's midpoint is sampled
//! and compared with the interpolation of its ends; an interval that misses is split, down to [`MAX_DEPTH`] halvings.
//! Every midpoint sampled stays a sample, so the keys chosen later are checked against it too.

use rayon::prelude::*;

use super::Strategy;
use super::keys::interpolate;
use super::nodes::{NodeSample, Sampled, align, follow_frames, sample};
use crate::diff::Side;

/// The most times an interval between two base samples is halved.
const MAX_DEPTH: usize = 8;

/// Intervals this short (seconds) are not split, so that their times remain distinct as `f32`.
fn min_gap(time: f64) -> f64 {
    (64.0 * f64::from(f32::EPSILON) * time.abs()).max(1e-6)
}

/// `sampled` (at `times`, sorted) with midpoints added wherever `misses(bone, interpolated, exact)` says the
/// interpolation of an interval's ends misses its midpoint; the times and samples sorted, frames followed. The
/// interval after a stepped key's lead (`leads`, per time) holds the key's jump, which no halving brings closer: it
/// is left as it is.
pub fn refine(
    side: &Side,
    strategy: Strategy,
    times: Vec<f64>,
    leads: &[bool],
    sampled: Sampled,
    misses: &(impl Fn(usize, &NodeSample, &NodeSample) -> bool + Sync),
) -> (Vec<f64>, Sampled) {
    let mut pool_times = times;
    let mut pool = sampled;
    let mut intervals: Vec<(usize, usize)> =
        (1..pool_times.len()).filter(|&i| !leads[i - 1]).map(|i| (i - 1, i)).collect();
    for _ in 0..MAX_DEPTH {
        intervals.retain(|&(a, b)| pool_times[b] - pool_times[a] > min_gap(pool_times[b]));
        if intervals.is_empty() {
            break;
        }
        let middles: Vec<f64> = intervals.iter().map(|&(a, b)| 0.5 * (pool_times[a] + pool_times[b])).collect();
        let mut new = sample(side, &middles, strategy);
        let failed: Vec<bool> = new
            .samples
            .par_chunks_mut(pool.bones.max(1))
            .zip(&intervals)
            .map(|(middle, &(a, b))| {
                let (left, right) = (pool.row(a), pool.row(b));
                let mut missed = false;
                for (bone, exact) in middle.iter_mut().enumerate() {
                    align(exact, &left[bone]);
                    missed |= misses(bone, &interpolate(&left[bone], &right[bone], 0.5), exact);
                }
                missed
            })
            .collect();
        let first_new = pool_times.len();
        pool_times.extend_from_slice(&middles);
        pool = pool.append(new);
        intervals = intervals
            .iter()
            .zip(failed)
            .enumerate()
            .filter(|(_, (_, failed))| *failed)
            .flat_map(|(q, (&(a, b), _))| [(a, first_new + q), (first_new + q, b)])
            .collect();
    }
    let (times, mut sorted) = pool.sorted_by(&pool_times);
    follow_frames(&mut sorted);
    (times, sorted)
}
