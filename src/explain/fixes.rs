//! The fixes for a sheared bone, each another evaluation of the same clip, analysed as `scan` analyses a clip and
//! compared with the declared evaluation as `diff` compares two.

use std::borrow::Cow;
use std::path::Path;
use std::sync::OnceLock;
use std::sync::atomic::AtomicBool;

use rayon::prelude::*;

use crate::analysis::{
    ClipScan, CurveRequest, Judged, SAME_SHEAR_DEG, ScanOptions, VariantJudges, analyze, around, clearly_flagged_at,
    flagged_in_run, gains, scan_variants,
};
use crate::bake::{self, ClipToBake, Request, Strategy};
use crate::diff::{
    Comparison, Extreme, Measure, MeshPair, Pairs, compare_at_size, compare_each, compare_each_beside,
    compare_each_within, compare_within, comparison_times,
};
use crate::eval::{Evaluation, Setup, Variant, bind_pose};
use crate::import;
use crate::model::{Choice, Clip, InheritMode, ModeChoice, Rig, Skeleton, Tool, Transform, Unit};

/// A change to how the clip is evaluated that may take a bone's shear away.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize)]
#[serde(tag = "kind", rename_all = "kebab-case")]
pub enum Change {
    /// One bone inherits under another mode (an engine's or DCC's flag on that bone).
    Mode { bone: usize, mode: InheritMode },
    /// One bone's local scale replaced by its uniform part (`eval::layers::uniform_part`) at every time.
    UniformScale { bone: usize },
    /// The clip baked to plain glTF as `bake` writes it: exact (helper nodes carry the stretch; the shear stays,
    /// playable by any engine) or TRS (one node per bone, the closest TRS under its baked parent; what differs is
    /// its cost). Either reproduces a source in which every bone inherits fully, shear and all.
    Bake { strategy: Strategy },
}

impl Change {
    /// One line for people, naming bones of `skeleton`.
    pub fn describe(&self, skeleton: &Skeleton) -> String {
        let name = |bone: usize| skeleton.bones().get(bone).map_or("?", |b| b.name.as_str()).to_owned();
        match *self {
            Change::Mode { bone, mode } => format!("{} → {mode}", name(bone)),
            Change::UniformScale { bone } => format!("{}'s scale made uniform", name(bone)),
            Change::Bake { strategy: Strategy::Exact } => "bake exact (helper nodes)".to_owned(),
            Change::Bake { strategy: Strategy::Trs } => "bake TRS".to_owned(),
        }
    }

    /// What is evaluated under this change, given what was (`setup`, of a rig with `skeleton`): the same clip,
    /// modes and layers but for what the change changes. A bake needs the baked rig ([`Change::baked`]) and is not
    /// one.
    pub fn apply(&self, setup: &Setup, skeleton: &Skeleton) -> Result<Setup, String> {
        let mut changed = setup.clone();
        match *self {
            Change::Mode { bone, .. } | Change::UniformScale { bone } if bone >= skeleton.len() => {
                return Err(format!("no bone {bone}"));
            }
            Change::Mode { bone, mode } => changed.modes.set(skeleton, bone, ModeChoice::Mode(mode)),
            Change::UniformScale { bone } => changed.layers.make_scale_uniform(bone),
            Change::Bake { .. } => return Err("a bake is evaluated from the rig it writes".to_owned()),
        }
        Ok(changed)
    }

    /// The bone below which (itself included) the change changes anything; `None` for the whole rig.
    pub(super) fn changed_below(&self) -> Option<usize> {
        match *self {
            Change::Mode { bone, .. } | Change::UniformScale { bone } => Some(bone),
            Change::Bake { .. } => None,
        }
    }

    /// For a bake: the rig its file holds, read back by bonescope's glTF importer, as `bake` writes it for every
    /// runtime at the default tolerance (`None` for the other changes).
    pub fn baked(&self, source: &Evaluation) -> Option<Result<Rig, String>> {
        let Change::Bake { strategy } = *self else {
            return None;
        };
        let name = source.clip.map_or_else(|| "rest pose".to_owned(), Clip::label);
        let clips = vec![ClipToBake::new(name, source.clone())];
        let request = Request::new(source.at_rest(), clips, strategy, bake::DEFAULT_TOLERANCE);
        let baked = match request {
            Ok(request) => bake::bake(&request),
            Err(error) => return Some(Err(error.to_string())),
        };
        Some(
            import::load_bytes(Path::new("baked.glb"), &baked.bytes)
                .map_err(|e| format!("the bake does not read back: {e}")),
        )
    }
}

/// Where a change's cost was largest.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Measured {
    /// At a skinned vertex (or a vertex of a mesh hanging from a bone).
    Skin,
    /// At a bone of the figure (its origin or a probe point on its axes): a rig without a mesh, a part of the figure
    /// its meshes do not cover, or a bone's tip that moves further than the skin around it.
    Bones,
}

/// How far a change moves what the viewer sees, at worst over the clip.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Cost {
    /// In the rig's units, and the first time it happens.
    pub distance: Extreme,
    /// As a fraction of the rig's size.
    pub fraction: f64,
    pub measured: Measured,
}

/// How many times a cost is searched at between the two intervals beside its worst ([`Baseline::refine`]): 15 put
/// a time within 1/16 of an interval of the peak, where a smooth distance falls short of it by the square of that,
/// under 1e-4 of the cost on every rig tested. (Searching again around the largest found, down to 1/128 of an
/// interval, changed costs by under 3e-5 and took 10–15 % longer in `scan --explain`.)
const BETWEEN: usize = 15;

/// How many changes one pass over the clip compares with the source ([`Baseline::costs`]): each holds its poses and
/// skinned meshes while the pass runs.
const BATCH: usize = 16;

/// How many variants of the source one pass over the clip scans ([`Baseline::apply_each`]): each holds a summary of
/// its own bones per run of samples while the pass runs.
const VARIANTS: usize = 32;

/// About how many times a lower bound of a cost compares ([`Baseline::cost_bound`]). The fixes of one bone often
/// cost within a few percent of each other: a bound over fewer times ranks them too loosely to rule many out, and
/// each one not ruled out is made or costed over the whole clip; over many more, bounding costs more than it saves
/// (measured in BENCHMARKS.md, §11).
const BOUND_TIMES: usize = 512;

/// Costs closer than this fraction of the rig's size are alike: the same motion measured through other rounding
/// (fixes that move the same bones the same way, evaluated along other paths, cost the same but for the last bits).
const SAME_COST: f64 = 1e-9;

/// Costs in steps of [`SAME_COST`] of the rig's size: fixes whose costs fall in one step rank alike, in the order
/// they are found for the bone (ties in a stable sort), not by their rounding.
#[derive(Clone, Copy, Debug)]
pub(super) struct CostSteps {
    unit: f64,
}

impl CostSteps {
    /// For a rig of size `rig_size` (the source's: every cost is in its units).
    pub fn of(rig_size: f64) -> Self {
        CostSteps { unit: (SAME_COST * rig_size).max(f64::MIN_POSITIVE) }
    }

    /// The step a cost of `distance` falls in.
    pub fn step(self, distance: f64) -> f64 {
        (distance / self.unit).round()
    }

    /// A distance just past every cost of step `step` (its edge moved out by far more than the rounding of the
    /// division and the product at it, a few parts in 1e16 at any step): one that moves further is in a later step.
    pub fn past(self, step: f64) -> f64 {
        (step + 0.5) * self.unit * (1.0 + 1e-12)
    }
}

/// How large the character is over a clip: the times an evaluation and its changes are compared at (its own
/// comparison times, [`comparison_times`]), and its size over them ([`Evaluation::size`]). Measuring it is a whole
/// evaluation of the clip, so one measured for an evaluation serves every explanation of it ([`super::Question`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Scale {
    pub times: Vec<f64>,
    pub size: f64,
}

impl Scale {
    /// `source`'s, its clip sampled `rate` times a second.
    pub fn of(source: &Evaluation, rate: f64) -> Self {
        Scale::against(source, source, rate)
    }

    /// `source`'s at the times it is compared with `other` at (both clips' keys and `rate` a second).
    fn against(source: &Evaluation, other: &Evaluation, rate: f64) -> Self {
        let times = comparison_times(source, other, rate);
        let size = source.size(&times);
        Scale { times, size }
    }

    /// The same size, at its times and the midpoints between them.
    fn with_midpoints(self) -> Self {
        Scale { times: crate::model::with_midpoints(&self.times), ..self }
    }
}

/// What every change is measured against, found once: the evaluation explained, its scan, its scale (for `diff`'s
/// comparison), and the options.
pub(super) struct Baseline<'e, 'a> {
    pub source: &'e Evaluation<'a>,
    pub before: &'e ClipScan,
    pub options: &'e ScanOptions,
    /// The source's own comparison times, and its size over them.
    scale: Cow<'e, Scale>,
    /// The times a scan of the source samples, which a change of modes or a uniform scale keeps (they follow the
    /// clip, and layers only where they retime it).
    analysis_times: Vec<f64>,
    /// The source's bones and meshes paired with themselves by name: what every change of the source's own rig (any
    /// but a bake) is compared on, before the pairs it leaves alone are dropped.
    own_pairs: Pairs,
    /// The rig's bind pose, found when a change first needs it (a Blender mode rests bones in it): every change of
    /// the rig is evaluated from it.
    bind_pose: OnceLock<Vec<Transform>>,
    /// What costs rank alike, for the source's size.
    pub steps: CostSteps,
}

impl<'e, 'a> Baseline<'e, 'a> {
    /// `scale` is the source's at the options' rate where already measured ([`Scale::of`]).
    pub fn new(
        source: &'e Evaluation<'a>,
        before: &'e ClipScan,
        options: &'e ScanOptions,
        scale: Option<&'e Scale>,
    ) -> Self {
        let scale = scale.map_or_else(|| Cow::Owned(Scale::of(source, options.rate)), Cow::Borrowed);
        debug_assert_eq!(scale.times, comparison_times(source, source, options.rate), "the source's scale");
        let analysis_times = source.times(options.rate);
        let own_pairs = Pairs::by_name(source, source);
        let steps = CostSteps::of(scale.size);
        Baseline { source, before, options, scale, analysis_times, own_pairs, bind_pose: OnceLock::new(), steps }
    }

    /// The cost `comparison` (of the source against a change of it) shows: the largest distance of any mesh's
    /// vertices, and of the origin and probe points of every bone of the figure; a skin that stays put does not
    /// hide a neck that moves, nor a bone's tip that swings further than the skin around it.
    fn visible(&self, comparison: &Comparison) -> Cost {
        let skin = comparison.meshes.iter().map(|m| m.distance).fold(Extreme::default(), Extreme::merge);
        let figure = self.source.skeleton().figure();
        let of_figure = comparison.bones.iter().filter(|b| figure[b.a]).map(|b| b.probe);
        let bones = of_figure.fold(Extreme::default(), Extreme::merge);
        let (distance, measured) = if bones.max > skin.max || self.source.rig.meshes.is_empty() {
            (bones, Measured::Bones)
        } else {
            (skin, Measured::Skin)
        };
        Cost { distance, fraction: distance.max / comparison.rig_size, measured }
    }

    /// `change` made to the source and scanned: on the changed bone's subtree alone when the change is to it (every
    /// other bone is as the source's scan says), on the whole baked rig for a bake.
    pub fn apply(&self, change: Change) -> Result<Applied, String> {
        let baked = change.baked(self.source).transpose()?;
        let fixed = self.fixed(change, baked.as_ref())?;
        let judged = change.changed_below().map_or(Judged::Every, Judged::Subtree);
        let request = CurveRequest { judged, ..CurveRequest::default() };
        let never = AtomicBool::new(false);
        let scan = analyze(&fixed, request, self.options, &|_, _| {}, &never).expect("never cancelled").scan;
        Ok(self.applied(change, baked, &scan))
    }

    /// Each of `changes` made and scanned as [`Baseline::apply`] does: those that are variants of the source (another
    /// mode or a uniform scale at one bone) scanned together, [`VARIANTS`] at a time in one pass over the clip
    /// ([`scan_variants`]); the others one by one, and the bakes beside them all, one after the other (each is
    /// parallel within, with a part that is not, and holds every sample of every bone while it runs).
    pub fn apply_each(&self, changes: &[Change]) -> Vec<Made> {
        // Only a change below one bone may be a variant; a bake is a rig of its own.
        let (below, bakes): (Vec<Change>, Vec<Change>) =
            changes.iter().partition(|change| change.changed_below().is_some());
        let (mut applied, baked) = rayon::join(
            || self.apply_below(below),
            || bakes.into_iter().map(|change| (change, self.apply(change))).collect::<Vec<_>>(),
        );
        applied.extend(baked);
        applied
    }

    /// Each of `changes` made and scanned ([`Baseline::apply_each`]) and, where made, costed ([`Baseline::costs`]):
    /// the variants of the source scanned in the passes that compare them with it, [`BATCH`] at a time
    /// ([`compare_each_beside`]: each variant evaluated once for both); the others (the bakes beside them all) made,
    /// then costed.
    pub fn made_and_costed(&self, changes: &[Change]) -> (Vec<Made>, Vec<Costed>) {
        // A scan samples the analysis's times, a comparison the comparison's: one pass serves both where they agree.
        let beside = self.analysis_times == self.scale.times;
        let (below, apart): (Vec<Change>, Vec<Change>) =
            changes.iter().partition(|change| beside && change.changed_below().is_some());
        let ((mut made, mut costs, left), (made_apart, costs_apart)) =
            rayon::join(|| self.made_beside(below), || self.made_then_costed(&apart));
        let (made_left, costs_left) = self.made_then_costed(&left);
        made.extend(made_apart.into_iter().chain(made_left));
        costs.extend(costs_apart.into_iter().chain(costs_left));
        (made, costs)
    }

    /// [`Baseline::made_and_costed`] of changes below one bone each, scanned as they are compared, and those left
    /// to be made apart (those that are no variants of the source).
    fn made_beside(&self, mut below: Vec<Change>) -> (Vec<Made>, Vec<Costed>, Vec<Change>) {
        let (mut made, mut costs, mut left) = (Vec::new(), Vec::new(), Vec::new());
        // Changes of one part of the rig together: each batch evaluates the source where its changes hang from.
        below.sort_by_key(|change| change.changed_below());
        for batch in below.chunks(BATCH) {
            let (on, failed) = self.compared_on_each(batch.iter().map(|&change| (change, None, ())), true);
            made.extend(failed.into_iter().map(|(change, why)| (change, Err(why))));
            let mut variants = Vec::new();
            for (change, on, ()) in &on {
                match Variant::of(self.source, &on.fixed) {
                    Some(variant) => variants.push((*change, on, variant)),
                    // Not read bone by bone (layers, another unit, no clip): made apart.
                    None => left.push(*change),
                }
            }
            match self.scanned_beside(&variants) {
                Some(found) => {
                    for (change, applied, cost) in found {
                        made.push((change, Ok(applied)));
                        costs.push((change, Ok(cost)));
                    }
                }
                None => left.extend(variants.iter().map(|(change, ..)| *change)),
            }
        }
        (made, costs, left)
    }

    /// Each of `changes` made ([`Baseline::apply_each`]), then those made costed ([`Baseline::costs`]).
    fn made_then_costed(&self, changes: &[Change]) -> (Vec<Made>, Vec<Costed>) {
        let made = self.apply_each(changes);
        let costed: Vec<(Change, &Applied)> =
            made.iter().filter_map(|(change, made)| Some((*change, made.as_ref().ok()?))).collect();
        let costs = self.costs(&costed);
        (made, costs)
    }

    /// Changes that are variants of the source (with what each is compared on, and the variant it is) made, scanned
    /// and costed in one pass over the clip; `None` where the comparison cannot evaluate one from the source's pose
    /// (morph targets).
    fn scanned_beside(&self, changes: &[(Change, &ComparedOn, Variant)]) -> Option<Vec<(Change, Applied, Cost)>> {
        let variants: Vec<Variant> = changes.iter().map(|(.., variant)| variant.clone()).collect();
        let judges = VariantJudges::new(self.source, &variants, self.options);
        let sides: Vec<(&Evaluation, &Pairs)> = changes.iter().map(|(_, on, _)| (&on.fixed, &on.pairs)).collect();
        let (compared, runs) = compare_each_beside(self.source, &sides, &self.scale.times, self.scale.size, &judges)?;
        let scans = judges.scans(self.analysis_times.clone(), runs);
        let found: Vec<_> = changes.iter().zip(scans).zip(compared).collect();
        let made = found.into_par_iter().map(|(((change, on, _), scan), comparison)| {
            (*change, self.applied(*change, None, &scan), self.refine(on, self.visible(&comparison)))
        });
        Some(made.collect())
    }

    /// [`Baseline::apply_each`] of changes below one bone each.
    fn apply_below(&self, mut below: Vec<Change>) -> Vec<Made> {
        let (mut applied, mut alone) = (Vec::new(), Vec::new());
        // Changes of one part of the rig together, each batch's evaluations made for it alone.
        below.sort_by_key(|change| change.changed_below());
        for batch in below.chunks(VARIANTS) {
            let mut made = Vec::new();
            for &change in batch {
                match self.fixed(change, None) {
                    Ok(fixed) => made.push((change, fixed)),
                    Err(why) => applied.push((change, Err(why))),
                }
            }
            let (mut scanned, mut variants) = (Vec::new(), Vec::new());
            for (change, fixed) in &made {
                if let Some(variant) = Variant::of(self.source, fixed) {
                    scanned.push(*change);
                    variants.push(variant);
                } else {
                    // Not read bone by bone (layers, another unit, no clip): made and scanned on its own.
                    alone.push(*change);
                }
            }
            let scans = scan_variants(self.source, &variants, self.options);
            applied.extend(
                scanned.into_iter().zip(&scans).map(|(change, scan)| (change, Ok(self.applied(change, None, scan)))),
            );
        }
        applied.par_extend(alone.into_par_iter().map(|change| (change, self.apply(change))));
        applied
    }

    /// `change` made (`baked`: the rig a bake writes) as `scan` found it: the changed bones' worst shear and
    /// verdicts from the change's scan, the others' from the source's.
    fn applied(&self, change: Change, baked: Option<Rig>, scan: &ClipScan) -> Applied {
        let (skeleton, changed) = (self.source.skeleton(), self.changed(change));
        let bone_of = |b: usize| match &baked {
            Some(rig) => rig.skeleton.find(&skeleton.bone(b).name),
            None => Some(b),
        };
        let shear = (0..skeleton.len())
            .map(|b| match bone_of(b) {
                Some(f) if changed(b) => (scan.bones[f].worst_shear_deg, scan.bones[f].stretched()),
                Some(_) => (self.before.bones[b].worst_shear_deg, self.before.bones[b].stretched()),
                None => (0.0, false),
            })
            .collect();
        Applied { baked, shear }
    }

    /// Whether `change` certainly leaves `bone` flagged: it is flagged in the run of samples that holds the bone's
    /// worst shear in the source, judged exactly as [`Baseline::apply`]'s scan judges that run
    /// ([`flagged_in_run`]). A change that does not remove a shear most often leaves it there, so this settles most
    /// of them for a run's work; `false` says nothing (the change must be made to know). A bake is its own rig:
    /// never settled here.
    pub fn leaves_flagged(&self, change: Change, bone: usize) -> bool {
        self.judged_at_worst(change, bone, flagged_in_run)
    }

    /// Whether `change` clearly leaves `bone` flagged at the bone's worst sample in the source
    /// ([`clearly_flagged_at`]): what [`Baseline::leaves_flagged`] settles from one sample. `false` says nothing.
    pub fn clearly_leaves_flagged(&self, change: Change, bone: usize) -> bool {
        self.judged_at_worst(change, bone, clearly_flagged_at)
    }

    /// What `judge` (of a bone of an evaluation at a time, over the analysis's times) says of `bone` under `change`
    /// at the bone's worst time in the source; `false` for a bake or a change that cannot be made.
    fn judged_at_worst(&self, change: Change, bone: usize, judge: WorstJudge) -> bool {
        let worst = self.before.bones.get(bone).map(|b| b.worst_shear_time);
        match (change.changed_below(), worst, self.fixed(change, None)) {
            (Some(_), Some(worst), Ok(fixed)) => judge(&fixed, bone, worst, &self.analysis_times, self.options),
            _ => false,
        }
    }

    /// What `change`, made (`applied`), costs: the source and the change compared as `diff` compares them, on the
    /// changed bones and the meshes that follow them (nothing else differs), at its largest between the times
    /// compared too ([`Baseline::refine`]).
    pub fn cost(&self, change: Change, applied: &Applied) -> Result<Cost, String> {
        let cost = self.cost_within(change, applied.baked.as_ref(), f64::INFINITY)?;
        Ok(cost.expect("no cost passes an infinite limit"))
    }

    /// `cost`, found at the times compared on `on`, where it is largest between those beside the time of its worst:
    /// a cost is the largest distance over the clip, not over the times compared. [`BETWEEN`] evenly spaced times
    /// across those two intervals, in one comparison pass (a pass costs more to set up than a time costs to
    /// compare). A lower bound of the cost found at the times compared bounds this one too.
    fn refine(&self, on: &ComparedOn, cost: Cost) -> Cost {
        let (lo, hi) = around(&on.scale.times, cost.distance.time);
        let step = (hi - lo) / (BETWEEN + 1) as f64;
        let times: Vec<f64> = (1..=BETWEEN).map(|i| lo + step * i as f64).collect();
        let found = self.visible(&compare_at_size(self.source, &on.fixed, &on.pairs, &times, on.scale.size));
        if gains(found.distance.max, cost.distance.max) { found } else { cost }
    }

    /// [`Baseline::cost`] where it is at most `limit`; `None` once something moves further (the comparison given
    /// up there). Needs the change made only for a bake (`baked`: the rig it writes).
    fn cost_within(&self, change: Change, baked: Option<&Rig>, limit: f64) -> Result<Option<Cost>, String> {
        let on = self.compared_on(change, baked, true)?;
        let Scale { times, size } = &*on.scale;
        let compared = compare_within(self.source, &on.fixed, &on.pairs, times, *size, limit);
        Ok(compared.map(|c| self.refine(&on, self.visible(&c))))
    }

    /// What each of `changes` (made) costs, as [`Baseline::cost`] says ([`Baseline::costs_within`], no limit).
    pub fn costs(&self, changes: &[(Change, &Applied)]) -> Vec<Costed> {
        let asked: Vec<_> =
            changes.iter().map(|&(change, made)| (change, made.baked.as_ref(), f64::INFINITY)).collect();
        let costs = self.costs_within(&asked).into_iter();
        costs.map(|(change, cost)| (change, cost.map(|c| c.expect("no cost passes an infinite limit")))).collect()
    }

    /// What each of `asked` (a change, for a bake the rig it writes, and a limit) costs, as [`Baseline::cost_within`]
    /// says: those that keep the clip's times (all but bakes) compared [`BATCH`] at a time in one pass that evaluates
    /// and skins the source once per time for the batch, the bakes each on its own beside them.
    pub fn costs_within(&self, asked: &[Asked]) -> Vec<(Change, Result<Option<Cost>, String>)> {
        let (bakes, mut kept): (Vec<&Asked>, Vec<_>) = asked.iter().partition(|(c, ..)| c.changed_below().is_none());
        // Changes of one part of the rig together: each batch evaluates the source where its changes hang from.
        kept.sort_by_key(|(change, ..)| change.changed_below());
        let bake_costs = || {
            bakes.into_iter().map(|&(change, made, limit)| (change, self.cost_within(change, made, limit))).collect()
        };
        let (mut costs, baked): (Vec<_>, Vec<_>) = rayon::join(|| self.costs_kept(&kept), bake_costs);
        costs.extend(baked);
        costs
    }

    /// [`Baseline::costs_within`] of changes that keep the clip's times, [`BATCH`] at a time.
    fn costs_kept(&self, kept: &[&Asked]) -> Vec<(Change, Result<Option<Cost>, String>)> {
        let mut costs = Vec::new();
        for batch in kept.chunks(BATCH) {
            let (on, failed) = self.compared_on_each(batch.iter().map(|&&asked| asked), true);
            costs.extend(failed.into_iter().map(|(change, why)| (change, Err(why))));
            let sides: Vec<_> = on.iter().map(|(_, on, limit)| (&on.fixed, &on.pairs, *limit)).collect();
            let compared = compare_each_within(self.source, &sides, &self.scale.times, self.scale.size);
            let refined = on
                .par_iter()
                .zip(compared)
                .map(|((change, on, _), c)| (*change, Ok(c.map(|c| self.refine(on, self.visible(&c))))));
            costs.par_extend(refined);
        }
        costs
    }

    /// What each of `changes` (with, for a bake, the rig it writes, and what the caller keeps with it) is compared
    /// with the source on ([`Baseline::compared_on`]), and why each that cannot be made cannot.
    fn compared_on_each<'r, T>(
        &self,
        changes: impl Iterator<Item = (Change, Option<&'r Rig>, T)>,
        skin: bool,
    ) -> (Vec<(Change, ComparedOn<'r, '_>, T)>, Vec<Unmade>)
    where
        'a: 'r,
    {
        let (mut on, mut failed) = (Vec::new(), Vec::new());
        for (change, baked, kept) in changes {
            match self.compared_on(change, baked, skin) {
                Ok(compared) => on.push((change, compared, kept)),
                Err(why) => failed.push((change, why)),
            }
        }
        (on, failed)
    }

    /// The lower bound of [`Baseline::cost`] of each of `asked` (a change, and for a bake the rig it writes:
    /// [`Baseline::cost_bound`]): those that keep the clip's times compared [`BATCH`] at a time in one pass over
    /// the bound's times that evaluates the source once per time for the batch, the batches and the bakes in
    /// parallel.
    pub fn cost_bounds(&self, asked: &[(Change, Option<&Rig>)]) -> Vec<(Change, Result<f64, String>)> {
        let (bakes, mut kept): (Vec<&(Change, Option<&Rig>)>, Vec<_>) =
            asked.iter().partition(|(c, _)| c.changed_below().is_none());
        kept.sort_by_key(|(change, _)| change.changed_below());
        let stride = (self.scale.times.len() / BOUND_TIMES).max(1);
        let times: Vec<f64> = self.scale.times.iter().copied().step_by(stride).collect();
        let kept = kept.par_chunks(BATCH).flat_map_iter(|batch| {
            let (on, failed) = self.compared_on_each(batch.iter().map(|&&(change, _)| (change, None, ())), false);
            let sides: Vec<(&Evaluation, &Pairs)> = on.iter().map(|(_, on, _)| (&on.fixed, &on.pairs)).collect();
            let compared = compare_each(self.source, &sides, &times, self.scale.size);
            let bounds = on.iter().zip(compared).map(|((change, ..), c)| (*change, Ok(self.visible(&c).distance.max)));
            failed.into_iter().map(|(change, why)| (change, Err(why))).chain(bounds.collect::<Vec<_>>())
        });
        let bakes = bakes.par_iter().map(|&&(change, baked)| (change, self.cost_bound(change, baked)));
        kept.chain(bakes).collect()
    }

    /// A lower bound of [`Baseline::cost`] for a fraction of the work: the bones alone, no skin, at about
    /// [`BOUND_TIMES`] evenly spread times (a largest distance over fewer points and times is never larger).
    /// Needs the change made only for a bake (`baked`: the rig it writes); any other change is evaluated from its
    /// setup alone, before it is scanned.
    pub fn cost_bound(&self, change: Change, baked: Option<&Rig>) -> Result<f64, String> {
        let stride = (self.scale.times.len() / BOUND_TIMES).max(1);
        Ok(self.cost_at(change, baked, stride)?.distance.max)
    }

    /// The cost of `change` (for a bake, `baked` the rig it writes) compared on the bones alone at every `stride`th
    /// time.
    fn cost_at(&self, change: Change, baked: Option<&Rig>, stride: usize) -> Result<Cost, String> {
        let on = self.compared_on(change, baked, false)?;
        let compared: Vec<f64> = on.scale.times.iter().copied().step_by(stride).collect();
        Ok(self.visible(&compare_at_size(self.source, &on.fixed, &on.pairs, &compared, on.scale.size)))
    }

    /// What `change` (for a bake, `baked` the rig it writes) is compared with the source on, with the meshes where
    /// `skin` says (else on the bones alone).
    fn compared_on<'r>(&self, change: Change, baked: Option<&'r Rig>, skin: bool) -> Result<ComparedOn<'r, '_>, String>
    where
        'a: 'r,
    {
        let fixed = self.fixed(change, baked)?;
        let mut pairs = self.pairs(change, &fixed);
        if !skin {
            pairs.meshes.clear();
        }
        // A change that keeps the clip's times (any but a bake) keeps the scale found once. A bake is compared
        // between its keys too, where it strays most (at them it matches the source best).
        let scale = match baked {
            None => Cow::Borrowed(&*self.scale),
            Some(_) => Cow::Owned(Scale::against(self.source, &fixed, self.options.rate).with_midpoints()),
        };
        Ok(ComparedOn { fixed, pairs, scale })
    }

    /// What the source and `fixed` (the evaluation `change` gives) are compared on: the bones of the figure that
    /// change (the cost reads no others) and the vertices that follow them (nothing else differs).
    fn pairs(&self, change: Change, fixed: &Evaluation) -> Pairs {
        let changed = self.changed(change);
        let figure = self.source.skeleton().figure();
        let by_name = match std::ptr::eq(fixed.rig, self.source.rig) {
            true => self.own_pairs.clone(),
            false => Pairs::by_name(self.source, fixed),
        };
        let mut pairs = Pairs { measure: Measure::Largest, ..by_name };
        pairs.bones.pairs.retain(|&(a, _)| changed(a) && figure[a]);
        let moving =
            |pair: MeshPair| Some(MeshPair { vertices: following(self.source.rig, pair.a, &changed)?, ..pair });
        pairs.meshes = pairs.meshes.into_iter().filter_map(moving).collect();
        pairs
    }

    /// The evaluation `change` gives: the baked rig's own, for a bake.
    fn fixed<'r>(&self, change: Change, baked: Option<&'r Rig>) -> Result<Evaluation<'r>, String>
    where
        'a: 'r,
    {
        match baked {
            Some(rig) => Ok(Evaluation::declared(rig, rig.clips.first())),
            None => {
                let setup = change.apply(&self.source.setup(), self.source.skeleton())?;
                let bind_pose = self.bind_pose.get_or_init(|| bind_pose(self.source.rig));
                Evaluation::of_bound(self.source.rig, &setup, bind_pose).map_err(|e| e.to_string())
            }
        }
    }

    /// Whether a source bone may change under `change`: every bone for a bake.
    fn changed(&self, change: Change) -> impl Fn(usize) -> bool + use<> {
        let below = change.changed_below().map(|top| self.source.skeleton().subtree(top));
        move |b: usize| below.as_ref().is_none_or(|bones| bones.binary_search(&b).is_ok())
    }
}

/// A change asked to be costed: the change, for a bake the rig it writes, and the limit past which its comparison is
/// given up.
pub(super) type Asked<'r> = (Change, Option<&'r Rig>, f64);

/// A judge of whether a bone of an evaluation is flagged around a time: the bone, the time, the analysis's times.
type WorstJudge = fn(&Evaluation, usize, f64, &[f64], &ScanOptions) -> bool;

/// A change that cannot be made, and why.
type Unmade = (Change, String);

/// A change made, or why it cannot be.
pub(super) type Made = (Change, Result<Applied, String>);

/// What a change costs, or why that cannot be found.
pub(super) type Costed = (Change, Result<Cost, String>);

/// What a change is compared with the source on: the evaluation it gives, the pairs, and the source's scale at the
/// times the two are compared at.
struct ComparedOn<'r, 't> {
    fixed: Evaluation<'r>,
    pairs: Pairs,
    scale: Cow<'t, Scale>,
}

/// A change made and scanned: for a bake, the baked rig read back; and by the source's bone index, each bone's worst
/// shear in degrees and whether it is flagged anywhere (a bone the changed rig lacks counts as neither).
pub(super) struct Applied {
    pub baked: Option<Rig>,
    pub shear: Vec<(f64, bool)>,
}

impl Applied {
    /// Where a fix by this change for `bone` ranks before its cost is known: fixes that leave the bone unflagged
    /// first, the modes of the file's own tool before others, then by the shear they leave ([`rank`]).
    pub fn standing(&self, bone: usize, other_mode: bool) -> (bool, bool, f64) {
        let (shear, flagged) = self.shear[bone];
        (flagged, other_mode, if flagged { shear } else { 0.0 })
    }
}

/// The vertices of mesh `mesh` of `rig` that move where the bones `changed` says do: `None` for none, `Some(None)`
/// for every one (a mesh that hangs from a changed bone, unskinned, or a skin that follows a changed node), else
/// those weighted to a changed joint (any weight but zero, as skinning reads them).
fn following(rig: &Rig, mesh: usize, changed: impl Fn(usize) -> bool) -> Option<Option<Vec<u32>>> {
    let mesh = &rig.meshes[mesh];
    let skin = mesh.skin.and_then(|s| rig.skins.get(s)).filter(|_| mesh.joints.len() == mesh.positions.len());
    let Some(skin) = skin else {
        return changed(mesh.bone).then_some(None);
    };
    if skin.node_bind.is_some_and(|node| changed(node.bone)) {
        return Some(None);
    }
    let moves = |(&j, &w): (&u16, &f32)| w != 0.0 && skin.joints.get(usize::from(j)).is_some_and(|&b| changed(b));
    let weighted = mesh.joints.iter().zip(&mesh.weights).enumerate();
    let vertices: Vec<u32> =
        weighted.filter(|(_, (js, ws))| js.iter().zip(ws.iter()).any(moves)).map(|(v, _)| v as u32).collect();
    (!vertices.is_empty()).then_some(Some(vertices))
}

/// One fix for one bone.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Fix {
    pub change: Change,
    /// [`Change::describe`].
    pub label: String,
    /// The bone's worst shear over the clip with the change, in degrees.
    pub shear_left_deg: f64,
    /// Whether the bone is no longer flagged anywhere in the clip.
    pub removes: bool,
    /// The other bones whose verdict the change changes, or whose worst shear it moves by more than the shear
    /// tolerance while they are flagged, in bone order.
    pub elsewhere: Vec<ShearElsewhere>,
    pub cost: Cost,
}

/// Another bone's worst shear over the clip before and with a change, and whether it is flagged.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct ShearElsewhere {
    pub bone: usize,
    pub name: String,
    pub before_deg: f64,
    pub after_deg: f64,
    pub flagged_before: bool,
    pub flagged_after: bool,
}

impl Fix {
    /// The fix `change` (made: `applied`, costing `cost`) is for `bone`, given what the clip did before (scanned
    /// with `min_shear_deg` as the shear tolerance).
    pub(super) fn new(
        skeleton: &Skeleton,
        bone: usize,
        change: Change,
        applied: &Applied,
        cost: Cost,
        (before, min_shear_deg): (&ClipScan, f64),
    ) -> Self {
        let (shear_left, still) = applied.shear[bone];
        let elsewhere = before.bones.iter().zip(&applied.shear).filter(|(b, _)| b.index != bone).filter_map(
            |(was, &(after_deg, flagged_after))| {
                let (before_deg, flagged_before) = (was.worst_shear_deg, was.stretched());
                let moved = (flagged_before || flagged_after) && (after_deg - before_deg).abs() > min_shear_deg;
                (moved || flagged_before != flagged_after).then(|| ShearElsewhere {
                    bone: was.index,
                    name: skeleton.bone(was.index).name.clone(),
                    before_deg,
                    after_deg,
                    flagged_before,
                    flagged_after,
                })
            },
        );
        Fix {
            change,
            label: change.describe(skeleton),
            shear_left_deg: shear_left,
            removes: !still,
            elsewhere: elsewhere.collect(),
            cost,
        }
    }

    /// Whether the fix changes nothing worth offering for a bone whose worst shear is `shear_deg`: a mode or scale
    /// change that leaves the shear where it was (within `min_shear_deg`), moves nothing visibly
    /// ([`super::INVISIBLE`]) and changes no other bone's shear (Blender's Fix Shear on a bone whose parent does
    /// not shear it).
    pub fn changes_nothing(&self, shear_deg: f64, min_shear_deg: f64) -> bool {
        !matches!(self.change, Change::Bake { .. })
            && !self.removes
            && (self.shear_left_deg - shear_deg).abs() <= min_shear_deg
            && self.cost.fraction < super::INVISIBLE
            && self.elsewhere.is_empty()
    }

    /// The other bones the change flags that were not flagged before.
    pub fn newly_flagged(&self) -> Vec<&str> {
        self.elsewhere.iter().filter(|e| e.flagged_after && !e.flagged_before).map(|e| e.name.as_str()).collect()
    }

    /// The other bones flagged before that the change leaves unflagged.
    pub fn cleared(&self) -> Vec<&str> {
        self.elsewhere.iter().filter(|e| e.flagged_before && !e.flagged_after).map(|e| e.name.as_str()).collect()
    }

    /// "forearm → segment-compensate, moves the skin 0.4 mm" (and the shear it leaves, where it leaves some),
    /// lengths in `unit` (the rig's).
    pub fn summary(&self, unit: Option<Unit>) -> String {
        let left = if self.removes { String::new() } else { format!(", leaves {:.2}°", self.shear_left_deg) };
        format!("{}, {}{left}", self.label, self.moves(unit))
    }

    /// "moves the skin 0.4 mm", in `unit` (the rig's).
    pub fn moves(&self, unit: Option<Unit>) -> String {
        let moved = match self.cost.measured {
            Measured::Skin => "moves the skin",
            Measured::Bones => "moves the bones",
        };
        format!("{moved} {}", Unit::readable(unit, self.cost.distance.max))
    }
}

/// Ranks fixes: those that remove the shear first, the modes of `tool` (the file's own) before the others, by cost
/// (in `steps`: alike costs in their order); then the others the same way by the shear they leave (to
/// [`SAME_SHEAR_DEG`]), then cost.
pub(super) fn rank(fixes: &mut [Fix], tool: Option<Tool>, steps: CostSteps) {
    let key = |f: &Fix| {
        let left = if f.removes { 0.0 } else { (f.shear_left_deg / SAME_SHEAR_DEG).round() };
        (!f.removes, is_other_mode(f.change, tool), left, steps.step(f.cost.distance.max))
    };
    fixes.sort_by(|a, b| {
        let (ka, kb) = (key(a), key(b));
        ka.0.cmp(&kb.0).then(ka.1.cmp(&kb.1)).then(ka.2.total_cmp(&kb.2)).then(ka.3.total_cmp(&kb.3))
    });
}

/// Whether `change` sets a mode that `tool` (the file's own) has no setting for: every mode is a glTF's, a BVH's
/// or a USD file's.
pub fn is_other_mode(change: Change, tool: Option<Tool>) -> bool {
    matches!(change, Change::Mode { mode, .. } if tool.is_some_and(|tool| !tool.modes().contains(&mode)))
}

/// The changes worth trying for `bone`, whose chain holds the unequally scaled bones `scaled`: each bone of the
/// chain below one of them under every other mode (only a bone below a squash inherits it), each of them made
/// uniform, and both bakes where `bakes` asks for them.
pub(super) fn candidates(evaluation: &Evaluation, bone: usize, scaled: &[usize], bakes: bool) -> Vec<Change> {
    let skeleton = evaluation.skeleton();
    let chain = skeleton.chain(bone);
    let top = chain.iter().position(|b| scaled.contains(b));
    let below = top.map_or(&[][..], |top| &chain[top + 1..]);
    let modes = below.iter().flat_map(|&b| {
        let current = evaluation.modes()[b];
        InheritMode::ALL.iter().copied().filter(move |&m| m != current).map(move |mode| Change::Mode { bone: b, mode })
    });
    let uniform = chain.iter().filter(|b| scaled.contains(b)).map(|&bone| Change::UniformScale { bone });
    let bakes = Strategy::ALL.iter().filter(|_| bakes).map(|&strategy| Change::Bake { strategy });
    modes.chain(uniform).chain(bakes).collect()
}

/// Whether a bake of `evaluation` reproduces it, shear and all: every bone inherits fully (a root's mode changes
/// nothing) and no layer changes the clip, so each bone's local transform is already the TRS a glTF node holds.
pub(super) fn bakes_reproduce(evaluation: &Evaluation) -> bool {
    evaluation.layers().is_none() && (0..evaluation.skeleton().len()).all(|b| evaluation.inherits_fully(b))
}

#[cfg(test)]
mod tests {
    use glam::{DMat4, Vec3};

    use super::*;
    use crate::model::{Bone, Mesh, NodeBind, Skin, Transform};

    #[test]
    fn fixes_that_leave_the_same_shear_but_for_rounding_rank_by_cost() {
        // Three fixes of other bones leave the bone's 29.07° as it was, one ulp apart where they are evaluated along
        // other paths; the one that moves nothing comes first, whichever shear rounds lower.
        let fix = |bone: usize, shear_left_deg: f64, moved: f64| Fix {
            change: Change::Mode { bone, mode: InheritMode::SegmentCompensate },
            label: String::new(),
            shear_left_deg,
            removes: false,
            elsewhere: Vec::new(),
            cost: Cost { distance: Extreme { max: moved, time: 0.0 }, fraction: moved, measured: Measured::Bones },
        };
        let shear: f64 = 29.069865920889978;
        let (below, above) = (shear.next_down(), shear.next_up());
        let mut fixes = vec![fix(1, below, 3e-6), fix(2, above, 0.0), fix(3, shear, 3e-8), fix(4, 20.0, 0.5)];
        rank(&mut fixes, None, CostSteps::of(1.0));
        let order: Vec<usize> = fixes.iter().map(|f| f.change.changed_below().unwrap()).collect();
        assert_eq!(order, [4, 2, 3, 1], "less shear left first, then the same shear by cost");
    }

    #[test]
    fn fixes_that_move_alike_but_for_rounding_rank_in_their_order() {
        // Three removals of a rig of size 2: the second and third move 0.168 but for their last bits (an ulp below
        // and 1e-10 above, both within a billionth of the rig), the first 0.1 % more. The two alike keep their order,
        // whichever rounds lower; one cheaper by more than a step comes first; a step's edges are a step apart.
        let fix = |bone: usize, moved: f64| Fix {
            change: Change::Mode { bone, mode: InheritMode::SegmentCompensate },
            label: String::new(),
            shear_left_deg: 0.0,
            removes: true,
            elsewhere: Vec::new(),
            cost: Cost {
                distance: Extreme { max: moved, time: 0.0 },
                fraction: moved / 2.0,
                measured: Measured::Bones,
            },
        };
        let moved: f64 = 0.168;
        let steps = CostSteps::of(2.0);
        let mut fixes = vec![fix(1, moved * 1.001), fix(2, moved + 1e-10), fix(3, moved.next_down())];
        rank(&mut fixes, None, steps);
        let order: Vec<usize> = fixes.iter().map(|f| f.change.changed_below().unwrap()).collect();
        assert_eq!(order, [2, 3, 1], "alike costs in their order, then the dearer one");
        let mut fixes = vec![fix(1, moved), fix(2, moved - 4e-9)];
        rank(&mut fixes, None, steps);
        assert_eq!(fixes[0].change.changed_below(), Some(2), "2e-9 of the rig cheaper is cheaper");
        let step = steps.step(moved);
        assert!(steps.step(steps.past(step)) == step + 1.0 && steps.step(steps.past(step - 1.0)) == step);
    }

    #[test]
    fn a_change_scanned_as_it_is_compared_is_the_change_scanned_and_compared_apart() {
        // Every mode of every bone and each bone's scale made uniform, on the demo rig (a skinned tube) and the stress
        // rig (a spine, chains squashing on their fifth bone), and a bake: made and costed in the passes that compare
        // them with the source, each is what it is made and costed on its own, bit for bit. A mode a bone already
        // has, and the bake, are no variants: made apart.
        for rig in [crate::import::demo_rig(), crate::import::stress_rig(12, 300, 3)] {
            let source = Evaluation::declared(&rig, rig.clips.first());
            let options = ScanOptions::default();
            let before = crate::analysis::scan(&source, &options, &|_, _| {});
            let baseline = Baseline::new(&source, &before, &options, None);
            let of_bone = |bone: usize| {
                let modes = InheritMode::ALL.iter().map(move |&mode| Change::Mode { bone, mode });
                modes.chain([Change::UniformScale { bone }])
            };
            let mut changes: Vec<Change> = (1..rig.skeleton.len()).flat_map(of_bone).collect();
            changes.push(Change::Bake { strategy: Strategy::Trs });
            let (applied, costs) = baseline.made_and_costed(&changes);
            let costs: std::collections::HashMap<Change, Cost> =
                costs.into_iter().map(|(change, cost)| (change, cost.unwrap())).collect();
            assert_eq!((applied.len(), costs.len()), (changes.len(), changes.len()));
            for (change, made) in applied {
                let (made, alone) = (made.unwrap(), baseline.apply(change).unwrap());
                assert_eq!(made.shear, alone.shear, "{change:?}");
                assert_eq!(costs[&change], baseline.cost(change, &alone).unwrap(), "{change:?}");
            }
        }
    }

    #[test]
    fn the_vertices_a_change_moves_are_those_skinning_moves() {
        // Two joints under a root, the mesh's node beside them: vertex 0 on the first joint, vertex 1 on the second
        // with a negative weight, vertex 2 on the root. A skin that follows its node moves wholly with it.
        let bones = vec![
            Bone::joint("root", None, Transform::IDENTITY),
            Bone::joint("a", Some(0), Transform::IDENTITY),
            Bone::joint("b", Some(0), Transform::IDENTITY),
            Bone::joint("node", Some(0), Transform::IDENTITY),
        ];
        let skin = Skin { joints: vec![0, 1, 2], inverse_bind: vec![DMat4::IDENTITY; 3], ..Skin::default() };
        let mesh = Mesh {
            skin: Some(0),
            bone: 3,
            positions: vec![Vec3::X; 3],
            joints: vec![[1, 0, 0, 0], [2, 0, 0, 0], [0, 0, 0, 0]],
            weights: vec![[1.0, 0.0, 0.0, 0.0], [-0.2, 0.0, 0.0, 0.0], [1.0, 0.0, 0.0, 0.0]],
            ..Mesh::default()
        };
        let mut rig =
            Rig { skeleton: Skeleton::new(bones).unwrap(), skins: vec![skin], meshes: vec![mesh], ..Rig::default() };
        let only = |bone: usize| move |b: usize| b == bone;
        assert_eq!(following(&rig, 0, only(1)), Some(Some(vec![0])));
        assert_eq!(following(&rig, 0, only(2)), Some(Some(vec![1])), "a negative weight moves its vertex too");
        assert_eq!(following(&rig, 0, only(3)), None, "the mesh's node moves no glTF skin");
        rig.skins[0].node_bind = Some(NodeBind { bone: 3, inverse_bind: DMat4::IDENTITY });
        assert_eq!(following(&rig, 0, only(3)), Some(None), "a skin that follows its node moves with it");
    }
}
