//! One clip's samples as animation channels: each bone's nodes at the keys that reproduce its samples, and the
//! morph weights the clip animates.
//!
//! A bone whose nodes only ever change at a stepped key of the source (between the sample before the key and the
//! key) holds still between keys: its channels are written with STEP interpolation, keyed where the value changes,
//! which reproduces the jump exactly. The others are linear (slerp for
//! rotations), keyed by [`reduce`]. A channel that only repeats its node's default is left out; one that holds a
//! single value keeps two keys.

use glam::DQuat;
use rayon::prelude::*;

use super::document::{Animation, Channel, GltfDocument, Interpolation, Node, Property};
use super::keys::{Metrics, reduce, weights_error};
use super::layout::{NodePlan, unit};
use super::nodes::{NodeSample, Sampled};
use super::times::BakeTimes;
use crate::eval::{Evaluation, MorphPose};

/// One clip's samples, ready to become channels.
pub struct ClipSamples<'a> {
    pub name: &'a str,
    pub source: &'a Evaluation<'a>,
    /// The times every bone was sampled at, and the stepped keys among them.
    pub base: &'a BakeTimes,
    pub sampled: &'a Sampled,
}

/// The channels of `clip` for the nodes of `layout` in `document`.
pub fn animation(layout: &NodePlan, clip: &ClipSamples, metrics: &Metrics, document: &GltfDocument) -> Animation {
    let per_bone: Vec<Vec<Channel>> = (0..clip.sampled.series.len())
        .into_par_iter()
        .map(|bone| bone_channels(layout, clip, metrics, document, bone))
        .collect();
    let mut channels: Vec<Channel> = per_bone.into_iter().flatten().collect();
    channels.extend(weight_channels(layout, clip, metrics, document));
    if channels.is_empty()
        && let Some(node) = document.nodes.first()
    {
        // glTF wants at least one channel; one that holds the first node still says how long the clip is.
        let end = clip.sampled.times.last().copied().unwrap_or(0.0) as f32;
        let times = if end > 0.0 { vec![0.0, end] } else { vec![0.0] };
        let values = times.iter().flat_map(|_| node.rotation).collect();
        let interpolation = Interpolation::Linear;
        channels.push(Channel { node: 0, property: Property::Rotation, interpolation, times, values });
    }
    Animation { name: clip.name.to_owned(), channels }
}

/// The channels of one bone's nodes.
fn bone_channels(
    layout: &NodePlan,
    clip: &ClipSamples,
    metrics: &Metrics,
    document: &GltfDocument,
    bone: usize,
) -> Vec<Channel> {
    let helper = layout.helper_node[bone].is_some();
    let series = &clip.sampled.series[bone];
    let baked: Vec<NodeSample> = series.nodes.iter().map(|n| n.as_baked(helper)).collect();
    let values = NodeValues::of(&baked, helper);
    let (keys, interpolation) = match values.steps(&clip.base.step_flags(&series.times)) {
        Some(keys) => (keys, Interpolation::Step),
        None => {
            let metric = metrics.bone(&clip.sampled.stats.parent_gain, bone);
            let error = |i, j, k| metric.error(&series.times, &baked, (i, j, k));
            (reduce(series.times.len(), metrics.budget, error), Interpolation::Linear)
        }
    };
    let keys = distinct_f32_times(&keys, &series.times);
    let key_times: Vec<f32> = keys.iter().map(|&k| series.times[k] as f32).collect();
    let (outer, own) = (layout.helper_node[bone].unwrap_or(layout.bone_node[bone]), layout.bone_node[bone]);
    let mut wanted = vec![
        (outer, Property::Translation, &values.translation, 3),
        (outer, Property::Rotation, &values.rotation, 4),
        (outer, Property::Scale, &values.scale, 3),
    ];
    if helper {
        wanted.push((own, Property::Rotation, &values.own_rotation, 4));
    }
    wanted
        .into_iter()
        .filter_map(|(node, property, all, width)| {
            let at_keys = keys.iter().flat_map(|&k| all[k * width..(k + 1) * width].iter().copied()).collect();
            let default = default_values(&document.nodes[node], property);
            channel(node, property, interpolation, &key_times, at_keys, &default)
        })
        .collect()
}

/// A bone's node values at every sample, as written (single precision).
struct NodeValues {
    translation: Vec<f32>,
    rotation: Vec<f32>,
    scale: Vec<f32>,
    /// The bone's own node's rotation `Uᵀ` under a helper (empty without one).
    own_rotation: Vec<f32>,
}

impl NodeValues {
    /// From a bone's samples as baked (with a `helper` or without).
    fn of(samples: &[NodeSample], helper: bool) -> Self {
        NodeValues {
            translation: samples.iter().flat_map(|s| s.translation.as_vec3().to_array()).collect(),
            rotation: continuous(samples.iter().map(|s| s.rotation)),
            scale: samples.iter().flat_map(|s| s.scale.as_vec3().to_array()).collect(),
            own_rotation: if helper { continuous(samples.iter().map(|s| s.stretch.conjugate())) } else { Vec::new() },
        }
    }

    /// Whether sample `s` and the next are written alike.
    fn same(&self, s: usize) -> bool {
        let equal = |values: &[f32], width: usize| {
            values.is_empty() || values[s * width..(s + 1) * width] == values[(s + 1) * width..(s + 2) * width]
        };
        equal(&self.translation, 3) && equal(&self.rotation, 4) && equal(&self.scale, 3) && equal(&self.own_rotation, 4)
    }

    /// The samples to key with STEP interpolation (the first, and every stepped key where the values change), when
    /// the values only ever change at stepped keys; `None` otherwise.
    fn steps(&self, steps: &[bool]) -> Option<Vec<usize>> {
        let mut keys = vec![0];
        for s in 0..steps.len().saturating_sub(1) {
            if self.same(s) {
                continue;
            }
            if !steps[s + 1] {
                return None;
            }
            keys.push(s + 1);
        }
        (keys.len() > 1).then_some(keys)
    }
}

/// The morph weights of every mesh group whose bone the clip animates them on.
fn weight_channels(layout: &NodePlan, clip: &ClipSamples, metrics: &Metrics, document: &GltfDocument) -> Vec<Channel> {
    let Some(source) = clip.source.clip else { return Vec::new() };
    let (times, rig) = (&clip.base.times, clip.source.rig);
    let mut channels = Vec::new();
    let mut morph = MorphPose::default();
    for (group, (node, meshes)) in document.meshes.iter().zip(&layout.groups) {
        let mesh = &rig.meshes[meshes[0]];
        if group.weights.is_empty() || source.morph().iter().all(|m| m.bone != mesh.bone) {
            continue;
        }
        let samples: Vec<Vec<f64>> = times
            .iter()
            .map(|&t| {
                morph.evaluate(Some(source), t);
                morph.weights(mesh).into_owned()
            })
            .collect();
        let amplitude: Vec<f64> = (0..group.weights.len())
            .map(|k| {
                let longest = group.primitives.iter().flat_map(|p| &p.morph_targets[k].offsets).map(|o| o.length());
                f64::from(longest.fold(0.0, f32::max)) * metrics.model_scale
            })
            .collect();
        let keys = reduce(times.len(), metrics.budget, |i, j, k| weights_error(&samples, times, &amplitude, (i, j, k)));
        let keys = distinct_f32_times(&keys, times);
        let key_times: Vec<f32> = keys.iter().map(|&k| times[k] as f32).collect();
        let values = keys.iter().flat_map(|&k| samples[k].iter().map(|&w| w as f32)).collect();
        let linear = Interpolation::Linear;
        if let Some(channel) = channel(*node, Property::Weights, linear, &key_times, values, &group.weights) {
            channels.push(channel);
        }
    }
    channels
}

/// Rotation keys in single precision, each in the hemisphere of the one before (slerp between them then takes the
/// short way whether or not a player checks).
fn continuous(rotations: impl Iterator<Item = DQuat>) -> Vec<f32> {
    let mut previous: Option<DQuat> = None;
    let mut values = Vec::new();
    for q in rotations {
        let q = match previous {
            Some(p) if p.dot(q) < 0.0 => -q,
            _ => q,
        };
        values.extend(unit(q));
        previous = Some(q);
    }
    values
}

/// The node's default value of `property`, as the numbers a channel of it holds per key.
fn default_values(node: &Node, property: Property) -> Vec<f32> {
    match property {
        Property::Translation => node.translation.to_vec(),
        Property::Rotation => node.rotation.to_vec(),
        Property::Scale => node.scale.to_vec(),
        Property::Weights => Vec::new(),
    }
}

/// A channel of `values` at `times`, or `None` when every key repeats `default`; a channel whose keys all repeat
/// its first keeps only its first and last key. Keys "repeat" a value when they differ from it by less than single
/// precision resolves in the channel ([`resolution`]): the re-solve against baked parents leaves noise far below
/// it in channels that never move, and keeping it would write every sample of them.
fn channel(
    node: usize,
    property: Property,
    interpolation: Interpolation,
    times: &[f32],
    values: Vec<f32>,
    default: &[f32],
) -> Option<Channel> {
    if times.is_empty() || values.is_empty() {
        return None;
    }
    let width = values.len() / times.len();
    let resolution = resolution(&values, width);
    let all_near = |value: &[f32]| values.chunks_exact(width).all(|key| near(key, value, resolution));
    if all_near(default) {
        return None;
    }
    let first = &values[..width];
    if all_near(first) && times.len() > 2 {
        let values = first.repeat(2);
        let times = vec![times[0], times[times.len() - 1]];
        return Some(Channel { node, property, interpolation, times, values });
    }
    Some(Channel { node, property, interpolation, times: times.to_vec(), values })
}

/// The smallest difference single precision resolves between keys of `width` numbers: its epsilon relative to
/// the longest key (as a vector).
fn resolution(values: &[f32], width: usize) -> f32 {
    let longest = values.chunks_exact(width).map(|key| key.iter().map(|v| v * v).sum::<f32>()).fold(0.0, f32::max);
    f32::EPSILON * longest.sqrt()
}

/// Whether keys `a` and `b` differ by no more than `resolution` in any number (equal ones always are).
fn near(a: &[f32], b: &[f32], resolution: f32) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x == y || (x - y).abs() <= resolution)
}

/// `keys` without the samples whose time rounds to the same `f32` as an earlier one's (glTF's times are `f32` and
/// strictly increasing).
fn distinct_f32_times(keys: &[usize], times: &[f64]) -> Vec<usize> {
    let mut out: Vec<usize> = Vec::with_capacity(keys.len());
    for &k in keys {
        if out.last().is_none_or(|&last| (times[k] as f32) > (times[last] as f32)) {
            out.push(k);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn values(translations: &[f32]) -> NodeValues {
        NodeValues {
            translation: translations.iter().flat_map(|&x| [x, 0.0, 0.0]).collect(),
            rotation: translations.iter().flat_map(|_| [0.0, 0.0, 0.0, 1.0]).collect(),
            scale: translations.iter().flat_map(|_| [1.0; 3]).collect(),
            own_rotation: Vec::new(),
        }
    }

    #[test]
    fn values_that_change_only_at_stepped_keys_are_steps() {
        // Samples: 0, lead, key, frame, lead, key.
        let steps = [false, false, true, false, false, true];
        assert_eq!(values(&[1.0, 1.0, 2.0, 2.0, 2.0, 3.0]).steps(&steps), Some(vec![0, 2, 5]));
        assert_eq!(values(&[1.0, 1.5, 2.0, 2.0, 2.0, 3.0]).steps(&steps), None, "a change that is not a jump");
        assert_eq!(values(&[1.0; 6]).steps(&steps), None, "nothing to step");
    }

    #[test]
    fn constant_and_default_channels() {
        let times = [0.0, 0.5, 1.0];
        let linear = Interpolation::Linear;
        let default = [0.0, 0.0, 0.0];
        assert_eq!(channel(0, Property::Translation, linear, &times, vec![0.0; 9], &default), None);
        let held = channel(0, Property::Translation, linear, &times, [1.0, 2.0, 3.0].repeat(3), &default).unwrap();
        assert_eq!((held.times, held.values), (vec![0.0, 1.0], [1.0, 2.0, 3.0].repeat(2)));
        let noisy = [0.1, 0.2, 0.3, 0.1 + 2e-14, 0.2, 0.3, 0.1, 0.2 - 3e-9, 0.3];
        let held = channel(0, Property::Translation, linear, &times, noisy.to_vec(), &default).unwrap();
        assert_eq!(held.values, [0.1, 0.2, 0.3].repeat(2), "noise below single precision's resolution is held");
        let moving = [0.1, 0.2, 0.3, 0.1, 0.2 + 1e-7, 0.3, 0.1, 0.2, 0.3];
        let kept = channel(0, Property::Translation, linear, &times, moving.to_vec(), &default).unwrap();
        assert_eq!(kept.times.len(), 3, "a motion single precision resolves is kept");
        let near_default = [2e-14, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0, -1e-15, 1.0];
        assert_eq!(channel(0, Property::Translation, linear, &times, near_default.to_vec(), &[0.0, 0.0, 1.0]), None);
        assert_eq!(distinct_f32_times(&[0, 1, 2], &[0.5, 0.5 + 1e-12, 1.0]), [0, 2], "one f32 time");
    }
}
