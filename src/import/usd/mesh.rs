//! Meshes, and the skins UsdSkel binds them with. A `Mesh` prim's points at the start time code, its faces made
//! triangle fans. Bound to a skeleton of the stage (`skel:skeleton` on it or an ancestor, with `SkelBindingAPI`
//! applied), it is skinned as UsdSkel skins: by the joints its `skel:joints` names (else the skeleton's), each point
//! by the `elementSize` influences `primvars:skel:jointIndices`/`jointWeights` give it (one set for every point where
//! their interpolation is `constant`), the four strongest kept and renormalised, from the space
//! `primvars:skel:geomBindTransform` puts it in: a joint's inverse bind matrix is `bindTransforms⁻¹ · geomBind`.
//! `primvars:skel:skinningMethod` `dualQuaternion` (on it or an ancestor) skins it with dual quaternions. Its blend
//! shapes deform it first ([`blend`]). An unbound mesh, or one without joint influences, hangs rigid on a node of its
//! own where its transform puts it.

use glam::{DMat4, Vec3};
use openusd::schemas::geom::{Mesh as UsdMesh, PointBased};
use openusd::schemas::skel::{InfluenceInterpolation, SkelBindingAPI, SkinningMethod};
use openusd::sdf::{self, Value};
use openusd::usd::{Attribute, Stage, TimeCode};

use super::blend;
use super::skeleton::{Placed, moving_node, transform, world_transform};
use super::{Timing, said};
use crate::model::{Bone, BoneTracks, Mesh, MorphWeights, NodeRole, Skin};

/// A mesh read: itself, the skin it is bound with, the node it hangs on where it needs one, and its animated
/// blend-shape weights.
pub struct Read {
    pub mesh: Mesh,
    pub skin: Option<Skin>,
    pub node: Option<Bone>,
    /// Where its node moves, that node's track.
    pub moving: Option<BoneTracks>,
    pub morph: Option<MorphWeights>,
}

/// The mesh at `path`; `bones` the rig's bones so far (its node, where it needs one, comes next), `skin_index` the
/// index its skin will have; `skeletons` where each skeleton of the stage was placed. `None` for a mesh without
/// points.
///
/// A skinned mesh hangs on its skeleton's node (skinning places it); one with blend shapes, whose weights are a
/// node's, or one not skinned hangs on a node of its own, where its transform puts it.
pub fn read(
    stage: &Stage,
    path: &sdf::Path,
    bones: usize,
    skin_index: usize,
    skeletons: &[Placed],
    timing: &Timing,
) -> Result<Option<Read>, String> {
    let start = timing.start;
    let mesh = UsdMesh::get(stage, path.clone()).map_err(said)?.ok_or("not a Mesh")?;
    let at_start = |attribute: Attribute| attribute.get_at::<Value>(TimeCode::new(start)).map_err(said);
    let positions = points(at_start(mesh.points_attr())?);
    if positions.is_empty() {
        return Ok(None);
    }
    let counts = int_array(at_start(mesh.face_vertex_counts_attr())?);
    let indices = int_array(at_start(mesh.face_vertex_indices_attr())?);
    let name = match super::skeleton::written(openusd::usd::SchemaBase::prim(&mesh), "name") {
        Some(openusd::sdf::Value::String(name)) => name,
        Some(openusd::sdf::Value::Token(name)) => name.as_str().to_owned(),
        _ => path.name().unwrap_or("Mesh").to_owned(),
    };
    let triangles = fans(&counts, &indices, positions.len());
    let mut read = Mesh { name: name.clone(), positions, indices: triangles, ..Mesh::default() };
    let api = SkelBindingAPI::get(stage, path.clone()).map_err(said)?;
    let bound = api.map(|api| binding(api, skeletons)).transpose()?.flatten();
    let shapes = match &bound {
        Some((api, placed)) => blend::read(stage, api, read.positions.len(), placed.weights.as_ref())?,
        None => None,
    };
    let skin = match &bound {
        Some((api, placed)) if has_influences(api)? => Some(skin(stage, path, api, placed, &mut read)?),
        _ => None,
    };
    let own_node = skin.is_none() || shapes.is_some();
    let bone = match &bound {
        Some((_, placed)) if !own_node => placed.node,
        _ => bones,
    };
    let node = own_node
        .then(|| -> Result<Bone, String> {
            let world = world_transform(stage, path, start)?;
            Ok(Bone { node: bones, role: NodeRole::Mesh, ..Bone::joint(name, None, transform(&world)) })
        })
        .transpose()?;
    let moving = if own_node { moving_node(stage, path, bones, timing)? } else { None };
    let mut morph = None;
    if let Some(shapes) = shapes {
        read.morph_weights = vec![0.0; shapes.targets.len()];
        read.morph_targets = shapes.targets;
        morph = (!shapes.weights.is_empty()).then_some(MorphWeights { bone, weights: shapes.weights });
    }
    let mesh = Mesh { bone, skin: skin.is_some().then_some(skin_index), ..read };
    Ok(Some(Read { mesh, skin, node, moving, morph }))
}

/// The skin of a mesh bound to `placed` with joint influences, its joints and weights set on `read`.
fn skin(
    stage: &Stage,
    path: &sdf::Path,
    api: &SkelBindingAPI,
    placed: &Placed,
    read: &mut Mesh,
) -> Result<Skin, String> {
    let joints = mesh_joints(api, placed)?;
    (read.joints, read.weights) = influences(api, read.positions.len(), joints.len())?.into_iter().unzip();
    if skinning_method(stage, path)? == Some(SkinningMethod::DualQuaternion) {
        read.dq_weights = vec![1.0; read.positions.len()];
    }
    let geom_bind = api.geom_bind_transform().map_err(said)?.map_or(DMat4::IDENTITY, |m| DMat4::from_cols_array(&m.0));
    let inverse_bind = joints.iter().map(|&j| placed.bind.get(j).map_or(geom_bind, |b| b.inverse() * geom_bind));
    Ok(Skin {
        name: Some(read.name.clone()),
        joints: joints.iter().map(|&j| placed.node + 1 + j).collect(),
        inverse_bind: inverse_bind.collect(),
        node_bind: None,
    })
}

/// The nearest `primvars:skel:skinningMethod` on the prim at `path` or an ancestor (a constant primvar, inherited
/// down namespace: a SkelRoot may set it for every mesh below).
fn skinning_method(stage: &Stage, path: &sdf::Path) -> Result<Option<SkinningMethod>, String> {
    let mut current = Some(path.clone());
    while let Some(prim) = current.filter(|p| !p.is_abs_root()) {
        let attribute = stage.prim(prim.clone()).attribute("primvars:skel:skinningMethod");
        if let Some(method) = attribute.get::<SkinningMethod>().map_err(said)? {
            return Ok(Some(method));
        }
        current = prim.parent();
    }
    Ok(None)
}

/// The skeleton a mesh's binding names (on it or inherited), among the placed ones; `None` where it names none of
/// them.
fn binding(api: SkelBindingAPI, skeletons: &[Placed]) -> Result<Option<(SkelBindingAPI, &Placed)>, String> {
    let Some(skeleton) = api.inherited_skeleton().map_err(said)? else { return Ok(None) };
    Ok(skeletons.iter().find(|p| p.path == skeleton).map(|placed| (api, placed)))
}

/// Whether the binding gives joint influences (without them, UsdSkel leaves the points to the blend shapes alone).
fn has_influences(api: &SkelBindingAPI) -> Result<bool, String> {
    Ok(!api.joint_indices().map_err(said)?.is_empty() || !api.joint_weights().map_err(said)?.is_empty())
}

/// The skeleton's joints (indices into its `joints`) the mesh's influences index: its own `skel:joints`, by path,
/// else the skeleton's order.
fn mesh_joints(api: &SkelBindingAPI, placed: &Placed) -> Result<Vec<usize>, String> {
    let subset = api.joint_subset().map_err(said)?;
    if subset.is_empty() {
        return Ok((0..placed.joints.len()).collect());
    }
    subset
        .iter()
        .map(|name| {
            let found = placed.joints.iter().position(|j| j == name);
            found.ok_or_else(|| format!("skel:joints names `{name}`, which is not a joint of {}", placed.path.as_str()))
        })
        .collect()
}

/// A point's four joints (indices into the mesh's) and their weights.
type Influences = ([u16; 4], [f32; 4]);

/// Per point, its four strongest influences (indices into the mesh's joints) and their weights renormalised; a point
/// whose indices leave the joints, or whose weights are not finite, keeps the ones that do not.
fn influences(api: &SkelBindingAPI, points: usize, joints: usize) -> Result<Vec<Influences>, String> {
    let per = usize::try_from(api.elements_per_element().map_err(said)?).unwrap_or(0).max(1);
    let (indices, weights) = (api.joint_indices().map_err(said)?, api.joint_weights().map_err(said)?);
    let constant = api.interpolation().map_err(said)? == InfluenceInterpolation::Constant;
    let sets = if constant { 1 } else { points };
    if indices.len() != sets * per || weights.len() != sets * per {
        return Err(format!(
            "{} joint indices and {} weights for {sets} × {per} influences",
            indices.len(),
            weights.len()
        ));
    }
    let set = |k: usize| {
        let mut pairs: Vec<(u16, f32)> = (k * per..(k + 1) * per)
            .filter_map(|i| {
                let joint = usize::try_from(indices[i]).ok().filter(|&j| j < joints && j <= usize::from(u16::MAX))?;
                Some((joint as u16, weights[i])).filter(|(_, w)| w.is_finite() && *w > 0.0)
            })
            .collect();
        pairs.sort_by(|a, b| b.1.total_cmp(&a.1));
        pairs.truncate(4);
        let total: f32 = pairs.iter().map(|(_, w)| w).sum();
        let (mut joint, mut weight) = ([0u16; 4], [0f32; 4]);
        for (slot, (j, w)) in pairs.into_iter().enumerate() {
            (joint[slot], weight[slot]) = (j, if total > 0.0 { w / total } else { 0.0 });
        }
        (joint, weight)
    };
    Ok((0..points).map(|p| set(if constant { 0 } else { p })).collect())
}

/// A `point3f[]` (or `point3d[]`) as positions; empty for anything else.
fn points(value: Option<Value>) -> Vec<Vec3> {
    match value {
        Some(Value::Vec3fVec(points)) => points.iter().map(|p| Vec3::new(p.x, p.y, p.z)).collect(),
        Some(Value::Vec3dVec(points)) => points.iter().map(|p| Vec3::new(p.x as f32, p.y as f32, p.z as f32)).collect(),
        _ => Vec::new(),
    }
}

/// An `int[]`; empty for anything else.
fn int_array(value: Option<Value>) -> Vec<i32> {
    match value {
        Some(Value::IntVec(values)) => values,
        _ => Vec::new(),
    }
}

/// The faces, `counts[f]` indices each, as triangle fans; a face with fewer than three corners, one that runs past
/// the indices, or one with a corner past the points is left out.
fn fans(counts: &[i32], indices: &[i32], points: usize) -> Vec<u32> {
    let mut triangles = Vec::new();
    let mut start = 0usize;
    for &count in counts {
        let Ok(count) = usize::try_from(count) else { break };
        let Some(face) = indices.get(start..start + count) else { break };
        start += count;
        let corners: Option<Vec<u32>> =
            face.iter().map(|&i| u32::try_from(i).ok().filter(|&i| (i as usize) < points)).collect();
        let Some(corners) = corners.filter(|c| c.len() >= 3) else { continue };
        for k in 1..corners.len() - 1 {
            triangles.extend([corners[0], corners[k], corners[k + 1]]);
        }
    }
    triangles
}
