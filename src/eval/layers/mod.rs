//! Runtime techniques layered on a sampled clip, each as a game runtime does it:
//!
//! ```text
//! clip ─sample─▶ pose ─▶ bind weight ─▶ blend ─▶ additive ─▶ crossfade ─▶ shake ─▶ uniform ─▶ targets ─▶ pose
//!   (interpolation       (mix with     (second   (difference  (into a third  (cosine   (chosen    (model-space
//!    override, for        bind pose)    clip,     from a ref,  clip, weight   wobble)   bones'     rotations)
//!    every clip read)                   synced)   local or     over time)               scale made
//!                                                 global)                               uniform)
//! ```
//!
//! [`Layers`] says what to do (serialisable; the default does nothing), [`LayerStack`] holds what it needs prepared
//! once (bind pose, additive reference, shake modifiers) and the buffers for evaluating any number of times without
//! allocating. Every step is also a pure function in its own module, tested against the formulas its module states.
//!
//! Weights are clamped to `[0, 1]`, NaN counting as 0; clip and bone indices are checked when the stack is built;
//! a non-finite time counts as 0. Nothing here panics on bad input.

mod additive;
mod crossfade;
mod interpolate;
mod mix;
mod shake;
mod target;
mod time;
mod uniform;

pub use additive::{AdditiveOrder, AdditiveReference, add, add_poses, difference};
pub use crossfade::{Crossfade, FadeCurve};
pub use interpolate::{Channel, KeyInterpolation, Resampling, RotationInterpolation};
pub use mix::{RotationBlend, mix, mix_poses, unit_weight};
pub use shake::{Shake, ShakeParams, UnknownShakeParam, bone_modifiers, shake_pose};
pub use target::{Target, pin_pose};
pub use time::{SyncedCycle, TICKS_PER_SECOND};
pub use uniform::{uniform_part, uniform_pose, uniform_scale};

use glam::DQuat;

use super::bind_pose;
use super::sample::{rest_pose_into, sample_clip_near, sample_clip_with};
use crate::model::{Clip, Rig, Skeleton, Transform};

/// A second clip blended with the main one.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Blend {
    /// Index of the clip in the rig.
    pub clip: usize,
    /// The blend factor `a`: 0 is the main clip, 1 this one.
    pub weight: f64,
    /// Play both at one normalised time over the blended cycle ([`SyncedCycle`]); else each at its own speed.
    pub sync: bool,
    pub rotation: RotationBlend,
}

/// An additive clip on top.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Additive {
    pub clip: usize,
    pub reference: AdditiveReference,
    pub order: AdditiveOrder,
    pub weight: f64,
}

/// Which techniques to layer on a clip, applied in the order of the fields. The default is no layers at all.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct Layers {
    /// 1: the clip as sampled; 0: the bind pose (`eval::bind`); between: mixed bone by bone.
    pub bind_weight: f64,
    /// How every clip a layer reads is sampled.
    pub interpolation: Resampling,
    pub blend: Option<Blend>,
    pub additive: Option<Additive>,
    pub crossfade: Option<Crossfade>,
    pub shake: Option<Shake>,
    /// Bones whose local scale is replaced by its uniform part ([`uniform_part`]): an ancestor's squash taken out
    /// to see the shear it causes go.
    pub uniform_scale: Vec<usize>,
    pub targets: Vec<Target>,
}

impl Default for Layers {
    fn default() -> Self {
        Layers {
            bind_weight: 1.0,
            interpolation: Resampling::default(),
            blend: None,
            additive: None,
            crossfade: None,
            shake: None,
            uniform_scale: Vec::new(),
            targets: Vec::new(),
        }
    }
}

impl Layers {
    /// One line for people: what the layers do, by name (empty without layers).
    pub fn summary(&self, rig: &Rig, clip: Option<&Clip>) -> String {
        let layers = self;
        let name = |index: usize| rig.clips.get(index).map_or_else(|| format!("animation {index}"), Clip::label);
        let bone =
            |index: usize| rig.skeleton.bones().get(index).map_or_else(|| format!("bone {index}"), |b| b.name.clone());
        let mut parts = Vec::new();
        if layers.bind_weight < 1.0 {
            parts.push(format!("bind weight {}", layers.bind_weight));
        }
        if !layers.interpolation.is_authored() {
            let r = layers.interpolation;
            parts.push(format!("interpolation {:?}/{:?}", r.keys, r.rotation).to_lowercase());
        }
        if let Some(b) = &layers.blend {
            let sync = if b.sync {
                let other = length(rig.clips.get(b.clip));
                let cycle = SyncedCycle::new(length(clip), other, b.weight);
                format!(", synced: cycle {:.4} s, rates {:.4} and {:.4}", cycle.length, cycle.rates[0], cycle.rates[1])
            } else {
                String::new()
            };
            parts.push(format!("blend `{}` a = {}{sync}", name(b.clip), b.weight));
        }
        if let Some(a) = &layers.additive {
            let how = format!("{:?} reference, {:?} order", a.reference, a.order).to_lowercase();
            parts.push(format!("additive `{}` ({how}, weight {})", name(a.clip), a.weight));
        }
        if let Some(c) = &layers.crossfade {
            let curve = format!("{:?}", c.curve).to_lowercase();
            parts.push(format!("crossfade into `{}` at {} s over {} s ({curve})", name(c.clip), c.at, c.duration));
        }
        if let Some(s) = &layers.shake {
            parts.push(format!("shake `{}`", bone(s.bone)));
        }
        for &b in &layers.uniform_scale {
            parts.push(format!("uniform scale `{}`", bone(b)));
        }
        for t in &layers.targets {
            parts.push(format!("target `{}` weight {}", bone(t.bone), t.weight));
        }
        parts.join("; ")
    }

    /// Adds `bone` to the bones whose local scale is made uniform ([`uniform_part`]), once.
    pub fn make_scale_uniform(&mut self, bone: usize) {
        if !self.uniform_scale.contains(&bone) {
            self.uniform_scale.push(bone);
        }
    }

    /// Whether these layers leave the clip exactly as sampled.
    pub fn is_empty(&self) -> bool {
        *self == Layers::default()
    }

    /// The same layers with every clip read as authored: the ghost to show beside an interpolation override.
    pub fn authored(&self) -> Layers {
        Layers { interpolation: Resampling::default(), ..self.clone() }
    }
}

/// Layers that name a clip or bone the rig does not have.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum LayerError {
    #[error("{layer}: no animation {index} (the file has {count})")]
    NoClip { layer: &'static str, index: usize, count: usize },
    #[error("{layer}: no bone {index} (the skeleton has {count})")]
    NoBone { layer: &'static str, index: usize, count: usize },
}

/// [`Layers`] prepared for one rig, with the buffers to evaluate them.
#[derive(Clone, Debug, Default)]
pub struct LayerStack {
    layers: Layers,
    /// The bind pose, when the bind weight is below 1.
    bind: Vec<Transform>,
    /// The additive clip's reference pose.
    reference: Vec<Transform>,
    /// The shake's per-bone modifiers.
    modifiers: Vec<f64>,
    scratch: Vec<Transform>,
    chain: Vec<DQuat>,
    /// Key-search hints of the main, blended, additive and incoming clips (see `sample_clip_near`).
    hints: [Vec<usize>; 4],
}

impl LayerStack {
    /// Whether the stack leaves the clip exactly as sampled (see [`Layers::is_empty`]).
    pub fn is_empty(&self) -> bool {
        self.layers.is_empty()
    }

    /// Checks every index against `rig` and prepares what does not change with time.
    pub fn new(rig: &Rig, layers: &Layers) -> Result<Self, LayerError> {
        let clips = rig.clips.len();
        let bones = rig.skeleton.len();
        let clip_of =
            |layer, index: usize| rig.clips.get(index).ok_or(LayerError::NoClip { layer, index, count: clips });
        let check_bone = |layer, index: usize| {
            if index < bones { Ok(()) } else { Err(LayerError::NoBone { layer, index, count: bones }) }
        };
        if let Some(blend) = &layers.blend {
            clip_of("blend", blend.clip)?;
        }
        if let Some(crossfade) = &layers.crossfade {
            clip_of("crossfade", crossfade.clip)?;
        }
        for target in &layers.targets {
            check_bone("target", target.bone)?;
        }
        for &bone in &layers.uniform_scale {
            check_bone("uniform scale", bone)?;
        }
        let reference = match &layers.additive {
            None => Vec::new(),
            Some(additive) => {
                let clip = clip_of("additive", additive.clip)?;
                let mut reference = Vec::new();
                match additive.reference {
                    AdditiveReference::First => {
                        sample(&rig.skeleton, Some(clip), 0.0, &layers.interpolation, &mut reference, None)
                    }
                    AdditiveReference::Rest => reference = rig.skeleton.rest_pose(),
                }
                reference
            }
        };
        let modifiers = match &layers.shake {
            None => Vec::new(),
            Some(shake) => {
                check_bone("shake", shake.bone)?;
                bone_modifiers(&rig.skeleton, shake.bone, shake.params.attenuation)
            }
        };
        let mut layers = layers.clone();
        layers.targets.sort_by_key(|t| t.bone);
        let bind = if unit_weight(layers.bind_weight) < 1.0 { bind_pose(rig) } else { Vec::new() };
        Ok(LayerStack {
            layers,
            bind,
            reference,
            modifiers,
            scratch: Vec::new(),
            chain: Vec::new(),
            hints: Default::default(),
        })
    }

    /// A stack that only reads every clip with `interpolation`: it names no clip or bone, so nothing to check.
    pub fn resampling(interpolation: Resampling) -> Self {
        LayerStack { layers: Layers { interpolation, ..Layers::default() }, ..LayerStack::default() }
    }

    pub fn layers(&self) -> &Layers {
        &self.layers
    }

    /// The blended cycle, when a synced blend is on: the timeline then runs over `cycle.length` and repeats.
    pub fn synced_cycle(&self, rig: &Rig, clip: Option<&Clip>) -> Option<SyncedCycle> {
        let blend = self.layers.blend.filter(|b| b.sync)?;
        let other = rig.clips.get(blend.clip)?;
        Some(SyncedCycle::new(length(clip), other.span().length(), blend.weight))
    }

    /// How long the layered timeline runs from the main clip's start: the synced cycle, or the main clip until the
    /// crossfade has brought the incoming clip to its end (the main clip's length without either).
    pub fn length(&self, rig: &Rig, clip: Option<&Clip>) -> f64 {
        if let Some(cycle) = self.synced_cycle(rig, clip) {
            return cycle.length;
        }
        let main = length(clip);
        let incoming = self.layers.crossfade.and_then(|c| Some(c.at.max(0.0) + rig.clips.get(c.clip)?.span().length()));
        incoming.filter(|end| end.is_finite()).map_or(main, |end| end.max(main))
    }

    /// The local pose of every bone of `rig` at `time` with the layers applied, written into `local`. `clip` is
    /// the main clip (`None`: the rest pose); `rig` must be the one the stack was built for.
    ///
    /// `time` is on the main clip's clock. The layers count from the main clip's start (a crossfade `at` 1 s begins
    /// a second after it), and every other clip plays from its own start then: each file's clock is its own, and a
    /// clip that starts at frame 1 is not played from before its first frame.
    pub fn evaluate(&mut self, rig: &Rig, clip: Option<&Clip>, time: f64, local: &mut Vec<Transform>) {
        let skeleton = &rig.skeleton;
        let time = if time.is_finite() { time } else { 0.0 };
        let elapsed = time - clip.map_or(0.0, |c| c.span().start);
        let at = |other: &Clip, elapsed: f64| other.span().start + elapsed;
        let layers = &self.layers;
        let resampling = &layers.interpolation;
        let [main_elapsed, blend_elapsed] =
            self.synced_cycle(rig, clip).map_or([elapsed, elapsed], |c| c.clip_times(elapsed));
        let [main_hints, blend_hints, additive_hints, incoming_hints] = &mut self.hints;
        sample(skeleton, clip, time - elapsed + main_elapsed, resampling, local, Some(main_hints));
        if !self.bind.is_empty() {
            mix_poses(local, &self.bind, 1.0 - unit_weight(layers.bind_weight), RotationBlend::Slerp);
        }
        if let Some(blend) = &layers.blend
            && let Some(other) = rig.clips.get(blend.clip)
        {
            sample(skeleton, Some(other), at(other, blend_elapsed), resampling, &mut self.scratch, Some(blend_hints));
            mix_poses(local, &self.scratch, blend.weight, blend.rotation);
        }
        if let Some(additive) = &layers.additive
            && let Some(other) = rig.clips.get(additive.clip)
        {
            sample(skeleton, Some(other), at(other, elapsed), resampling, &mut self.scratch, Some(additive_hints));
            add_poses(local, &self.scratch, &self.reference, additive.weight, additive.order);
        }
        if let Some(crossfade) = &layers.crossfade
            && let Some(incoming) = rig.clips.get(crossfade.clip)
        {
            let weight = crossfade.weight(elapsed);
            if weight > 0.0 {
                let time = at(incoming, crossfade.incoming_time(elapsed));
                sample(skeleton, Some(incoming), time, resampling, &mut self.scratch, Some(incoming_hints));
                mix_poses(local, &self.scratch, weight, RotationBlend::Slerp);
            }
        }
        if let Some(shake) = &layers.shake {
            shake_pose(local, &self.modifiers, &shake.params, elapsed);
        }
        uniform_pose(local, &layers.uniform_scale);
        pin_pose(skeleton, local, &layers.targets, &mut self.chain);
    }
}

/// How long `clip` plays (0 for the rest pose).
fn length(clip: Option<&Clip>) -> f64 {
    clip.map_or(0.0, |c| c.span().length())
}

/// `clip` sampled at `time` (the rest pose for `None`), the key searches starting from `hints` when given.
fn sample(
    skeleton: &Skeleton,
    clip: Option<&Clip>,
    time: f64,
    resampling: &Resampling,
    out: &mut Vec<Transform>,
    hints: Option<&mut Vec<usize>>,
) {
    match clip {
        Some(clip) if resampling.is_authored() => sample_clip_near(skeleton, clip, time, out, hints),
        Some(clip) => sample_clip_with(skeleton, clip, time, resampling, out, hints),
        None => rest_pose_into(skeleton, out),
    }
}
