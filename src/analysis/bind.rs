//! Do a skin's inverse bind matrices agree with its skeleton? Two different things make a joint's bind differ from
//! the pose the file stores, and only one is a fault:
//!
//! - **A broken skin**: one joint's bind matrix disagrees with the joints around it. Bound 5 cm off its bone, it
//!   pulls the vertices it carries 5 cm away from their neighbours' in every pose.
//! - **A stored pose that is not the bind pose**: DCCs store the pose of their current frame (Blender's FBX), or of
//!   any time (3ds Max, Maya), while the bind matrices keep the pose the mesh was bound in. The skin renders right;
//!   where the clip animates those joints it does not even show.
//!
//! Bind matrices live in the skin's bind space, which may differ from the model space by the mesh node's transform
//! and any unit or axis conversion, so they are compared joint to joint: each joint relative to its **anchor**, the
//! nearest of its ancestors in the skin (`IBM_a · IBM_j⁻¹`, where the stored pose has `W_a⁻¹ · W_j`), and the roots
//! of a skin relative to their common bind space. Only joints some vertex is weighted to count: the others deform
//! nothing (an FBX skin's extra joint for its unweighted vertices is where the mesh node is now, not a bind).
//!
//! Relative to its anchor, a joint bound elsewhere and a joint posed elsewhere look alike. Their children tell them
//! apart: a posed joint carries its children along (they agree with it), while a bind matrix moved on its own leaves
//! them behind (every child disagrees with it, but agrees with its anchor as if it were not there). So a joint is
//! **broken** when its children say so, and **posed** otherwise. A moved leaf or root has no such witness and reads
//! as posed.
//!
//! A bind matrix whose last row is not (0, 0, 0, 1) places nothing rigidly: every point it carries is divided by a
//! homogeneous coordinate that skinning drops (an exporter that multiplied every entry by its unit factor scrambles
//! the skin that way). Such a joint is broken whatever its neighbours hold, and said so.

use glam::DMat4;
use serde::Serialize;

use crate::eval::{BonesEvaluator, Evaluation, invert, median, over_runs};
use crate::math::decompose;
use crate::model::{MAX_FRAMES, Rig, sample_times};

/// How far a bind matrix may be from the stored pose before it counts as elsewhere.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct BindTolerance {
    /// Model units (default 1e-4).
    pub distance: f64,
    /// Degrees (default 0.01).
    pub angle_deg: f64,
    /// Relative change of any scale factor (default 1e-4).
    pub scale: f64,
}

impl Default for BindTolerance {
    fn default() -> Self {
        BindTolerance { distance: 1e-4, angle_deg: 0.01, scale: 1e-4 }
    }
}

/// How far a joint's bind matrix is from a pose's model matrix of it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct BindGap {
    /// Between the two origins, in model units.
    pub distance: f64,
    /// Between the two rotations (polar decomposition), in degrees.
    pub angle_deg: f64,
    /// The largest relative change of a scale factor (1 for a factor that is zero in the pose and not in the bind).
    pub scale_change: f64,
}

impl BindGap {
    fn between(bind: &DMat4, pose: &DMat4) -> Self {
        let (b, p) = (decompose(bind), decompose(pose));
        BindGap {
            distance: b.translation.distance(p.translation),
            angle_deg: b.rotation.angle_between(p.rotation).to_degrees(),
            scale_change: (0..3).map(|axis| scale_change(b.scale[axis], p.scale[axis])).fold(0.0, f64::max),
        }
    }

    /// The largest of the three as a multiple of its tolerance: at most 1 within the tolerance.
    fn excess(&self, tolerance: &BindTolerance) -> f64 {
        let ratios = [
            self.distance / tolerance.distance,
            self.angle_deg / tolerance.angle_deg,
            self.scale_change / tolerance.scale,
        ];
        // A NaN (a zero tolerance over a zero gap) is no excess; `f64::max` ignores it.
        ratios.into_iter().fold(0.0, f64::max)
    }

    fn within(&self, tolerance: &BindTolerance) -> bool {
        self.excess(tolerance) <= 1.0
    }
}

/// One joint whose bind differs from the stored pose relative to its anchor (see the module).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct BindMismatch {
    pub bone: usize,
    pub name: String,
    #[serde(flatten)]
    pub gap: BindGap,
    /// The bind matrix's last row, where it is not (0, 0, 0, 1).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub last_row: Option<[f64; 4]>,
}

impl BindMismatch {
    /// What is wrong with the joint's bind, in a few words.
    pub fn says(&self) -> String {
        match self.last_row {
            Some(row) => {
                // To nine decimals: 0.01, not 0.010000000000000002.
                let [x, y, z, w] = row.map(|v| (v * 1e9).round() / 1e9 + 0.0);
                format!(
                    "`{}`'s bind matrix has the last row ({x}, {y}, {z}, {w}), not (0, 0, 0, 1): it places nothing \
                     rigidly",
                    self.name
                )
            }
            None => format!(
                "`{}` is bound {:.6} units and {:.4}° (scale {:+.4} %) off the joints around it",
                self.name,
                self.gap.distance,
                self.gap.angle_deg,
                100.0 * self.gap.scale_change
            ),
        }
    }
}

/// How far a bind matrix's last row may be from (0, 0, 0, 1): far below any unit factor, far above rounding.
const LAST_ROW_TOLERANCE: f64 = 1e-9;

/// The last row of `bind` where it is not (0, 0, 0, 1).
fn not_affine(bind: &DMat4) -> Option<[f64; 4]> {
    let row = bind.row(3).to_array();
    let off = row.iter().zip([0.0, 0.0, 0.0, 1.0]).any(|(a, b): (&f64, f64)| (a - b).abs() > LAST_ROW_TOLERANCE);
    // `+ 0.0` makes a negative zero 0.
    off.then_some(row.map(|v| v + 0.0))
}

/// A frame of the clip.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct ClipFrame {
    /// At the clip's frame rate (the nearest whole frame).
    pub frame: f64,
    pub time: f64,
}

/// What the bind check found, joints in bone order (a joint of several skins once, with its first skin's bind).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct BindCheck {
    /// Joints whose bind matrix disagrees with the joints around it: a broken skin.
    pub broken: Vec<BindMismatch>,
    /// Joints the stored pose holds away from their bind: harmless.
    pub posed: Vec<BindMismatch>,
    /// Where there are posed joints, the clip's frame whose pose is the bind pose: every joint but the broken ones
    /// at its bind relative to its anchor, within the tolerance (the closest such frame, the first of equals).
    pub bind_frame: Option<ClipFrame>,
}

impl BindCheck {
    /// The note on posed joints, for people: which joints, how far, and which frame is the bind pose.
    pub fn note(&self) -> Option<String> {
        let first = self.posed.first()?;
        let count = self.posed.len();
        let mut names: Vec<&str> = self.posed.iter().take(6).map(|m| m.name.as_str()).collect();
        if count > names.len() {
            names.push("…");
        }
        let angle = self.posed.iter().map(|m| m.gap.angle_deg).fold(first.gap.angle_deg, f64::max);
        let distance = self.posed.iter().map(|m| m.gap.distance).fold(first.gap.distance, f64::max);
        // A distance that would print as 0.0000 is left out.
        let moved = if distance >= 5e-5 { format!(" and {distance:.4} units") } else { String::new() };
        let frame = match self.bind_frame {
            Some(f) => format!("the clip's frame {:.0} ({:.3} s) is the bind pose", f.frame, f.time),
            None => "no frame of the clip is the bind pose".to_owned(),
        };
        Some(format!(
            "the stored pose is not the bind pose: {count} {} ({}) {} posed up to {angle:.2}°{moved} from where the \
             mesh was bound; {frame}",
            if count == 1 { "joint" } else { "joints" },
            names.join(", "),
            if count == 1 { "is" } else { "are" },
        ))
    }
}

/// The bind check of `evaluation`'s rig at its rest pose (under the evaluation's modes), with the frame of its clip
/// as authored (without layers) that is the bind pose, as the module says.
pub fn check_bind(evaluation: &Evaluation, tolerance: &BindTolerance) -> BindCheck {
    let rig = evaluation.rig;
    let authored = evaluation.without_layers();
    let rest = authored.at_rest().pose_at(0.0).model.model;
    let mut check = BindCheck::default();
    let mismatch = |joint: &Joint, gap| BindMismatch {
        bone: joint.bone,
        name: rig.skeleton.bone(joint.bone).name.clone(),
        gap,
        last_row: not_affine(&joint.bind),
    };
    // Each skin with its broken joints.
    let mut judged = Vec::new();
    for mut skin in checked_skins(rig) {
        let broken = skin.broken(&rest, tolerance);
        let gaps = skin.gaps(&rest);
        check.broken.extend(broken.iter().map(|&j| mismatch(&skin.joints[j], gaps[j])));
        // The others are judged from their nearest anchor that is not broken.
        skin.skip_anchors(&broken);
        let gaps = skin.gaps(&rest);
        let projective =
            (0..skin.joints.len()).filter(|j| !broken.contains(j) && not_affine(&skin.joints[*j].bind).is_some());
        check.broken.extend(projective.map(|j| mismatch(&skin.joints[j], gaps[j])));
        let broken_or_projective = |j: &usize| broken.contains(j) || not_affine(&skin.joints[*j].bind).is_some();
        let posed = (0..skin.joints.len()).filter(|j| !broken_or_projective(j) && !gaps[*j].within(tolerance));
        check.posed.extend(posed.map(|j| mismatch(&skin.joints[j], gaps[j])));
        judged.push((skin, broken));
    }
    if !check.posed.is_empty() {
        check.bind_frame = bind_frame(&judged, &authored, tolerance);
    }
    check.broken.sort_by_key(|m| m.bone);
    check.posed.sort_by_key(|m| m.bone);
    check
}

/// A joint the check compares: weighted, with an invertible bind matrix.
struct Joint {
    bone: usize,
    inverse_bind: DMat4,
    bind: DMat4,
    /// The nearest ancestor among the skin's checked joints (its index there); `None` for a root of the skin.
    anchor: Option<usize>,
}

/// The checked joints of one skin, parents first.
struct CheckedSkin {
    joints: Vec<Joint>,
}

impl CheckedSkin {
    /// How far each joint's bind is from `model`'s matrix of it, relative to its anchor.
    fn gaps(&self, model: &[DMat4]) -> Vec<BindGap> {
        let roots = self.root_space(model);
        (0..self.joints.len()).map(|j| self.gap(j, self.joints[j].anchor, model, &roots)).collect()
    }

    /// How far joint `j`'s bind is from `model`'s matrix of it when placed relative to `anchor` as `model` poses
    /// the anchor (for none, in the roots' common bind space `roots`).
    fn gap(&self, j: usize, anchor: Option<usize>, model: &[DMat4], roots: &DMat4) -> BindGap {
        let space = anchor.map_or(*roots, |a| model[self.joints[a].bone] * self.joints[a].inverse_bind);
        BindGap::between(&(space * self.joints[j].bind), &model[self.joints[j].bone])
    }

    /// The bind-space-to-model transform `W_r · IBM_r` most of the roots share at `model` (entry-wise median).
    fn root_space(&self, model: &[DMat4]) -> DMat4 {
        let roots = self.joints.iter().filter(|j| j.anchor.is_none());
        median(roots.map(|j| model[j.bone] * j.inverse_bind)).unwrap_or(DMat4::IDENTITY)
    }

    /// The joints whose bind matrix is the odd one out at `rest`: off relative to their anchor, with children that
    /// are all off relative to them but at their bind relative to that anchor.
    fn broken(&self, rest: &[DMat4], tolerance: &BindTolerance) -> Vec<usize> {
        let roots = self.root_space(rest);
        let gaps = self.gaps(rest);
        let children = |j: usize| (0..self.joints.len()).filter(move |&c| self.joints[c].anchor == Some(j));
        (0..self.joints.len())
            .filter(|&j| {
                let Some(anchor) = self.joints[j].anchor else { return false };
                let left_behind =
                    |c: usize| !gaps[c].within(tolerance) && self.gap(c, Some(anchor), rest, &roots).within(tolerance);
                !gaps[j].within(tolerance) && children(j).next().is_some() && children(j).all(left_behind)
            })
            .collect()
    }

    /// Anchors every joint to its nearest anchor that is not one of `skipped`.
    fn skip_anchors(&mut self, skipped: &[usize]) {
        for j in 0..self.joints.len() {
            let mut anchor = self.joints[j].anchor;
            while let Some(a) = anchor.filter(|a| skipped.contains(a)) {
                anchor = self.joints[a].anchor;
            }
            self.joints[j].anchor = anchor;
        }
    }
}

/// Every skin's checked joints (a bone already checked in an earlier skin is left out of later ones).
fn checked_skins(rig: &Rig) -> Vec<CheckedSkin> {
    let mut seen = vec![false; rig.skeleton.len()];
    rig.skins
        .iter()
        .enumerate()
        .map(|(s, skin)| {
            let weighted = rig.weighted_joints(s);
            let mut joints = Vec::new();
            for (k, (&bone, ibm)) in skin.joints.iter().zip(&skin.inverse_bind).enumerate() {
                if !weighted[k] || seen.get(bone) != Some(&false) {
                    continue;
                }
                let Some(bind) = invert(ibm) else { continue };
                seen[bone] = true;
                joints.push(Joint { bone, inverse_bind: *ibm, bind, anchor: None });
            }
            // In bone order, parents first: an anchor comes before the joints anchored to it.
            joints.sort_by_key(|j| j.bone);
            let index_of_bone: std::collections::HashMap<usize, usize> =
                joints.iter().enumerate().map(|(i, j)| (j.bone, i)).collect();
            for joint in &mut joints {
                let mut up = rig.skeleton.parent(joint.bone);
                while let Some(bone) = up {
                    if let Some(&a) = index_of_bone.get(&bone) {
                        joint.anchor = Some(a);
                        break;
                    }
                    up = rig.skeleton.parent(bone);
                }
            }
            CheckedSkin { joints }
        })
        .collect()
}

/// The frame of `authored`'s clip (at its frame rate, thinned past [`MAX_FRAMES`] as every whole-clip pass is)
/// whose pose is closest to the bind pose of the skins' joints but their broken ones, if it is within the tolerance.
/// Only the checked joints and their ancestors are evaluated (bone by bone where the clip allows, and in a frame
/// only as far as it is looked at), over runs of frames on every thread, and a frame is left as soon as one joint
/// shows it further than the closest frame of its run or than the tolerance; of equally close frames, the first.
fn bind_frame(
    skins: &[(CheckedSkin, Vec<usize>)],
    authored: &Evaluation,
    tolerance: &BindTolerance,
) -> Option<ClipFrame> {
    let clip = authored.clip?;
    let rate = clip.frame_rate();
    let joints: Vec<usize> = skins.iter().flat_map(|(skin, _)| skin.joints.iter().map(|j| j.bone)).collect();
    let bones = authored.skeleton().with_ancestors(&joints);
    let span = clip.span();
    let times = sample_times([], span.start, span.end, rate, MAX_FRAMES).times;
    let closest = |a: (f64, f64), b: (f64, f64)| if b.0 < a.0 { b } else { a };
    // Bones are evaluated parents first, so each skin's last root's bone brings every root of it.
    let last_roots: Vec<Option<usize>> =
        skins.iter().map(|(skin, _)| skin.joints.iter().filter(|j| j.anchor.is_none()).map(|j| j.bone).max()).collect();
    let runs = over_runs(&times, |run| {
        let mut frame = FramePose::new(authored, &bones);
        let mut best: Option<(f64, f64)> = None;
        for &time in run {
            // A frame further than the tolerance is no bind pose, however close.
            let beaten = best.map_or(1.0, |(excess, _)| excess.min(1.0));
            frame.start(time);
            let excess = frame_excess(skins, &last_roots, &mut frame, tolerance, beaten);
            best = Some(best.map_or((excess, time), |best| closest(best, (excess, time))));
        }
        best
    });
    let (excess, time) = runs.into_iter().flatten().reduce(closest)?;
    (excess <= 1.0).then(|| ClipFrame { frame: (time * rate).round(), time })
}

/// The largest excess over `tolerance` of the gaps of `skins`' joints (their broken ones aside) at `frame`, or a
/// value past `beaten` as soon as one joint's passes it (the frame cannot be the closest). `last_roots` is each
/// skin's root joint of the highest bone index (`None` for a skin without joints).
fn frame_excess(
    skins: &[(CheckedSkin, Vec<usize>)],
    last_roots: &[Option<usize>],
    frame: &mut FramePose,
    tolerance: &BindTolerance,
    beaten: f64,
) -> f64 {
    let mut largest: f64 = 0.0;
    for ((skin, broken), &last_root) in skins.iter().zip(last_roots) {
        let Some(last_root) = last_root else { continue };
        let roots = skin.root_space(frame.model_with(last_root));
        for j in (0..skin.joints.len()).filter(|j| !broken.contains(j)) {
            let model = frame.model_with(skin.joints[j].bone);
            largest = largest.max(skin.gap(j, skin.joints[j].anchor, model, &roots).excess(tolerance));
            if largest > beaten {
                return largest;
            }
        }
    }
    largest
}

/// One frame's pose of some bones (each with its ancestors, parents first), evaluated only as far as it is looked
/// at: a frame left after its first joints costs those joints' chains, not the rig.
struct FramePose<'e, 'a> {
    evaluator: BonesEvaluator<'e, 'a>,
    /// Each bone's place among the bones, plus one (how many bones bring it).
    through: Vec<usize>,
    time: f64,
    evaluated: usize,
}

impl<'e, 'a> FramePose<'e, 'a> {
    fn new(evaluation: &'e Evaluation<'a>, bones: &'e [usize]) -> Self {
        let mut through = vec![0; evaluation.skeleton().len()];
        for (place, &bone) in bones.iter().enumerate() {
            through[bone] = place + 1;
        }
        FramePose { evaluator: BonesEvaluator::for_prefixes(evaluation, bones), through, time: 0.0, evaluated: 0 }
    }

    /// Looks at the frame at `time`: nothing of it evaluated yet.
    fn start(&mut self, time: f64) {
        self.time = time;
        self.evaluated = 0;
    }

    /// The model matrices, with `bone` and its ancestors evaluated. The evaluated prefix at least doubles each time
    /// it grows, so a frame looked at whole costs at most two evaluations of it.
    fn model_with(&mut self, bone: usize) -> &[DMat4] {
        let needed = self.through[bone];
        if needed > self.evaluated {
            self.evaluated = self.evaluator.evaluate_first(self.time, needed.max(2 * self.evaluated)).1;
        }
        &self.evaluator.pose().model.model
    }
}

/// How much a scale factor changes from `pose` to `bind`, relative to `pose`; a zero (degenerate) factor in the pose
/// has no such ratio, and counts as all of the bind's (1), or none when both are zero, never NaN or infinity.
fn scale_change(bind: f64, pose: f64) -> f64 {
    match (bind - pose).abs() / pose.abs() {
        change if change.is_finite() => change,
        _ if bind == pose => 0.0,
        _ => 1.0,
    }
}

#[cfg(test)]
mod tests {
    use glam::{DQuat, DVec3};

    use super::*;
    use crate::import::demo_rig;
    use crate::model::Skin;

    /// The demo arm's skin is upper arm → forearm → hand (bones 1, 2, 3; joints 0, 1, 2), bound at rest.
    fn checked(rig: &Rig) -> BindCheck {
        check_bind(&Evaluation::declared(rig, rig.clips.first()), &BindTolerance::default())
    }

    fn names(mismatches: &[BindMismatch]) -> Vec<&str> {
        mismatches.iter().map(|m| m.name.as_str()).collect()
    }

    #[test]
    fn a_skin_bound_at_rest_is_neither_broken_nor_posed() {
        assert_eq!(checked(&demo_rig()), BindCheck::default());
    }

    #[test]
    fn a_bind_matrix_scaled_entry_by_entry_is_named_not_rigid() {
        // Every entry of every bind matrix times 0.01 (an exporter's unit factor applied to the whole matrix): the
        // joints still agree with each other, so only their last row gives them away, and it is named.
        let mut rig = demo_rig();
        for ibm in &mut rig.skins[0].inverse_bind {
            *ibm = (*ibm).inverse().mul_scalar(0.01).inverse();
        }
        let check = checked(&rig);
        assert_eq!(names(&check.broken), ["upper_arm", "forearm", "hand"]);
        assert!(check.posed.is_empty());
        assert!(check.broken.iter().all(|m| m.last_row.is_some_and(|r| (r[3] - 0.01).abs() < 1e-15 && r[0] == 0.0)));
        let said = check.broken[1].says();
        assert_eq!(
            said,
            "`forearm`'s bind matrix has the last row (0, 0, 0, 0.01), not (0, 0, 0, 1): it places nothing rigidly"
        );
    }

    #[test]
    fn a_bind_matrix_moved_on_its_own_breaks_the_skin() {
        let mut rig = demo_rig();
        // The forearm rests at (1, 1.5, 0); bind it 3 cm higher, turned 10° about Z. The hand, still bound where it
        // rests, is left behind: off relative to the forearm, at its bind relative to the upper arm.
        let bound =
            DMat4::from_rotation_translation(DQuat::from_rotation_z(10f64.to_radians()), DVec3::new(1.0, 1.53, 0.0));
        rig.skins[0].inverse_bind[1] = bound.inverse();
        let check = checked(&rig);
        assert_eq!(names(&check.broken), ["forearm"]);
        assert!(check.posed.is_empty() && check.note().is_none(), "{check:?}");
        let gap = check.broken[0].gap;
        assert!((gap.distance - 0.03).abs() < 1e-12, "{gap:?}");
        assert!((gap.angle_deg - 10.0).abs() < 1e-9, "{gap:?}");
        assert!(gap.scale_change < 1e-12, "{gap:?}");
    }

    #[test]
    fn a_skin_bound_in_a_frame_of_the_clip_is_posed_at_rest_and_names_that_frame() {
        let mut rig = demo_rig();
        // Bind every joint where frame 15 (0.5 s) of the stretch clip has it: the upper arm stretched 1.6× (the
        // skin's root, which places the skin), the forearm bent by `bend(0.5)`, the hand carried along.
        let evaluation = Evaluation::declared(&rig, rig.clips.first());
        let frame = evaluation.pose_at(0.5).model.model;
        let binds: Vec<DMat4> = rig.skins[0].joints.iter().map(|&bone| frame[bone].inverse()).collect();
        rig.skins[0].inverse_bind = binds;
        let check = checked(&rig);
        assert!(check.broken.is_empty(), "{check:?}");
        assert_eq!(names(&check.posed), ["forearm"]);
        // The bend is Rz(75°·s)·Ry(20°·s) with s = sin(π/4): its angle θ has cos(θ/2) = cos(37.5°·s)·cos(10°·s).
        let s = std::f64::consts::FRAC_1_SQRT_2;
        let bend = 2.0 * ((37.5 * s).to_radians().cos() * (10.0 * s).to_radians().cos()).acos();
        let gap = check.posed[0].gap;
        assert!((gap.angle_deg - bend.to_degrees()).abs() < 1e-4, "{gap:?} vs {}°", bend.to_degrees());
        assert!(gap.distance < 1e-9, "the forearm stays at the elbow: {gap:?}");
        assert_eq!(check.bind_frame, Some(ClipFrame { frame: 15.0, time: 0.5 }));
        let note = check.note().unwrap();
        assert!(note.contains("1 joint (forearm) is posed") && note.contains("frame 15 (0.500 s)"), "{note}");
    }

    #[test]
    fn the_bind_frame_is_the_closest_a_search_of_every_whole_pose_finds() {
        // Bound between frames 15 and 16 (0.51 s), with a tolerance several frames pass: the search, which leaves a
        // frame early and evaluates it only as far as it looks, picks the frame that judging every joint of every
        // frame's whole pose picks (the least excess, the first of equals).
        let mut rig = demo_rig();
        let frame = Evaluation::declared(&rig, rig.clips.first()).pose_at(0.51).model.model;
        rig.skins[0].inverse_bind = rig.skins[0].joints.iter().map(|&bone| frame[bone].inverse()).collect();
        let tolerance = BindTolerance { distance: 0.05, angle_deg: 4.0, scale: 0.05 };
        let evaluation = Evaluation::declared(&rig, rig.clips.first());
        let skins = checked_skins(&rig);
        let excess = |time: f64| {
            let model = evaluation.pose_at(time).model.model;
            let gaps = skins.iter().flat_map(|skin| skin.gaps(&model));
            gaps.map(|gap| gap.excess(&tolerance)).fold(0.0, f64::max)
        };
        let clip = &rig.clips[0];
        let span = clip.span();
        let times = sample_times([], span.start, span.end, clip.frame_rate(), MAX_FRAMES).times;
        let excesses: Vec<(f64, f64)> = times.iter().map(|&time| (excess(time), time)).collect();
        assert!(excesses.iter().filter(|(e, _)| *e <= 1.0).count() >= 3, "several frames pass: {excesses:?}");
        let closest = excesses.into_iter().reduce(|a, b| if b.0 < a.0 { b } else { a }).unwrap();
        let check = check_bind(&evaluation, &tolerance);
        assert_eq!(check.bind_frame.map(|f| f.time), Some(closest.1));
        assert_eq!(check_bind(&evaluation, &BindTolerance::default()).bind_frame, None, "0.51 s is no frame");
    }

    #[test]
    fn a_pose_no_frame_holds_is_named_as_such() {
        let mut rig = demo_rig();
        // Bound with the forearm (and the hand with it) twisted 30° about its axis, X: no frame of the stretch clip
        // twists it, and the stored pose has it straight.
        let rest = rig.skeleton.rest_model_matrices();
        let forearm = rest[2] * DMat4::from_quat(DQuat::from_rotation_x(30f64.to_radians()));
        let hand = forearm * rig.skeleton.bone(3).rest.matrix();
        rig.skins[0].inverse_bind[1] = forearm.inverse();
        rig.skins[0].inverse_bind[2] = hand.inverse();
        let check = checked(&rig);
        assert!(check.broken.is_empty());
        assert_eq!(names(&check.posed), ["forearm"]);
        assert!((check.posed[0].gap.angle_deg - 30.0).abs() < 1e-9);
        assert_eq!(check.bind_frame, None);
        assert!(check.note().unwrap().ends_with("no frame of the clip is the bind pose"));
    }

    #[test]
    fn a_moved_leaf_has_no_witness_and_reads_as_posed() {
        let mut rig = demo_rig();
        // The hand has no joint below it to say whether its bind or its pose moved.
        rig.skins[0].inverse_bind[2] = DMat4::from_translation(DVec3::new(2.0, 1.55, 0.0)).inverse();
        let check = checked(&rig);
        assert!(check.broken.is_empty());
        assert_eq!(names(&check.posed), ["hand"]);
        assert!((check.posed[0].gap.distance - 0.05).abs() < 1e-12);
        assert!(check.note().unwrap().contains("1 joint (hand) is posed up to 0.00° and 0.0500 units"));
    }

    #[test]
    fn joints_no_vertex_follows_are_not_checked() {
        let mut rig = demo_rig();
        // A second skin listing the shoulder, bound anywhere, with no mesh on it.
        rig.skins.push(Skin {
            name: None,
            joints: vec![0, 2],
            inverse_bind: vec![DMat4::from_translation(DVec3::splat(7.0)), DMat4::ZERO],
            node_bind: None,
        });
        assert_eq!(checked(&rig), BindCheck::default());
    }

    #[test]
    fn scale_changes_are_relative_to_the_pose_and_finite_at_zero() {
        assert_eq!(scale_change(1.5, 1.0), 0.5);
        assert_eq!(scale_change(-2.0, -4.0), 0.5, "mirrored factors compare by size");
        assert_eq!(scale_change(2.0, 0.0), 1.0, "a zero factor in the pose: all of the bind's");
        assert_eq!(scale_change(0.0, 0.0), 0.0);
        assert_eq!(scale_change(1.0, 1e-320), 1.0, "a ratio past f64 counts as all of it");
    }
}
