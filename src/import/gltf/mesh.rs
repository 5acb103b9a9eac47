//! Skins (joints and inverse bind matrices) and the triangle meshes of the scene's nodes.

use glam::{DMat4, DVec4};

use super::accessor::Accessors;
use super::scene::SceneBones;
use super::schema::{self, Root};
use super::{Failure, Result};
use crate::model::{Mesh, MorphTarget, Skin};

/// How far the last row of an inverse bind matrix, stored in single precision, may be from `0, 0, 0, 1`.
const AFFINE_TOLERANCE: f64 = 1e-6;

/// glTF's `mode` for triangle lists (the default).
const TRIANGLES: usize = 4;

/// Every skin of the document, in file order (so `Rig::skins[i]` is `skins[i]`); every joint must be a bone.
pub(super) fn read_skins(
    root: &Root,
    accessors: &Accessors,
    bone_of_node: &[Option<usize>],
    notes: &mut Vec<String>,
) -> Result<Vec<Skin>> {
    root.skins.iter().enumerate().map(|(i, skin)| read_skin(i, skin, root, accessors, bone_of_node, notes)).collect()
}

fn read_skin(
    index: usize,
    skin: &schema::Skin,
    root: &Root,
    accessors: &Accessors,
    bone_of_node: &[Option<usize>],
    notes: &mut Vec<String>,
) -> Result<Skin> {
    let place = format!("skins[{index}]");
    let joints = skin
        .joints
        .iter()
        .enumerate()
        .map(|(j, &node)| {
            schema::item(&root.nodes, node, "nodes", format_args!("{place}.joints[{j}]"))?;
            bone_of_node[node.0]
                .ok_or_else(|| Failure::at(&place, format!("joint nodes[{}] is not in the scene", node.0)))
        })
        .collect::<Result<Vec<usize>>>()?;
    let inverse_bind = match skin.inverse_bind_matrices {
        None => vec![DMat4::IDENTITY; joints.len()],
        Some(accessor) => {
            let mut matrices = accessors.matrices(accessor, &format!("{place}.inverseBindMatrices"))?;
            // The spec allows more matrices than joints; the extra ones belong to no joint.
            if matrices.len() < joints.len() {
                let message = format!("{} inverse bind matrices for {} joints", matrices.len(), joints.len());
                return Err(Failure::at(place, message));
            }
            matrices.truncate(joints.len());
            if let Some(k) = matrices.iter().position(|m| !m.is_finite()) {
                return Err(Failure::at(place, format!("inverse bind matrix {k} is not finite")));
            }
            // All zeros is what an accessor without data holds: valid glTF, but nothing to bind with.
            let zero = matrices.iter().filter(|m| **m == DMat4::ZERO).count();
            if zero > 0 {
                notes.push(format!("{place}: {zero} inverse bind matrices are all zeros (their accessor has no data)"));
            }
            let affine = |m: &DMat4| *m == DMat4::ZERO || m.row(3).abs_diff_eq(DVec4::W, AFFINE_TOLERANCE);
            if let Some(k) = matrices.iter().position(|m| !affine(m)) {
                let row = matrices[k].row(3);
                let message = format!("inverse bind matrix {k} is not affine (its last row is {row}, not 0, 0, 0, 1)");
                return Err(Failure::at(place, message));
            }
            matrices
        }
    };
    Ok(Skin { name: skin.name.clone(), joints, inverse_bind, node_bind: None })
}

/// One [`Mesh`] per triangle primitive of each scene node with a mesh, named after the mesh (or the node).
pub(super) fn read_meshes(
    root: &Root,
    accessors: &Accessors,
    scene: &SceneBones,
    skins: &[Skin],
    notes: &mut Vec<String>,
) -> Result<Vec<Mesh>> {
    let mut meshes = Vec::new();
    let (mut other_modes, mut unweighted, mut unnormalized) = (0, 0, 0);
    // Normals only travel into a bake: a broken NORMAL leaves them out rather than the file.
    let mut unread_normals = Vec::new();
    let mut unsupplied = Vec::new();
    for (bone, node_of_bone) in scene.skeleton.bones().iter().enumerate() {
        let node = &root.nodes[node_of_bone.node];
        let Some(mesh_index) = node.mesh else { continue };
        let mesh = schema::item(&root.meshes, mesh_index, "meshes", format_args!("nodes[{}].mesh", node_of_bone.node))?;
        let skin = match node.skin {
            Some(skin) => {
                schema::item(skins, skin, "skins", format_args!("nodes[{}].skin", node_of_bone.node))?;
                Some(skin.0)
            }
            None => None,
        };
        for (p, primitive) in mesh.primitives.iter().enumerate() {
            if primitive.mode.map_or(TRIANGLES, |m| m.0) != TRIANGLES {
                other_modes += 1;
                continue;
            }
            let place = format!("meshes[{}].primitives[{p}]", mesh_index.0);
            if let Some(buffer) = unsupplied_buffer(primitive, accessors) {
                unsupplied.push(format!("{place} (buffers[{}])", buffer.0));
                continue;
            }
            let base = mesh.name.as_deref().unwrap_or(&scene.skeleton.bone(bone).name);
            let name = match mesh.primitives.len() {
                1 => base.to_owned(),
                _ => format!("{base}[{p}]"),
            };
            let mut read = Mesh { name, bone, ..Mesh::default() };
            read.positions = positions(primitive, accessors, &place)?;
            read.normals = normals(primitive, accessors, read.positions.len(), &place).unwrap_or_else(|failure| {
                unread_normals.push(format!("{}: {}", failure.place.unwrap_or_default(), failure.message));
                Vec::new()
            });
            if let Some(skin) = skin {
                if read_skinning(&mut read, primitive, accessors, &skins[skin], &place)? {
                    read.skin = Some(skin);
                    unnormalized += read.normalize_weights();
                } else {
                    unweighted += 1;
                }
            }
            read.indices = triangle_indices(primitive, accessors, read.positions.len(), &place)?;
            read.morph_targets = morph_targets(primitive, accessors, read.positions.len(), &place)?;
            let weights = node.weights.as_ref().unwrap_or(&mesh.weights);
            read.morph_weights =
                (0..read.morph_targets.len()).map(|k| weights.get(k).map_or(0.0, |&w| w as f32)).collect();
            meshes.push(read);
        }
    }
    if other_modes > 0 {
        notes.push(format!("{other_modes} mesh primitives that are not triangle lists were skipped"));
    }
    if unweighted > 0 {
        notes.push(format!("{unweighted} primitives of skinned nodes have no JOINTS_0/WEIGHTS_0, read unskinned"));
    }
    if !unread_normals.is_empty() {
        notes.push(format!("normals left out: {}", unread_normals.join("; ")));
    }
    if unnormalized > 0 {
        notes.push(format!("{unnormalized} vertices' skin weights did not sum to 1; normalised, as glTF requires"));
    }
    if !unsupplied.is_empty() {
        notes.push(format!(
            "not drawn, their data lies in buffers without a uri (to be supplied by an application): {}",
            unsupplied.join(", ")
        ));
    }
    Ok(meshes)
}

/// A buffer without a source in the file that the primitive's geometry needs, if any.
fn unsupplied_buffer(primitive: &schema::Primitive, accessors: &Accessors) -> Option<schema::Uint> {
    let attributes = ["POSITION", "JOINTS_0", "WEIGHTS_0"].into_iter().filter_map(|a| primitive.attributes.get(a));
    attributes.copied().chain(primitive.indices).find_map(|accessor| accessors.unsupplied_buffer(accessor))
}

fn positions(primitive: &schema::Primitive, accessors: &Accessors, place: &str) -> Result<Vec<glam::Vec3>> {
    let accessor = primitive.attributes.get("POSITION").ok_or_else(|| Failure::at(place, "has no POSITION"))?;
    accessors.positions(*accessor, &format!("{place}.attributes.POSITION"), "POSITION")
}

/// The primitive's `NORMAL`s, one per vertex (empty without them).
fn normals(
    primitive: &schema::Primitive,
    accessors: &Accessors,
    vertices: usize,
    place: &str,
) -> Result<Vec<glam::Vec3>> {
    let Some(&accessor) = primitive.attributes.get("NORMAL") else { return Ok(Vec::new()) };
    let place = format!("{place}.attributes.NORMAL");
    let normals = accessors.positions(accessor, &place, "NORMAL")?;
    if normals.len() != vertices {
        return Err(Failure::at(place, format!("{} normals for {vertices} vertices", normals.len())));
    }
    Ok(normals)
}

/// The primitive's morph targets (their `POSITION` displacements; a target without one displaces nothing).
fn morph_targets(
    primitive: &schema::Primitive,
    accessors: &Accessors,
    vertices: usize,
    place: &str,
) -> Result<Vec<MorphTarget>> {
    let target = |(k, attributes): (usize, &schema::Attributes)| {
        let offsets = match attributes.get("POSITION") {
            Some(&accessor) => {
                let place = format!("{place}.targets[{k}].POSITION");
                let offsets = accessors.positions(accessor, &place, "morph target POSITION")?;
                if offsets.len() != vertices {
                    let message = format!("{} displacements for {vertices} vertices", offsets.len());
                    return Err(Failure::at(place, message));
                }
                offsets
            }
            None => vec![glam::Vec3::ZERO; vertices],
        };
        Ok(MorphTarget { name: format!("target {k}"), offsets })
    };
    primitive.targets.iter().enumerate().map(target).collect()
}

/// Reads `JOINTS_0` and `WEIGHTS_0` into `mesh`; `false` when the primitive lacks either.
fn read_skinning(
    mesh: &mut Mesh,
    primitive: &schema::Primitive,
    accessors: &Accessors,
    skin: &Skin,
    place: &str,
) -> Result<bool> {
    let (Some(&joints), Some(&weights)) = (primitive.attributes.get("JOINTS_0"), primitive.attributes.get("WEIGHTS_0"))
    else {
        return Ok(false);
    };
    mesh.joints = accessors.joints(joints, &format!("{place}.attributes.JOINTS_0"))?;
    mesh.weights = accessors.weights(weights, &format!("{place}.attributes.WEIGHTS_0"))?;
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
    primitive: &schema::Primitive,
    accessors: &Accessors,
    vertices: usize,
    place: &str,
) -> Result<Vec<u32>> {
    let indices = match primitive.indices {
        Some(accessor) => accessors.indices(accessor, &format!("{place}.indices"))?,
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
