//! Skins (joints and inverse bind matrices) and the meshes they deform.

use glam::{DMat4, Vec3};

/// A set of joints with the inverse bind matrix of each.
#[derive(Clone, Debug, PartialEq)]
pub struct Skin {
    pub name: Option<String>,
    /// Bone index of each joint.
    pub joints: Vec<usize>,
    /// One per joint; the identity where the file gives none.
    pub inverse_bind: Vec<DMat4>,
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
    /// Per vertex, four indices into the skin's joint list (empty when not skinned).
    pub joints: Vec<[u16; 4]>,
    /// Per vertex, four weights matching `joints` (empty when not skinned).
    pub weights: Vec<[f32; 4]>,
    /// Triangle list.
    pub indices: Vec<u32>,
}
