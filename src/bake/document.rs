//! The baked scene as plain data, before it is encoded: nodes with their default TRS, meshes, skins and
//! animations of sampled channels. [`super::glb`] turns it into a glTF binary.

use glam::DMat4;

pub use crate::model::Interpolation;
use crate::model::Mesh;

/// One glTF node.
#[derive(Clone, Debug, PartialEq)]
pub struct Node {
    pub name: String,
    pub parent: Option<usize>,
    pub translation: [f32; 3],
    /// A unit quaternion `[x, y, z, w]`.
    pub rotation: [f32; 4],
    pub scale: [f32; 3],
    /// Index into [`GltfDocument::meshes`].
    pub mesh: Option<usize>,
    /// Index into [`GltfDocument::skins`].
    pub skin: Option<usize>,
}

impl Node {
    /// A node with the identity transform, no mesh and no name.
    pub fn identity(parent: Option<usize>) -> Self {
        Node {
            name: String::new(),
            parent,
            translation: [0.0; 3],
            rotation: [0.0, 0.0, 0.0, 1.0],
            scale: [1.0; 3],
            mesh: None,
            skin: None,
        }
    }
}

/// One glTF mesh: the source meshes that become its primitives (one node shows one mesh).
#[derive(Clone, Debug)]
pub struct MeshGroup<'a> {
    pub name: String,
    pub primitives: Vec<&'a Mesh>,
    /// The default morph-target weights (one per target; every primitive has as many targets).
    pub weights: Vec<f32>,
}

/// One glTF skin.
#[derive(Clone, Debug, PartialEq)]
pub struct SkinOut {
    pub name: Option<String>,
    /// Node indices.
    pub joints: Vec<usize>,
    pub inverse_bind: Vec<DMat4>,
    /// For each joint of the source skin, its index here (joints no vertex uses are left out).
    pub joint_map: Vec<u16>,
}

/// What a channel animates.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Property {
    Translation,
    Rotation,
    Scale,
    /// The morph-target weights of the node's mesh.
    Weights,
}

/// Keys of one property of one node.
#[derive(Clone, Debug, PartialEq)]
pub struct Channel {
    pub node: usize,
    pub property: Property,
    /// Linear (slerp for rotations) or step; never cubic.
    pub interpolation: Interpolation,
    /// Strictly increasing.
    pub times: Vec<f32>,
    /// `times.len() × width` numbers.
    pub values: Vec<f32>,
}

/// One glTF animation.
#[derive(Clone, Debug, PartialEq)]
pub struct Animation {
    pub name: String,
    pub channels: Vec<Channel>,
}

/// The whole baked scene.
#[derive(Clone, Debug, Default)]
pub struct GltfDocument<'a> {
    pub nodes: Vec<Node>,
    pub meshes: Vec<MeshGroup<'a>>,
    pub skins: Vec<SkinOut>,
    pub animations: Vec<Animation>,
    /// Written as the asset's generator.
    pub generator: String,
}
