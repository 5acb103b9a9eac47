//! The fixes for a sheared bone, each another evaluation of the same clip, analysed as `scan` analyses a clip and
//! compared with the declared evaluation as `diff` compares two.

use std::path::Path;

use std::sync::atomic::AtomicBool;

use crate::analysis::{ClipScan, CurveRequest, Judged, ScanOptions, analyze};
use crate::bake::{self, ClipToBake, Engine, Request, Strategy};
use crate::diff::{Comparison, Extreme, Pairs, compare, comparison_times};
use crate::eval::{Evaluation, LayerStack};
use crate::import;
use crate::model::{Choice, Clip, InheritMode, Rig, Skeleton, Unit};

/// A change to how the clip is evaluated that may take a bone's shear away.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize)]
#[serde(tag = "kind", rename_all = "kebab-case")]
pub enum Change {
    /// One bone inherits under another mode (an engine's or DCC's flag on that bone).
    Mode { bone: usize, mode: InheritMode },
    /// One bone's local scale replaced by its uniform part (`eval::layers::uniform_part`) at every time.
    UniformScale { bone: usize },
    /// The clip baked to plain glTF: exact (helper nodes carry the stretch; the shear stays, playable by any
    /// engine) or TRS (the closest transform per bone; the shear goes, at its cost).
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

    /// The evaluation of `source`'s clip under this change (layers and modes kept). A bake needs the baked rig
    /// ([`Change::baked`]) and is not one.
    pub fn apply<'a>(&self, source: &Evaluation<'a>) -> Result<Evaluation<'a>, String> {
        match *self {
            Change::Mode { bone, mode } => {
                let mut modes = source.modes().to_vec();
                *modes.get_mut(bone).ok_or("no such bone")? = mode;
                Ok(source.with_modes(&modes))
            }
            Change::UniformScale { bone } => {
                let mut layers = source.layers().map(|s| s.layers().clone()).unwrap_or_default();
                if !layers.uniform_scale.contains(&bone) {
                    layers.uniform_scale.push(bone);
                }
                let stack = LayerStack::new(source.rig, &layers).map_err(|e| e.to_string())?;
                Ok(source.clone().with_layers(stack))
            }
            Change::Bake { .. } => Err("a bake is evaluated from the rig it writes".to_owned()),
        }
    }

    /// The bone below which (itself included) the change changes anything; `None` for the whole rig.
    fn changed_below(&self) -> Option<usize> {
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
        let request = Request {
            rest: source.at_rest(),
            clips: vec![ClipToBake { name, source: source.clone() }],
            strategy,
            tolerance: bake::DEFAULT_TOLERANCE,
            engine: Engine::Generic,
        };
        let baked = bake::bake(&request);
        Some(
            import::load_bytes(Path::new("baked.glb"), &baked.glb)
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
    /// At a bone no mesh shows (its origin or a probe point on its axes): a rig without a mesh, or a part of the
    /// figure its meshes do not cover.
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

impl Cost {
    /// The cost `comparison` (of the rig `rig` against a change of it) shows: the largest distance of any mesh's
    /// vertices, and of the probe points of every bone of the figure that no mesh shows
    /// ([`Rig::shown_by_meshes`]); a skin that stays put does not hide a neck that moves.
    pub fn of(comparison: &Comparison, rig: &Rig) -> Self {
        let (shown, figure) = (rig.shown_by_meshes(), rig.skeleton.figure());
        let skin = comparison.meshes.iter().map(|m| m.distance).fold(Extreme::default(), Extreme::merge);
        let unseen = comparison.bones.iter().filter(|b| figure[b.a] && !shown[b.a]).map(|b| b.probe);
        let bones = unseen.fold(Extreme::default(), Extreme::merge);
        let (distance, measured) = if bones.max > skin.max { (bones, Measured::Bones) } else { (skin, Measured::Skin) };
        let measured = if comparison.meshes.is_empty() { Measured::Bones } else { measured };
        Cost { distance, fraction: distance.max / comparison.rig_size, measured }
    }
}

/// What one change does to the whole rig: every source bone's worst shear and flag under it, and its cost.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct Outcome {
    /// By the source's bone index: the worst shear in degrees and whether the bone is flagged anywhere (a bone the
    /// changed rig lacks counts as neither).
    pub shear: Vec<(f64, bool)>,
    pub cost: Cost,
}

impl Outcome {
    /// `change` applied to `source` and measured; `before` is `source`'s scan with `options`.
    pub fn of(source: &Evaluation, change: Change, before: &ClipScan, options: &ScanOptions) -> Result<Self, String> {
        let Some(rig) = change.baked(source) else {
            let fixed = change.apply(source)?;
            return Ok(Outcome::measure(source, &fixed, change.changed_below(), before, options, Some));
        };
        let rig = rig?;
        let fixed = Evaluation::declared(&rig, rig.clips.first());
        let skeleton = source.skeleton();
        Ok(Outcome::measure(source, &fixed, None, before, options, |b| rig.skeleton.find(&skeleton.bone(b).name)))
    }

    /// `fixed` scanned and compared with `source`: only `top` and the bones below it when the change is to them
    /// alone (every other bone is as `before` says, and its difference nothing); `bone_of` finds a source bone in
    /// `fixed`'s rig.
    fn measure(
        source: &Evaluation,
        fixed: &Evaluation,
        top: Option<usize>,
        before: &ClipScan,
        options: &ScanOptions,
        bone_of: impl Fn(usize) -> Option<usize>,
    ) -> Self {
        let judged = top.map_or(Judged::Every, Judged::Subtree);
        let request = CurveRequest { judged, ..CurveRequest::default() };
        let never = AtomicBool::new(false);
        let summary = analyze(fixed, request, options, &|_, _| {}, &never).expect("never cancelled").scan;
        let changed = top.map(|top| source.skeleton().subtree(top));
        let is_changed = |b: usize| changed.as_ref().is_none_or(|bones| bones.binary_search(&b).is_ok());
        let shear = (0..source.skeleton().len())
            .map(|b| match bone_of(b) {
                Some(f) if is_changed(b) => (summary.bones[f].worst_shear_deg, summary.bones[f].stretched()),
                Some(_) => (before.bones[b].worst_shear_deg, before.bones[b].stretched()),
                None => (0.0, false),
            })
            .collect();
        let mut pairs = Pairs::by_name(source, fixed);
        pairs.bones.pairs.retain(|&(a, _)| is_changed(a));
        let comparison = compare(source, fixed, &pairs, &comparison_times(source, fixed, options.rate));
        Outcome { shear, cost: Cost::of(&comparison, source.rig) }
    }
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
    /// Other bones flagged under the change that were not before, and flagged before that no longer are.
    pub newly_flagged: Vec<String>,
    pub cleared: Vec<String>,
    pub cost: Cost,
}

impl Fix {
    /// The fix `change` is for `bone`, given what it does (`outcome`) and what the clip did before (`before`).
    pub(super) fn new(skeleton: &Skeleton, bone: usize, change: Change, outcome: &Outcome, before: &ClipScan) -> Self {
        let (shear_left, still) = outcome.shear[bone];
        let others = |was: bool| {
            let changed = before
                .bones
                .iter()
                .zip(&outcome.shear)
                .filter(|(b, (_, now))| b.index != bone && b.stretched() == was && *now != was);
            changed.map(|(b, _)| skeleton.bone(b.index).name.clone()).collect()
        };
        Fix {
            change,
            label: change.describe(skeleton),
            shear_left_deg: shear_left,
            removes: !still,
            newly_flagged: others(false),
            cleared: others(true),
            cost: outcome.cost,
        }
    }
}

impl Fix {
    /// "forearm → segment-compensate, moves the skin 0.4 mm" (and the shear it leaves, where it leaves some),
    /// lengths in `unit` (the rig's).
    pub fn summary(&self, unit: Option<Unit>) -> String {
        let moved = match self.cost.measured {
            Measured::Skin => "moves the skin",
            Measured::Bones => "moves the bones",
        };
        let left = if self.removes { String::new() } else { format!(", leaves {:.2}°", self.shear_left_deg) };
        format!("{}, {moved} {}{left}", self.label, Unit::readable(unit, self.cost.distance.max))
    }
}

/// Ranks fixes: those that remove the shear first, by cost; then the others by the shear they leave, then cost.
pub(super) fn rank(fixes: &mut [Fix]) {
    let key = |f: &Fix| (!f.removes, if f.removes { 0.0 } else { f.shear_left_deg }, f.cost.distance.max);
    fixes.sort_by(|a, b| {
        let (ka, kb) = (key(a), key(b));
        ka.0.cmp(&kb.0).then(ka.1.total_cmp(&kb.1)).then(ka.2.total_cmp(&kb.2))
    });
}

/// The changes worth trying for `bone`, whose chain holds the unequally scaled bones `scaled`: each bone of the
/// chain below one of them under every other mode (only a bone below a squash inherits it), each of them made
/// uniform, and both bakes.
pub(super) fn candidates(evaluation: &Evaluation, bone: usize, scaled: &[usize]) -> Vec<Change> {
    let skeleton = evaluation.skeleton();
    let chain = skeleton.chain(bone);
    let top = chain.iter().position(|b| scaled.contains(b));
    let below = top.map_or(&[][..], |top| &chain[top + 1..]);
    let modes = below.iter().flat_map(|&b| {
        let current = evaluation.modes()[b];
        InheritMode::ALL.into_iter().filter(move |&m| m != current).map(move |mode| Change::Mode { bone: b, mode })
    });
    let uniform = chain.iter().filter(|b| scaled.contains(b)).map(|&bone| Change::UniformScale { bone });
    let bakes = Strategy::ALL.iter().map(|&strategy| Change::Bake { strategy });
    modes.chain(uniform).chain(bakes).collect()
}
