//! Animations as [`Clip`]s: translation, rotation and scale channels become tracks, morph-weight channels one
//! weight track per morph target.
//!
//! A channel names its target by `node` and `path`, or with `KHR_animation_pointer` by a JSON pointer: pointers to a
//! node's `translation`, `rotation`, `scale` or `weights`, or a mesh's `weights`, are read like ordinary channels;
//! others (materials, cameras, lights) are counted in the notes. Key times are read once per input accessor and
//! shared (`Arc`) by every track that uses it, as exporters commonly give all channels of a clip one time accessor.

use std::collections::hash_map::{Entry, HashMap};
use std::collections::{BTreeMap, HashSet};
use std::sync::Arc;

use glam::{Quat, Vec3};
use rayon::prelude::*;

use super::accessor::Accessors;
use super::schema::{self, Root, Uint};
use super::{Failure, Result};
use crate::model::{BoneTracks, Clip, Interpolation, KeyValue, MorphWeights, Track};

/// What the channels of all clips add up to, for the notes.
#[derive(Default)]
struct Tally {
    outside_scene: usize,
    /// `KHR_animation_pointer` targets bonescope does not evaluate, by pointer.
    other_pointers: BTreeMap<String, usize>,
}

pub(super) fn read_clips(
    root: &Root,
    accessors: &Accessors<'_>,
    bone_of_node: &[Option<usize>],
    notes: &mut Vec<String>,
) -> Result<Vec<Clip>> {
    let mut reader = Reader {
        root,
        accessors,
        bone_of_node,
        times: HashMap::new(),
        vec3s: HashMap::new(),
        rotations: HashMap::new(),
        tally: Tally::default(),
    };
    reader.decode_ahead();
    let clips = root.animations.iter().enumerate().map(|(i, a)| reader.clip(i, a)).collect::<Result<Vec<_>>>()?;
    let tally = reader.tally;
    if tally.outside_scene > 0 {
        notes.push(format!("{} animation channels target nodes outside the scene, ignored", tally.outside_scene));
    }
    if !tally.other_pointers.is_empty() {
        let count: usize = tally.other_pointers.values().sum();
        let pointers = tally.other_pointers.keys().map(|p| format!("`{p}`")).collect::<Vec<_>>().join(", ");
        notes.push(format!("{count} animation channels animate properties bonescope does not evaluate: {pointers}"));
    }
    Ok(clips)
}

/// What a channel animates.
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
enum Property {
    Translation,
    Rotation,
    Scale,
    Weights,
}

impl Property {
    fn from_name(name: &str) -> Option<Self> {
        match name {
            "translation" => Some(Property::Translation),
            "rotation" => Some(Property::Rotation),
            "scale" => Some(Property::Scale),
            "weights" => Some(Property::Weights),
            _ => None,
        }
    }

    /// What a channel's output accessor holds for this property, as errors name it (rotations have their own).
    fn output(self) -> &'static str {
        match self {
            Property::Scale => "scale output",
            _ => "translation output",
        }
    }

    fn name(self) -> &'static str {
        match self {
            Property::Translation => "translation",
            Property::Rotation => "rotation",
            Property::Scale => "scale",
            Property::Weights => "morph weights",
        }
    }
}

/// A channel's target: which nodes (a mesh's weights animate every node that shows the mesh) and what of them.
enum Target {
    Node(usize, Property),
    MeshWeights(usize),
    /// A `KHR_animation_pointer` bonescope does not evaluate.
    Other(String),
}

struct Reader<'a, 'd> {
    root: &'a Root,
    accessors: &'a Accessors<'d>,
    bone_of_node: &'a [Option<usize>],
    /// Key times by input accessor index.
    times: HashMap<Uint, Arc<[f64]>>,
    /// Decoded outputs by accessor index, or why one does not decode: channels sharing a sampler share its values
    /// (2,000 channels of one 100,000-key sampler are one decode, not 2,000).
    vec3s: HashMap<Uint, Result<Arc<[Vec3]>>>,
    rotations: HashMap<Uint, Result<Arc<[Quat]>>>,
    tally: Tally,
}

impl Reader<'_, '_> {
    /// Decodes the outputs of every clip's node channels on every core, ahead of reading the channels in order: a
    /// long clip is mostly these (1.2 million rotation keys in 200 accessors for 200 bones over 6,000 frames), each
    /// read from the file and decoded on its own. Each is decoded as its first channel decodes it, so one that fails
    /// fails as it would have there; one whose channel is never read (an earlier channel fails) only cost its time.
    fn decode_ahead(&mut self) {
        let (mut vec3s, mut rotations) = (Vec::new(), Vec::new());
        let mut seen = HashSet::new();
        for (index, animation) in self.root.animations.iter().enumerate() {
            for (c, channel) in animation.channels.iter().enumerate() {
                let channel_place = format!("animations[{index}].channels[{c}]");
                let Ok(Target::Node(node, property)) = self.target(&channel.target, &channel_place) else { continue };
                let read = self.bone_of_node.get(node).is_some_and(Option::is_some);
                let sampler = self.sampler(animation, channel.sampler, &channel_place);
                let Some(output) = sampler.ok().filter(|_| read).map(|s| s.output) else { continue };
                let place = sampler_place(index, channel.sampler);
                match property {
                    Property::Translation | Property::Scale if seen.insert((false, output)) => {
                        vec3s.push((output, place, property.output()));
                    }
                    Property::Rotation if seen.insert((true, output)) => rotations.push((output, place)),
                    _ => {}
                }
            }
        }
        let accessors = self.accessors;
        let (vec3s, rotations) = rayon::join(
            || vec3s.into_par_iter().map(|(at, place, what)| (at, accessors.vec3s(at, &place, what).map(Arc::from))),
            || rotations.into_par_iter().map(|(at, place)| (at, accessors.rotations(at, &place).map(Arc::from))),
        );
        self.vec3s.par_extend(vec3s);
        self.rotations.par_extend(rotations);
    }

    fn clip(&mut self, index: usize, animation: &schema::Animation) -> Result<Clip> {
        let mut tracks: BTreeMap<usize, BoneTracks> = BTreeMap::new();
        let mut morph = Vec::new();
        let mut targets = HashSet::new();
        for (c, channel) in animation.channels.iter().enumerate() {
            let channel_place = format!("animations[{index}].channels[{c}]");
            let (node, property) = match self.target(&channel.target, &channel_place)? {
                Target::Node(node, property) => (node, property),
                Target::MeshWeights(mesh) => {
                    let sampler = self.sampler(animation, channel.sampler, &channel_place)?;
                    for bone in self.bones_showing(mesh) {
                        morph.push(self.morph_weights(bone, sampler, channel.sampler, index)?);
                    }
                    continue;
                }
                Target::Other(pointer) => {
                    *self.tally.other_pointers.entry(pointer).or_default() += 1;
                    continue;
                }
            };
            if !targets.insert((node, property)) {
                let message = format!("a second channel for the {} of nodes[{node}]", property.name());
                return Err(Failure::at(channel_place, message));
            }
            let Some(bone) = self.bone_of_node[node] else {
                self.tally.outside_scene += 1;
                continue;
            };
            let sampler = self.sampler(animation, channel.sampler, &channel_place)?;
            let place = sampler_place(index, channel.sampler);
            let times = self.times(sampler.input, &place)?;
            let interpolation = interpolation(sampler, &place)?;
            let output = sampler.output;
            // A bone whose only channels are morph weights gets an empty entry, dropped below.
            let bone_tracks = tracks.entry(bone).or_insert_with(|| BoneTracks::new(bone));
            match property {
                Property::Translation | Property::Scale => {
                    let values =
                        decoded(&mut self.vec3s, output, || self.accessors.vec3s(output, &place, property.output()))?;
                    let track = Some(track(times, values, interpolation, &place)?);
                    match property {
                        Property::Scale => bone_tracks.scale = track,
                        _ => bone_tracks.translation = track,
                    }
                }
                Property::Rotation => {
                    let values = decoded(&mut self.rotations, output, || self.accessors.rotations(output, &place))?;
                    bone_tracks.rotation = Some(track(times, values, interpolation, &place)?);
                }
                Property::Weights => morph.push(self.morph_weights(bone, sampler, channel.sampler, index)?),
            }
        }
        let tracks = tracks
            .into_values()
            .filter(|t| t.translation.is_some() || t.rotation.is_some() || t.scale.is_some())
            .collect();
        Ok(Clip::new(index, animation.name.clone(), tracks, morph).with_key_rate())
    }

    /// What `target` animates, checked to exist.
    fn target(&self, target: &schema::Target, place: &str) -> Result<Target> {
        if let Some(pointer) = &target.extensions.animation_pointer
            && target.path == "pointer"
        {
            return self.pointer_target(&pointer.pointer, &format!("{place}.target"));
        }
        let Some(node) = target.node else {
            // Valid only with an extension bonescope does not know; nothing here to evaluate.
            return Ok(Target::Other(format!("path `{}` without a node", target.path)));
        };
        schema::item(&self.root.nodes, node, "nodes", format!("{place}.target.node"))?;
        match Property::from_name(&target.path) {
            Some(property) => Ok(Target::Node(node.0, property)),
            None => Err(Failure::at(format!("{place}.target.path"), format!("unknown path `{}`", target.path))),
        }
    }

    /// A `KHR_animation_pointer` target: `/nodes/N/{translation,rotation,scale,weights}` or `/meshes/M/weights`.
    fn pointer_target(&self, pointer: &str, place: &str) -> Result<Target> {
        let parts: Vec<&str> = pointer.strip_prefix('/').unwrap_or_default().split('/').collect();
        let index = |text: &str, list_len: usize, kind: &str| -> Result<usize> {
            match text.parse::<usize>() {
                Ok(i) if i < list_len => Ok(i),
                _ => Err(Failure::at(place, format!("pointer `{pointer}` names no existing {kind}"))),
            }
        };
        match parts[..] {
            ["nodes", node, property] => match Property::from_name(property) {
                Some(property) => Ok(Target::Node(index(node, self.root.nodes.len(), "node")?, property)),
                None => Ok(Target::Other(pointer.to_owned())),
            },
            ["meshes", mesh, "weights"] => Ok(Target::MeshWeights(index(mesh, self.root.meshes.len(), "mesh")?)),
            _ => Ok(Target::Other(pointer.to_owned())),
        }
    }

    /// The bones whose node shows `meshes[mesh]`.
    fn bones_showing(&self, mesh: usize) -> Vec<usize> {
        let nodes = self.root.nodes.iter().enumerate().filter(|(_, n)| n.mesh.is_some_and(|m| m.0 == mesh));
        nodes.filter_map(|(node, _)| self.bone_of_node[node]).collect()
    }

    fn sampler<'s>(
        &self,
        animation: &'s schema::Animation,
        index: Uint,
        place: &str,
    ) -> Result<&'s schema::AnimationSampler> {
        schema::item(&animation.samplers, index, "samplers", format!("{place}.sampler"))
    }

    /// The morph weights of `bone` a sampler animates: one track per target.
    fn morph_weights(
        &mut self,
        bone: usize,
        sampler: &schema::AnimationSampler,
        sampler_index: Uint,
        animation: usize,
    ) -> Result<MorphWeights> {
        let place = sampler_place(animation, sampler_index);
        let times = self.times(sampler.input, &place)?;
        let interpolation = interpolation(sampler, &place)?;
        let outputs = self.accessors.morph_weights(sampler.output, &place)?;
        let weights = weight_tracks(&times, interpolation, &outputs, &place)?;
        Ok(MorphWeights { bone, weights })
    }

    /// The key times of an input accessor, read on first use. glTF's clock starts at 0: a time before it is
    /// refused (the other formats' clocks may run before 0, so tracks take one).
    fn times(&mut self, input: Uint, place: &str) -> Result<Arc<[f64]>> {
        match self.times.entry(input) {
            Entry::Occupied(entry) => Ok(entry.get().clone()),
            Entry::Vacant(entry) => {
                let times = self.accessors.times(input, place)?;
                if let Some((index, time)) = times.iter().enumerate().find(|(_, t)| **t < 0.0) {
                    let why = format!("key time {index} ({time}) is negative: glTF's key times start at 0");
                    return Err(Failure::at(place, why));
                }
                Ok(entry.insert(times.into()).clone())
            }
        }
    }
}

/// Where a channel's sampler is, as errors name it.
fn sampler_place(animation: usize, sampler: Uint) -> String {
    format!("animations[{animation}].samplers[{}]", sampler.0)
}

/// The values of `accessor`, decoded by `decode` on first use (or ahead: [`Reader::decode_ahead`]).
fn decoded<T>(
    cache: &mut HashMap<Uint, Result<Arc<[T]>>>,
    accessor: Uint,
    decode: impl FnOnce() -> Result<Vec<T>>,
) -> Result<Arc<[T]>> {
    cache.entry(accessor).or_insert_with(|| decode().map(Arc::from)).clone()
}

/// A checked track; what [`Track::new`] finds wrong is placed at the sampler.
fn track<T: KeyValue>(
    times: Arc<[f64]>,
    values: Arc<[T]>,
    interpolation: Interpolation,
    place: &str,
) -> Result<Track<T>> {
    Track::new(times, values, interpolation).map_err(|e| Failure::at(place, e.to_string()))
}

/// A morph-weight sampler's outputs as one track per target: glTF stores, per key, every target's weight (for cubic
/// splines every target's in-tangent, then values, then out-tangents), so the count must be a whole number of
/// weights per stored key.
fn weight_tracks(
    times: &Arc<[f64]>,
    interpolation: Interpolation,
    outputs: &[f32],
    place: &str,
) -> Result<Vec<Track<f32>>> {
    let stored = times.len() * interpolation.values_per_key();
    if stored == 0 || !outputs.len().is_multiple_of(stored) {
        let message =
            format!("{} morph-weight outputs are not a whole number per key ({stored} stored keys)", outputs.len());
        return Err(Failure::at(place, message));
    }
    let targets = outputs.len() / stored;
    (0..targets)
        .map(|target| {
            let values = outputs.iter().skip(target).step_by(targets).copied().collect();
            track(times.clone(), values, interpolation, place)
        })
        .collect()
}

/// The sampler's interpolation (`LINEAR` when absent).
fn interpolation(sampler: &schema::AnimationSampler, place: &str) -> Result<Interpolation> {
    match sampler.interpolation.as_deref() {
        None | Some("LINEAR") => Ok(Interpolation::Linear),
        Some("STEP") => Ok(Interpolation::Step),
        Some("CUBICSPLINE") => Ok(Interpolation::CubicSpline),
        Some(other) => Err(Failure::at(format!("{place}.interpolation"), format!("unknown interpolation `{other}`"))),
    }
}
