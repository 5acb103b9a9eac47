//! Procedural shake: a cosine wobble added to a bone and, growing level by level, to the bones below it
//! (the snowboarder's arms shaking on harsh snow).
//!
//! The recipe, with its parameters' names: `factor = cos(time·speed)·amplitude`; a bone modifier that starts at 1 on
//! the chosen bone and grows by `attenuation` for every hierarchy level below it (while above 0.1, never below
//! 0); `factor·modifier·(1 − fade)` scales a translation `(transx, transy, transz)` and a rotation of
//! `(rotx, roty, rotz)` radians (Euler XYZ). Here the translation is added to the bone's local translation (in its
//! parent's frame) and the rotation turns the bone in its own frame, after its animated rotation.

use glam::{DQuat, DVec3, EulerRot};

use crate::model::{Skeleton, Transform};

/// The shake's parameters, with the recipe's defaults: speed 40, amplitude 0.3, attenuation 0.3, translation
/// (0, 1, 0), rotation (0, 0.1, 0) radians, fade 0.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct ShakeParams {
    /// Angular speed of the cosine, radians per second.
    pub speed: f64,
    pub amplitude: f64,
    /// Added to the bone modifier for each level below the chosen bone.
    pub attenuation: f64,
    /// `(transx, transy, transz)`.
    pub translation: DVec3,
    /// `(rotx, roty, rotz)`, radians.
    pub rotation: DVec3,
    /// 0: full shake; 1: none (what a runtime moves to fade the shake in and out).
    pub fade: f64,
}

impl Default for ShakeParams {
    fn default() -> Self {
        ShakeParams {
            speed: 40.0,
            amplitude: 0.3,
            attenuation: 0.3,
            translation: DVec3::new(0.0, 1.0, 0.0),
            rotation: DVec3::new(0.0, 0.1, 0.0),
            fade: 0.0,
        }
    }
}

/// A parameter name that is not one of [`ShakeParams::NAMES`].
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("no shake parameter `{0}` (known: {names})", names = ShakeParams::NAMES.join(", "))]
pub struct UnknownShakeParam(pub String);

impl ShakeParams {
    /// The names [`ShakeParams::set`] knows, the recipe's own.
    pub const NAMES: [&str; 10] =
        ["speed", "amplitude", "attenuation", "transx", "transy", "transz", "rotx", "roty", "rotz", "fade"];

    /// Sets one parameter by name (case-insensitive).
    pub fn set(&mut self, name: &str, value: f64) -> Result<(), UnknownShakeParam> {
        let slot = match name.to_ascii_lowercase().as_str() {
            "speed" => &mut self.speed,
            "amplitude" => &mut self.amplitude,
            "attenuation" => &mut self.attenuation,
            "transx" => &mut self.translation.x,
            "transy" => &mut self.translation.y,
            "transz" => &mut self.translation.z,
            "rotx" => &mut self.rotation.x,
            "roty" => &mut self.rotation.y,
            "rotz" => &mut self.rotation.z,
            "fade" => &mut self.fade,
            _ => return Err(UnknownShakeParam(name.to_owned())),
        };
        *slot = value;
        Ok(())
    }

    /// `cos(time·speed)·amplitude`.
    pub fn factor(&self, time: f64) -> f64 {
        (time * self.speed).cos() * self.amplitude
    }
}

/// A shake on the bone `bone` and everything below it.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Shake {
    pub bone: usize,
    pub params: ShakeParams,
}

/// The bone modifier of every bone: 1 on `bone`, then per level below it `m + attenuation` while `m > 0.1`,
/// never below 0; 0 outside `bone`'s subtree.
pub fn bone_modifiers(skeleton: &Skeleton, bone: usize, attenuation: f64) -> Vec<f64> {
    let mut modifiers: Vec<Option<f64>> = Vec::with_capacity(skeleton.len());
    for (index, b) in skeleton.bones().iter().enumerate() {
        let below = b.parent.and_then(|p| modifiers[p]).map(|m| if m > 0.1 { m + attenuation } else { m }.max(0.0));
        modifiers.push(if index == bone { Some(1.0) } else { below });
    }
    modifiers.into_iter().map(|m| m.unwrap_or(0.0)).collect()
}

/// Adds the shake at `time` to every bone with a non-zero modifier.
pub fn shake_pose(pose: &mut [Transform], modifiers: &[f64], params: &ShakeParams, time: f64) {
    let factor = params.factor(time) * (1.0 - super::unit_weight(params.fade));
    if factor == 0.0 || !factor.is_finite() {
        return;
    }
    for (local, &modifier) in pose.iter_mut().zip(modifiers) {
        if modifier != 0.0 {
            let f = factor * modifier;
            let turn = params.rotation * f;
            local.translation += params.translation * f;
            local.rotation *= DQuat::from_euler(EulerRot::XYZ, turn.x, turn.y, turn.z);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::{Bone, InheritMode, NodeRole};

    fn chain() -> Skeleton {
        let bone = |parent| Bone {
            name: String::new(),
            node: 0,
            parent,
            rest: Transform::IDENTITY,
            inherit: InheritMode::Full,
            role: NodeRole::Joint,
        };
        Skeleton::new(vec![bone(None), bone(Some(0)), bone(Some(1)), bone(Some(2)), bone(Some(0))]).unwrap()
    }

    #[test]
    fn modifiers_grow_by_the_attenuation_per_level() {
        let m = bone_modifiers(&chain(), 1, 0.3);
        assert_eq!(m[0], 0.0, "above the chosen bone");
        assert_eq!(m[4], 0.0, "beside it");
        assert_eq!(m[1], 1.0);
        assert!((m[2] - 1.3).abs() < 1e-15 && (m[3] - 1.6).abs() < 1e-15);
        // A negative attenuation shrinks the modifier until it is at most 0.1, then it stays; never below 0.
        let m = bone_modifiers(&chain(), 0, -0.9375);
        assert_eq!([m[1], m[2], m[3]], [0.0625; 3]);
        let m = bone_modifiers(&chain(), 0, -0.4);
        assert_eq!([m[1], m[2], m[3]], [0.6, 0.19999999999999996, 0.0]);
        assert_eq!(bone_modifiers(&chain(), 0, -2.0)[1], 0.0);
        assert!(bone_modifiers(&chain(), 99, 0.3).iter().all(|&m| m == 0.0), "an unknown bone shakes nothing");
    }

    #[test]
    fn the_seeds_defaults_at_a_known_time() {
        let params = ShakeParams::default();
        // t = 0: factor = cos 0 · 0.3 = 0.3. Level 1 below the bone (modifier 1.3): f = 0.39:
        // translation + (0, 0.39, 0), rotation by 0.039 rad about Y.
        assert_eq!(params.factor(0.0), 0.3);
        let mut pose = [Transform::IDENTITY; 5];
        shake_pose(&mut pose, &bone_modifiers(&chain(), 1, params.attenuation), &params, 0.0);
        assert_eq!(pose[0], Transform::IDENTITY);
        assert!(pose[2].translation.abs_diff_eq(DVec3::new(0.0, 0.39, 0.0), 1e-15));
        assert!(pose[2].rotation.abs_diff_eq(DQuat::from_rotation_y(0.039), 1e-15));
        // t = π/80: cos(π/2) = 0, no shake at all; fade 1 silences it too.
        assert!(params.factor(std::f64::consts::PI / 80.0).abs() < 1e-15);
        let mut faded = [Transform::IDENTITY; 5];
        shake_pose(&mut faded, &[1.0; 5], &ShakeParams { fade: 1.0, ..params }, 0.0);
        assert_eq!(faded, [Transform::IDENTITY; 5]);
    }

    #[test]
    fn parameters_by_the_seeds_names() {
        let mut params = ShakeParams::default();
        params.set("RotZ", 0.5).unwrap();
        params.set("transx", 2.0).unwrap();
        assert_eq!((params.rotation.z, params.translation.x), (0.5, 2.0));
        let error = params.set("wobble", 1.0).unwrap_err();
        assert!(error.to_string().contains("known: speed, amplitude"), "{error}");
    }
}
