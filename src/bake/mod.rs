//! Baking any scale inheritance into plain glTF: the fix for the shear bonescope diagnoses.
//!
//! A glTF node is translation·rotation·scale, and glTF composes nodes with full inheritance, so a bone whose model
//! matrix `W` shears under its parent cannot be one node. It can be two. Shoemake's decomposition of the local matrix
//! a bone needs, `L = W'_parent⁻¹·W = T·R·U·K·Uᵀ` (`U` is the stretch rotation, `docs/decomposition.md`), splits as
//!
//! ```text
//! L = (T · (R·U) · K) · (Uᵀ)
//!      └─ helper node ─┘  └ the bone's own node: a rotation
//! ```
//!
//! so a helper node `<bone>.stretch` carrying `T`, `R·U`, `K` between the bone and its parent, with the bone
//! carrying `Uᵀ`, reproduces `W` exactly in any engine that composes glTF nodes. Bones whose `U` never matters get
//! no helper. That is [`Strategy::Exact`]; [`Strategy::Trs`] keeps one node per bone, each the closest TRS to what it
//! needs under its already-baked parent, for runtimes whose transforms cannot shear.
//!
//! The steps: sample every clip at its frames and key times (`times`), and wherever between them linear
//! interpolation would miss the source (`refine`); solve each bone's nodes at each sample (`nodes`); keep the
//! fewest keys that reproduce the samples within the tolerance (`keys`, `channels`); lay out nodes, meshes and
//! skins (`layout`, `skins`) and write the scene (`document`, `glb`). [`report()`] measures the written file
//! against the source.

mod channels;
mod document;
mod engine;
mod file;
mod glb;
mod keys;
mod layout;
mod nodes;
mod refine;
pub mod report;
mod skins;
mod times;
mod usd;

pub use engine::Engine;
pub use file::{BakeError, Plan, Written, bake_file, in_metres};
pub use report::{BakeReport, report};
pub use times::{BakeTimes, bake_times};
pub use usd::{CUSTOM_DATA, Encoding};

use keys::Metrics;
use layout::NodePlan;
use nodes::{NodeSample, Stats};
use rayon::prelude::*;
use refine::{Dense, Refined};

use crate::eval::Evaluation;
use crate::eval::layers::RotationInterpolation;
use crate::model::{Choice, Clip, Rig};

/// How bones become glTF nodes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Strategy {
    /// A helper node above every bone that needs its stretch rotation: exact.
    #[default]
    Exact,
    /// One TRS node per bone, re-solved against its baked parent: for runtimes that cannot shear.
    Trs,
}

impl Choice for Strategy {
    const ALL: &'static [Strategy] = &[Strategy::Exact, Strategy::Trs];

    fn id(self) -> &'static str {
        match self {
            Strategy::Exact => "exact",
            Strategy::Trs => "trs",
        }
    }

    fn description(self) -> &'static str {
        match self {
            Strategy::Exact => "a helper node above every bone that needs its stretch rotation: exact",
            Strategy::Trs => {
                "one TRS node per bone, re-solved against its baked parent: for runtimes that cannot shear"
            }
        }
    }
}

/// The file a bake writes: a glTF binary, or a UsdSkel scene in one of USD's encodings.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Output {
    #[default]
    Glb,
    Usd(Encoding),
}

impl Output {
    /// The extensions a bake writes, for messages.
    pub const EXTENSIONS: &'static str = "`.glb`, `.usda`, `.usdc` or `.usdz`";

    /// The output a file named `path` asks for by its extension (in any case); `None` for any other.
    pub fn of(path: &std::path::Path) -> Option<Output> {
        let extension = path.extension()?.to_str()?.to_ascii_lowercase();
        Some(match extension.as_str() {
            "glb" => Output::Glb,
            "usda" => Output::Usd(Encoding::Text),
            "usdc" | "usd" => Output::Usd(Encoding::Crate),
            "usdz" => Output::Usd(Encoding::Package),
            _ => return None,
        })
    }

    /// Whether a file of this kind plays one clip (a USD stage has one timeline).
    pub fn one_clip(self) -> bool {
        matches!(self, Output::Usd(_))
    }
}

/// The default tolerance: keys reproduce the source within this fraction of the rig's size.
pub const DEFAULT_TOLERANCE: f64 = 1e-4;

/// How the runtimes that play glTF interpolate rotation keys: slerp, as glTF specifies, and nlerp, where a player
/// makes one curve of each quaternion component and normalises their values (Blender's importer, Unity, Unreal's
/// compressed tracks). Keys that survive both play within the tolerance everywhere.
pub const EVERY_RUNTIME: &[RotationInterpolation] = &[RotationInterpolation::Slerp, RotationInterpolation::Nlerp];

/// One animation to bake: its name in the baked file, and the evaluation it reproduces (a clip, or the rest pose,
/// possibly through layers: a blend, an additive layer or a shake baked into a new clip).
#[derive(Clone, Debug)]
pub struct ClipToBake<'a> {
    pub name: String,
    pub source: Evaluation<'a>,
}

impl<'a> ClipToBake<'a> {
    /// `source` baked as `name`, on its own clock where that starts at 0 or later, else played from 0 (glTF's clock
    /// starts there: an FBX take from −166,666 s is written from 0, and the bake says so).
    pub fn new(name: String, source: Evaluation<'a>) -> Self {
        let start = source.span().start;
        let source = if start < 0.0 { source.delayed(-start) } else { source };
        ClipToBake { name, source }
    }
}

/// What to bake: clips of one rig under one set of modes, over that rig at rest under those modes.
#[derive(Clone, Debug)]
pub struct Request<'a> {
    /// The rig at rest under the modes the clips are evaluated with: what the nodes hold where no animation says
    /// otherwise.
    rest: Evaluation<'a>,
    clips: Vec<ClipToBake<'a>>,
    pub strategy: Strategy,
    /// Between keys, the result stays within this fraction of the rig's size of the source (0 keeps every sample).
    pub tolerance: f64,
    /// The runtime it is for: under the rotation interpolations it plays keys with ([`Engine::rotations`]), the
    /// result stays within the tolerance.
    pub engine: Engine,
}

/// Why clips cannot be baked together.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum RequestError {
    #[error("`{clip}` is an evaluation of another rig than the rest pose's")]
    OtherRig { clip: String },
    #[error("`{clip}` is evaluated under other modes than the rest pose: one file holds one hierarchy")]
    OtherModes { clip: String },
    #[error("nothing to bake: no clip, not even the rest pose")]
    NoClip,
}

impl<'a> Request<'a> {
    /// `clips` over `rest`, for every runtime; refused unless each is an evaluation of `rest`'s rig under `rest`'s
    /// modes (the file written holds one hierarchy, and its nodes' rest transforms are `rest`'s).
    pub fn new(
        rest: Evaluation<'a>,
        clips: Vec<ClipToBake<'a>>,
        strategy: Strategy,
        tolerance: f64,
    ) -> Result<Self, RequestError> {
        if clips.is_empty() {
            return Err(RequestError::NoClip);
        }
        for clip in &clips {
            if !std::ptr::eq(clip.source.rig, rest.rig) {
                return Err(RequestError::OtherRig { clip: clip.name.clone() });
            }
            if clip.source.modes() != rest.modes() {
                return Err(RequestError::OtherModes { clip: clip.name.clone() });
            }
        }
        Ok(Request { rest, clips, strategy, tolerance, engine: Engine::Generic })
    }

    /// Every clip of `source`'s rig (or the one `only` names) evaluated as `source` is, or its rest pose for a rig
    /// without clips (which the baked nodes then hold, with no animation in the file), for every runtime.
    pub fn every_clip(source: &Evaluation<'a>, only: Option<&'a Clip>, strategy: Strategy, tolerance: f64) -> Self {
        let rest = source.at_rest();
        let clips: Vec<&Clip> = match only {
            Some(clip) => vec![clip],
            None => source.rig.clips.iter().collect(),
        };
        let clips = if clips.is_empty() {
            vec![ClipToBake::new("rest pose".to_owned(), rest.clone())]
        } else {
            let of = |clip: &'a Clip| rest.clone().with_clip(Some(clip));
            clips.into_iter().map(|clip| ClipToBake::new(clip.label(), of(clip))).collect()
        };
        Request { rest, clips, strategy, tolerance, engine: Engine::Generic }
    }

    /// What a bake of `source` writes: every clip evaluated as `source` is (or the one `only` names), or, where
    /// `source` plays layers, their result as one new clip named after its main clip and what was layered on it.
    pub fn of(source: &Evaluation<'a>, only: Option<&'a Clip>, strategy: Strategy, tolerance: f64) -> Self {
        let layers = source.setup().layers;
        if layers.is_empty() {
            return Request::every_clip(source, only, strategy, tolerance);
        }
        let main = source.clip.map_or_else(|| "rest pose".to_owned(), |c| c.label());
        let name = format!("{main} + {}", layers.summary(source.rig, source.clip));
        let rest = source.at_rest();
        let clips = vec![ClipToBake::new(name, source.clone())];
        Request { rest, clips, strategy, tolerance, engine: Engine::Generic }
    }

    /// The same for `engine`.
    pub fn for_engine(self, engine: Engine) -> Self {
        Request { engine, ..self }
    }

    pub fn rig(&self) -> &'a Rig {
        self.rest.rig
    }

    /// The rig at rest under the clips' modes.
    pub fn rest(&self) -> &Evaluation<'a> {
        &self.rest
    }

    pub fn clips(&self) -> &[ClipToBake<'a>] {
        &self.clips
    }
}

/// One baked animation.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct BakedAnimation {
    pub name: String,
    /// The sampled times.
    pub times: Vec<f64>,
    /// How many keys were written, over all channels.
    pub keys: usize,
}

/// The result of a bake.
#[derive(Clone, Debug)]
pub struct Baked {
    pub output: Output,
    /// The file's bytes: a glTF binary, or the USD layer or package asked for ([`bake_to`]).
    pub bytes: Vec<u8>,
    /// Per source bone: whether it got a helper node.
    pub helpers: Vec<bool>,
    pub animations: Vec<BakedAnimation>,
    /// The rig's size ([`Evaluation::size`]) and the tolerance in model units.
    pub rig_size: f64,
    pub tolerance: f64,
    /// What a user should know about the result.
    pub notes: Vec<String>,
}

/// Bakes `request` into a glTF binary.
pub fn bake(request: &Request) -> Baked {
    bake_keeping(request, Output::Glb, HELD).expect("a glTF binary is always encoded")
}

/// Bakes `request` into a file of `output`'s kind (of a USD stage, the first clip alone: its one timeline); `Err`
/// where USD's writer fails.
pub fn bake_to(request: &Request, output: Output) -> Result<Baked, String> {
    bake_keeping(request, output, HELD)
}

/// [`bake_to`], keeping up to `held` bytes of samples between passes ([`HELD`]).
fn bake_keeping(request: &Request, output: Output, held: usize) -> Result<Baked, String> {
    let (rig, strategy) = (request.rig(), request.strategy);
    let sources: Vec<&Evaluation> = request.clips().iter().map(|c| &c.source).collect();
    let base: Vec<BakeTimes> = sources.iter().map(|source| bake_times(source)).collect();
    let size = sources.iter().zip(&base).map(|(source, base)| source.size(&base.times)).fold(0.0, f64::max);
    let size = if size > 0.0 { size } else { request.rest().size(&[0.0]) };
    let tolerance = request.tolerance.max(0.0) * size;
    let metrics = Metrics::new(request.rest(), size, tolerance, request.engine.rotations());
    let dense: Vec<DenseClip> = sources
        .iter()
        .zip(&base)
        .map(|(&source, base)| DenseClip::new(source, strategy, base, &metrics, held))
        .collect();
    let (rest, at_rest) = nodes::solve(request.rest(), &[0.0], strategy);
    let helpers: Vec<bool> = (0..rig.skeleton.len())
        .map(|bone| at_rest.stretched[bone] || dense.iter().any(|d| d.refined.stats.stretched[bone]))
        .collect();
    let layout = NodePlan::new(rig, &helpers);
    let mut notes = layout.notes.clone();
    let mut document = layout.document(rig, &rest);
    let mut animations = Vec::new();
    for (clip, dense) in request.clips().iter().zip(&dense) {
        let times = &dense.refined.times;
        if clip.source.clip.is_none() && clip.source.layers().is_none() {
            // The rest pose is what the nodes hold without an animation.
            animations.push(BakedAnimation { name: clip.name.clone(), times: times.clone(), keys: 0 });
            continue;
        }
        let animation = channels::animation(&layout, &clip.name, dense, &metrics, &document);
        let keys = animation.channels.iter().map(|c| c.times.len()).sum();
        animations.push(BakedAnimation { name: clip.name.clone(), times: times.clone(), keys });
        document.animations.push(animation);
    }
    for clip in request.clips().iter().filter(|c| c.source.delay() != 0.0 && output == Output::Glb) {
        let delay = clip.source.delay();
        notes.push(format!(
            "`{}` starts at {} s on its file's clock: written from 0 (glTF's clock starts there), {delay} s later",
            clip.name, -delay
        ));
    }
    notes.extend(request.clips().iter().filter_map(coarse_times));
    notes.extend(source_notes(rig, output, dense.iter().map(|d| d.refined.stats.singular).sum()));
    let bytes = match output {
        Output::Glb => {
            layout.for_gltf(rig, &mut document, &mut notes);
            glb::encode(&document)
        }
        Output::Usd(encoding) => {
            let conversion = layout.converted(rig, &mut document);
            usd::encode(document, &clock(request), conversion, encoding, &mut notes)?
        }
    };
    Ok(Baked { output, bytes, helpers, animations, rig_size: size, tolerance, notes })
}

/// A USD bake's clock: its first clip's rate and span, and how much later than its own clock it was baked.
fn clock(request: &Request) -> usd::Clock {
    let source = &request.clips()[0].source;
    let span = source.span();
    usd::Clock {
        codes_per_second: source.clip.map_or(DEFAULT_CODES_PER_SECOND, Clip::frame_rate),
        delay: source.delay(),
        span: (span.start, span.end),
    }
}

/// A USD bake's time codes per second where there is no clip to take them from: USD's own default.
const DEFAULT_CODES_PER_SECOND: f64 = 24.0;

/// Key times further apart than this, in seconds, where single precision holds them, are worth a note: a tenth of
/// a millisecond, a 300th of a frame at 30 fps.
const COARSE_TIME: f64 = 1e-4;

/// A note where `clip` lasts so long that glTF's single-precision key times are coarse at its end: a time `t` is
/// kept to `2^(⌊log₂ t⌋ − 23)` s, 1/64 s at 200,000 s, and keys move by that much.
fn coarse_times(clip: &ClipToBake) -> Option<String> {
    let end = clip.source.span().end;
    let step = f64::from(f32::EPSILON) * 2f64.powf(end.abs().log2().floor());
    (end.is_finite() && step > COARSE_TIME).then(|| {
        format!(
            "`{}` runs to {end:.0} s, where glTF's single-precision key times are {step:.3e} s apart: keys move that \
             far, and the bake misses the source by as much as the clip moves in it",
            clip.name
        )
    })
}

/// How many bytes of samples a bake keeps from the pass that learns what every sample teaches for the pass that
/// chooses the keys, rather than sampling the clip again: a clip of a few dozen bones over a minute keeps them; a
/// long clip of hundreds of bones, whose samples would take hundreds of megabytes, is sampled twice.
const HELD: usize = 64 << 20;

/// One clip sampled at its base times and wherever between them the source needs more ([`refine`]; not with a zero
/// tolerance, which no halving could reach), pass after pass, its samples handed on as they come. What the base
/// samples teach (which bones' stretch rotations matter, how much their parents scale) decides where to halve, so it
/// is learnt first; what every sample teaches decides the file's nodes and each bone's tolerance, so a pass through
/// every sample learns it before the keys are chosen. Where they fit in [`HELD`] (about two samples per base time
/// and bone), that pass keeps the samples for the keys; else the keys are chosen in a pass of their own.
struct DenseClip<'a> {
    pub sampling: Sampling<'a>,
    /// What every sample teaches, and every time some bone is sampled at.
    pub refined: Refined,
    /// Every bone's samples, where they are kept.
    held: Option<Vec<Vec<(f64, NodeSample)>>>,
}

impl<'a> DenseClip<'a> {
    /// The clip of `source` at `base`'s times, keeping up to `held` bytes of samples.
    fn new(
        source: &'a Evaluation<'a>,
        strategy: Strategy,
        base: &'a BakeTimes,
        metrics: &'a Metrics,
        held: usize,
    ) -> Self {
        let first = nodes::stats(source, &base.times, strategy);
        let steps = base.step_flags(&base.times);
        let sampling = Sampling { source, strategy, base, steps, metrics, first };
        // Each bone's share of what may be kept; a bone past it (halved deep) gives it up, and the clip is sampled
        // again.
        let bones = source.skeleton().len();
        let share = held / (bones.max(1) * std::mem::size_of::<(f64, NodeSample)>());
        let mut held: Vec<Option<Vec<(f64, NodeSample)>>> =
            vec![Some(Vec::new()); if 2 * base.times.len() <= share { bones } else { 0 }];
        let refined = sampling.run(&mut held, |held, samples| match held {
            Some(kept) if kept.len() + samples.len() <= share => kept.extend_from_slice(samples),
            _ => *held = None,
        });
        let held = held.into_iter().collect::<Option<Vec<_>>>().filter(|held| held.len() == bones && bones > 0);
        DenseClip { sampling, refined, held }
    }

    /// Hands each bone's samples, in time order, to `feed` with its state, one of `states` per bone.
    pub fn run<S: Send>(&self, states: &mut [S], feed: impl Fn(&mut S, &[(f64, NodeSample)]) + Sync) {
        match &self.held {
            Some(held) => states.par_iter_mut().zip(held).for_each(|(state, samples)| feed(state, samples)),
            None => _ = self.sampling.run(states, feed),
        }
    }
}

/// What a run through one clip needs: the clip, its base times, and what its base samples teach.
struct Sampling<'a> {
    pub source: &'a Evaluation<'a>,
    strategy: Strategy,
    /// The times every bone is sampled at, and the stepped keys among them.
    pub base: &'a BakeTimes,
    steps: Vec<bool>,
    metrics: &'a Metrics,
    first: Stats,
}

impl Sampling<'_> {
    /// Runs through the clip, each bone's samples handed to `feed` with its state ([`Dense::run`]).
    fn run<S: Send>(&self, states: &mut [S], feed: impl Fn(&mut S, &[(f64, NodeSample)]) + Sync) -> Refined {
        let (metrics, gains) = (self.metrics, &self.first.parent_gain);
        let misses = |bone: usize, ends: [&NodeSample; 2], fraction: f64, exact: &NodeSample| {
            let metric = metrics.bone(gains, bone);
            metric.between(ends, fraction, exact) > metrics.budget || metric.parting(ends) > metrics.budget
        };
        let dense = Dense {
            source: self.source,
            strategy: self.strategy,
            times: &self.base.times,
            steps: &self.steps,
            helper: &self.first.stretched,
            misses: (metrics.budget > 0.0).then_some(&misses),
        };
        dense.run(states, feed)
    }
}

/// What the source has that the baked file (of `output`'s kind) says differently.
fn source_notes(rig: &Rig, output: Output, singular: usize) -> Vec<String> {
    let mut notes = Vec::new();
    let dual: Vec<&str> =
        rig.meshes.iter().filter(|m| m.dq_weights.iter().any(|&w| w > 0.0)).map(|m| m.name.as_str()).collect();
    // UsdSkel skins with dual quaternions too (its writer says where it cannot).
    if !dual.is_empty() && output == Output::Glb {
        notes.push(format!(
            "skinned with dual quaternions in the file, linearly in glTF (see the vertex errors): {}",
            dual.join(", ")
        ));
    }
    for skin in rig.skins.iter().filter(|s| s.node_bind.is_some()) {
        notes.push(format!(
            "skin `{}` follows its mesh node's motion since the bind (Maya); the baked skin does not",
            skin.name.as_deref().unwrap_or("unnamed")
        ));
    }
    if singular > 0 {
        notes.push(format!(
            "{singular} bone samples under a parent scaled to nothing took the source's local transform"
        ));
    }
    notes
}

/// Writes `bytes` to `path` atomically: into a temporary file beside it, then renamed over it, so the path holds
/// either its old content or all of the new one, never a half-written file. The file gets the permissions a new
/// file would (a temporary file's are the owner's only). An error is the system's reason alone, for the caller to
/// name `path` with: the temporary file is no name the user gave.
pub fn save(path: &std::path::Path, bytes: &[u8]) -> std::io::Result<()> {
    use std::io::Write;
    let folder = path.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(std::path::Path::new("."));
    // Opened, and written, as a plain file rather than through tempfile's own, whose errors name the temporary file.
    let mut file = tempfile::Builder::new().make_in(folder, |temporary| std::fs::File::create_new(temporary))?;
    file.as_file_mut().write_all(bytes)?;
    file.as_file().sync_all()?;
    file.persist(path).map_err(|e| e.error)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::import::stress_rig;
    use crate::model::InheritMode;

    #[test]
    fn a_clip_whose_samples_are_kept_is_baked_as_one_sampled_twice() {
        // The stress rig with its chains compensating the squash above them (so that bones are halved deep), baked
        // keeping every sample between the passes, none, and some (bones halved deep give theirs up): one file.
        let rig = stress_rig(12, 300, 3);
        let modes = vec![InheritMode::SegmentCompensate; rig.skeleton.len()];
        let source = Evaluation::new(&rig, rig.clips.first(), &modes).unwrap();
        for strategy in [Strategy::Exact, Strategy::Trs] {
            let request = Request::every_clip(&source, None, strategy, DEFAULT_TOLERANCE);
            let bake = |held: usize| bake_keeping(&request, Output::Glb, held).unwrap().bytes;
            let kept = bake(usize::MAX);
            assert_eq!(bake(0), kept, "{strategy:?}");
            assert_eq!(bake(1 << 20), kept, "{strategy:?}");
        }
    }

    #[test]
    fn save_replaces_the_file_whole_with_a_new_file_s_permissions() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.glb");
        std::fs::write(&path, b"old content, longer than the new").unwrap();
        super::save(&path, b"new").unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"new");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1, "no temporary file left beside it");
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            let created = dir.path().join("created");
            std::fs::write(&created, b"").unwrap();
            let mode = |path| std::fs::metadata(path).unwrap().permissions().mode();
            assert_eq!(mode(&path), mode(&created), "the mode a created file gets under this umask");
        }
    }
}
