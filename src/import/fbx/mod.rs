//! FBX import (binary and ASCII, FBX 5 to 7.7) through ufbx, the best-maintained FBX reader.
//!
//! ufbx does the parsing and the FBX semantics; this module maps its scene onto a [`Rig`]:
//! - every node below ufbx's root becomes a bone whose rest transform is ufbx's evaluated `local_transform`
//!   (translation, pivots, offsets, pre/post rotation and rotation order folded into one T·R·S, exactly as ufbx
//!   evaluates them) and whose mode is ufbx's `inherit_mode` (NORMAL → `full`, IGNORE_PARENT_SCALE →
//!   `segment-compensate`, COMPONENTWISE_SCALE → `componentwise`), kept as the file declares it
//!   (`inherit_mode_handling = PRESERVE`);
//! - every animation stack becomes a clip sampled by ufbx at every frame and key time ([`anim`]);
//! - meshes with their skins ([`mesh`]).
//!
//! Units and axes: [`Space::YUpMetres`] asks ufbx for the conversion to right-handed Y-up metres on its root
//! (`UFBX_SPACE_CONVERSION_TRANSFORM_ROOT`), which becomes the skeleton's placement: every node keeps the
//! transform the file gives it, so the inheritance modes compensate the scales the file's author set and never
//! the unit's (adjusting the top-level nodes instead folds the unit into their scale). [`Space::File`] leaves the
//! file's own axes and units.
//!
//! Hostile files: ufbx is fuzzed upstream and never trusts a count; on top of that its allocators get a memory limit
//! proportional to the file's size ([`memory_limit`]), so an array claiming 2³² values fails instead of allocating.
//! ufbx says what is wrong but not where, so a failed file is walked by [`locate`] to name the place.

mod anim;
mod channels;
mod locate;
mod mesh;
mod scene;

use std::fs::File;
use std::path::Path;

use super::failure::{Failure, Result};
use super::{ImportError, Options, Space};
use crate::model::{Rig, Tool, Unit};

/// Reads an FBX file whose bytes are in memory.
pub fn load(path: &Path, bytes: &[u8], options: &Options) -> std::result::Result<Rig, ImportError> {
    check_braces(bytes).map_err(|f| f.with_path(path))?;
    let scene = ufbx::load_memory(bytes, ufbx_load_opts(options, bytes.len()))
        .map_err(|e| Failure::ufbx(&e, locate::locate(bytes)));
    scene.and_then(|scene| read(&scene, bytes.len(), options)).map_err(|f| f.with_path(path))
}

/// Reads the FBX file at `path`, open as `file` after its first bytes `head`: ufbx reads the rest through a buffer of
/// its own, so the file is never held in memory whole. (A file ufbx refuses is read whole to locate the break.)
pub fn load_file(path: &Path, file: File, head: &[u8], options: &Options) -> std::result::Result<Rig, ImportError> {
    if !head.starts_with(BINARY_MAGIC) {
        let bytes =
            std::fs::read(path).map_err(|e| ImportError::new(path, None, format!("cannot read the file: {e}")))?;
        check_braces(&bytes).map_err(|f| f.with_path(path))?;
    }
    let size = file.metadata().map_or(head.len(), |m| usize::try_from(m.len()).unwrap_or(usize::MAX));
    let scene = ufbx::load_stream_prefix(ufbx::Stream::File(file), head, ufbx_load_opts(options, size))
        .map_err(|e| Failure::ufbx(&e, std::fs::read(path).ok().and_then(|bytes| locate::locate(&bytes))));
    scene.and_then(|scene| read(&scene, size, options)).map_err(|f| f.with_path(path))
}

/// How a binary FBX file starts.
const BINARY_MAGIC: &[u8] = b"Kaydara FBX Binary  \0";

/// Refuses an ASCII file whose blocks do not nest: ufbx reads one with a `{` or `}` missing or extra as a different
/// hierarchy than its author's, without a word.
fn check_braces(bytes: &[u8]) -> Result<()> {
    if bytes.starts_with(BINARY_MAGIC) {
        return Ok(());
    }
    match locate::ascii(bytes) {
        None => Ok(()),
        Some(place) => Err(Failure::at(
            place,
            "the file's blocks do not nest as they should: refused rather than read as another hierarchy",
        )),
    }
}

impl Failure {
    /// A ufbx error: its description and what it was reading as the message; `place` from [`locate`].
    fn ufbx(error: &ufbx::Error, place: Option<String>) -> Self {
        let mut message = error.description.to_string();
        let info = error.info();
        if !info.is_empty() {
            message = format!("{message} ({info})");
        }
        if matches!(error.type_, ufbx::ErrorType::MemoryLimit | ufbx::ErrorType::AllocationLimit) {
            message = format!("{message}: the file asks for far more memory than its size can justify");
        }
        if let Some(reading) = reading(error) {
            message = format!("{message} (ufbx: {reading})");
        }
        Failure { place, message }
    }
}

/// What ufbx was doing when it failed, from its error stack (compiled in: `.cargo/config.toml`): the check that
/// failed and the functions it was in, innermost first, e.g. "check `depth < 32` in ascii_parse_node <
/// parse_toplevel_child_imp < read_objects".
fn reading(error: &ufbx::Error) -> Option<String> {
    const FUNCTIONS: usize = 4;
    let frames: Vec<&ufbx::ErrorFrame> = error.stack.iter().take(error.stack_size as usize).collect();
    let innermost = frames.first()?;
    let mut functions: Vec<&str> = Vec::new();
    for frame in &frames {
        let function = frame.function.trim_start_matches("ufbxi_");
        if functions.last() != Some(&function) && !function.is_empty() {
            functions.push(function);
        }
    }
    let check: &str = &innermost.description;
    let within = functions.iter().take(FUNCTIONS).copied().collect::<Vec<_>>().join(" < ");
    let more = if functions.len() > FUNCTIONS { " < …" } else { "" };
    Some(if check.is_empty() { format!("in {within}{more}") } else { format!("check `{check}` in {within}{more}") })
}

/// The memory ufbx may use for one file of `file_size` bytes: generous for real files (a compressed binary FBX
/// expands several times, and ufbx keeps both the parse tree and the scene), bounded for hostile ones, and never
/// beyond the memory budget ([`budget`](crate::import::budget)).
pub fn memory_limit(file_size: usize) -> usize {
    let by_size = (256usize << 20).saturating_add(file_size.saturating_mul(64));
    by_size.min(usize::try_from(crate::import::budget::limit()).unwrap_or(usize::MAX))
}

/// The ufbx load options bonescope uses, so that tests can load a file exactly the way the importer does.
pub fn ufbx_load_opts(options: &Options, file_size: usize) -> ufbx::LoadOpts<'static> {
    let limit = memory_limit(file_size);
    let mut opts = ufbx::LoadOpts {
        // Keep the file's inherit types (also the default) and its geometric transforms.
        inherit_mode_handling: ufbx::InheritModeHandling::Preserve,
        geometry_transform_handling: ufbx::GeometryTransformHandling::Preserve,
        space_conversion: ufbx::SpaceConversion::TransformRoot,
        ignore_embedded: true,
        clean_skin_weights: true,
        ..Default::default()
    };
    opts.temp_allocator.memory_limit = limit;
    opts.result_allocator.memory_limit = limit;
    if options.space == Space::YUpMetres {
        opts.target_axes = ufbx::CoordinateAxes {
            right: ufbx::CoordinateAxis::PositiveX,
            up: ufbx::CoordinateAxis::PositiveY,
            front: ufbx::CoordinateAxis::PositiveZ,
        };
        opts.target_unit_meters = 1.0;
    }
    opts
}

/// The rig of a loaded scene from a file of `file_size` bytes (which bounds what may be sampled and copied).
fn read(scene: &ufbx::SceneRoot, file_size: usize, options: &Options) -> Result<Rig> {
    let mut notes = vec![space_note(scene, options.space)];
    let bones = scene::read(scene, &mut notes)?;
    let (skins, meshes) = mesh::read(scene, &bones, file_size, &mut notes)?;
    let clips = anim::read_clips(scene, &bones.bone_of_node, file_size, &mut notes)?;
    let unit = unit(scene, options.space);
    let tool = Tool::named(&scene.metadata.original_application.name);
    Ok(Rig { skeleton: bones.skeleton, clips, skins, meshes, unit, notes, tool })
}

/// The unit the file states (ufbx keeps the file's own settings in `scene.settings` even when it converts).
fn file_unit(scene: &ufbx::Scene) -> Option<Unit> {
    Unit::metres(scene.settings.unit_meters)
}

/// The unit of the loaded rig: metres where ufbx converted the file's stated unit, else the file's.
fn unit(scene: &ufbx::Scene, space: Space) -> Option<Unit> {
    let stated = file_unit(scene);
    match space {
        Space::YUpMetres => stated.map(|_| Unit::METRE),
        Space::File => stated,
    }
}

/// What the file's units and axes are, and what became of them.
fn space_note(scene: &ufbx::Scene, space: Space) -> String {
    let settings = &scene.settings;
    let up = match settings.axes.up {
        ufbx::CoordinateAxis::Unknown => "no up axis stated".to_owned(),
        axis => format!("{}-up", axis_name(axis)),
    };
    let unit = file_unit(scene).map_or_else(|| "no unit stated".to_owned(), |u| u.to_string());
    let stated = settings.axes.up != ufbx::CoordinateAxis::Unknown;
    match space {
        Space::YUpMetres if stated => {
            format!("units and axes: in the file {up}, {unit}; converted to Y-up metres above the roots")
        }
        Space::YUpMetres => format!(
            "units and axes: in the file {up}, {unit}; converted to metres above the roots, axes \
             left as they are"
        ),
        Space::File => format!("units and axes: the file's own ({up}, {unit}), not converted"),
    }
}

fn axis_name(axis: ufbx::CoordinateAxis) -> &'static str {
    match axis {
        ufbx::CoordinateAxis::PositiveX => "X",
        ufbx::CoordinateAxis::NegativeX => "-X",
        ufbx::CoordinateAxis::PositiveY => "Y",
        ufbx::CoordinateAxis::NegativeY => "-Y",
        ufbx::CoordinateAxis::PositiveZ => "Z",
        ufbx::CoordinateAxis::NegativeZ => "-Z",
        ufbx::CoordinateAxis::Unknown => "?",
    }
}

/// A ufbx matrix (columns of a 3×4 affine) as a glam matrix.
fn matrix(m: &ufbx::Matrix) -> glam::DMat4 {
    glam::DMat4::from_cols_array(&[
        m.m00, m.m10, m.m20, 0.0, m.m01, m.m11, m.m21, 0.0, m.m02, m.m12, m.m22, 0.0, m.m03, m.m13, m.m23, 1.0,
    ])
}

/// A node's name for people: its name, or `node<id>` when it has none.
fn node_name(node: &ufbx::Node) -> String {
    let name: &str = &node.element.name;
    if name.is_empty() { crate::model::Bone::unnamed(node.element.typed_id as usize) } else { name.to_owned() }
}
