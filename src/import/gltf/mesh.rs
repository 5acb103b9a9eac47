//! Skins (joints and inverse bind matrices) and the triangle meshes of the scene's nodes.

use glam::DMat4;
use gltf::mesh::{Mode, Semantic};

use super::scene::SceneBones;
use super::{Failure, Result, accessor};
use crate::model::{Mesh, Skin};

/// Every skin of the document, in file order (so `Rig::skins[i]` is `skins[i]`); every joint must be a bone.
pub(super) fn read_skins(
    doc: &gltf::Document,
    buffers: &[Vec<u8>],
    bone_of_node: &[Option<usize>],
) -> Result<Vec<Skin>> {
    doc.skins().map(|skin| read_skin(&skin, buffers, bone_of_node)).collect()
}

fn read_skin(skin: &gltf::Skin, buffers: &[Vec<u8>], bone_of_node: &[Option<usize>]) -> Result<Skin> {
    let place = format!("skins[{}]", skin.index());
    let joints = skin
        .joints()
        .map(|node| {
            bone_of_node[node.index()]
                .ok_or_else(|| Failure::at(&place, format!("joint nodes[{}] is not in the scene", node.index())))
        })
        .collect::<Result<Vec<usize>>>()?;
    let inverse_bind = match skin.inverse_bind_matrices() {
        None => vec![DMat4::IDENTITY; joints.len()],
        Some(accessor) => {
            let mut matrices = accessor::matrices(&accessor, buffers)?;
            // The spec allows more matrices than joints; the extra ones belong to no joint.
            if matrices.len() < joints.len() {
                let message = format!("{} inverse bind matrices for {} joints", matrices.len(), joints.len());
                return Err(Failure::at(place, message));
            }
            matrices.truncate(joints.len());
            if let Some(k) = matrices.iter().position(|m| !m.is_finite()) {
                return Err(Failure::at(place, format!("inverse bind matrix {k} is not finite")));
            }
            matrices
        }
    };
    Ok(Skin { name: skin.name().map(str::to_owned), joints, inverse_bind })
}

/// One [`Mesh`] per triangle primitive of each scene node with a mesh, named after the mesh (or the node).
pub(super) fn read_meshes(
    doc: &gltf::Document,
    buffers: &[Vec<u8>],
    scene: &SceneBones,
    skins: &[Skin],
    notes: &mut Vec<String>,
) -> Result<Vec<Mesh>> {
    let nodes: Vec<gltf::Node> = doc.nodes().collect();
    let mut meshes = Vec::new();
    let (mut other_modes, mut unweighted) = (0, 0);
    for (bone, node) in scene.skeleton.bones().iter().enumerate() {
        let node = &nodes[node.node];
        let Some(mesh) = node.mesh() else { continue };
        let skin = node.skin().map(|s| s.index());
        for primitive in mesh.primitives() {
            if primitive.mode() != Mode::Triangles {
                other_modes += 1;
                continue;
            }
            let place = format!("meshes[{}].primitives[{}]", mesh.index(), primitive.index());
            let base = mesh.name().unwrap_or(&scene.skeleton.bone(bone).name);
            let name = match mesh.primitives().len() {
                1 => base.to_owned(),
                _ => format!("{base}[{}]", primitive.index()),
            };
            let mut read = Mesh { name, bone, ..Mesh::default() };
            read.positions = positions(&primitive, buffers, &place)?;
            if let Some(skin) = skin {
                if read_skinning(&mut read, &primitive, buffers, &skins[skin], &place)? {
                    read.skin = Some(skin);
                } else {
                    unweighted += 1;
                }
            }
            read.indices = triangle_indices(&primitive, buffers, read.positions.len(), &place)?;
            meshes.push(read);
        }
    }
    if other_modes > 0 {
        notes.push(format!("{other_modes} mesh primitives that are not triangle lists were skipped"));
    }
    if unweighted > 0 {
        notes.push(format!("{unweighted} primitives of skinned nodes have no JOINTS_0/WEIGHTS_0, read unskinned"));
    }
    Ok(meshes)
}

fn positions(primitive: &gltf::Primitive, buffers: &[Vec<u8>], place: &str) -> Result<Vec<glam::Vec3>> {
    // Validation has made sure that every primitive has a POSITION attribute.
    let accessor = primitive.get(&Semantic::Positions).ok_or_else(|| Failure::at(place, "has no POSITION"))?;
    accessor::vec3s(&accessor, buffers, "POSITION")
}

/// Reads `JOINTS_0` and `WEIGHTS_0` into `mesh`; `false` when the primitive lacks either.
fn read_skinning(
    mesh: &mut Mesh,
    primitive: &gltf::Primitive,
    buffers: &[Vec<u8>],
    skin: &Skin,
    place: &str,
) -> Result<bool> {
    let (Some(joints), Some(weights)) = (primitive.get(&Semantic::Joints(0)), primitive.get(&Semantic::Weights(0)))
    else {
        return Ok(false);
    };
    mesh.joints = accessor::joints(&joints, buffers)?;
    mesh.weights = accessor::weights(&weights, buffers)?;
    let vertices = mesh.positions.len();
    if mesh.joints.len() != vertices || mesh.weights.len() != vertices {
        let message =
            format!("{vertices} positions but {} JOINTS_0 and {} WEIGHTS_0", mesh.joints.len(), mesh.weights.len());
        return Err(Failure::at(place, message));
    }
    let limit = skin.joints.len();
    if let Some(v) = mesh.joints.iter().position(|j| j.iter().any(|&i| usize::from(i) >= limit)) {
        let message = format!("vertex {v} has joint indices {:?}, but the skin has {limit} joints", mesh.joints[v]);
        return Err(Failure::at(place, message));
    }
    Ok(true)
}

/// The triangle list: the `indices` accessor, or `0..n` without one.
fn triangle_indices(
    primitive: &gltf::Primitive,
    buffers: &[Vec<u8>],
    vertices: usize,
    place: &str,
) -> Result<Vec<u32>> {
    let indices = match primitive.indices() {
        Some(accessor) => accessor::indices(&accessor, buffers)?,
        None => {
            let n = u32::try_from(vertices).map_err(|_| Failure::at(place, "too many vertices"))?;
            (0..n).collect()
        }
    };
    if !indices.len().is_multiple_of(3) {
        return Err(Failure::at(place, format!("{} indices do not make whole triangles", indices.len())));
    }
    if let Some(&bad) = indices.iter().find(|&&i| i as usize >= vertices) {
        return Err(Failure::at(place, format!("index {bad} is out of range ({vertices} vertices)")));
    }
    Ok(indices)
}
