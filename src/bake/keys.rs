//! Which samples become keys: the fewest, greedily, such that linear interpolation between neighbouring keys
//! reproduces every dropped sample within a tolerance, with rotations interpolated as every runtime the bake is for
//! does it: glTF's slerp, and the component-wise nlerp of players that make one curve per quaternion component
//! (Blender's importer, Unity's quaternion curves, Unreal's compressed tracks), which normalise afterwards.
//!
//! Between two keys far apart in angle the two part by more than any tolerance: keys `θ` apart (as rotations) give
//! rotations up to `θ³/240` apart ([`nlerp_departure`]; `docs/bake-interpolation.md` derives it), 2e-5 rad for
//! keys 10° apart but 1.6e-2 rad at 90°. So every dropped sample is checked against each interpolation.
//!
//! From each key the next one is pushed as far as it goes: the span doubles while every sample inside it is
//! reproduced, then a binary search finds the farthest span that still is. Every span chosen has been checked
//! sample by sample, so the result always holds; a whole clip costs `O(n log L)` checks for spans of `L` samples.

use std::f64::consts::SQRT_2;

use glam::{DMat3, DMat4, DQuat, DVec3};

use super::nodes::NodeSample;
use crate::diff::PROBE_FRACTION;
use crate::eval::layers::RotationInterpolation;
use crate::eval::{Evaluation, Pose, skin_meshes};
use crate::math::angle_between;

/// The indices of the samples to keep among `count` (the first and last always), such that
/// `error(i, j, k) ≤ tolerance` for every dropped `k` between its kept neighbours `i < k < j`.
pub fn reduce(count: usize, tolerance: f64, error: impl Fn(usize, usize, usize) -> f64) -> Vec<usize> {
    let mut reducer = Reducer::default();
    reducer.finish(count, tolerance, error);
    reducer.keys
}

/// [`reduce`] as the samples come: it keeps the keys it can choose from the samples known so far, and needs no
/// sample before [`Reducer::from`] again, so a caller may drop them. The keys are [`reduce`]'s whatever the samples'
/// arrival.
#[derive(Clone, Debug, Default)]
pub struct Reducer {
    /// The keys chosen so far.
    pub keys: Vec<usize>,
    /// The last key, from which the next is pushed as far as it goes.
    from: usize,
    /// The farthest sample the span from `from` is known to reach, and how far the next try goes beyond it.
    good: usize,
    step: usize,
}

impl Reducer {
    /// The first sample the keys still to come may need.
    pub fn from(&self) -> usize {
        self.from
    }

    /// Chooses the keys `count` samples known so far settle (more follow).
    pub fn grow(&mut self, count: usize, tolerance: f64, error: impl Fn(usize, usize, usize) -> f64) {
        self.choose(count, None, tolerance, error);
    }

    /// Chooses the rest of the keys, `count` being every sample.
    pub fn finish(&mut self, count: usize, tolerance: f64, error: impl Fn(usize, usize, usize) -> f64) {
        if count == 0 {
            return;
        }
        self.choose(count, Some(count - 1), tolerance, error);
    }

    /// From each key the next one is pushed as far as it goes: the span doubles while every sample inside it is
    /// reproduced, then a binary search finds the farthest span that still is. Without `last` (the last sample's
    /// index), it stops where a span would reach past the `known` samples.
    fn choose(
        &mut self,
        known: usize,
        last: Option<usize>,
        tolerance: f64,
        error: impl Fn(usize, usize, usize) -> f64,
    ) {
        if known == 0 {
            return;
        }
        let spans = |from: usize, to: usize| (from + 1..to).all(|k| error(from, to, k) <= tolerance);
        if self.keys.is_empty() {
            self.keys.push(0);
            (self.good, self.step) = (1, 1);
        }
        while last.is_none_or(|last| self.from < last) {
            let mut bad = None;
            loop {
                let candidate = match last {
                    Some(last) if self.good >= last => break,
                    Some(last) => (self.good + self.step).min(last),
                    None if self.good + self.step >= known => return,
                    None => self.good + self.step,
                };
                if spans(self.from, candidate) {
                    self.good = candidate;
                    self.step *= 2;
                } else {
                    bad = Some(candidate);
                    break;
                }
            }
            if let Some(mut bad) = bad {
                while bad - self.good > 1 {
                    let middle = self.good + (bad - self.good) / 2;
                    if spans(self.from, middle) { self.good = middle } else { bad = middle }
                }
            }
            self.keys.push(self.good);
            self.from = self.good;
            (self.good, self.step) = (self.from + 1, 1);
        }
    }
}

/// How far each bone's nodes may stray between keys, and how it is measured ([`BoneMetric`]).
pub struct Metrics {
    /// How far a bone's interpolated nodes may be from a sample, and its samples from the source's curve between
    /// them: each bone's share of the tolerance (the errors of a chain's bones add up at its end, so the tolerance
    /// over the longest chain), halved, since keys that stay within it of the samples, which stay within it of
    /// the source, stay within twice it of the source.
    pub budget: f64,
    /// Per bone: how far from its origin the points it moves lie, in its own units ([`reaches`]).
    reach: Vec<f64>,
    /// How far a morph target's displacement reaches in model units per unit of offset.
    pub model_scale: f64,
    /// The rotation interpolations the keys must survive.
    rotations: &'static [RotationInterpolation],
}

impl Metrics {
    /// For the rig of `rest` (its rest pose under the bake's modes), `size` and `tolerance` in model units, keys
    /// that must survive every interpolation of `rotations`.
    pub fn new(rest: &Evaluation, size: f64, tolerance: f64, rotations: &'static [RotationInterpolation]) -> Self {
        let pose = rest.pose_at(0.0);
        let scales: Vec<f64> = pose.model.model.iter().map(uniform_scale).collect();
        let mut sorted: Vec<f64> = scales.iter().copied().filter(|s| *s > 0.0).collect();
        sorted.sort_by(f64::total_cmp);
        let typical = sorted.get(sorted.len() / 2).copied().unwrap_or(1.0);
        let reach = reaches(rest, &pose, size * PROBE_FRACTION)
            .iter()
            .zip(&scales)
            .map(|(&r, &s)| r / if s > 1e-6 * typical { s } else { typical })
            .collect();
        let chain = rest.rig.skeleton.depths().into_iter().max().map_or(1, |d| d + 1);
        Metrics { budget: 0.5 * tolerance / chain as f64, reach, model_scale: typical, rotations }
    }

    /// The metric of `bone`, whose parent scales lengths by at most `gains[bone]`.
    pub fn bone(&self, gains: &[f64], bone: usize) -> BoneMetric {
        BoneMetric { gain: gains[bone].max(f64::MIN_POSITIVE), reach: self.reach[bone], rotations: self.rotations }
    }
}

/// How far from each bone's origin, at rest, the points it moves lie: its descendants' origins, the vertices skinned
/// to them or to it, and the probe points the report measures (`probe` out), with half as much again for the motion
/// of the descendants' own animation.
fn reaches(rest: &Evaluation, pose: &Pose, probe: f64) -> Vec<f64> {
    let skeleton = &rest.rig.skeleton;
    let origins: Vec<DVec3> = pose.model.model.iter().map(|m| m.w_axis.truncate()).collect();
    let mut reach = vec![probe; skeleton.len()];
    let mut reach_up = |bone: usize, point: DVec3| {
        let mut current = Some(bone);
        while let Some(b) = current {
            reach[b] = reach[b].max(point.distance(origins[b]));
            current = skeleton.parent(b);
        }
    };
    for (bone, &origin) in origins.iter().enumerate() {
        reach_up(bone, origin);
    }
    let rig = rest.rig;
    for (mesh, positions) in rig.meshes.iter().zip(skin_meshes(rig, &pose.model.model, &pose.morph)) {
        for (v, position) in positions.into_iter().enumerate() {
            let bones = match mesh.skin.and_then(|s| rig.skins.get(s)) {
                Some(skin) => mesh.joints[v]
                    .iter()
                    .zip(&mesh.weights[v])
                    .filter(|(_, w)| **w > 0.0)
                    .filter_map(|(&j, _)| skin.joints.get(usize::from(j)).copied())
                    .collect(),
                None => vec![mesh.bone],
            };
            for bone in bones {
                reach_up(bone, position);
            }
        }
    }
    reach.iter().map(|r| 1.5 * r).collect()
}

/// `|det|^(1/3)` of the 3×3 part: how much the matrix scales lengths on average.
fn uniform_scale(m: &DMat4) -> f64 {
    DMat3::from_mat4(*m).determinant().abs().cbrt()
}

/// How far one bone's nodes may be from its samples between keys, and how that distance is measured.
///
/// Interpolating the nodes between keys `i` and `j` gives a local matrix `L'` at sample `k` where the sample says
/// `L`; a point of the bone's subtree at local position `y` then moves by `W'_parent·(L' − L)·y` in model space. The
/// bound used is `gain·(|ΔT| + ‖ΔA‖_F·reach)`: `gain` bounds how much the parent scales lengths, `reach` how far
/// the subtree's points lie from the bone's origin in its own units. Interpolated nodes are as far as the farthest
/// of their interpolations (`rotations`).
#[derive(Clone, Copy, Debug)]
pub struct BoneMetric {
    pub gain: f64,
    pub reach: f64,
    pub rotations: &'static [RotationInterpolation],
}

impl BoneMetric {
    /// The model-space distance bound for a bone's sample `k` interpolated between its samples `i` and `j`, each
    /// its time and nodes as baked: `[i, j, k]`.
    pub fn error(&self, [(ti, i), (tj, j), (tk, k)]: [(f64, &NodeSample); 3]) -> f64 {
        self.between([i, j], (tk - ti) / (tj - ti), k)
    }

    /// The model-space distance bound between `exact` and the nodes a fraction `t` of the way between `ends`,
    /// under the interpolation that comes out farthest.
    pub fn between(&self, [a, b]: [&NodeSample; 2], t: f64, exact: &NodeSample) -> f64 {
        self.rotations.iter().map(|&r| self.distance(&interpolate(a, b, t, r), exact)).fold(0.0, f64::max)
    }

    /// How far apart (as `BoneMetric::distance` measures) the interpolations of `rotations` can put the nodes
    /// between `a` and `b`: nothing without nlerp among them, else as far as nlerp departs from slerp. Both agree at
    /// the keys and half way, where refinement samples, so this, not a sample, tells where nlerp leaves the source.
    ///
    /// Only the rotations differ: the linear part `Q·S·Vᵀ` moves by `‖ΔQ‖_F·s + ‖ΔV‖_F·s` at most (`s` the largest
    /// factor), and rotations `δ` apart have `‖ΔR‖_F = 2√2·sin(δ/2) ≤ √2·δ`.
    pub fn parting(&self, [a, b]: [&NodeSample; 2]) -> f64 {
        if !self.rotations.contains(&RotationInterpolation::Nlerp) {
            return 0.0;
        }
        let turn = |p: DQuat, q: DQuat| nlerp_departure(angle_between(p, q));
        let scale = a.scale.abs().max(b.scale.abs()).max_element();
        let linear = SQRT_2 * scale * (turn(a.rotation, b.rotation) + turn(a.stretch, b.stretch));
        self.gain * linear * self.reach
    }

    /// The model-space distance bound between the nodes `interpolated` and `exact`.
    fn distance(&self, interpolated: &NodeSample, exact: &NodeSample) -> f64 {
        let (interpolated, exact) = (interpolated.matrix(), exact.matrix());
        let linear = DMat3::from_mat4(interpolated) - DMat3::from_mat4(exact);
        let offset = (interpolated.w_axis - exact.w_axis).truncate().length();
        let frobenius = linear.to_cols_array().iter().map(|v| v * v).sum::<f64>().sqrt();
        self.gain * (offset + frobenius * self.reach)
    }
}

/// Whether a rotation of the nodes turns by more than a quarter turn from `a` to `b`. Keys that far apart are
/// never interpolated: near a half turn, which way slerp goes hangs on the last bits of the numbers, and a helper
/// node and its bone could then turn opposite ways.
pub fn too_far(a: &NodeSample, b: &NodeSample) -> bool {
    let apart = |p: DQuat, q: DQuat| p.dot(q).abs() < std::f64::consts::FRAC_1_SQRT_2;
    apart(a.rotation, b.rotation) || apart(a.stretch, b.stretch)
}

/// The most by which nlerp and slerp between two rotations `angle` apart (radians of rotation, up to a quarter
/// turn: [`too_far`] keys are never interpolated) part, as an angle of rotation: `angle³/240`. On the arc of
/// half-angle `φ` between the keys nlerp is at `atan(t·sin φ / (1 − t + t·cos φ))` where slerp is at `t·φ`; the
/// difference is `−φ³·t(1 − t)(1 − 2t)/6` to third order, largest at `t = ½ ± √3/6`, so the rotations part by
/// `√3·angle³/432` plus higher terms that stay below the rounder `angle³/240` up to a quarter turn
/// (`docs/bake-interpolation.md`).
pub fn nlerp_departure(angle: f64) -> f64 {
    angle.powi(3) / 240.0
}

/// The nodes a fraction `t` of the way from `a` to `b`, as a glTF player that interpolates rotations by `rotation`
/// computes them (translation and scale are linear in every runtime).
pub fn interpolate(a: &NodeSample, b: &NodeSample, t: f64, rotation: RotationInterpolation) -> NodeSample {
    NodeSample {
        translation: a.translation.lerp(b.translation, t),
        rotation: rotation.mix(a.rotation, b.rotation, t),
        scale: a.scale.lerp(b.scale, t),
        stretch: if a.stretch == b.stretch { a.stretch } else { rotation.mix(a.stretch, b.stretch, t) },
    }
}

/// The model-space distance bound of morph weights interpolated between keys: each weight's change times how far
/// its target can move a vertex (`amplitude`).
pub fn weights_error(samples: &[Vec<f64>], times: &[f64], amplitude: &[f64], (i, j, k): (usize, usize, usize)) -> f64 {
    let t = (times[k] - times[i]) / (times[j] - times[i]);
    let (a, b, exact) = (&samples[i], &samples[j], &samples[k]);
    (0..exact.len()).map(|w| ((a[w] + (b[w] - a[w]) * t) - exact[w]).abs() * amplitude[w]).fold(0.0, f64::max)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bake::EVERY_RUNTIME;
    use crate::math::{nlerp, slerp};

    /// The largest angle between slerp and nlerp from `a` to `b`, by brute force over 10,000 fractions.
    fn largest_departure(a: DQuat, b: DQuat) -> f64 {
        (0..=10_000)
            .map(|i| f64::from(i) / 1e4)
            .map(|t| angle_between(slerp(a, b, t), nlerp(a, b, t)))
            .fold(0.0, f64::max)
    }

    #[test]
    fn nlerp_departs_from_slerp_by_at_most_the_cube_of_the_angle_over_240() {
        // Up to a quarter turn the bound holds and is tight: within 4 % of the brute-force largest departure (the
        // cubic term alone, √3·θ³/432, is 3.8 % below the bound; the higher terms close most of the gap).
        let axis = DVec3::new(1.0, -2.0, 0.5).normalize();
        let start = DQuat::from_euler(glam::EulerRot::XYZ, 0.3, -1.1, 2.0);
        for degrees in [0.5, 1.0, 5.0, 10.0, 30.0, 45.0, 60.0, 75.0, 89.0, 90.0] {
            let angle = f64::to_radians(degrees);
            let (a, b) = (start, DQuat::from_axis_angle(axis, angle) * start);
            let found = largest_departure(a, b);
            let bound = nlerp_departure(angle);
            assert!(found <= bound, "{degrees}°: {found:e} > {bound:e}");
            assert!(found >= 0.96 * bound, "{degrees}°: {found:e} is far below {bound:e}");
        }
    }

    #[test]
    fn parting_bounds_how_far_slerp_and_nlerp_put_the_nodes() {
        // Nodes turning and stretching between two keys: the metric's distance between their slerp and nlerp,
        // found by brute force over t, stays within `parting` and comes within 5 % of it when only the rotation turns
        // (the bound's only slack is then sin(δ/2) ≤ δ/2 and the cubic's).
        let a = NodeSample {
            translation: DVec3::ZERO,
            rotation: DQuat::from_rotation_y(0.2),
            scale: DVec3::new(1.5, -1.5, 1.5),
            stretch: DQuat::from_rotation_x(0.1),
        };
        let metric = BoneMetric { gain: 2.0, reach: 3.0, rotations: EVERY_RUNTIME };
        let brute = |a: &NodeSample, b: &NodeSample| {
            let at = |t: f64| {
                let [s, n] =
                    [RotationInterpolation::Slerp, RotationInterpolation::Nlerp].map(|r| interpolate(a, b, t, r));
                metric.distance(&s, &n)
            };
            (0..=2000).map(|i| at(f64::from(i) / 2000.0)).fold(0.0, f64::max)
        };
        for degrees in [5.0, 20.0, 60.0, 89.0] {
            let turn = DQuat::from_axis_angle(DVec3::new(1.0, 1.0, 0.0).normalize(), f64::to_radians(degrees));
            let turned = NodeSample { rotation: turn * a.rotation, ..a };
            let (found, bound) = (brute(&a, &turned), metric.parting([&a, &turned]));
            assert!(found <= bound && found >= 0.95 * bound, "{degrees}°: {found:e} against {bound:e}");
            let both = NodeSample { stretch: turn * a.stretch, scale: DVec3::new(1.0, -2.0, 0.5), ..turned };
            let (found, bound) = (brute(&a, &both), metric.parting([&a, &both]));
            assert!(found <= bound, "{degrees}°, stretch turning too: {found:e} against {bound:e}");
        }
        let slerp_only = BoneMetric { rotations: &[RotationInterpolation::Slerp], ..metric };
        assert_eq!(slerp_only.parting([&a, &NodeSample { rotation: DQuat::IDENTITY, ..a }]), 0.0);
    }

    #[test]
    fn a_bone_turning_at_constant_speed_is_keyed_as_often_as_nlerp_needs() {
        // One bone turning 120° about Z at constant speed, sampled every 0.1°. Slerp reproduces it between any two
        // samples, so a slerp-only reduction keeps the ends. Under nlerp, keys `θ` apart miss the samples between
        // them by up to `reach·2√2·sin(δ/2)` with `δ ≤ θ³/240`, within `budget` wherever
        // `θ ≤ θ_max = (240·budget/(√2·reach))^⅓`: the reduction's keys (greedy, checked sample by sample) lie
        // at least `θ_max` apart, less one sample, and at most a few percent more (the bound is that tight).
        let step = f64::to_radians(0.1);
        let count = 1201;
        let times: Vec<f64> = (0..count).map(|k| k as f64).collect();
        let nodes: Vec<NodeSample> = times
            .iter()
            .map(|&k| NodeSample { rotation: DQuat::from_rotation_z(k * step), ..NodeSample::IDENTITY })
            .collect();
        let (budget, reach) = (1e-5, 2.0);
        let metric = |rotations| BoneMetric { gain: 1.0, reach, rotations };
        let keys = |rotations| {
            let metric = metric(rotations);
            reduce(count, budget, |i, j, k| metric.error([i, j, k].map(|s| (times[s], &nodes[s]))))
        };
        assert_eq!(keys(&[RotationInterpolation::Slerp]), [0, count - 1]);
        let widest = (240.0 * budget / (std::f64::consts::SQRT_2 * reach)).cbrt();
        let keys = keys(EVERY_RUNTIME);
        let spans = keys.windows(2).map(|w| (w[1] - w[0]) as f64 * step);
        for (n, span) in spans.clone().enumerate().take(keys.len() - 2) {
            assert!(span >= widest - step && span <= 1.03 * widest + step, "span {n}: {span} against {widest}");
        }
        for pair in keys.windows(2) {
            for k in pair[0]..=pair[1] {
                let t = (times[k] - times[pair[0]]) / (times[pair[1]] - times[pair[0]]);
                let played = nlerp(nodes[pair[0]].rotation, nodes[pair[1]].rotation, t);
                let miss =
                    reach * 2.0 * std::f64::consts::SQRT_2 * (0.5 * angle_between(played, nodes[k].rotation)).sin();
                assert!(miss <= budget, "sample {k} between keys {pair:?}: {miss:e}");
            }
        }
    }

    #[test]
    fn a_line_keeps_its_ends_and_a_corner_keeps_the_corner() {
        let line: Vec<f64> = (0..50).map(f64::from).collect();
        let linear = |values: &[f64]| {
            let values = values.to_vec();
            move |i: usize, j: usize, k: usize| {
                let t = (k - i) as f64 / (j - i) as f64;
                (values[i] + (values[j] - values[i]) * t - values[k]).abs()
            }
        };
        assert_eq!(reduce(50, 1e-12, linear(&line)), [0, 49]);
        let corner: Vec<f64> = (0..50).map(|k: i32| f64::from((k - 20).abs())).collect();
        assert_eq!(reduce(50, 1e-12, linear(&corner)), [0, 20, 49]);
        assert_eq!(reduce(1, 0.0, linear(&[1.0])), [0]);
        assert_eq!(reduce(0, 0.0, linear(&[])), Vec::<usize>::new());
    }

    #[test]
    fn keys_chosen_as_the_samples_come_are_those_chosen_from_all_of_them() {
        // A sine with corners and a still stretch, fed a few samples at a time (one, seven, a hundred): the same keys
        // as the whole curve gives, and no sample asked for before the reducer's first needed one.
        let values: Vec<f64> = (0..600)
            .map(|k| f64::from(k) * 0.05)
            .map(|x| if (10.0..15.0).contains(&x) { 0.3 } else { x.sin() + (x - 20.0).abs() * 0.1 })
            .collect();
        let error = |i: usize, j: usize, k: usize| {
            let t = (k - i) as f64 / (j - i) as f64;
            (values[i] + (values[j] - values[i]) * t - values[k]).abs()
        };
        for tolerance in [1e-1, 1e-3] {
            let whole = reduce(values.len(), tolerance, error);
            for chunk in [1, 7, 100] {
                let mut reducer = Reducer::default();
                let mut known = 0;
                while known < values.len() {
                    known = (known + chunk).min(values.len());
                    let needed = reducer.from();
                    let checked = |i: usize, j: usize, k: usize| {
                        assert!(i >= needed && j < known && k < known, "{i} {j} {k}: from {needed}, {known} known");
                        error(i, j, k)
                    };
                    reducer.grow(known, tolerance, checked);
                    assert!(reducer.keys.iter().all(|&key| key < known));
                }
                reducer.finish(values.len(), tolerance, error);
                assert_eq!(reducer.keys, whole, "{tolerance}, {chunk} at a time");
            }
        }
    }

    #[test]
    fn every_dropped_sample_is_within_the_tolerance() {
        // A sine over 20 radians, sampled every 0.05: the kept keys reproduce every sample, and no more are kept than
        // keys spaced evenly by √(8·tolerance) (linear interpolation's error bound for a curvature of 1), rounded
        // down to whole samples, would need.
        let values: Vec<f64> = (0..400).map(|k| (f64::from(k) * 0.05).sin()).collect();
        let error = |i: usize, j: usize, k: usize| {
            let t = (k - i) as f64 / (j - i) as f64;
            (values[i] + (values[j] - values[i]) * t - values[k]).abs()
        };
        for tolerance in [1e-1, 1e-2, 1e-3] {
            let keys = reduce(values.len(), tolerance, error);
            for pair in keys.windows(2) {
                assert!((pair[0] + 1..pair[1]).all(|k| error(pair[0], pair[1], k) <= tolerance));
            }
            let spacing = ((8.0 * tolerance).sqrt() / 0.05).floor().max(1.0) * 0.05;
            let even = (20.0 / spacing).ceil() as usize + 2;
            assert!(keys.len() <= even, "{tolerance}: {} keys, evenly spaced ones need {even}", keys.len());
        }
    }

    #[test]
    fn interpolation_is_the_runtimes() {
        let axis = DVec3::new(0.0, 1.0, 1.0).normalize();
        let a = NodeSample {
            translation: DVec3::ZERO,
            rotation: DQuat::IDENTITY,
            scale: DVec3::ONE,
            stretch: DQuat::IDENTITY,
        };
        let b = NodeSample {
            translation: DVec3::new(2.0, 0.0, 0.0),
            rotation: DQuat::from_axis_angle(axis, 1.0),
            scale: DVec3::splat(3.0),
            stretch: DQuat::IDENTITY,
        };
        for rotation in [RotationInterpolation::Slerp, RotationInterpolation::Nlerp] {
            // Half way both are at half the angle (nlerp departs from slerp on either side of it).
            let half = interpolate(&a, &b, 0.5, rotation);
            assert_eq!(half.translation, DVec3::X);
            assert_eq!(half.scale, DVec3::splat(2.0));
            assert!(half.rotation.abs_diff_eq(DQuat::from_axis_angle(axis, 0.5), 1e-15));
        }
        let quarter = |rotation| interpolate(&a, &b, 0.25, rotation).rotation;
        assert!(quarter(RotationInterpolation::Slerp).abs_diff_eq(DQuat::from_axis_angle(axis, 0.25), 1e-15));
        // Nlerp's point on the arc of half-angle φ = 0.5 is at atan(t·sin φ / (1 − t + t·cos φ)) from `a`.
        let ahead = (0.25 * 0.5f64.sin()).atan2(0.75 + 0.25 * 0.5f64.cos());
        assert!(quarter(RotationInterpolation::Nlerp).abs_diff_eq(DQuat::from_axis_angle(axis, 2.0 * ahead), 1e-15));
    }
}
