//! One side of a comparison: a clip of a rig evaluated with some inheritance modes, as sampled or through layers;
//! the times a comparison visits; and the size of the rig that differences are measured against.

use glam::DVec3;

use crate::analysis::layered_sample_times;
use crate::eval::skinning::{skin_meshes_with, skin_positions_with};
use crate::eval::{Hierarchy, LayerStack, Pose, SkinningMethod};
use crate::model::{Clip, InheritMode, Rig, sample_times};

/// The most frames of the comparison rate visited at every one of (longer clips are thinned between sparse keys,
/// as every whole-clip pass does).
const MAX_FRAMES: usize = 1 << 20;

/// A clip of a rig (its rest pose for `None`) as one evaluation sees it.
#[derive(Clone, Debug)]
pub struct Side<'a> {
    pub rig: &'a Rig,
    pub clip: Option<&'a Clip>,
    pub hierarchy: Hierarchy,
    /// The layers the clip plays through; `None` plays it as sampled.
    pub layers: Option<LayerStack>,
    pub skinning: SkinningMethod,
}

impl<'a> Side<'a> {
    /// `clip` of `rig` with one mode per bone, as sampled, skinned as the file says.
    pub fn new(rig: &'a Rig, clip: Option<&'a Clip>, modes: &[InheritMode]) -> Self {
        let hierarchy = Hierarchy::new(&rig.skeleton, modes);
        Side { rig, clip, hierarchy, layers: None, skinning: SkinningMethod::AsFile }
    }

    /// The same through `layers` (built for this rig).
    pub fn with_layers(mut self, layers: LayerStack) -> Self {
        self.layers = Some(layers);
        self
    }

    /// How long the evaluation runs: the clip's duration, or the layered timeline's.
    pub fn duration(&self) -> f64 {
        match &self.layers {
            Some(layers) => layers.duration(self.rig, self.clip),
            None => self.clip.map_or(0.0, Clip::duration),
        }
    }

    /// The times at which the evaluation has keys: the clip's key times, or, where layers make a timeline of
    /// their own, its two ends.
    pub fn key_times(&self) -> Vec<f64> {
        match &self.layers {
            Some(layers) => layered_sample_times(self.rig, self.clip, layers, 0.0),
            None => self.clip.map_or_else(|| vec![0.0], Clip::key_times),
        }
    }

    /// Evaluates the pose at `time` into `pose`, through `layers` (a worker's own copy of this side's stack).
    pub fn evaluate(&self, pose: &mut Pose, layers: &mut Option<LayerStack>, time: f64) {
        match layers {
            Some(stack) => pose.evaluate_layered(self.rig, self.clip, &self.hierarchy, stack, time),
            None => pose.evaluate(&self.rig.skeleton, self.clip, &self.hierarchy, time),
        }
    }

    /// The positions of mesh `mesh` at the pose `pose`, morphed and skinned (`out` is reused).
    pub fn skin(&self, pose: &Pose, mesh: usize, out: &mut Vec<DVec3>) {
        let (rig, model) = (self.rig, &pose.model.model);
        skin_positions_with(&rig.meshes[mesh], &rig.skins, model, &pose.morph, self.skinning, out);
    }
}

/// The times two evaluations are compared at: every key time of either within the shorter duration, and `rate`
/// times a second over it (sorted, near-duplicates counted once).
pub fn comparison_times(a: &Side, b: &Side, rate: f64) -> Vec<f64> {
    let end = a.duration().min(b.duration());
    let keys = a.key_times().into_iter().chain(b.key_times());
    sample_times(keys, 0.0, end, rate, MAX_FRAMES).times
}

/// The size differences are measured against: the largest bounding-box diagonal of the character over `times`
/// (the origins of the bones [`Rig::character_bones`] names, at each time, with every skinned mesh at the first
/// time); 1 when that is zero (a single bone), so relative tolerances stay meaningful.
pub fn rig_size(side: &Side, times: &[f64]) -> f64 {
    let character = side.rig.character_bones(side.clip);
    let mut pose = Pose::default();
    let mut layers = side.layers.clone();
    let mut size: f64 = 0.0;
    for (i, &time) in times.iter().enumerate() {
        side.evaluate(&mut pose, &mut layers, time);
        let origins = pose.model.model.iter().zip(&character).filter(|(_, c)| **c).map(|(m, _)| m.w_axis.truncate());
        let vertices = if i == 0 {
            skin_meshes_with(side.rig, &pose.model.model, &pose.morph, side.skinning).concat()
        } else {
            Vec::new()
        };
        size = size.max(diagonal(origins.chain(vertices)));
    }
    if size > 0.0 && size.is_finite() { size } else { 1.0 }
}

/// The diagonal of the bounding box of `points` (0 for none).
fn diagonal(points: impl Iterator<Item = DVec3>) -> f64 {
    let (lo, hi) = points.fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), p| (lo.min(p), hi.max(p)));
    if lo.cmple(hi).all() { (hi - lo).length() } else { 0.0 }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::import::demo_rig;

    #[test]
    fn the_demo_arm_is_about_its_length() {
        let rig = demo_rig();
        let clip = rig.clips.first();
        let side = Side::new(&rig, clip, &rig.skeleton.declared_modes());
        let times = comparison_times(&side, &side, 30.0);
        assert_eq!(times.first(), Some(&0.0));
        assert_eq!(times.last(), Some(&side.duration()));
        let size = rig_size(&side, &times);
        let rest = rig.skeleton.rest_model_matrices();
        let span = rest.iter().map(|m| m.w_axis.truncate().length()).fold(0.0, f64::max);
        assert!(size >= span && size < 4.0 * span, "{size} against the rest span {span}");
        assert_eq!(diagonal(std::iter::empty()), 0.0);
        assert_eq!(diagonal([DVec3::ZERO, DVec3::new(3.0, 4.0, 0.0)].into_iter()), 5.0);
    }
}
