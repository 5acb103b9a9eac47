//! The node hierarchy of one scene as a parents-first [`Skeleton`].
//!
//! Every node of the scene becomes a bone, in depth-first order. The hierarchy is checked first (no node with two
//! parents, no cycle), and the walk uses an explicit stack, so a hostile file can neither loop nor overflow the
//! call stack.
//!
//! A node's role: a camera or a light when it has one; a joint when a skin lists it or the animation moves it; a
//! mesh when it shows one; otherwise a helper, unless joints hang from it ([`Skeleton::new`]).

use glam::{DMat4, DQuat, DVec3, DVec4};

use super::schema::{self, Root, Uint};
use super::{Failure, Result};
use crate::model::{Bone, InheritMode, NodeRole, Skeleton, Transform};

/// The skeleton and the node ↔ bone mapping.
pub(super) struct SceneBones {
    pub skeleton: Skeleton,
    /// The bone of each node, `None` for nodes outside the scene.
    pub bone_of_node: Vec<Option<usize>>,
}

pub(super) fn read(root: &Root, notes: &mut Vec<String>) -> Result<SceneBones> {
    let parents = parents(root)?;
    check_acyclic(&parents)?;
    let roots = scene_roots(root, &parents, notes)?;
    let moved = joints_and_animated(root);
    let mut bone_of_node = vec![None; root.nodes.len()];
    let mut bones: Vec<Bone> = Vec::new();
    // Depth-first: (node, parent bone), children pushed in reverse so they come out in file order.
    let mut stack: Vec<(usize, Option<usize>)> = roots.iter().rev().map(|&r| (r, None)).collect();
    while let Some((index, parent)) = stack.pop() {
        let node = &root.nodes[index];
        let bone = bones.len();
        bone_of_node[index] = Some(bone);
        let role = match role(node, moved[index]) {
            // A plain node below a joint carries the chain onward (a static node under an animated one): it moves
            // with the chain, so it is of the figure.
            NodeRole::Helper if parent.is_some_and(|p: usize| bones[p].role == NodeRole::Joint) => NodeRole::Joint,
            role => role,
        };
        bones.push(Bone {
            name: node.name.clone().unwrap_or_else(|| Bone::unnamed(index)),
            node: index,
            parent,
            rest: rest_transform(node, index)?,
            inherit: InheritMode::Full,
            role,
        });
        stack.extend(node.children.iter().rev().map(|c| (c.0, Some(bone))));
    }
    let outside = root.nodes.len() - bones.len();
    if outside > 0 {
        notes.push(format!("{outside} nodes outside the scene are not bones"));
    }
    // Cannot fail: depth-first order puts every parent before its children.
    let skeleton = Skeleton::new(bones).map_err(|e| Failure::whole(e.to_string()))?;
    Ok(SceneBones { skeleton, bone_of_node })
}

/// Per node, whether a skin lists it as a joint or an animation channel moves it (its translation, rotation or
/// scale; animated morph weights move no node). References out of range are left to the skins' and animations'
/// own readers, which name them.
fn joints_and_animated(root: &Root) -> Vec<bool> {
    let mut moved = vec![false; root.nodes.len()];
    let joints = root.skins.iter().flat_map(|s| &s.joints).map(|j| j.0);
    let channels = root.animations.iter().flat_map(|a| &a.channels).map(|c| &c.target);
    let animated = channels.filter(|t| t.path != "weights").filter_map(|t| t.node).map(|n| n.0);
    for node in joints.chain(animated) {
        if let Some(m) = moved.get_mut(node) {
            *m = true;
        }
    }
    moved
}

/// What a node is (a node can hold a camera and be animated: it is a camera).
fn role(node: &schema::Node, moved: bool) -> NodeRole {
    if node.camera.is_some() {
        NodeRole::Camera
    } else if node.extensions.lights_punctual.is_some() {
        NodeRole::Light
    } else if moved {
        NodeRole::Joint
    } else if node.mesh.is_some() {
        NodeRole::Mesh
    } else {
        NodeRole::Helper
    }
}

/// Each node's parent; a child that does not exist, or a node listed as a child twice, is an error.
fn parents(root: &Root) -> Result<Vec<Option<usize>>> {
    let mut parents = vec![None; root.nodes.len()];
    for (index, node) in root.nodes.iter().enumerate() {
        for (c, &child) in node.children.iter().enumerate() {
            schema::item(&root.nodes, child, "nodes", format_args!("nodes[{index}].children[{c}]"))?;
            if let Some(first) = parents[child.0].replace(index) {
                let message = format!("has two parents: nodes[{first}] and nodes[{index}]");
                return Err(Failure::at(format!("nodes[{}]", child.0), message));
            }
        }
    }
    Ok(parents)
}

/// With one parent per node, a cycle is a chain of parents that comes back to a node on it.
fn check_acyclic(parents: &[Option<usize>]) -> Result<()> {
    #[derive(Clone, Copy, PartialEq)]
    enum State {
        Unseen,
        OnPath,
        Done,
    }
    let mut state = vec![State::Unseen; parents.len()];
    let mut path = Vec::new();
    for start in 0..parents.len() {
        let mut current = Some(start);
        while let Some(node) = current {
            match state[node] {
                State::Done => break,
                State::OnPath => {
                    return Err(Failure::at(format!("nodes[{node}]"), "is its own ancestor (node cycle)"));
                }
                State::Unseen => {
                    state[node] = State::OnPath;
                    path.push(node);
                    current = parents[node];
                }
            }
        }
        for node in path.drain(..) {
            state[node] = State::Done;
        }
    }
    Ok(())
}

/// The root nodes of the default scene, else of scene 0, else every node without a parent.
fn scene_roots(root: &Root, parents: &[Option<usize>], notes: &mut Vec<String>) -> Result<Vec<usize>> {
    let index = match root.scene {
        Some(scene) => schema::item(&root.scenes, scene, "scenes", "scene").map(|_| scene.0)?,
        None if root.scenes.is_empty() => {
            return Ok((0..parents.len()).filter(|&n| parents[n].is_none()).collect());
        }
        None => 0,
    };
    if root.scenes.len() > 1 {
        notes.push(format!("{} scenes; bones come from scene {index}", root.scenes.len()));
    }
    let place = format!("scenes[{index}]");
    let mut roots: Vec<usize> = Vec::new();
    for (i, &node) in root.scenes[index].nodes.iter().enumerate() {
        schema::item(&root.nodes, node, "nodes", format_args!("{place}.nodes[{i}]"))?;
        let Uint(node) = node;
        if let Some(parent) = parents[node] {
            return Err(Failure::at(&place, format!("lists nodes[{node}], a child of nodes[{parent}]")));
        }
        if roots.contains(&node) {
            return Err(Failure::at(&place, format!("lists nodes[{node}] twice")));
        }
        roots.push(node);
    }
    Ok(roots)
}

/// Checks that every number of the node's transform is a finite single-precision number, as glTF stores them: a
/// value beyond (`1e39`) is a broken file, not a bigger rig.
fn check_single_precision(node: &schema::Node, index: usize) -> Result<()> {
    let fields: [(&str, Option<&[f64]>); 4] = [
        ("matrix", node.matrix.as_ref().map(|m| &m[..])),
        ("translation", node.translation.as_ref().map(|t| &t[..])),
        ("rotation", node.rotation.as_ref().map(|r| &r[..])),
        ("scale", node.scale.as_ref().map(|s| &s[..])),
    ];
    for (field, values) in fields {
        let values = values.unwrap_or_default();
        if let Some(k) = values.iter().position(|v| !v.is_finite() || v.abs() > f64::from(f32::MAX)) {
            let message = format!("{} is not a finite single-precision number", values[k]);
            return Err(Failure::at(format!("nodes[{index}].{field}[{k}]"), message));
        }
    }
    Ok(())
}

/// The node's local transform: its `matrix` decomposed, or its TRS with the spec's defaults.
fn rest_transform(node: &schema::Node, index: usize) -> Result<Transform> {
    check_single_precision(node, index)?;
    let place = || format!("nodes[{index}]");
    let rest = match &node.matrix {
        Some(matrix) => {
            let m = DMat4::from_cols_array(matrix);
            if !matrix.iter().all(|c| c.is_finite()) {
                return Err(Failure::at(place(), "matrix is not finite"));
            }
            if m.row(3) != DVec4::W {
                return Err(Failure::at(place(), "matrix is not affine (its last row is not 0, 0, 0, 1)"));
            }
            matrix_to_transform(&m)
        }
        None => Transform::from_trs(
            node.translation.map_or(DVec3::ZERO, DVec3::from_array),
            // Exporters write unit quaternions in single precision; renormalise in double (zero stays zero and
            // is rejected below as not finite).
            node.rotation.map_or(DQuat::IDENTITY, |r| DQuat::from_array(r).normalize()),
            node.scale.map_or(DVec3::ONE, DVec3::from_array),
        ),
    };
    let finite =
        rest.translation.is_finite() && rest.rotation.is_finite() && rest.scale.is_finite() && rest.stretch.is_finite();
    if finite { Ok(rest) } else { Err(Failure::at(place(), "transform is not finite")) }
}

/// A node `matrix` as a transform, keeping any shear in the stretch rotation and a mirror in the scale's sign.
fn matrix_to_transform(m: &DMat4) -> Transform {
    crate::math::decompose(m).transform()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matrices_round_trip_through_the_transform() {
        let trs = DMat4::from_scale_rotation_translation(
            DVec3::new(2.0, 0.5, 3.0),
            DQuat::from_euler(glam::EulerRot::XYZ, 0.3, -1.1, 2.0),
            DVec3::new(1.0, -2.0, 0.5),
        );
        let mirrored = trs * DMat4::from_scale(DVec3::new(1.0, -1.0, 1.0));
        for m in [trs, mirrored] {
            let t = matrix_to_transform(&m);
            assert!(t.matrix().abs_diff_eq(m, 1e-12), "{m:?} → {t:?}");
        }
        let t = matrix_to_transform(&mirrored);
        assert!(t.scale.cmplt(DVec3::ZERO).all(), "the mirror sign goes into every scale factor: {t:?}");
    }

    #[test]
    fn a_sheared_matrix_keeps_its_shear() {
        // Columns (1,0,0), (1,1,0), (0,0,1): a 45° shear no TRS can hold.
        let sheared =
            DMat4::from_cols(DVec4::X, DVec4::new(1.0, 1.0, 0.0, 0.0), DVec4::Z, DVec4::new(1.0, 2.0, 3.0, 1.0));
        let t = matrix_to_transform(&sheared);
        assert!(!t.is_trs());
        assert!(t.matrix().abs_diff_eq(sheared, 1e-14));
        // A singular matrix is kept too, with a zero scale factor.
        let flat = DMat4::from_scale(DVec3::new(1.0, 0.0, 1.0));
        assert!(matrix_to_transform(&flat).matrix().abs_diff_eq(flat, 1e-15));
    }

    #[test]
    fn cycles_are_found() {
        assert!(check_acyclic(&[None, Some(0), Some(1)]).is_ok());
        let err = check_acyclic(&[None, Some(2), Some(1)]).unwrap_err();
        assert_eq!(err.place.as_deref(), Some("nodes[1]"));
        assert!(check_acyclic(&[Some(0)]).is_err(), "a node that is its own child");
    }
}
