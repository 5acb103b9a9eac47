//! An evaluation that differs from another only at one bone and below it (another mode there): evaluated from the
//! other's pose at the same time, its own subtree alone. Explaining a shear weighs hundreds of such changes against
//! one clip; each shares the ancestors of the bone it changes with the clip as it is.

use super::{Chains, Evaluation, Hierarchy, ModelPose};
use crate::model::Clip;

/// `evaluation`, which differs from a reference only at `top` and below it.
#[derive(Clone, Debug)]
pub struct Variant<'e, 'a> {
    pub evaluation: &'e Evaluation<'a>,
    pub top: usize,
    /// `top` and every bone below it, parents first.
    pub bones: Vec<usize>,
}

impl<'e, 'a> Variant<'e, 'a> {
    /// `evaluation` as a variant of `reference`, where it is one: the same rig, clip and skinning, both read from the
    /// clip bone by bone ([`Evaluation::reads_bone_by_bone`]), and the modes differing only at and below one bone
    /// (the top: the lowest bone above all that differ).
    pub fn of(reference: &Evaluation, evaluation: &'e Evaluation<'a>) -> Option<Self> {
        let alike = std::ptr::eq(reference.rig, evaluation.rig)
            && reference.clip.is_some()
            && reference.clip.map(std::ptr::from_ref) == evaluation.clip.map(std::ptr::from_ref)
            && reference.skinning == evaluation.skinning
            && reference.reads_bone_by_bone()
            && evaluation.reads_bone_by_bone();
        let skeleton = evaluation.skeleton();
        let modes = reference.modes().iter().zip(evaluation.modes());
        let mut differing = modes.enumerate().filter(|(_, (a, b))| a != b).map(|(bone, _)| bone);
        let mut top = differing.next().filter(|_| alike)?;
        for bone in differing {
            while !skeleton.chain(bone).contains(&top) {
                top = skeleton.parent(top)?;
            }
        }
        Some(Variant { evaluation, top, bones: skeleton.subtree(top) })
    }
}

/// A reference evaluated for its variants, time after time: the bones they hang from and their own bones, read bone
/// by bone, with every matrix a variant's modes may read ([`Hierarchy::reference`]).
pub struct Reference<'e> {
    hierarchy: Hierarchy,
    chains: Chains<'e>,
}

impl<'e> Reference<'e> {
    /// `reference` (read bone by bone, as its variants are) evaluated on `bones`: sorted, with every ancestor of each,
    /// holding each variant's bones.
    pub fn new(reference: &'e Evaluation, clip: &'e Clip, bones: &'e [usize]) -> Self {
        let chains = Chains::new(reference.skeleton(), clip, bones);
        Reference { hierarchy: reference.hierarchy.reference(), chains }
    }

    /// The reference at `time`.
    pub fn evaluate(&mut self, time: f64) -> &super::Pose {
        self.chains.evaluate(time, &self.hierarchy)
    }

    /// The pose last evaluated.
    pub fn pose(&self) -> &super::Pose {
        self.chains.pose()
    }

    /// `variant` at the time last evaluated: its bones' model matrices into `out` (its bones' local transforms are
    /// the reference's).
    pub fn evaluate_variant(&self, variant: &Variant, out: &mut ModelPose) {
        let pose = self.chains.pose();
        variant.evaluation.hierarchy.evaluate_below(&pose.local, &variant.bones, &pose.model, out);
    }
}

#[cfg(test)]
mod tests {
    use glam::{DMat4, DQuat, DVec3};

    use super::*;
    use crate::import::stress_rig;
    use crate::model::{Choice, InheritMode, Placement, Rig};

    /// The stress rig's spine and first chain, with a squash on the chain's fifth bone; placed where `placed` says
    /// (centimetres, Z up, the root a conversion node).
    fn rig(placed: bool) -> Rig {
        let mut rig = stress_rig(12, 40, 3);
        if placed {
            let conversion = DMat4::from_scale_rotation_translation(
                DVec3::splat(0.01),
                DQuat::from_rotation_x(-std::f64::consts::FRAC_PI_2),
                DVec3::ZERO,
            );
            let mut conversion_nodes = vec![false; rig.skeleton.len()];
            conversion_nodes[0] = true;
            rig.skeleton = rig.skeleton.clone().placed(Placement { conversion, conversion_nodes });
        }
        rig
    }

    #[test]
    fn a_variant_evaluated_below_its_top_is_the_change_evaluated_whole() {
        // Every bone under every mode, with its squashed ancestor under segment compensate or not: the subtree's
        // model matrices equal the whole change's, bit for bit, placed or not.
        for placed in [false, true] {
            let rig = rig(placed);
            let (skeleton, clip) = (&rig.skeleton, &rig.clips[0]);
            let every: Vec<usize> = (0..skeleton.len()).collect();
            for squash_mode in [InheritMode::Full, InheritMode::SegmentCompensate] {
                let mut modes = vec![InheritMode::Full; skeleton.len()];
                modes[5] = squash_mode;
                let source = Evaluation::new(&rig, Some(clip), &modes).unwrap();
                let mut reference = Reference::new(&source, clip, &every);
                let mut out = ModelPose::default();
                for top in 1..skeleton.len() {
                    for &mode in InheritMode::ALL.iter().filter(|&&m| m != modes[top]) {
                        let mut changed_modes = modes.clone();
                        changed_modes[top] = mode;
                        let changed = source.with_modes(&changed_modes).unwrap();
                        let variant = Variant::of(&source, &changed).expect("a change of one mode is a variant");
                        assert_eq!(variant.top, top);
                        for time in [0.0, 0.37, 1.1] {
                            reference.evaluate(time);
                            reference.evaluate_variant(&variant, &mut out);
                            let whole = changed.pose_at(time).model.model;
                            for &b in &variant.bones {
                                assert_eq!(out.model[b], whole[b], "bone {b}, {top} → {mode}, {time} s, {placed}");
                            }
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn a_variant_s_top_is_the_lowest_bone_above_every_change() {
        // The stress rig's spine (bone 0) carries chains 1–10 and 11: a change on bone 6 alone is a variant below
        // it, one on bones 6 and 8 below 6, one on bones 6 and 11 below the spine.
        let rig = rig(false);
        let source = Evaluation::declared(&rig, rig.clips.first());
        let changed = |bones: &[usize]| {
            let mut modes = source.modes().to_vec();
            bones.iter().for_each(|&b| modes[b] = InheritMode::SegmentCompensate);
            source.with_modes(&modes).unwrap()
        };
        let top = |bones: &[usize]| Variant::of(&source, &changed(bones)).map(|v| (v.top, v.bones.len()));
        assert_eq!(top(&[6]), Some((6, 5)));
        assert_eq!(top(&[8, 6]), Some((6, 5)));
        assert_eq!(top(&[6, 11]), Some((0, 12)));
        assert_eq!(top(&[]), None, "no change");
        assert!(Variant::of(&source, &changed(&[6]).at_rest()).is_none(), "another clip");
        let layered = changed(&[6]).played_with(crate::eval::layers::RotationInterpolation::Nlerp);
        assert!(Variant::of(&source, &layered).is_none(), "layers read whole poses");
    }
}
