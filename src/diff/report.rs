//! Two files compared as a whole: their animations paired (by name, or as chosen), each pair compared, and what
//! had no partner listed.

use super::{BoneDifference, DiffError, Extreme, MeshDifference, Pairs, compare, comparison_times, match_clips};
use crate::eval::Evaluation;
use crate::eval::layers::RotationInterpolation;
use crate::model::{Clip, InheritMode, Rig, Unit};

/// One side of a file comparison, before clips are chosen.
#[derive(Clone, Debug)]
pub struct FileSide<'a> {
    /// The file's name, as reports show it.
    pub file: String,
    pub rig: &'a Rig,
    pub modes: Vec<InheritMode>,
    /// What the modes are called in reports (`declared`, or a mode's id).
    pub inherit: String,
    /// The clip to compare (by name or index); every clip, paired by name, when neither side names one.
    pub anim: Option<String>,
    /// How its linear rotation tracks are interpolated: as the file says (slerp), or as a runtime plays them.
    pub interp: RotationInterpolation,
}

/// One pair of animations compared.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct AnimationDiff {
    /// The clips' names (`rest pose` for a file without clips).
    pub a: String,
    pub b: String,
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

/// Compares `a` with `b` at their key times and `rate` times a second, lengths in A's unit; `map` pairs bones by
/// name explicitly.
pub fn diff_files(a: &FileSide, b: &FileSide, map: &[(String, String)], rate: f64) -> Result<FileDiff, DiffError> {
    let (pairs, only_a, only_b) = pair_clips(a, b)?;
    let label = |rig: &Rig, clip: Option<usize>| clip.map_or_else(|| "rest pose".to_owned(), |c| rig.clips[c].label());
    let animations = pairs
        .iter()
        .map(|&(ca, cb)| {
            let side_a = Evaluation::new(a.rig, ca.map(|c| &a.rig.clips[c]), &a.modes).played_with(a.interp);
            let side_b = Evaluation::new(b.rig, cb.map(|c| &b.rig.clips[c]), &b.modes)
                .measured_in(a.rig.unit)
                .played_with(b.interp);
            let pairs = Pairs::mapped(&side_a, &side_b, map)?;
            let comparison = compare(&side_a, &side_b, &pairs, &comparison_times(&side_a, &side_b, rate));
            let names = |rig: &Rig, bones: &[usize]| bones.iter().map(|&i| rig.skeleton.bone(i).name.clone()).collect();
            Ok(AnimationDiff {
                a: label(a.rig, ca),
                b: label(b.rig, cb),
                samples: comparison.samples,
                rig_size: comparison.rig_size,
                worst: comparison.worst_distance(),
                only_a: names(a.rig, &pairs.bones.only_a),
                only_b: names(b.rig, &pairs.bones.only_b),
                helpers: pairs.bones.helpers,
                conversion_a: names(a.rig, &pairs.bones.conversion_a),
                conversion_b: names(b.rig, &pairs.bones.conversion_b),
                bones: comparison.bones,
                meshes: comparison.meshes,
            })
        })
        .collect::<Result<Vec<_>, DiffError>>()?;
    Ok(FileDiff {
        a: a.file.clone(),
        b: b.file.clone(),
        inherit_a: a.inherit.clone(),
        inherit_b: b.inherit.clone(),
        unit_a: a.rig.unit,
        unit_b: b.rig.unit,
        interp_a: a.interp,
        interp_b: b.interp,
        rate,
        animations,
        clips_only_a: only_a.iter().map(|&c| label(a.rig, Some(c))).collect(),
        clips_only_b: only_b.iter().map(|&c| label(b.rig, Some(c))).collect(),
    })
}

/// Clip pairs `(in A, in B)` (`None`: the rest pose), and the clips of each side left out.
type ClipPairs = (Vec<(Option<usize>, Option<usize>)>, Vec<usize>, Vec<usize>);

/// The clips to compare: the ones named (a name given for one side only is looked up on both), else every clip
/// paired by name; two files without clips compare their rest poses.
fn pair_clips(a: &FileSide, b: &FileSide) -> Result<ClipPairs, DiffError> {
    let find = |side: &FileSide, name: &str| -> Result<usize, DiffError> {
        let no_clip = || DiffError::NoClip { file: side.file.clone(), name: name.to_owned() };
        let clip = side.rig.find_clip(name).ok_or_else(no_clip)?;
        Ok(side.rig.clips.iter().position(|c| std::ptr::eq(c, clip)).unwrap_or(0))
    };
    match (&a.anim, &b.anim) {
        (None, None) if a.rig.clips.is_empty() && b.rig.clips.is_empty() => Ok((vec![(None, None)], vec![], vec![])),
        (None, None) => {
            let (pairs, only_a, only_b) = match_clips(&a.rig.clips, &b.rig.clips);
            Ok((pairs.into_iter().map(|(i, j)| (Some(i), Some(j))).collect(), only_a, only_b))
        }
        (Some(x), Some(y)) => Ok((vec![(Some(find(a, x)?), Some(find(b, y)?))], vec![], vec![])),
        (Some(name), None) | (None, Some(name)) => {
            let same = |side: &FileSide, other: &FileSide, index: usize| -> Result<usize, DiffError> {
                let clip: &Clip = &other.rig.clips[index];
                find(side, clip.name.as_deref().unwrap_or(name))
            };
            if a.anim.is_some() {
                let i = find(a, name)?;
                Ok((vec![(Some(i), Some(same(b, a, i)?))], vec![], vec![]))
            } else {
                let j = find(b, name)?;
                Ok((vec![(Some(same(a, b, j)?), Some(j))], vec![], vec![]))
            }
        }
    }
}
