//! A few bones of a big rig evaluated without the rest: each read from the clip one track at a time and combined
//! under the hierarchy, for curves of one bone or an explanation of its shear over a long clip.

use super::{BoneCursor, Evaluation, Evaluator, Hierarchy, Pose};
use crate::model::{Clip, Skeleton, Transform};

/// Some bones (plotted ones and all their ancestors) read from a clip one bone at a time and evaluated under a
/// hierarchy, sample by sample: the rest of a big rig is never sampled.
pub struct Chains<'a> {
    /// The bones, parents first.
    bones: &'a [usize],
    cursors: Vec<BoneCursor<'a>>,
    /// Only the bones' entries are meaningful.
    pose: Pose,
}

impl<'a> Chains<'a> {
    pub fn new(skeleton: &Skeleton, clip: &'a Clip, bones: &'a [usize]) -> Self {
        let cursors = bones.iter().map(|&b| BoneCursor::new(skeleton, clip, b)).collect();
        let mut pose = Pose::default();
        pose.local = vec![Transform::IDENTITY; skeleton.len()];
        Chains { bones, cursors, pose }
    }

    /// The pose last evaluated: only the bones' entries are meaningful.
    pub fn pose(&self) -> &Pose {
        &self.pose
    }

    pub fn evaluate(&mut self, time: f64, hierarchy: &Hierarchy) -> &Pose {
        self.evaluate_first(time, self.bones.len(), hierarchy)
    }

    /// [`Chains::evaluate`] of the first `count` bones alone: parents coming first, a prefix holds its ancestors.
    pub fn evaluate_first(&mut self, time: f64, count: usize, hierarchy: &Hierarchy) -> &Pose {
        let bones = &self.bones[..count.min(self.bones.len())];
        for (&bone, cursor) in bones.iter().zip(&mut self.cursors) {
            self.pose.local[bone] = cursor.local(time);
        }
        hierarchy.evaluate_bones(&self.pose.local, bones, &mut self.pose.model);
        &self.pose
    }
}

/// Some bones of an evaluation (each with its ancestors, parents first), evaluated time after time: by [`Chains`]
/// where the clip can be read bone by bone (no layers, lengths in the rig's own unit), else as whole poses. Only
/// those bones' entries of a pose are meaningful.
pub enum BonesEvaluator<'e, 'a> {
    Chains(Box<Chains<'e>>, &'e Hierarchy),
    Whole(Box<Evaluator<'e, 'a>>),
}

impl<'e, 'a> BonesEvaluator<'e, 'a> {
    /// `bones` (sorted, with every ancestor of each) of `evaluation`; all of them read whole poses.
    pub fn new(evaluation: &'e Evaluation<'a>, bones: &'e [usize]) -> Self {
        let every = bones.len() == evaluation.skeleton().len();
        Self::reading(evaluation, bones, !every)
    }

    /// `bones` of `evaluation` to be evaluated a few at a time ([`BonesEvaluator::evaluate_first`]): bone by bone
    /// wherever the clip allows, even all of them.
    pub fn for_prefixes(evaluation: &'e Evaluation<'a>, bones: &'e [usize]) -> Self {
        Self::reading(evaluation, bones, true)
    }

    fn reading(evaluation: &'e Evaluation<'a>, bones: &'e [usize], bone_by_bone: bool) -> Self {
        match evaluation.clip.filter(|_| bone_by_bone && evaluation.reads_bone_by_bone()) {
            Some(clip) => {
                BonesEvaluator::Chains(Box::new(Chains::new(evaluation.skeleton(), clip, bones)), &evaluation.hierarchy)
            }
            None => BonesEvaluator::Whole(Box::new(evaluation.evaluator())),
        }
    }

    pub fn evaluate(&mut self, time: f64) -> &Pose {
        match self {
            BonesEvaluator::Chains(chains, hierarchy) => chains.evaluate(time, hierarchy),
            BonesEvaluator::Whole(evaluator) => evaluator.evaluate(time),
        }
    }

    /// The first `count` bones at `time`, and how many of the bones the pose holds: `count` or more (whole poses
    /// hold all).
    pub fn evaluate_first(&mut self, time: f64, count: usize) -> (&Pose, usize) {
        match self {
            BonesEvaluator::Chains(chains, hierarchy) => {
                let count = count.min(chains.bones.len());
                (chains.evaluate_first(time, count, hierarchy), count)
            }
            BonesEvaluator::Whole(evaluator) => (evaluator.evaluate(time), usize::MAX),
        }
    }

    /// The pose last evaluated.
    pub fn pose(&self) -> &Pose {
        match self {
            BonesEvaluator::Chains(chains, _) => &chains.pose,
            BonesEvaluator::Whole(evaluator) => &evaluator.pose,
        }
    }
}
