//! A few bones of a big rig evaluated without the rest: each read from the clip one track at a time and combined
//! under the hierarchy, for curves of one bone or an explanation of its shear over a long clip.

use super::{BoneCursor, Hierarchy, Pose};
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

    pub fn evaluate(&mut self, time: f64, hierarchy: &Hierarchy) -> &Pose {
        for (&bone, cursor) in self.bones.iter().zip(&mut self.cursors) {
            self.pose.local[bone] = cursor.local(time);
        }
        hierarchy.evaluate_bones(&self.pose.local, self.bones, &mut self.pose.model);
        &self.pose
    }
}
