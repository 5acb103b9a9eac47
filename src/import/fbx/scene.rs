//! ufbx's nodes as a parents-first [`Skeleton`].
//!
//! Every node below ufbx's synthetic root becomes a bone, depth first, children in file order. The root carries
//! ufbx's unit and axes conversion, which becomes the skeleton's [`Placement`]; it becomes a bone itself only when
//! it carries anything else (a bone list must not silently drop a transform). The walk uses an explicit stack.
//!
//! Each node's role comes from its FBX node attribute ([`role`]): limb nodes and the nodes skin clusters bind to are
//! joints, cameras and lights are what they say, and a null, a marker (HumanIK's effectors) or anything else is a
//! helper, unless joints hang from it ([`Skeleton::new`]).

use glam::{DMat4, DQuat, DVec3};

use super::{Failure, Result, node_name};
use crate::model::{Bone, InheritMode, NodeRole, Placement, Skeleton, Transform};

/// The skeleton and the node ↔ bone mapping.
pub(super) struct SceneBones {
    pub skeleton: Skeleton,
    /// The bone of each ufbx node (indexed by `typed_id`), `None` for the root when it is not a bone.
    pub bone_of_node: Vec<Option<usize>>,
}

pub(super) fn read(scene: &ufbx::Scene, notes: &mut Vec<String>) -> Result<SceneBones> {
    let root = &scene.root_node;
    let node_count = scene.nodes.len();
    let mut bone_of_node = vec![None; node_count];
    let mut bones: Vec<Bone> = Vec::new();
    let mut stack: Vec<(&ufbx::Node, Option<usize>)> = Vec::new();
    // ufbx puts the unit and axes conversion on its root: outside the rig, where no mode can compensate it.
    let conversion = from_ufbx(&root.local_transform).filter(Transform::only_converts);
    if conversion.is_some() {
        stack.extend(root.children.iter().rev().map(|c| (c.as_ref(), None)));
    } else {
        stack.push((root, None));
    }
    let mut counts = [0usize; 3];
    // Skin clusters may bind to any node (a null, a mesh): what a mesh is bound to is a joint.
    let mut bound = vec![false; node_count];
    for node in scene.skin_clusters.iter().filter_map(|c| c.bone_node.as_ref()) {
        if let Some(b) = bound.get_mut(node.element.typed_id as usize) {
            *b = true;
        }
    }
    while let Some((node, parent)) = stack.pop() {
        let id = node.element.typed_id as usize;
        let Some(slot) = bone_of_node.get_mut(id) else {
            return Err(Failure::at(node_name(node), format!("node id {id} out of range ({node_count} nodes)")));
        };
        if slot.is_some() {
            return Err(Failure::at(node_name(node), "reached twice in the node hierarchy"));
        }
        let bone = bones.len();
        *slot = Some(bone);
        let inherit = declared_mode(node);
        counts[match inherit {
            InheritMode::SegmentCompensate => 1,
            InheritMode::Componentwise => 2,
            _ => 0,
        }] += 1;
        let role = if bound[id] { NodeRole::Joint } else { role(node) };
        bones.push(Bone { name: node_name(node), node: id, parent, rest: transform(node)?, inherit, role });
        stack.extend(node.children.iter().rev().map(|c| (c.as_ref(), Some(bone))));
    }
    notes.push(format!(
        "inherit types as declared: {} full (RSrs), {} segment-compensate (Rrs), {} componentwise (RrSs)",
        counts[0], counts[1], counts[2]
    ));
    let root_id = root.element.typed_id as usize;
    let unreached = bone_of_node.iter().enumerate().filter(|&(id, b)| b.is_none() && id != root_id).count();
    if unreached > 0 {
        notes.push(format!("{unreached} nodes outside the root's hierarchy are not bones"));
    }
    let skeleton = Skeleton::new(bones).map_err(|e| Failure::whole(e.to_string()))?;
    let conversion = conversion.map_or(DMat4::IDENTITY, |c| c.matrix());
    let skeleton = skeleton.placed(Placement { conversion, conversion_nodes: Vec::new() });
    Ok(SceneBones { skeleton, bone_of_node })
}

/// What the node's attribute makes it (a node without one is a transform, a helper).
fn role(node: &ufbx::Node) -> NodeRole {
    match node.attrib_type {
        ufbx::ElementType::Bone => NodeRole::Joint,
        ufbx::ElementType::Mesh => NodeRole::Mesh,
        ufbx::ElementType::Camera | ufbx::ElementType::StereoCamera | ufbx::ElementType::CameraSwitcher => {
            NodeRole::Camera
        }
        ufbx::ElementType::Light => NodeRole::Light,
        _ => NodeRole::Helper,
    }
}

/// The node's InheritType as the file declares it. ufbx reads it into `inherit_mode`, but makes a top-level node's
/// normal where it converts at the root; that mode changes nothing (a root's model matrix is its local one in every
/// mode) but is what the file says, so it is read from the property there.
fn declared_mode(node: &ufbx::Node) -> InheritMode {
    let top_level = node.parent.as_ref().is_some_and(|p| p.is_root);
    match node.element.props.find_prop("InheritType").map(|p| p.value_int) {
        Some(0) if top_level => InheritMode::Componentwise,
        Some(2) if top_level => InheritMode::SegmentCompensate,
        _ => inherit_mode(node.inherit_mode),
    }
}

/// ufbx's reading of the file's InheritType, as a bonescope mode.
pub(super) fn inherit_mode(mode: ufbx::InheritMode) -> InheritMode {
    match mode {
        ufbx::InheritMode::Normal => InheritMode::Full,
        ufbx::InheritMode::IgnoreParentScale => InheritMode::SegmentCompensate,
        ufbx::InheritMode::ComponentwiseScale => InheritMode::Componentwise,
    }
}

/// A ufbx transform as a bonescope one, checked finite.
pub(super) fn from_ufbx(t: &ufbx::Transform) -> Option<Transform> {
    let translation = DVec3::new(t.translation.x, t.translation.y, t.translation.z);
    let rotation = DQuat::from_xyzw(t.rotation.x, t.rotation.y, t.rotation.z, t.rotation.w);
    let scale = DVec3::new(t.scale.x, t.scale.y, t.scale.z);
    let finite = translation.is_finite() && rotation.is_finite() && scale.is_finite();
    finite.then(|| Transform::from_trs(translation, rotation, scale))
}

fn transform(node: &ufbx::Node) -> Result<Transform> {
    from_ufbx(&node.local_transform).ok_or_else(|| Failure::at(node_name(node), "transform is not finite"))
}
