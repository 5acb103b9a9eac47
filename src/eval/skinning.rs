//! CPU linear blend skinning: `v' = Σ wᵢ · W(jointᵢ) · IBM(jointᵢ) · v` (glTF's skinning rule).

use glam::{DMat4, DVec3};

use crate::model::{Mesh, Rig};

/// Each mesh's vertex positions in model space for the given model matrices (one per bone): skinned meshes by
/// their joints, others by their node's matrix.
pub fn skin_meshes(rig: &Rig, model: &[DMat4]) -> Vec<Vec<DVec3>> {
    rig.meshes.iter().map(|mesh| skin_mesh(rig, mesh, model)).collect()
}

/// One mesh's vertex positions in model space.
pub fn skin_mesh(rig: &Rig, mesh: &Mesh, model: &[DMat4]) -> Vec<DVec3> {
    let skin = mesh.skin.and_then(|s| rig.skins.get(s)).filter(|_| mesh.joints.len() == mesh.positions.len());
    let Some(skin) = skin else {
        let node = model.get(mesh.bone).copied().unwrap_or(DMat4::IDENTITY);
        return mesh.positions.iter().map(|p| node.transform_point3(p.as_dvec3())).collect();
    };
    let joint_matrices: Vec<DMat4> =
        skin.joints.iter().zip(&skin.inverse_bind).map(|(&bone, ibm)| model[bone] * *ibm).collect();
    mesh.positions
        .iter()
        .zip(&mesh.joints)
        .zip(&mesh.weights)
        .map(|((p, joints), weights)| {
            let blended = joints.iter().zip(weights).fold(DMat4::ZERO, |sum, (&j, &w)| {
                match joint_matrices.get(usize::from(j)) {
                    Some(m) if w != 0.0 => sum + *m * f64::from(w),
                    _ => sum,
                }
            });
            blended.transform_point3(p.as_dvec3())
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use glam::{DQuat, Vec3};

    use super::*;
    use crate::model::Skin;

    #[test]
    fn blends_joint_matrices_by_weight() {
        // Two joints bound at rest (IBM = identity); joint 1 moves up by 2: a half-half vertex moves up by 1.
        let mut rig = Rig::default();
        rig.skins.push(Skin { name: None, joints: vec![0, 1], inverse_bind: vec![DMat4::IDENTITY; 2] });
        let mesh = Mesh {
            name: "m".into(),
            bone: 0,
            skin: Some(0),
            positions: vec![Vec3::X, Vec3::X],
            joints: vec![[0, 1, 0, 0], [1, 0, 0, 0]],
            weights: vec![[0.5, 0.5, 0.0, 0.0], [1.0, 0.0, 0.0, 0.0]],
            indices: vec![],
        };
        let model = [DMat4::IDENTITY, DMat4::from_translation(DVec3::Y * 2.0)];
        let skinned = skin_mesh(&rig, &mesh, &model);
        assert!(skinned[0].abs_diff_eq(DVec3::new(1.0, 1.0, 0.0), 1e-12));
        assert!(skinned[1].abs_diff_eq(DVec3::new(1.0, 2.0, 0.0), 1e-12));
    }

    #[test]
    fn unskinned_meshes_follow_their_node() {
        let rig = Rig::default();
        let mesh = Mesh { name: "m".into(), bone: 0, positions: vec![Vec3::X], ..Mesh::default() };
        let model = [DMat4::from_quat(DQuat::from_rotation_z(std::f64::consts::FRAC_PI_2))];
        assert!(skin_mesh(&rig, &mesh, &model)[0].abs_diff_eq(DVec3::Y, 1e-12));
    }
}
