//! Local → model matrices, with each bone's scale-inheritance mode (`docs/inheritance-modes.md`).
//!
//! Besides its model matrix `W`, every bone gets the matrices its children may need: `U`, the model matrix
//! without the bone's own scale (ufbx's `unscaled_node_to_world`), `G`, the rigid chain of translations and
//! rotations only (the first pass of a two-pass "don't inherit scale"), and the scale vectors ufbx carries for
//! componentwise inheritance.
//! They are computed only where some bone needs them, so an all-`full` rig costs one matrix product per bone.
//!
//! Every mode is evaluated in the file's own space: a file's unit and axes conversion and its conversion nodes
//! ([`Placement`]) are the world to the bones below them, as an armature object's transform is to Blender's bones
//! and a unit conversion is to Maya's joints, so no mode compensates them. The model matrices are then placed:
//! `W = C·W_file`, with `C` the conversion above the bone.

use glam::{DMat4, DVec3};

use super::blender;
use crate::model::{InheritMode, Placement, Rig, Skeleton, Transform};

/// The model-space result of one evaluation.
#[derive(Clone, Debug, Default)]
pub struct ModelPose {
    /// `W`, one per bone.
    pub model: Vec<DMat4>,
    /// Where the hierarchy places its bones: `W_file`, the model matrices in the file's space that children are
    /// evaluated from (empty where nothing is placed: `model` is in the file's space).
    file: Vec<DMat4>,
    unscaled: Vec<DMat4>,
    rigid: Vec<DMat4>,
    /// ufbx's `inherit_scale`: the scale a componentwise or compensating child multiplies its offset by.
    inherit_scale: Vec<DVec3>,
    /// The `inherit_scale` of ufbx's `inherit_scale_node`: what a compensating child multiplies its scale by.
    carried_scale: Vec<DVec3>,
    /// For conversion nodes: their placed matrix, the conversion the bones below them stand in, and whether it is
    /// the identity (an exporter's `Armature` at rest: nothing to place).
    conversions: Vec<DMat4>,
    identity_conversions: Vec<bool>,
}

/// A skeleton's parent links and modes, prepared once and evaluated for any number of poses.
#[derive(Clone, Debug)]
pub struct Hierarchy {
    parents: Vec<Option<usize>>,
    modes: Vec<InheritMode>,
    /// For Blender modes: the rest offset `O = T·R` of the bone and its inverse.
    offsets: Vec<Option<(DMat4, DMat4)>>,
    needs_unscaled: Vec<bool>,
    /// Per bone, whether its rigid matrix is read: by a bone below it that inherits an unscaled parent.
    needs_rigid: Vec<bool>,
    /// The skeleton's conversion and conversion nodes.
    placement: Placement,
    /// Per bone, the conversion node whose placed matrix places it (itself for a conversion node), or `None` for
    /// the skeleton's conversion; empty where nothing is placed.
    placed_by: Vec<Option<usize>>,
    /// Whether any bone is placed: children are then evaluated from their parents' matrices in the file's space.
    places: bool,
}

/// Marks `bone` and every bone above it in `marks` (by bone; `parents` gives each bone's parent).
fn mark_chain(parents: &[Option<usize>], marks: &mut [bool], bone: usize) {
    let mut at = Some(bone);
    while let Some(bone) = at.filter(|&b| !marks[b]) {
        marks[bone] = true;
        at = parents[bone];
    }
}

/// Modes or rest transforms that are not one per bone.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{given} {what} for a skeleton of {bones} bones: one per bone")]
pub struct HierarchyError {
    pub what: &'static str,
    pub given: usize,
    pub bones: usize,
}

/// `given` things of `what` for `skeleton`, refused unless one per bone.
fn one_per_bone(skeleton: &Skeleton, given: usize, what: &'static str) -> Result<(), HierarchyError> {
    let bones = skeleton.len();
    if given == bones { Ok(()) } else { Err(HierarchyError { what, given, bones }) }
}

impl Hierarchy {
    /// `modes`, one mode per bone; the Blender modes' bone offsets are the rest pose's.
    pub fn new(skeleton: &Skeleton, modes: &[InheritMode]) -> Result<Self, HierarchyError> {
        Hierarchy::with_bone_rest(skeleton, modes, &skeleton.rest_pose())
    }

    /// The modes `skeleton`'s file declares; the Blender modes' bone offsets are the rest pose's.
    pub fn declared(skeleton: &Skeleton) -> Self {
        Hierarchy::build(skeleton, &skeleton.declared_modes(), &skeleton.rest_pose())
    }

    /// The hierarchy of `rig` under `modes`, one per bone: the Blender modes' bone offsets are the bind pose, which
    /// is what Blender's bones rest in (an FBX file's nodes may hold another pose by default).
    pub fn of_rig(rig: &Rig, modes: &[InheritMode]) -> Result<Self, HierarchyError> {
        one_per_bone(&rig.skeleton, modes.len(), "inheritance modes")?;
        Ok(Hierarchy::of_rig_bound(rig, modes, None))
    }

    /// [`Hierarchy::of_rig`] of modes known to be one per bone (resolved from the rig's own skeleton), given the
    /// rig's bind pose ([`super::bind_pose`]) where it is known: the Blender modes rest bones in it.
    pub(super) fn of_rig_bound(rig: &Rig, modes: &[InheritMode], bind_pose: Option<&[Transform]>) -> Self {
        let skeleton = &rig.skeleton;
        if !modes.iter().any(|m| m.is_blender()) {
            return Hierarchy::build(skeleton, modes, &skeleton.rest_pose());
        }
        match bind_pose {
            Some(bind_pose) => Hierarchy::build(skeleton, modes, bind_pose),
            None => Hierarchy::build(skeleton, modes, &super::bind_pose(rig)),
        }
    }

    /// `modes`, one mode per bone, and `bone_rest`, the local transform each bone rests in for the Blender modes
    /// (their bone offset `O`: its translation and rotation).
    pub fn with_bone_rest(
        skeleton: &Skeleton,
        modes: &[InheritMode],
        bone_rest: &[Transform],
    ) -> Result<Self, HierarchyError> {
        one_per_bone(skeleton, modes.len(), "inheritance modes")?;
        one_per_bone(skeleton, bone_rest.len(), "rest transforms")?;
        Ok(Hierarchy::build(skeleton, modes, bone_rest))
    }

    /// The hierarchy of `modes` and `bone_rest`, each one per bone of `skeleton`.
    fn build(skeleton: &Skeleton, modes: &[InheritMode], bone_rest: &[Transform]) -> Self {
        let parents: Vec<Option<usize>> = skeleton.bones().iter().map(|b| b.parent).collect();
        let offsets = bone_rest
            .iter()
            .zip(modes)
            .map(|(rest, mode)| {
                mode.is_blender().then(|| {
                    let offset = rest.rigid_matrix();
                    (offset, offset.inverse())
                })
            })
            .collect();
        let mut needs_unscaled = vec![false; parents.len()];
        for (parent, mode) in parents.iter().zip(modes) {
            if let Some(p) = parent
                && matches!(mode, InheritMode::SegmentCompensate | InheritMode::Componentwise)
            {
                needs_unscaled[*p] = true;
            }
        }
        let mut needs_rigid = vec![false; parents.len()];
        for (bone, mode) in modes.iter().enumerate() {
            if *mode == InheritMode::UnscaledParent {
                mark_chain(&parents, &mut needs_rigid, bone);
            }
        }
        let placement = skeleton.placement().clone();
        let placed_by = skeleton.placed_by().to_vec();
        let places = !placed_by.is_empty() || placement.conversion != DMat4::IDENTITY;
        Hierarchy { parents, modes: modes.to_vec(), offsets, needs_unscaled, needs_rigid, placement, placed_by, places }
    }

    /// The same hierarchy evaluating, besides every model matrix, the matrices a child under any mode reads of its
    /// parent at the bones `hanging_from`: a reference that changes of mode below their children are evaluated from
    /// ([`Hierarchy::evaluate_below`]). Its model matrices are this hierarchy's.
    pub fn reference(&self, hanging_from: &[usize]) -> Hierarchy {
        let (mut needs_unscaled, mut needs_rigid) = (self.needs_unscaled.clone(), self.needs_rigid.clone());
        for &bone in hanging_from.iter().filter(|&&bone| bone < self.parents.len()) {
            needs_unscaled[bone] = true;
            mark_chain(&self.parents, &mut needs_rigid, bone);
        }
        Hierarchy { needs_unscaled, needs_rigid, ..self.clone() }
    }

    pub fn modes(&self) -> &[InheritMode] {
        &self.modes
    }

    /// Model matrices of the local pose `local` (one transform per bone, parents first).
    pub fn evaluate(&self, local: &[Transform], out: &mut ModelPose) {
        self.size(local.len(), out);
        for (i, bone_local) in local.iter().enumerate() {
            self.evaluate_bone(i, bone_local, out);
        }
        self.place(0..local.len(), out);
    }

    /// Model matrices of `bones` only (in increasing order, with every ancestor of each), for a few bones of a big
    /// rig; only their entries of `local` are read, and the other bones' entries of `out` are not written.
    pub fn evaluate_bones(&self, local: &[Transform], bones: &[usize], out: &mut ModelPose) {
        self.size(local.len(), out);
        for &i in bones {
            self.evaluate_bone(i, &local[i], out);
        }
        self.place(bones.iter().copied(), out);
    }

    /// Model matrices of `bones` (a subtree, its top first, parents first) under the matrices its top's parent has
    /// in `reference`: a pose of a hierarchy that agrees with this one outside the subtree (the same skeleton, the
    /// same modes) and evaluates every matrix a child may read ([`Hierarchy::reference`]), at the same time. What a
    /// change below one bone gives, without evaluating its ancestors again; `local` gives the subtree's local
    /// transforms, and of `out` only the subtree's entries and its top's parent's are written.
    pub fn evaluate_below(
        &self,
        local: impl Fn(usize) -> Transform,
        bones: &[usize],
        reference: &ModelPose,
        out: &mut ModelPose,
    ) {
        self.size(self.parents.len(), out);
        if let Some(parent) = bones.first().and_then(|&top| self.parents[top]) {
            out.copy_bone(reference, parent);
            if let Some(&Some(node)) = self.placed_by.get(parent) {
                out.copy_conversion(reference, node);
            }
        }
        for &i in bones {
            self.evaluate_bone(i, &local(i), out);
        }
        self.place(bones.iter().copied(), out);
    }

    /// `W = C·W_file` for `bones`, evaluated in the file's space, once every bone they hang from is.
    fn place(&self, bones: impl Iterator<Item = usize>, out: &mut ModelPose) {
        if self.placed_by.is_empty() {
            return;
        }
        for i in bones {
            match self.placed_by[i] {
                Some(node) if node == i => out.model[i] = out.conversions[i],
                Some(node) if out.identity_conversions[node] => {}
                Some(node) => out.model[i] = out.conversions[node] * out.model[i],
                None if self.placement.conversion == DMat4::IDENTITY => {}
                None => out.model[i] = self.placement.conversion * out.model[i],
            }
        }
    }

    /// Sizes `out` for this hierarchy, given `bones` local transforms: one per bone.
    fn size(&self, bones: usize, out: &mut ModelPose) {
        let n = self.parents.len();
        assert_eq!(bones, n, "one local transform per bone");
        for v in [&mut out.model, &mut out.unscaled, &mut out.rigid] {
            v.resize(n, DMat4::IDENTITY);
        }
        out.inherit_scale.resize(n, DVec3::ONE);
        out.carried_scale.resize(n, DVec3::ONE);
        if self.places {
            out.file.resize(n, DMat4::IDENTITY);
        }
        if !self.placed_by.is_empty() {
            out.conversions.resize(n, DMat4::IDENTITY);
            out.identity_conversions.resize(n, true);
        }
    }

    fn evaluate_bone(&self, i: usize, local: &Transform, out: &mut ModelPose) {
        if self.placement.is_conversion(i) {
            // Above the rig (every ancestor is a conversion too): to the bones below, the world.
            let above = self.parents[i].map_or(self.placement.conversion, |p| out.conversions[p]);
            out.conversions[i] = above * local.matrix();
            out.identity_conversions[i] = out.conversions[i] == DMat4::IDENTITY;
            out.model[i] = DMat4::IDENTITY;
            out.file[i] = DMat4::IDENTITY;
            out.unscaled[i] = DMat4::IDENTITY;
            out.rigid[i] = DMat4::IDENTITY;
            out.inherit_scale[i] = DVec3::ONE;
            out.carried_scale[i] = DVec3::ONE;
            return;
        }
        let Some(p) = self.parents[i] else {
            out.model[i] = local.matrix();
            out.unscaled[i] = local.rigid_matrix();
            out.rigid[i] = out.unscaled[i];
            out.inherit_scale[i] = local.scale;
            out.carried_scale[i] = DVec3::ONE;
            self.keep_file_space(i, out);
            return;
        };
        let parent = if self.places { out.file[p] } else { out.model[p] };
        if self.needs_rigid[i] {
            out.rigid[i] = out.rigid[p] * local.rigid_matrix();
        }
        let (mut inherit_scale, mut carried_scale) = (local.scale, DVec3::ONE);
        match self.modes[i] {
            InheritMode::Full => {
                out.model[i] = parent * local.matrix();
                if self.needs_unscaled[i] {
                    out.unscaled[i] = parent * local.rigid_matrix();
                }
            }
            InheritMode::UnscaledParent => {
                out.model[i] = out.rigid[p] * local.matrix();
                out.unscaled[i] = out.rigid[i];
            }
            mode @ (InheritMode::SegmentCompensate | InheritMode::Componentwise) => {
                // ufbx: t' = t ⊙ inherit_scale(parent); s' = s ⊙ inherit_scale(inherit_scale_node), where that
                // node is the parent for componentwise bones and, for compensating ones, the parent's own (none
                // below a plain parent, so only the offset is scaled: Maya's segment scale compensate).
                let scale_factor = match mode {
                    InheritMode::Componentwise => out.inherit_scale[p],
                    _ => out.carried_scale[p],
                };
                carried_scale = scale_factor;
                let offset = local.translation * out.inherit_scale[p];
                let scaled = Transform { translation: offset, scale: local.scale * scale_factor, ..*local };
                out.unscaled[i] = out.unscaled[p] * scaled.rigid_matrix();
                out.model[i] = out.unscaled[p] * scaled.matrix();
                inherit_scale = scaled.scale;
            }
            mode => {
                let (offset, offset_inverse) = self.offsets[i].expect("offsets are prepared for Blender modes");
                let mode = blender::BlenderInherit::from_mode(mode).expect("a Blender mode");
                out.model[i] = blender::child_pose(mode, &parent, &offset, &(offset_inverse * local.matrix()));
                if self.needs_unscaled[i] {
                    let channel = offset_inverse * local.rigid_matrix();
                    out.unscaled[i] = blender::child_pose(mode, &parent, &offset, &channel);
                }
            }
        }
        out.inherit_scale[i] = inherit_scale;
        out.carried_scale[i] = carried_scale;
        self.keep_file_space(i, out);
    }

    /// Keeps bone `i`'s model matrix in the file's space, where it is to be placed.
    fn keep_file_space(&self, i: usize, out: &mut ModelPose) {
        if self.places {
            out.file[i] = out.model[i];
        }
    }
}

impl ModelPose {
    /// Every matrix and scale `bone` has in `from`, the pose of the same skeleton at the same time.
    fn copy_bone(&mut self, from: &ModelPose, bone: usize) {
        self.model[bone] = from.model[bone];
        if let (Some(to), Some(&file)) = (self.file.get_mut(bone), from.file.get(bone)) {
            *to = file;
        }
        self.unscaled[bone] = from.unscaled[bone];
        self.rigid[bone] = from.rigid[bone];
        self.inherit_scale[bone] = from.inherit_scale[bone];
        self.carried_scale[bone] = from.carried_scale[bone];
        self.copy_conversion(from, bone);
    }

    /// Conversion node `node`'s placed matrix in `from`, where the poses place bones by conversion nodes.
    fn copy_conversion(&mut self, from: &ModelPose, node: usize) {
        if let (Some(to), Some(&conversion)) = (self.conversions.get_mut(node), from.conversions.get(node)) {
            *to = conversion;
            self.identity_conversions[node] = from.identity_conversions[node];
        }
    }
}
