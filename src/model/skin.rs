//! Skins (joints and inverse bind matrices) and the meshes they deform.

use glam::{DMat4, Vec3};

/// A set of joints with the inverse bind matrix of each.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct Skin {
    pub name: Option<String>,
    /// Bone index of each joint.
    pub joints: Vec<usize>,
    /// One per joint; the identity where the file gives none.
    pub inverse_bind: Vec<DMat4>,
    /// Where the skinned result also follows its mesh's node (Maya), that node and its bind; `None` where the node
    /// does not move the result (glTF, which says so, and the FBX SDK's own evaluation).
    pub node_bind: Option<NodeBind>,
}

/// How a skin's result follows the mesh node it is on, as Maya shows it: the skin cluster deforms the mesh as it
/// was bound, and the mesh node's transform since the bind then moves the result, i.e. every joint matrix is
/// premultiplied by `W_node · inverse_bind` (the identity while the node stays where it was bound).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NodeBind {
    /// The bone (node) the mesh is on.
    pub bone: usize,
    /// The geometric transform times the inverse of the node's model matrix at bind.
    pub inverse_bind: DMat4,
}

/// A triangle mesh attached to a bone, optionally skinned (linear blend skinning, four influences per vertex).
#[derive(Clone, Debug, PartialEq, Default)]
pub struct Mesh {
    pub name: String,
    /// The bone (node) the mesh hangs on; its model matrix places an unskinned mesh.
    pub bone: usize,
    /// Index into `Rig::skins`.
    pub skin: Option<usize>,
    pub positions: Vec<Vec3>,
    /// Per vertex, the normal the file gives (empty where it gives none, or none per vertex).
    pub normals: Vec<Vec3>,
    /// Per vertex, four indices into the skin's joint list (empty when not skinned).
    pub joints: Vec<[u16; 4]>,
    /// Per vertex, four weights matching `joints` (empty when not skinned).
    pub weights: Vec<[f32; 4]>,
    /// Per vertex, how far it is skinned with dual quaternions rather than linearly (FBX's skinning method and
    /// blend weights: 0 linear, 1 dual quaternion); empty when the whole mesh is skinned linearly.
    pub dq_weights: Vec<f32>,
    /// Morph targets (blend shapes), added to the positions with their weights before skinning.
    pub morph_targets: Vec<MorphTarget>,
    /// One per morph target: the weights when no clip animates them (glTF's default weights, FBX's stored ones).
    pub morph_weights: Vec<f32>,
    /// Triangle list.
    pub indices: Vec<u32>,
}

/// One morph target: a displacement of every vertex, applied with a weight.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct MorphTarget {
    pub name: String,
    /// One per vertex of the mesh.
    pub offsets: Vec<Vec3>,
}

/// How far the weights of a vertex may sum from 1 before they count as not normalised (a few `f32` roundings of
/// four numbers stay well inside it).
pub const WEIGHT_SUM_TOLERANCE: f32 = 1e-5;

/// The weights divided by their sum, when that sum is positive and further from 1 than [`WEIGHT_SUM_TOLERANCE`];
/// `None` for weights that need nothing (or cannot be helped: all zero).
pub fn normalized_weights(weights: [f32; 4]) -> Option<[f32; 4]> {
    let total: f32 = weights.iter().sum();
    ((total - 1.0).abs() > WEIGHT_SUM_TOLERANCE && total > 0.0 && total.is_finite()).then(|| weights.map(|w| w / total))
}

impl Mesh {
    /// Makes every vertex's skin weights sum to 1 (glTF requires it, DCCs do it, engines do it when a file does not);
    /// how many vertices changed.
    pub fn normalize_weights(&mut self) -> usize {
        let mut changed = 0;
        for weights in &mut self.weights {
            if let Some(normalized) = normalized_weights(*weights) {
                *weights = normalized;
                changed += 1;
            }
        }
        changed
    }

    /// Removes the vertices whose position, skin weights or morph displacements are not finite (NaN or infinite: a
    /// broken export), with their skinning and every triangle that uses one, so the rest can be skinned and drawn;
    /// how many were removed.
    pub fn remove_non_finite_vertices(&mut self) -> usize {
        let finite = |v: usize| {
            self.positions[v].is_finite()
                && self.weights.get(v).is_none_or(|w| w.iter().all(|x| x.is_finite()))
                && self.morph_targets.iter().all(|t| t.offsets.get(v).is_none_or(|o| o.is_finite()))
        };
        let keep: Vec<bool> = (0..self.positions.len()).map(finite).collect();
        let removed = keep.iter().filter(|&&k| !k).count();
        if removed == 0 {
            return 0;
        }
        let mut new_index = Vec::with_capacity(keep.len());
        let mut next = 0u32;
        for &k in &keep {
            new_index.push(next);
            next += u32::from(k);
        }
        retain_kept(&mut self.positions, &keep);
        retain_kept(&mut self.normals, &keep);
        retain_kept(&mut self.joints, &keep);
        retain_kept(&mut self.weights, &keep);
        retain_kept(&mut self.dq_weights, &keep);
        for target in &mut self.morph_targets {
            retain_kept(&mut target.offsets, &keep);
        }
        let kept = |i: &u32| keep.get(*i as usize).copied().unwrap_or(false);
        self.indices = self
            .indices
            .chunks_exact(3)
            .filter(|triangle| triangle.iter().all(kept))
            .flat_map(|triangle| triangle.iter().map(|&i| new_index[i as usize]))
            .collect();
        removed
    }
}

/// Keeps the elements whose `keep` flag is set (a per-vertex array may be empty: then nothing to do).
fn retain_kept<T>(values: &mut Vec<T>, keep: &[bool]) {
    if values.len() == keep.len() {
        let mut flags = keep.iter();
        values.retain(|_| flags.next().copied().unwrap_or(false));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn weights_are_normalised_only_when_off() {
        let mut mesh = Mesh {
            weights: vec![[0.5, 0.25, 0.0, 0.0], [0.5, 0.5, 0.0, 0.0], [0.25, 0.25, 0.25, 0.250001], [0.0; 4]],
            ..Mesh::default()
        };
        assert_eq!(mesh.normalize_weights(), 1);
        assert_eq!(mesh.weights[0], [2.0 / 3.0, 1.0 / 3.0, 0.0, 0.0]);
        assert_eq!(mesh.weights[2], [0.25, 0.25, 0.25, 0.250001], "within the tolerance: as stored");
        assert_eq!(mesh.weights[3], [0.0; 4], "nothing to divide");
    }

    #[test]
    fn non_finite_vertices_leave_with_their_triangles() {
        let mut mesh = Mesh {
            positions: vec![Vec3::ZERO, Vec3::NAN, Vec3::X, Vec3::Y, Vec3::new(f32::INFINITY, 0.0, 0.0)],
            joints: vec![[0; 4], [1; 4], [2; 4], [3; 4], [4; 4]],
            weights: vec![[1.0, 0.0, 0.0, 0.0]; 5],
            indices: vec![0, 2, 3, 0, 1, 2, 3, 2, 4, 3, 2, 0],
            ..Mesh::default()
        };
        assert_eq!(mesh.remove_non_finite_vertices(), 2);
        assert_eq!(mesh.positions, [Vec3::ZERO, Vec3::X, Vec3::Y]);
        assert_eq!(mesh.joints, [[0; 4], [2; 4], [3; 4]]);
        assert_eq!(mesh.weights.len(), 3);
        assert_eq!(mesh.indices, [0, 1, 2, 2, 1, 0], "the triangles without a bad vertex, renumbered");
        assert_eq!(mesh.remove_non_finite_vertices(), 0);
    }
}
