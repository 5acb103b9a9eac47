//! OpenUSD (`.usda`, `.usdc`, `.usdz`) through the `openusd` crate, which composes the stage (sublayers, references,
//! payloads, `defaultPrim`, inactive prims left out) as Pixar's USD does. Every UsdSkel `Skeleton` of the stage
//! becomes bones below a node standing for the Skeleton prim (its transform in the world, its Xform ancestors'
//! included), and the `SkelAnimation` bound to it (`skel:animationSource`, on it or an ancestor) its tracks
//! ([`skeleton`]). A stage has one timeline, on which every skeleton plays its animation: one clip holds them all.
//! Meshes bound to a skeleton are skinned and blend-shaped as UsdSkel does it, the others hang rigid where they are
//! ([`mesh`], [`blend`]).
//!
//! UsdSkel has no scale-inheritance modes: every joint inherits its parent fully, so each joint declares `full`.
//! Times: a time code `t` is at `t / timeCodesPerSecond` seconds, the stage's own clock (Blender writes frame `f` at
//! time code `f`, so its frame 1 is at 1/24 s as in its glTF export), and the clip spans the stage's start and end
//! time codes where it states them. Units and axes: the stage's
//! `metersPerUnit` (0.01 where unauthored, as USD says) and `upAxis` (Y where unauthored) are converted to Y-up
//! metres above the roots, like an FBX file's; in the file's own space nothing is converted.
//!
//! Every asset the stage names (sublayers, references, payloads) must lie in the root layer's folder: the resolver
//! finds nothing outside it.

mod blend;
mod guard;
mod mesh;
mod resolver;
mod samples;
mod skeleton;

use std::path::Path;

use glam::{DMat4, DVec3};
use openusd::usd::{PrimPredicate, Stage};
use openusd::usda::unregistered::Unregistered;

use super::{ImportError, Options, Space};
use crate::model::{Clip, MorphWeights, Placement, Rig, Skeleton, Span, Unit};
use resolver::FolderResolver;

/// USD's `metersPerUnit` where a stage authors none: centimetres.
const DEFAULT_METERS_PER_UNIT: f64 = 0.01;

/// Reads the USD file at `path` (any of its three encodings) into a rig. A panic inside the `openusd` crate (a bug
/// there, which a hostile file may find) is that file's error, not the end of the process.
///
/// Every array the binary layers decode, and every array of samples and keys made of what the layers hold, is
/// charged to the memory budget before it is allocated (the counts in their headers say how large; a value dropped
/// once read is given back): a file that would need more at once is refused with the budget's figures.
pub fn load(path: &Path, options: &Options) -> Result<Rig, ImportError> {
    let ((read, needed), unregistered) = openusd::usda::unregistered::within(|| {
        openusd::usdc::budget::within(super::budget::limit(), || guard::caught(|| read(path, options)))
    });
    let read = read.unwrap_or_else(|bug| {
        Err(ImportError::new(path, None, format!("the USD reader failed (a bug in openusd): {bug}")))
    });
    let mut rig =
        read.map_err(|error| match within_budget(needed, || "the arrays read from its layers".to_owned()) {
            Err(message) => ImportError::new(path, None, message),
            Ok(()) => error,
        })?;
    rig.notes.extend(unregistered_note(&unregistered));
    Ok(rig)
}

/// What the text layers hold that no USD type reads: attributes of unknown types (a typo: `flaot[]`), whose values
/// Pixar's USD keeps as text no schema reads, and so does the `openusd` crate. A reader asking for one finds no
/// value of its type: it is skipped.
fn unregistered_note(unregistered: &[Unregistered]) -> Option<String> {
    let listed: Vec<String> =
        unregistered.iter().map(|u| format!("{} ({})", u.attribute.as_str(), u.type_name)).collect();
    (!listed.is_empty()).then(|| format!("attributes of types USD does not know, skipped: {}", listed.join(", ")))
}

/// [`load`], unguarded.
fn read(path: &Path, options: &Options) -> Result<Rig, ImportError> {
    let fail = |place: Option<String>, message: String| ImportError::new(path, place, message);
    let stage = open(path).map_err(|message| fail(None, message))?;
    let conversion = Conversion::of(&stage);
    let (skeletons, mesh_paths) = prims(&stage).map_err(|message| fail(None, message))?;
    let (mut bones, mut animations, mut placed) = (Vec::new(), Vec::new(), Vec::new());
    let mut notes = vec![conversion.note(options.space)];
    for skel in skeletons {
        let read = skeleton::read(&stage, &skel, bones.len(), &conversion.timing)
            .map_err(|message| fail(Some(skel.as_str().to_owned()), message))?;
        bones.extend(read.bones);
        notes.extend(read.notes);
        animations.extend(read.animation);
        placed.push(read.placed);
    }
    let (mut meshes, mut skins, mut morph) = (Vec::new(), Vec::new(), Vec::new());
    let mut moving = Vec::new();
    for path in mesh_paths {
        let read = mesh::read(&stage, &path, bones.len(), skins.len(), &placed, &conversion.timing)
            .map_err(|message| fail(Some(path.as_str().to_owned()), message))?;
        let Some(read) = read else { continue };
        meshes.push(read.mesh);
        skins.extend(read.skin);
        bones.extend(read.node);
        morph.extend(read.morph);
        moving.extend(read.moving);
    }
    if !moving.is_empty() {
        animations.push(skeleton::Animation { name: None, tracks: moving });
    }
    notes.extend(animations_note(&animations));
    let clips = clip(animations, morph, &conversion.timing).into_iter().collect();
    notes.push("modes: UsdSkel has none: every joint inherits its parent fully (declared full)".to_owned());
    let skeleton = Skeleton::new(bones).map_err(|e| fail(None, e.to_string()))?;
    let (skeleton, unit) = match options.space {
        Space::YUpMetres => (skeleton.placed(conversion.placement()), Some(Unit::METRE)),
        Space::File => (skeleton, Unit::metres(conversion.meters_per_unit)),
    };
    Ok(Rig { skeleton, clips, skins, meshes, unit, notes, tool: None })
}

/// The skeletons' animations (and the tracks of moving nodes), and the blend-shape weights they animate, as one
/// clip over the stage's range, named after its main animation ([`main_animation`]); `None` for none.
fn clip(animations: Vec<skeleton::Animation>, morph: Vec<MorphWeights>, timing: &Timing) -> Option<Clip> {
    if animations.is_empty() {
        return None;
    }
    let name = main_animation(&animations).and_then(|a| a.name.clone());
    let tracks = animations.into_iter().flat_map(|a| a.tracks).collect();
    let clip = Clip::new(0, name, tracks, morph).with_frame_rate(timing.codes_per_second);
    Some(match timing.span() {
        Some(span) => clip.with_span(span),
        None => clip,
    })
}

/// The SkelAnimation a stage's clip is named after: the one that animates the most joints, the first of equals (a
/// character's beside a skeleton Blender writes for a mesh parented to one of its bones).
fn main_animation(animations: &[skeleton::Animation]) -> Option<&skeleton::Animation> {
    let named = animations.iter().filter(|a| a.name.is_some());
    named.rev().max_by_key(|a| a.tracks.len())
}

/// What to say where several SkelAnimations play as the stage's one clip.
fn animations_note(animations: &[skeleton::Animation]) -> Option<String> {
    let names: Vec<&str> = animations.iter().filter_map(|a| a.name.as_deref()).collect();
    let main = main_animation(animations)?.name.as_deref()?;
    (names.len() > 1).then(|| {
        format!(
            "animation: the stage's {} SkelAnimations ({}) play on its one timeline as one clip, named after `{main}` \
             (the most joints)",
            names.len(),
            names.join(", ")
        )
    })
}

/// Reads a USD file already in memory: written to a folder of its own first (USD reads layers by path), so any
/// layer it names is not found.
pub fn load_bytes(path: &Path, bytes: &[u8], options: &Options) -> Result<Rig, ImportError> {
    let fail = |e: std::io::Error| ImportError::new(path, None, format!("cannot stage the file for reading: {e}"));
    let folder = tempfile::tempdir().map_err(fail)?;
    let name = path.file_name().map_or_else(|| "layer.usd".into(), |n| n.to_owned());
    let staged = folder.path().join(name);
    std::fs::write(&staged, bytes).map_err(fail)?;
    load(&staged, options).map_err(|e| ImportError { path: path.to_owned(), ..e })
}

/// The composed stage of the file at `path`, its assets confined to its folder.
fn open(path: &Path) -> Result<Stage, String> {
    let text = path.to_str().ok_or("the path is not valid UTF-8, which USD needs")?;
    let resolver = FolderResolver::for_file(path).map_err(|e| format!("cannot read the file: {e}"))?;
    Stage::builder().resolver(resolver).open(text).map_err(said)
}

/// The paths of the stage's Skeleton and Mesh prims, each in namespace order.
fn prims(stage: &Stage) -> Result<(Vec<openusd::sdf::Path>, Vec<openusd::sdf::Path>), String> {
    let (mut skeletons, mut meshes) = (Vec::new(), Vec::new());
    let mut failed = None;
    stage
        .traverse(PrimPredicate::DEFAULT, |path| match stage.prim(path.clone()).type_name() {
            Ok(Some(name)) if name.as_str() == "Skeleton" => skeletons.push(path.clone()),
            Ok(Some(name)) if name.as_str() == "Mesh" => meshes.push(path.clone()),
            Ok(_) => {}
            Err(e) => failed = failed.take().or(Some(format!("{}: {}", path.as_str(), said(e)))),
        })
        .map_err(said)?;
    failed.map_or(Ok((skeletons, meshes)), Err)
}

/// Refuses what would take `bytes` beyond the memory one file may use.
fn within_budget(bytes: u64, what: impl FnOnce() -> String) -> Result<(), String> {
    super::budget::check(bytes, None, what).map_err(|failure| failure.message)
}

/// Charges `count` values of `T` to the reading's memory budget before they are made (the binary layers' arrays are
/// charged to the same budget by the crate itself).
fn charge<T>(count: usize) -> Result<(), String> {
    openusd::usdc::budget::charge(count, size_of::<T>()).map_err(said)
}

/// An error of the `openusd` crate in one line, its causes after its message.
fn said(error: impl std::fmt::Display) -> String {
    format!("{error:#}")
}

/// How the stage's time codes are seconds, and which of them it plays.
#[derive(Clone, Copy, Debug)]
pub struct Timing {
    pub codes_per_second: f64,
    /// The first time code played: the stage's start time code (0 where it states none).
    pub start: f64,
    /// The stage's end time code, where it states a range.
    pub end: Option<f64>,
}

impl Timing {
    pub fn seconds(&self, code: f64) -> f64 {
        code / self.codes_per_second
    }

    /// The stage's range in seconds, where it states one.
    fn span(&self) -> Option<Span> {
        let end = self.end.filter(|end| *end >= self.start)?;
        Some(Span::new(self.seconds(self.start), self.seconds(end)))
    }
}

/// The stage's units, axes and time.
struct Conversion {
    meters_per_unit: f64,
    z_up: bool,
    timing: Timing,
}

impl Conversion {
    fn of(stage: &Stage) -> Conversion {
        let meta = |field: &str| stage.stage_metadata(field).ok().flatten();
        let meters_per_unit = match meta("metersPerUnit") {
            Some(openusd::sdf::Value::Double(m)) if m > 0.0 && m.is_finite() => m,
            Some(openusd::sdf::Value::Float(m)) if m > 0.0 && m.is_finite() => f64::from(m),
            _ => DEFAULT_METERS_PER_UNIT,
        };
        let z_up = matches!(meta("upAxis"), Some(openusd::sdf::Value::Token(axis)) if axis.as_str() == "Z");
        let codes_per_second = Some(stage.time_codes_per_second()).filter(|r| *r > 0.0 && r.is_finite());
        let authored = stage.has_authored_time_code_range();
        let start = Some(stage.start_time_code()).filter(|s| authored && s.is_finite()).unwrap_or(0.0);
        let end = Some(stage.end_time_code()).filter(|e| authored && e.is_finite());
        let timing = Timing { codes_per_second: codes_per_second.unwrap_or(24.0), start, end };
        Conversion { meters_per_unit, z_up, timing }
    }

    /// The conversion to Y-up metres: Z up turns a quarter about X (Z onto Y, Y onto −Z), then the unit.
    fn placement(&self) -> Placement {
        let axes = if self.z_up { DMat4::from_rotation_x(-std::f64::consts::FRAC_PI_2) } else { DMat4::IDENTITY };
        let conversion = DMat4::from_scale(DVec3::splat(self.meters_per_unit)) * axes;
        Placement { conversion, conversion_nodes: Vec::new() }
    }

    fn note(&self, space: Space) -> String {
        let up = if self.z_up { "Z up" } else { "Y up" };
        let unit = Unit::metres(self.meters_per_unit).map_or_else(|| "no unit".to_owned(), |u| u.to_string());
        let timing = &self.timing;
        let time = format!("time code t at t / {} s", timing.codes_per_second);
        match space {
            Space::YUpMetres => {
                format!("units and axes: in the file {up}, {unit}; converted to Y-up metres above the roots; {time}")
            }
            Space::File => format!("units and axes: the file's own ({up}, {unit}), not converted; {time}"),
        }
    }
}
