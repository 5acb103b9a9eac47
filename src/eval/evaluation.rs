//! What is evaluated: a clip of a rig under one inheritance mode per bone, through layers, skinned one way, and the
//! times a whole-clip pass visits it at, its lengths in its rig's unit or another. Every consumer builds one — the analysis, a ghost, a compared file, a bake
//! and the file it wrote, `inspect`, `export` — and a comparison is two of them.

use glam::{DMat4, DVec3, DVec4};

use super::hierarchy::HierarchyError;
use super::layers::{Resampling, RotationInterpolation};
use super::skinning::{Method as SkinningMethod, skin_meshes_with, skin_positions_with};
use super::{Hierarchy, LayerStack, ModelPose, Pose, over_runs};
use crate::model::{Clip, InheritMode, MAX_FRAMES, Modes, Rig, Skeleton, Span, Unit, sample_times};

/// A clip of a rig (its rest pose for `None`) as one evaluation sees it.
#[derive(Clone, Debug)]
pub struct Evaluation<'a> {
    pub rig: &'a Rig,
    pub clip: Option<&'a Clip>,
    /// The bones' modes, ready to combine local transforms into model matrices.
    pub hierarchy: Hierarchy,
    /// The modes as a [`Setup`](super::Setup) chose them (`--inherit full` on a rig that declares full is not
    /// `declared`), where it did.
    chosen: Option<Modes>,
    /// The layers the clip plays through; never a stack that leaves the clip as it is (that is `None`).
    layers: Option<LayerStack>,
    pub skinning: SkinningMethod,
    /// The unit lengths are measured in: the rig's own for `None` ([`Evaluation::measured_in`]).
    unit: Option<Unit>,
    /// What the model matrices multiply lengths by: 1 in the rig's own unit.
    length_scale: f64,
    /// How many seconds later than its file's clock the clip plays ([`Evaluation::delayed`]).
    delay: f64,
}

impl<'a> Evaluation<'a> {
    /// `clip` of `rig` with one mode per bone, as sampled, skinned as the file says; refused unless the modes
    /// are one per bone.
    pub fn new(rig: &'a Rig, clip: Option<&'a Clip>, modes: &[InheritMode]) -> Result<Self, HierarchyError> {
        Ok(Evaluation::under(rig, clip, Hierarchy::of_rig(rig, modes)?))
    }

    /// `clip` of `rig` under `hierarchy` (the rig's), as sampled, skinned as the file says.
    pub(super) fn under(rig: &'a Rig, clip: Option<&'a Clip>, hierarchy: Hierarchy) -> Self {
        let skinning = SkinningMethod::AsFile;
        let (unit, length_scale, delay) = (None, 1.0, 0.0);
        Evaluation { rig, clip, hierarchy, chosen: None, layers: None, skinning, unit, length_scale, delay }
    }

    /// `clip` of `rig` with the modes its file declares.
    pub fn declared(rig: &'a Rig, clip: Option<&'a Clip>) -> Self {
        Evaluation::under(rig, clip, Hierarchy::of_rig_bound(rig, &rig.skeleton.declared_modes(), None))
    }

    /// The same through `layers` (built, and so checked, for this rig). Layers that change nothing are no layers:
    /// the clip is then sampled directly.
    pub fn with_layers(mut self, layers: LayerStack) -> Self {
        self.layers = Some(layers).filter(|l| !l.is_empty());
        self
    }

    /// The same modes (and layers) on another clip of the rig.
    pub fn with_clip(mut self, clip: Option<&'a Clip>) -> Self {
        self.clip = clip;
        self
    }

    /// The same skinned with `method`.
    pub fn with_skinning(mut self, method: SkinningMethod) -> Self {
        self.skinning = method;
        self
    }

    /// The same with its lengths in `unit`: every model matrix (and so every skinned vertex) scaled about the origin
    /// by the rig's unit per `unit`, as ufbx converts an FBX file's unit (a uniform scale above the roots, which
    /// commutes with every rotation and so with every mode). Where the rig or `unit` is not known, the rig's numbers
    /// are taken as they are.
    pub fn measured_in(mut self, unit: Option<Unit>) -> Self {
        self.unit = unit;
        self.length_scale = match (self.rig.unit, unit) {
            (Some(own), Some(unit)) => own.per(unit),
            _ => 1.0,
        };
        self
    }

    /// The same played `seconds` later: the pose at time `t` is the clip's at `t − seconds` on its file's clock, and
    /// its span, key times and sample times move with it. How two files whose clocks disagree (one exporter starts
    /// a take at 0, the other at its first frame) are compared at corresponding times.
    pub fn delayed(mut self, seconds: f64) -> Self {
        self.delay = if seconds.is_finite() { seconds } else { 0.0 };
        self
    }

    /// How many seconds later than its file's clock the clip plays.
    pub fn delay(&self) -> f64 {
        self.delay
    }

    /// The same clip through the same layers under other modes, one per bone (a ghost: "what if every bone
    /// were …").
    pub fn with_modes(&self, modes: &[InheritMode]) -> Result<Self, HierarchyError> {
        Ok(Evaluation { hierarchy: Hierarchy::of_rig(self.rig, modes)?, chosen: None, ..self.clone() })
    }

    /// The same clip, without layers, its linear rotation tracks interpolated by `rotation`: as a runtime that
    /// interpolates them so plays the file (slerp is as authored, glTF's).
    pub fn played_with(self, rotation: RotationInterpolation) -> Self {
        let resampling = Resampling { rotation, ..Resampling::default() };
        self.with_layers(LayerStack::resampling(resampling))
    }

    /// The same clip as authored: without the layers.
    pub fn without_layers(&self) -> Self {
        Evaluation { layers: None, ..self.clone() }
    }

    /// The rig at rest under the same modes: no clip, no layers.
    pub fn at_rest(&self) -> Self {
        Evaluation { clip: None, layers: None, ..self.clone() }
    }

    pub fn skeleton(&self) -> &'a Skeleton {
        &self.rig.skeleton
    }

    pub fn modes(&self) -> &[InheritMode] {
        self.hierarchy.modes()
    }

    /// Whether `bone`'s model matrix is its parent's times its local matrix: full inheritance, or a root. A root's
    /// mode changes nothing (it has no parent to inherit from): FBX files declare cameras and other top-level nodes
    /// componentwise, and that must not take the whole rig off the paths that pass a parent's stretch down.
    pub fn inherits_fully(&self, bone: usize) -> bool {
        self.skeleton().parent(bone).is_none() || self.modes()[bone] == InheritMode::Full
    }

    /// The modes as chosen: a setup's, or the file's with the bones that differ given their own.
    pub fn chosen_modes(&self) -> Modes {
        self.chosen.clone().unwrap_or_else(|| Modes::of_bones(self.skeleton(), self.modes()))
    }

    /// The same, its modes called `modes` (which are the ones it evaluates).
    pub(super) fn chosen_as(self, modes: Modes) -> Self {
        Evaluation { chosen: Some(modes), ..self }
    }

    /// Per bone, what its model matrix's scale factors are divided by to be the ones the file's author set: the
    /// unit conversion above it ([`Skeleton::length_scales`]) and the unit it is measured in.
    pub fn length_scales(&self) -> Vec<f64> {
        self.rig.skeleton.length_scales().iter().map(|s| s * self.length_scale).collect()
    }

    /// The unit lengths are measured in, where not the rig's own.
    pub fn unit(&self) -> Option<Unit> {
        self.unit
    }

    pub fn layers(&self) -> Option<&LayerStack> {
        self.layers.as_ref()
    }

    /// Where the evaluation runs on its clock: the clip's span, or the layered timeline's from the clip's start (a
    /// synced blend's cycle, a crossfade into a longer clip); at 0 for the rest pose. Moved by the delay.
    pub fn span(&self) -> Span {
        let own = self.clip.map_or(Span::at(0.0), Clip::span);
        let span = match &self.layers {
            Some(layers) => Span::new(own.start, own.start + layers.length(self.rig, self.clip)),
            None => own,
        };
        span.shifted(self.delay)
    }

    /// The times at which the evaluation has keys: the clip's key times, or, where layers make a timeline of their
    /// own, its two ends.
    pub fn key_times(&self) -> Vec<f64> {
        match &self.layers {
            Some(_) => self.times(0.0),
            None => self.clip.map_or_else(|| vec![0.0], |clip| self.delayed_times(clip.key_times())),
        }
    }

    /// The times a whole-clip pass visits: every key time, plus every frame `k / rate` within the span, plus its two
    /// ends; sorted, without duplicates (thinned between sparse keys past [`MAX_FRAMES`] frames). Where the layers
    /// change the timeline (a synced blend plays a cycle of another length, a crossfade runs on into the incoming
    /// clip), the grid over the layered span and its ends. Just the start for the rest pose.
    pub fn times(&self, rate: f64) -> Vec<f64> {
        let (rig, clip) = (self.rig, self.clip);
        let own = clip.map_or(Span::at(0.0), Clip::span);
        let retimed = self
            .layers
            .as_ref()
            .is_some_and(|layers| layers.synced_cycle(rig, clip).is_some() || layers.length(rig, clip) != own.length());
        let span = self.span();
        match clip {
            _ if retimed => sample_times([], span.start, span.end, rate, MAX_FRAMES).times,
            Some(clip) => {
                sample_times(self.delayed_times(clip.key_times()), span.start, span.end, rate, MAX_FRAMES).times
            }
            None => vec![span.start],
        }
    }

    /// Times of the clip's clock as the evaluation plays them.
    fn delayed_times(&self, mut times: Vec<f64>) -> Vec<f64> {
        if self.delay != 0.0 {
            times.iter_mut().for_each(|t| *t += self.delay);
        }
        times
    }

    /// Whether a pose's bones can be read from the clip one at a time ([`super::Chains`]): no layers (which read
    /// whole poses), lengths in the rig's own unit and the file's own clock.
    pub fn reads_bone_by_bone(&self) -> bool {
        self.layers.is_none() && self.in_rig_unit() && self.delay == 0.0
    }

    /// Whether lengths are in the rig's own unit (no [`Evaluation::measured_in`] that scales them).
    pub fn in_rig_unit(&self) -> bool {
        self.length_scale == 1.0
    }

    /// A worker's state for evaluating poses one time after another (its own pose buffers and copy of the layers).
    pub fn evaluator(&self) -> Evaluator<'_, 'a> {
        Evaluator { evaluation: self, layers: self.layers.clone(), pose: Pose::default() }
    }

    /// The pose at `time` (for a single time; a loop over times reuses one [`Evaluator`]).
    pub fn pose_at(&self, time: f64) -> Pose {
        let mut evaluator = self.evaluator();
        evaluator.evaluate(time);
        evaluator.pose
    }

    /// The positions of mesh `mesh` at `pose`, morphed and skinned (`out` is reused).
    pub fn skin(&self, pose: &Pose, mesh: usize, out: &mut Vec<DVec3>) {
        let (rig, model) = (self.rig, &pose.model.model);
        skin_positions_with(&rig.meshes[mesh], &rig.skins, model, &pose.morph, self.skinning, out);
    }

    /// Every mesh at `pose`, morphed and skinned.
    pub fn skin_all(&self, pose: &Pose) -> Vec<Vec<DVec3>> {
        skin_meshes_with(self.rig, &pose.model.model, &pose.morph, self.skinning)
    }

    /// The size differences and tolerances are measured against: the largest bounding-box diagonal of the
    /// character over `times` (the origins of its bones, [`Skeleton::character`], at each time, with every skinned
    /// mesh at the first time); 1 when that is zero (a single bone), so relative figures stay meaningful.
    pub fn size(&self, times: &[f64]) -> f64 {
        let meshes: Vec<usize> = (0..self.rig.meshes.len()).collect();
        self.size_of(times, &self.rig.skeleton.character(), &meshes)
    }

    /// [`Evaluation::size`] of some of the character: the bones flagged in `bones` and the meshes `meshes`.
    pub fn size_of(&self, times: &[f64], bones: &[bool], meshes: &[usize]) -> f64 {
        let Some((&first, later)) = times.split_first() else { return 1.0 };
        let mut evaluator = self.evaluator();
        let pose = evaluator.evaluate(first);
        let mut vertices = Vec::new();
        for &mesh in meshes {
            let mut skinned = Vec::new();
            self.skin(pose, mesh, &mut skinned);
            vertices.extend(skinned);
        }
        let at_first = diagonal(origins(pose, bones).chain(vertices));
        // A whole pose at every time: the later times in runs on every core (a largest value is the same whichever
        // order it is found in).
        let runs = over_runs(later, |run| {
            let mut evaluator = self.evaluator();
            run.iter().map(|&time| diagonal(origins(evaluator.evaluate(time), bones))).fold(0.0, f64::max)
        });
        let size = runs.into_iter().fold(at_first, f64::max);
        if size > 0.0 && size.is_finite() { size } else { 1.0 }
    }
}

/// One thread's state for evaluating an [`Evaluation`] at one time after another: the pose (reused across times,
/// and across increasing times to skip key searches) and its own copy of the layers (they hold scratch buffers).
#[derive(Clone, Debug)]
pub struct Evaluator<'e, 'a> {
    evaluation: &'e Evaluation<'a>,
    layers: Option<LayerStack>,
    pub pose: Pose,
}

impl<'e, 'a> Evaluator<'e, 'a> {
    /// What this evaluator evaluates.
    pub fn evaluation(&self) -> &'e Evaluation<'a> {
        self.evaluation
    }

    /// Evaluates the pose at `time`.
    pub fn evaluate(&mut self, time: f64) -> &Pose {
        let e = self.evaluation;
        let time = time - e.delay;
        match &mut self.layers {
            Some(stack) => self.pose.evaluate_layered(e.rig, e.clip, &e.hierarchy, stack, time),
            None => self.pose.evaluate(&e.rig.skeleton, e.clip, &e.hierarchy, time),
        }
        if e.length_scale != 1.0 {
            scale_lengths(&mut self.pose.model.model, e.length_scale);
        }
        &self.pose
    }

    /// The local pose last evaluated combined under `hierarchy` (this rig's, other modes) into `out`, in this
    /// evaluation's unit: one sampling shared by several sets of modes (what `fit` tries at each time).
    pub fn model_under(&self, hierarchy: &Hierarchy, out: &mut ModelPose) {
        hierarchy.evaluate(&self.pose.local, out);
        if self.evaluation.length_scale != 1.0 {
            scale_lengths(&mut out.model, self.evaluation.length_scale);
        }
    }
}

/// `S(scale)·W` for every matrix `W`: each column's vector part scaled, the translation's included.
fn scale_lengths(model: &mut [DMat4], scale: f64) {
    let columns = DVec4::new(scale, scale, scale, 1.0);
    for m in model {
        for axis in [&mut m.x_axis, &mut m.y_axis, &mut m.z_axis, &mut m.w_axis] {
            *axis *= columns;
        }
    }
}

/// The origins of the bones flagged in `bones` at `pose`.
fn origins<'p>(pose: &'p Pose, bones: &'p [bool]) -> impl Iterator<Item = DVec3> + 'p {
    pose.model.model.iter().zip(bones).filter(|(_, c)| **c).map(|(m, _)| m.w_axis.truncate())
}

/// The diagonal of the bounding box of `points` (0 for none).
fn diagonal(points: impl Iterator<Item = DVec3>) -> f64 {
    let (lo, hi) = points.fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), p| (lo.min(p), hi.max(p)));
    if lo.cmple(hi).all() { (hi - lo).length() } else { 0.0 }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::eval::Layers;
    use crate::eval::layers::Crossfade;
    use crate::import::demo_rig;

    #[test]
    fn the_demo_arm_is_about_its_length() {
        let rig = demo_rig();
        let evaluation = Evaluation::declared(&rig, rig.clips.first());
        let times = evaluation.times(30.0);
        assert_eq!(times.first(), Some(&0.0));
        assert_eq!(times.last(), Some(&evaluation.span().end));
        let size = evaluation.size(&times);
        let rest = rig.skeleton.rest_model_matrices();
        let span = rest.iter().map(|m| m.w_axis.truncate().length()).fold(0.0, f64::max);
        assert!(size >= span && size < 4.0 * span, "{size} against the rest span {span}");
        assert_eq!(diagonal(std::iter::empty()), 0.0);
        assert_eq!(diagonal([DVec3::ZERO, DVec3::new(3.0, 4.0, 0.0)].into_iter()), 5.0);
    }

    #[test]
    fn layers_that_change_nothing_are_no_layers() {
        let rig = demo_rig();
        let plain = Evaluation::declared(&rig, rig.clips.first());
        let empty = plain.clone().with_layers(LayerStack::new(&rig, &Layers::default()).unwrap());
        assert!(empty.layers().is_none());
        assert_eq!(empty.times(30.0), plain.times(30.0));
        assert_eq!(empty.key_times(), rig.clips[0].key_times());
    }

    #[test]
    fn a_crossfade_into_a_longer_run_retimes_the_grid() {
        // A crossfade at 1.5 s into the second clip (2 s long) runs on to 3.5 s; the grid covers that at the rate,
        // both ends included, and a ghost without the layers keeps the clip's own times.
        let rig = demo_rig();
        let main = &rig.clips[0];
        let crossfade = Crossfade { clip: 1, at: 1.5, duration: 0.5, curve: Default::default() };
        let stack = LayerStack::new(&rig, &Layers { crossfade: Some(crossfade), ..Layers::default() }).unwrap();
        let layered = Evaluation::declared(&rig, Some(main)).with_layers(stack);
        let end = 1.5 + rig.clips[1].span().length();
        assert!(end > main.span().end);
        assert_eq!(layered.span(), Span::new(0.0, end));
        let times = layered.times(10.0);
        assert_eq!((times[0], *times.last().unwrap(), times.len()), (0.0, end, 36));
        assert!(times.windows(2).all(|w| (w[1] - w[0] - 0.1).abs() < 1e-12), "{times:?}");
        assert_eq!(layered.key_times(), [0.0, end]);
        assert_eq!(layered.without_layers().times(10.0), Evaluation::declared(&rig, Some(main)).times(10.0));
    }

    #[test]
    fn measured_in_centimetres_every_length_is_a_hundred_times_longer() {
        // The demo is in metres: in centimetres each origin, each axis and each vertex is 100× as long, to rounding.
        let rig = demo_rig();
        let metres = Evaluation::declared(&rig, rig.clips.first());
        let centimetres = metres.clone().measured_in("cm".parse().ok());
        let (a, b) = (metres.pose_at(0.7), centimetres.pose_at(0.7));
        for (wa, wb) in a.model.model.iter().zip(&b.model.model) {
            assert!(wb.abs_diff_eq(DMat4::from_scale(DVec3::splat(100.0)) * *wa, 1e-12), "{wa} → {wb}");
        }
        let (va, vb) = (metres.skin_all(&a), centimetres.skin_all(&b));
        for (p, q) in va.concat().iter().zip(&vb.concat()) {
            assert!((*q - 100.0 * *p).length() < 1e-12, "{p} → {q}");
        }
        let times = metres.times(10.0);
        assert!((centimetres.size(&times) / metres.size(&times) - 100.0).abs() < 1e-9);
        // A unit that is not known leaves the numbers as they are.
        let unstated = Rig { unit: None, ..rig.clone() };
        let as_is = Evaluation::declared(&unstated, rig.clips.first()).measured_in("cm".parse().ok());
        assert_eq!(as_is.pose_at(0.7).model.model, a.model.model);
        assert_eq!(metres.clone().measured_in(None).pose_at(0.7).model.model, a.model.model);
    }

    #[test]
    fn an_evaluator_matches_a_fresh_pose_at_every_time() {
        let rig = demo_rig();
        let evaluation =
            Evaluation::new(&rig, rig.clips.first(), &vec![InheritMode::Full; rig.skeleton.len()]).unwrap();
        let mut evaluator = evaluation.evaluator();
        for &time in &evaluation.times(12.0) {
            let reused = evaluator.evaluate(time).model.model.clone();
            assert_eq!(reused, evaluation.pose_at(time).model.model, "at {time}");
        }
    }
}
