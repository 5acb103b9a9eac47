//! The node hierarchy of one scene as a parents-first [`Skeleton`].
//!
//! Every node of the scene becomes a bone, in depth-first order. The hierarchy is checked first (no node with two
//! parents, no cycle), and the walk uses an explicit stack, so a hostile file can neither loop nor overflow the
//! call stack.

use glam::{DMat4, DQuat, DVec3, DVec4};
use gltf::scene::Transform as NodeTransform;

use super::{Failure, Result};
use crate::model::{Bone, InheritMode, Skeleton, Transform};

/// The skeleton and the node ↔ bone mapping.
pub(super) struct SceneBones {
    pub skeleton: Skeleton,
    /// The bone of each node, `None` for nodes outside the scene.
    pub bone_of_node: Vec<Option<usize>>,
}

pub(super) fn read(doc: &gltf::Document, notes: &mut Vec<String>) -> Result<SceneBones> {
    let parents = parents(doc)?;
    check_acyclic(&parents)?;
    let roots = scene_roots(doc, &parents, notes)?;
    let nodes: Vec<gltf::Node> = doc.nodes().collect();
    let mut bone_of_node = vec![None; nodes.len()];
    let mut bones = Vec::new();
    // Depth-first: (node, parent bone), children pushed in reverse so they come out in file order.
    let mut stack: Vec<(usize, Option<usize>)> = roots.iter().rev().map(|&r| (r, None)).collect();
    while let Some((index, parent)) = stack.pop() {
        let node = &nodes[index];
        let bone = bones.len();
        bone_of_node[index] = Some(bone);
        bones.push(Bone {
            name: node.name().map_or_else(|| format!("node{index}"), str::to_owned),
            node: index,
            parent,
            rest: rest_transform(node)?,
            inherit: InheritMode::Full,
        });
        let children: Vec<usize> = node.children().map(|c| c.index()).collect();
        stack.extend(children.into_iter().rev().map(|c| (c, Some(bone))));
    }
    let outside = nodes.len() - bones.len();
    if outside > 0 {
        notes.push(format!("{outside} nodes outside the scene are not bones"));
    }
    // Cannot fail: depth-first order puts every parent before its children.
    let skeleton = Skeleton::new(bones).map_err(|e| Failure::whole(e.to_string()))?;
    Ok(SceneBones { skeleton, bone_of_node })
}

/// Each node's parent; a node listed as a child twice is an error.
fn parents(doc: &gltf::Document) -> Result<Vec<Option<usize>>> {
    let mut parents = vec![None; doc.nodes().len()];
    for node in doc.nodes() {
        for child in node.children() {
            if let Some(first) = parents[child.index()].replace(node.index()) {
                let message = format!("has two parents: nodes[{first}] and nodes[{}]", node.index());
                return Err(Failure::at(format!("nodes[{}]", child.index()), message));
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
fn scene_roots(doc: &gltf::Document, parents: &[Option<usize>], notes: &mut Vec<String>) -> Result<Vec<usize>> {
    let Some(scene) = doc.default_scene().or_else(|| doc.scenes().next()) else {
        return Ok((0..parents.len()).filter(|&n| parents[n].is_none()).collect());
    };
    if doc.scenes().len() > 1 {
        notes.push(format!("{} scenes; bones come from scene {}", doc.scenes().len(), scene.index()));
    }
    let place = || format!("scenes[{}]", scene.index());
    let mut roots: Vec<usize> = Vec::new();
    for node in scene.nodes() {
        let index = node.index();
        if let Some(parent) = parents[index] {
            return Err(Failure::at(place(), format!("lists nodes[{index}], a child of nodes[{parent}]")));
        }
        if roots.contains(&index) {
            return Err(Failure::at(place(), format!("lists nodes[{index}] twice")));
        }
        roots.push(index);
    }
    Ok(roots)
}

/// The node's local transform: TRS as given, or its matrix decomposed.
fn rest_transform(node: &gltf::Node) -> Result<Transform> {
    let place = || format!("nodes[{}]", node.index());
    let rest = match node.transform() {
        NodeTransform::Decomposed { translation, rotation, scale } => Transform::from_trs(
            DVec3::from_array(translation.map(f64::from)),
            // Exporters write unit quaternions in single precision; renormalise in double (zero stays zero and
            // is rejected below as not finite).
            DQuat::from_array(rotation.map(f64::from)).normalize(),
            DVec3::from_array(scale.map(f64::from)),
        ),
        NodeTransform::Matrix { matrix } => {
            let m = DMat4::from_cols_array_2d(&matrix.map(|column| column.map(f64::from)));
            if m.row(3) != DVec4::W {
                return Err(Failure::at(place(), "matrix is not affine (its last row is not 0, 0, 0, 1)"));
            }
            if !m.is_finite() {
                return Err(Failure::at(place(), "matrix is not finite"));
            }
            matrix_to_transform(&m)
        }
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
