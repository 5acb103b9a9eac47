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
//!
//! A clip is sampled [`BATCH`] base times at a time and each batch's samples handed on as soon as they are settled
//! ([`Dense::run`]), so what is held is a batch, not the clip: a long clip of many bones has millions of samples.

use std::collections::VecDeque;

use rayon::prelude::*;

use super::Strategy;
use super::keys::too_far;
use super::nodes::{BATCH, Follower, NodeSample, NodeSolver, Stats, align, solve};
use super::times::{MIN_KEY_SPACING, in_single_precision};
use crate::eval::Evaluation;

/// The most times an interval between two base samples is halved.
const MAX_DEPTH: usize = 8;

/// A test of a bone's nodes interpolated a fraction of the way between two samples against its exact ones:
/// `misses(bone, [from, to], fraction, exact)`.
pub trait Misses: Fn(usize, [&NodeSample; 2], f64, &NodeSample) -> bool + Sync {}
impl<F: Fn(usize, [&NodeSample; 2], f64, &NodeSample) -> bool + Sync> Misses for F {}

/// One clip sampled at its base times (sorted) and, where `misses` says the interpolation of an interval's ends
/// misses its midpoint, between them; `helper` says which bones' stretch rotations matter at the base times (the
/// others are judged without it). The interval that ends at a stepped key (`steps`, per base time) holds the key's
/// jump, which no halving brings closer: it is left as it is. Without `misses` (a zero tolerance, which no halving
/// could reach) the base times alone.
pub struct Dense<'a, M> {
    pub source: &'a Evaluation<'a>,
    pub strategy: Strategy,
    pub times: &'a [f64],
    pub steps: &'a [bool],
    pub helper: &'a [bool],
    pub misses: Option<&'a M>,
}

/// What a run through a clip learnt: about the bones, from every sample, and every time some bone was sampled at
/// (sorted).
pub struct Refined {
    pub stats: Stats,
    pub times: Vec<f64>,
}

impl<M: Misses> Dense<'_, M> {
    /// Runs through the clip in batches of base times: each batch solved, every bone's base samples made continuous
    /// ([`Follower`]), the intervals between them halved where they miss, and each bone's samples (base and
    /// midpoints, in time order, made continuous again) handed to `feed` with its state, one of `states` per bone
    /// (none: the samples are not wanted).
    pub fn run<S: Send>(&self, states: &mut [S], feed: impl Fn(&mut S, &[(f64, NodeSample)]) + Sync) -> Refined {
        let bones = self.source.skeleton().len();
        let mut pass = Pass {
            stats: Stats::new(bones),
            times: Vec::with_capacity(self.times.len()),
            base: vec![Follower::default(); bones],
            dense: vec![Follower::default(); bones],
            settled: (0..bones).map(|_| VecDeque::with_capacity(BATCH + 1)).collect(),
            first: 0,
            handed: false,
        };
        for (b, batch) in self.times.chunks(BATCH).enumerate() {
            let (rows, found) = solve(self.source, batch, self.strategy);
            pass.learn(found);
            pass.base.par_iter_mut().zip(&mut pass.settled).enumerate().for_each(|(bone, (follower, settled))| {
                let mut followed = Vec::with_capacity(batch.len());
                for (s, &time) in batch.iter().enumerate() {
                    follower.push(time, rows[s * bones + bone], &mut followed);
                }
                settled.extend(followed.iter().map(|(_, node)| *node));
            });
            let last = b * BATCH + batch.len() == self.times.len();
            if last {
                self.settle_the_rest(&mut pass);
            }
            self.hand_on(&mut pass, states, &feed, last);
        }
        pass.times.sort_by(f64::total_cmp);
        pass.times.dedup();
        Refined { stats: pass.stats, times: pass.times }
    }

    /// Every sample held back settled: the clip is over.
    fn settle_the_rest(&self, pass: &mut Pass) {
        for (follower, settled) in pass.base.iter_mut().zip(&mut pass.settled) {
            let mut followed = Vec::new();
            follower.finish(&mut followed);
            settled.extend(followed.iter().map(|(_, node)| *node));
        }
    }

    /// Halves the intervals between the base samples every bone has settled, and hands each bone's samples up to
    /// the last of them on (all that are left, at the clip's `end`).
    fn hand_on<S: Send>(
        &self,
        pass: &mut Pass,
        states: &mut [S],
        feed: &(impl Fn(&mut S, &[(f64, NodeSample)]) + Sync),
        end: bool,
    ) {
        let ready = pass.settled.iter().map(VecDeque::len).min().unwrap_or(0);
        if ready == 0 {
            return;
        }
        let (first, from) = (pass.first, usize::from(pass.handed));
        // Base sample `first + s` is handed on after the midpoints of the interval that ends at it (the clip's first
        // sample has none).
        let intervals = (first + 1..first + ready).filter(|&k| !self.steps[k]).collect();
        let found = self.halved(pass, intervals);
        pass.times.extend(&self.times[first + from..first + ready]);
        pass.times.extend(found.iter().flat_map(|found| &found.times));
        // Without states nothing is handed on: what the pass learns is all it is for.
        let mut found = if states.is_empty() { Vec::new() } else { per_bone(found, pass.settled.len()) };
        let settled = &pass.settled;
        states.par_iter_mut().zip(&mut pass.dense).zip(&mut found).enumerate().for_each(
            |(bone, ((state, follower), midpoints))| {
                let mut midpoints = midpoints.drain(..).peekable();
                let mut out = Vec::new();
                for (s, &node) in settled[bone].iter().enumerate().take(ready).skip(from) {
                    let time = self.times[first + s];
                    if self.misses.is_none() {
                        // Nothing halved: the base samples, already continuous.
                        out.push((time, node));
                        continue;
                    }
                    while let Some((t, midpoint)) = midpoints.next_if(|(t, _)| *t < time) {
                        follower.push(t, midpoint, &mut out);
                    }
                    follower.push(time, node, &mut out);
                }
                if end {
                    follower.finish(&mut out);
                }
                feed(state, &out);
            },
        );
        // The last base sample handed on starts the next interval.
        pass.settled.iter_mut().for_each(|settled| _ = settled.drain(..ready - 1));
        (pass.first, pass.handed) = (first + ready - 1, true);
    }

    /// The midpoints taken in each of the intervals that end at base samples `ends` (each starting at the sample
    /// before), every bone's starting from `pass.settled` (whose front is base sample `pass.first`), in parallel:
    /// each interval's searches start from its start, so whichever worker takes it finds the same.
    fn halved(&self, pass: &mut Pass, ends: Vec<usize>) -> Vec<Found> {
        let bones = pass.settled.len();
        let Some(misses) = self.misses else { return Vec::new() };
        let halving = Halving { helper: self.helper, misses };
        let (settled, first) = (&pass.settled, pass.first);
        let found: Vec<(Found, Stats)> = ends
            .into_par_iter()
            .map_init(
                || NodeSolver::new(self.source, self.strategy),
                |worker, k| {
                    let ends = (0..bones).map(|bone| (bone, settled[bone][k - 1 - first], settled[bone][k - first]));
                    let span = (self.times[k - 1], self.times[k]);
                    let mut found = Found::default();
                    halving.interval(worker, span, ends.collect(), &mut found);
                    (found, std::mem::replace(&mut worker.stats, Stats::new(bones)))
                },
            )
            .collect();
        found
            .into_iter()
            .map(|(found, stats)| {
                pass.learn(stats);
                found
            })
            .collect()
    }
}

/// A run through a clip while it goes on.
struct Pass {
    stats: Stats,
    /// Every time sampled so far.
    times: Vec<f64>,
    /// Per bone: its base samples and all its samples, made continuous.
    base: Vec<Follower>,
    dense: Vec<Follower>,
    /// Per bone: its base samples made continuous and settled, from base sample `first` on, not handed on yet (but
    /// the first where `handed`: it starts the next interval).
    settled: Vec<VecDeque<NodeSample>>,
    first: usize,
    handed: bool,
}

impl Pass {
    /// What solving some samples learnt, added to what is known.
    fn learn(&mut self, stats: Stats) {
        let bones = self.base.len();
        self.stats = std::mem::replace(&mut self.stats, Stats::new(bones)).merge(stats);
    }
}

/// The midpoints taken in one interval: (bone, time, nodes) of those taken for each bone; and every time taken.
#[derive(Default)]
struct Found {
    midpoints: Vec<(usize, f64, NodeSample)>,
    times: Vec<f64>,
}

/// Each of `bones`' midpoints among `found`, in time order.
fn per_bone(found: Vec<Found>, bones: usize) -> Vec<Vec<(f64, NodeSample)>> {
    let mut counts = vec![0; bones];
    found.iter().flat_map(|f| &f.midpoints).for_each(|&(bone, ..)| counts[bone] += 1);
    let mut per_bone: Vec<Vec<(f64, NodeSample)>> = counts.into_iter().map(Vec::with_capacity).collect();
    for (bone, time, node) in found.into_iter().flat_map(|f| f.midpoints) {
        per_bone[bone].push((time, node));
    }
    per_bone.iter_mut().for_each(|midpoints| midpoints.sort_by(|a, b| a.0.total_cmp(&b.0)));
    per_bone
}

/// The ends of an interval for one bone that is still being halved: (bone, nodes at the start, nodes at the end).
type Ends = (usize, NodeSample, NodeSample);

/// The halving of intervals: which bones' stretch rotations matter at the base samples, and where a bone misses.
struct Halving<'a, M> {
    helper: &'a [bool],
    misses: &'a M,
}

impl<M: Misses> Halving<'_, M> {
    /// Halves the interval `span` for the bones of `ends` (every bone, with its nodes at both ends), its searches
    /// started from the interval's start (whichever interval a worker took before, the result is the same).
    fn interval(&self, worker: &mut NodeSolver, span: (f64, f64), ends: Vec<Ends>, found: &mut Found) {
        worker.start_near(ends.iter().map(|(_, start, _)| start));
        self.halve(worker, span, ends, 0, found);
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
        let helper = self.helper;
        let row = worker.solve_at(time);
        found.times.push(time);
        let (mut left, mut right) = (Vec::new(), Vec::new());
        for (bone, a, b) in ends {
            let mut exact = row[bone];
            align(&mut exact, &a);
            found.midpoints.push((bone, time, exact));
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
    use std::sync::Arc;

    use glam::{DQuat, DVec3, Quat, Vec3};

    use super::*;
    use crate::bake::nodes::{self, Series, follow_frames};
    use crate::import::demo_rig;
    use crate::model::{Bone, BoneTracks, Clip, InheritMode, Interpolation, Rig, Skeleton, Track, Transform};

    /// Every bone's samples of `side` at `times` as [`Dense::run`] hands them on, and what it learnt.
    fn densely(side: &Evaluation, times: &[f64], steps: &[bool], misses: &impl Misses) -> (Vec<Series>, Refined) {
        let first = nodes::stats(side, times, Strategy::Exact);
        let dense = Dense {
            source: side,
            strategy: Strategy::Exact,
            times,
            steps,
            helper: &first.stretched,
            misses: Some(misses),
        };
        let mut series = vec![Series::default(); side.skeleton().len()];
        let refined = dense.run(&mut series, |series, samples| {
            for &(time, node) in samples {
                series.times.push(time);
                series.nodes.push(node);
            }
        });
        (series, refined)
    }

    /// The same, the whole clip at once: every base sample, then every interval halved, then each bone's midpoints
    /// merged in and its frames followed again.
    fn whole(side: &Evaluation, times: &[f64], steps: &[bool], misses: &impl Misses) -> Vec<Series> {
        let mut base = nodes::sample(side, times, Strategy::Exact);
        base.series.iter_mut().for_each(follow_frames);
        let halving = Halving { helper: &base.stats.stretched, misses };
        let mut found = Found::default();
        for k in (1..times.len()).filter(|&k| !steps[k]) {
            let mut worker = NodeSolver::new(side, Strategy::Exact);
            let ends = base.series.iter().enumerate().map(|(bone, s)| (bone, s.nodes[k - 1], s.nodes[k]));
            halving.interval(&mut worker, (times[k - 1], times[k]), ends.collect(), &mut found);
        }
        let bones = base.series.len();
        base.series
            .into_iter()
            .zip(per_bone(vec![found], bones))
            .map(|(series, extra)| {
                let mut all: Vec<(f64, NodeSample)> = series.times.into_iter().zip(series.nodes).chain(extra).collect();
                all.sort_by(|a, b| a.0.total_cmp(&b.0));
                let (times, nodes) = all.into_iter().unzip();
                let mut merged = Series { times, nodes };
                follow_frames(&mut merged);
                merged
            })
            .collect()
    }

    #[test]
    fn only_the_bones_that_miss_are_halved_further() {
        let rig = demo_rig();
        let modes = vec![InheritMode::Full; rig.skeleton.len()];
        let side = Evaluation::new(&rig, rig.clips.first(), &modes).unwrap();
        let times: Vec<f64> = (0..=4).map(|k| f64::from(k) * 0.25).collect();
        let missing = 2;
        let (refined, found) = densely(&side, &times, &[false; 5], &|bone, _, _, _: &_| bone == missing);
        let intervals = times.len() - 1;
        for (bone, series) in refined.iter().enumerate() {
            // Every interval's midpoint for every bone; for the one that misses, every level of halving.
            let expected = times.len() + intervals * if bone == missing { (1 << MAX_DEPTH) - 1 } else { 1 };
            assert_eq!(series.times.len(), expected, "bone {bone}");
            assert!(series.times.windows(2).all(|w| w[0] < w[1]), "bone {bone}: sorted and distinct");
        }
        assert_eq!(found.times, refined[missing].times, "every time some bone has");
        let (stepped, _) = densely(&side, &times, &[false, true, true, true, true], &|_, _, _, _: &_| false);
        assert_eq!(stepped[0].times, times, "intervals that end at stepped keys are left");
    }

    /// A chain of three bones whose middle one turns and is scaled to nothing from 4.2 s to 6 s of a 13 s clip.
    fn vanishing_rig() -> Rig {
        let track = |times: &[f64], values: Vec<Vec3>| {
            Some(Track::new(Arc::from(times), values, Interpolation::Linear).unwrap())
        };
        let mut middle = BoneTracks::new(1);
        let scale = [Vec3::ONE, Vec3::ONE, Vec3::ZERO, Vec3::ZERO, Vec3::ONE, Vec3::new(2.0, 1.0, 1.0)];
        middle.scale = track(&[0.0, 4.0, 4.2, 6.0, 6.5, 13.0], scale.to_vec());
        let turns: Vec<Quat> = (0..14).map(|s| Quat::from_rotation_z(0.4 * s as f32)).collect();
        let times: Vec<f64> = (0..14).map(f64::from).collect();
        middle.rotation = Some(Track::new(Arc::from(times.as_slice()), turns, Interpolation::Linear).unwrap());
        let along = Transform::from_trs(DVec3::X, DQuat::from_rotation_y(0.3), DVec3::ONE);
        let bones = vec![
            Bone::joint("root", None, Transform::IDENTITY),
            Bone::joint("middle", Some(0), along),
            Bone::joint("tip", Some(1), along),
        ];
        let clip = Clip::new(0, None, vec![middle], vec![]);
        Rig { skeleton: Skeleton::new(bones).unwrap(), clips: vec![clip], ..Rig::default() }
    }

    #[test]
    fn a_clip_sampled_a_batch_at_a_time_is_the_clip_sampled_whole() {
        // 1,301 base times, so batches end inside the stretch where the middle bone is scaled to nothing (its samples
        // held back until it is not) and inside deep halvings; a stepped key at every 97th time. Under segment
        // compensate the tip's stretch turns, so where each search starts shows in the nodes.
        let rig = vanishing_rig();
        for mode in [InheritMode::Full, InheritMode::SegmentCompensate] {
            let side = Evaluation::new(&rig, rig.clips.first(), &[InheritMode::Full, InheritMode::Full, mode]).unwrap();
            let times: Vec<f64> = (0..=1300).map(|k| f64::from(k) / 100.0).collect();
            let steps: Vec<bool> = (0..times.len()).map(|k| k.is_multiple_of(97)).collect();
            let misses = |bone: usize, _: [&NodeSample; 2], _: f64, exact: &NodeSample| {
                bone == 2 && exact.translation.x.to_bits().is_multiple_of(5)
            };
            let (series, refined) = densely(&side, &times, &steps, &misses);
            assert_eq!(series, whole(&side, &times, &steps, &misses), "{mode:?}");
            assert!(series[2].times.len() > times.len() * 6 / 5, "the tip is halved further in places");
            let zero = series[1].nodes.iter().filter(|n| n.scale == DVec3::ZERO).count();
            assert!(zero > 150, "the middle bone is scaled to nothing across a batch's end: {zero}");
            let every: Vec<f64> = series[2].times.clone();
            assert_eq!(refined.times, every, "every time some bone has");
        }
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
        let mut base = nodes::sample(&side, &times, Strategy::Exact);
        base.series.iter_mut().for_each(follow_frames);
        fn always(_: usize, _: [&NodeSample; 2], _: f64, _: &NodeSample) -> bool {
            true
        }
        let halving = Halving { helper: &base.stats.stretched, misses: &always };
        let halved = |earlier: &[f64]| {
            let mut worker = NodeSolver::new(&side, Strategy::Exact);
            earlier.iter().for_each(|&time| _ = worker.solve_at(time));
            let mut found = Found::default();
            let ends = base.series.iter().enumerate().map(|(bone, s)| (bone, s.nodes[2], s.nodes[3]));
            halving.interval(&mut worker, (times[2], times[3]), ends.collect(), &mut found);
            per_bone(vec![found], rig.skeleton.len())
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
        let (refined, _) = densely(&side, &times, &[false; 5], &|bone, _, _, _: &_| bone == 2);
        let series = &refined[2].times;
        assert_eq!(series.len(), times.len() + 4 * 63);
        let closest = series.windows(2).map(|w| w[1] - w[0]).fold(f64::INFINITY, f64::min);
        assert!((MIN_KEY_SPACING..2.0 * MIN_KEY_SPACING).contains(&closest), "{closest}");
    }
}
