//! Animation stacks as clips, sampled by ufbx at every frame and every key.
//!
//! FBX animates Euler angles (in the node's rotation order, between pre- and post-rotations and pivots) with
//! per-component weighted Bézier curves, in layers; a T·R·S keyframe track interpolated linearly cannot represent
//! that exactly. So each stack is baked onto one grid of times: every frame of the file's frame rate plus every
//! time at which some curve of the stack has a key (and, for a step, a millisecond before the value jumps). At each
//! grid time every animated node gets ufbx's own evaluation of its local transform (`ufbx_evaluate_transform`), so
//! bonescope's model matrices equal ufbx's at every grid time; between grid times they are interpolated linearly
//! (slerp for rotations), which is what a game runtime given the same keys would do.
//!
//! A clip covers its stack's time span (the take's start and stop, which is what DCCs play); keys outside it are
//! not sampled. Times are the file's, in seconds, as stored (a take that starts before 0 or after it starts there:
//! Blender writes each action's take from 0, Maya a take at its scene frames). A long stack with sparse keys is thinned between keys ([`sample_times`]), so the samples stay bounded by
//! the keys, and the grid's size is checked against the file's size before anything is evaluated. (The key times are
//! read from the curves here rather than from `ufbx_bake_anim`, whose run time a hostile file can make unbounded.)
//!
//! Sampling is most of the time an FBX file takes to load (one `ufbx_evaluate_transform` per node and grid time,
//! each looking up the node's transform properties), so it is done only where it can give a new value: a node
//! whose curves all hold one value, in layers of constant weight, with no connected property and no scale helper
//! (nothing else ufbx's evaluation reads changes in time), is evaluated once and that transform kept at every grid
//! time (ProAnimationBank's `skeleton.fbx` keys all 127 nodes that way over 151 frames). The other nodes are
//! sampled in parallel (on the rayon pool, which `scan` shares between files): ufbx's evaluation only reads the
//! loaded scene, which ufbx's `SceneRoot` declares safe to share between threads. A node whose transform is made of
//! its translation, rotation and scale channels alone is evaluated from them directly ([`Channels`]), to the same
//! bits as ufbx.

use std::sync::Arc;

use glam::{Quat, Vec3};
use rayon::prelude::*;

use super::channels::{Channels, evaluated_from_own_properties};
use super::mesh::{blend_channels, shape_weights};
use super::{Failure, Result, memory_limit, node_name};
use crate::model::{
    BoneTracks, Clip, Interpolation, MAX_FRAMES, MorphWeights, SAMPLES_PER_SPARSE_GAP, Span, Track, sample_times,
};

/// Frames per second assumed when the file states none that makes sense.
const DEFAULT_FPS: f64 = 30.0;

/// How long before a stepped key's jump the value before it is sampled (as ufbx's baker does).
const STEP: f64 = 1e-3;

/// Bytes one sample of one node costs (a time, a translation, a rotation and a scale in `f32`), for the budget.
const SAMPLE_BYTES: usize = 8 + 12 + 16 + 12;

pub(super) fn read_clips(
    scene: &ufbx::SceneRoot,
    bone_of_node: &[Option<usize>],
    file_size: usize,
    notes: &mut Vec<String>,
) -> Result<Vec<Clip>> {
    let stated = scene.settings.frames_per_second;
    let fps = if stated.is_finite() && stated > 0.0 { stated } else { DEFAULT_FPS };
    // One budget for all stacks: a file could hold many.
    let mut budget = memory_limit(file_size) / SAMPLE_BYTES;
    let mut clips = Vec::with_capacity(scene.anim_stacks.len());
    for (index, stack) in scene.anim_stacks.iter().enumerate() {
        let reader = StackReader { scene, index, stack, fps, budget };
        let (clip, samples) = reader.clip(bone_of_node, notes)?;
        budget = budget.saturating_sub(samples);
        clips.push(clip);
    }
    if !clips.is_empty() {
        let rate = if fps == stated { format!("{fps} fps") } else { format!("{fps} fps (the file states {stated})") };
        notes.push(format!(
            "animation: {} stacks sampled by ufbx at every frame ({rate}) and every key time: exact there, linear \
             (slerp for rotations) in between",
            clips.len()
        ));
    }
    Ok(clips)
}

/// What a stack animates.
struct Animated {
    /// The nodes (typed ids) whose properties it animates, in order of appearance.
    nodes: Vec<usize>,
    /// By node id: whether ufbx's evaluation of the node can change in time (see the module's documentation).
    moving: Vec<bool>,
    /// Every key time of their curves and of the blend channels' (with a time just before each step).
    times: Vec<f64>,
    /// By blend channel (typed id): whether it is animated.
    channels: Vec<bool>,
}

/// Whether a curve holds one value at every time: all keys equal and every tangent flat, so that no interpolation
/// (constant, linear or cubic) and no extrapolation (constant, slope or repetition) can leave that value.
fn is_flat(curve: &ufbx::AnimCurve) -> bool {
    let first = curve.keyframes.first().map(|k| k.value);
    curve.keyframes.iter().all(|k| Some(k.value) == first && k.left.dy == 0.0 && k.right.dy == 0.0)
}

struct StackReader<'a> {
    scene: &'a ufbx::SceneRoot,
    index: usize,
    stack: &'a ufbx::AnimStack,
    fps: f64,
    /// The most node samples the file's size still allows.
    budget: usize,
}

impl StackReader<'_> {
    fn place(&self) -> String {
        format!("animation stack {} `{}`", self.index, &*self.stack.element.name)
    }

    /// The clip, and how many node samples it holds.
    fn clip(&self, bone_of_node: &[Option<usize>], notes: &mut Vec<String>) -> Result<(Clip, usize)> {
        let Animated { nodes, moving, times: keys, channels } = self.keys()?;
        // (bone, node id, whether it moves): what crosses threads is the scene and indices into it.
        let animated: Vec<(usize, usize, bool)> = nodes
            .into_iter()
            .filter(|&id| id < self.scene.nodes.len())
            .filter_map(|id| Some((bone_of_node.get(id).copied().flatten()?, id, moving[id])))
            .collect();
        let (begin, end) = self.span(keys.iter().copied());
        let grid: Arc<[f64]> = self.grid(begin, end, keys, animated.len(), notes)?.into();
        let sampler = NodeSampler { scene: self.scene, stack: self.index, place: self.place(), grid: &grid };
        let tracks = animated
            .par_iter()
            .map(|&(bone, node, moves)| sampler.sample(bone, node, moves))
            .collect::<Result<Vec<_>>>()?;
        let morph = self.morph_weights(bone_of_node, &channels, &grid)?;
        let samples = grid.len() * (tracks.len() + morph.len());
        let name: &str = &self.stack.element.name;
        let clip = Clip::new(self.index, (!name.is_empty()).then(|| name.to_owned()), tracks, morph);
        Ok((clip.with_frame_rate(self.fps).with_span(Span::new(begin, end)), samples))
    }

    /// What the stack animates, and every key time of it.
    fn keys(&self) -> Result<Animated> {
        let mut seen = vec![false; self.scene.nodes.len()];
        let mut moving = vec![false; self.scene.nodes.len()];
        let mut channels = vec![false; self.scene.blend_channels.len()];
        let (mut nodes, mut times) = (Vec::new(), Vec::new());
        for layer in self.stack.layers.iter() {
            for prop in layer.anim_props.iter() {
                let element = &prop.element;
                let id = element.typed_id as usize;
                match element.type_ {
                    ufbx::ElementType::Node => {
                        if let Some(flag) = seen.get_mut(id)
                            && !*flag
                        {
                            *flag = true;
                            nodes.push(id);
                        }
                        if let Some(moves) = moving.get_mut(id) {
                            *moves |= layer.weight_is_animated
                                || prop.anim_value.curves.iter().flatten().any(|c| !is_flat(c));
                        }
                    }
                    ufbx::ElementType::BlendChannel => {
                        if let Some(flag) = channels.get_mut(id) {
                            *flag = true;
                        }
                    }
                    // Older exporters (3ds Max 7, Blender) animate a shape's weight as a property of the mesh.
                    ufbx::ElementType::Mesh => {
                        for channel in self.scene.meshes.get(id).into_iter().flat_map(|m| blend_channels(m)) {
                            if let Some(flag) = channels.get_mut(channel.element.typed_id as usize) {
                                *flag = true;
                            }
                        }
                    }
                    _ => continue,
                }
                for curve in prop.anim_value.curves.iter().flatten() {
                    let keys = &curve.keyframes;
                    for (k, key) in keys.iter().enumerate() {
                        times.push(key.time);
                        let next = keys.get(k + 1).map(|n| n.time);
                        match (key.interpolation, next) {
                            (ufbx::Interpolation::ConstantPrev, Some(next)) => {
                                times.push(next - STEP.min(0.5 * (next - key.time)));
                            }
                            (ufbx::Interpolation::ConstantNext, Some(next)) => {
                                times.push(key.time + STEP.min(0.5 * (next - key.time)));
                            }
                            _ => {}
                        }
                    }
                    if times.len() > self.budget {
                        return Err(Failure::at(self.place(), "more keys than the file's size can justify"));
                    }
                }
            }
        }
        times.retain(|t| t.is_finite());
        for &id in &nodes {
            moving[id] |= self.scene.nodes.get(id).is_none_or(|node| !evaluated_from_own_properties(node));
        }
        Ok(Animated { nodes, moving, times, channels })
    }

    /// The stack's time span, or that of its keys when the stack states none (or a reversed one).
    fn span(&self, keys: impl Iterator<Item = f64>) -> (f64, f64) {
        let (begin, end) = (self.stack.time_begin, self.stack.time_end);
        if begin.is_finite() && end.is_finite() && begin < end {
            return (begin, end);
        }
        let (min, max) = keys.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), t| (lo.min(t), hi.max(t)));
        if min.is_finite() && max.is_finite() { (min, max) } else { (0.0, 0.0) }
    }

    /// The times to sample: [`sample_times`] of the keys over `[begin, end]` at the file's frame rate, thinned where
    /// keys are sparse when every frame for every node would exceed the budget.
    fn grid(&self, begin: f64, end: f64, keys: Vec<f64>, nodes: usize, notes: &mut Vec<String>) -> Result<Vec<f64>> {
        let max_frames = (self.budget / nodes.max(1)).min(MAX_FRAMES);
        let sampled = sample_times(keys, begin, end, self.fps, max_frames);
        if sampled.times.len().saturating_mul(nodes) > self.budget {
            return Err(Failure::at(self.place(), "more keys than the file's size can justify"));
        }
        if sampled.thinned {
            notes.push(format!(
                "{} spans {} s ({} frames at {} fps) with few keys: sampled at its key times, every frame where keys \
                 are dense and {SAMPLES_PER_SPARSE_GAP} times across each longer gap ({} samples)",
                self.place(),
                end - begin,
                sampled.frames,
                self.fps,
                sampled.times.len()
            ));
        }
        Ok(sampled.times)
    }

    /// The morph weights of every mesh with an animated blend channel, at every grid time: each channel's weight
    /// as ufbx evaluates it, split among its shapes by the in-between rule ([`shape_weights`]).
    fn morph_weights(
        &self,
        bone_of_node: &[Option<usize>],
        animated: &[bool],
        grid: &Arc<[f64]>,
    ) -> Result<Vec<MorphWeights>> {
        let mut morph = Vec::new();
        for node in self.scene.nodes.iter() {
            let Some(mesh) = node.mesh.as_ref() else { continue };
            let channels: Vec<&ufbx::BlendChannel> = blend_channels(mesh).collect();
            let is_animated = |c: &&ufbx::BlendChannel| animated.get(c.element.typed_id as usize) == Some(&true);
            let Some(bone) = bone_of_node.get(node.element.typed_id as usize).copied().flatten() else { continue };
            if !channels.iter().any(is_animated) {
                continue;
            }
            let mut weights = Vec::new();
            for channel in channels {
                let mut shares: Vec<Vec<f32>> = vec![Vec::with_capacity(grid.len()); channel.keyframes.len()];
                for &time in grid.iter() {
                    let weight = ufbx::evaluate_blend_weight(&self.stack.anim, channel, time);
                    for (share, value) in shares.iter_mut().zip(shape_weights(channel, weight)) {
                        share.push(value as f32);
                    }
                }
                for values in shares {
                    let place = || format!("{}, blend channel `{}`", self.place(), &*channel.element.name);
                    let track = Track::new(grid.clone(), values, Interpolation::Linear)
                        .map_err(|e| Failure::at(place(), format!("weight: {e}")))?;
                    weights.push(track);
                }
            }
            morph.push(MorphWeights { bone, weights });
        }
        Ok(morph)
    }
}

/// Samples nodes of one stack at every grid time; shared by the threads that sample.
struct NodeSampler<'a> {
    scene: &'a ufbx::SceneRoot,
    /// The stack's index.
    stack: usize,
    /// The stack, for errors.
    place: String,
    /// The times sampled, which are the clip's key times.
    grid: &'a Arc<[f64]>,
}

impl NodeSampler<'_> {
    /// The tracks of `bone`, the node with typed id `node`: evaluated at every grid time, or, when it does not
    /// `move`, once and held.
    fn sample(&self, bone: usize, node: usize, moves: bool) -> Result<BoneTracks> {
        let (node, stack) = (&self.scene.nodes[node], &self.scene.anim_stacks[self.stack]);
        let (mut translations, mut rotations, mut scales) = (
            Vec::with_capacity(self.grid.len()),
            Vec::with_capacity(self.grid.len()),
            Vec::with_capacity(self.grid.len()),
        );
        let channels = Channels::of(node, stack);
        let evaluate = |time| match &channels {
            Some(channels) => channels.at(time),
            None => ufbx::evaluate_transform(&stack.anim, node, time),
        };
        let held = if moves { None } else { self.grid.first().map(|&time| evaluate(time)) };
        for &time in self.grid.iter() {
            let t = held.unwrap_or_else(|| evaluate(time));
            translations.push(Vec3::new(t.translation.x as f32, t.translation.y as f32, t.translation.z as f32));
            rotations.push(Quat::from_xyzw(
                t.rotation.x as f32,
                t.rotation.y as f32,
                t.rotation.z as f32,
                t.rotation.w as f32,
            ));
            scales.push(Vec3::new(t.scale.x as f32, t.scale.y as f32, t.scale.z as f32));
        }
        let fail =
            |what: &str, e| Failure::at(format!("{}, node `{}`", self.place, node_name(node)), format!("{what}: {e}"));
        let times = || self.grid.clone();
        let mut tracks = BoneTracks::new(bone);
        tracks.translation =
            Some(Track::new(times(), translations, Interpolation::Linear).map_err(|e| fail("translation", e))?);
        tracks.rotation = Some(Track::new(times(), rotations, Interpolation::Linear).map_err(|e| fail("rotation", e))?);
        tracks.scale = Some(Track::new(times(), scales, Interpolation::Linear).map_err(|e| fail("scale", e))?);
        Ok(tracks)
    }
}
