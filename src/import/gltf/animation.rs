//! Animations as [`Clip`]s: translation, rotation and scale channels become tracks, morph-weight channels are
//! listed.
//!
//! Key times are read once per input accessor and shared (`Arc`) by every track that uses it, as exporters
//! commonly give all channels of a clip one time accessor.

use std::collections::hash_map::{Entry, HashMap};
use std::collections::{BTreeMap, HashSet};
use std::sync::Arc;

use gltf::animation::{Interpolation as GltfInterpolation, Property};

use super::{Failure, Result, accessor};
use crate::model::{BoneTracks, Clip, Interpolation, KeyValue, MorphChannel, Track};

/// What the channels of all clips add up to, for the notes.
#[derive(Default)]
struct Tally {
    morph_channels: usize,
    outside_scene: usize,
}

pub(super) fn read_clips(
    doc: &gltf::Document,
    buffers: &[Vec<u8>],
    bone_of_node: &[Option<usize>],
    notes: &mut Vec<String>,
) -> Result<Vec<Clip>> {
    let mut reader = Reader { buffers, bone_of_node, times: HashMap::new(), tally: Tally::default() };
    let clips = doc.animations().map(|a| reader.clip(&a)).collect::<Result<Vec<_>>>()?;
    if reader.tally.morph_channels > 0 {
        notes.push(format!("{} morph-weight channels listed, not evaluated", reader.tally.morph_channels));
    }
    if reader.tally.outside_scene > 0 {
        notes
            .push(format!("{} animation channels target nodes outside the scene, ignored", reader.tally.outside_scene));
    }
    Ok(clips)
}

struct Reader<'a> {
    buffers: &'a [Vec<u8>],
    bone_of_node: &'a [Option<usize>],
    /// Key times by input accessor index.
    times: HashMap<usize, Arc<[f64]>>,
    tally: Tally,
}

impl Reader<'_> {
    fn clip(&mut self, animation: &gltf::Animation) -> Result<Clip> {
        let mut tracks: BTreeMap<usize, BoneTracks> = BTreeMap::new();
        let mut morph_channels = Vec::new();
        let mut targets = HashSet::new();
        for channel in animation.channels() {
            let node = channel.target().node().index();
            let property = channel.target().property();
            if !targets.insert((node, property_name(property))) {
                let place = format!("animations[{}].channels[{}]", animation.index(), channel.index());
                let message = format!("a second channel for the {} of nodes[{node}]", property_name(property));
                return Err(Failure::at(place, message));
            }
            let Some(bone) = self.bone_of_node[node] else {
                self.tally.outside_scene += 1;
                continue;
            };
            let sampler = channel.sampler();
            let place = format!("animations[{}].samplers[{}]", animation.index(), sampler.index());
            let times = self.times(&sampler.input())?;
            let interpolation = interpolation(sampler.interpolation());
            let output = sampler.output();
            let bone_tracks = tracks.entry(bone).or_insert_with(|| BoneTracks::new(bone));
            match property {
                Property::Translation => {
                    let values = accessor::vec3s(&output, self.buffers, "translation output")?;
                    bone_tracks.translation = Some(track(times, values, interpolation, &place)?);
                }
                Property::Scale => {
                    let values = accessor::vec3s(&output, self.buffers, "scale output")?;
                    bone_tracks.scale = Some(track(times, values, interpolation, &place)?);
                }
                Property::Rotation => {
                    let values = accessor::rotations(&output, self.buffers)?;
                    bone_tracks.rotation = Some(track(times, values, interpolation, &place)?);
                }
                Property::MorphTargetWeights => {
                    accessor::check_morph_weights(&output, self.buffers)?;
                    morph_channels.push(morph_channel(bone, &times, interpolation, output.count(), &place)?);
                    self.tally.morph_channels += 1;
                }
            }
        }
        // A bone whose only channels were morph weights has an empty entry.
        let tracks = tracks
            .into_values()
            .filter(|t| t.translation.is_some() || t.rotation.is_some() || t.scale.is_some())
            .collect();
        Ok(Clip::new(animation.index(), animation.name().map(str::to_owned), tracks, morph_channels))
    }

    /// The key times of an input accessor, read on first use.
    fn times(&mut self, input: &gltf::Accessor) -> Result<Arc<[f64]>> {
        match self.times.entry(input.index()) {
            Entry::Occupied(entry) => Ok(entry.get().clone()),
            Entry::Vacant(entry) => Ok(entry.insert(accessor::times(input, self.buffers)?.into()).clone()),
        }
    }
}

/// A checked track; what [`Track::new`] finds wrong is placed at the sampler.
fn track<T: KeyValue>(
    times: Arc<[f64]>,
    values: Vec<T>,
    interpolation: Interpolation,
    place: &str,
) -> Result<Track<T>> {
    Track::new(times, values, interpolation).map_err(|e| Failure::at(place, e.to_string()))
}

/// A morph-weight channel, with the checks [`Track::new`] does for the others: valid times, and an output
/// count that is a whole number of weights per stored key.
fn morph_channel(
    bone: usize,
    times: &[f64],
    interpolation: Interpolation,
    outputs: usize,
    place: &str,
) -> Result<MorphChannel> {
    let valid_times = times.first().is_some_and(|&t| t >= 0.0)
        && times.windows(2).all(|w| w[0] < w[1])
        && times.iter().all(|t| t.is_finite());
    if !valid_times {
        return Err(Failure::at(place, "key times are not finite, non-negative and increasing"));
    }
    let stored = times.len() * interpolation.values_per_key();
    if !outputs.is_multiple_of(stored) {
        let message = format!("{outputs} morph-weight outputs are not a whole number per key ({stored} stored keys)");
        return Err(Failure::at(place, message));
    }
    let last_time = times.last().copied().unwrap_or_default();
    Ok(MorphChannel { bone, keys: times.len(), interpolation, last_time })
}

fn interpolation(interpolation: GltfInterpolation) -> Interpolation {
    match interpolation {
        GltfInterpolation::Step => Interpolation::Step,
        GltfInterpolation::Linear => Interpolation::Linear,
        GltfInterpolation::CubicSpline => Interpolation::CubicSpline,
    }
}

fn property_name(property: Property) -> &'static str {
    match property {
        Property::Translation => "translation",
        Property::Rotation => "rotation",
        Property::Scale => "scale",
        Property::MorphTargetWeights => "morph weights",
    }
}
