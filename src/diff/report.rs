//! Two files compared as a whole: their animations paired (by name, or as chosen), each pair compared, and what
//! had no partner listed.

use super::{
    BoneDifference, DiffError, Extreme, Frames, MeshDifference, Pairs, compare, comparison_times, match_clips,
};
use crate::eval::layers::RotationInterpolation;
use crate::eval::{Evaluation, Setup};
use crate::model::{Clip, ModeChoice, Modes, Rig, Span, Unit};

/// The clips `names` choose, `[in A, in B]`, each a name or an index: a name given for one side only is looked up on
/// both (the other file's clip named as the chosen clip is, exactly or as [`match_clips`] compares names: Blender's
/// FBX names a take `Armature|walk`). `None`: every clip, paired by name. The error is a clip one file lacks:
/// [`MissingClip`].
pub fn chosen_clips(rigs: [&Rig; 2], names: [Option<&str>; 2]) -> Result<Option<[usize; 2]>, MissingClip> {
    let find = |searched: usize, named_by: usize, name: &str| {
        let rig = rigs[searched];
        let clip = rig.clip_named(name).map_err(|why| MissingClip { searched, named_by, why })?;
        Ok(rig.clips.iter().position(|c| std::ptr::eq(c, clip)).expect("a clip of the rig"))
    };
    // The other side's clip named like `clip` of side `chosen`.
    let alike = |chosen: usize, clip: usize| {
        let other = 1 - chosen;
        let one = std::slice::from_ref(&rigs[chosen].clips[clip]);
        match match_clips(one, &rigs[other].clips).0[..] {
            [(_, j)] => Ok(j),
            _ => find(other, chosen, &rigs[chosen].clips[clip].label()),
        }
    };
    Ok(Some(match names {
        [None, None] => return Ok(None),
        [Some(x), Some(y)] => [find(0, 0, x)?, find(1, 1, y)?],
        [Some(x), None] => {
            let i = find(0, 0, x)?;
            [i, alike(0, i)?]
        }
        [None, Some(y)] => {
            let j = find(1, 1, y)?;
            [alike(1, j)?, j]
        }
    }))
}

/// A clip name one file of a comparison lacks: the file searched (0 for A, 1 for B), the side whose choice named
/// it, and what the file has.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct MissingClip {
    pub searched: usize,
    pub named_by: usize,
    pub why: String,
}

/// One side of a file comparison: a file's rig and what is evaluated of it (its modes, how its keys are played; its
/// clip where the clips are [`Clips::Chosen`]). Its lengths are measured in the first side's unit.
#[derive(Clone, Debug)]
pub struct FileSide<'a> {
    /// The file's name, as reports show it.
    pub file: String,
    pub rig: &'a Rig,
    pub setup: Setup,
}

impl<'a> FileSide<'a> {
    /// `rig` (its file shown as `file`) under `modes`, its clip `clip` (where clips are chosen), as authored.
    pub fn new(file: String, rig: &'a Rig, modes: ModeChoice, clip: Option<usize>) -> Self {
        FileSide { file, rig, setup: Setup { clip, modes: Modes::all(modes), ..Setup::default() } }
    }
}

/// How B's clock meets A's in a file comparison. Each file keeps its own clock (a time reads the same in every
/// format), so two exports of one scene whose exporters put its first frame at different times (Blender's FBX starts
/// each take at 0, its glTF and USD at the frame's own time) are a frame or more apart until aligned.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Align {
    /// Equal times of both clocks are compared.
    #[default]
    Clocks,
    /// B's clip is played from A's clip's start.
    Start,
    /// B is played this many seconds later than its clock says.
    Delay(f64),
}

impl std::str::FromStr for Align {
    type Err = String;

    /// `clocks`, `start`, or a number of seconds B is played later.
    fn from_str(text: &str) -> Result<Self, String> {
        match text.trim() {
            "clocks" => Ok(Align::Clocks),
            "start" => Ok(Align::Start),
            seconds => match seconds.parse::<f64>() {
                Ok(seconds) if seconds.is_finite() => Ok(Align::Delay(seconds)),
                _ => Err(format!("expected `clocks`, `start` or a number of seconds, got `{text}`")),
            },
        }
    }
}

impl Align {
    /// How many seconds later B is played for its clip over `b` to meet A's over `a`.
    fn delay(self, a: Span, b: Span) -> f64 {
        match self {
            Align::Clocks => 0.0,
            Align::Start => a.start - b.start,
            Align::Delay(seconds) => seconds,
        }
    }
}

/// Which clips a file comparison compares.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Clips {
    /// Every clip paired with the other file's of the same name (the rest poses, where neither file has clips).
    ByName,
    /// Each side's [`Setup::clip`].
    Chosen,
}

/// One pair of animations compared.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct AnimationDiff {
    /// The clips' names (`rest pose` for a file without clips).
    pub a: String,
    pub b: String,
    /// Where each clip lies on its own file's clock (B's as its file says, before any delay).
    pub span_a: Span,
    pub span_b: Span,
    /// How many seconds later than its clock says B was played ([`Align`]); times are A's.
    pub delay_b: f64,
    /// A's frame rate, which the times' frames are counted at.
    pub frame_rate: Option<f64>,
    /// How many times were compared: none where the two clips never play at once.
    pub samples: usize,
    /// The larger of the two rigs' sizes, which percentages are of.
    pub rig_size: f64,
    /// The largest distance of any bone's probe points or any vertex.
    pub worst: Extreme,
    pub bones: Vec<BoneDifference>,
    pub meshes: Vec<MeshDifference>,
    /// Bones without a partner.
    pub only_a: Vec<String>,
    pub only_b: Vec<String>,
    /// Helper nodes of a bake, left out.
    pub helpers: usize,
    /// Conversion nodes, left out: nodes that only state the file's axes and unit.
    pub conversion_a: Vec<String>,
    pub conversion_b: Vec<String>,
    /// Nodes of skinned meshes, left out: their skins are compared.
    pub skinned_a: Vec<String>,
    pub skinned_b: Vec<String>,
}

/// The whole comparison.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct FileDiff {
    pub a: String,
    pub b: String,
    pub inherit_a: String,
    pub inherit_b: String,
    /// The rigs' units in metres (`null`: the file states none, and its numbers are taken as they are); lengths are
    /// in A's unit, B's brought into it.
    pub unit_a: Option<Unit>,
    pub unit_b: Option<Unit>,
    /// How each side's linear rotation tracks were interpolated.
    pub interp_a: RotationInterpolation,
    pub interp_b: RotationInterpolation,
    pub rate: f64,
    pub animations: Vec<AnimationDiff>,
    /// Clips without a partner.
    pub clips_only_a: Vec<String>,
    pub clips_only_b: Vec<String>,
}

/// Compares `a` with `b` at their key times and `rate` times a second where both play, B's clock meeting A's as
/// `align` says, lengths in A's unit; `map` pairs bones by name explicitly. Two files with clips none of which pair
/// by name are an error that lists them ([`DiffError::NoClipPairs`]).
pub fn diff_files<'a>(
    a: &FileSide<'a>,
    b: &FileSide<'a>,
    clips: Clips,
    map: &[(String, String)],
    rate: f64,
    align: Align,
) -> Result<FileDiff, DiffError> {
    let (pairs, only_a, only_b) = pair_clips(a, b, clips);
    let label = |rig: &Rig, clip: Option<usize>| clip.map_or_else(|| "rest pose".to_owned(), |c| rig.clips[c].label());
    // One file under two sets of modes gives each bone one frame; two files may each choose their own.
    let frames = if a.file == b.file { Frames::Same } else { Frames::UpToConvention };
    if pairs.is_empty() {
        let labels = |rig: &Rig| (0..rig.clips.len()).map(|c| label(rig, Some(c))).collect();
        return Err(DiffError::NoClipPairs { a: labels(a.rig), b: labels(b.rig) });
    }
    let evaluation = |side: &FileSide<'a>, clip, unit| {
        let setup = Setup { clip, unit, ..side.setup.clone() };
        Evaluation::of(side.rig, &setup).map_err(|error| DiffError::Setup { file: side.file.clone(), error })
    };
    let animations = pairs
        .iter()
        .map(|&(ca, cb)| {
            let side_a = evaluation(a, ca, None)?;
            let side_b = evaluation(b, cb, a.rig.unit)?;
            let (span_a, span_b) = (side_a.span(), side_b.span());
            let delay_b = align.delay(span_a, span_b);
            let side_b = side_b.delayed(delay_b);
            let pairs = Pairs::mapped(&side_a, &side_b, map, frames)?;
            let comparison = compare(&side_a, &side_b, &pairs, &comparison_times(&side_a, &side_b, rate));
            let names = |rig: &Rig, bones: &[usize]| bones.iter().map(|&i| rig.skeleton.bone(i).name.clone()).collect();
            Ok(AnimationDiff {
                a: label(a.rig, ca),
                b: label(b.rig, cb),
                span_a,
                span_b,
                delay_b,
                frame_rate: side_a.clip.map(Clip::frame_rate),
                samples: comparison.samples,
                rig_size: comparison.rig_size,
                worst: comparison.worst_distance(),
                only_a: names(a.rig, &pairs.bones.only_a),
                only_b: names(b.rig, &pairs.bones.only_b),
                helpers: pairs.bones.helpers,
                conversion_a: names(a.rig, &pairs.bones.conversion_a),
                conversion_b: names(b.rig, &pairs.bones.conversion_b),
                skinned_a: names(a.rig, &pairs.bones.skinned_a),
                skinned_b: names(b.rig, &pairs.bones.skinned_b),
                bones: comparison.bones,
                meshes: comparison.meshes,
            })
        })
        .collect::<Result<Vec<_>, DiffError>>()?;
    Ok(FileDiff {
        a: a.file.clone(),
        b: b.file.clone(),
        inherit_a: a.setup.modes.label().to_owned(),
        inherit_b: b.setup.modes.label().to_owned(),
        unit_a: a.rig.unit,
        unit_b: b.rig.unit,
        interp_a: a.setup.layers.interpolation.rotation,
        interp_b: b.setup.layers.interpolation.rotation,
        rate,
        animations,
        clips_only_a: only_a.iter().map(|&c| label(a.rig, Some(c))).collect(),
        clips_only_b: only_b.iter().map(|&c| label(b.rig, Some(c))).collect(),
    })
}

/// Clip pairs `(in A, in B)` (`None`: the rest pose), and the clips of each side left out.
type ClipPairs = (Vec<(Option<usize>, Option<usize>)>, Vec<usize>, Vec<usize>);

/// The clips to compare: the ones chosen, else every clip paired by name; two files without clips compare their rest
/// poses, and two with one clip each those whatever their names (a BVH's unnamed motion, a USD stage's timeline).
fn pair_clips(a: &FileSide, b: &FileSide, clips: Clips) -> ClipPairs {
    match clips {
        Clips::Chosen => (vec![(a.setup.clip, b.setup.clip)], vec![], vec![]),
        Clips::ByName if a.rig.clips.is_empty() && b.rig.clips.is_empty() => (vec![(None, None)], vec![], vec![]),
        Clips::ByName if a.rig.clips.len() == 1 && b.rig.clips.len() == 1 => (vec![(Some(0), Some(0))], vec![], vec![]),
        Clips::ByName => {
            let (pairs, only_a, only_b) = match_clips(&a.rig.clips, &b.rig.clips);
            (pairs.into_iter().map(|(i, j)| (Some(i), Some(j))).collect(), only_a, only_b)
        }
    }
}
