//! Scans of many variants of one evaluation (each another mode or a uniform scale at one bone, [`Variant`]) in one
//! pass over the clip:
//! the bones above the variants are sampled, evaluated and judged once per time for all of them, and each variant
//! evaluates and judges its own subtree under them. Explaining a shear weighs every mode of every bone below a
//! squash; scanned one by one, each would evaluate its chain from the root again. The judging is its own type
//! ([`VariantJudges`]), so that a pass that compares the variants with the evaluation judges them on its way.

use rayon::prelude::*;

use glam::{DMat4, DQuat};

use super::chunk::ChunkResult;
use super::clip_analysis::ClipScan;
use super::findings::Judge;
use super::request::ScanOptions;
use super::scan::{assemble, refine_shears};
use super::stretch::Stretch;
use crate::eval::{Beside, Evaluation, ModelPose, Pose, Reference, Variant, run_length};
use crate::model::Transform;

/// Each variant of `source` scanned as [`super::analyze`] scans it judging its top's subtree
/// ([`super::Judged::Subtree`]): the same summaries, bit for bit, for the bones of the subtree; the other bones'
/// stay empty. One pass over the clip for all of them: `variants` of one part of the rig share the most.
pub fn scan_variants(source: &Evaluation, variants: &[Variant], options: &ScanOptions) -> Vec<ClipScan> {
    if variants.is_empty() {
        return Vec::new();
    }
    let times = source.times(options.rate);
    let judges = VariantJudges::new(source, variants, options);
    let runs: Vec<JudgedRun> = times
        .par_chunks(run_length(times.len()))
        .map(|run| {
            let mut reference =
                Reference::new(source, judges.bones(), &judges.hanging_from).expect("variants have a clip");
            let mut out = ModelPose::default();
            let mut judged = judges.run(run.len());
            for (sample, &time) in run.iter().enumerate() {
                judges.reference(&mut judged, reference.evaluate(time));
                for (k, variant) in variants.iter().enumerate() {
                    reference.evaluate_variant(variant, &mut out);
                    judges.variant(&mut judged, k, sample, time, reference.pose(), &out);
                }
            }
            judged
        })
        .collect();
    judges.scans(times, runs)
}

/// Variants of one evaluation judged as [`scan_variants`] judges them, by whichever pass over the clip evaluates
/// them ([`Beside`]): a scan of its own, or a comparison of the variants with their source that judges them on the
/// way ([`crate::diff::compare_each_beside`]), each variant evaluated once for both.
pub struct VariantJudges<'v, 'e, 'a> {
    source: &'v Evaluation<'a>,
    variants: &'v [Variant<'e, 'a>],
    judge: Judge,
    /// Each variant's bones, and the bones above those that inherit their parent's stretch (judged on the source).
    own: Vec<Judging>,
    above: Judging,
    /// What a root inherits: the placement's scale.
    root: Stretch,
    /// Every variant's bones with their ancestors, and the bones the variants hang from (their tops' parents).
    evaluated: Vec<usize>,
    hanging_from: Vec<usize>,
}

/// What one run of samples found: the stretches of the bones above the variants at its last sample, each variant's
/// own, and each variant's summaries of its bones.
pub struct JudgedRun {
    above: Vec<Stretch>,
    own: Vec<Vec<Stretch>>,
    results: Vec<ChunkResult>,
}

impl<'v, 'e, 'a> VariantJudges<'v, 'e, 'a> {
    /// `variants` of `source`, judged with `options`' tolerances.
    pub fn new(source: &'v Evaluation<'a>, variants: &'v [Variant<'e, 'a>], options: &ScanOptions) -> Self {
        let skeleton = source.skeleton();
        let hanging_from: Vec<usize> = variants.iter().filter_map(|v| skeleton.parent(v.top)).collect();
        let every: Vec<usize> = variants.iter().flat_map(|v| v.bones.iter().copied()).collect();
        // Only a top that inherits its parent's stretch reads it (another mode's is its model matrix's).
        let inheriting = variants.iter().filter(|v| v.evaluation.inherits_fully(v.top));
        let read: Vec<usize> = inheriting.filter_map(|v| skeleton.parent(v.top)).collect();
        VariantJudges {
            source,
            variants,
            judge: Judge::new(&options.tolerances),
            own: variants.iter().map(Judging::of_variant).collect(),
            above: Judging::of_bones(source, &skeleton.with_ancestors(&read)),
            root: Stretch::uniform(skeleton.placement().conversion_scale()),
            evaluated: skeleton.with_ancestors(&every),
            hanging_from,
        }
    }

    /// Each variant's scan from the runs of samples at `times` (the analysis's, [`Evaluation::times`]) in time
    /// order: its summaries assembled, each worst shear refined between samples.
    pub fn scans(&self, times: Vec<f64>, runs: Vec<JudgedRun>) -> Vec<ClipScan> {
        let mut per_variant: Vec<Vec<ChunkResult>> = self.variants.iter().map(|_| Vec::new()).collect();
        for run in runs {
            per_variant.iter_mut().zip(run.results).for_each(|(chunks, chunk)| chunks.push(chunk));
        }
        let figure = self.source.skeleton().figure();
        per_variant
            .into_par_iter()
            .zip(self.variants)
            .map(|(chunks, variant)| {
                let mut analysis = assemble(figure, times.clone(), Vec::new(), chunks, &variant.bones);
                refine_shears(variant.evaluation, &analysis.times, &mut analysis.scan.bones, &self.judge);
                analysis.scan
            })
            .collect()
    }
}

impl Beside for VariantJudges<'_, '_, '_> {
    type Run = JudgedRun;

    fn bones(&self) -> &[usize] {
        &self.evaluated
    }

    fn run(&self, samples: usize) -> JudgedRun {
        JudgedRun {
            above: vec![Stretch::NONE; self.source.skeleton().len()],
            own: self.variants.iter().map(|v| vec![Stretch::NONE; v.bones.len()]).collect(),
            // Each variant's own bones alone, by their place among them.
            results: self.variants.iter().map(|v| ChunkResult::new(v.bones.len(), samples)).collect(),
        }
    }

    fn reference(&self, run: &mut JudgedRun, pose: &Pose) {
        let stretches = &mut run.above;
        for &(bone, inherits, parent) in &self.above.bones {
            let over = parent.map_or(self.root, |p| p.stretch(&[], stretches));
            let start = stretches[bone].frame();
            stretches[bone] = judged(inherits, over, &pose.local[bone], &pose.model.model[bone], start, &self.judge);
        }
    }

    fn variant(&self, run: &mut JudgedRun, k: usize, sample: usize, time: f64, reference: &Pose, model: &ModelPose) {
        let (variant, own, result) = (&self.variants[k], &mut run.own[k], &mut run.results[k]);
        for (i, &(bone, inherits, parent)) in self.own[k].bones.iter().enumerate() {
            let over = parent.map_or(self.root, |p| p.stretch(own, &run.above));
            let local = variant.local(&reference.local, bone);
            own[i] = judged(inherits, over, &local, &model.model[bone], own[i].frame(), &self.judge);
            result.add(i, sample, time, &own[i].verdict(&self.judge));
        }
    }
}

/// A bone's stretch (`start`: where a decomposition starts its search) under `over`, its parent's (or what a root
/// inherits): passed down through its local transform `local` where it `inherits` it, else decomposed from its model
/// matrix `model`.
fn judged(inherits: bool, over: Stretch, local: &Transform, model: &DMat4, start: DQuat, judge: &Judge) -> Stretch {
    match inherits {
        true => over.child(&mut &*local, start, judge),
        false => Stretch::of_matrix(model, start),
    }
}

/// Where a bone's parent is judged: among the variant's own bones (its position there), or above the variants.
#[derive(Clone, Copy)]
enum Parent {
    Own(usize),
    Above(usize),
}

impl Parent {
    /// Its stretch, given the variant's own bones' and the bones' above.
    fn stretch(self, own: &[Stretch], above: &[Stretch]) -> Stretch {
        match self {
            Parent::Own(k) => own[k],
            Parent::Above(bone) => above[bone],
        }
    }
}

/// The bones a pass judges, parents first: each with whether it inherits its parent's stretch
/// ([`Evaluation::inherits_fully`]), and where its parent is judged (`None` for a root).
struct Judging {
    bones: Vec<(usize, bool, Option<Parent>)>,
}

impl Judging {
    /// `bones` (parents first) of `evaluation`, judged above the variants.
    fn of_bones(evaluation: &Evaluation, bones: &[usize]) -> Self {
        let skeleton = evaluation.skeleton();
        let judged = bones.iter().map(|&b| (b, evaluation.inherits_fully(b), skeleton.parent(b).map(Parent::Above)));
        Judging { bones: judged.collect() }
    }

    /// The bones of `variant`.
    fn of_variant(variant: &Variant) -> Self {
        let skeleton = variant.evaluation.skeleton();
        let parent = |b: usize| {
            let p = skeleton.parent(b)?;
            Some(variant.bones.binary_search(&p).map_or(Parent::Above(p), Parent::Own))
        };
        let judged = variant.bones.iter().map(|&b| (b, variant.evaluation.inherits_fully(b), parent(b)));
        Judging { bones: judged.collect() }
    }
}

#[cfg(test)]
mod tests {
    use std::sync::atomic::AtomicBool;

    use super::*;
    use crate::analysis::{CurveRequest, Judged, analyze};
    use crate::eval::variant_changes_of as changes_of;
    use crate::import::stress_rig;
    use crate::model::InheritMode;

    #[test]
    fn a_variant_scanned_with_the_others_is_its_subtree_scanned_alone() {
        // Every other mode of every bone of the stress rig's spine and first chain (a squash on its fifth bone), and
        // each bone's scale made uniform,
        // the squash itself compensated or not, over several runs of samples: every summary of the subtree equals
        // the whole analysis's of that subtree, bit for bit.
        let rig = stress_rig(12, 300, 3);
        let options = ScanOptions::default();
        let never = AtomicBool::new(false);
        for squash in [InheritMode::Full, InheritMode::SegmentCompensate] {
            let mut modes = vec![InheritMode::Full; rig.skeleton.len()];
            modes[5] = squash;
            let source = Evaluation::new(&rig, rig.clips.first(), &modes).unwrap();
            let changed: Vec<Evaluation> = (1..rig.skeleton.len()).flat_map(|top| changes_of(&source, top)).collect();
            let variants: Vec<Variant> = changed.iter().map(|e| Variant::of(&source, e).unwrap()).collect();
            let scans = scan_variants(&source, &variants, &options);
            let mut flagged = 0;
            for (variant, scan) in variants.iter().zip(&scans) {
                let request = CurveRequest { judged: Judged::Subtree(variant.top), ..CurveRequest::default() };
                let alone = analyze(variant.evaluation, request, &options, &|_, _| {}, &never).unwrap().scan;
                assert_eq!(scan.samples, alone.samples);
                for &b in &variant.bones {
                    assert_eq!(scan.bones[b], alone.bones[b], "bone {b} below {}", variant.top);
                    flagged += usize::from(alone.bones[b].stretched());
                }
            }
            assert!(flagged > 0, "some variants shear");
        }
    }
}
