//! Sampling as densely as the source needs: wherever linear interpolation between two neighbouring samples of a
//! bone (under any of the rotation interpolations the keys must survive) misses the source at their midpoint by
//! more than the tolerance, the bone is sampled at the midpoints of both halves in turn.
//!
//! Frames and key times are not always enough. A parent whose scale doubles within a frame, under a child that
//! compensates it, needs the child's local scale to follow `1/s(t)`, a curve no straight line between two frames
//! follows (4 % off at the middle, in Maya's mixed-inheritance test file). So every interval's midpoint is sampled
//! and compared with the interpolation of its ends (and, for keys a runtime may play by nlerp, its ends checked to
//! be near enough in angle that nlerp cannot part from slerp by more than the tolerance: the two agree half way,
//! so the midpoint cannot show it); where a bone misses, its halves are, down to [`MAX_DEPTH`]
//! halvings. Only the bones that miss are sampled deeper (a pose is evaluated whole, but only their nodes are kept),
//! so a few compensating bones do not multiply the samples of the whole rig. Every midpoint sampled stays a sample
//! of the bones it was taken for, so the keys chosen later are checked against it too.

use rayon::prelude::*;

use super::Strategy;
use super::keys::too_far;
use super::nodes::{NodeSample, NodeSolver, Sampled, Series, Stats, align, follow_frames};
use super::times::{MIN_KEY_SPACING, in_single_precision};
use crate::eval::Evaluation;

/// The most times an interval between two base samples is halved.
const MAX_DEPTH: usize = 8;

/// A test of a bone's nodes interpolated a fraction of the way between two samples against its exact ones:
/// `misses(bone, [from, to], fraction, exact)`.
pub trait Misses: Fn(usize, [&NodeSample; 2], f64, &NodeSample) -> bool + Sync {}
impl<F: Fn(usize, [&NodeSample; 2], f64, &NodeSample) -> bool + Sync> Misses for F {}

/// `sampled` (every bone at the same sorted times, frames followed) with midpoints added to each bone wherever
/// `misses` says the interpolation of an interval's ends misses its midpoint; frames followed again. The interval
/// that ends at a stepped key (`steps`, per time) holds the key's jump, which no halving brings closer: it is left as
/// it is.
pub fn refine(
    source: &Evaluation,
    strategy: Strategy,
    steps: &[bool],
    sampled: Sampled,
    misses: &impl Misses,
) -> Sampled {
    let bones = sampled.series.len();
    let halving = Halving { sampled: &sampled, misses };
    let (stats, found) = (1..sampled.times.len())
        .into_par_iter()
        .filter(|&i| !steps[i])
        .fold(
            || (NodeSolver::new(source, strategy), Found::new(bones)),
            |(mut worker, mut found), i| {
                halving.base_interval(&mut worker, i, &mut found);
                (worker, found)
            },
        )
        .map(|(worker, found)| (worker.stats, found))
        .reduce(|| (Stats::new(bones), Found::new(bones)), |(a, one), (b, other)| (a.merge(b), one.merge(other)));
    found.merged_into(sampled, stats)
}

/// The midpoints taken: per bone, (time, nodes) of those taken for it; and every time taken.
struct Found {
    per_bone: Vec<Vec<(f64, NodeSample)>>,
    times: Vec<f64>,
}

impl Found {
    fn new(bones: usize) -> Self {
        Found { per_bone: vec![Vec::new(); bones], times: Vec::new() }
    }

    fn merge(mut self, other: Found) -> Self {
        for (mine, theirs) in self.per_bone.iter_mut().zip(other.per_bone) {
            mine.extend(theirs);
        }
        self.times.extend(other.times);
        self
    }

    /// `sampled` with the midpoints merged into their bones' series (frames followed again), every time any bone
    /// has, and what the midpoints taught about the bones (`stats`).
    fn merged_into(self, sampled: Sampled, stats: Stats) -> Sampled {
        let mut times = sampled.times;
        times.extend(self.times);
        times.sort_by(f64::total_cmp);
        times.dedup();
        let series: Vec<Series> = sampled
            .series
            .into_par_iter()
            .zip(self.per_bone)
            .map(|(series, extra)| {
                let mut merged = series.merged(extra);
                follow_frames(&mut merged);
                merged
            })
            .collect();
        Sampled { series, times, stats: sampled.stats.merge(stats) }
    }
}

/// The ends of an interval for one bone that is still being halved: (bone, nodes at the start, nodes at the end).
type Ends = (usize, NodeSample, NodeSample);

struct Halving<'a, M> {
    sampled: &'a Sampled,
    misses: &'a M,
}

impl<M: Misses> Halving<'_, M> {
    /// Halves the interval of base samples `i − 1` to `i` for every bone, its searches started from the interval's
    /// start (whichever interval a worker took before, the result is the same).
    fn base_interval(&self, worker: &mut NodeSolver, i: usize, found: &mut Found) {
        let ends: Vec<Ends> =
            self.sampled.series.iter().enumerate().map(|(bone, s)| (bone, s.nodes[i - 1], s.nodes[i])).collect();
        worker.start_near(ends.iter().map(|(_, start, _)| start));
        let times = &self.sampled.times;
        self.halve(worker, (times[i - 1], times[i]), ends, 0, found);
    }

    /// Samples the bones of `ends` at the middle of `span` (in single precision, where their keys will be; a span
    /// with no such time strictly inside it is as fine as glTF can store), and halves both halves for those that
    /// miss it, `depth` halvings deep.
    fn halve(&self, worker: &mut NodeSolver, span: (f64, f64), ends: Vec<Ends>, depth: usize, found: &mut Found) {
        let time = in_single_precision(0.5 * (span.0 + span.1));
        let room = (time - span.0).min(span.1 - time);
        if ends.is_empty() || depth == MAX_DEPTH || !(span.0 < time && time < span.1) || room < MIN_KEY_SPACING {
            return;
        }
        // The middle in single precision is not quite half way.
        let fraction = (time - span.0) / (span.1 - span.0);
        let helper = &self.sampled.stats.stretched;
        let row = worker.solve_at(time);
        found.times.push(time);
        let (mut left, mut right) = (Vec::new(), Vec::new());
        for (bone, a, b) in ends {
            let mut exact = row[bone];
            align(&mut exact, &a);
            found.per_bone[bone].push((time, exact));
            // Bones whose stretch rotation never matters at the base samples are judged without it (it turns at
            // random where the factors are nearly equal, and it will be dropped).
            let [a_baked, b_baked, middle] = [&a, &b, &exact].map(|n| n.as_baked(helper[bone]));
            if too_far(&a_baked, &b_baked) || (self.misses)(bone, [&a_baked, &b_baked], fraction, &middle) {
                left.push((bone, a, exact));
                right.push((bone, exact, b));
            }
        }
        self.halve(worker, (span.0, time), left, depth + 1, found);
        self.halve(worker, (time, span.1), right, depth + 1, found);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::import::demo_rig;
    use crate::model::InheritMode;

    #[test]
    fn only_the_bones_that_miss_are_halved_further() {
        let rig = demo_rig();
        let modes = vec![InheritMode::Full; rig.skeleton.len()];
        let side = Evaluation::new(&rig, rig.clips.first(), &modes).unwrap();
        let times: Vec<f64> = (0..=4).map(|k| f64::from(k) * 0.25).collect();
        let base = super::super::nodes::sample(&side, &times, Strategy::Exact);
        let missing = 2;
        let refined = refine(&side, Strategy::Exact, &[false; 5], base.clone(), &|bone, _, _, _: &_| bone == missing);
        let intervals = times.len() - 1;
        for (bone, series) in refined.series.iter().enumerate() {
            // Every interval's midpoint for every bone; for the one that misses, every level of halving.
            let expected = times.len() + intervals * if bone == missing { (1 << MAX_DEPTH) - 1 } else { 1 };
            assert_eq!(series.times.len(), expected, "bone {bone}");
            assert!(series.times.windows(2).all(|w| w[0] < w[1]), "bone {bone}: sorted and distinct");
            assert_eq!(series.times.len(), series.nodes.len());
        }
        assert_eq!(refined.times, refined.series[missing].times, "every time some bone has");
        let stepped = refine(&side, Strategy::Exact, &[false, true, true, true, true], base, &|_, _, _, _: &_| false);
        assert_eq!(stepped.series[0].times.len(), times.len(), "intervals that end at stepped keys are left");
    }

    #[test]
    fn an_interval_is_halved_alike_whatever_its_worker_solved_before() {
        // Workers take intervals in whatever order the threads run: what one finds must not depend on the times it
        // solved before (each search starts near the interval's start), or a bake differs from run to run. Under
        // segment compensate the demo rig's stretch rotations turn where two factors are nearly equal, so where a
        // search starts shows in the nodes found.
        let rig = demo_rig();
        let modes = vec![InheritMode::SegmentCompensate; rig.skeleton.len()];
        let side = Evaluation::new(&rig, rig.clips.first(), &modes).unwrap();
        let times: Vec<f64> = (0..=8).map(|k| f64::from(k) * 0.25).collect();
        let base = super::super::nodes::sample(&side, &times, Strategy::Exact);
        fn always(_: usize, _: [&NodeSample; 2], _: f64, _: &NodeSample) -> bool {
            true
        }
        let halving = Halving { sampled: &base, misses: &always };
        let halved = |earlier: &[f64]| {
            let mut worker = NodeSolver::new(&side, Strategy::Exact);
            earlier.iter().for_each(|&time| _ = worker.solve_at(time));
            let mut found = Found::new(rig.skeleton.len());
            halving.base_interval(&mut worker, 3, &mut found);
            found.per_bone
        };
        let fresh = halved(&[]);
        assert!(fresh.iter().all(|taken| taken.len() == (1 << MAX_DEPTH) - 1), "every bone halved throughout");
        assert_eq!(halved(&[1.9, 0.1]), fresh);
    }

    #[test]
    fn halving_stops_a_hundredth_of_a_frame_apart() {
        // Frames of 24 fps, a bone that always misses: halved while the halves stay 1/2400 s wide, 1/24 → 1/1536 s
        // (the next halves, 1/3072 s, would be closer than that), so 63 midpoints an interval.
        let rig = demo_rig();
        let modes = vec![InheritMode::Full; rig.skeleton.len()];
        let side = Evaluation::new(&rig, rig.clips.first(), &modes).unwrap();
        let times: Vec<f64> = (0..=4).map(|k| f64::from(k) / 24.0).collect();
        let base = super::super::nodes::sample(&side, &times, Strategy::Exact);
        let refined = refine(&side, Strategy::Exact, &[false; 5], base, &|bone, _, _, _: &_| bone == 2);
        let series = &refined.series[2].times;
        assert_eq!(series.len(), times.len() + 4 * 63);
        let closest = series.windows(2).map(|w| w[1] - w[0]).fold(f64::INFINITY, f64::min);
        assert!((MIN_KEY_SPACING..2.0 * MIN_KEY_SPACING).contains(&closest), "{closest}");
    }
}
