//! An evaluation that differs from another only at one bone and below it (another mode there, a scale made
//! uniform): evaluated from the other's pose at the same time, its own subtree alone. Explaining a shear weighs hundreds of such changes against
//! one clip; each shares the ancestors of the bone it changes with the clip as it is.

use super::layers::{Layers, uniform_scale};
use super::{Chains, Evaluation, Hierarchy, ModelPose, Pose};
use crate::model::Transform;

/// `evaluation`, which differs from a reference only at `top` and below it.
#[derive(Clone, Debug)]
pub struct Variant<'e, 'a> {
    pub evaluation: &'e Evaluation<'a>,
    pub top: usize,
    /// `top` and every bone below it, parents first.
    pub bones: Vec<usize>,
    /// The bones whose local scale it makes uniform (a layer of nothing else).
    uniform: Vec<usize>,
}

impl<'e, 'a> Variant<'e, 'a> {
    /// `evaluation` as a variant of `reference`, where it is one: the same rig, clip and skinning, lengths in the
    /// rig's unit, the reference read from the clip bone by bone ([`Evaluation::reads_bone_by_bone`]) and
    /// `evaluation` too but for scales it makes uniform; the modes and those scales differing only at and below one
    /// bone (the top: the lowest bone above all that differ).
    pub fn of(reference: &Evaluation, evaluation: &'e Evaluation<'a>) -> Option<Self> {
        let uniform = only_uniform_scales(evaluation)?;
        let alike = std::ptr::eq(reference.rig, evaluation.rig)
            && reference.clip.is_some()
            && reference.clip.map(std::ptr::from_ref) == evaluation.clip.map(std::ptr::from_ref)
            && reference.skinning == evaluation.skinning
            && reference.delay() == evaluation.delay()
            && reference.reads_bone_by_bone()
            && evaluation.in_rig_unit();
        let skeleton = evaluation.skeleton();
        let modes = reference.modes().iter().zip(evaluation.modes());
        let other_modes = modes.enumerate().filter(|(_, (a, b))| a != b).map(|(bone, _)| bone);
        let mut differing = other_modes.chain(uniform.iter().copied());
        let mut top = differing.next().filter(|_| alike)?;
        for bone in differing {
            while !skeleton.chain(bone).contains(&top) {
                top = skeleton.parent(top)?;
            }
        }
        Some(Variant { evaluation, top, bones: skeleton.subtree(top), uniform })
    }

    /// `bone`'s local transform, the reference's being `reference` (one per bone).
    pub fn local(&self, reference: &[Transform], bone: usize) -> Transform {
        let mut local = reference[bone];
        if self.uniform.contains(&bone) {
            uniform_scale(&mut local);
        }
        local
    }
}

/// The bones whose scale `evaluation`'s layers make uniform, where they do nothing else (none without layers).
fn only_uniform_scales(evaluation: &Evaluation) -> Option<Vec<usize>> {
    let Some(stack) = evaluation.layers() else {
        return Some(Vec::new());
    };
    let uniform = &stack.layers().uniform_scale;
    (*stack.layers() == Layers { uniform_scale: uniform.clone(), ..Layers::default() }).then(|| uniform.clone())
}

/// What else a pass over the clip that evaluates variants of a reference does with them, time after time in the runs
/// of samples of [`super::over_runs`]: at each time the reference's pose once, then each variant's model matrices.
/// A scan judges the variants so; a comparison of the variants with the reference can judge them on its way, each
/// evaluated once for both.
pub trait Beside: Sync {
    /// What a run of samples keeps.
    type Run: Send;

    /// The bones the reference is evaluated on for this (sorted, with every ancestor of each), besides the pass's
    /// own.
    fn bones(&self) -> &[usize];

    /// A new run of `samples` samples.
    fn run(&self, samples: usize) -> Self::Run;

    /// The reference at the run's next time.
    fn reference(&self, run: &mut Self::Run, pose: &Pose);

    /// Variant `k` at sample `sample` of the run, at `time`: the reference's pose there, and the variant's model
    /// matrices (its own bones' at least).
    fn variant(&self, run: &mut Self::Run, k: usize, sample: usize, time: f64, reference: &Pose, model: &ModelPose);
}

/// A reference evaluated for its variants, time after time: the bones they hang from and their own bones, read bone
/// by bone, with every matrix a variant's modes may read ([`Hierarchy::reference`]).
pub struct Reference<'e> {
    hierarchy: Hierarchy,
    chains: Chains<'e>,
}

impl<'e> Reference<'e> {
    /// `reference` (read bone by bone, as its variants are) evaluated on `bones`: sorted, with every ancestor of each,
    /// holding each variant's bones; `hanging_from` are the bones the variants hang from (their tops' parents).
    /// `None` without a clip: a rest pose has no variants.
    pub fn new(reference: &'e Evaluation, bones: &'e [usize], hanging_from: &[usize]) -> Option<Self> {
        let chains = Chains::new(reference.skeleton(), reference.clip?, bones);
        Some(Reference { hierarchy: reference.hierarchy.reference(hanging_from), chains })
    }

    /// The reference at `time`.
    pub fn evaluate(&mut self, time: f64) -> &Pose {
        self.chains.evaluate(time, &self.hierarchy)
    }

    /// The pose last evaluated.
    pub fn pose(&self) -> &Pose {
        self.chains.pose()
    }

    /// `variant` at the time last evaluated: its bones' model matrices into `out` (their local transforms are the
    /// reference's, as the variant changes them: [`Variant::local`]).
    pub fn evaluate_variant(&self, variant: &Variant, out: &mut ModelPose) {
        let pose = self.chains.pose();
        let local = |bone: usize| variant.local(&pose.local, bone);
        variant.evaluation.hierarchy.evaluate_below(local, &variant.bones, &pose.model, out);
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use glam::{DMat4, DQuat, DVec3};

    use super::*;
    use crate::eval::LayerStack;
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

    /// Every change of one bone `explain` weighs on `source`: each other mode, and its scale made uniform.
    pub(crate) fn changes_of<'a>(source: &Evaluation<'a>, top: usize) -> Vec<Evaluation<'a>> {
        let modes = source.modes();
        let other = InheritMode::ALL.iter().filter(|&&m| m != modes[top]).map(|&mode| {
            let mut changed = modes.to_vec();
            changed[top] = mode;
            source.with_modes(&changed).unwrap()
        });
        let layers = Layers { uniform_scale: vec![top], ..Layers::default() };
        let uniform = source.clone().with_layers(LayerStack::new(source.rig, &layers).unwrap());
        other.chain([uniform]).collect()
    }

    #[test]
    fn a_variant_evaluated_below_its_top_is_the_change_evaluated_whole() {
        // Every bone under every mode or with its scale made uniform, its squashed ancestor under segment
        // compensate or not: the subtree's model matrices equal the whole change's, bit for bit, placed or not.
        for placed in [false, true] {
            let rig = rig(placed);
            let (skeleton, clip) = (&rig.skeleton, &rig.clips[0]);
            let every: Vec<usize> = (0..skeleton.len()).collect();
            for squash_mode in [InheritMode::Full, InheritMode::SegmentCompensate] {
                let mut modes = vec![InheritMode::Full; skeleton.len()];
                modes[5] = squash_mode;
                let source = Evaluation::new(&rig, Some(clip), &modes).unwrap();
                let mut reference = Reference::new(&source, &every, &every).unwrap();
                let mut out = ModelPose::default();
                for top in 1..skeleton.len() {
                    for changed in changes_of(&source, top) {
                        let variant = Variant::of(&source, &changed).expect("a change of one bone is a variant");
                        assert_eq!(variant.top, top);
                        for time in [0.0, 0.37, 1.1] {
                            reference.evaluate(time);
                            reference.evaluate_variant(&variant, &mut out);
                            let whole = changed.pose_at(time).model.model;
                            for &b in &variant.bones {
                                assert_eq!(out.model[b], whole[b], "bone {b} below {top}, {time} s, {placed}");
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
        let uniform = Layers { uniform_scale: vec![8], ..Layers::default() };
        let uniform = changed(&[6]).with_layers(LayerStack::new(&rig, &uniform).unwrap());
        assert_eq!(Variant::of(&source, &uniform).map(|v| v.top), Some(6), "a scale made uniform below the mode");
        assert!(Variant::of(&uniform, &source).is_none(), "a layered reference reads whole poses");
    }
}
