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
use super::keys::{interpolate, too_far};
use super::nodes::{NodeSample, Sampled, align, follow_frames, sample};
use super::times::in_single_precision;
use crate::diff::Side;

/// The most times an interval between two base samples is halved.
const MAX_DEPTH: usize = 8;

/// `sampled` (at `times`, sorted) with midpoints added wherever `misses(bone, interpolated, exact)` says the
/// interpolation of an interval's ends misses its midpoint; the times and samples sorted, frames followed. The
/// interval that ends at a stepped key (`steps`, per time) holds the key's jump, which no halving brings closer: it
/// is left as it is.
pub fn refine(
    side: &Side,
    strategy: Strategy,
    times: Vec<f64>,
    steps: &[bool],
    sampled: Sampled,
    misses: &(impl Fn(usize, &NodeSample, &NodeSample) -> bool + Sync),
) -> (Vec<f64>, Sampled) {
    // Bones whose stretch rotation never matters at the first samples are judged without it (it turns at random
    // where the factors are nearly equal, and it will be dropped).
    let helper = sampled.stats.stretched.clone();
    let mut pool_times = times;
    let mut pool = sampled;
    let mut intervals: Vec<(usize, usize)> = (1..pool_times.len()).filter(|&i| !steps[i]).map(|i| (i - 1, i)).collect();
    for _ in 0..MAX_DEPTH {
        // Midpoints are taken in single precision, where their keys will be; an interval with no such time strictly
        // inside it is as fine as glTF can store.
        let middle = |&(a, b): &(usize, usize)| in_single_precision(0.5 * (pool_times[a] + pool_times[b]));
        intervals.retain(|interval| {
            (pool_times[interval.0] < middle(interval)) && (middle(interval) < pool_times[interval.1])
        });
        if intervals.is_empty() {
            break;
        }
        let middles: Vec<f64> = intervals.iter().map(middle).collect();
        let mut new = sample(side, &middles, strategy);
        let failed: Vec<bool> = new
            .samples
            .par_chunks_mut(pool.bones.max(1))
            .zip(&intervals)
            .zip(&middles)
            .map(|((middle, &(a, b)), &time)| {
                // The middle in single precision is not quite half way.
                let fraction = (time - pool_times[a]) / (pool_times[b] - pool_times[a]);
                let (left, right) = (pool.row(a), pool.row(b));
                let mut missed = false;
                for (bone, exact) in middle.iter_mut().enumerate() {
                    align(exact, &left[bone]);
                    let [a, b, middle] = [&left[bone], &right[bone], &*exact].map(|n| n.as_baked(helper[bone]));
                    missed |= too_far(&a, &b) || misses(bone, &interpolate(&a, &b, fraction), &middle);
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
