//! Pose dumps: a runtime's evaluated matrices, read as a rig (`docs/pose-dump.md` is the format's definition, and
//! `docs/pose-dump.schema.json` its JSON Schema).
//!
//! A dump lists bones (names, parents by name) and, at increasing times, one 4×4 matrix per bone: world (model
//! space) or local (`world = parent's world · local`), written column- or row-major, as JSON (`json`) or CSV
//! (`csv`). Both are parsed into one `Dump`, which is then made a [`Rig`] without meshes whose bones all inherit
//! fully (a dump has no modes of its own): each bone's local matrix `L = W_parent⁻¹ · W` at each time, decomposed
//! `L = T·R·U·S·Uᵀ` (`math::decompose`), is one key of its translation, rotation, scale and stretch tracks. The
//! stretch `U` is kept per key because a runtime that composes otherwise than `full` (Unreal's `componentwise`, say)
//! makes locals that shear, and a rig that drops it would no longer give back the dumped matrices; its frame is
//! kept continuous over time ([`stretch_nearest`]) so that keys slerp into one another. Evaluated under `full`, the
//! rig gives back every dumped matrix at its time, to single precision (the tracks' storage); between times the
//! keys interpolate linearly, as every runtime samples. The first time's pose is the rest pose.
//!
//! A dump that says its up axis is Z is turned into bonescope's Y-up space above its roots; its unit, where it
//! states one, is the rig's. Bad dumps are refused with one line naming the place: ragged rows, a matrix that is
//! not affine, a singular parent matrix (a world dump's child cannot be made local to it), bones or parents no
//! bone is named, a parent loop, times that do not increase, numbers that are not finite. The memory a dump needs
//! is estimated from its size before it is parsed, and every step is linear in its size.

mod csv;
mod json;

pub use csv::COLUMNS as CSV_COLUMNS;

use std::collections::HashMap;
use std::sync::Arc;

use glam::{DMat4, DQuat, DVec3, DVec4, Quat, Vec3};

use super::budget;
use super::failure::{Failure, Result};
use crate::math::{affine_inverse, decompose, stretch_nearest};
use crate::model::{Bone, BoneTracks, Choice, Clip, Interpolation, Rig, Skeleton, Track, Transform, Unit, UpAxis};

/// What a dump's JSON `format` member and its CSV's first line say it is.
pub const FORMAT_ID: &str = "bonescope-pose-dump";

/// The version of the format this build reads and writes.
pub const VERSION: u32 = 1;

/// How far a matrix's bottom row may be from `(0, 0, 0, 1)`: single-precision rounding of a runtime's product.
const AFFINE_TOLERANCE: f64 = 1e-5;

/// The smallest a number can be written in a dump (`0,`): how many matrices a file of a given size can hold at most.
const BYTES_PER_MATRIX: u64 = 2 * 16;

/// What one matrix costs while a dump is read: the parsed matrix and its keys (single precision).
const MATRIX_COST: u64 = (16 * 8) + (4 * 14);

/// What the matrices of a dump are relative to.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum DumpSpace {
    /// Model space: the bone's matrix as the runtime draws it.
    #[default]
    World,
    /// The parent's space: `world = parent's world · local` (a root's is its world matrix).
    Local,
}

impl Choice for DumpSpace {
    const ALL: &'static [Self] = &[DumpSpace::World, DumpSpace::Local];

    fn id(self) -> &'static str {
        match self {
            DumpSpace::World => "world",
            DumpSpace::Local => "local",
        }
    }

    fn description(self) -> &'static str {
        match self {
            DumpSpace::World => "model-space matrices, as the runtime draws each bone",
            DumpSpace::Local => "matrices relative to the parent: world = parent's world · local",
        }
    }
}

/// How a matrix's 16 numbers are listed.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum MatrixOrder {
    /// Column after column (three.js's `elements`, glTF's `matrix`, OpenGL): the translation is numbers 13–15.
    #[default]
    ColumnMajor,
    /// Row after row (DirectX, Unreal's `FMatrix` printed transposed aside): the translation is numbers 4, 8, 12.
    RowMajor,
}

impl Choice for MatrixOrder {
    const ALL: &'static [Self] = &[MatrixOrder::ColumnMajor, MatrixOrder::RowMajor];

    fn id(self) -> &'static str {
        match self {
            MatrixOrder::ColumnMajor => "column-major",
            MatrixOrder::RowMajor => "row-major",
        }
    }

    fn description(self) -> &'static str {
        match self {
            MatrixOrder::ColumnMajor => "the four columns one after another; the translation is numbers 13-15",
            MatrixOrder::RowMajor => "the four rows one after another; the translation is numbers 4, 8 and 12",
        }
    }
}

impl MatrixOrder {
    /// The matrix whose numbers are `numbers` in this order.
    pub fn matrix(self, numbers: &[f64; 16]) -> DMat4 {
        let m = DMat4::from_cols_array(numbers);
        match self {
            MatrixOrder::ColumnMajor => m,
            MatrixOrder::RowMajor => m.transpose(),
        }
    }

    /// The numbers of `m` in this order.
    pub fn numbers(self, m: &DMat4) -> [f64; 16] {
        match self {
            MatrixOrder::ColumnMajor => m.to_cols_array(),
            MatrixOrder::RowMajor => m.transpose().to_cols_array(),
        }
    }
}

/// What a dump says of itself besides its bones and matrices.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct DumpHeader {
    pub space: DumpSpace,
    pub order: MatrixOrder,
    /// The length of one of its units, where it says.
    pub unit: Option<Unit>,
    /// The axis its figure stands along, where it says (Y where it does not).
    pub up: Option<UpAxis>,
    /// The name of the animation it holds, where it says (the clip's name; `diff` pairs clips by it).
    pub clip: Option<String>,
    /// What wrote it (a runtime and its version), where it says.
    pub source: Option<String>,
}

/// A dump as its file lists it: bones in file order, every time's matrices in that order.
struct Dump {
    header: DumpHeader,
    /// Names and parent names, in file order.
    bones: Vec<(String, Option<String>)>,
    times: Vec<f64>,
    /// One per time: a matrix per bone.
    frames: Vec<Vec<DMat4>>,
    syntax: Syntax,
}

/// How a dump is written, and so how its places are named.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Syntax {
    /// One JSON document: places are JSON paths (`frames[3].matrices[7]`).
    Json,
    /// A header line, a row of column names, then a row per time and bone: places are lines.
    Csv,
}

impl Syntax {
    /// Where the matrix of time `t` and bone `bone` (file order) of a dump of `bones` bones is.
    fn place(self, t: usize, bone: usize, bones: usize) -> String {
        match self {
            Syntax::Json => format!("frames[{t}].matrices[{bone}]"),
            Syntax::Csv => format!("line {}", csv::FIRST_ROW_LINE + t * bones + bone),
        }
    }
}

/// Refuses a dump of `bytes` bytes whose matrices could need more memory than the budget.
fn check_budget(bytes: u64) -> Result<()> {
    let matrices = bytes / BYTES_PER_MATRIX;
    budget::check(matrices.saturating_mul(MATRIX_COST), None, || format!("a pose dump of up to {matrices} matrices"))
}

/// Whether the first bytes of a file (blanks and a byte-order mark skipped) are a pose dump, and how it is written:
/// CSV whose first line names the format, or JSON that names it as a string (its `format` member, which the format
/// asks to be written first) in what was read of it.
pub(super) fn detect(text: &[u8]) -> Option<Syntax> {
    let quoted = format!("\"{FORMAT_ID}\"");
    let csv = text.strip_prefix(b"#").is_some_and(|rest| rest.trim_ascii_start().starts_with(FORMAT_ID.as_bytes()));
    let json = text.first() == Some(&b'{') && text.windows(quoted.len()).any(|w| w == quoted.as_bytes());
    match (json, csv) {
        (true, _) => Some(Syntax::Json),
        (_, true) => Some(Syntax::Csv),
        _ => None,
    }
}

/// Reads a pose dump of `size` bytes from `reader`, written as `syntax`.
pub(super) fn read(reader: impl std::io::BufRead, size: u64, syntax: Syntax) -> Result<Rig> {
    check_budget(size)?;
    let dump = match syntax {
        Syntax::Json => json::read(reader)?,
        Syntax::Csv => csv::read(reader)?,
    };
    dump.rig()
}

impl Dump {
    /// The rig the dump describes.
    fn rig(self) -> Result<Rig> {
        let Dump { header, bones, times, frames, syntax } = self;
        let order = parents_first(&bones)?;
        let parents = parent_indices(&bones, &order);
        let n = order.len();
        let mut keys = Keys::new(n, times.len());
        let mut world = vec![DMat4::IDENTITY; n];
        let turn = header.up.unwrap_or_default().to_y_up();
        // Each time's matrices are dropped once made keys: the dump is never held twice.
        for (t, (&time, matrices)) in times.iter().zip(frames).enumerate() {
            for (i, &file_bone) in order.iter().enumerate() {
                let place = || syntax.place(t, file_bone, n);
                let matrix = matrices[file_bone];
                check_affine(&matrix).map_err(|why| Failure::at(place(), why))?;
                let (model, local) = match (header.space, parents[i]) {
                    (_, None) => (turn * matrix, turn * matrix),
                    (DumpSpace::Local, Some(p)) => (world[p] * matrix, matrix),
                    (DumpSpace::World, Some(p)) => {
                        let inverse = affine_inverse(&world[p]).ok_or_else(|| {
                            let parent = &bones[order[p]].0;
                            Failure::at(place(), format!("the parent `{parent}`'s matrix is singular at t = {time}"))
                        })?;
                        (turn * matrix, inverse * turn * matrix)
                    }
                };
                world[i] = model;
                keys.push(i, local);
            }
        }
        let skeleton_bones = order.iter().zip(&parents).zip(keys.rest()).map(|((&file_bone, &parent), rest)| Bone {
            node: file_bone,
            ..Bone::joint(bones[file_bone].0.clone(), parent, rest)
        });
        let skeleton = Skeleton::new(skeleton_bones.collect()).map_err(|e| Failure::whole(e.to_string()))?;
        let tracks = keys.tracks(times.into()).map_err(|e| Failure::at("times", e.to_string()))?;
        let clip = Clip::new(0, header.clip.clone(), tracks, Vec::new()).with_key_rate();
        let notes = notes(&header, n, clip.span().length());
        Ok(Rig { skeleton, clips: vec![clip], unit: header.unit, notes, ..Rig::default() })
    }
}

/// What a user should know of how the dump was read.
fn notes(header: &DumpHeader, bones: usize, length: f64) -> Vec<String> {
    let source = header.source.as_deref().map_or(String::new(), |s| format!(" written by {s}"));
    let mut notes = vec![format!(
        "pose dump{source}: {bones} bones, {} {} matrices over {length} s; its first time's pose is the rest pose, \
         and every bone inherits fully (a dump has no modes of its own)",
        header.space.id(),
        header.order.id(),
    )];
    if header.up == Some(UpAxis::Z) {
        notes.push("axes: Z up, as the dump says: turned into Y up above the roots".to_owned());
    }
    if header.unit.is_none() {
        notes.push("unit: the dump states none (give one with --unit where a command takes it)".to_owned());
    }
    notes
}

/// Why `m` is not an affine matrix with finite numbers, if it is not.
fn check_affine(m: &DMat4) -> std::result::Result<(), String> {
    if !m.is_finite() {
        return Err("a number is not finite".to_owned());
    }
    let bottom = m.row(3);
    if !bottom.abs_diff_eq(DVec4::W, AFFINE_TOLERANCE) {
        return Err(format!(
            "not an affine matrix: its bottom row is ({}, {}, {}, {}), not (0, 0, 0, 1) (is the order right?)",
            bottom.x, bottom.y, bottom.z, bottom.w
        ));
    }
    Ok(())
}

/// The bones in an order that puts every parent before its children, as file indices: the file's own where it
/// already does (most dumps list bones so), else breadth first from the roots. Refused for repeated names, parents
/// no bone is named (all of them listed) and loops.
fn parents_first(bones: &[(String, Option<String>)]) -> Result<Vec<usize>> {
    let mut index: HashMap<&str, usize> = HashMap::with_capacity(bones.len());
    for (i, (name, _)) in bones.iter().enumerate() {
        if index.insert(name, i).is_some() {
            return Err(Failure::at(format!("bones[{i}]"), format!("the name `{name}` is given to two bones")));
        }
    }
    let unknown: Vec<String> = bones
        .iter()
        .filter_map(|(_, p)| p.as_deref())
        .filter(|p| !index.contains_key(p))
        .map(|p| format!("`{p}`"))
        .collect();
    if !unknown.is_empty() {
        return Err(Failure::whole(format!("parents that no bone is named: {}", unknown.join(", "))));
    }
    let parent = |i: usize| bones[i].1.as_deref().map(|p| index[p]);
    if (0..bones.len()).all(|i| parent(i).is_none_or(|p| p < i)) {
        return Ok((0..bones.len()).collect());
    }
    let mut children: Vec<Vec<usize>> = vec![Vec::new(); bones.len()];
    let mut order: Vec<usize> = Vec::with_capacity(bones.len());
    for i in 0..bones.len() {
        match parent(i) {
            Some(p) => children[p].push(i),
            None => order.push(i),
        }
    }
    let mut next = 0;
    while next < order.len() {
        order.extend_from_slice(&children[order[next]]);
        next += 1;
    }
    if order.len() < bones.len() {
        let mut placed = vec![false; bones.len()];
        order.iter().for_each(|&i| placed[i] = true);
        let looped = placed.iter().position(|&p| !p).unwrap_or_default();
        return Err(Failure::at(format!("bones[{looped}]"), format!("`{}` is its own ancestor", bones[looped].0)));
    }
    Ok(order)
}

/// Each bone's parent, as an index into `order` (every parent names a bone: [`parents_first`] checked).
fn parent_indices(bones: &[(String, Option<String>)], order: &[usize]) -> Vec<Option<usize>> {
    let mut position = vec![0; order.len()];
    for (i, &file_bone) in order.iter().enumerate() {
        position[file_bone] = i;
    }
    let index: HashMap<&str, usize> = bones.iter().enumerate().map(|(i, (name, _))| (name.as_str(), i)).collect();
    order.iter().map(|&file_bone| bones[file_bone].1.as_deref().map(|p| position[index[p]])).collect()
}

/// Every bone's keys as they are made, time after time.
struct Keys {
    previous: Vec<Option<Transform>>,
    translation: Vec<Vec<Vec3>>,
    rotation: Vec<Vec<Quat>>,
    scale: Vec<Vec<Vec3>>,
    stretch: Vec<Vec<Quat>>,
    rest: Vec<Transform>,
}

impl Keys {
    fn new(bones: usize, times: usize) -> Self {
        fn per_bone<T>(bones: usize, times: usize) -> Vec<Vec<T>> {
            (0..bones).map(|_| Vec::with_capacity(times)).collect()
        }
        Keys {
            previous: vec![None; bones],
            translation: per_bone(bones, times),
            rotation: per_bone(bones, times),
            scale: per_bone(bones, times),
            stretch: per_bone(bones, times),
            rest: Vec::with_capacity(bones),
        }
    }

    /// The next key of `bone`: its local matrix, decomposed and made continuous with its previous key.
    fn push(&mut self, bone: usize, local: DMat4) {
        let mut key = decompose(&local).transform();
        match &self.previous[bone] {
            Some(previous) => follow(&mut key, previous),
            None => self.rest.push(key),
        }
        self.previous[bone] = Some(key);
        self.translation[bone].push(key.translation.as_vec3());
        self.rotation[bone].push(key.rotation.as_quat());
        self.scale[bone].push(key.scale.as_vec3());
        self.stretch[bone].push(key.stretch.as_quat());
    }

    /// The first time's local transforms (none before [`Keys::push`] has seen a time).
    fn rest(&self) -> Vec<Transform> {
        self.rest.clone()
    }

    /// Every bone's tracks over `times`; a stretch track only for a bone whose locals ever shear.
    fn tracks(self, times: Arc<[f64]>) -> std::result::Result<Vec<BoneTracks>, crate::model::TrackError> {
        let linear = Interpolation::Linear;
        let channels = self.translation.into_iter().zip(self.rotation).zip(self.scale).zip(self.stretch);
        channels
            .enumerate()
            .map(|(bone, (((t, r), s), u))| {
                let mut tracks = BoneTracks::new(bone);
                tracks.translation = Some(Track::new(times.clone(), t, linear)?);
                tracks.rotation = Some(Track::new(times.clone(), r, linear)?);
                tracks.scale = Some(Track::new(times.clone(), s, linear)?);
                if u.iter().any(|&q| q != Quat::IDENTITY) {
                    tracks.stretch = Some(Track::new(times.clone(), u, linear)?);
                }
                Ok(tracks)
            })
            .collect()
    }
}

/// Makes `key` continue from `previous`: of the stretch frames that give the same `U·S·Uᵀ` (the decomposition may
/// swap axes between two times), the one nearest the previous key's, its factors permuted to match, so that the
/// keys interpolate into one another. A bone scaled to nothing keeps the previous rotations (any gives its matrix).
fn follow(key: &mut Transform, previous: &Transform) {
    if key.scale == DVec3::ZERO {
        (key.rotation, key.stretch) = (previous.rotation, previous.stretch);
        return;
    }
    if key.stretch == DQuat::IDENTITY && previous.stretch == DQuat::IDENTITY {
        return;
    }
    let sign = if key.scale.x.is_sign_negative() { -1.0 } else { 1.0 };
    let (stretch, factors) = stretch_nearest(key.stretch, key.scale * sign, previous.stretch);
    key.stretch = if stretch.dot(previous.stretch) < 0.0 { -stretch } else { stretch };
    key.scale = factors * sign;
}

/// Parses `text` as one of the values of `T` by id, or says which it expected.
fn choice<T: Choice>(text: &str, what: &str) -> std::result::Result<T, String> {
    T::from_id(text).ok_or_else(|| {
        let ids: Vec<&str> = T::ALL.iter().map(|v| v.id()).collect();
        format!("{what} `{text}` is not one of {}", ids.join(", "))
    })
}

/// Checks the format's name and version.
fn check_format(format: &str, version: u32) -> std::result::Result<(), String> {
    if format != FORMAT_ID {
        return Err(format!("the format is `{format}`, not `{FORMAT_ID}`"));
    }
    if version != VERSION {
        return Err(format!("version {version} of the pose dump format; this bonescope reads version {VERSION}"));
    }
    Ok(())
}

/// The first time that is not finite or not after the one before it, with its index.
fn first_bad_time(times: &[f64]) -> Option<(usize, String)> {
    if let Some(i) = times.iter().position(|t| !t.is_finite()) {
        return Some((i, format!("the time {} is not finite", times[i])));
    }
    let i = times.windows(2).position(|w| w[1] <= w[0])?;
    Some((i + 1, format!("the time {} does not come after the one before it ({})", times[i + 1], times[i])))
}

#[cfg(test)]
mod tests;
