//! CPU skinning: a mesh's vertex positions at an evaluated pose.
//!
//! The joint matrix of joint `j` is `W_j · IBM_j` (model matrix of the joint's bone times its inverse bind matrix).
//! - Linear blend skinning, as glTF and FBX define it: a vertex moves to `Σ w_j · (W_j · IBM_j) · v`.
//! - Dual-quaternion skinning (Kavan et al. 2008), which FBX declares per skin (and per vertex, blended with linear):
//!   each joint matrix is split by the polar decomposition into a rigid part `T_j · R_j` and a stretch
//!   `S_j = R_jᵀ · A_j` (scale and shear, `A_j` the linear part); the rigid parts are blended as unit dual
//!   quaternions, the stretches linearly, and the vertex moves to `T · R · (Σ w_j S_j) · v`. This is exact wherever
//!   linear blending is (one influence, or influences that agree), keeps volume under twists where linear blending
//!   collapses, and equals Maya's and ufbx's "dual quaternion with scale" whenever the joint matrices do not shear
//!   (ufbx blends per-axis scales, which cannot carry shear; with shear, bonescope's blend keeps it).
//!   A vertex with DQ weight `d` gets `(1 − d) · linear + d · dual quaternion`.
//!
//! The skinned mesh's own node does not move it (glTF: "the skinned mesh node's own transform MUST be ignored"),
//! except for skins that follow their node ([`crate::model::NodeBind`], Maya). An unskinned mesh is placed by its
//! bone's model matrix. Pure functions over slices, in `f64`, so the viewport and the exporter share them.

use glam::{DMat3, DMat4, DQuat, DVec3};

use super::MorphPose;
use crate::math::{decompose, largest_column_cosine, shear_deg_of_cosine};
use crate::model::{Choice, Mesh, Rig, Skin};

/// Which skinning to use: the file's (per skin and vertex), or one of them everywhere (engines differ).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Method {
    /// What the file declares: linear, dual quaternion, or a per-vertex blend of both.
    #[default]
    AsFile,
    Linear,
    DualQuaternion,
}

impl Choice for Method {
    const ALL: &'static [Method] = &[Method::AsFile, Method::Linear, Method::DualQuaternion];

    fn id(self) -> &'static str {
        match self {
            Method::AsFile => "as-file",
            Method::Linear => "linear",
            Method::DualQuaternion => "dual-quaternion",
        }
    }

    fn description(self) -> &'static str {
        match self {
            Method::AsFile => "what the file declares: linear, dual quaternion, or a per-vertex blend of both",
            Method::Linear => "linear blend skinning everywhere",
            Method::DualQuaternion => "dual quaternion skinning everywhere",
        }
    }
}

impl Method {
    pub fn label(self) -> &'static str {
        match self {
            Method::AsFile => "as the file says",
            Method::Linear => "linear blend",
            Method::DualQuaternion => "dual quaternion",
        }
    }

    /// The blend towards dual quaternions of vertex `v` of `mesh`.
    fn dq_weight(self, mesh: &Mesh, v: usize) -> f64 {
        match self {
            Method::AsFile => mesh.dq_weights.get(v).map_or(0.0, |&d| f64::from(d.clamp(0.0, 1.0))),
            Method::Linear => 0.0,
            Method::DualQuaternion => 1.0,
        }
    }
}

/// `W_j · IBM_j` for every joint of `skin`, from the model matrices of all bones; premultiplied by the mesh node's
/// motion since the bind where the skin follows its node ([`crate::model::NodeBind`]).
pub fn joint_matrices(skin: &Skin, model: &[DMat4], out: &mut Vec<DMat4>) {
    out.clear();
    let moved = moved_since_bind(skin, model);
    out.extend((0..skin.joints.len()).map(|j| joint_matrix(skin, model, moved, j)));
}

/// The mesh node's motion since the bind, where the skin follows its node.
fn moved_since_bind(skin: &Skin, model: &[DMat4]) -> Option<DMat4> {
    skin.node_bind.map(|node| model[node.bone] * node.inverse_bind)
}

/// The joint matrix of joint `j` of `skin`, given [`moved_since_bind`].
fn joint_matrix(skin: &Skin, model: &[DMat4], moved: Option<DMat4>, j: usize) -> DMat4 {
    let joint = model[skin.joints[j]] * skin.inverse_bind[j];
    moved.map_or(joint, |moved| moved * joint)
}

/// How far the vertices of a linearly skinned mesh can lie apart under two poses, bounded from their joints alone.
/// A vertex bound at `p` lands at `Σ w_j·J_j·p`, so two poses put it at most `Σ|w_j| · max_j |(J_j − J′_j)·p|` apart,
/// and `|(J − J′)·p|` is convex in `p`: over the box of the vertices weighted to a joint it is largest at a corner.
/// Lets a comparison skip skinning where the bound says nothing can move further than what it has already seen.
#[derive(Clone, Debug, PartialEq)]
pub struct Reach {
    /// Per joint some vertex is weighted to (a skin's joint index, or the mesh's bone for an unskinned mesh), the
    /// points that bound those vertices' distances ([`Hull`]), through the joint's inverse bind where skinned.
    joints: Vec<(usize, Hull)>,
    /// The largest `Σ|w_j|` of a vertex (1 unskinned).
    weight: f64,
    skin: Option<usize>,
}

impl Reach {
    /// The reach of `vertices` of `mesh` (every one for `None`) skinned by `method`; `None` where the bound does
    /// not hold: morph targets (the bind positions move), a dual-quaternion blend, vertices that are not finite.
    pub fn of(mesh: &Mesh, skins: &[Skin], method: Method, vertices: Option<&[u32]>) -> Option<Reach> {
        if !mesh.morph_targets.is_empty() {
            return None;
        }
        let chosen: Vec<usize> = match vertices {
            Some(list) => list.iter().map(|&v| v as usize).filter(|&v| v < mesh.positions.len()).collect(),
            None => (0..mesh.positions.len()).collect(),
        };
        let position = |v: usize| Some(mesh.positions[v].as_dvec3()).filter(|p| p.is_finite());
        let skin = mesh.skin.filter(|&s| s < skins.len() && mesh.joints.len() == mesh.positions.len());
        let Some(skin) = skin else {
            let mut hull = Hull::default();
            for &v in &chosen {
                hull.add(position(v)?);
            }
            return Some(Reach { joints: vec![(mesh.bone, hull.closed()?)], weight: 1.0, skin: None });
        };
        let mut hulls: Vec<Hull> = vec![Hull::default(); skins[skin].joints.len()];
        let mut weight: f64 = 0.0;
        for v in chosen {
            if method.dq_weight(mesh, v) != 0.0 {
                return None;
            }
            let (p, weights) = (position(v)?, mesh.weights.get(v)?);
            let influences = mesh.joints[v].iter().zip(weights).filter(|(_, w)| **w != 0.0);
            let mut sum = 0.0;
            for (&j, &w) in influences {
                hulls.get_mut(usize::from(j))?.add(p);
                sum += f64::from(w).abs();
            }
            weight = weight.max(sum);
        }
        // Each joint's points carried through its inverse bind once: `(J − J′)·p = (W − W′)·(IBM·p)`.
        let inverse_bind = &skins[skin].inverse_bind;
        let closed = hulls.into_iter().enumerate().filter_map(|(j, hull)| Some((j, hull.closed()?)));
        let joints = closed.map(|(j, hull)| Some((j, hull.mapped(inverse_bind.get(j)?)))).collect::<Option<_>>()?;
        Some(Reach { joints, weight, skin: Some(skin) })
    }

    /// The most any of the vertices lies apart under the poses whose model matrices (of every bone) are `a` and `b`.
    pub fn bound(&self, skins: &[Skin], a: &[DMat4], b: &[DMat4]) -> f64 {
        let skin = self.skin.map(|s| &skins[s]);
        let moved = skin.map(|skin| (moved_since_bind(skin, a), moved_since_bind(skin, b)));
        let joints = self.joints.iter().map(|(joint, hull)| {
            let difference = match (skin, moved) {
                // A − B, nothing where the joint does not move (a variant's joints above it).
                (Some(skin), Some((None, None))) => {
                    let bone = skin.joints[*joint];
                    if a[bone] == b[bone] {
                        return 0.0;
                    }
                    a[bone] - b[bone]
                }
                (Some(skin), Some((moved_a, moved_b))) => {
                    let bone = skin.joints[*joint];
                    let posed = |model: &[DMat4], moved: Option<DMat4>| moved.map_or(model[bone], |m| m * model[bone]);
                    posed(a, moved_a) - posed(b, moved_b)
                }
                _ => a[*joint] - b[*joint],
            };
            hull.apart(&difference)
        });
        self.weight * joints.fold(0.0, f64::max)
    }
}

/// The points whose distances under a joint's motion bound those of every vertex weighted to it: the vertices
/// themselves while there are at most eight, else the eight corners of their box.
#[derive(Clone, Debug, Default, PartialEq)]
struct Hull {
    /// The first eight vertices (or fewer, the rest unused), and the box of them all.
    points: [DVec3; 8],
    count: usize,
    low: DVec3,
    high: DVec3,
}

impl Hull {
    fn add(&mut self, p: DVec3) {
        if let Some(slot) = self.points.get_mut(self.count) {
            *slot = p;
        }
        (self.low, self.high) = match self.count {
            0 => (p, p),
            _ => (self.low.min(p), self.high.max(p)),
        };
        self.count += 1;
    }

    /// The hull once every vertex is added: its points are the box's corners where there are more than eight;
    /// `None` for no vertex.
    fn closed(mut self) -> Option<Self> {
        if self.count > self.points.len() {
            (self.points, self.count) = (box_corners((self.low, self.high)), self.points.len());
        }
        (self.count > 0).then_some(self)
    }

    /// The hull of the points carried by `m` (an affine map keeps a point inside the hull of the others' images).
    fn mapped(mut self, m: &DMat4) -> Self {
        for p in &mut self.points[..self.count] {
            *p = m.transform_point3(*p);
        }
        self
    }

    /// How far `difference` (`J − J′`) moves the farthest point.
    fn apart(&self, difference: &DMat4) -> f64 {
        let points = &self.points[..self.count];
        points.iter().map(|&p| (*difference * p.extend(1.0)).truncate().length()).fold(0.0, f64::max)
    }
}

/// The eight corners of the box from `low` to `high`.
fn box_corners((low, high): (DVec3, DVec3)) -> [DVec3; 8] {
    std::array::from_fn(|k| {
        let pick = |bit: usize, l: f64, h: f64| if k & bit == 0 { l } else { h };
        DVec3::new(pick(1, low.x, high.x), pick(2, low.y, high.y), pick(4, low.z, high.z))
    })
}

/// The positions of `mesh` in model space, given the model matrices of all bones (`out` is reused), skinned as the
/// file says.
///
/// Weights are used as stored (importers keep them normalised); joints whose weight is zero are skipped.
pub fn skin_positions(mesh: &Mesh, skins: &[Skin], model: &[DMat4], morph: &MorphPose, out: &mut Vec<DVec3>) {
    skin_positions_with(mesh, skins, model, morph, Method::AsFile, out);
}

/// [`skin_positions`] with the skinning `method` chosen.
pub fn skin_positions_with(
    mesh: &Mesh,
    skins: &[Skin],
    model: &[DMat4],
    morph: &MorphPose,
    method: Method,
    out: &mut Vec<DVec3>,
) {
    out.clear();
    Skinner::new(mesh, skins, None).skin(mesh, skins, (model, morph), method, out);
}

/// Skins some vertices of one mesh time after time (every vertex for `None`), as [`skin_positions_with`] skins them
/// all: the joints they are weighted to found once, and only those joints' matrices computed at each time. A
/// comparison that knows the other vertices cannot move skins only these.
#[derive(Clone, Debug)]
pub struct Skinner {
    /// The vertices skinned, those in range; every one for `None`.
    vertices: Option<Vec<u32>>,
    /// The joints of the mesh's skin those vertices are weighted to (any weight but zero), each once; every joint
    /// for `None`.
    used: Option<Vec<usize>>,
    /// The joint matrices at the time skinned, indexed as the skin's joints (those not used are not kept up).
    joints: Vec<DMat4>,
}

impl Skinner {
    /// For `vertices` of `mesh` (skinned by one of `skins`, where it is).
    pub fn new(mesh: &Mesh, skins: &[Skin], vertices: Option<Vec<u32>>) -> Self {
        let count = mesh.positions.len();
        let vertices = vertices.map(|list| list.into_iter().filter(|&v| (v as usize) < count).collect::<Vec<_>>());
        let joints = skin_of(mesh, skins).map_or(0, |skin| skin.joints.len());
        let used = vertices.as_ref().filter(|_| joints > 0).map(|list| {
            let mut used = vec![false; joints];
            for &v in list {
                let weighted = mesh.joints[v as usize].iter().zip(mesh.weights.get(v as usize).into_iter().flatten());
                for (&j, _) in weighted.filter(|(_, w)| **w != 0.0) {
                    if let Some(slot) = used.get_mut(usize::from(j)) {
                        *slot = true;
                    }
                }
            }
            (0..joints).filter(|&j| used[j]).collect()
        });
        let joints = if used.is_some() { vec![DMat4::IDENTITY; joints] } else { Vec::new() };
        Skinner { vertices, used, joints }
    }

    /// The vertices at `posed` (the model matrices, meaningful at least at the joints of the vertices, and the morph
    /// weights) skinned by `method`, into `out` (one position per vertex of the mesh; the others left as they were).
    pub fn skin(
        &mut self,
        mesh: &Mesh,
        skins: &[Skin],
        (model, morph): (&[DMat4], &MorphPose),
        method: Method,
        out: &mut Vec<DVec3>,
    ) {
        let positions = morph.positions(mesh);
        out.resize(positions.len(), DVec3::ZERO);
        let vertices = self.vertices.as_deref();
        let each = |visit: &mut dyn FnMut(usize)| match vertices {
            Some(list) => list.iter().map(|&v| v as usize).for_each(visit),
            None => (0..positions.len()).for_each(visit),
        };
        let Some(skin) = skin_of(mesh, skins) else {
            let placement = model[mesh.bone];
            each(&mut |v| out[v] = placement.transform_point3(positions[v].as_dvec3()));
            return;
        };
        let moved = moved_since_bind(skin, model);
        match &self.used {
            Some(used) => used.iter().for_each(|&j| self.joints[j] = joint_matrix(skin, model, moved, j)),
            None => joint_matrices(skin, model, &mut self.joints),
        }
        let joints = &self.joints;
        let mut any_dq = false;
        each(&mut |v| any_dq |= method.dq_weight(mesh, v) > 0.0);
        let rigid: Vec<RigidStretch> = if any_dq { joints.iter().map(RigidStretch::of).collect() } else { Vec::new() };
        each(&mut |v| {
            let Some(influences) = influences(mesh, v) else { return };
            let p = positions[v].as_dvec3();
            let dq = method.dq_weight(mesh, v);
            let linear = || influences.clone().map(|(j, w)| joints[j].transform_point3(p) * w).sum::<DVec3>();
            out[v] = match dq {
                0.0 => linear(),
                1.0 => dual_quaternion(&rigid, influences, p),
                d => linear() * (1.0 - d) + dual_quaternion(&rigid, influences, p) * d,
            };
        });
    }
}

/// The joints vertex `v` of `mesh` is weighted to, with their weights (zero weights skipped); `None` past the end of
/// the weights (importers keep them as long as the joints: a shorter list skins the vertices it covers).
fn influences(mesh: &Mesh, v: usize) -> Option<impl Iterator<Item = (usize, f64)> + Clone + '_> {
    let weights = mesh.weights.get(v)?;
    Some(mesh.joints[v].iter().zip(weights).filter(|(_, w)| **w != 0.0).map(|(&j, &w)| (usize::from(j), f64::from(w))))
}

/// The skin of `mesh` among `skins`, where it has one with a joint list per vertex.
fn skin_of<'s>(mesh: &Mesh, skins: &'s [Skin]) -> Option<&'s Skin> {
    mesh.skin.and_then(|s| skins.get(s)).filter(|_| mesh.joints.len() == mesh.positions.len())
}

/// A joint matrix split for dual-quaternion blending: rotation `R`, the dual part `½·t·R`, and the stretch `Rᵀ·A`.
struct RigidStretch {
    real: DQuat,
    dual: DQuat,
    stretch: DMat3,
}

impl RigidStretch {
    fn of(m: &DMat4) -> Self {
        let linear = DMat3::from_mat4(*m);
        let real = decompose(m).rotation.normalize();
        let t = m.w_axis.truncate();
        let dual = DQuat::from_xyzw(0.5 * t.x, 0.5 * t.y, 0.5 * t.z, 0.0) * real;
        RigidStretch { real, dual, stretch: DMat3::from_quat(real).transpose() * linear }
    }
}

/// A blend of joints by dual quaternions: the unit rigid part (rotation and translation) and the blended stretch.
struct DualBlend {
    rotation: DQuat,
    translation: DVec3,
    stretch: DMat3,
}

impl DualBlend {
    /// Kavan's blend of the rigid parts (signs aligned with the first influence, so the blend takes the short way)
    /// with the stretches blended linearly; `None` for no weight.
    fn of(joints: &[RigidStretch], influences: impl Iterator<Item = (usize, f64)>) -> Option<Self> {
        let (mut real, mut dual, mut stretch) =
            (DQuat::from_xyzw(0.0, 0.0, 0.0, 0.0), DQuat::from_xyzw(0.0, 0.0, 0.0, 0.0), DMat3::ZERO);
        let (mut first, mut total): (Option<DQuat>, f64) = (None, 0.0);
        for (j, w) in influences {
            total += w;
            let joint = &joints[j];
            let reference = *first.get_or_insert(joint.real);
            let w_signed = if reference.dot(joint.real) < 0.0 { -w } else { w };
            real += joint.real * w_signed;
            dual += joint.dual * w_signed;
            stretch += joint.stretch * w;
        }
        let length = real.length();
        if length == 0.0 || total == 0.0 {
            return None;
        }
        // Unit dual quaternion, and the stretch over the weights' sum (stored weights may sum to 1 ± 1e-7).
        let (real, dual) = (real / length, dual / length);
        // t = 2 · dual · real*, the translation of a unit dual quaternion.
        let t = dual * real.conjugate() * 2.0;
        Some(DualBlend { rotation: real, translation: DVec3::new(t.x, t.y, t.z), stretch: stretch / total })
    }
}

/// `p` skinned by the dual-quaternion blend of `influences` (left where it is for no weight).
fn dual_quaternion(joints: &[RigidStretch], influences: impl Iterator<Item = (usize, f64)>, p: DVec3) -> DVec3 {
    DualBlend::of(joints, influences).map_or(p, |b| b.rotation * (b.stretch * p) + b.translation)
}

/// The shear each vertex of `mesh` carries at the pose `model` (the model matrices of all bones), in degrees: its
/// joints' own shear ([`crate::analysis::Assessment::shear_deg`]: the largest deviation from 90° between the columns
/// of the joint's model matrix), weighted as the vertex is. A vertex weighted to one bone reads exactly that bone's
/// shear, and no vertex reads any where no bone shears: a linear blend of two differently turned joints is no
/// rotation either, but that is the skinning's own squash, found wherever joints bend, not a scale's shear. An
/// unskinned mesh has its bone's shear throughout; morph targets move the positions and change no vertex's shear.
pub fn vertex_shears(mesh: &Mesh, skins: &[Skin], model: &[DMat4]) -> Vec<f64> {
    let count = mesh.positions.len();
    let bone_shear = |bone: usize| model.get(bone).map_or(0.0, |m| column_shear_deg(&DMat3::from_mat4(*m)));
    let Some(skin) = skin_of(mesh, skins) else {
        return vec![bone_shear(mesh.bone); count];
    };
    let joints: Vec<f64> = skin.joints.iter().map(|&bone| bone_shear(bone)).collect();
    let shear = |v: usize| {
        let influences = influences(mesh, v)?.filter(|&(j, _)| j < joints.len());
        let (sum, total) = influences.fold((0.0, 0.0), |(sum, total), (j, w)| (sum + w * joints[j], total + w));
        (total > 0.0).then(|| sum / total)
    };
    (0..count).map(|v| shear(v).unwrap_or(0.0)).collect()
}

/// The largest deviation from 90° between two columns of `m`, in degrees.
fn column_shear_deg(m: &DMat3) -> f64 {
    shear_deg_of_cosine(largest_column_cosine(m))
}

/// [`vertex_shears`] of every mesh of the rig at the pose `model`.
pub fn skin_shears(rig: &Rig, model: &[DMat4]) -> Vec<Vec<f64>> {
    rig.meshes.iter().map(|mesh| vertex_shears(mesh, &rig.skins, model)).collect()
}

/// Every mesh of the rig morphed and skinned at the pose `model` (one vector of positions per mesh), as the file
/// says.
pub fn skin_meshes(rig: &Rig, model: &[DMat4], morph: &MorphPose) -> Vec<Vec<DVec3>> {
    skin_meshes_with(rig, model, morph, Method::AsFile)
}

/// [`skin_meshes`] with the skinning `method` chosen.
pub fn skin_meshes_with(rig: &Rig, model: &[DMat4], morph: &MorphPose, method: Method) -> Vec<Vec<DVec3>> {
    rig.meshes
        .iter()
        .map(|mesh| {
            let mut out = Vec::new();
            skin_positions_with(mesh, &rig.skins, model, morph, method, &mut out);
            out
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use glam::{DQuat, Vec3};

    use super::*;

    #[test]
    fn unskinned_meshes_follow_their_bone() {
        let mesh = Mesh { bone: 1, positions: vec![Vec3::new(1.0, 0.0, 0.0)], ..Mesh::default() };
        let model = [DMat4::IDENTITY, DMat4::from_translation(DVec3::new(0.0, 2.0, 0.0))];
        let mut out = Vec::new();
        skin_positions(&mesh, &[], &model, &MorphPose::default(), &mut out);
        assert_eq!(out, vec![DVec3::new(1.0, 2.0, 0.0)]);
    }

    #[test]
    fn linear_blend_of_two_joints() {
        // Joint 0: bone 0 moved +2 in X, bound at the origin. Joint 1: bone 1 turned 90° about Z, bound 1 up in Y.
        // v = (1, 1, 0): joint 0 gives (3, 1, 0); joint 1 gives Rz(90°)·(v − (0, 1, 0)) = Rz·(1, 0, 0) = (0, 1, 0).
        // Weights 0.25 / 0.75: (0.75, 0.25, 0) + (0, 0.75, 0) = (0.75, 1, 0).
        let skin = Skin {
            name: None,
            joints: vec![0, 1],
            inverse_bind: vec![DMat4::IDENTITY, DMat4::from_translation(DVec3::new(0.0, -1.0, 0.0))],
            node_bind: None,
        };
        let mesh = Mesh {
            bone: 0,
            skin: Some(0),
            positions: vec![Vec3::new(1.0, 1.0, 0.0)],
            joints: vec![[0, 1, 0, 0]],
            weights: vec![[0.25, 0.75, 0.0, 0.0]],
            ..Mesh::default()
        };
        let model = [
            DMat4::from_translation(DVec3::new(2.0, 0.0, 0.0)),
            DMat4::from_quat(DQuat::from_rotation_z(std::f64::consts::FRAC_PI_2)),
        ];
        let mut out = Vec::new();
        skin_positions(&mesh, &[skin], &model, &MorphPose::default(), &mut out);
        assert!(out[0].abs_diff_eq(DVec3::new(0.75, 1.0, 0.0), 1e-12), "{:?}", out[0]);
    }

    /// One vertex at `p` bound to two joints (bones 0 and 1, bound at the origin) with weights `w0`, `w1`.
    fn two_joints(p: DVec3, w0: f32, w1: f32, dq_weights: Vec<f32>) -> (Skin, Mesh) {
        let skin = Skin { joints: vec![0, 1], inverse_bind: vec![DMat4::IDENTITY; 2], ..Skin::default() };
        let mesh = Mesh {
            skin: Some(0),
            positions: vec![p.as_vec3()],
            joints: vec![[0, 1, 0, 0]],
            weights: vec![[w0, w1, 0.0, 0.0]],
            dq_weights,
            ..Mesh::default()
        };
        (skin, mesh)
    }

    #[test]
    fn a_reach_bounds_how_far_every_vertex_lies_apart() {
        // Random skins of 40 vertices over 5 joints, or of 6 (a joint's vertices bounding it themselves, fewer than
        // its box's corners), a node bind on every other one, under random sheared poses: the bound is never below
        // the largest vertex distance, and for one joint moved by a translation alone it is that translation.
        use rand::{RngExt, SeedableRng};
        let mut rng = rand_xorshift::XorShiftRng::seed_from_u64(11);
        let mut noise = |scale: f64| DVec3::from_array(std::array::from_fn(|_| (rng.random::<f64>() - 0.5) * scale));
        for case in 0..200 {
            let joints = 5;
            let matrix = |n: &mut dyn FnMut(f64) -> DVec3| {
                DMat4::from_cols(n(2.0).extend(0.0), n(2.0).extend(0.0), n(2.0).extend(0.0), n(10.0).extend(1.0))
            };
            let inverse_bind = (0..joints).map(|_| matrix(&mut noise)).collect();
            let node_bind =
                (case % 2 == 0).then(|| crate::model::NodeBind { bone: 0, inverse_bind: matrix(&mut noise) });
            let skin = Skin { joints: (0..joints).collect(), inverse_bind, node_bind, ..Skin::default() };
            let mut mesh = Mesh { skin: Some(0), ..Mesh::default() };
            for _ in 0..if case % 3 == 0 { 6 } else { 40 } {
                mesh.positions.push(noise(4.0).as_vec3());
                let picked: [u16; 4] = std::array::from_fn(|_| (noise(1.0).x.abs() * 9.9) as u16 % joints as u16);
                let weights = noise(1.0).abs();
                mesh.joints.push(picked);
                mesh.weights.push([weights.x as f32, weights.y as f32, weights.z as f32, 0.25]);
            }
            let (a, b): (Vec<DMat4>, Vec<DMat4>) =
                (0..joints).map(|_| (matrix(&mut noise), matrix(&mut noise))).unzip();
            let skins = [skin];
            let reach = Reach::of(&mesh, &skins, Method::Linear, None).expect("a linear skin has a reach");
            let (mut at_a, mut at_b) = (Vec::new(), Vec::new());
            skin_positions_with(&mesh, &skins, &a, &MorphPose::default(), Method::Linear, &mut at_a);
            skin_positions_with(&mesh, &skins, &b, &MorphPose::default(), Method::Linear, &mut at_b);
            let largest = at_a.iter().zip(&at_b).map(|(p, q)| p.distance(*q)).fold(0.0, f64::max);
            let bound = reach.bound(&skins, &a, &b);
            assert!(bound >= largest * (1.0 - 1e-12), "case {case}: bound {bound} under {largest}");
        }
        let (skin, mesh) = two_joints(DVec3::new(0.3, -1.0, 2.0), 1.0, 0.0, vec![]);
        let moved = [DMat4::from_translation(DVec3::new(0.0, 3.0, 4.0)), DMat4::IDENTITY];
        let reach = Reach::of(&mesh, std::slice::from_ref(&skin), Method::Linear, None).unwrap();
        assert!((reach.bound(&[skin], &moved, &[DMat4::IDENTITY; 2]) - 5.0).abs() < 1e-12);
        let (skin, mesh) = two_joints(DVec3::X, 0.5, 0.5, vec![0.5]);
        assert_eq!(Reach::of(&mesh, &[skin], Method::AsFile, None), None, "no bound through dual quaternions");
    }

    fn skinned(skin: Skin, mesh: &Mesh, model: &[DMat4], method: Method) -> DVec3 {
        let mut out = Vec::new();
        skin_positions_with(mesh, &[skin], model, &MorphPose::default(), method, &mut out);
        out[0]
    }

    #[test]
    fn dual_quaternions_keep_a_twisted_vertex_on_its_circle() {
        // Halfway between no turn and 90° about Z, DQ turns (1, 0, 0) by 45°; linear blending pulls it inwards to
        // (0.5, 0.5, 0), 0.707 from the axis (the candy-wrapper collapse).
        let model = [DMat4::IDENTITY, DMat4::from_quat(DQuat::from_rotation_z(std::f64::consts::FRAC_PI_2))];
        let (skin, mesh) = two_joints(DVec3::X, 0.5, 0.5, vec![]);
        let half = std::f64::consts::FRAC_1_SQRT_2;
        let dq = skinned(skin.clone(), &mesh, &model, Method::DualQuaternion);
        assert!(dq.abs_diff_eq(DVec3::new(half, half, 0.0), 1e-12), "{dq:?}");
        let linear = skinned(skin.clone(), &mesh, &model, Method::Linear);
        assert!(linear.abs_diff_eq(DVec3::new(0.5, 0.5, 0.0), 1e-12), "{linear:?}");
        assert_eq!(skinned(skin, &mesh, &model, Method::AsFile), linear, "the file declares no DQ weights");
    }

    #[test]
    fn dual_quaternions_blend_translations_linearly() {
        let model =
            [DMat4::from_translation(DVec3::new(2.0, 0.0, 0.0)), DMat4::from_translation(DVec3::new(0.0, 2.0, 0.0))];
        let (skin, mesh) = two_joints(DVec3::new(0.0, 0.0, 1.0), 0.25, 0.75, vec![1.0]);
        let p = skinned(skin, &mesh, &model, Method::AsFile);
        assert!(p.abs_diff_eq(DVec3::new(0.5, 1.5, 1.0), 1e-12), "{p:?}");
    }

    #[test]
    fn dual_quaternions_are_exact_where_linear_blending_is() {
        // Both joints carry the same sheared, scaled, turned and moved matrix (and a mirrored one): any blend of
        // them is that matrix, in either method.
        let sheared =
            DMat4::from_cols_array(&[1.5, 0.2, 0.0, 0.0, 0.7, 0.9, 0.1, 0.0, -0.3, 0.0, 2.0, 0.0, 4.0, -1.0, 0.5, 1.0])
                * DMat4::from_quat(DQuat::from_euler(glam::EulerRot::XYZ, 0.3, -1.1, 2.0));
        for m in [sheared, sheared * DMat4::from_scale(DVec3::new(-1.0, 1.0, 1.0))] {
            let p = DVec3::new(0.25, -0.75, 1.5);
            let (skin, mesh) = two_joints(p, 0.25, 0.75, vec![1.0]);
            let dq = skinned(skin, &mesh, &[m, m], Method::AsFile);
            assert!(dq.abs_diff_eq(m.transform_point3(p), 1e-12), "{dq:?} vs {:?}", m.transform_point3(p));
        }
    }

    #[test]
    fn dq_weights_blend_the_two_methods() {
        let model = [DMat4::IDENTITY, DMat4::from_quat(DQuat::from_rotation_z(std::f64::consts::FRAC_PI_2))];
        let (skin, mesh) = two_joints(DVec3::X, 0.5, 0.5, vec![0.25]);
        let p = skinned(skin.clone(), &mesh, &model, Method::AsFile);
        let expected = skinned(skin.clone(), &mesh, &model, Method::Linear) * 0.75
            + skinned(skin, &mesh, &model, Method::DualQuaternion) * 0.25;
        assert!(p.abs_diff_eq(expected, 1e-12), "{p:?} vs {expected:?}");
    }

    /// A bone sheared by 30°: its Y column leans 30° towards X (60° between them), scaled 1.5 along Z, turned and
    /// moved; and its bind frame, turned 90° about Z at (0, 1, 0) (the inverse bind matrix is its inverse).
    fn sheared_bone() -> (DMat4, DMat4) {
        let (sin, cos) = 30f64.to_radians().sin_cos();
        let shear = DMat4::from_cols(
            glam::DVec4::X,
            glam::DVec4::new(sin, cos, 0.0, 0.0),
            glam::DVec4::new(0.0, 0.0, 1.5, 0.0),
            glam::DVec4::new(0.3, 2.0, -1.0, 1.0),
        );
        let turn = DMat4::from_quat(DQuat::from_rotation_y(0.7));
        let bind = DMat4::from_rotation_translation(DQuat::from_rotation_z(std::f64::consts::FRAC_PI_2), DVec3::Y);
        (turn * shear, bind.inverse())
    }

    /// The largest deviation from 90° between the columns of `m`, measured by hand: each pair's angle from its
    /// cosine.
    fn shear_by_angles(m: DMat3) -> f64 {
        let columns = [m.x_axis, m.y_axis, m.z_axis];
        let angle = |a: DVec3, b: DVec3| (a.dot(b) / (a.length() * b.length())).acos().to_degrees();
        [(0, 1), (0, 2), (1, 2)]
            .map(|(i, j)| (angle(columns[i], columns[j]) - 90.0).abs())
            .into_iter()
            .fold(0.0, f64::max)
    }

    #[test]
    fn a_vertex_bound_to_one_bone_has_that_bones_shear() {
        // Bone 0 is the sheared bone, bone 1 only turned and moved. Vertices: one fully on each bone, one halfway.
        let (sheared, inverse_bind) = sheared_bone();
        let turned = DMat4::from_rotation_translation(DQuat::from_rotation_x(1.1), DVec3::new(1.0, 0.0, 0.0));
        let skin = Skin { joints: vec![0, 1], inverse_bind: vec![inverse_bind, DMat4::IDENTITY], ..Skin::default() };
        let mesh = Mesh {
            skin: Some(0),
            positions: vec![Vec3::ZERO; 3],
            joints: vec![[0, 1, 0, 0]; 3],
            weights: vec![[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.5, 0.5, 0.0, 0.0]],
            ..Mesh::default()
        };
        let model = [sheared, turned];
        let bone = crate::analysis::Assessment::of(&sheared, &crate::analysis::Tolerances::default()).shear_deg;
        assert!((bone - 30.0).abs() < 1e-9, "the bone's own shear: {bone}");
        let shears = vertex_shears(&mesh, std::slice::from_ref(&skin), &model);
        assert!((shears[0] - bone).abs() < 1e-9, "{} vs the bone's {bone}", shears[0]);
        assert!(shears[1].abs() < 1e-9, "a rigid bone gives none, {}", shears[1]);
        assert!((shears[2] - bone / 2.0).abs() < 1e-9, "halfway, half the sheared bone's: {}", shears[2]);
        // Unskinned, a mesh has its bone's shear everywhere.
        let placed = Mesh { bone: 0, positions: vec![Vec3::X; 2], ..Mesh::default() };
        let shears = vertex_shears(&placed, &[], &model);
        assert!(shears.iter().all(|s| (s - bone).abs() < 1e-9), "{shears:?}");
    }

    #[test]
    fn a_vertex_between_two_turned_bones_that_shear_not_reads_no_shear() {
        // The blend of two joints turned about different axes squashes the skin between them (linear blending's
        // own distortion, whose columns meet at other than 90°): no bone shears, so no vertex does.
        let skin = Skin { joints: vec![0, 1], inverse_bind: vec![DMat4::IDENTITY; 2], ..Skin::default() };
        let turned = DQuat::from_rotation_x(1.2) * DQuat::from_rotation_z(0.9);
        let model = [DMat4::IDENTITY, DMat4::from_quat(turned)];
        let mesh = Mesh {
            skin: Some(0),
            positions: vec![Vec3::new(0.2, 0.9, -0.4); 2],
            joints: vec![[0, 1, 0, 0]; 2],
            weights: vec![[0.5, 0.5, 0.0, 0.0], [0.3, 0.7, 0.0, 0.0]],
            ..Mesh::default()
        };
        let blend = DMat3::from_mat4(model[0]) * 0.5 + DMat3::from_mat4(model[1]) * 0.5;
        assert!(shear_by_angles(blend) > 1.0, "the blend itself is no rotation");
        let shears = vertex_shears(&mesh, std::slice::from_ref(&skin), &model);
        assert!(shears.iter().all(|s| s.abs() < 1e-12), "rounding alone: {shears:?}");
    }

    #[test]
    fn a_skin_that_follows_its_node_moves_with_it() {
        // The mesh node (bone 1) was bound at x = 1 and is now at x = 3: the result moves by +2.
        let mut skin = Skin { joints: vec![0], inverse_bind: vec![DMat4::IDENTITY], ..Skin::default() };
        skin.node_bind =
            Some(crate::model::NodeBind { bone: 1, inverse_bind: DMat4::from_translation(DVec3::new(-1.0, 0.0, 0.0)) });
        let mesh = Mesh {
            skin: Some(0),
            positions: vec![Vec3::Y],
            joints: vec![[0; 4]],
            weights: vec![[1.0, 0.0, 0.0, 0.0]],
            ..Mesh::default()
        };
        let model = [DMat4::IDENTITY, DMat4::from_translation(DVec3::new(3.0, 0.0, 0.0))];
        assert_eq!(skinned(skin, &mesh, &model, Method::AsFile), DVec3::new(2.0, 1.0, 0.0));
    }
}
