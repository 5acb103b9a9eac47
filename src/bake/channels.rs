//! One clip's samples as animation channels: each bone's nodes at the keys that reproduce its samples, and the
//! morph weights the clip animates.
//!
//! A bone whose nodes only ever change at a stepped key of the source (between the sample before the key and the
//! key) holds still between keys: its channels are written with STEP interpolation, keyed where the value changes,
//! which reproduces the jump exactly. The others are linear (slerp for
//! rotations), keyed by [`reduce`]. A channel that only repeats its node's default is left out; one that holds a
//! single value keeps two keys.

use std::collections::VecDeque;

use glam::DQuat;
use rayon::prelude::*;

use super::document::{Animation, Channel, GltfDocument, Interpolation, Node, Property};
use super::keys::{BoneMetric, Metrics, Reducer, reduce, weights_error};
use super::layout::{NodePlan, unit};
use super::nodes::NodeSample;
use super::times::BakeTimes;
use super::{DenseClip, Sampling};
use crate::eval::MorphPose;

/// The animation `name`: the channels of `dense`'s clip for the nodes of `layout` in `document`, every bone's keys
/// chosen as a last run through the clip hands its samples on.
pub fn animation(
    layout: &NodePlan,
    name: &str,
    dense: &DenseClip,
    metrics: &Metrics,
    document: &GltfDocument,
) -> Animation {
    let gains = &dense.refined.stats.parent_gain;
    let mut keys: Vec<BoneKeys> =
        (0..layout.bone_node.len()).map(|bone| BoneKeys::new(layout, metrics, gains, bone)).collect();
    dense.run(&mut keys, |keys, samples| {
        samples.iter().for_each(|(time, node)| keys.push(*time, node, dense.sampling.base))
    });
    let per_bone: Vec<Vec<Channel>> =
        keys.into_par_iter().enumerate().map(|(bone, keys)| keys.channels(layout, document, bone)).collect();
    let mut channels: Vec<Channel> = per_bone.into_iter().flatten().collect();
    channels.extend(weight_channels(layout, dense, metrics, document));
    if channels.is_empty()
        && let Some(node) = document.nodes.first()
    {
        // glTF wants at least one channel; one that holds the first node still says how long the clip is.
        let end = dense.refined.times.last().copied().unwrap_or(0.0) as f32;
        let times = if end > 0.0 { vec![0.0, end] } else { vec![0.0] };
        let values = times.iter().flat_map(|_| node.rotation).collect();
        let interpolation = Interpolation::Linear;
        channels.push(Channel { node: 0, property: Property::Rotation, interpolation, times, values });
    }
    Animation { name: name.to_owned(), channels }
}

/// One bone's keys, chosen as its samples come in time order (each bone's nodes as sampled, frames followed): every
/// sample as written, the keys as far as the samples known settle them, and only the samples the keys still to come
/// may need.
///
/// A bone whose nodes only ever change at a stepped key of the source (between the sample before the key and the
/// key) holds still between keys: its channels are written with STEP interpolation, keyed where the values change,
/// which reproduces the jump exactly. The others are linear (slerp for rotations), keyed by [`Reducer`].
struct BoneKeys {
    helper: bool,
    metric: BoneMetric,
    budget: f64,
    /// How many samples came.
    count: usize,
    /// The samples from the first the reducer may still need on: (time, nodes as baked, as written).
    window: VecDeque<(f64, NodeSample, Written)>,
    reducer: Reducer,
    /// How many of the reducer's keys are in `linear`.
    taken: usize,
    /// The reducer's keys so far.
    linear: Keys,
    stepped: Steps,
    /// The last sample as written, and its rotations before they were written (whose hemispheres the next sample's
    /// follow).
    last: Option<Written>,
    turns: Option<[DQuat; 2]>,
}

impl BoneKeys {
    fn new(layout: &NodePlan, metrics: &Metrics, gains: &[f64], bone: usize) -> Self {
        BoneKeys {
            helper: layout.helper_node[bone].is_some(),
            metric: metrics.bone(gains, bone),
            budget: metrics.budget,
            count: 0,
            window: VecDeque::new(),
            reducer: Reducer::default(),
            taken: 0,
            linear: Keys::default(),
            stepped: Steps(Some(Vec::new())),
            last: None,
            turns: None,
        }
    }

    /// The next sample: the bone's `node` at `time` (frames followed), of a clip first sampled at `base`.
    fn push(&mut self, time: f64, node: &NodeSample, base: &BakeTimes) {
        let baked = node.as_baked(self.helper);
        let written = Written::of(time, &baked, self.helper, &mut self.turns);
        self.stepped.push(self.last.as_ref(), written, base.is_step(time));
        self.window.push_back((time, baked, written));
        self.count += 1;
        self.last = Some(written);
        self.choose(false);
    }

    /// Lets the reducer choose what the samples so far settle (`all`: every sample came), records its keys, and
    /// drops the samples it no longer needs.
    fn choose(&mut self, all: bool) {
        let offset = self.count - self.window.len();
        let (metric, window) = (&self.metric, &self.window);
        let sample = |s: usize| {
            let (time, node, _) = &window[s - offset];
            (*time, node)
        };
        let error = |i: usize, j: usize, k: usize| metric.error([i, j, k].map(sample));
        match all {
            true => self.reducer.finish(self.count, self.budget, error),
            false => self.reducer.grow(self.count, self.budget, error),
        }
        for &key in &self.reducer.keys[self.taken..] {
            self.linear.push(&self.window[key - offset].2);
        }
        self.taken = self.reducer.keys.len();
        self.window.drain(..self.reducer.from() - offset);
    }

    /// The bone's channels, every sample having come.
    fn channels(mut self, layout: &NodePlan, document: &GltfDocument, bone: usize) -> Vec<Channel> {
        let (keys, interpolation) = match std::mem::replace(&mut self.stepped, Steps(None)).keys() {
            Some(keys) => (keys, Interpolation::Step),
            None => {
                self.choose(true);
                (self.linear.written(), Interpolation::Linear)
            }
        };
        let keys = distinct_f32_times(keys, |key| key.time);
        let key_times: Vec<f32> = keys.iter().map(|k| k.time).collect();
        let (outer, own) = (layout.helper_node[bone].unwrap_or(layout.bone_node[bone]), layout.bone_node[bone]);
        let mut wanted: Vec<(usize, Property, WrittenValues)> = vec![
            (outer, Property::Translation, |w| &w.translation),
            (outer, Property::Rotation, |w| &w.rotation),
            (outer, Property::Scale, |w| &w.scale),
        ];
        if self.helper {
            wanted.push((own, Property::Rotation, |w| &w.own_rotation));
        }
        wanted
            .into_iter()
            .filter_map(|(node, property, values)| {
                let at_keys = keys.iter().flat_map(|k| values(k).iter().copied()).collect();
                let default = default_values(&document.nodes[node], property);
                channel(node, property, interpolation, &key_times, at_keys, &default)
            })
            .collect()
    }
}

/// A bone's keys as written, each node value's in runs of keys that hold it (most channels hold still): what a bake
/// holds of a bone while its samples come.
#[derive(Default)]
struct Keys {
    times: Vec<f32>,
    translation: Runs<3>,
    rotation: Runs<4>,
    scale: Runs<3>,
    own_rotation: Runs<4>,
}

impl Keys {
    fn push(&mut self, key: &Written) {
        grow(&mut self.times, key.time);
        self.translation.push(key.translation);
        self.rotation.push(key.rotation);
        self.scale.push(key.scale);
        self.own_rotation.push(key.own_rotation);
    }

    /// The keys, in order.
    fn written(&self) -> Vec<Written> {
        let values = self.translation.values().zip(self.rotation.values()).zip(self.scale.values());
        let keys = self.times.iter().zip(values).zip(self.own_rotation.values());
        let written = |((&time, ((translation, rotation), scale)), own_rotation)| Written {
            time,
            translation,
            rotation,
            scale,
            own_rotation,
        };
        keys.map(written).collect()
    }
}

/// Values of `N` numbers, each with how many keys in a row hold it.
#[derive(Default)]
struct Runs<const N: usize>(Vec<([f32; N], u32)>);

impl<const N: usize> Runs<N> {
    fn push(&mut self, value: [f32; N]) {
        match self.0.last_mut() {
            Some((last, count)) if *last == value && *count < u32::MAX => *count += 1,
            _ => grow(&mut self.0, (value, 1)),
        }
    }

    fn values(&self) -> impl Iterator<Item = [f32; N]> + '_ {
        self.0.iter().flat_map(|&(value, count)| std::iter::repeat_n(value, count as usize))
    }
}

/// Pushes `item`, growing `list` by a quarter at a time rather than doubling it: a bone's keys are most of what a
/// bake holds.
fn grow<T>(list: &mut Vec<T>, item: T) {
    if list.len() == list.capacity() {
        list.reserve_exact(list.len() / 4 + 16);
    }
    list.push(item);
}

/// The keys of a bone whose values only ever change at stepped keys: the first sample and every stepped key where
/// the values change; `None` once they change anywhere else.
struct Steps(Option<Vec<Written>>);

impl Steps {
    /// The next sample, `written`, after `last`; `stepped` where a stepped key is at it.
    fn push(&mut self, last: Option<&Written>, written: Written, stepped: bool) {
        let Some(keys) = &mut self.0 else { return };
        match last {
            None => keys.push(written),
            Some(last) if last.same(&written) => {}
            Some(_) if stepped => keys.push(written),
            Some(_) => self.0 = None,
        }
    }

    /// The keys, where the values changed at stepped keys alone, and at one at least.
    fn keys(self) -> Option<Vec<Written>> {
        self.0.filter(|keys| keys.len() > 1)
    }
}

/// The numbers of one node's property in a sample as written.
type WrittenValues = fn(&Written) -> &[f32];

/// One sample of a bone's nodes as written (single precision), with its time.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Written {
    time: f32,
    translation: [f32; 3],
    /// In the hemisphere of the sample before (slerp between keys then takes the short way whether or not a player
    /// checks).
    rotation: [f32; 4],
    scale: [f32; 3],
    /// The bone's own node's rotation `Uᵀ` under a helper (nothing without one), in the hemisphere of the sample
    /// before.
    own_rotation: [f32; 4],
}

impl Written {
    /// `node` (as baked, with a `helper` or without) at `time`; `turns` are the rotations of the sample before, as
    /// they were before they were written, and become this sample's.
    fn of(time: f64, node: &NodeSample, helper: bool, turns: &mut Option<[DQuat; 2]>) -> Self {
        let before = *turns;
        let near = |q: DQuat, k: usize| match before {
            Some(before) if before[k].dot(q) < 0.0 => -q,
            _ => q,
        };
        let rotation = near(node.rotation, 0);
        let own = if helper { near(node.stretch.conjugate(), 1) } else { DQuat::IDENTITY };
        *turns = Some([rotation, own]);
        Written {
            time: time as f32,
            translation: node.translation.as_vec3().to_array(),
            rotation: unit(rotation),
            scale: node.scale.as_vec3().to_array(),
            own_rotation: if helper { unit(own) } else { [0.0; 4] },
        }
    }

    /// Whether `other` is written alike.
    fn same(&self, other: &Written) -> bool {
        self.translation == other.translation
            && self.rotation == other.rotation
            && self.scale == other.scale
            && self.own_rotation == other.own_rotation
    }
}

/// The morph weights of every mesh group whose bone the clip animates them on.
fn weight_channels(layout: &NodePlan, dense: &DenseClip, metrics: &Metrics, document: &GltfDocument) -> Vec<Channel> {
    let Sampling { source: evaluation, base, .. } = &dense.sampling;
    let Some(source) = evaluation.clip else { return Vec::new() };
    let (times, rig) = (&base.times, evaluation.rig);
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
        let keys = distinct_f32_times(keys, |&k| times[k] as f32);
        let key_times: Vec<f32> = keys.iter().map(|&k| times[k] as f32).collect();
        let values = keys.iter().flat_map(|&k| samples[k].iter().map(|&w| w as f32)).collect();
        let linear = Interpolation::Linear;
        if let Some(channel) = channel(*node, Property::Weights, linear, &key_times, values, &group.weights) {
            channels.push(channel);
        }
    }
    channels
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

/// `keys` without those whose time in single precision (`time`) is an earlier one's (glTF's times are `f32` and
/// strictly increasing).
fn distinct_f32_times<K>(keys: Vec<K>, time: impl Fn(&K) -> f32) -> Vec<K> {
    let mut out: Vec<K> = Vec::with_capacity(keys.len());
    for key in keys {
        if out.last().is_none_or(|last| time(&key) > time(last)) {
            out.push(key);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The step keys of samples moved along X by `translations`, a stepped key at the samples `steps` flags: the
    /// indices of the samples keyed.
    fn step_keys(translations: &[f64], steps: &[bool]) -> Option<Vec<usize>> {
        let mut stepped = Steps(Some(Vec::new()));
        let (mut last, mut turns): (Option<Written>, _) = (None, None);
        for (k, (&x, &step)) in translations.iter().zip(steps).enumerate() {
            let node = NodeSample { translation: glam::DVec3::X * x, ..NodeSample::IDENTITY };
            let written = Written::of(k as f64, &node, false, &mut turns);
            stepped.push(last.as_ref(), written, step);
            last = Some(written);
        }
        stepped.keys().map(|keys| keys.iter().map(|k| k.time as usize).collect())
    }

    #[test]
    fn values_that_change_only_at_stepped_keys_are_steps() {
        // Samples: 0, lead, key, frame, lead, key.
        let steps = [false, false, true, false, false, true];
        assert_eq!(step_keys(&[1.0, 1.0, 2.0, 2.0, 2.0, 3.0], &steps), Some(vec![0, 2, 5]));
        assert_eq!(step_keys(&[1.0, 1.5, 2.0, 2.0, 2.0, 3.0], &steps), None, "a change that is not a jump");
        assert_eq!(step_keys(&[1.0; 6], &steps), None, "nothing to step");
    }

    #[test]
    fn keys_held_in_runs_are_the_keys_pushed() {
        // Translations that hold still, step and hold again, a rotation that turns at every key.
        let keys: Vec<Written> = (0..40)
            .map(|k| Written {
                time: k as f32 * 0.5,
                translation: [if k < 10 { 1.0 } else { 2.0 }, 0.0, 0.0],
                rotation: [0.0, 0.0, (k as f32 * 0.01).sin(), (k as f32 * 0.01).cos()],
                scale: [1.0; 3],
                own_rotation: [0.0; 4],
            })
            .collect();
        let mut held = Keys::default();
        keys.iter().for_each(|key| held.push(key));
        assert_eq!(held.written(), keys);
        assert_eq!((held.translation.0.len(), held.scale.0.len(), held.rotation.0.len()), (2, 1, 40));
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
        let times = [0.5, 0.5 + 1e-12, 1.0];
        assert_eq!(distinct_f32_times(vec![0, 1, 2], |&k| times[k] as f32), [0, 2], "one f32 time");
    }
}
