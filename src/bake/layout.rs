//! Which glTF node each bone becomes: a helper node `<bone>.stretch` and the bone's own node for a bone that needs
//! its stretch rotation, one node for any other; where meshes hang (on their bone's node, primitives of one glTF mesh
//! where they can share it); and the document's nodes, meshes and skins with the rest pose as default TRS.

use glam::DQuat;

use super::document::{GltfDocument, MeshGroup, Node};
use super::nodes::{NodeSample, under_conversion};
use super::skins::{common_root, skins, unique_name};
use crate::diff::HELPER_SUFFIX;
use crate::math::decompose;
use crate::model::{Mesh, Rig};

/// Which glTF node each bone and helper becomes, and which meshes hang where.
pub struct NodePlan {
    /// The node of each bone.
    pub bone_node: Vec<usize>,
    /// The helper node above each bone that has one.
    pub helper_node: Vec<Option<usize>>,
    /// Per mesh group: the node it is on and the source meshes (indices into `Rig::meshes`).
    pub groups: Vec<(usize, Vec<usize>)>,
    /// Extra nodes for meshes that could not share their bone's node: (parent node, mesh).
    extra: Vec<(usize, usize)>,
    pub notes: Vec<String>,
}

impl NodePlan {
    pub fn new(rig: &Rig, helpers: &[bool]) -> Self {
        // A helper node comes just before its bone's node.
        let mut bone_node = Vec::with_capacity(helpers.len());
        let mut helper_node = Vec::with_capacity(helpers.len());
        let mut nodes = 0;
        for &helper in helpers {
            helper_node.push(helper.then_some(nodes));
            nodes += usize::from(helper);
            bone_node.push(nodes);
            nodes += 1;
        }
        let mut layout = NodePlan { bone_node, helper_node, groups: Vec::new(), extra: Vec::new(), notes: Vec::new() };
        layout.place_meshes(rig);
        layout
    }

    /// Every mesh on its bone's node; meshes that share a bone share its glTF mesh as primitives when they can
    /// (the same skin and as many morph targets), else hang on child nodes of their own. A mesh without a face is
    /// left out: glTF has no empty accessor, and a placeholder (as exporters leave on characters) shows nothing.
    fn place_meshes(&mut self, rig: &Rig) {
        let mut by_bone: Vec<Vec<usize>> = vec![Vec::new(); rig.skeleton.len()];
        let mut faceless = Vec::new();
        for (m, mesh) in rig.meshes.iter().enumerate() {
            if mesh.indices.is_empty() {
                faceless.push(mesh.name.clone());
            } else if let Some(list) = by_bone.get_mut(mesh.bone) {
                list.push(m);
            }
        }
        if !faceless.is_empty() {
            self.notes.push(format!("meshes without faces left out (glTF has no empty mesh): {}", faceless.join(", ")));
        }
        let mut moved = Vec::new();
        for (bone, meshes) in by_bone.into_iter().enumerate() {
            let Some(&first) = meshes.first() else { continue };
            let fits = |m: &usize| {
                let (a, b) = (&rig.meshes[first], &rig.meshes[*m]);
                a.skin == b.skin && a.morph_targets.len() == b.morph_targets.len()
            };
            let (shared, apart): (Vec<usize>, Vec<usize>) = meshes.into_iter().partition(fits);
            self.groups.push((self.bone_node[bone], shared));
            for m in apart {
                self.extra.push((self.bone_node[bone], m));
                moved.push(rig.meshes[m].name.clone());
            }
        }
        if !moved.is_empty() {
            self.notes
                .push(format!("meshes on child nodes of their own (a glTF node shows one mesh): {}", moved.join(", ")));
        }
    }

    /// The nodes, meshes and skins, with each node's default TRS from the rest pose (`rest`, one per bone).
    pub fn document<'a>(&self, rig: &'a Rig, rest: &[NodeSample]) -> GltfDocument<'a> {
        let mut document =
            GltfDocument { generator: format!("bonescope {}", env!("CARGO_PKG_VERSION")), ..GltfDocument::default() };
        for (bone, b) in rig.skeleton.bones().iter().enumerate() {
            let node = &rest[bone].as_baked(self.helper_node[bone].is_some());
            let parent = b.parent.map(|p| self.bone_node[p]);
            match self.helper_node[bone] {
                Some(helper) => {
                    document.nodes.push(node_with(&format!("{}{HELPER_SUFFIX}", b.name), parent, node));
                    let own = NodeSample { rotation: node.stretch.conjugate(), ..NodeSample::IDENTITY };
                    document.nodes.push(node_with(&b.name, Some(helper), &own));
                }
                None => document.nodes.push(node_with(&b.name, parent, node)),
            }
        }
        for (node, meshes) in &self.groups {
            document.nodes[*node].mesh = Some(document.meshes.len());
            document.meshes.push(group(rig, meshes));
        }
        for &(parent, mesh) in &self.extra {
            let name = rig.meshes[mesh].name.clone();
            document.nodes.push(Node {
                mesh: Some(document.meshes.len()),
                ..node_with(&name, Some(parent), &NodeSample::IDENTITY)
            });
            document.meshes.push(group(rig, &[mesh]));
        }
        for node in &mut document.nodes {
            node.skin = node.mesh.and_then(|m| document.meshes[m].primitives[0].skin);
        }
        document.skins = skins(rig, &self.bone_node);
        document
    }

    /// What glTF needs of `document` beyond its nodes: the source's unit and axes on a node above the roots, and one
    /// root above every skin's joints; what a user should know of them goes to `notes`.
    pub fn for_gltf(&self, rig: &Rig, document: &mut GltfDocument, notes: &mut Vec<String>) {
        self.converted(rig, document);
        common_root(document, notes);
    }

    /// The source's unit and axes on a node `conversion` above the roots that need it ([`under_conversion`]): the
    /// baked bones keep the file's own numbers, and a reader that places conversion nodes outside the rig, as
    /// bonescope does, reads the scale factors the file's author set. The node, where one was needed.
    pub fn converted(&self, rig: &Rig, document: &mut GltfDocument) -> Option<usize> {
        // A bone's topmost node: its helper where it has one.
        let top_node = |bone: usize| self.helper_node[bone].unwrap_or(self.bone_node[bone]);
        let under: Vec<usize> = (under_conversion(&rig.skeleton).iter().enumerate())
            .filter(|(_, under)| **under)
            .map(|(bone, _)| top_node(bone))
            .collect();
        if under.is_empty() {
            return None;
        }
        let node = document.nodes.len();
        for &root in &under {
            document.nodes[root].parent = Some(node);
        }
        let parts = decompose(&rig.skeleton.placement().conversion);
        let sample = NodeSample { rotation: parts.rotation, scale: parts.scale * parts.sign, ..NodeSample::IDENTITY };
        document.nodes.push(node_with(&unique_name(&document.nodes, "conversion"), None, &sample));
        Some(node)
    }
}

/// A node named `name` with the TRS of `sample` (its stretch is carried by the bone's own node, not here).
fn node_with(name: &str, parent: Option<usize>, sample: &NodeSample) -> Node {
    Node {
        name: name.to_owned(),
        parent,
        translation: sample.translation.as_vec3().to_array(),
        rotation: unit(sample.rotation),
        scale: sample.scale.as_vec3().to_array(),
        mesh: None,
        skin: None,
    }
}

/// A quaternion in single precision, of unit length there.
pub fn unit(q: DQuat) -> [f32; 4] {
    q.as_quat().normalize().to_array()
}

/// The source meshes `meshes` as one glTF mesh, named as the importer will name them back: a single mesh by its own
/// name, primitives `base[0]`, `base[1]`, … by `base`.
fn group<'a>(rig: &'a Rig, meshes: &[usize]) -> MeshGroup<'a> {
    let primitives: Vec<&Mesh> = meshes.iter().map(|&m| &rig.meshes[m]).collect();
    let name = match primitives.as_slice() {
        [one] => one.name.clone(),
        many => {
            let base = many[0].name.strip_suffix("[0]").unwrap_or(&many[0].name);
            base.to_owned()
        }
    };
    MeshGroup { name, weights: primitives[0].morph_weights.clone(), primitives }
}
