//! Skins as the baked files want them: only the joints the meshes use (FBX skins also list the mesh's own node, for
//! vertices no cluster weights), and for glTF every skin's joints under one root node (the validator's
//! `SKIN_NO_COMMON_ROOT`): where the joints lie under several roots, one new root node takes them all in.

use super::document::{GltfDocument, Node, SkinOut};
use crate::model::Rig;

/// The skins of `rig` over the nodes `bone_node` gives each bone, each with only the joints its meshes use.
pub fn skins(rig: &Rig, bone_node: &[usize]) -> Vec<SkinOut> {
    let mut skins = Vec::with_capacity(rig.skins.len());
    for (s, skin) in rig.skins.iter().enumerate() {
        let used = used_joints(rig, s, skin.joints.len());
        let mut joint_map = vec![0u16; skin.joints.len()];
        let (mut joints, mut inverse_bind) = (Vec::new(), Vec::new());
        for (j, (&bone, ibm)) in skin.joints.iter().zip(&skin.inverse_bind).enumerate() {
            if used[j] {
                joint_map[j] = joints.len() as u16;
                joints.push(bone_node[bone]);
                inverse_bind.push(*ibm);
            }
        }
        skins.push(SkinOut { name: skin.name.clone(), joints, inverse_bind, joint_map });
    }
    skins
}

/// Where some skin's joints lie under several root nodes (glTF wants one), a new root node above every root,
/// said in `notes`.
pub fn common_root(document: &mut GltfDocument, notes: &mut Vec<String>) {
    let roots = |joints: &[usize]| joints.iter().map(|&n| root_of(&document.nodes, n)).collect::<Vec<_>>();
    let apart = document.skins.iter().any(|skin| roots(&skin.joints).windows(2).any(|w| w[0] != w[1]));
    if apart {
        let name = unique_name(&document.nodes, "root");
        let wrapper = document.nodes.len();
        for node in document.nodes.iter_mut().filter(|n| n.parent.is_none()) {
            node.parent = Some(wrapper);
        }
        document.nodes.push(Node { name: name.clone(), ..Node::identity(None) });
        notes.push(format!("a skin's joints lie under several root nodes; a new root `{name}` holds them all"));
    }
}

/// Which joints of skin `s` some vertex of a mesh weights (a vertex with no positive weight falls back on joint 0).
fn used_joints(rig: &Rig, s: usize, count: usize) -> Vec<bool> {
    let mut used = vec![false; count];
    for mesh in rig.meshes.iter().filter(|m| m.skin == Some(s)) {
        for (joints, weights) in mesh.joints.iter().zip(&mesh.weights) {
            let mut any = false;
            for (&j, &w) in joints.iter().zip(weights) {
                if w > 0.0 && w.is_finite() && usize::from(j) < count {
                    used[usize::from(j)] = true;
                    any = true;
                }
            }
            if !any && count > 0 {
                used[0] = true;
            }
        }
    }
    if !used.contains(&true) && count > 0 {
        // A skin no vertex uses still needs a joint.
        used[0] = true;
    }
    used
}

/// The root above `node`.
fn root_of(nodes: &[Node], mut node: usize) -> usize {
    while let Some(parent) = nodes[node].parent {
        node = parent;
    }
    node
}

/// `base`, or `base.1`, `base.2`, … whichever no node is called yet.
pub(super) fn unique_name(nodes: &[Node], base: &str) -> String {
    unique(base, '.', |name| nodes.iter().any(|n| n.name == name))
}

/// `base`, or `base` with `1`, `2`, … after `separator`, whichever is not `taken`.
pub(super) fn unique(base: &str, separator: char, taken: impl Fn(&str) -> bool) -> String {
    if !taken(base) {
        return base.to_owned();
    }
    (1..).map(|k| format!("{base}{separator}{k}")).find(|name| !taken(name)).unwrap_or_default()
}

#[cfg(test)]
mod tests {
    use glam::{DMat4, Vec3};

    use super::*;
    use crate::model::{Mesh, Skin, named_skeleton};

    fn rig(bones: &[(&str, Option<usize>)], joints: Vec<usize>, weights: Vec<[f32; 4]>) -> Rig {
        let skeleton = named_skeleton(bones);
        let count = joints.len();
        let skin = Skin { name: None, joints, inverse_bind: vec![DMat4::IDENTITY; count], node_bind: None };
        let vertices = weights.len();
        let mesh = Mesh {
            positions: vec![Vec3::ZERO; vertices],
            skin: Some(0),
            joints: (0..vertices).map(|v| [0, 1, 2, v as u16 % 3]).collect(),
            weights,
            ..Mesh::default()
        };
        Rig { skeleton, skins: vec![skin], meshes: vec![mesh], ..Rig::default() }
    }

    fn document(rig: &Rig) -> GltfDocument<'static> {
        let nodes = rig.skeleton.bones().iter().map(|b| Node { name: b.name.clone(), ..Node::identity(b.parent) });
        GltfDocument { nodes: nodes.collect(), ..GltfDocument::default() }
    }

    #[test]
    fn unused_joints_leave_and_the_rest_are_renumbered() {
        // Joints: root, arm, and the mesh's own node (a second root) that no vertex weights.
        let rig = rig(&[("root", None), ("arm", Some(0)), ("mesh", None)], vec![0, 1, 2], vec![[0.5, 0.5, 0.0, 0.0]]);
        let (mut doc, mut notes) = (document(&rig), Vec::new());
        doc.skins = skins(&rig, &[0, 1, 2]);
        common_root(&mut doc, &mut notes);
        assert_eq!(doc.skins[0].joints, [0, 1]);
        assert_eq!(doc.skins[0].joint_map, [0, 1, 0]);
        assert!(notes.is_empty() && doc.nodes.len() == 3, "no new root needed");
    }

    #[test]
    fn joints_under_two_roots_get_a_common_one() {
        let rig = rig(&[("root", None), ("mesh", None)], vec![0, 1], vec![[0.5, 0.5, 0.0, 0.0]]);
        let (mut doc, mut notes) = (document(&rig), Vec::new());
        doc.skins = skins(&rig, &[0, 1]);
        common_root(&mut doc, &mut notes);
        assert_eq!(doc.nodes.len(), 3);
        assert_eq!((doc.nodes[0].parent, doc.nodes[1].parent, doc.nodes[2].parent), (Some(2), Some(2), None));
        assert_eq!(doc.nodes[2].name, "root.1", "`root` is taken");
        assert_eq!(notes.len(), 1);
    }
}
