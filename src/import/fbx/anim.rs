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
//! not sampled. Times are the file's, in seconds; a stack that starts before t = 0 is shifted to start at 0 (and
//! says so). A long stack with sparse keys is thinned between keys ([`sample_times`]), so the samples stay bounded by
//! the keys, and the grid's size is checked against the file's size before anything is evaluated. (The key times are
//! read from the curves here rather than from `ufbx_bake_anim`, whose run time a hostile file can make unbounded.)

use std::sync::Arc;

use glam::{Quat, Vec3};

use super::mesh::{blend_channels, shape_weights};
use super::{Failure, Result, memory_limit, node_name};
use crate::model::{BoneTracks, Clip, Interpolation, MorphWeights, SAMPLES_PER_SPARSE_GAP, Track, sample_times};

/// Frames per second assumed when the file states none that makes sense.
const DEFAULT_FPS: f64 = 30.0;

/// The most frames a stack is sampled at every one of (9.7 hours at 30 fps); longer spans are thinned where keys are
/// sparse.
const MAX_FRAMES: usize = 1 << 20;

/// How long before a stepped key's jump the value before it is sampled (as ufbx's baker does).
const STEP: f64 = 1e-3;

/// Bytes one sample of one node costs (a time, a translation, a rotation and a scale in `f32`), for the budget.
const SAMPLE_BYTES: usize = 8 + 12 + 16 + 12;

pub(super) fn read_clips(
    scene: &ufbx::Scene,
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

struct StackReader<'a> {
    scene: &'a ufbx::Scene,
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
        let (nodes, keys, channels) = self.keys()?;
        let animated: Vec<(usize, &ufbx::Node)> = nodes
            .into_iter()
            .filter_map(|id| Some((bone_of_node.get(id).copied().flatten()?, self.scene.nodes.get(id)?.as_ref())))
            .collect();
        let (begin, end) = self.span(keys.iter().copied());
        let grid = self.grid(begin, end, keys, animated.len(), notes)?;
        let shift = if begin < 0.0 { -begin } else { 0.0 };
        if shift > 0.0 {
            notes.push(format!("{} starts at t = {begin} s; its clip is shifted to start at 0", self.place()));
        }
        let times: Arc<[f64]> = grid.iter().map(|t| t + shift).collect();
        let mut tracks = Vec::with_capacity(animated.len());
        for (bone, node) in animated {
            tracks.push(self.sample(bone, node, &grid, &times)?);
        }
        let morph = self.morph_weights(bone_of_node, &channels, &grid, &times)?;
        let samples = grid.len() * (tracks.len() + morph.len());
        let name: &str = &self.stack.element.name;
        let clip = Clip::new(self.index, (!name.is_empty()).then(|| name.to_owned()), tracks, morph);
        Ok((clip.with_frame_rate(self.fps), samples))
    }

    /// The nodes (typed ids) whose properties the stack animates, in order of appearance, every key time of their
    /// curves and of the blend channels' (with a time just before each step), and whether each blend channel (by
    /// typed id) is animated.
    fn keys(&self) -> Result<(Vec<usize>, Vec<f64>, Vec<bool>)> {
        let mut seen = vec![false; self.scene.nodes.len()];
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
        Ok((nodes, times, channels))
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
        grid: &[f64],
        times: &Arc<[f64]>,
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
                for &time in grid {
                    let weight = ufbx::evaluate_blend_weight(&self.stack.anim, channel, time);
                    for (share, value) in shares.iter_mut().zip(shape_weights(channel, weight)) {
                        share.push(value as f32);
                    }
                }
                for values in shares {
                    let place = || format!("{}, blend channel `{}`", self.place(), &*channel.element.name);
                    let track = Track::new(times.clone(), values, Interpolation::Linear)
                        .map_err(|e| Failure::at(place(), format!("weight: {e}")))?;
                    weights.push(track);
                }
            }
            morph.push(MorphWeights { bone, weights });
        }
        Ok(morph)
    }

    /// One animated node at every grid time (`times`: the grid as the clip's times).
    fn sample(&self, bone: usize, node: &ufbx::Node, grid: &[f64], times: &Arc<[f64]>) -> Result<BoneTracks> {
        let (mut translations, mut rotations, mut scales) =
            (Vec::with_capacity(grid.len()), Vec::with_capacity(grid.len()), Vec::with_capacity(grid.len()));
        for &time in grid {
            let t = ufbx::evaluate_transform(&self.stack.anim, node, time);
            translations.push(Vec3::new(t.translation.x as f32, t.translation.y as f32, t.translation.z as f32));
            rotations.push(Quat::from_xyzw(
                t.rotation.x as f32,
                t.rotation.y as f32,
                t.rotation.z as f32,
                t.rotation.w as f32,
            ));
            scales.push(Vec3::new(t.scale.x as f32, t.scale.y as f32, t.scale.z as f32));
        }
        let fail = |what: &str, e| {
            Failure::at(format!("{}, node `{}`", self.place(), node_name(node)), format!("{what}: {e}"))
        };
        let mut tracks = BoneTracks::new(bone);
        tracks.translation =
            Some(Track::new(times.clone(), translations, Interpolation::Linear).map_err(|e| fail("translation", e))?);
        tracks.rotation =
            Some(Track::new(times.clone(), rotations, Interpolation::Linear).map_err(|e| fail("rotation", e))?);
        tracks.scale = Some(Track::new(times.clone(), scales, Interpolation::Linear).map_err(|e| fail("scale", e))?);
        Ok(tracks)
    }
}
