//! Why a bone shears, and the cheapest fix.
//!
//! A bone's model matrix shears when an unequal scale on its chain meets a rotation below it that turns the scale's
//! axes: under full inheritance `W = L_root···L_parent·L_bone`, and the columns of `S·R` stay orthogonal only where
//! `R` keeps `S`'s axes on axes. **Attribution** ([`attribute`], [`causes`]) asks every bone of the chain, the bone
//! itself included, how much shear is left when only its local scale is replaced by its uniform part
//! (`eval::layers::uniform_part`), all else as evaluated; the difference is its contribution. Scales compound and
//! cancel, so contributions need not add up: the fewest bones whose uniform scales together remove the shear are
//! named as well. Over a clip every flagged sample has a main cause (the largest contribution), and the runs of
//! samples with one main cause are its time spans.
//!
//! **Fixes** ([`Change`]) are other evaluations of the same clip: one bone of the chain under another inheritance
//! mode, one squashing bone's scale made uniform (a layer), or the clip baked (exact or TRS). Each is analysed as
//! `scan` analyses a clip and compared with the evaluation explained as `diff` compares two: the shear left on the
//! bone and what it does to the others, and the visible cost, how far the skin (or, without a mesh, the bones'
//! probe points) moves at worst. A fix that removes the shear comes before one that does not; among those, the one
//! that moves the character least.

mod attribution;
mod fixes;

pub use attribution::{Attribution, CauseSpan, Causes, Link, attribute, causes, causes_each};
pub use fixes::{Change, Cost, Fix, Measured, Scale, ShearElsewhere, is_other_mode};

use std::collections::HashMap;
use std::sync::atomic::{AtomicBool, Ordering};

use glam::DVec3;
use rayon::prelude::*;

use crate::analysis::report::{AnimationInfo, AnimationScan, ExplainedBone};
use crate::analysis::sketch::Sketch;
use crate::analysis::{ClipAnalysis, CurveRequest, SAME_SHEAR_DEG, ScanOptions, Tolerances, analyze};
use crate::bake::Strategy;
use crate::eval::{Evaluation, Layers};
use crate::model::{Tool, Unit, significant};
use fixes::{Applied, Asked, Baseline, CostSteps, bakes_reproduce, candidates, rank};

/// One bone explained over a clip.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Explanation {
    pub bone: usize,
    pub name: String,
    /// Its worst shear over the clip, in degrees, as the scan found it (refined between samples).
    pub worst_shear_deg: f64,
    pub causes: Causes,
    /// Ranked: the best first. Empty when the bone is never flagged.
    pub fixes: Vec<Fix>,
    /// Changes that could not be measured, and why.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub notes: Vec<String>,
    /// Whether the clip already plays as authored in any engine: every bone inherits fully and no layer changes
    /// it, so a glTF node holds each local transform and a bake changes nothing.
    pub plays_as_authored: bool,
}

impl Explanation {
    /// The best fix, if the bone needs one.
    pub fn best_fix(&self) -> Option<&Fix> {
        self.fixes.first()
    }

    /// The answer to "make it play as authored in my engine": the exact bake, where it was measured.
    pub fn as_authored(&self) -> Option<&Fix> {
        self.fixes.iter().find(|f| f.change == Change::Bake { strategy: Strategy::Exact })
    }

    /// The answer to "take the shear out of the rig": the cheapest fix that removes it, where one does.
    pub fn removal(&self) -> Option<&Fix> {
        self.fixes.iter().find(|f| f.removes)
    }

    /// Both answers, a line each, lengths in `unit` (the rig's): "to play it as authored in any engine: bake exact,
    /// no visible change" and "to remove the shear: forearm → blender-aligned, moves the skin 11 cm — no fix under
    /// 1 % of the rig". Empty when the bone is never flagged.
    pub fn answers(&self, unit: Option<Unit>) -> Vec<String> {
        if self.causes.stretched_samples == 0 {
            return Vec::new();
        }
        let mut lines = Vec::new();
        match self.as_authored() {
            Some(bake) => {
                let change =
                    if bake.cost.fraction < INVISIBLE { "no visible change".to_owned() } else { bake.moves(unit) };
                lines.push(format!("to play it as authored in any engine: bake exact, {change}"));
            }
            None if self.plays_as_authored => lines.push(
                "to play it as authored in any engine: it already does (every bone inherits fully, as glTF's nodes \
                 do; the shear is in the clip)"
                    .to_owned(),
            ),
            None => {}
        }
        let removal = match self.removal() {
            Some(fix) if fix.cost.fraction >= SMALL => format!("{} — no fix under 1 % of the rig", fix.summary(unit)),
            Some(fix) => fix.summary(unit),
            None => "no single change removes it".to_owned(),
        };
        lines.push(format!("to remove the shear: {removal}"));
        lines
    }

    /// The fixes to show: all of them where `all`, else those that change something (see [`Fix::changes_nothing`]).
    pub fn shown_fixes(&self, all: bool, min_shear_deg: f64) -> impl Iterator<Item = &Fix> {
        self.fixes.iter().filter(move |f| all || !f.changes_nothing(self.worst_shear_deg, min_shear_deg))
    }

    /// The explanation in brief, as `scan --explain` records it.
    pub fn brief(&self, unit: Option<Unit>) -> ExplainedBone {
        let fix = self.best_fix();
        ExplainedBone {
            name: self.name.clone(),
            main_cause: self.causes.at.main_cause().map(|l| l.name.clone()),
            together: self.causes.at.together().iter().map(|l| l.name.clone()).collect(),
            answers: self.answers(unit),
            best_fix: fix.map(|f| f.label.clone()),
            fix_removes: fix.map(|f| f.removes),
            fix_cost: fix.map(|f| f.cost.distance.max),
            fix_cost_fraction: fix.map(|f| f.cost.fraction),
            line: self.headline(unit),
        }
    }

    /// One line for a report: the main cause where the bone shears most, and the best fix (the cheapest that
    /// removes the shear, where one does), lengths in `unit` (the rig's). "forearm: upper_arm's scale (1.3, 0.8, 1)
    /// under a 35° turn; fix: forearm → segment-compensate, moves the skin 0.4 mm".
    pub fn headline(&self, unit: Option<Unit>) -> String {
        let name = &self.name;
        if self.causes.stretched_samples == 0 {
            return format!("{name}: not sheared beyond the tolerances");
        }
        let at = &self.causes.at;
        let cause = match (at.main_cause(), at.together().as_slice()) {
            (Some(link), _) if link.bone == self.bone => "its own stretch".to_owned(),
            (Some(link), _) => {
                let turn = link.turn_deg.unwrap_or(0.0);
                format!("{}'s scale {} under a {turn:.0}° turn", link.name, scale_text(link.scale))
            }
            (None, []) => "no single bone's scale".to_owned(),
            (None, [one]) => format!("{}'s scale {}", one.name, scale_text(one.scale)),
            (None, together) => {
                let each: Vec<String> =
                    together.iter().map(|l| format!("{} {}", l.name, scale_text(l.scale))).collect();
                format!("the scales of {} together, no one alone", each.join(" and "))
            }
        };
        match self.best_fix() {
            Some(fix) => format!("{name}: {cause}; fix: {}", fix.summary(unit)),
            None => format!("{name}: {cause}"),
        }
    }
}

/// A scale's factors with the digits that tell them apart: three significant ones, and more where factors unequal
/// by the default anisotropy tolerance would print alike, up to six decimals ("(1.002, 1, 1)", not "(1, 1, 1)").
fn scale_text(scale: DVec3) -> String {
    let k = scale.to_array();
    let unequal = Tolerances::default().min_anisotropy;
    let apart = |d: usize| {
        let differ = |i: usize, j: usize| (k[i] - k[j]).abs() > unequal * k[i].abs().min(k[j].abs());
        let pairs = [(0, 1), (0, 2), (1, 2)];
        pairs.iter().all(|&(i, j)| !differ(i, j) || format!("{:.d$}", k[i]) != format!("{:.d$}", k[j]))
    };
    let decimals = (0..=6).find(|&d| apart(d)).unwrap_or(6);
    let text = |x: f64| {
        let fixed = format!("{x:.decimals$}");
        let fixed = if fixed.contains('.') { fixed.trim_end_matches('0').trim_end_matches('.') } else { &fixed };
        let short = significant(x);
        // Whichever shows more digits.
        if fixed.len() > short.len() { fixed.to_owned() } else { short }
    };
    let [x, y, z] = k.map(text);
    format!("({x}, {y}, {z})")
}

/// `explain`'s report of a file: the bones explained over one clip, as `explain --format json` prints it.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Report<'a> {
    pub file: String,
    pub animation: Option<AnimationInfo>,
    /// The mode given for every bone, or `declared`.
    pub inherit: String,
    pub rate: f64,
    /// The layers the clip plays through (the default for none).
    pub layers: Layers,
    /// The rig's unit, where its file states one: every length (the fixes' costs) is in it.
    pub unit: Option<Unit>,
    pub bones: &'a [Explanation],
}

impl<'a> Report<'a> {
    /// `bones`, explained over `evaluation`'s clip sampled at `rate` per second, of the file shown as `file`.
    pub fn new(file: String, evaluation: &Evaluation, rate: f64, bones: &'a [Explanation]) -> Self {
        let setup = evaluation.setup();
        Report {
            file,
            animation: evaluation.clip.map(AnimationInfo::of),
            inherit: setup.modes.label().to_owned(),
            rate,
            layers: setup.layers,
            unit: evaluation.rig.unit,
            bones,
        }
    }
}

/// `evaluation`'s clip scanned as `scan` reports it, each stretched bone explained in brief (its main cause and
/// best fix) where `explained` asks: one clip of `scan [--explain]`. `None` once `cancel` is set (checked between
/// runs of samples and before the explanations).
pub fn scan_clip(
    evaluation: &Evaluation,
    options: &ScanOptions,
    explained: bool,
    cancel: &AtomicBool,
) -> Option<AnimationScan> {
    let analysis = analyze(evaluation, CurveRequest::default(), options, &|_, _| {}, cancel)?;
    let briefs = match explained {
        _ if cancel.load(Ordering::Relaxed) => return None,
        true => explain(evaluation, &analysis, Question { costs: Costs::Best, ..Question::default() }, options),
        false => Vec::new(),
    };
    let inherit = evaluation.setup().modes.label().to_owned();
    let sketch = Sketch::of(evaluation, &analysis.scan, &options.tolerances);
    let scanned = AnimationScan::new(evaluation.skeleton(), evaluation.clip, inherit, options.rate, analysis.scan);
    let explained = briefs.iter().map(|e| e.brief(evaluation.rig.unit)).collect();
    Some(AnimationScan { explained, sketch, ..scanned })
}

/// Below this fraction of the rig's size a change is not visible: the exact bake's rounding.
pub const INVISIBLE: f64 = 1e-4;

/// A fix that moves the character by this fraction of the rig's size or more is no small change.
pub const SMALL: f64 = 0.01;

/// Which fixes an explanation measures the cost of.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Costs {
    /// Every candidate's: the whole ranking (`explain`, the app).
    #[default]
    Every,
    /// Only those that can rank first once their shear is known, and no bake that reproduces the clip (it removes
    /// nothing): the best fix alone (`scan --explain`).
    Best,
}

/// What to explain: which bones (every flagged bone, the worst first, for `None`), the time to detail (each bone's
/// worst for `None`), and which fixes to cost; and the evaluation's [`Scale`] at the options' rate where it is
/// already measured (else it is measured, where there is something to explain).
#[derive(Clone, Copy, Debug, Default)]
pub struct Question<'q> {
    pub bones: Option<&'q [usize]>,
    pub at: Option<f64>,
    pub costs: Costs,
    pub scale: Option<&'q Scale>,
}

/// Explains the bones `question` asks about over `evaluation`'s clip. `analysis` is the clip's with `options`, every
/// bone judged ([`crate::analysis::scan`]'s: where each bone is flagged, and what the fixes change). A change shared
/// by several bones' fixes is made and measured once.
pub fn explain(
    evaluation: &Evaluation,
    analysis: &ClipAnalysis,
    question: Question,
    options: &ScanOptions,
) -> Vec<Explanation> {
    let before = &analysis.scan;
    let flagged = || before.stretched_worst_first().iter().map(|b| b.index).collect();
    let bones = question.bones.map_or_else(flagged, <[usize]>::to_vec);
    if bones.is_empty() {
        // Nothing sheared, nothing asked: no baseline to measure (a whole evaluation of a long clip).
        return Vec::new();
    }
    debug_assert_eq!(analysis.times, evaluation.times(options.rate), "the analysis's times");
    let tolerances = &options.tolerances;
    // Detailed at the time asked for, else where the scan found the bone's worst shear (refined between samples):
    // one figure per bone, whatever the sampling.
    let at = |bone: usize| question.at.unwrap_or_else(|| before.bones.get(bone).map_or(0.0, |b| b.worst_shear_time));
    let asked: Vec<(usize, f64)> = bones.iter().map(|&bone| (bone, at(bone))).collect();
    let causes = causes_each(evaluation, analysis, &asked, tolerances);
    // A bake that reproduces the clip leaves every shear where it was: no candidate for the best fix.
    let plays_as_authored = bakes_reproduce(evaluation);
    let bakes = question.costs == Costs::Every || !plays_as_authored;
    let changes: Vec<Vec<Change>> = bones
        .iter()
        .zip(&causes)
        .map(|(&bone, causes)| match causes.stretched_samples {
            0 => Vec::new(),
            _ => candidates(evaluation, bone, &scaled(causes, tolerances.min_anisotropy), bakes),
        })
        .collect();
    let baseline = Baseline::new(evaluation, before, options, question.scale);
    let tool = evaluation.rig.tool;
    let mut known = Known::default();
    match question.costs {
        Costs::Every => {
            let every: Vec<Change> = changes.iter().flatten().copied().collect();
            known.make_costed(&baseline, &every);
        }
        Costs::Best => {
            let bakes: Vec<Change> =
                changes.iter().flatten().copied().filter(|c| c.changed_below().is_none()).collect();
            known.make(&baseline, &bakes);
            let open = open_changes(&baseline, &bones, &changes, tool);
            known.bound(&baseline, &open.iter().flatten().map(|&(_, change)| change).collect::<Vec<_>>());
            let mut searches: Vec<Removal> = bones
                .iter()
                .zip(&open)
                .map(|(&bone, open)| Removal::new(bone, open, &known.bounds, baseline.steps))
                .collect();
            remove(&baseline, &mut searches, &mut known);
            // Where no change removes the shear, the best is among every change made.
            let unremoved: Vec<usize> = (0..bones.len()).filter(|&i| searches[i].best.is_none()).collect();
            known.make(&baseline, &unremoved.iter().flat_map(|&i| changes[i].iter().copied()).collect::<Vec<_>>());
            for i in unremoved {
                cheapest(&baseline, &contenders(bones[i], &changes[i], &known.applied, tool), &mut known);
            }
        }
    }
    let Known { applied, costs, .. } = known;
    let steps = baseline.steps;
    let skeleton = evaluation.skeleton();
    let scanned = (before, tolerances.min_shear_deg);
    let explained = bones.iter().zip(causes).zip(changes).map(|((&bone, causes), changes)| {
        let mut fixes = Vec::new();
        let mut notes = Vec::new();
        for change in changes {
            match (applied.get(&change), costs.get(&change)) {
                (Some(Ok(made)), Some(Ok(cost))) => {
                    fixes.push(Fix::new(skeleton, bone, change, made, *cost, scanned));
                }
                (Some(Err(why)), _) | (_, Some(Err(why))) => {
                    notes.push(format!("{}: {why}", change.describe(skeleton)));
                }
                // Not made or not costed: not needed for the best fix.
                (None, _) | (Some(Ok(_)), None) => {}
            }
        }
        rank(&mut fixes, tool, steps);
        let worst_shear_deg = before.bones.get(bone).map_or(0.0, |b| b.worst_shear_deg);
        let name = skeleton.bone(bone).name.clone();
        Explanation { bone, name, worst_shear_deg, causes, fixes, notes, plays_as_authored }
    });
    explained.collect()
}

/// What is known of the changes looked at so far, each found once for every bone whose fixes include it: made
/// and scanned, costed, and the lower bound of its cost.
#[derive(Default)]
struct Known {
    applied: HashMap<Change, Result<Applied, String>>,
    costs: HashMap<Change, Result<Cost, String>>,
    /// [`Baseline::cost_bound`]; `None` where it could not be found (the change is then not a contender).
    bounds: HashMap<Change, Option<f64>>,
}

impl Known {
    /// Makes each of `changes` not yet made, in parallel.
    fn make(&mut self, baseline: &Baseline, changes: &[Change]) {
        let missing = distinct(changes.iter().copied().filter(|change| !self.applied.contains_key(change)));
        self.applied.extend(baseline.apply_each(&missing));
    }

    /// Makes and costs each of `changes` not yet made, in one pass over the clip for both where they are variants
    /// of the source ([`Baseline::made_and_costed`]); a cost found before is kept.
    fn make_costed(&mut self, baseline: &Baseline, changes: &[Change]) {
        let missing = distinct(changes.iter().copied().filter(|change| !self.applied.contains_key(change)));
        let (applied, costs) = baseline.made_and_costed(&missing);
        self.applied.extend(applied);
        for (change, cost) in costs {
            self.costs.entry(change).or_insert(cost);
        }
    }

    /// The lower bound of the cost of each of `changes`, those not known yet found together
    /// ([`Baseline::cost_bounds`]; a bake's needs it made: one that is not has none).
    fn bound(&mut self, baseline: &Baseline, changes: &[Change]) -> Vec<Option<f64>> {
        let missing = distinct(changes.iter().copied().filter(|change| !self.bounds.contains_key(change)));
        let (mut asked, mut unbounded) = (Vec::new(), Vec::new());
        for change in missing {
            match (change.changed_below(), self.applied.get(&change)) {
                (Some(_), _) => asked.push((change, None)),
                (None, Some(Ok(Applied { baked: Some(rig), .. }))) => asked.push((change, Some(rig))),
                (None, _) => unbounded.push(change),
            }
        }
        let found = baseline.cost_bounds(&asked).into_iter().map(|(change, bound)| (change, bound.ok()));
        let found: Vec<(Change, Option<f64>)> = found.collect();
        self.bounds.extend(found.into_iter().chain(unbounded.into_iter().map(|change| (change, None))));
        changes.iter().map(|change| self.bounds[change]).collect()
    }
}

/// Each bone's changes that may remove its shear, with their places among its changes: those that set no mode
/// foreign to the file's tool, but for those that clearly leave the bone flagged where it is worst
/// ([`Baseline::clearly_leaves_flagged`]: one sample, where a bound is a pass over the bound's times). A change that
/// does not remove a shear most often leaves it there: most are settled so, whatever they cost.
fn open_changes(
    baseline: &Baseline,
    bones: &[usize],
    changes: &[Vec<Change>],
    tool: Option<Tool>,
) -> Vec<Vec<(usize, Change)>> {
    let asked: Vec<(usize, usize, usize, Change)> = bones
        .iter()
        .zip(changes)
        .enumerate()
        .flat_map(|(i, (&bone, changes))| {
            let own = changes.iter().enumerate().filter(move |(_, change)| !is_other_mode(**change, tool));
            own.map(move |(place, &change)| (i, bone, place, change))
        })
        .collect();
    let open: Vec<bool> =
        asked.par_iter().map(|&(_, bone, _, change)| !baseline.clearly_leaves_flagged(change, bone)).collect();
    let mut each = vec![Vec::new(); bones.len()];
    for ((i, _, place, change), _) in asked.into_iter().zip(open).filter(|(_, open)| *open) {
        each[i].push((place, change));
    }
    each
}

/// One bone's search for the cheapest of its open changes ([`open_changes`]) that leaves it unflagged (costs alike,
/// in one [`CostSteps`] step: the first in its changes), making and costing as few changes as it takes. They are
/// tried in the order of their cost's lower bound ([`Baseline::cost_bound`]: a bake's once it is made, any other's
/// from its setup), until the next bound lies in a later step than the cheapest cost found (a bound never exceeds its
/// cost); one whose bound lies in the cheapest's step ranks after it where it comes after it, and is passed over.
/// What it finds depends on what each change is alone, whoever made or costed it, so the searches of every bone go on
/// side by side ([`remove`]), each needing one change made or costed at a time.
struct Removal {
    bone: usize,
    /// The changes by their bound, then their place among the bone's changes: (bound, place, change).
    order: Vec<(f64, usize, Change)>,
    /// The first of `order` not yet settled.
    next: usize,
    /// Whether the change at `next` was looked at on the run of samples where the bone is worst, and not settled.
    looked: bool,
    /// Whether the comparison of the change at `next` was given up past the cheapest cost found: it costs more.
    given_up: bool,
    /// The cheapest removal found: (cost, place, change).
    best: Option<(f64, usize, Change)>,
}

/// What a search needs to go on: a change made, or a change costed where it costs at most a limit (the cheapest
/// cost found; a comparison past it is given up).
#[derive(Clone, Copy)]
enum Need {
    Made(Change),
    Costed(Change, f64),
}

impl Need {
    fn made(self) -> Option<Change> {
        match self {
            Need::Made(change) => Some(change),
            Need::Costed(..) => None,
        }
    }

    fn costed(self) -> Option<(Change, f64)> {
        match self {
            Need::Costed(change, limit) => Some((change, limit)),
            Need::Made(_) => None,
        }
    }
}

impl Removal {
    /// The search of `bone` through `changes`, given their lower bounds (a change without one is no contender).
    /// Bounds in one step ([`CostSteps`]) are tried in the bone's order: of changes that move alike, the first.
    fn new(bone: usize, changes: &[(usize, Change)], bounds: &HashMap<Change, Option<f64>>, steps: CostSteps) -> Self {
        let bounded = changes.iter().filter_map(|&(place, change)| Some((bounds[&change]?, place, change)));
        let mut order: Vec<(f64, usize, Change)> = bounded.collect();
        order.sort_by(|a, b| steps.step(a.0).total_cmp(&steps.step(b.0)).then(a.1.cmp(&b.1)));
        Removal { bone, order, next: 0, looked: false, given_up: false, best: None }
    }

    /// Goes on as far as what is `known` settles; what it needs next, or `None` once the search is over.
    fn advance(&mut self, baseline: &Baseline, known: &Known) -> Option<Need> {
        let steps = baseline.steps;
        while let Some(&(bound, place, change)) = self.order.get(self.next) {
            if let Some((cost, first, _)) = self.best {
                // A change costs at least its bound: in a later step it costs more, in the same one it ranks after
                // the cheapest where it comes after it.
                let (step, cheapest) = (steps.step(bound), steps.step(cost));
                if step > cheapest {
                    break;
                }
                if step == cheapest && place > first {
                    (self.next, self.looked, self.given_up) = (self.next + 1, false, false);
                    continue;
                }
            }
            match self.look(baseline, known, place, change) {
                Ok(Some(cost)) => self.best = Some((cost, place, change)),
                Ok(None) => {}
                Err(need) => return Some(need),
            }
            (self.next, self.looked, self.given_up) = (self.next + 1, false, false);
        }
        self.next = self.order.len();
        None
    }

    /// What `change` (at `place` among the bone's changes) is to the search: a cheaper removal (its cost), not one
    /// (`None`), or not known yet (what is needed to know). A change not made yet is first looked at on the run of
    /// samples where the bone is worst ([`Baseline::leaves_flagged`]), which settles most that leave it flagged;
    /// once a removal is known, a change is costed (up to the cheapest cost) before it is made, as most cost more.
    fn look(&mut self, baseline: &Baseline, known: &Known, place: usize, change: Change) -> Result<Option<f64>, Need> {
        let made = known.applied.get(&change);
        let first_look = made.is_none() && !std::mem::replace(&mut self.looked, true);
        if self.given_up || (first_look && baseline.leaves_flagged(change, self.bone)) {
            return Ok(None);
        }
        let steps = baseline.steps;
        let cheaper = |cost: f64| {
            self.best.is_none_or(|(cheapest, first, _)| {
                let (step, cheapest) = (steps.step(cost), steps.step(cheapest));
                step < cheapest || (step == cheapest && place < first)
            })
        };
        // The furthest it may move and still rank first: within the cheapest's step where it comes before it, else
        // in an earlier step.
        let limit = self.best.map_or(f64::INFINITY, |(cost, first, _)| {
            steps.past(steps.step(cost) - if place < first { 0.0 } else { 1.0 })
        });
        match (made, known.costs.get(&change)) {
            (Some(Err(_)), _) | (_, Some(Err(_))) => Ok(None),
            (_, Some(Ok(cost))) if !cheaper(cost.distance.max) => Ok(None),
            (None, None) if self.best.is_some() => Err(Need::Costed(change, limit)),
            (None, _) => Err(Need::Made(change)),
            (Some(Ok(made)), _) if made.standing(self.bone, false).0 => Ok(None),
            (Some(Ok(_)), None) => Err(Need::Costed(change, limit)),
            (Some(Ok(_)), Some(Ok(cost))) => Ok(Some(cost.distance.max)),
        }
    }
}

/// The searches for each bone's cheapest removal, side by side: in each round every search goes on as far as what
/// is known settles, then what they need is made, and costed, together ([`Baseline::apply_each`] and
/// [`Baseline::costs_within`]: the changes of one part of the rig in one pass over the clip, the source evaluated
/// once per time for them all). A change several searches need is made or costed once (at the largest limit).
fn remove(baseline: &Baseline, searches: &mut [Removal], known: &mut Known) {
    loop {
        let known_now = &*known;
        let needs: Vec<(usize, Need)> = searches
            .par_iter_mut()
            .enumerate()
            .filter_map(|(i, search)| Some((i, search.advance(baseline, known_now)?)))
            .collect();
        if needs.is_empty() {
            return;
        }
        // A change made whose cost is not known yet is costed in the same pass: it is needed by a search that has
        // found no removal, and is costed next where it is one.
        let (costed, made): (Vec<Change>, Vec<Change>) =
            needs.iter().filter_map(|&(_, need)| need.made()).partition(|change| !known.costs.contains_key(change));

        known.make_costed(baseline, &costed);
        known.make(baseline, &made);
        let mut limits: HashMap<Change, f64> = HashMap::new();
        for (change, limit) in needs.iter().filter_map(|&(_, need)| need.costed()) {
            let at = limits.entry(change).or_insert(limit);
            *at = at.max(limit);
        }
        let baked = |change: &Change| match known.applied.get(change) {
            Some(Ok(made)) => made.baked.as_ref(),
            _ => None,
        };
        let asked: Vec<Asked> = distinct(limits.keys().copied())
            .into_iter()
            .map(|change| (change, baked(&change), limits[&change]))
            .collect();
        let mut given_up = Vec::new();
        for (change, cost) in baseline.costs_within(&asked) {
            match cost.transpose() {
                // Past the largest limit asked: it costs more than the cheapest removal of every search that asked.
                None => given_up.push(change),
                Some(cost) => _ = known.costs.insert(change, cost),
            }
        }
        for (i, need) in needs {
            searches[i].given_up = need.costed().is_some_and(|(change, _)| given_up.contains(&change));
        }
    }
}

/// Costs enough of `contenders` (made) into `known` for the cheapest to be among them, exactly: lower bounds of every
/// cost first ([`Baseline::cost_bound`]), then exact costs in the order of their bounds until the next bound lies in a
/// later step than the cheapest exact cost found (costs alike included, so the ranking's order among them is kept).
fn cheapest(baseline: &Baseline, contenders: &[Change], known: &mut Known) {
    let made: Vec<Change> =
        contenders.iter().copied().filter(|change| matches!(known.applied.get(change), Some(Ok(_)))).collect();
    let bounds = known.bound(baseline, &made);
    let mut bounds: Vec<(f64, Change)> =
        made.into_iter().zip(bounds).filter_map(|(change, bound)| Some((bound?, change))).collect();
    bounds.sort_by(|a, b| a.0.total_cmp(&b.0));
    let (steps, mut cheapest) = (baseline.steps, f64::INFINITY);
    for (bound, change) in bounds {
        // Costs alike rank in the bone's order: every one in the cheapest's step is costed.
        if steps.step(bound) > steps.step(cheapest) {
            break;
        }
        let Some(Ok(made)) = known.applied.get(&change) else { continue };
        let cost = known.costs.entry(change).or_insert_with(|| baseline.cost(change, made));
        if let Ok(cost) = cost {
            cheapest = cheapest.min(cost.distance.max);
        }
    }
}

/// Each change once, in a stable order.
fn distinct(changes: impl IntoIterator<Item = Change>) -> Vec<Change> {
    let mut distinct: Vec<Change> = changes.into_iter().collect();
    distinct.sort_by_cached_key(|c| format!("{c:?}"));
    distinct.dedup();
    distinct
}

/// The changes of `bone`'s fixes that can rank first once their shear is known: those that stand best
/// ([`Applied::standing`]), the shear left equal to within [`SAME_SHEAR_DEG`].
fn contenders(
    bone: usize,
    changes: &[Change],
    applied: &HashMap<Change, Result<Applied, String>>,
    tool: Option<Tool>,
) -> Vec<Change> {
    let standing =
        |change: &Change| applied[change].as_ref().ok().map(|a| a.standing(bone, is_other_mode(*change, tool)));
    let best =
        changes.iter().filter_map(standing).min_by(|a, b| a.0.cmp(&b.0).then(a.1.cmp(&b.1)).then(a.2.total_cmp(&b.2)));
    let Some((flagged, other, shear)) = best else {
        return Vec::new();
    };
    let ties = |s: (bool, bool, f64)| s.0 == flagged && s.1 == other && (s.2 - shear).abs() <= SAME_SHEAR_DEG;
    changes.iter().copied().filter(|c| standing(c).is_some_and(ties)).collect()
}

/// The bones of the chain that squash where the bone is flagged: every main cause, and every unequally scaled
/// bone at the detailed time.
fn scaled(causes: &Causes, min_anisotropy: f64) -> Vec<usize> {
    let at = causes.at.chain.iter().filter(|l| l.anisotropy > min_anisotropy).map(|l| l.bone);
    let mut bones: Vec<usize> = causes.spans.iter().map(|s| s.bone).chain(at).collect();
    bones.sort_unstable();
    bones.dedup();
    bones
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use glam::{DQuat, DVec3, Quat, Vec3};

    use super::*;
    use crate::model::{Bone, BoneTracks, Clip, InheritMode, Interpolation, Rig, Skeleton, Track, Transform};

    fn rig(bones: Vec<Bone>, clips: Vec<Clip>) -> Rig {
        Rig { skeleton: Skeleton::new(bones).unwrap(), clips, ..Rig::default() }
    }

    /// `bones` (the flagged ones for `None`) of `evaluation` explained with the default options.
    fn explained(evaluation: &Evaluation, bones: Option<&[usize]>) -> Vec<Explanation> {
        let options = ScanOptions::default();
        let before = crate::analysis::scan_analysis(evaluation, &options);
        explain(evaluation, &before, Question { bones, ..Question::default() }, &options)
    }

    fn turned(axis: DVec3, degrees: f64) -> Transform {
        Transform::from_trs(DVec3::X, DQuat::from_axis_angle(axis, degrees.to_radians()), DVec3::ONE)
    }

    /// A root scaled by `scale` and a child one along X, turned `degrees` about Z.
    fn parent_and_child(scale: DVec3, degrees: f64) -> Rig {
        let parent = Transform::from_trs(DVec3::ZERO, DQuat::IDENTITY, scale);
        rig(vec![Bone::joint("parent", None, parent), Bone::joint("child", Some(0), turned(DVec3::Z, degrees))], vec![])
    }

    #[test]
    fn scales_print_with_the_digits_that_show_them_unequal() {
        // Three significant digits, more where factors unequal by more than 0.01 % would print alike.
        assert_eq!(scale_text(DVec3::new(1.0019, 1.0, 1.0)), "(1.002, 1, 1)");
        assert_eq!(scale_text(DVec3::new(0.99999, 1.25442, 1.0)), "(1, 1.25, 1)");
        assert_eq!(scale_text(DVec3::new(0.844, 1.4093, 0.844)), "(0.844, 1.41, 0.844)");
        assert_eq!(scale_text(DVec3::new(1.00002, 1.0, 1.00001)), "(1, 1, 1)");
        assert_eq!(scale_text(DVec3::new(1.0, 1.000_15, 1.0)), "(1, 1.0002, 1)");
    }

    #[test]
    fn a_squashed_parent_over_a_turned_child_is_all_of_its_shear() {
        // Parent scaled (2, 1, 1), child turned 45° about Z: the child's X and Y axes are diag(2,1,1)·(c, s, 0)
        // and diag(2,1,1)·(−s, c, 0) with c = s = 1/√2, i.e. (√2, 1/√2, 0) and (−√2, 1/√2, 0): cos = (−2 + 1/2)/(5/2)
        // = −3/5, a shear of asin(3/5) = 36.87°. Without the parent's squash there is none.
        let rig = parent_and_child(DVec3::new(2.0, 1.0, 1.0), 45.0);
        let evaluation = Evaluation::declared(&rig, None);
        let explained = explained(&evaluation, None);
        assert_eq!(explained.len(), 1, "only the child is flagged");
        let child = &explained[0];
        let at = &child.causes.at;
        let expected = 0.6f64.asin().to_degrees();
        assert!((at.shear_deg - expected).abs() < 1e-9, "{} against {expected}", at.shear_deg);
        let parent = &at.chain[0];
        assert!(parent.shear_left_deg.abs() < 1e-9 && (parent.contribution_deg - expected).abs() < 1e-9, "{parent:?}");
        assert!(
            (parent.anisotropy - 1.0).abs() < 1e-12 && (parent.turn_deg.unwrap() - 45.0).abs() < 1e-9,
            "{parent:?}"
        );
        assert!(at.chain[1].contribution_deg.abs() < 1e-9, "the child's own scale is uniform");
        assert_eq!((at.sufficient.as_slice(), at.main_cause().map(|l| l.bone)), (&[0][..], Some(0)));
        let compensate = Change::Mode { bone: 1, mode: InheritMode::SegmentCompensate };
        let fix = child.fixes.iter().find(|f| f.change == compensate).unwrap();
        assert!(fix.removes && fix.shear_left_deg < 1e-9, "{fix:?}");
        assert!(child.fixes[0].removes, "a fix that removes the shear ranks first: {:?}", child.fixes[0]);
        let exact = child.fixes.iter().find(|f| f.change == Change::Bake { strategy: crate::bake::Strategy::Exact });
        let exact = exact.unwrap();
        assert!(
            !exact.removes && (exact.shear_left_deg - expected).abs() < 1e-4,
            "an exact bake keeps the shear: {exact:?}"
        );
        assert!(exact.cost.fraction < 1e-6 && exact.cost.measured == Measured::Bones, "{exact:?}");
    }

    /// A track of `values` at `times`, linear.
    fn track<T: crate::model::KeyValue>(times: &[f64], values: &[T]) -> Track<T> {
        Track::new(Arc::from(times), values.to_vec(), Interpolation::Linear).unwrap()
    }

    /// root → a → m → b, a and m scaled by the tracks `a` and `m`: m turns a's axes 30° about Z, b turns m's 30°
    /// about X, so b shears under a squash of either.
    fn squashed_chain(a: Track<Vec3>, m: Track<Vec3>) -> Rig {
        let bones = vec![
            Bone::joint("root", None, Transform::IDENTITY),
            Bone::joint("a", Some(0), Transform::from_trs(DVec3::X, DQuat::IDENTITY, DVec3::ONE)),
            Bone::joint("m", Some(1), turned(DVec3::Z, 30.0)),
            Bone::joint("b", Some(2), turned(DVec3::X, 30.0)),
        ];
        let (mut a_tracks, mut m_tracks) = (BoneTracks::new(1), BoneTracks::new(2));
        (a_tracks.scale, m_tracks.scale) = (Some(a), Some(m));
        m_tracks.rotation = Some(track(&[0.0], &[Quat::from_rotation_z(30f32.to_radians())]));
        rig(bones, vec![Clip::new(0, None, vec![a_tracks, m_tracks], vec![])])
    }

    /// a squashes along X until 1 s and is uniform from 1.5 s, m along Y from 2 s on, uniform until 1.5 s; a's
    /// scale is `a_scale` times that.
    fn squashes_in_turn(a_scale: Vec3) -> Rig {
        let (x, y) = (Vec3::new(1.5, 1.0, 1.0), Vec3::new(1.0, 1.5, 1.0));
        let a = track(&[0.0, 1.0, 1.5, 3.0], &[x * a_scale, x * a_scale, a_scale, a_scale]);
        squashed_chain(a, track(&[0.0, 1.5, 2.0, 3.0], &[Vec3::ONE, Vec3::ONE, y, y]))
    }

    /// `bones`' causes over `evaluation`'s clip at 10 samples a second, each detailed at its worst shear.
    fn causes_at_worst(evaluation: &Evaluation, bones: &[usize]) -> Vec<Causes> {
        let scanned = crate::analysis::scan_analysis(evaluation, &ScanOptions { rate: 10.0, ..ScanOptions::default() });
        let asked: Vec<(usize, f64)> = bones.iter().map(|&b| (b, scanned.scan.bones[b].worst_shear_time)).collect();
        causes_each(evaluation, &scanned, &asked, &Default::default())
    }

    #[test]
    fn each_squash_is_the_main_cause_while_it_lasts() {
        // a squashes until 1 s and is uniform from 1.5 s, m from 2 s on, uniform until 1.5 s.
        let rig = squashes_in_turn(Vec3::ONE);
        let evaluation = Evaluation::declared(&rig, rig.clips.first());
        let causes = causes_at_worst(&evaluation, &[3]).remove(0);
        let spans: Vec<(&str, f64, f64)> = causes.spans.iter().map(|s| (s.name.as_str(), s.from, s.to)).collect();
        assert_eq!(spans.len(), 2, "{spans:?}");
        assert_eq!((spans[0].0, spans[0].1), ("a", 0.0));
        assert!((1.4..=1.6).contains(&spans[0].2), "a is the cause until both are uniform at 1.5 s: {spans:?}");
        assert_eq!((spans[1].0, spans[1].2), ("m", 3.0));
        assert!(spans[1].1 > 1.5 && spans[1].1 < 1.7, "{spans:?}");
        assert!(causes.at.time >= 2.0, "the worst shear is under m's full squash: {:?}", causes.at);
    }

    #[test]
    fn main_causes_read_from_the_scales_are_those_the_matrices_give() {
        // Where the clip is read bone by bone, a flagged sample whose chain holds one squash takes it as its main cause
        // from the scales alone; lengths measured in another unit read whole poses, and every main cause is found
        // from the matrices. Both agree: on the stress rig (chains squashing on their fifth bone), and where a
        // chain holds two squashes at once (a fading out while m fades in), the one that shears less first.
        let mut stress = crate::import::stress_rig(24, 120, 3);
        // a's squash grows from 1.2 to 1.6 over the first second and fades out by 3 s, while m's stays at 1.3: the
        // cause changes twice.
        let a = track(&[0.0, 1.0, 3.0], &[Vec3::new(1.2, 1.0, 1.0), Vec3::new(1.6, 1.0, 1.0), Vec3::ONE]);
        let mut overlapping = squashed_chain(a, track(&[0.0], &[Vec3::new(1.0, 1.3, 1.0)]));
        // a's scale uneven by 0.009 %, under the anisotropy tolerance but enough to shear b by more than half the
        // shear tolerance alone: not certain from the scales.
        let uneven = squashes_in_turn(Vec3::new(1.0, 1.00009, 1.0));
        for rig in [&mut stress, &mut overlapping, &mut { uneven }] {
            rig.unit = Some(crate::model::Unit::METRE);
            let by_bone = Evaluation::declared(rig, rig.clips.first());
            let whole = by_bone.clone().measured_in(crate::model::Unit::metres(0.01));
            assert!(by_bone.reads_bone_by_bone() && !whole.reads_bone_by_bone());
            let scanned =
                crate::analysis::scan_analysis(&by_bone, &ScanOptions { rate: 10.0, ..ScanOptions::default() });
            let bones: Vec<usize> = (0..rig.skeleton.len()).filter(|&b| scanned.scan.bones[b].stretched()).collect();
            let asked: Vec<(usize, f64)> = bones.iter().map(|&b| (b, scanned.scan.bones[b].worst_shear_time)).collect();
            let spans = |evaluation: &Evaluation| {
                let causes = causes_each(evaluation, &scanned, &asked, &Default::default());
                causes.into_iter().map(|c| (c.stretched_samples, c.spans)).collect::<Vec<_>>()
            };
            let read = spans(&by_bone);
            assert!(read.iter().any(|(_, spans)| !spans.is_empty()), "some bone has a main cause");
            assert_eq!(read, spans(&whole));
        }
        let changing = causes_at_worst(&Evaluation::declared(&overlapping, overlapping.clips.first()), &[3]);
        let causes: Vec<&str> = changing[0].spans.iter().map(|s| s.name.as_str()).collect();
        assert_eq!(causes, ["m", "a", "m"], "a's squash outgrows m's, then fades");
    }

    #[test]
    fn causes_found_together_are_each_bone_s_found_alone() {
        // Every bone of the stress rig (a spine, chains squashing on their fifth bone), asked in reverse bone order,
        // some detailed at another time than their worst: the shared pass over the group's chains gives each bone's
        // causes bit for bit.
        let rig = crate::import::stress_rig(12, 300, 3);
        let evaluation = Evaluation::declared(&rig, rig.clips.first());
        let scanned =
            crate::analysis::scan_analysis(&evaluation, &ScanOptions { rate: 30.0, ..ScanOptions::default() });
        let times = &scanned.times;
        let at = |b: usize| {
            if b.is_multiple_of(3) { times[b % times.len()] } else { scanned.scan.bones[b].worst_shear_time }
        };
        let asked: Vec<(usize, f64)> = (0..rig.skeleton.len()).rev().map(|b| (b, at(b))).collect();
        let tolerances = crate::analysis::Tolerances::default();
        let together = causes_each(&evaluation, &scanned, &asked, &tolerances);
        let alone: Vec<Causes> =
            asked.iter().map(|&(b, at)| causes(&evaluation, &scanned, b, at, &tolerances)).collect();
        assert!(together.iter().filter(|c| c.stretched_samples > 0 && !c.spans.is_empty()).count() > 2);
        assert!(together == alone, "a bone's causes depend on the bones found with it");
    }

    #[test]
    fn an_explanation_is_the_same_to_the_last_bit_on_any_number_of_cores() {
        // The demo rig at 240 samples a second: runs of samples that start their decompositions' searches afresh
        // would fall elsewhere on one core than on three, and move the last bits of the figures with them.
        let rig = crate::import::demo_rig();
        let evaluation = Evaluation::declared(&rig, rig.clips.first());
        let options = ScanOptions { rate: 240.0, ..ScanOptions::default() };
        let on = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            pool.install(|| {
                let before = crate::analysis::scan_analysis(&evaluation, &options);
                let explained = explain(&evaluation, &before, Question::default(), &options);
                (format!("{before:?}"), explained)
            })
        };
        let (one, three) = (on(1), on(3));
        assert!(!one.1.is_empty(), "the demo's forearm is explained");
        assert!(one.0 == three.0, "the scan differs between one core and three");
        assert!(one.1 == three.1, "the explanation differs between one core and three");
    }

    #[test]
    fn a_bone_scaled_along_its_own_axes_has_nothing_to_explain() {
        // Scaled (2, 1, 1) with its child along the same axes: non-uniform, but no shear anywhere.
        let rig = parent_and_child(DVec3::new(2.0, 1.0, 1.0), 90.0);
        let evaluation = Evaluation::declared(&rig, None);
        assert!(explained(&evaluation, None).is_empty(), "nothing is flagged");
        for explained in explained(&evaluation, Some(&[0, 1])) {
            assert_eq!(explained.causes.stretched_samples, 0, "{explained:?}");
            assert!(
                explained.fixes.is_empty()
                    && explained.causes.spans.is_empty()
                    && explained.causes.at.sufficient.is_empty()
            );
            assert!(explained.causes.at.shear_deg < 1e-9);
        }
    }
}
