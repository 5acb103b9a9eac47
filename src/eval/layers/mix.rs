//! Mixing two local poses bone by bone: the weighted blend behind the bind weight, the two-clip blend, the
//! crossfade and the targets.

use glam::DQuat;

use crate::math::{nlerp, slerp};
use crate::model::{Choice, Transform};

/// How rotations are mixed: slerp (constant angular speed) or nlerp (cheaper, speeds up mid-way); both take the
/// shortest path.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum RotationBlend {
    #[default]
    Slerp,
    Nlerp,
}

impl Choice for RotationBlend {
    const ALL: &'static [RotationBlend] = &[RotationBlend::Slerp, RotationBlend::Nlerp];

    fn id(self) -> &'static str {
        match self {
            RotationBlend::Slerp => "slerp",
            RotationBlend::Nlerp => "nlerp",
        }
    }

    fn description(self) -> &'static str {
        match self {
            RotationBlend::Slerp => "constant angular speed",
            RotationBlend::Nlerp => "quaternion components mixed, then normalised",
        }
    }
}

impl RotationBlend {
    pub fn mix(self, a: DQuat, b: DQuat, t: f64) -> DQuat {
        match self {
            RotationBlend::Slerp => slerp(a, b, t),
            RotationBlend::Nlerp => nlerp(a, b, t),
        }
    }
}

/// A weight clamped to `[0, 1]`; NaN counts as 0 (the layer does nothing).
pub fn unit_weight(w: f64) -> f64 {
    if w.is_nan() { 0.0 } else { w.clamp(0.0, 1.0) }
}

/// `a` at weight 0, `b` at weight 1: translation and scale linearly, rotation (and a stretch rotation, where the
/// two differ) by `rotation`.
pub fn mix(a: &Transform, b: &Transform, w: f64, rotation: RotationBlend) -> Transform {
    Transform {
        translation: a.translation.lerp(b.translation, w),
        rotation: rotation.mix(a.rotation, b.rotation, w),
        scale: a.scale.lerp(b.scale, w),
        // Equal stretches stay bit-identical, so TRS bones keep their exact identity (and the fast matrix path).
        stretch: if a.stretch == b.stretch { a.stretch } else { rotation.mix(a.stretch, b.stretch, w) },
    }
}

/// Mixes `other` into `pose` with weight `w` (clamped): nothing at 0, a copy at 1.
pub fn mix_poses(pose: &mut [Transform], other: &[Transform], w: f64, rotation: RotationBlend) {
    let w = unit_weight(w);
    if w == 0.0 {
        return;
    }
    for (a, b) in pose.iter_mut().zip(other) {
        *a = if w == 1.0 { *b } else { mix(a, b, w, rotation) };
    }
}

#[cfg(test)]
mod tests {
    use glam::DVec3;

    use super::*;

    #[test]
    fn weights_are_clamped_and_nan_is_off() {
        assert_eq!(
            [unit_weight(-1.0), unit_weight(0.3), unit_weight(2.0), unit_weight(f64::NAN)],
            [0.0, 0.3, 1.0, 0.0]
        );
    }

    #[test]
    fn mixing_interpolates_each_part() {
        let a = Transform::from_trs(DVec3::ZERO, DQuat::from_rotation_y(0.0), DVec3::ONE);
        let b = Transform::from_trs(DVec3::new(4.0, 0.0, 0.0), DQuat::from_rotation_y(1.0), DVec3::splat(3.0));
        for rotation in [RotationBlend::Slerp, RotationBlend::Nlerp] {
            let m = mix(&a, &b, 0.25, rotation);
            assert_eq!(m.translation, DVec3::new(1.0, 0.0, 0.0));
            assert_eq!(m.scale, DVec3::splat(1.5));
            assert_eq!(m.stretch, DQuat::IDENTITY);
        }
        // Slerp turns a quarter of the angle. Nlerp of a 1 rad turn at t = 0.25 turns by twice
        // atan2(0.25·sin 0.5, 0.75 + 0.25·cos 0.5).
        assert!(mix(&a, &b, 0.25, RotationBlend::Slerp).rotation.abs_diff_eq(DQuat::from_rotation_y(0.25), 1e-15));
        let half = (0.25 * 0.5f64.sin()).atan2(0.75 + 0.25 * 0.5f64.cos());
        let nlerped = mix(&a, &b, 0.25, RotationBlend::Nlerp).rotation;
        assert!(nlerped.abs_diff_eq(DQuat::from_rotation_y(2.0 * half), 1e-15), "{nlerped:?}");
        let mut pose = [a];
        mix_poses(&mut pose, &[b], 1.0, RotationBlend::Slerp);
        assert_eq!(pose[0], b);
        mix_poses(&mut pose, &[a], f64::NAN, RotationBlend::Slerp);
        assert_eq!(pose[0], b);
    }
}
