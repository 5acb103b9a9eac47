//! How close a bake came to its source: the source's evaluation against the baked file's, read back by bonescope's
//! own glTF importer, played with each rotation interpolation of the runtime it is for, and compared at every
//! sampled time ([`crate::diff::compare`]; the worse of the interpolations per bone), so the report measures the
//! file that was written, as that runtime plays it, not the intentions behind it.

use super::{Baked, BakedAnimation, Engine, Output, Request, Strategy};
use crate::diff::{Comparison, DEFAULT_RATE, Extreme, Measure, MeshDifference, Pairs, compare_each, comparison_times};
use crate::eval::Evaluation;
use crate::eval::layers::RotationInterpolation;
use crate::model::{Choice, Rig, with_midpoints};

/// How one bone was baked.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum BoneNodes {
    /// A helper node carries `T, R·U, K` and the bone `Uᵀ` (exact).
    Helper,
    /// One node: the bone's `U` never mattered (exact).
    Plain,
    /// One node, the closest TRS ([`Strategy::Trs`]).
    Trs,
}

/// One bone's error over an animation, in model units.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct BoneError {
    pub name: String,
    pub nodes: BoneNodes,
    /// At the bone's origin.
    pub origin: Extreme,
    /// At the origin and the probe points on its axes (a tenth of the rig's size out).
    pub probe: Extreme,
}

/// One baked animation against its source.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct AnimationReport {
    pub name: String,
    pub samples: usize,
    pub keys: usize,
    pub bones: Vec<BoneError>,
    /// Per skinned mesh, its vertices' distances from the source's.
    pub meshes: Vec<MeshDifference>,
    /// The largest error anywhere (a probe or a vertex), model units.
    pub worst: Extreme,
    /// Frames per second of the clip baked (its file's, or the rate its keys show), for times said with frames.
    pub frame_rate: Option<f64>,
    /// Source bones the baked file lacks, and the reverse (none when the bake is sound).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub unmatched: Vec<String>,
}

/// The whole report.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct BakeReport {
    /// The runtime the bake is for, and the rotation interpolations it plays keys with, which the errors are the
    /// worse of.
    pub engine: Engine,
    pub rotations: &'static [RotationInterpolation],
    pub strategy: Strategy,
    pub rig_size: f64,
    /// The key tolerance, model units.
    pub tolerance: f64,
    /// The bones that got a helper node.
    pub helpers: Vec<String>,
    pub animations: Vec<AnimationReport>,
    pub notes: Vec<String>,
}

impl BakeReport {
    /// The largest error of any animation.
    pub fn worst(&self) -> Extreme {
        self.animations.iter().map(|a| a.worst).fold(Extreme::default(), Extreme::merge)
    }

    /// What the runtime will show, in a line: the source within the tolerance (helper nodes), or the closest TRS
    /// per bone, whose error the report lists.
    pub fn what_it_shows(&self) -> String {
        let played: Vec<&str> = self.rotations.iter().map(|r| r.id()).collect();
        let played = played.join(" and ");
        let worst = self.worst();
        match self.strategy {
            // What was measured, where it passes what was asked: a bound is not said where it does not hold.
            Strategy::Exact if worst.max > self.tolerance => format!(
                "{} shows the source within {:.3e} at {:.4} s, past the {:.3e} asked (rotation keys checked under \
                 {played}; measured below)",
                self.engine.id(),
                worst.max,
                worst.time,
                self.tolerance
            ),
            Strategy::Exact => format!(
                "{} shows the source within {:.3e} (rotation keys checked under {played}; measured below)",
                self.engine.id(),
                self.tolerance
            ),
            Strategy::Trs => format!(
                "{} shows each bone's closest TRS (rotations by {played}): exact only where no bone shears; the \
                 error per bone is below",
                self.engine.id()
            ),
        }
    }
}

/// Compares every animation of `request` with the same animation of `baked_rig` (the bake read back).
pub fn report(request: &Request, baked: &Baked, baked_rig: &Rig) -> BakeReport {
    let skeleton = request.rest().skeleton();
    let animations = baked
        .animations
        .iter()
        .enumerate()
        .map(|(k, animation)| {
            let source = &request.clips()[k].source;
            let result = Evaluation::declared(baked_rig, baked_rig.clips.get(k));
            // A USD stage keeps the clip's own clock, where glTF's starts at 0 (a clip before it is delayed).
            let result = if baked.output == Output::Glb { result } else { result.delayed(source.delay()) };
            // The report prints distances alone: the polar parts are not decomposed.
            let pairs = Pairs { measure: Measure::Distances, ..Pairs::by_name(source, &result) };
            let comparison =
                played(request.engine, source, &result, &pairs, &checked_times(source, &result, animation));
            let nodes = |bone: usize| match (request.strategy, baked.helpers[bone]) {
                (Strategy::Trs, _) => BoneNodes::Trs,
                (Strategy::Exact, true) => BoneNodes::Helper,
                (Strategy::Exact, false) => BoneNodes::Plain,
            };
            let bones = comparison
                .bones
                .iter()
                .map(|d| BoneError { name: d.name.clone(), nodes: nodes(d.a), origin: d.position, probe: d.probe })
                .collect();
            let meshes = comparison.meshes.clone();
            let unmatched_source =
                pairs.bones.only_a.iter().map(|&b| format!("{} (only in the source)", skeleton.bone(b).name));
            let unmatched_baked =
                pairs.bones.only_b.iter().map(|&b| format!("{} (only in the bake)", baked_rig.skeleton.bone(b).name));
            AnimationReport {
                name: animation.name.clone(),
                samples: comparison.samples,
                keys: animation.keys,
                bones,
                meshes,
                worst: comparison.worst_distance(),
                frame_rate: source.clip.map(|clip| clip.frame_rate()),
                unmatched: unmatched_source.chain(unmatched_baked).collect(),
            }
        })
        .collect();
    let helpers = skeleton.bones().iter().zip(&baked.helpers).filter(|(_, h)| **h).map(|(b, _)| b.name.clone());
    BakeReport {
        engine: request.engine,
        rotations: request.engine.rotations(),
        strategy: request.strategy,
        rig_size: baked.rig_size,
        tolerance: baked.tolerance,
        helpers: helpers.collect(),
        animations,
        notes: baked.notes.clone(),
    }
}

/// The times a bake is checked at, so that its worst is one `bonescope diff` of the two files never exceeds: every
/// baked time and the midpoint between each two (where a sampled curve strays most from its chord), and the times
/// `diff` compares at (both sides' keys and [`DEFAULT_RATE`] a second).
fn checked_times(source: &Evaluation, result: &Evaluation, animation: &BakedAnimation) -> Vec<f64> {
    let mut times = with_midpoints(&animation.times);
    times.extend(comparison_times(source, result, DEFAULT_RATE));
    times.sort_by(f64::total_cmp);
    times.dedup();
    times
}

/// The worse of the comparisons of `source` with `result` played under each rotation interpolation `engine` plays
/// keys with, made in one pass (the source evaluated once per time for all of them).
fn played(engine: Engine, source: &Evaluation, result: &Evaluation, pairs: &Pairs, times: &[f64]) -> Comparison {
    // Every engine plays keys some way; glTF's way stands in for none.
    let rotations = Some(engine.rotations()).filter(|r| !r.is_empty()).unwrap_or(&[RotationInterpolation::Slerp]);
    let played: Vec<Evaluation> = rotations.iter().map(|&r| result.clone().played_with(r)).collect();
    let sides: Vec<(&Evaluation, &Pairs)> = played.iter().map(|e| (e, pairs)).collect();
    let comparisons = compare_each(source, &sides, times, source.size(times));
    comparisons.into_iter().reduce(Comparison::worse).expect("one comparison per rotation interpolation")
}
