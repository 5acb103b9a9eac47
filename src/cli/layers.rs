//! The layer options `inspect`, `scan` and `render` share (`eval::layers`), parsed once and resolved against a
//! loaded rig: names become clip and bone indices, weights are checked.

use anyhow::{Context, anyhow, bail};
use clap::Args;
use glam::DQuat;

use super::options::{choice, clip_index};
use crate::eval::layers::{
    Additive, AdditiveOrder, AdditiveReference, Blend, Crossfade, FadeCurve, KeyInterpolation, Layers, Resampling,
    RotationBlend, RotationInterpolation, Shake, ShakeParams, Target,
};
use crate::model::{Choice, Rig};

/// Runtime techniques layered on the animation, applied in this order: bind weight, interpolation, blend,
/// additive, crossfade, shake, uniform scale, targets.
#[derive(Clone, Debug, Default, PartialEq, Args)]
pub struct LayerArgs {
    /// Mix with the bind pose from the skin's inverse bind matrices: 1 is the animation, 0 the bind pose.
    #[arg(long, value_name = "W")]
    pub bind_weight: Option<f64>,
    /// Read every animation with this interpolation instead of the file's (cubic: Catmull-Rom through the keys).
    #[arg(long, value_parser = choice::<KeyInterpolation>(), value_name = "MODE", default_value = KeyInterpolation::default().id())]
    pub interp: KeyInterpolation,
    /// How rotation keys are interpolated (euler: per-component Euler XYZ angles).
    #[arg(long, value_parser = choice::<RotationInterpolation>(), value_name = "MODE", default_value = RotationInterpolation::default().id())]
    pub rot_interp: RotationInterpolation,
    /// Blend a second animation (name or index) with the main one.
    #[arg(long, value_name = "NAME|INDEX", requires = "weight")]
    pub blend: Option<String>,
    /// The blend factor a: 0 is the main animation, 1 the --blend one.
    #[arg(long, value_name = "A", requires = "blend")]
    pub weight: Option<f64>,
    /// Play both at one normalised time over a cycle of (T2 − T1)·a + T1 seconds; --time is then the time of that
    /// cycle and wraps at its length.
    #[arg(long, requires = "blend")]
    pub sync: bool,
    /// How the blend mixes rotations.
    #[arg(long, value_parser = choice::<RotationBlend>(), value_name = "MODE", requires = "blend")]
    pub blend_rotation: Option<RotationBlend>,
    /// Add an additive animation (name or index): its difference from a reference pose.
    #[arg(long, value_name = "NAME|INDEX")]
    pub additive: Option<String>,
    /// The pose the additive animation is the difference from: its first frame or the rest pose.
    #[arg(long, value_parser = choice::<AdditiveReference>(), value_name = "REF", requires = "additive")]
    pub additive_ref: Option<AdditiveReference>,
    /// local: q_base·q_add (in the bone's frame); global: q_add·q_base (in the parent's frame).
    #[arg(long, value_parser = choice::<AdditiveOrder>(), value_name = "ORDER", requires = "additive")]
    pub additive_order: Option<AdditiveOrder>,
    /// How much of the additive animation to add (default 1).
    #[arg(long, value_name = "W", requires = "additive")]
    pub additive_weight: Option<f64>,
    /// Crossfade into another animation (name or index), which starts from its beginning.
    #[arg(long, value_name = "NAME|INDEX", requires_all = ["crossfade_at", "crossfade_duration"])]
    pub crossfade: Option<String>,
    /// When the crossfade starts, in seconds.
    #[arg(long, value_name = "SECONDS", requires = "crossfade", allow_negative_numbers = true)]
    pub crossfade_at: Option<f64>,
    /// How long the crossfade lasts, in seconds (0: a cut).
    #[arg(long, value_name = "SECONDS", requires = "crossfade")]
    pub crossfade_duration: Option<f64>,
    /// How the incoming animation's weight rises.
    #[arg(long, value_parser = choice::<FadeCurve>(), value_name = "CURVE", requires = "crossfade")]
    pub crossfade_curve: Option<FadeCurve>,
    /// Shake this bone and, growing per level, the bones below it: factor = cos(time·speed)·amplitude.
    #[arg(long, value_name = "BONE")]
    pub shake: Option<String>,
    /// Set a shake parameter (repeatable): speed (40), amplitude (0.3), attenuation (0.3), transx, transy (1),
    /// transz, rotx, roty (0.1), rotz, fade (0).
    #[arg(
        long,
        value_name = "NAME=VALUE",
        value_parser = parse_shake_param,
        requires = "shake",
        allow_negative_numbers = true
    )]
    pub shake_param: Vec<(String, f64)>,
    /// Replace this bone's local scale by its uniform part, the geometric mean of its factors' magnitudes, each
    /// sign kept (repeatable): what `explain` proposes for an ancestor whose squash shears the bones below it.
    #[arg(long, value_name = "BONE")]
    pub uniform_scale: Vec<String>,
    /// Pin a bone to a model-space rotation (quaternion x,y,z,w), with an optional weight (repeatable).
    #[arg(long, value_name = "BONE=x,y,z,w[@WEIGHT]", value_parser = parse_target, allow_negative_numbers = true)]
    pub target: Vec<TargetArg>,
}

/// `--target` before its bone is looked up.
#[derive(Clone, Debug, PartialEq)]
pub struct TargetArg {
    pub bone: String,
    pub rotation: DQuat,
    pub weight: f64,
}

/// The largest shake parameter: a factor (speed × amplitude, times a per-level modifier growing by the attenuation)
/// of a million per parameter is far beyond any shake, and keeps every shaken bone's matrix finite.
const MAX_SHAKE_PARAM: f64 = 1e6;

fn parse_shake_param(s: &str) -> Result<(String, f64), String> {
    let (name, value) = s.split_once('=').ok_or_else(|| format!("expected NAME=VALUE, got `{s}`"))?;
    let value: f64 = value.trim().parse().map_err(|_| format!("`{value}` is not a number"))?;
    if !value.is_finite() || value.abs() > MAX_SHAKE_PARAM {
        return Err(format!("{name} must be a number from -{MAX_SHAKE_PARAM:e} to {MAX_SHAKE_PARAM:e}, got {value:e}"));
    }
    Ok((name.trim().to_owned(), value))
}

fn parse_target(s: &str) -> Result<TargetArg, String> {
    let (bone, rest) = s.rsplit_once('=').ok_or_else(|| format!("expected BONE=x,y,z,w[@WEIGHT], got `{s}`"))?;
    let (rotation, weight) = rest.split_once('@').unwrap_or((rest, "1"));
    let numbers: Vec<f64> = rotation
        .split(',')
        .map(|n| n.trim().parse::<f64>().map_err(|_| format!("`{n}` is not a number")))
        .collect::<Result<_, _>>()?;
    let [x, y, z, w] = numbers[..] else {
        return Err(format!("expected four quaternion components x,y,z,w, got `{rotation}`"));
    };
    let rotation = DQuat::from_xyzw(x, y, z, w);
    if !rotation.is_finite() || rotation.length() == 0.0 {
        return Err(format!("the rotation `{rest}` is not a finite, non-zero quaternion"));
    }
    let weight = weight.trim().parse::<f64>().map_err(|_| format!("weight `{weight}` is not a number"))?;
    Ok(TargetArg { bone: bone.to_owned(), rotation: rotation.normalize(), weight })
}

impl LayerArgs {
    /// The layers these options describe for `rig`.
    pub fn layers(&self, rig: &Rig) -> anyhow::Result<Layers> {
        let mut layers = Layers {
            bind_weight: weight("--bind-weight", self.bind_weight.unwrap_or(1.0))?,
            interpolation: Resampling { keys: self.interp, rotation: self.rot_interp },
            ..Layers::default()
        };
        if let Some(name) = &self.blend {
            layers.blend = Some(Blend {
                clip: clip_index(rig, "--blend", name)?,
                weight: weight("--weight", self.weight.unwrap_or(0.0))?,
                sync: self.sync,
                rotation: self.blend_rotation.unwrap_or_default(),
            });
        }
        if let Some(name) = &self.additive {
            layers.additive = Some(Additive {
                clip: clip_index(rig, "--additive", name)?,
                reference: self.additive_ref.unwrap_or_default(),
                order: self.additive_order.unwrap_or_default(),
                weight: weight("--additive-weight", self.additive_weight.unwrap_or(1.0))?,
            });
        }
        if let Some(name) = &self.crossfade {
            let at = seconds("--crossfade-at", self.crossfade_at.unwrap_or(0.0))?;
            let duration = seconds("--crossfade-duration", self.crossfade_duration.unwrap_or(0.0))?;
            if duration < 0.0 {
                bail!("--crossfade-duration must not be negative, got {duration}");
            }
            let clip = clip_index(rig, "--crossfade", name)?;
            layers.crossfade = Some(Crossfade { clip, at, duration, curve: self.crossfade_curve.unwrap_or_default() });
        }
        if let Some(name) = &self.shake {
            let mut params = ShakeParams::default();
            for (param, value) in &self.shake_param {
                params.set(param, *value).context("--shake-param")?;
            }
            layers.shake = Some(Shake { bone: bone_index(rig, "--shake", name)?, params });
        }
        for name in &self.uniform_scale {
            layers.make_scale_uniform(bone_index(rig, "--uniform-scale", name)?);
        }
        for target in &self.target {
            layers.targets.push(Target {
                bone: bone_index(rig, "--target", &target.bone)?,
                rotation: target.rotation,
                weight: weight("--target weight", target.weight)?,
            });
        }
        Ok(layers)
    }
}

/// The bone named `name`, or with index `name`.
pub(super) fn bone_index(rig: &Rig, option: &str, name: &str) -> anyhow::Result<usize> {
    let skeleton = &rig.skeleton;
    skeleton
        .find(name)
        .or_else(|| name.parse::<usize>().ok().filter(|&i| i < skeleton.len()))
        .ok_or_else(|| anyhow!("{option}: no bone named `{name}` (the skeleton has {} bones)", skeleton.len()))
}

fn weight(option: &str, value: f64) -> anyhow::Result<f64> {
    if (0.0..=1.0).contains(&value) { Ok(value) } else { bail!("{option} must be between 0 and 1, got {value}") }
}

fn seconds(option: &str, value: f64) -> anyhow::Result<f64> {
    if value.is_finite() { Ok(value) } else { bail!("{option} must be a finite number of seconds, got {value}") }
}
