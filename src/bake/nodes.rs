//! What each bone's glTF nodes hold at each sampled time.
//!
//! A bone's baked local matrix is `L = W'_parent⁻¹ · W_bone`: what it needs under its already-baked parent so that
//! plain glTF composition (full inheritance) gives back the source's model matrix `W_bone` (a root's parent is the
//! source's unit and axes conversion, which the baked file carries on a node of its own, unless the root is a
//! conversion node and carries it itself). Its polar decomposition
//! `L = T·F·R·U·K·Uᵀ` becomes a [`NodeSample`] `T · Q · S · Vᵀ`:
//! - [`Strategy::Exact`]: `Q = R·U`, `S = F·K`, `V = U`. A bone that ever needs `U` (a stretched local matrix) gets a
//!   helper node carrying `T, Q, S` above itself, and carries `Vᵀ = Uᵀ` (a rotation) itself: exact, since
//!   `T·(R·U)·(F·K)·Uᵀ = L`. The others carry `T, R, F·K` (their `U` changes nothing).
//! - [`Strategy::Trs`]: one node per bone, `Q = R`, `S = F·diag(U·K·Uᵀ)` (the part of the stretch along the bone's
//!   own axes, the closest a TRS can come with that rotation), `V = I`; `W'` is the baked product, so each bone is
//!   solved against its parent as baked and the errors do not add up down the chain.
//!
//! Where a parent's matrix is singular (a bone scaled to zero) `L` is taken from the source's own local transform.
//! Every bone is solved at each time, in parallel over runs of time ([`solve`]); a [`Follower`] then makes each
//! bone's nodes (its `U` above all) continuous over time as they come.

use glam::{DMat3, DMat4, DQuat, DVec3};

use super::Strategy;
use crate::eval::{Evaluation, Evaluator, over_runs_of};
use crate::math::{AffineParts, affine_inverse, decompose_near, frobenius, stretch_nearest};
use crate::model::{Skeleton, affine};

/// A stretch rotation matters when dropping it moves `U·K·Uᵀ` by more than this fraction of the largest factor: a
/// few single-precision roundings. Less is the noise of a file's `f32` numbers (factors 1e-7 apart, whose frame
/// turns at random), which a helper node, itself stored in `f32`, could not carry anyway.
const STRETCH_MATTERS: f64 = 4.0 * f32::EPSILON as f64;

/// One bone's nodes at one time: the local matrix `T · Q · S · Vᵀ`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NodeSample {
    pub translation: DVec3,
    /// `R·U` with a helper, else `R`.
    pub rotation: DQuat,
    /// The factors with the mirror's sign.
    pub scale: DVec3,
    /// `U` with a helper (the bone node carries its inverse), else the identity in effect.
    pub stretch: DQuat,
}

impl NodeSample {
    pub const IDENTITY: NodeSample =
        NodeSample { translation: DVec3::ZERO, rotation: DQuat::IDENTITY, scale: DVec3::ONE, stretch: DQuat::IDENTITY };

    /// The local matrix the bone's nodes give.
    pub fn matrix(&self) -> DMat4 {
        let stretch = DMat3::from_quat(self.stretch);
        let linear = DMat3::from_quat(self.rotation) * DMat3::from_diagonal(self.scale) * stretch.transpose();
        affine(linear, self.translation)
    }

    /// The rotation of the single node of a bone without a helper: `R = Q·Vᵀ`.
    pub fn plain_rotation(&self) -> DQuat {
        (self.rotation * self.stretch.conjugate()).normalize()
    }

    /// The nodes of a bone without a helper: `T, R, S` (its `U` changes nothing).
    pub fn plain(&self) -> NodeSample {
        NodeSample { rotation: self.plain_rotation(), stretch: DQuat::IDENTITY, ..*self }
    }

    /// As the nodes of a bone with a helper (`helper`) or without.
    pub fn as_baked(&self, helper: bool) -> NodeSample {
        if helper { *self } else { self.plain() }
    }

    fn exact(parts: &AffineParts) -> Self {
        NodeSample {
            translation: parts.translation,
            rotation: (parts.rotation * parts.stretch).normalize(),
            scale: parts.scale * parts.sign,
            stretch: parts.stretch,
        }
    }

    fn trs(parts: &AffineParts) -> Self {
        let u = DMat3::from_quat(parts.stretch);
        let symmetric = u * DMat3::from_diagonal(parts.scale) * u.transpose();
        let along_axes = DVec3::new(symmetric.x_axis.x, symmetric.y_axis.y, symmetric.z_axis.z);
        NodeSample {
            translation: parts.translation,
            rotation: parts.rotation,
            scale: along_axes * parts.sign,
            stretch: DQuat::IDENTITY,
        }
    }
}

/// One bone's nodes at the times it is sampled at, in time order.
#[derive(Clone, Debug, Default, PartialEq)]
#[cfg(test)]
pub struct Series {
    pub times: Vec<f64>,
    pub nodes: Vec<NodeSample>,
}

/// Every bone's nodes at some times, bone by bone (what the tests compare).
#[derive(Clone, Debug)]
#[cfg(test)]
pub struct Sampled {
    /// One per bone.
    pub series: Vec<Series>,
    pub stats: Stats,
}

/// How many consecutive times are solved together (in runs of [`RUN`]), every bone at each: what is held at once
/// before it is handed on.
pub const BATCH: usize = 512;

/// How many consecutive times one solver solves, each search started near the time before (the first from the
/// identity): the same on every machine, so that the nodes, and the file, do not depend on the number of cores.
const RUN: usize = 256;

/// Samples `source` at `times` (sorted) for `strategy`, every bone at every time, bone by bone.
#[cfg(test)]
pub fn sample(source: &Evaluation, times: &[f64], strategy: Strategy) -> Sampled {
    let bones = source.skeleton().len();
    let empty = Series { times: times.to_vec(), nodes: Vec::with_capacity(times.len()) };
    let mut series = vec![empty; bones];
    let mut stats = Stats::new(bones);
    for batch in times.chunks(BATCH) {
        let (rows, found) = solve(source, batch, strategy);
        stats = stats.merge(found);
        for row in rows.chunks_exact(bones.max(1)) {
            series.iter_mut().zip(row).for_each(|(series, node)| series.nodes.push(*node));
        }
    }
    Sampled { series, stats }
}

/// Every bone's nodes at each of `times` (consecutive times of the clip from a multiple of [`RUN`] on), a row of
/// one per bone after another, and what solving them learnt. The times are solved in runs of [`RUN`], each run's
/// searches starting afresh, so a time's nodes are the same whichever times are solved with it.
pub fn solve(source: &Evaluation, times: &[f64], strategy: Strategy) -> (Vec<NodeSample>, Stats) {
    let bones = source.skeleton().len();
    let runs = over_runs_of(times, RUN, |run| {
        let mut solver = NodeSolver::new(source, strategy);
        let mut rows = Vec::with_capacity(run.len() * bones);
        for &time in run {
            rows.extend_from_slice(solver.solve_at(time));
        }
        (rows, solver.stats)
    });
    let mut stats = Stats::new(bones);
    let mut rows = Vec::with_capacity(times.len() * bones);
    for (run, found) in runs {
        rows.extend(run);
        stats = stats.merge(found);
    }
    (rows, stats)
}

/// What solving every bone at `times` (sorted) learns about the bones, [`BATCH`] times at a time: the nodes are not
/// kept.
pub fn stats(source: &Evaluation, times: &[f64], strategy: Strategy) -> Stats {
    let bones = source.skeleton().len();
    let batches = times.chunks(BATCH).map(|batch| {
        let runs = over_runs_of(batch, RUN, |run| {
            let mut solver = NodeSolver::new(source, strategy);
            run.iter().for_each(|&time| _ = solver.solve_at(time));
            solver.stats
        });
        runs.into_iter().fold(Stats::new(bones), Stats::merge)
    });
    batches.fold(Stats::new(bones), Stats::merge)
}

/// What sampling learns about the bones.
#[derive(Clone, Debug)]
pub struct Stats {
    /// Per bone: whether its `U` matters at some time.
    pub stretched: Vec<bool>,
    /// Per bone: an upper bound of how much its parent's baked matrix scales lengths (the largest Frobenius norm of
    /// the 3×3 part over time; 1 for roots).
    pub parent_gain: Vec<f64>,
    /// How many samples took a local transform from the source because the parent was singular.
    pub singular: usize,
}

impl Stats {
    pub fn new(bones: usize) -> Self {
        Stats { stretched: vec![false; bones], parent_gain: vec![0.0; bones], singular: 0 }
    }

    pub fn merge(mut self, other: Stats) -> Self {
        for (s, o) in self.stretched.iter_mut().zip(other.stretched) {
            *s |= o;
        }
        for (g, o) in self.parent_gain.iter_mut().zip(other.parent_gain) {
            *g = g.max(o);
        }
        self.singular += other.singular;
        self
    }
}

/// One thread's evaluation of the source: its pose, baked model matrices and findings.
pub struct NodeSolver<'e, 'a> {
    source: Evaluator<'e, 'a>,
    strategy: Strategy,
    parents: Vec<Option<usize>>,
    /// The source's unit and axes conversion and its inverse, and per bone whether it is a root that hangs from a
    /// node carrying it in the baked file ([`under_conversion`]); a root that is a conversion node carries it itself.
    conversion: DMat4,
    conversion_inverse: DMat4,
    under_conversion: Vec<bool>,
    /// `W'`: the model matrices the baked nodes give.
    baked: Vec<DMat4>,
    /// The previous time's stretch of each bone, where the search for this time's starts.
    previous: Vec<DQuat>,
    /// Every bone's nodes at the time last solved.
    row: Vec<NodeSample>,
    pub stats: Stats,
}

impl<'e, 'a> NodeSolver<'e, 'a> {
    pub fn new(source: &'e Evaluation<'a>, strategy: Strategy) -> Self {
        let parents: Vec<Option<usize>> = source.skeleton().bones().iter().map(|b| b.parent).collect();
        let bones = parents.len();
        NodeSolver {
            source: source.evaluator(),
            strategy,
            parents,
            conversion: source.skeleton().placement().conversion,
            conversion_inverse: source.skeleton().placement().conversion.inverse(),
            under_conversion: under_conversion(source.skeleton()),
            baked: vec![DMat4::IDENTITY; bones],
            previous: vec![DQuat::IDENTITY; bones],
            row: vec![NodeSample::IDENTITY; bones],
            stats: Stats::new(bones),
        }
    }

    /// Starts the next times' searches from `nodes` (each bone's, at a time solved before): what is solved then
    /// depends on those alone, not on whatever this solver solved last.
    pub fn start_near<'n>(&mut self, nodes: impl Iterator<Item = &'n NodeSample>) {
        for (previous, node) in self.previous.iter_mut().zip(nodes) {
            *previous = node.stretch;
        }
    }

    /// Every bone's nodes at `time`.
    pub fn solve_at(&mut self, time: f64) -> &[NodeSample] {
        self.source.evaluate(time);
        for bone in 0..self.parents.len() {
            self.row[bone] = self.solve(bone);
        }
        &self.row
    }

    /// The nodes of `bone` for the pose just evaluated, its parent's already solved.
    fn solve(&mut self, bone: usize) -> NodeSample {
        let parent = self.parents[bone];
        let pose = &self.source.pose;
        let source = pose.model.model[bone];
        let local = match parent {
            None if self.under_conversion[bone] => self.conversion_inverse * source,
            None => source,
            Some(p) => match affine_inverse(&self.baked[p]) {
                Some(inverse) => inverse * source,
                None => {
                    self.stats.singular += 1;
                    pose.local[bone].matrix()
                }
            },
        };
        let parts = decompose_near(&local, self.previous[bone]);
        self.previous[bone] = parts.stretch;
        let gain = parent.map_or(1.0, |p| frobenius(&self.baked[p]));
        self.stats.parent_gain[bone] = self.stats.parent_gain[bone].max(gain);
        match self.strategy {
            Strategy::Exact => {
                self.stats.stretched[bone] |= stretch_matters(&parts);
                self.baked[bone] = source;
                NodeSample::exact(&parts)
            }
            Strategy::Trs => {
                let sample = NodeSample::trs(&parts);
                let root_above = if self.under_conversion[bone] { self.conversion } else { DMat4::IDENTITY };
                let above = parent.map_or(root_above, |p| self.baked[p]);
                self.baked[bone] = above * sample.matrix();
                sample
            }
        }
    }
}

/// Whether dropping `U` would change `U·K·Uᵀ` by more than rounding.
fn stretch_matters(parts: &AffineParts) -> bool {
    if parts.stretch == DQuat::IDENTITY {
        return false;
    }
    let u = DMat3::from_quat(parts.stretch);
    let difference = u * DMat3::from_diagonal(parts.scale) * u.transpose() - DMat3::from_diagonal(parts.scale);
    let largest = difference.to_cols_array().iter().fold(0.0f64, |m, v| m.max(v.abs()));
    largest > STRETCH_MATTERS * parts.scale.abs().max_element()
}

/// Makes a bone's nodes continuous over time ([`Follower`]), the whole series at once.
#[cfg(test)]
pub fn follow_frames(series: &mut Series) {
    let mut follower = Follower::default();
    let mut followed = Vec::with_capacity(series.nodes.len());
    for (&time, &node) in series.times.iter().zip(&series.nodes) {
        follower.push(time, node, &mut followed);
    }
    follower.finish(&mut followed);
    series.nodes = followed.into_iter().map(|(_, node)| node).collect();
}

/// Makes a bone's nodes continuous over time as they come in time order: each sample [`align`]ed to the one before.
/// A sample of the bone scaled to nothing is held back until one where it is not, whose rotations it then takes
/// (where the bone is scaled to nothing from the start, the first where it is not); those at the end keep the
/// rotations before them.
#[derive(Clone, Debug, Default)]
pub struct Follower {
    last: Option<NodeSample>,
    held: Vec<(f64, NodeSample)>,
}

impl Follower {
    /// The bone's nodes at `time`, after those pushed before: what it settles goes to `out`, in time order.
    pub fn push(&mut self, time: f64, mut node: NodeSample, out: &mut Vec<(f64, NodeSample)>) {
        if let Some(last) = &self.last {
            align(&mut node, last);
        }
        self.last = Some(node);
        if node.scale == DVec3::ZERO {
            self.held.push((time, node));
            return;
        }
        out.extend(
            self.held
                .drain(..)
                .map(|(t, held)| (t, NodeSample { rotation: node.rotation, stretch: node.stretch, ..held })),
        );
        out.push((time, node));
    }

    /// Every sample pushed having come: those held back go to `out`.
    pub fn finish(&mut self, out: &mut Vec<(f64, NodeSample)>) {
        out.append(&mut self.held);
    }
}

/// Makes `current` continue from `previous`: its stretch frame becomes the equivalent one nearest the previous
/// sample's (the decomposition's canonical frame may swap axes between two samples), `Q = R·U` following it, and
/// both rotations move to the hemisphere of the previous ones, so slerp between keys takes the path the samples
/// mean.
///
/// A bone scaled to nothing has no rotation of its own (any gives the same matrix): it keeps the previous ones, so
/// that keys on either side of it do not turn the bone for nothing.
pub fn align(current: &mut NodeSample, previous: &NodeSample) {
    if current.scale == DVec3::ZERO {
        (current.rotation, current.stretch) = (previous.rotation, previous.stretch);
        return;
    }
    let rotation = current.plain_rotation();
    let sign = if current.scale.x.is_sign_negative() { -1.0 } else { 1.0 };
    let (stretch, factors) = stretch_nearest(current.stretch, current.scale * sign, previous.stretch);
    current.stretch = same_hemisphere(stretch, previous.stretch);
    current.scale = factors * sign;
    current.rotation = same_hemisphere((rotation * current.stretch).normalize(), previous.rotation);
}

/// `q` or `−q`, whichever is nearer `reference`.
fn same_hemisphere(q: DQuat, reference: DQuat) -> DQuat {
    if q.dot(reference) < 0.0 { -q } else { q }
}

/// Per bone, whether it is a root the baked file hangs from a node carrying the skeleton's unit and axes
/// conversion: every root but the conversion nodes (which carry it themselves, as an exporter's armature scaled
/// 100 under a centimetre file becomes one of scale 1), where there is a conversion.
pub fn under_conversion(skeleton: &Skeleton) -> Vec<bool> {
    let placement = skeleton.placement();
    let converts = placement.conversion != DMat4::IDENTITY;
    let roots = skeleton.bones().iter().enumerate();
    roots.map(|(i, bone)| converts && bone.parent.is_none() && !placement.is_conversion(i)).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::import::demo_rig;
    use crate::model::InheritMode;

    /// The demo rig with every bone compensating its parent's scale, and `count + 1` times evenly over its clip.
    fn compensated_demo(count: u32, test: impl FnOnce(&Evaluation, &[f64])) {
        let rig = demo_rig();
        let modes = vec![InheritMode::SegmentCompensate; rig.skeleton.len()];
        let side = Evaluation::new(&rig, rig.clips.first(), &modes).unwrap();
        let span = side.span();
        let times: Vec<f64> =
            (0..=count).map(|k| span.start + f64::from(k) * span.length() / f64::from(count)).collect();
        test(&side, &times);
    }

    #[test]
    fn the_samples_are_the_same_whatever_the_number_of_cores() {
        // A solver's searches start near the time it solved before, so where runs start shows in the nodes (the demo
        // rig's compensated bones turn their stretch where two factors are nearly equal): runs of a fixed length.
        compensated_demo(1000, |side, times| {
            let on = |threads: usize| {
                let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
                pool.install(|| sample(side, times, Strategy::Exact).series)
            };
            let one = on(1);
            assert_eq!(on(3), one);
            assert_eq!(on(16), one);
        });
    }

    #[test]
    fn exact_samples_give_back_every_model_matrix() {
        compensated_demo(20, |side, times| {
            let rig = side.rig;
            let mut sampled = sample(side, times, Strategy::Exact);
            let helper = sampled.stats.stretched.clone();
            assert!(helper.contains(&true), "the demo's compensated forearm is stretched in its local matrix");
            sampled.series.iter_mut().for_each(follow_frames);
            for (s, &time) in times.iter().enumerate() {
                let pose = side.pose_at(time);
                let mut baked: Vec<DMat4> = Vec::new();
                for (bone, b) in rig.skeleton.bones().iter().enumerate() {
                    let local = sampled.series[bone].nodes[s].as_baked(helper[bone]).matrix();
                    baked.push(b.parent.map_or(local, |p| baked[p] * local));
                    assert!(baked[bone].abs_diff_eq(pose.model.model[bone], 1e-12), "{} at {time}", b.name);
                }
            }
        });
    }

    #[test]
    fn frames_follow_the_previous_sample() {
        // One bone whose stretch frame is handed over swapped at every other sample.
        let swap = DQuat::from_rotation_z(std::f64::consts::FRAC_PI_2);
        let frame = DQuat::from_rotation_x(0.3);
        let k = DVec3::new(1.0, 2.0, 3.0);
        let mut samples: Vec<NodeSample> = (0..6)
            .map(|s| {
                let (stretch, scale) = if s % 2 == 0 { (frame, k) } else { (frame * swap, DVec3::new(2.0, 1.0, 3.0)) };
                let parts =
                    AffineParts { translation: DVec3::ZERO, rotation: DQuat::IDENTITY, stretch, scale, sign: 1.0 };
                NodeSample::exact(&parts)
            })
            .collect();
        let matrices: Vec<DMat4> = samples.iter().map(NodeSample::matrix).collect();
        let mut series = Series { times: (0..6).map(f64::from).collect(), nodes: std::mem::take(&mut samples) };
        follow_frames(&mut series);
        for (s, m) in matrices.iter().enumerate() {
            let node = &series.nodes[s];
            assert!(node.matrix().abs_diff_eq(*m, 1e-12), "sample {s} keeps its matrix");
            assert!(node.stretch.abs_diff_eq(frame, 1e-12), "sample {s}: {:?}", node.stretch);
            assert_eq!(node.scale, k);
        }
    }

    #[test]
    fn a_bone_scaled_to_nothing_takes_the_rotations_of_the_next_sample_where_it_is_not() {
        // Samples 0–1 and 4–5 scaled to nothing, 2–3 and 6 not, 7–8 to nothing again: 0–1 take sample 2's rotations,
        // 4–5 sample 6's, and 7–8 (nothing after them) keep those before them, whatever order they came in.
        let turned = |angle: f64, scale: f64| NodeSample {
            rotation: DQuat::from_rotation_z(angle),
            scale: DVec3::splat(scale),
            ..NodeSample::IDENTITY
        };
        let scales = [0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 2.0, 0.0, 0.0];
        let nodes: Vec<NodeSample> = scales.iter().enumerate().map(|(s, &k)| turned(0.1 * s as f64, k)).collect();
        let mut follower = Follower::default();
        let mut out = Vec::new();
        let mut settled = Vec::new();
        for (s, node) in nodes.iter().enumerate() {
            follower.push(s as f64, *node, &mut out);
            settled.push(out.len());
        }
        assert_eq!(settled, [0, 0, 3, 4, 4, 4, 7, 7, 7], "held back while scaled to nothing");
        follower.finish(&mut out);
        let angles: Vec<f64> = out.iter().map(|(_, n)| 2.0 * n.rotation.z.atan2(n.rotation.w)).collect();
        let expected = [0.2, 0.2, 0.2, 0.3, 0.6, 0.6, 0.6, 0.6, 0.6];
        assert!(angles.iter().zip(expected).all(|(a, e)| (a - e).abs() < 1e-12), "{angles:?}");
        assert!(out.iter().enumerate().all(|(s, (t, n))| *t == s as f64 && n.scale == nodes[s].scale));
    }

    #[test]
    fn trs_nodes_keep_the_stretch_along_the_axes() {
        // A 45° stretch frame about Z with factors (2, 1, 1): U·K·Uᵀ has 1.5 on the X and Y diagonal.
        let parts = AffineParts {
            translation: DVec3::X,
            rotation: DQuat::from_rotation_y(0.2),
            stretch: DQuat::from_rotation_z(std::f64::consts::FRAC_PI_4),
            scale: DVec3::new(2.0, 1.0, 1.0),
            sign: -1.0,
        };
        let node = NodeSample::trs(&parts);
        assert!(node.scale.abs_diff_eq(DVec3::new(-1.5, -1.5, -1.0), 1e-12));
        assert_eq!((node.rotation, node.stretch), (parts.rotation, DQuat::IDENTITY));
    }
}
