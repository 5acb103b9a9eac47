//! The bind pose: where each joint was when the mesh was bound to the skeleton, read back from the
//! skin's inverse bind matrices.
//!
//! An inverse bind matrix maps model space to the joint's space *in the skin's bind space*, which need not be the
//! model space: a glTF skin may hang under a Z-up→Y-up node, an FBX mesh may be bound in centimetres under a 0.01
//! conversion, the mesh node may be moved. What holds at rest is that `S_j = W_j · IBM_j` (rest model matrix times
//! inverse bind matrix) is one matrix `S` for every joint of a skin: the bind-space-to-model transform. So the bind
//! pose in model space is `S · IBM_j⁻¹`, and a joint is bound elsewhere when its `S_j` differs from the skin's `S`.

use glam::DMat4;

use super::{Hierarchy, ModelPose};
use crate::math::decompose;
use crate::model::{Rig, Transform};

/// Per skin, its bind-space-to-model transform `S` at the rest pose `rest_model`: the entry-wise median of its
/// joints' `W_j · IBM_j`, so that a few joints bound elsewhere do not move it (when most joints agree, it is their
/// matrix exactly). The identity for a skin without joints.
pub fn skin_bind_spaces(rig: &Rig, rest_model: &[DMat4]) -> Vec<DMat4> {
    rig.skins
        .iter()
        .map(|skin| {
            let spaces = skin
                .joints
                .iter()
                .zip(&skin.inverse_bind)
                .filter_map(|(&joint, ibm)| Some(*rest_model.get(joint)? * *ibm));
            median(spaces).unwrap_or(DMat4::IDENTITY)
        })
        .collect()
}

/// The entry-wise median of the finite `matrices` (the upper one of an even count): their common value when most
/// agree, whatever the others hold; `None` when there is none.
pub(crate) fn median(matrices: impl Iterator<Item = DMat4>) -> Option<DMat4> {
    let entries: Vec<[f64; 16]> =
        matrices.map(|m| m.to_cols_array()).filter(|m| m.iter().all(|x| x.is_finite())).collect();
    if entries.is_empty() {
        return None;
    }
    let mut median = [0.0; 16];
    for (entry, out) in median.iter_mut().enumerate() {
        let mut values: Vec<f64> = entries.iter().map(|m| m[entry]).collect();
        values.sort_by(f64::total_cmp);
        *out = values[values.len() / 2];
    }
    Some(DMat4::from_cols_array(&median))
}

/// The rest pose's model matrices under the file's own modes.
pub fn rest_model_matrices(rig: &Rig) -> Vec<DMat4> {
    let mut rest = ModelPose::default();
    Hierarchy::declared(&rig.skeleton).evaluate(&rig.skeleton.rest_pose(), &mut rest);
    rest.model
}

/// Model matrices of the bind pose: `S · IBM⁻¹` for every joint (of the first skin that lists it, `S` that skin's
/// bind space at the file's rest pose); any other bone sits at its rest transform below its parent's bind matrix.
/// An inverse bind matrix that cannot be inverted counts as missing.
pub fn bind_model_matrices(rig: &Rig) -> Vec<DMat4> {
    let spaces = skin_bind_spaces(rig, &rest_model_matrices(rig));
    let bones = rig.skeleton.bones();
    let mut bound: Vec<Option<DMat4>> = vec![None; bones.len()];
    for (skin, space) in rig.skins.iter().zip(&spaces) {
        for (&joint, ibm) in skin.joints.iter().zip(&skin.inverse_bind) {
            if let Some(slot @ None) = bound.get_mut(joint) {
                *slot = invert(ibm).map(|bind| *space * bind);
            }
        }
    }
    let placement = rig.skeleton.placement().conversion;
    let mut model: Vec<DMat4> = Vec::with_capacity(bones.len());
    for (bone, bound) in bones.iter().zip(bound) {
        let below_parent = || bone.parent.map_or(placement, |p| model[p]) * bone.rest.matrix();
        model.push(bound.unwrap_or_else(below_parent));
    }
    model
}

/// The bind pose as local transforms, `B_parent⁻¹ · B` decomposed (exact under full inheritance; a shear is kept
/// in the stretch rotation, a mirror in the scale's sign). The rest pose for a rig without skins.
pub fn bind_pose(rig: &Rig) -> Vec<Transform> {
    let model = bind_model_matrices(rig);
    // A root's bind matrix stands in the file's unit and axes conversion, as its rest does.
    let placement_inverse = rig.skeleton.placement().conversion.inverse();
    rig.skeleton
        .bones()
        .iter()
        .zip(&model)
        .map(|(bone, m)| match bone.parent {
            None => decompose(&(placement_inverse * *m)).transform(),
            Some(p) => match invert(&model[p]) {
                Some(parent_inverse) => decompose(&(parent_inverse * *m)).transform(),
                None => bone.rest,
            },
        })
        .collect()
}

/// The inverse of an affine matrix, if it has a finite one.
pub(crate) fn invert(m: &DMat4) -> Option<DMat4> {
    let determinant = m.determinant();
    let inverse = m.inverse();
    (determinant != 0.0 && determinant.is_finite() && inverse.is_finite()).then_some(inverse)
}

#[cfg(test)]
mod tests {
    use glam::{DQuat, DVec3};

    use super::*;
    use crate::import::demo_rig;
    use crate::model::Skin;

    #[test]
    fn a_rig_bound_at_rest_has_its_rest_pose_as_bind_pose() {
        let rig = demo_rig();
        for (bind, rest) in bind_pose(&rig).iter().zip(rig.skeleton.rest_pose()) {
            assert!(bind.matrix().abs_diff_eq(rest.matrix(), 1e-12));
        }
    }

    #[test]
    fn inverse_bind_matrices_define_the_bind_pose() {
        let mut rig = demo_rig();
        // Bind the forearm (joint 1 of the skin, bone 2) turned 90° about Z at the elbow, (1, 1.5, 0) in model space.
        let elbow = DMat4::from_rotation_translation(DQuat::from_rotation_z(1.0), DVec3::new(1.0, 1.5, 0.0));
        rig.skins[0].inverse_bind[1] = elbow.inverse();
        let model = bind_model_matrices(&rig);
        assert!(model[2].abs_diff_eq(elbow, 1e-12));
        let pose = bind_pose(&rig);
        // Its parent (the upper arm) is bound at rest, at (0, 1.5, 0): the local bind is 1 along X, turned 1 rad.
        assert!(pose[2].translation.abs_diff_eq(DVec3::X, 1e-12));
        assert!(pose[2].rotation.abs_diff_eq(DQuat::from_rotation_z(1.0), 1e-12));
        // The hand (bone 3) is bound at rest relative to the model, so its local bind undoes the forearm's turn.
        assert!((model[2] * pose[3].matrix()).abs_diff_eq(model[3], 1e-12));
    }

    #[test]
    fn singular_inverse_bind_matrices_fall_back_to_the_rest_pose() {
        let mut rig = demo_rig();
        rig.skins.push(Skin {
            name: None,
            joints: vec![0, 77],
            inverse_bind: vec![DMat4::ZERO, DMat4::IDENTITY],
            node_bind: None,
        });
        rig.skins.swap(0, 1);
        let pose = bind_pose(&rig);
        assert!(pose.iter().all(|t| t.translation.is_finite() && t.rotation.is_finite()));
        assert_eq!(pose[0], rig.skeleton.bone(0).rest);
    }
}
