//! World-space targets: a bone pinned to a model-space rotation, as a ragdoll's physics or a hand on a
//! ledge asks, by setting its local rotation to `inverse(parent model rotation) · target`.
//!
//! The parent's model rotation is that of the rigid chain of local rotations from the root (the joints' rotation
//! quaternions; scale plays no part), with every target above it already applied. A weight tweens between the
//! animated rotation (0) and the target (1) by slerp, so a bone can move in and out of the constraint.

use glam::DQuat;

use crate::math::slerp;
use crate::model::{Skeleton, Transform};

/// Pin bone `bone` to the model-space rotation `rotation` with weight `weight` in `[0, 1]`.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Target {
    pub bone: usize,
    /// `[x, y, z, w]`; normalised when applied (a zero quaternion counts as the identity).
    pub rotation: DQuat,
    pub weight: f64,
}

/// Applies `targets` (sorted by bone) to `pose`. `chain` is a reusable buffer for the model rotations.
pub fn pin_pose(skeleton: &Skeleton, pose: &mut [Transform], targets: &[Target], chain: &mut Vec<DQuat>) {
    let Some(last) = targets.iter().map(|t| t.bone).max() else {
        return;
    };
    debug_assert!(targets.is_sorted_by_key(|t| t.bone));
    chain.clear();
    let mut pending = targets.iter().peekable();
    for (index, (bone, local)) in skeleton.bones().iter().zip(pose.iter_mut()).enumerate().take(last + 1) {
        let parent = bone.parent.map_or(DQuat::IDENTITY, |p| chain[p]);
        while let Some(target) = pending.next_if(|t| t.bone == index) {
            let pinned = parent.inverse() * unit(target.rotation);
            local.rotation = match super::unit_weight(target.weight) {
                0.0 => local.rotation,
                1.0 => pinned,
                w => slerp(local.rotation, pinned, w),
            };
        }
        chain.push(parent * local.rotation);
    }
}

fn unit(q: DQuat) -> DQuat {
    let length = q.length();
    if length > 0.0 && length.is_finite() { q / length } else { DQuat::IDENTITY }
}

#[cfg(test)]
mod tests {
    use std::f64::consts::FRAC_PI_2;

    use glam::DVec3;

    use super::*;
    use crate::model::{Bone, InheritMode, NodeRole};

    fn arm() -> Skeleton {
        let bone = |parent, rotation| Bone {
            name: String::new(),
            node: 0,
            parent,
            rest: Transform::from_trs(DVec3::X, rotation, DVec3::ONE),
            inherit: InheritMode::Full,
            role: NodeRole::Joint,
        };
        Skeleton::new(vec![
            bone(None, DQuat::from_rotation_z(FRAC_PI_2)),
            bone(Some(0), DQuat::from_rotation_x(0.3)),
            bone(Some(1), DQuat::from_rotation_y(0.2)),
        ])
        .unwrap()
    }

    #[test]
    fn a_pinned_bone_has_the_target_as_model_rotation() {
        let skeleton = arm();
        let mut pose = skeleton.rest_pose();
        let target = DQuat::from_rotation_y(1.0);
        let mut chain = Vec::new();
        pin_pose(&skeleton, &mut pose, &[Target { bone: 1, rotation: target, weight: 1.0 }], &mut chain);
        // local = Rz(90°)⁻¹ · target, so parent · local = target.
        assert!(pose[1].rotation.abs_diff_eq(DQuat::from_rotation_z(-FRAC_PI_2) * target, 1e-15));
        assert!(chain[1].abs_diff_eq(target, 1e-15));
        // The child keeps its local rotation and follows its pinned parent.
        assert_eq!(pose[2].rotation, DQuat::from_rotation_y(0.2));
        assert!((chain[1] * pose[2].rotation).abs_diff_eq(target * DQuat::from_rotation_y(0.2), 1e-15));
    }

    #[test]
    fn the_weight_tweens_from_the_animation_to_the_target() {
        let skeleton = arm();
        let mut pose = skeleton.rest_pose();
        let mut chain = Vec::new();
        // Root: parent is the identity, so the pinned local rotation is the target itself; half way from
        // Rz(90°) to Rz(30°) is Rz(60°).
        let target = Target { bone: 0, rotation: DQuat::from_rotation_z(FRAC_PI_2 / 3.0), weight: 0.5 };
        pin_pose(&skeleton, &mut pose, &[target], &mut chain);
        assert!(pose[0].rotation.abs_diff_eq(DQuat::from_rotation_z(FRAC_PI_2 * 2.0 / 3.0), 1e-15));
        // Weight 0 and an empty list change nothing; a zero quaternion is the identity target.
        let mut rest = skeleton.rest_pose();
        pin_pose(&skeleton, &mut rest, &[Target { weight: 0.0, ..target }], &mut chain);
        pin_pose(&skeleton, &mut rest, &[], &mut chain);
        assert_eq!(rest, skeleton.rest_pose());
        let zero = Target { bone: 0, rotation: DQuat::from_xyzw(0.0, 0.0, 0.0, 0.0), weight: 1.0 };
        pin_pose(&skeleton, &mut rest, &[zero], &mut chain);
        assert_eq!(rest[0].rotation, DQuat::IDENTITY);
    }
}
