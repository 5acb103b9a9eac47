//! Uniform scale: a bone's local scale replaced by its uniform part, what `explain` proposes when one bone's
//! squash shears the bones below it.
//!
//! The uniform part of a scale `(k₁, k₂, k₃)` keeps the volume and each axis's sign: `g = ∛|k₁·k₂·k₃|`, giving
//! `(sign k₁·g, sign k₂·g, sign k₃·g)`. Its stretch rotation no longer matters (every frame of a uniform scale is
//! the same), so it is reset. A mirrored bone stays mirrored, and a bone scaled to nothing along one axis stays a
//! point (`g = 0`).

use glam::{DQuat, DVec3};

use crate::model::Transform;

/// The uniform part of `scale`: the geometric mean of the magnitudes, each component's sign kept.
pub fn uniform_part(scale: DVec3) -> DVec3 {
    let mean = (scale.x * scale.y * scale.z).abs().cbrt();
    DVec3::new(mean.copysign(scale.x), mean.copysign(scale.y), mean.copysign(scale.z))
}

/// `local` with its scale made uniform ([`uniform_part`]) and no stretch rotation.
pub fn uniform_scale(local: &mut Transform) {
    local.scale = uniform_part(local.scale);
    local.stretch = DQuat::IDENTITY;
}

/// Makes the local scale of each of `bones` uniform in `pose` (bones past its end are left out).
pub fn uniform_pose(pose: &mut [Transform], bones: &[usize]) {
    for &bone in bones {
        if let Some(local) = pose.get_mut(bone) {
            uniform_scale(local);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_uniform_part_keeps_volume_and_signs() {
        // (2, 1, 0.5) has volume 1: the uniform part is 1 on every axis. (−8, 1, 1): ∛8 = 2, the X sign kept.
        assert_eq!(uniform_part(DVec3::new(2.0, 1.0, 0.5)), DVec3::ONE);
        assert_eq!(uniform_part(DVec3::new(-8.0, 1.0, 1.0)), DVec3::new(-2.0, 2.0, 2.0));
        assert_eq!(uniform_part(DVec3::new(3.0, 0.0, 1.0)), DVec3::ZERO);
        let scale = DVec3::new(1.3, 0.8, 1.1);
        let uniform = uniform_part(scale);
        assert!((uniform.x.powi(3) - scale.x * scale.y * scale.z).abs() < 1e-15);
        assert!(uniform.x == uniform.y && uniform.y == uniform.z);
    }

    #[test]
    fn a_uniform_bone_loses_its_stretch_and_keeps_the_rest() {
        let stretch = DQuat::from_rotation_y(0.4);
        let mut local = Transform { scale: DVec3::new(2.0, 2.0, 2.0), stretch, ..Transform::IDENTITY };
        local.translation = DVec3::new(1.0, 2.0, 3.0);
        let mut pose = vec![local, local];
        uniform_pose(&mut pose, &[1, 7]);
        assert_eq!(pose[0], local, "other bones stay as they were");
        assert_eq!(pose[1], Transform { stretch: DQuat::IDENTITY, ..local });
    }
}
