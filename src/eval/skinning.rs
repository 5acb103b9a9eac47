//! CPU skinning: a mesh's vertex positions at an evaluated pose.
//!
//! Linear blend skinning, as glTF and FBX define it: the joint matrix of joint `j` is `W_j · IBM_j` (model matrix
//! of the joint's bone times its inverse bind matrix) and a vertex moves to `Σ w_j · (W_j · IBM_j) · v`. The
//! skinned mesh's own node does not move it (glTF: "the skinned mesh node's own transform MUST be ignored"). An
//! unskinned mesh is placed by its bone's model matrix.
//!
//! Pure functions over slices, in `f64`, so the viewport and the exporter share them.

use glam::{DMat4, DVec3};

use crate::model::{Mesh, Rig, Skin};

/// `W_j · IBM_j` for every joint of `skin`, from the model matrices of all bones.
pub fn joint_matrices(skin: &Skin, model: &[DMat4], out: &mut Vec<DMat4>) {
    out.clear();
    out.extend(skin.joints.iter().zip(&skin.inverse_bind).map(|(&bone, ibm)| model[bone] * *ibm));
}

/// The positions of `mesh` in model space, given the model matrices of all bones (`out` is reused).
///
/// Weights are used as stored (importers keep them normalised); joints whose weight is zero are skipped.
pub fn skin_positions(mesh: &Mesh, skins: &[Skin], model: &[DMat4], out: &mut Vec<DVec3>) {
    out.clear();
    let skin = mesh.skin.and_then(|s| skins.get(s)).filter(|_| mesh.joints.len() == mesh.positions.len());
    let Some(skin) = skin else {
        let placement = model[mesh.bone];
        out.extend(mesh.positions.iter().map(|p| placement.transform_point3(p.as_dvec3())));
        return;
    };
    let mut joints = Vec::with_capacity(skin.joints.len());
    joint_matrices(skin, model, &mut joints);
    for ((position, indices), weights) in mesh.positions.iter().zip(&mesh.joints).zip(&mesh.weights) {
        let v = position.as_dvec3();
        let mut sum = DVec3::ZERO;
        for (&joint, &weight) in indices.iter().zip(weights) {
            if weight != 0.0 {
                sum += joints[usize::from(joint)].transform_point3(v) * f64::from(weight);
            }
        }
        out.push(sum);
    }
}

/// Every mesh of the rig skinned at the pose `model` (one vector of positions per mesh).
pub fn skin_meshes(rig: &Rig, model: &[DMat4]) -> Vec<Vec<DVec3>> {
    rig.meshes
        .iter()
        .map(|mesh| {
            let mut out = Vec::new();
            skin_positions(mesh, &rig.skins, model, &mut out);
            out
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use glam::{DQuat, Vec3};

    use super::*;

    #[test]
    fn unskinned_meshes_follow_their_bone() {
        let mesh = Mesh { bone: 1, positions: vec![Vec3::new(1.0, 0.0, 0.0)], ..Mesh::default() };
        let model = [DMat4::IDENTITY, DMat4::from_translation(DVec3::new(0.0, 2.0, 0.0))];
        let mut out = Vec::new();
        skin_positions(&mesh, &[], &model, &mut out);
        assert_eq!(out, vec![DVec3::new(1.0, 2.0, 0.0)]);
    }

    #[test]
    fn linear_blend_of_two_joints() {
        // Joint 0: bone 0 moved +2 in X, bound at the origin. Joint 1: bone 1 turned 90° about Z, bound 1 up in Y.
        // v = (1, 1, 0): joint 0 gives (3, 1, 0); joint 1 gives Rz(90°)·(v − (0, 1, 0)) = Rz·(1, 0, 0) = (0, 1, 0).
        // Weights 0.25 / 0.75: (0.75, 0.25, 0) + (0, 0.75, 0) = (0.75, 1, 0).
        let skin = Skin {
            name: None,
            joints: vec![0, 1],
            inverse_bind: vec![DMat4::IDENTITY, DMat4::from_translation(DVec3::new(0.0, -1.0, 0.0))],
        };
        let mesh = Mesh {
            bone: 0,
            skin: Some(0),
            positions: vec![Vec3::new(1.0, 1.0, 0.0)],
            joints: vec![[0, 1, 0, 0]],
            weights: vec![[0.25, 0.75, 0.0, 0.0]],
            ..Mesh::default()
        };
        let model = [
            DMat4::from_translation(DVec3::new(2.0, 0.0, 0.0)),
            DMat4::from_quat(DQuat::from_rotation_z(std::f64::consts::FRAC_PI_2)),
        ];
        let mut out = Vec::new();
        skin_positions(&mesh, &[skin], &model, &mut out);
        assert!(out[0].abs_diff_eq(DVec3::new(0.75, 1.0, 0.0), 1e-12), "{:?}", out[0]);
    }
}
