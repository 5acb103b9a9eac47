//! One evaluation step from a clip and a time to local and model matrices, with reusable buffers.

use super::sample::{rest_pose_into, sample_clip_near};
use super::{Hierarchy, LayerStack, ModelPose, MorphPose};
use crate::model::{Clip, Rig, Skeleton, Transform};

/// The local transforms and model matrices of every bone at one time. Reuse it across times to avoid allocating,
/// and across increasing times to skip key searches.
#[derive(Clone, Debug, Default)]
pub struct Pose {
    pub local: Vec<Transform>,
    pub model: ModelPose,
    /// The morph-target weights the clip animates (layers do not blend them: the main clip's hold).
    pub morph: MorphPose,
    /// Where each track's keys were found last time (see `sample_clip_near`).
    hints: Vec<usize>,
}

impl Pose {
    /// Samples `clip` at `time` (the rest pose when there is no clip) and evaluates the hierarchy.
    pub fn evaluate(&mut self, skeleton: &Skeleton, clip: Option<&Clip>, hierarchy: &Hierarchy, time: f64) {
        match clip {
            Some(clip) => sample_clip_near(skeleton, clip, time, &mut self.local, Some(&mut self.hints)),
            None => rest_pose_into(skeleton, &mut self.local),
        }
        hierarchy.evaluate(&self.local, &mut self.model);
        self.morph.evaluate(clip, time);
    }

    /// Like [`Pose::evaluate`], through `layers` (built for `rig`).
    pub fn evaluate_layered(
        &mut self,
        rig: &Rig,
        clip: Option<&Clip>,
        hierarchy: &Hierarchy,
        layers: &mut LayerStack,
        time: f64,
    ) {
        layers.evaluate(rig, clip, time, &mut self.local);
        hierarchy.evaluate(&self.local, &mut self.model);
        self.morph.evaluate(clip, time);
    }
}
