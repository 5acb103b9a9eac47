//! Meshes and their skins.
//!
//! Every node with a mesh gives one [`Mesh`] (an instanced mesh gives one per node), triangulated by ufbx.
//! - Unskinned: positions are in the node's space (the node's geometric transform, which FBX does not inherit,
//!   applied), so the node's model matrix places them.
//! - Skinned (the first skin deformer; FBX allows several, rarely used): positions stay in geometry space and each
//!   cluster becomes a joint with inverse bind matrix `geometry_to_bone`, so `Σ w·W_bone·geometry_to_bone·v` is
//!   ufbx's (and the FBX SDK's) linear blend skinning. Each vertex keeps its four strongest weights, renormalised;
//!   a vertex without weights follows the mesh's own node, as in ufbx, Maya and Blender, through one extra joint
//!   (the mesh node, with the geometric transform as its inverse bind matrix).

use glam::Vec3;

use super::scene::SceneBones;
use super::{Failure, Result, matrix, memory_limit, node_name};
use crate::import::budget::size;
use crate::model::{Mesh, MorphTarget, NodeBind, Skin};

pub(super) fn read(
    scene: &ufbx::Scene,
    bones: &SceneBones,
    file_size: usize,
    notes: &mut Vec<String>,
) -> Result<(Vec<Skin>, Vec<Mesh>)> {
    let mut skins = Vec::new();
    let mut meshes = Vec::new();
    let mut tally = Tally::default();
    let follows_node = skins_follow_their_node(scene);
    // An instanced mesh is copied per node: a small file could otherwise ask for any amount of memory.
    let limit = memory_limit(file_size);
    let mut needed = 0usize;
    for (bone, bone_data) in bones.skeleton.bones().iter().enumerate() {
        let Some(node) = scene.nodes.get(bone_data.node) else { continue };
        let Some(mesh) = node.mesh.as_ref() else { continue };
        let place = format!("mesh `{}` on node `{}`", mesh.element.name, node_name(node));
        // Positions, normals, joints and weights per vertex, and positions and normals skinned; three indices per
        // triangle.
        let bytes = mesh
            .vertices
            .len()
            .saturating_mul(12 + 12 + 8 + 16 + 24)
            .saturating_add(mesh.num_triangles.saturating_mul(12));
        needed = needed.saturating_add(bytes);
        if needed > limit {
            let message = format!(
                "needs ~{} for the meshes, each copied for every node that shows it ({} nodes show this one of {} \
                 vertices); the limit is {} (for a file of this size, or --max-memory)",
                size(needed as u64),
                mesh.element.instances.len(),
                mesh.vertices.len(),
                size(limit as u64)
            );
            return Err(Failure::at(&place, message));
        }
        let mut read = Mesh { name: mesh_name(mesh, node), bone, ..Mesh::default() };
        read.indices = triangles(mesh, &place, &mut tally)?;
        // Unskinned positions (and their displacements) are placed in the node's space.
        let mut to_space = glam::DMat4::IDENTITY;
        match mesh.skin_deformers.first() {
            Some(skin) => {
                if mesh.skin_deformers.len() > 1 {
                    tally.extra_skins += 1;
                }
                // ufbx sets a per-vertex blend towards dual-quaternion skinning for DQ and blended skins.
                if skin.vertices.iter().any(|v| v.dq_weight > 0.0) {
                    tally.dual_quaternion += 1;
                    read.dq_weights = (0..mesh.vertices.len())
                        .map(|v| skin.vertices.get(v).map_or(0.0, |s| s.dq_weight as f32))
                        .collect();
                }
                read.positions = mesh.vertices.iter().map(|v| Vec3::new(v.x as f32, v.y as f32, v.z as f32)).collect();
                let skin = read_skin(skin, node, bones, follows_node, &mut read, &place, &mut tally)?;
                read.skin = Some(skins.len());
                skins.push(skin);
            }
            None => {
                to_space = matrix(&node.geometry_to_node);
                read.positions = mesh
                    .vertices
                    .iter()
                    .map(|v| to_space.transform_point3(glam::DVec3::new(v.x, v.y, v.z)).as_vec3())
                    .collect();
            }
        }
        read.normals = vertex_normals(mesh, &to_space);
        tally.split_normals += usize::from(mesh.vertex_normal.exists && !mesh.vertex_normal.unique_per_vertex);
        read_blend_shapes(mesh, &to_space, &mut read);
        if !read.morph_targets.is_empty() {
            tally.blend_shapes += 1;
        }
        tally.non_finite += read.remove_non_finite_vertices();
        meshes.push(read);
    }
    tally.notes(notes);
    Ok((skins, meshes))
}

/// One normal per vertex from the file's normals per face corner: the one its corners share, or, where the faces
/// around a vertex disagree (a hard edge), their normalised sum; in the mesh's `to_space` (where its positions are);
/// empty when the file has none.
fn vertex_normals(mesh: &ufbx::Mesh, to_space: &glam::DMat4) -> Vec<Vec3> {
    let normals = &mesh.vertex_normal;
    if !normals.exists {
        return Vec::new();
    }
    let mut sums = vec![glam::DVec3::ZERO; mesh.vertices.len()];
    for (&vertex, &index) in mesh.vertex_indices.iter().zip(normals.indices.iter()) {
        if let (Some(sum), Some(n)) = (sums.get_mut(vertex as usize), normals.values.get(index as usize)) {
            *sum += glam::DVec3::new(n.x, n.y, n.z);
        }
    }
    // Normals go by the inverse transpose; a singular placement leaves them as they are.
    let linear = glam::DMat3::from_mat4(*to_space);
    let linear = if linear.determinant() != 0.0 { linear.inverse().transpose() } else { glam::DMat3::IDENTITY };
    sums.iter().map(|sum| (linear * *sum).normalize_or_zero().as_vec3()).collect()
}

/// Every shape of the mesh's blend channels as a morph target (displacements in the mesh's `to_space`), in the order
/// of [`blend_channels`], weighted as the file stores them.
fn read_blend_shapes(mesh: &ufbx::Mesh, to_space: &glam::DMat4, read: &mut Mesh) {
    for channel in blend_channels(mesh) {
        read.morph_weights.extend(shape_weights(channel, channel.weight).into_iter().map(|w| w as f32));
        for keyframe in channel.keyframes.iter() {
            let shape = &keyframe.shape;
            let mut offsets = vec![Vec3::ZERO; mesh.vertices.len()];
            // A shape may weight each of its offsets (Blender's vertex group of a shape key).
            let weight = |i: usize| shape.offset_weights.get(i).copied().unwrap_or(1.0);
            for (i, (&vertex, offset)) in shape.offset_vertices.iter().zip(shape.position_offsets.iter()).enumerate() {
                if let Some(slot) = offsets.get_mut(vertex as usize) {
                    let offset = glam::DVec3::new(offset.x, offset.y, offset.z) * weight(i);
                    *slot = to_space.transform_vector3(offset).as_vec3();
                }
            }
            read.morph_targets.push(MorphTarget { name: shape.element.name.to_string(), offsets });
        }
    }
}

/// The blend channels of a mesh, in the order their shapes become morph targets (deformers, then channels, then
/// each channel's shapes by target weight).
pub(super) fn blend_channels(mesh: &ufbx::Mesh) -> impl Iterator<Item = &ufbx::BlendChannel> {
    mesh.blend_deformers.iter().flat_map(|deformer| deformer.channels.iter().map(|c| c.as_ref()))
}

/// Each shape's share of a channel at `weight` (0 to 1), by [`split_among_shapes`].
pub(super) fn shape_weights(channel: &ufbx::BlendChannel, weight: f64) -> Vec<f64> {
    let targets: Vec<f64> = channel.keyframes.iter().map(|k| k.target_weight).collect();
    split_among_shapes(&targets, weight)
}

/// FBX's in-between rule as ufbx evaluates it: given the shapes' target weights (ascending), `weight` falls between
/// two of them (or one and zero, the base shape) and is split linearly between those two.
fn split_among_shapes(targets: &[f64], weight: f64) -> Vec<f64> {
    let mut shares = vec![0.0; targets.len()];
    // `None` is the base shape at target weight 0.
    let target = |k: Option<usize>| k.map_or(0.0, |k| targets[k]);
    let last_negative = targets.iter().rposition(|&t| t < 0.0);
    let first_positive = last_negative.map_or(0, |n| n + 1);
    let mut next = None;
    let mut prev =
        if weight > 0.0 { last_negative } else { (first_positive < targets.len()).then_some(first_positive) };
    if weight > 0.0 {
        for (k, &target) in targets.iter().enumerate().skip(first_positive) {
            (prev, next) = (next, Some(k));
            if target > weight {
                break;
            }
        }
    } else {
        for (k, &target) in targets.iter().enumerate().take(first_positive).rev() {
            (prev, next) = (next, Some(k));
            if target < weight {
                break;
            }
        }
    }
    let delta = target(next) - target(prev);
    if delta != 0.0 {
        let t = (weight - target(prev)) / delta;
        if let Some(p) = prev {
            shares[p] = 1.0 - t;
        }
        if let Some(n) = next {
            shares[n] = t;
        }
    }
    shares
}

/// What the notes say about all meshes together.
#[derive(Default)]
struct Tally {
    extra_skins: usize,
    dual_quaternion: usize,
    blend_shapes: usize,
    skipped_faces: usize,
    trimmed_weights: usize,
    unweighted: usize,
    non_finite: usize,
    split_normals: usize,
}

impl Tally {
    fn notes(&self, notes: &mut Vec<String>) {
        let lines = [
            (self.extra_skins, "meshes have more than one skin deformer; only the first is used"),
            (self.dual_quaternion, "skins use (partly) dual-quaternion skinning, as the file declares"),
            (
                self.blend_shapes,
                "meshes have blend shapes (each in-between shape a morph target, applied before skinning)",
            ),
            (self.skipped_faces, "faces with fewer than 3 corners (points, lines) were skipped"),
            (self.trimmed_weights, "vertices have more than 4 weights; the 4 strongest are kept, renormalised"),
            (self.unweighted, "skinned vertices have no weights and follow their mesh's node"),
            (self.non_finite, "vertices are not finite (NaN or infinite), left out of skinning and drawing"),
            (
                self.split_normals,
                "meshes have hard edges (normals that differ between faces at a vertex), averaged per vertex",
            ),
        ];
        notes.extend(lines.iter().filter(|(n, _)| *n > 0).map(|(n, what)| format!("{n} {what}")));
    }
}

fn mesh_name(mesh: &ufbx::Mesh, node: &ufbx::Node) -> String {
    let name: &str = &mesh.element.name;
    if name.is_empty() { node_name(node) } else { name.to_owned() }
}

/// Every polygon as triangles (ufbx's triangulation), as indices into `mesh.vertices`.
fn triangles(mesh: &ufbx::Mesh, place: &str, tally: &mut Tally) -> Result<Vec<u32>> {
    let vertex_count = mesh.vertices.len();
    let mut indices = Vec::with_capacity(mesh.num_triangles.min(mesh.vertex_indices.len()).saturating_mul(3));
    let mut corners = Vec::new();
    for face in mesh.faces.iter() {
        if face.num_indices < 3 {
            tally.skipped_faces += 1;
            continue;
        }
        corners.resize((face.num_indices as usize - 2) * 3, 0);
        let count = ufbx::triangulate_face(&mut corners, mesh, *face) as usize;
        for &corner in &corners[..(count * 3).min(corners.len())] {
            let vertex = mesh.vertex_indices.get(corner as usize).copied().filter(|&v| (v as usize) < vertex_count);
            let Some(vertex) = vertex else {
                return Err(Failure::at(place, format!("face corner {corner} has no vertex")));
            };
            indices.push(vertex);
        }
    }
    Ok(indices)
}

/// The skin of one mesh instance, filling the mesh's joints and weights.
fn read_skin(
    skin: &ufbx::SkinDeformer,
    mesh_node: &ufbx::Node,
    bones: &SceneBones,
    follows_node: bool,
    mesh: &mut Mesh,
    place: &str,
    tally: &mut Tally,
) -> Result<Skin> {
    let bone_of = |node: &ufbx::Node| bones.bone_of_node.get(node.element.typed_id as usize).copied().flatten();
    let mut joints = Vec::with_capacity(skin.clusters.len() + 1);
    let mut inverse_bind = Vec::with_capacity(skin.clusters.len() + 1);
    // Per cluster, its joint index (clusters without a bone get none and their weights are dropped).
    let mut joint_of_cluster = Vec::with_capacity(skin.clusters.len());
    for cluster in skin.clusters.iter() {
        let bone = cluster.bone_node.as_ref().and_then(|n| bone_of(n));
        joint_of_cluster.push(bone.map(|b| {
            joints.push(b);
            inverse_bind.push(matrix(&cluster.geometry_to_bone));
            joints.len() - 1
        }));
    }
    let own = joints.len();
    let mesh_bone = bone_of(mesh_node).ok_or_else(|| Failure::at(place, "the mesh's node is not a bone"))?;
    joints.push(mesh_bone);
    inverse_bind.push(matrix(&mesh_node.geometry_to_node));
    if joints.len() > usize::from(u16::MAX) + 1 {
        return Err(Failure::at(place, format!("{} joints; at most 65536 are supported", joints.len())));
    }
    if let Some(k) = inverse_bind.iter().position(|m| !m.is_finite()) {
        return Err(Failure::at(place, format!("bind matrix of joint {k} is not finite")));
    }
    let vertex_count = mesh.positions.len();
    if skin.vertices.len() < vertex_count {
        let message = format!("the skin has weights for {} vertices, the mesh has {vertex_count}", skin.vertices.len());
        return Err(Failure::at(place, message));
    }
    mesh.joints.reserve_exact(vertex_count);
    mesh.weights.reserve_exact(vertex_count);
    let mut strongest: Vec<(f64, usize)> = Vec::new();
    for (v, vertex) in skin.vertices.iter().take(vertex_count).enumerate() {
        let begin = vertex.weight_begin as usize;
        let Some(weights) = skin.weights.get(begin..begin.saturating_add(vertex.num_weights as usize)) else {
            return Err(Failure::at(place, format!("vertex {v}: weights out of range")));
        };
        strongest.clear();
        for w in weights {
            let joint = joint_of_cluster.get(w.cluster_index as usize).copied().flatten();
            if let Some(joint) = joint.filter(|_| w.weight > 0.0 && w.weight.is_finite()) {
                strongest.push((w.weight, joint));
            }
        }
        strongest.sort_by(|a, b| b.0.total_cmp(&a.0));
        if strongest.len() > 4 {
            tally.trimmed_weights += 1;
            strongest.truncate(4);
        }
        let total: f64 = strongest.iter().map(|w| w.0).sum();
        let (mut j, mut w) = ([0u16; 4], [0f32; 4]);
        if total > 0.0 {
            for (k, &(weight, joint)) in strongest.iter().enumerate() {
                j[k] = joint as u16;
                w[k] = (weight / total) as f32;
            }
        } else {
            tally.unweighted += 1;
            j[0] = own as u16;
            w[0] = 1.0;
        }
        mesh.joints.push(j);
        mesh.weights.push(w);
    }
    let name: &str = &skin.element.name;
    let node_bind = follows_node.then(|| node_bind(skin, mesh_node, mesh_bone)).flatten();
    Ok(Skin { name: (!name.is_empty()).then(|| name.to_owned()), joints, inverse_bind, node_bind })
}

/// Whether the scene's skinned meshes also follow their node, as Maya shows them (its skin cluster deforms in the
/// mesh's space as bound; the mesh's transform then applies). 3ds Max, Blender and the FBX SDK leave the mesh node
/// out, as glTF does; the corpus's OBJ references of each tool agree (`ufbx:transform_skin` on Maya's).
fn skins_follow_their_node(scene: &ufbx::Scene) -> bool {
    scene.metadata.original_application.name.contains("Maya")
}

/// The mesh node's bind for a skin that follows it: the node's model matrix in the file's bind pose (that of the
/// node, or of another instance of its mesh, as ufbx's runner looks it up), else from a cluster (the cluster's bone
/// at bind times the mesh node relative to that bone); `None` when neither is there.
fn node_bind(skin: &ufbx::SkinDeformer, mesh_node: &ufbx::Node, bone: usize) -> Option<NodeBind> {
    let posed = |node: &ufbx::Node| {
        let pose = node.bind_pose.as_ref()?;
        ufbx::get_bone_pose(pose, node).map(|p| matrix(&p.bone_to_world))
    };
    let instances = || mesh_node.mesh.as_ref()?.element.instances.iter().find_map(|n| posed(n));
    let from_cluster = || {
        let cluster = skin.clusters.first()?;
        Some(matrix(&cluster.bind_to_world) * matrix(&cluster.mesh_node_to_bone))
    };
    let node_at_bind = posed(mesh_node).or_else(instances).or_else(from_cluster)?;
    let inverse_bind = matrix(&mesh_node.geometry_to_node) * node_at_bind.inverse();
    inverse_bind.is_finite().then_some(NodeBind { bone, inverse_bind })
}

#[cfg(test)]
mod tests {
    use super::split_among_shapes;

    #[test]
    fn a_weight_between_in_between_shapes_is_split_between_them() {
        // Maya's in-between shapes at 0.5 and 1: 0.25 is half the first; 0.75 half of each; 1 the last alone.
        assert_eq!(split_among_shapes(&[0.5, 1.0], 0.25), [0.5, 0.0]);
        assert_eq!(split_among_shapes(&[0.5, 1.0], 0.75), [0.5, 0.5]);
        assert_eq!(split_among_shapes(&[0.5, 1.0], 1.0), [0.0, 1.0]);
        // Past the last target the last shape is extrapolated, as ufbx does.
        assert_eq!(split_among_shapes(&[0.5, 1.0], 1.5), [-1.0, 2.0]);
        // A plain shape scales with the weight; zero is the base.
        assert_eq!(split_among_shapes(&[1.0], 0.3), [0.3]);
        assert_eq!(split_among_shapes(&[1.0], 0.0), [0.0]);
        // Negative targets take negative weights.
        assert_eq!(split_among_shapes(&[-1.0, 1.0], -0.5), [0.5, 0.0]);
    }
}
