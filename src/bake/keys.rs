//! Which samples become keys: the fewest, greedily, such that linear interpolation (slerp for rotations) between
//! neighbouring keys reproduces every dropped sample within a tolerance.
//!
//! From each key the next one is pushed as far as it goes: the span doubles while every sample inside it is
//! reproduced, then a binary search finds the farthest span that still is. Every span chosen has been checked
//! sample by sample, so the result always holds; a whole clip costs `O(n log L)` checks for spans of `L` samples.

use glam::{DMat3, DMat4, DQuat, DVec3};

use super::nodes::NodeSample;
use crate::diff::PROBE_FRACTION;
use crate::eval::{Evaluation, Pose, skin_meshes};
use crate::math::slerp;

/// The indices of the samples to keep among `count` (the first and last always), such that
/// `error(i, j, k) ≤ tolerance` for every dropped `k` between its kept neighbours `i < k < j`.
pub fn reduce(count: usize, tolerance: f64, error: impl Fn(usize, usize, usize) -> f64) -> Vec<usize> {
    if count <= 2 {
        return (0..count).collect();
    }
    let spans = |from: usize, to: usize| (from + 1..to).all(|k| error(from, to, k) <= tolerance);
    let last = count - 1;
    let mut keys = vec![0];
    let mut from = 0;
    while from < last {
        let (mut good, mut step) = (from + 1, 1);
        let mut bad = None;
        while good < last {
            let candidate = (good + step).min(last);
            if spans(from, candidate) {
                good = candidate;
                step *= 2;
            } else {
                bad = Some(candidate);
                break;
            }
        }
        if let Some(mut bad) = bad {
            while bad - good > 1 {
                let middle = good + (bad - good) / 2;
                if spans(from, middle) { good = middle } else { bad = middle }
            }
        }
        keys.push(good);
        from = good;
    }
    keys
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
}

impl Metrics {
    /// For the rig of `rest` (its rest pose under the bake's modes), `size` and `tolerance` in model units.
    pub fn new(rest: &Evaluation, size: f64, tolerance: f64) -> Self {
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
        Metrics { budget: 0.5 * tolerance / chain as f64, reach, model_scale: typical }
    }

    /// The metric of `bone`, whose parent scales lengths by at most `gains[bone]`.
    pub fn bone(&self, gains: &[f64], bone: usize) -> BoneMetric {
        BoneMetric { gain: gains[bone].max(f64::MIN_POSITIVE), reach: self.reach[bone] }
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
/// the subtree's points lie from the bone's origin in its own units.
#[derive(Clone, Copy, Debug)]
pub struct BoneMetric {
    pub gain: f64,
    pub reach: f64,
}

impl BoneMetric {
    /// The model-space distance bound for sample `k` of a bone's `nodes` (as baked, at `times`) interpolated
    /// between its samples `i` and `j`.
    pub fn error(&self, times: &[f64], nodes: &[NodeSample], (i, j, k): (usize, usize, usize)) -> f64 {
        let t = (times[k] - times[i]) / (times[j] - times[i]);
        self.distance(&interpolate(&nodes[i], &nodes[j], t), &nodes[k])
    }

    /// The model-space distance bound between the nodes `interpolated` and `exact`.
    pub fn distance(&self, interpolated: &NodeSample, exact: &NodeSample) -> f64 {
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

/// The nodes a fraction `t` of the way from `a` to `b`, as a glTF player computes them.
pub fn interpolate(a: &NodeSample, b: &NodeSample, t: f64) -> NodeSample {
    NodeSample {
        translation: a.translation.lerp(b.translation, t),
        rotation: slerp(a.rotation, b.rotation, t),
        scale: a.scale.lerp(b.scale, t),
        stretch: if a.stretch == b.stretch { a.stretch } else { slerp(a.stretch, b.stretch, t) },
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
    fn interpolation_is_gltfs() {
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
        let half = interpolate(&a, &b, 0.5);
        assert_eq!(half.translation, DVec3::X);
        assert_eq!(half.scale, DVec3::splat(2.0));
        assert!(half.rotation.abs_diff_eq(DQuat::from_axis_angle(axis, 0.5), 1e-15));
    }
}
