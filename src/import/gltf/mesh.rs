//! Skins (joints and inverse bind matrices) and the triangle meshes of the scene's nodes.

use std::collections::HashMap;
use std::rc::Rc;

use glam::{DMat4, DVec4};

use super::accessor::Accessors;
use super::scene::SceneBones;
use super::schema::{self, DataType, Root};
use super::{Failure, Result};
use crate::model::{Mesh, MorphTarget, NOT_DRAWN_NOTE, Skeleton, Skin};

/// How far the last row of an inverse bind matrix, stored in single precision, may be from `0, 0, 0, 1`.
const AFFINE_TOLERANCE: f64 = 1e-6;

/// glTF's `mode`s of triangles: lists (the default), strips and fans.
const TRIANGLES: usize = 4;
const TRIANGLE_STRIP: usize = 5;
const TRIANGLE_FAN: usize = 6;

/// Every skin of the document, in file order (so `Rig::skins[i]` is `skins[i]`); every joint must be a bone.
pub(super) fn read_skins(
    root: &Root,
    accessors: &Accessors,
    bone_of_node: &[Option<usize>],
    notes: &mut Vec<String>,
) -> Result<Vec<Skin>> {
    // Skins may share one accessor of matrices: it is decoded once, each skin taking its joints' share.
    let mut decoded: HashMap<schema::Uint, Rc<Vec<DMat4>>> = HashMap::new();
    let mut matrices = |accessor: schema::Uint, place: &str| -> Result<Rc<Vec<DMat4>>> {
        if let Some(matrices) = decoded.get(&accessor) {
            return Ok(matrices.clone());
        }
        let matrices = Rc::new(accessors.matrices(accessor, place)?);
        decoded.insert(accessor, matrices.clone());
        Ok(matrices)
    };
    let mut skins = Vec::with_capacity(root.skins.len());
    for (i, skin) in root.skins.iter().enumerate() {
        skins.push(read_skin(i, skin, root, &mut matrices, bone_of_node, notes)?);
    }
    Ok(skins)
}

fn read_skin(
    index: usize,
    skin: &schema::Skin,
    root: &Root,
    matrices: &mut impl FnMut(schema::Uint, &str) -> Result<Rc<Vec<DMat4>>>,
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
            let all = matrices(accessor, &format!("{place}.inverseBindMatrices"))?;
            // The spec allows more matrices than joints; the extra ones belong to no joint.
            let Some(matrices) = all.get(..joints.len()) else {
                let message = format!("{} inverse bind matrices for {} joints", all.len(), joints.len());
                return Err(Failure::at(place, message));
            };
            let matrices = matrices.to_vec();
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
    let mut tally = Tally::default();
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
        let node_place = format!("nodes[{}].extensions.EXT_mesh_gpu_instancing", node_of_bone.node);
        let instances =
            node.extensions.gpu_instancing.as_ref().map(|i| instances(i, accessors, &node_place)).transpose()?;
        let shown = Shown { node, mesh, mesh_index: mesh_index.0, bone, skin };
        for p in 0..mesh.primitives.len() {
            let Some(read) = read_primitive(root, accessors, scene, skins, &shown, p, &mut tally)? else { continue };
            match &instances {
                Some(instances) => meshes.extend(instances.iter().enumerate().map(|(k, m)| instance(&read, k, m))),
                None => meshes.push(read),
            }
        }
    }
    tally.notes(notes);
    Ok(meshes)
}

/// A node's mesh, and where it hangs: its bone, its skin.
struct Shown<'a> {
    node: &'a schema::Node,
    mesh: &'a schema::Mesh,
    mesh_index: usize,
    bone: usize,
    skin: Option<usize>,
}

/// Primitive `p` of the mesh `shown` shows, read; `None` where it is left out (not triangles, its data not in the
/// file, its compressed data not decoding), with the reason in `tally`.
fn read_primitive(
    root: &Root,
    accessors: &Accessors,
    scene: &SceneBones,
    skins: &[Skin],
    shown: &Shown,
    p: usize,
    tally: &mut Tally,
) -> Result<Option<Mesh>> {
    let (mesh, bone) = (shown.mesh, shown.bone);
    let primitive = &mesh.primitives[p];
    let mode = primitive.mode.map_or(TRIANGLES, |m| m.0);
    if !matches!(mode, TRIANGLES | TRIANGLE_STRIP | TRIANGLE_FAN) {
        tally.other_modes += 1;
        return Ok(None);
    }
    let place = format!("meshes[{}].primitives[{p}]", shown.mesh_index);
    let base = mesh.name.as_deref().unwrap_or(&scene.skeleton.bone(bone).name);
    let name = if mesh.primitives.len() == 1 { base.to_owned() } else { format!("{base}[{p}]") };
    if let Some(buffer) = unsupplied_buffer(primitive, accessors) {
        tally.unsupplied.push(format!("{name} at {place} (buffers[{}])", buffer.0));
        return Ok(None);
    }
    if let Err(failure) = decompress(primitive, accessors, &place) {
        tally.undecoded.push(format!("{name} at {}: {}", failure.place.unwrap_or_default(), failure.message));
        return Ok(None);
    }
    let mut read = Mesh { name, bone, ..Mesh::default() };
    read.positions = positions(primitive, accessors, &place)?;
    if shown.skin.is_some() && quantized_positions(root, primitive) {
        dequantize_by_node(&mut read.positions, &scene.skeleton, bone);
        tally.dequantized_by_node += 1;
    }
    // Normals only travel into a bake: a broken NORMAL leaves them out rather than the file.
    read.normals = normals(primitive, accessors, read.positions.len(), &place).unwrap_or_else(|failure| {
        tally.unread_normals.push(format!("{}: {}", failure.place.unwrap_or_default(), failure.message));
        Vec::new()
    });
    if let Some(skin) = shown.skin {
        if read_skinning(&mut read, primitive, accessors, &skins[skin], &place, tally)? {
            read.skin = Some(skin);
        } else {
            tally.unweighted += 1;
        }
    }
    read.indices = triangle_indices(primitive, accessors, read.positions.len(), mode, &place, tally)?;
    read.morph_targets = morph_targets(primitive, accessors, read.positions.len(), &place)?;
    tally.non_finite += read.remove_non_finite_vertices();
    tally.unnormalized += read.normalize_weights();
    let weights = shown.node.weights.as_ref().unwrap_or(&mesh.weights);
    read.morph_weights = (0..read.morph_targets.len()).map(|k| weights.get(k).map_or(0.0, |&w| w as f32)).collect();
    Ok(Some(read))
}

/// What the meshes of a document add up to, for the notes.
#[derive(Default)]
struct Tally {
    /// Primitives of points or lines.
    other_modes: usize,
    unweighted: usize,
    unnormalized: usize,
    /// Vertices left out for a position, weight or displacement that is not finite.
    non_finite: usize,
    /// Vertices with more than four influences (two sets), of which the four strongest are kept.
    beyond_four: usize,
    /// Primitives whose indices end in an incomplete triangle.
    incomplete: Vec<String>,
    /// Primitives with triangles that index past their vertices, and how many such triangles each dropped.
    out_of_range: Vec<(String, usize)>,
    /// Skinned primitives whose quantized positions were put where their node is.
    dequantized_by_node: usize,
    /// Primitives whose normals could not be read, and why.
    unread_normals: Vec<String>,
    /// Primitives whose data lies in buffers without a uri.
    unsupplied: Vec<String>,
    /// Primitives whose compressed data does not decode, and why.
    undecoded: Vec<String>,
}

impl Tally {
    fn notes(&self, notes: &mut Vec<String>) {
        if self.other_modes > 0 {
            notes.push(format!("{} mesh primitives of points or lines were skipped", self.other_modes));
        }
        if self.unweighted > 0 {
            notes.push(format!(
                "{} primitives of skinned nodes have no JOINTS_0/WEIGHTS_0, read unskinned",
                self.unweighted
            ));
        }
        if self.unnormalized > 0 {
            let count = self.unnormalized;
            notes.push(format!("{count} vertices' skin weights did not sum to 1; normalised, as glTF requires"));
        }
        if self.non_finite > 0 {
            let count = self.non_finite;
            notes.push(format!(
                "{count} vertices whose position, weights or morph displacements are not finite left out"
            ));
        }
        if self.beyond_four > 0 {
            notes.push(format!(
                "{} vertices have more than 4 influences (JOINTS_1/WEIGHTS_1): the 4 strongest are kept, renormalised",
                self.beyond_four
            ));
        }
        if !self.incomplete.is_empty() {
            let places = self.incomplete.join(", ");
            notes
                .push(format!("indices that do not make whole triangles: the incomplete last one left out ({places})"));
        }
        if self.dequantized_by_node > 0 {
            notes.push(format!(
                "{} skinned primitives with quantized positions are bound where their node puts them, as three.js \
                 and Babylon.js bind them (the specification has a skinned mesh ignore its node)",
                self.dequantized_by_node
            ));
        }
        if !self.out_of_range.is_empty() {
            let places: Vec<String> =
                self.out_of_range.iter().map(|(place, dropped)| format!("{dropped} in {place}")).collect();
            notes.push(format!("triangles whose indices pass their vertices left out: {}", places.join(", ")));
        }
        if !self.unread_normals.is_empty() {
            notes.push(format!("normals left out: {}", self.unread_normals.join("; ")));
        }
        if !self.unsupplied.is_empty() {
            notes.push(format!(
                "{NOT_DRAWN_NOTE}their data lies in buffers without a uri (to be supplied by an application): {}",
                self.unsupplied.join(", ")
            ));
        }
        if !self.undecoded.is_empty() {
            let undecoded = self.undecoded.join("; ");
            notes.push(format!("{NOT_DRAWN_NOTE}their compressed geometry does not decode: {undecoded}"));
        }
    }
}

/// The attributes of a primitive's geometry.
const GEOMETRY: [&str; 5] = ["POSITION", "JOINTS_0", "WEIGHTS_0", "JOINTS_1", "WEIGHTS_1"];

/// A buffer without a source in the file that the primitive's geometry needs, if any.
fn unsupplied_buffer(primitive: &schema::Primitive, accessors: &Accessors) -> Option<schema::Uint> {
    let attributes = GEOMETRY.into_iter().filter_map(|a| primitive.attributes.get(a));
    attributes.copied().chain(primitive.indices).find_map(|accessor| accessors.unsupplied_buffer(accessor))
}

/// Decodes what the primitive's geometry holds compressed (a Draco stream, meshopt buffer views), so that a stream
/// that does not decode leaves the primitive out instead of the file.
fn decompress(primitive: &schema::Primitive, accessors: &Accessors, place: &str) -> Result<()> {
    if let Some(compressed) = &primitive.extensions.draco {
        return accessors.supply_draco(primitive, compressed, place);
    }
    let targets = primitive.targets.iter().flat_map(|t| t.values());
    let mut used = primitive.attributes.values().chain(targets).chain(&primitive.indices);
    used.try_for_each(|&accessor| accessors.decodes(accessor, place))
}

/// The transform of each instance `EXT_mesh_gpu_instancing` gives, within its node: `T · R · S`.
fn instances(instancing: &schema::Instancing, accessors: &Accessors, place: &str) -> Result<Vec<DMat4>> {
    let attribute = |name: &str| instancing.attributes.get(name).copied();
    let user = |name: &str| format!("{place}.attributes.{name}");
    let translations = attribute("TRANSLATION").map(|a| accessors.vec3s(a, &user("TRANSLATION"), "TRANSLATION"));
    let rotations = attribute("ROTATION").map(|a| accessors.rotations(a, &user("ROTATION")));
    let scales = attribute("SCALE").map(|a| accessors.vec3s(a, &user("SCALE"), "SCALE"));
    let (translations, rotations, scales) = (translations.transpose()?, rotations.transpose()?, scales.transpose()?);
    let counts = [translations.as_ref().map(Vec::len), rotations.as_ref().map(Vec::len), scales.as_ref().map(Vec::len)];
    let count = counts.iter().flatten().max().copied().unwrap_or(0);
    if counts.iter().flatten().any(|&c| c != count) {
        return Err(Failure::at(place, format!("its attributes hold {counts:?} instances, not one count")));
    }
    Ok((0..count)
        .map(|k| {
            let t = translations.as_ref().map_or(glam::Vec3::ZERO, |t| t[k]);
            let r = rotations.as_ref().map_or(glam::Quat::IDENTITY, |r| r[k].normalize());
            let s = scales.as_ref().map_or(glam::Vec3::ONE, |s| s[k]);
            DMat4::from_scale_rotation_translation(s.as_dvec3(), r.as_dquat(), t.as_dvec3())
        })
        .collect())
}

/// Instance `k` of `mesh`, moved by `transform` within its node: positions, morph displacements and normals.
fn instance(mesh: &Mesh, k: usize, transform: &DMat4) -> Mesh {
    let linear = glam::DMat3::from_mat4(*transform);
    let normal = if linear.determinant() != 0.0 { linear.inverse().transpose() } else { linear };
    let point = |p: &glam::Vec3| transform.transform_point3(p.as_dvec3()).as_vec3();
    let mut moved = Mesh { name: format!("{}#{k}", mesh.name), ..mesh.clone() };
    moved.positions = mesh.positions.iter().map(point).collect();
    moved.normals = mesh.normals.iter().map(|n| (normal * n.as_dvec3()).normalize_or_zero().as_vec3()).collect();
    for target in &mut moved.morph_targets {
        target.offsets.iter_mut().for_each(|o| *o = (linear * o.as_dvec3()).as_vec3());
    }
    moved
}

/// Whether the primitive's `POSITION` is integers (`KHR_mesh_quantization`), which need a transform to mean lengths.
fn quantized_positions(root: &Root, primitive: &schema::Primitive) -> bool {
    let accessor = primitive.attributes.get("POSITION").and_then(|a| root.accessors.get(a.0));
    accessor.is_some_and(|a| DataType::from_code(a.component_type) != Some(DataType::F32))
}

/// Quantized positions of a skinned mesh, put where its node's transform at rest puts them. The specification has
/// a skinned mesh ignore its node, so a quantizer (gltfpack) that puts the dequantization on the node relies on what
/// renderers do: three.js and Babylon.js bind a skinned mesh where its node is when the file is read.
fn dequantize_by_node(positions: &mut [glam::Vec3], skeleton: &Skeleton, bone: usize) {
    let mut node = glam::DMat4::IDENTITY;
    let mut current = Some(bone);
    while let Some(b) = current {
        node = skeleton.bone(b).rest.matrix() * node;
        current = skeleton.parent(b);
    }
    for p in positions {
        *p = node.transform_point3(p.as_dvec3()).as_vec3();
    }
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

/// Reads `JOINTS_0` and `WEIGHTS_0` into `mesh` (with `JOINTS_1` and `WEIGHTS_1`, the four strongest of the eight
/// influences); `false` when the primitive lacks the first set.
fn read_skinning(
    mesh: &mut Mesh,
    primitive: &schema::Primitive,
    accessors: &Accessors,
    skin: &Skin,
    place: &str,
    tally: &mut Tally,
) -> Result<bool> {
    let Some((joints, weights)) = influence_set(primitive, accessors, 0, mesh.positions.len(), place)? else {
        return Ok(false);
    };
    (mesh.joints, mesh.weights) = (joints, weights);
    if let Some((joints, weights)) = influence_set(primitive, accessors, 1, mesh.positions.len(), place)? {
        for (v, (second_joints, second_weights)) in joints.into_iter().zip(weights).enumerate() {
            let (joints, weights, dropped) =
                strongest([mesh.joints[v], second_joints], [mesh.weights[v], second_weights]);
            (mesh.joints[v], mesh.weights[v]) = (joints, weights);
            tally.beyond_four += usize::from(dropped);
        }
    }
    let limit = skin.joints.len();
    if let Some(v) = mesh.joints.iter().position(|j| j.iter().any(|&i| usize::from(i) >= limit)) {
        let message = format!("vertex {v} has joint indices {:?}, but the skin has {limit} joints", mesh.joints[v]);
        return Err(Failure::at(place, message));
    }
    Ok(true)
}

/// Influences per vertex: `JOINTS_set` and `WEIGHTS_set`, one of each per vertex; `None` without them.
type Influences = (Vec<[u16; 4]>, Vec<[f32; 4]>);

/// The influence set `set` of a primitive of `vertices` vertices, if it has one.
fn influence_set(
    primitive: &schema::Primitive,
    accessors: &Accessors,
    set: usize,
    vertices: usize,
    place: &str,
) -> Result<Option<Influences>> {
    let (joints_name, weights_name) = (format!("JOINTS_{set}"), format!("WEIGHTS_{set}"));
    let (Some(&joints), Some(&weights)) =
        (primitive.attributes.get(&joints_name), primitive.attributes.get(&weights_name))
    else {
        return Ok(None);
    };
    let joints = accessors.joints(joints, &format!("{place}.attributes.{joints_name}"))?;
    let weights = accessors.weights(weights, &format!("{place}.attributes.{weights_name}"))?;
    if joints.len() != vertices || weights.len() != vertices {
        let message =
            format!("{vertices} positions but {} {joints_name} and {} {weights_name}", joints.len(), weights.len());
        return Err(Failure::at(place, message));
    }
    Ok(Some((joints, weights)))
}

/// The four strongest of a vertex's eight influences (the model holds four, as FBX's reader keeps them), and whether
/// one with weight was left out; the weights are renormalised with the others afterwards.
fn strongest(joints: [[u16; 4]; 2], weights: [[f32; 4]; 2]) -> ([u16; 4], [f32; 4], bool) {
    let mut all: Vec<(f32, u16)> =
        weights.as_flattened().iter().copied().zip(joints.as_flattened().iter().copied()).collect();
    // Strongest first; a weight that is not a number sorts last, and its vertex is left out later.
    all.sort_by(|a, b| b.0.total_cmp(&a.0));
    let dropped = all[4..].iter().any(|&(w, _)| w != 0.0);
    (std::array::from_fn(|k| all[k].1), std::array::from_fn(|k| all[k].0), dropped)
}

/// The triangle list of a primitive drawn as `mode` (list, strip or fan): the `indices` accessor, or `0..n` without
/// one; an incomplete last triangle of a list is left out, and so is a triangle with an index past the vertices
/// (both noted: the rest of the mesh still shows, as other readers show it).
fn triangle_indices(
    primitive: &schema::Primitive,
    accessors: &Accessors,
    vertices: usize,
    mode: usize,
    place: &str,
    tally: &mut Tally,
) -> Result<Vec<u32>> {
    let mut indices = match primitive.indices {
        Some(accessor) => accessors.indices(accessor, &format!("{place}.indices"))?,
        None => {
            let n = u32::try_from(vertices).map_err(|_| Failure::at(place, "too many vertices"))?;
            (0..n).collect()
        }
    };
    let triangles = match mode {
        TRIANGLE_STRIP => strip_triangles(&indices),
        TRIANGLE_FAN => fan_triangles(&indices),
        _ => {
            if !indices.len().is_multiple_of(3) {
                tally.incomplete.push(place.to_owned());
                indices.truncate(indices.len() - indices.len() % 3);
            }
            indices
        }
    };
    let inside = |triangle: &[u32]| triangle.iter().all(|&i| (i as usize) < vertices);
    let kept: Vec<u32> = triangles.chunks_exact(3).filter(|t| inside(t)).flatten().copied().collect();
    let dropped = (triangles.len() - kept.len()) / 3;
    if dropped > 0 {
        tally.out_of_range.push((place.to_owned(), dropped));
    }
    Ok(kept)
}

/// A triangle strip as a list: triangle `i` is `v[i], v[i+(1+i%2)], v[i+(2−i%2)]` (the glTF specification's: every
/// other one turned back, so all keep the first one's winding).
fn strip_triangles(strip: &[u32]) -> Vec<u32> {
    (0..strip.len().saturating_sub(2)).flat_map(|i| [strip[i], strip[i + 1 + i % 2], strip[i + 2 - i % 2]]).collect()
}

/// A triangle fan as a list: triangle `i` is `v[i+1], v[i+2], v[0]` (the glTF specification's order).
fn fan_triangles(fan: &[u32]) -> Vec<u32> {
    (1..fan.len().saturating_sub(1)).flat_map(|i| [fan[i], fan[i + 1], fan[0]]).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn strips_and_fans_become_lists_in_the_specification_order() {
        assert_eq!(strip_triangles(&[0, 1, 2, 3, 4]), [0, 1, 2, 1, 3, 2, 2, 3, 4]);
        assert_eq!(fan_triangles(&[0, 1, 2, 3]), [1, 2, 0, 2, 3, 0]);
        assert!(
            strip_triangles(&[0, 1]).is_empty() && fan_triangles(&[0, 1]).is_empty() && fan_triangles(&[]).is_empty()
        );
    }

    #[test]
    fn the_four_strongest_of_eight_influences_are_kept() {
        let (joints, weights, dropped) =
            strongest([[0, 1, 2, 3], [4, 5, 6, 7]], [[0.1, 0.3, 0.0, 0.05], [0.2, 0.0, 0.25, 0.1]]);
        assert_eq!(joints, [1, 6, 4, 0]);
        assert_eq!(weights, [0.3, 0.25, 0.2, 0.1]);
        assert!(dropped, "0.1 of joint 7 and 0.05 of joint 3 are left out");
        let (_, _, dropped) = strongest([[0, 1, 0, 0], [2, 0, 0, 0]], [[0.5, 0.25, 0.0, 0.0], [0.25, 0.0, 0.0, 0.0]]);
        assert!(!dropped);
    }
}
