//! Whole-clip scans: on clips whose answer is known by hand, and against decomposing every model matrix.

mod common;

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

use bonescope::analysis::{Assessment, Components, CurveRequest, Judged, ScanOptions, Tolerances, analyze, scan};
use bonescope::eval::{Evaluation, Hierarchy, Pose};
use bonescope::import::{demo_rig, stress_rig};
use bonescope::model::{
    Bone, BoneTracks, Choice, Clip, InheritMode, Interpolation, MAX_FRAMES, NodeRole, Rig, Skeleton, Track, Transform,
    sample_times,
};
use glam::{DMat4, DQuat, DVec3, Quat, Vec3};

/// A rig of `skeleton` with one clip.
fn rig_of((skeleton, clip): (Skeleton, Clip)) -> Rig {
    Rig { skeleton, clips: vec![clip], ..Rig::default() }
}

/// A parent whose X scale grows linearly from 1 at t = 0 to 2 at t = 1, and a child turned 45° about Z.
fn growing_parent() -> (Skeleton, Clip) {
    let child_rest = Transform::from_trs(DVec3::X, DQuat::from_rotation_z(45f64.to_radians()), DVec3::ONE);
    let bones = vec![
        Bone::joint("parent", None, Transform::IDENTITY),
        Bone { node: 1, ..Bone::joint("child", Some(0), child_rest) },
    ];
    let mut tracks = BoneTracks::new(0);
    let times: Arc<[f64]> = Arc::from([0.0, 1.0].as_slice());
    tracks.scale = Some(Track::new(times, vec![Vec3::ONE, Vec3::new(2.0, 1.0, 1.0)], Interpolation::Linear).unwrap());
    (Skeleton::new(bones).unwrap(), Clip::new(0, Some("grow".into()), vec![tracks], vec![]))
}

#[test]
fn sample_times_are_keys_plus_the_rate_grid() {
    let rig = rig_of(growing_parent());
    let times = Evaluation::declared(&rig, rig.clips.first()).times(4.0);
    assert_eq!(times, vec![0.0, 0.25, 0.5, 0.75, 1.0]);
    assert_eq!(Evaluation::declared(&rig, None).times(60.0), vec![0.0]);
}

#[test]
fn the_child_is_stretched_from_the_first_sample_after_zero_and_worst_at_the_end() {
    let rig = rig_of(growing_parent());
    let options = ScanOptions { rate: 10.0, ..ScanOptions::default() };
    let calls = AtomicUsize::new(0);
    let last = AtomicUsize::new(0);
    let progress = |done: usize, total: usize| {
        assert!(done <= total && total == 11);
        calls.fetch_add(1, Ordering::Relaxed);
        last.fetch_max(done, Ordering::Relaxed);
    };
    let result = scan(&Evaluation::declared(&rig, rig.clips.first()), &options, &progress);
    assert_eq!(result.samples, 11);
    assert!(calls.load(Ordering::Relaxed) >= 1);
    assert_eq!(last.load(Ordering::Relaxed), 11, "progress reaches the total");
    let parent = &result.bones[0];
    assert!(!parent.stretched(), "the parent's scale is along its own axes");
    assert_eq!(parent.non_uniform_samples, 10);
    let child = &result.bones[1];
    // At t = 0 nothing is scaled; from t = 0.1 on the parent's X scale shears the turned child.
    assert_eq!(child.flagged_samples, 10);
    assert_eq!(child.first_flagged_time, Some(0.1));
    // At t = 1: columns diag(2,1,1)·(c, c, 0) and diag(2,1,1)·(−c, c, 0) meet at acos(−0.6): 36.87° of shear.
    assert_eq!(child.worst_shear_time, 1.0);
    assert!((child.worst_shear_deg - ((-0.6f64).acos().to_degrees() - 90.0)).abs() < 1e-9);
}

#[test]
fn segment_compensation_removes_the_stretch() {
    let rig = rig_of(growing_parent());
    let evaluation =
        Evaluation::new(&rig, rig.clips.first(), &[InheritMode::Full, InheritMode::SegmentCompensate]).unwrap();
    let result = scan(&evaluation, &ScanOptions::default(), &|_, _| {});
    assert!(result.bones.iter().all(|b| !b.stretched()));
}

#[test]
fn stretched_spans_run_from_the_first_flagged_sample_to_the_end() {
    let rig = rig_of(growing_parent());
    let options = ScanOptions { rate: 10.0, ..ScanOptions::default() };
    let never = AtomicBool::new(false);
    let request = CurveRequest { bones: &[1], ghost: None, ..Default::default() };
    let evaluation = Evaluation::declared(&rig, rig.clips.first());
    let analysis = analyze(&evaluation, request, &options, &|_, _| {}, &never).unwrap();
    assert_eq!(analysis.stretched_spans(Some(1)), vec![(0.1, 1.0)]);
    assert_eq!(analysis.stretched_spans(None), vec![(0.1, 1.0)]);
    assert!(analysis.stretched_spans(Some(0)).is_empty());
    assert_eq!(analysis.curves_of(1).unwrap().model.len(), 11);
}

/// A camera hung under the growing parent, beside a joint that stays still: the camera shears as the child did, and
/// its summary says so, but the "any bone" spans the timeline marks are the figure's, which is never stretched.
#[test]
fn a_stretched_camera_is_reported_but_does_not_mark_the_figure_stretched() {
    let (skeleton, clip) = growing_parent();
    let mut bones = skeleton.bones().to_vec();
    bones[1].role = NodeRole::Camera;
    bones.push(Bone { name: "hand".into(), node: 2, parent: Some(0), role: NodeRole::Joint, ..bones[0].clone() });
    let rig = rig_of((Skeleton::new(bones).unwrap(), clip));
    let options = ScanOptions { rate: 10.0, ..ScanOptions::default() };
    let never = AtomicBool::new(false);
    let evaluation = Evaluation::declared(&rig, rig.clips.first());
    let analysis = analyze(&evaluation, CurveRequest::default(), &options, &|_, _| {}, &never).unwrap();
    assert_eq!(analysis.scan.bones[1].flagged_samples, 10, "the camera's matrix is sheared all the same");
    assert_eq!(analysis.stretched_spans(Some(1)), vec![(0.1, 1.0)]);
    assert!(analysis.stretched_spans(None).is_empty(), "no bone of the figure is stretched");
}

/// The per-bone summaries of a whole-clip scan, computed the plain way: every bone's model matrix evaluated and
/// decomposed at every sample time.
fn brute_force(skeleton: &Skeleton, clip: &Clip, hierarchy: &Hierarchy, options: &ScanOptions) -> Vec<BruteSummary> {
    let mut pose = Pose::default();
    let mut summaries = vec![BruteSummary::default(); skeleton.len()];
    for time in sample_times(clip.key_times(), clip.span().start, clip.span().end, options.rate, MAX_FRAMES).times {
        pose.evaluate(skeleton, Some(clip), hierarchy, time);
        for (summary, model) in summaries.iter_mut().zip(&pose.model.model) {
            let a = Assessment::of(model, &options.tolerances);
            summary.shear_at.push((time, a.shear_deg));
            summary.stretched_at.push(a.findings.stretched);
            summary.worst_shear_deg = summary.worst_shear_deg.max(a.shear_deg);
            if a.findings.stretched {
                summary.worst_stretch_deg = summary.worst_stretch_deg.max(a.stretch_deg);
                summary.flagged += 1;
                summary.first_flagged.get_or_insert(time);
            }
            summary.non_uniform += usize::from(a.findings.non_uniform);
            summary.mirrored += usize::from(a.findings.mirrored);
            summary.degenerate += usize::from(a.findings.degenerate);
        }
    }
    summaries
}

#[derive(Clone, Debug, Default)]
struct BruteSummary {
    worst_shear_deg: f64,
    worst_stretch_deg: f64,
    flagged: usize,
    first_flagged: Option<f64>,
    non_uniform: usize,
    mirrored: usize,
    degenerate: usize,
    shear_at: Vec<(f64, f64)>,
    stretched_at: Vec<bool>,
}

/// The scan judges bones from stretches passed down the hierarchy (model matrices only where a bone does not
/// inherit fully); it must agree with decomposing every model matrix: counts and first times exactly, every
/// sample's flag, the worst stretch to 1e-9°; the worst shear, refined between samples, never below the sampled
/// worst, the one decomposed at its reported time and, where the samples see one beyond the tolerance, never below
/// (by more than 0.001°) a sampling sixteen times as fine.
fn assert_scan_matches_brute_force(label: &str, rig: &Rig, clip: usize, modes: &[InheritMode]) {
    let (skeleton, clip) = (&rig.skeleton, &rig.clips[clip]);
    let hierarchy = Hierarchy::new(skeleton, modes).unwrap();
    let options = ScanOptions { rate: 30.0, ..ScanOptions::default() };
    let never = AtomicBool::new(false);
    let evaluation = Evaluation::new(rig, Some(clip), modes).unwrap();
    let analysis = analyze(&evaluation, CurveRequest::default(), &options, &|_, _| {}, &never).unwrap();
    let expected = brute_force(skeleton, clip, &hierarchy, &options);
    let finer = brute_force(skeleton, clip, &hierarchy, &ScanOptions { rate: 16.0 * options.rate, ..options });
    let mut pose = Pose::default();
    for ((got, want), fine) in analysis.scan.bones.iter().zip(&expected).zip(&finer) {
        let bone = format!("{label}: bone {} ({})", got.index, skeleton.bone(got.index).name);
        let shear = (got.worst_shear_deg, want.worst_shear_deg, fine.worst_shear_deg);
        // A shear the samples see as none (0 at every frame of an interpolated curve) is not searched for.
        let seen = shear.1 >= options.tolerances.min_shear_deg;
        assert!(shear.0 >= shear.1 - 1e-9 && (!seen || shear.0 >= shear.2 - 1e-3), "{bone}: worst shear {shear:?}");
        pose.evaluate(skeleton, Some(clip), &hierarchy, got.worst_shear_time);
        let at_reported = Assessment::of(&pose.model.model[got.index], &options.tolerances).shear_deg;
        assert!((at_reported - got.worst_shear_deg).abs() < 1e-9, "{bone}: worst shear time");
        let stretch = (got.worst_stretch_deg, want.worst_stretch_deg);
        assert!((stretch.0 - stretch.1).abs() < 1e-9, "{bone}: worst stretch {stretch:?}");
        assert_eq!(
            (got.flagged_samples, got.first_flagged_time, got.non_uniform_samples),
            (want.flagged, want.first_flagged, want.non_uniform),
            "{bone}"
        );
        assert_eq!((got.mirrored_samples, got.degenerate_samples), (want.mirrored, want.degenerate), "{bone}");
        let flags: Vec<bool> = (0..analysis.times.len()).map(|s| analysis.stretched_at(got.index, s)).collect();
        assert!(flags == want.stretched_at, "{bone}: stretched flags per sample");
    }
}

/// Bones whose stretch never changes (judged once per chunk) beside ones that do: a constantly sheared bone under a
/// rest scale of (1, 2, 1), a turning bone below it, and a bone with a constant non-uniform scale track.
fn fixed_and_moving() -> (Skeleton, Clip) {
    let bone = |name: &str, parent: Option<usize>, rest: Transform| Bone::joint(name, parent, rest);
    let turned = DQuat::from_rotation_z(0.5);
    let bones = vec![
        bone("root", None, Transform::IDENTITY),
        bone("squashed", Some(0), Transform::from_trs(DVec3::Y, DQuat::IDENTITY, DVec3::new(1.0, 2.0, 1.0))),
        bone("sheared", Some(1), Transform::from_trs(DVec3::Y, turned, DVec3::ONE)),
        bone("turning", Some(2), Transform::from_trs(DVec3::Y, DQuat::IDENTITY, DVec3::ONE)),
        bone("held", Some(0), Transform::IDENTITY),
    ];
    let times: Arc<[f64]> = (0..=100).map(f64::from).collect();
    let turning = |speed: f32| (0..=100).map(|k| Quat::from_rotation_x(speed * k as f32)).collect::<Vec<_>>();
    let linear = Interpolation::Linear;
    let mut root = BoneTracks::new(0);
    root.rotation = Some(Track::new(times.clone(), turning(0.3), linear).unwrap());
    let mut turns = BoneTracks::new(3);
    turns.rotation = Some(Track::new(times.clone(), turning(0.2), linear).unwrap());
    let mut held = BoneTracks::new(4);
    held.scale = Some(Track::new(times.clone(), vec![Vec3::new(1.0, 3.0, 1.0); 101], linear).unwrap());
    held.rotation = Some(Track::new(times, turning(0.1), linear).unwrap());
    (Skeleton::new(bones).unwrap(), Clip::new(0, None, vec![root, turns, held], vec![]))
}

#[test]
fn the_scan_agrees_with_decomposing_every_model_matrix() {
    let fixed = rig_of(fixed_and_moving());
    assert_scan_matches_brute_force("fixed and moving", &fixed, 0, &[InheritMode::Full; 5]);
    // The long clip spreads over several chunks of several words of flags each.
    let (stress, long) = (stress_rig(40, 240, 4), stress_rig(12, 2400, 4));
    let demo = demo_rig();
    let mut subjects = vec![
        ("stress rig", &stress, 0),
        ("long stress rig", &long, 0),
        ("demo stretch", &demo, 0),
        ("demo plain", &demo, 1),
    ];
    let stretchy = bonescope::import::load(&common::asset("blender/stretchy_full.glb"));
    match &stretchy {
        Ok(rig) => subjects.push(("stretchy_full.glb", rig, 0)),
        Err(e) => eprintln!("skipping stretchy_full.glb: {e}"),
    }
    for (label, rig, clip) in subjects {
        let skeleton = &rig.skeleton;
        for &mode in InheritMode::ALL {
            let label = format!("{label}, all {}", mode.id());
            assert_scan_matches_brute_force(&label, rig, clip, &vec![mode; skeleton.len()]);
        }
        // Mixed: fully inheriting bones below bones judged from their model matrices.
        let mixed: Vec<InheritMode> = (0..skeleton.len()).map(|b| InheritMode::ALL[b % 3]).collect();
        assert_scan_matches_brute_force(&format!("{label}, mixed"), rig, clip, &mixed);
    }
}

/// A curve's components are those of `matrix`'s assessment (in single precision).
fn assert_components(got: &Components, matrix: &DMat4, label: &str) {
    let expected = Assessment::of(matrix, &ScanOptions::default().tolerances);
    let parts = &expected.parts;
    assert!(got.position().abs_diff_eq(parts.translation, 1e-6), "{label}");
    assert!(
        got.rotation.abs_diff_eq(parts.rotation.as_quat(), 1e-6),
        "{label}: {:?} vs {:?}",
        got.rotation,
        parts.rotation
    );
    assert!(got.scale.abs_diff_eq(parts.scale.as_vec3(), 1e-6), "{label}: {} vs {}", got.scale, parts.scale);
    assert!(
        got.stretch.abs_diff_eq(parts.stretch.as_quat(), 1e-5),
        "{label}: {:?} vs {:?}",
        got.stretch,
        parts.stretch
    );
    assert!((got.shear_deg - expected.shear_deg as f32).abs() < 1e-4, "{label}");
    assert_eq!(got.sign, parts.sign as f32, "{label}");
}

/// Curves are the plotted bones' decomposed local and model matrices (the model ones from the judged stretches),
/// and the ghost curves the same under the ghost's modes, evaluated only down their chains: they must be the
/// components of whole poses.
#[test]
fn curves_match_the_whole_pose_and_ghost_curves_the_pose_under_the_ghost_modes() {
    let rig = stress_rig(30, 150, 5);
    let (skeleton, clip) = (&rig.skeleton, &rig.clips[0]);
    let hierarchy = Hierarchy::new(skeleton, &skeleton.declared_modes()).unwrap();
    let options = ScanOptions { rate: 30.0, ..ScanOptions::default() };
    let plotted = [7, 16, 25];
    let never = AtomicBool::new(false);
    let evaluation = Evaluation::declared(&rig, Some(clip));
    for &mode in InheritMode::ALL {
        let ghost_hierarchy = Hierarchy::new(skeleton, &vec![mode; skeleton.len()]).unwrap();
        let ghost = evaluation.with_modes(ghost_hierarchy.modes()).unwrap();
        let request = CurveRequest { bones: &plotted, ghost: Some(&ghost), ..Default::default() };
        let analysis = analyze(&evaluation, request, &options, &|_, _| {}, &never).unwrap();
        let (mut pose, mut ghost_pose) = (Pose::default(), Pose::default());
        for (sample, &time) in analysis.times.iter().enumerate() {
            pose.evaluate(skeleton, Some(clip), &hierarchy, time);
            ghost_pose.evaluate(skeleton, Some(clip), &ghost_hierarchy, time);
            for &bone in &plotted {
                let curves = analysis.curves_of(bone).unwrap();
                let label = format!("{}: bone {bone} at {time}", mode.id());
                assert_components(&curves.model[sample], &pose.model.model[bone], &format!("{label}, model"));
                assert_components(&curves.local[sample], &pose.local[bone].matrix(), &format!("{label}, local"));
                let ghost = &ghost_pose.model.model[bone];
                assert_components(&curves.ghost_model[sample], ghost, &format!("{label}, ghost"));
            }
        }
    }
}

/// Degenerate requests still give an answer: no bones, a clip of one key, no clip at all, curves of a bone that
/// is not there.
#[test]
fn empty_rigs_single_keys_rest_poses_and_missing_bones_scan() {
    let options = ScanOptions::default();
    let none = rig_of((Skeleton::new(vec![]).unwrap(), Clip::new(0, None, vec![], vec![])));
    let scanned = scan(&Evaluation::declared(&none, none.clips.first()), &options, &|_, _| {});
    assert_eq!((scanned.samples, scanned.bones.len()), (1, 0));
    let (skeleton, _) = growing_parent();
    let mut one_key = BoneTracks::new(0);
    let squashed = vec![Vec3::new(2.0, 1.0, 1.0)];
    one_key.scale = Some(Track::new(Arc::from([0.5].as_slice()), squashed, Interpolation::Step).unwrap());
    let rig = rig_of((skeleton, Clip::new(0, None, vec![one_key], vec![])));
    let evaluation = Evaluation::declared(&rig, rig.clips.first());
    let scanned = scan(&evaluation, &options, &|_, _| {});
    // The child under a constant (2, 1, 1) scale, turned 45°: sheared at every sample, judged once.
    assert_eq!(scanned.bones[1].flagged_samples, scanned.samples);
    let rest = scan(&evaluation.at_rest(), &options, &|_, _| {});
    assert_eq!((rest.samples, rest.bones[1].flagged_samples), (1, 0));
    // Curves asked for a bone the skeleton does not have (a selection kept across a reload) are left out.
    let request = CurveRequest { bones: &[1, 7], ghost: None, ..Default::default() };
    let never = AtomicBool::new(false);
    let analysis = analyze(&evaluation, request, &options, &|_, _| {}, &never).unwrap();
    assert_eq!(analysis.curves_of(1).map(|c| c.model.len()), Some(analysis.times.len()));
    assert!(analysis.curves_of(7).is_none());
}

/// The curves of a selection, judged down its chains only, are the curves of the whole-rig analysis exactly, and
/// so are the summaries of the bones on those chains: by bone (full inheritance) and by pose (other modes).
#[test]
fn curves_of_the_chains_alone_equal_those_of_the_whole_analysis() {
    let rig = stress_rig(30, 150, 5);
    let (skeleton, clip) = (&rig.skeleton, &rig.clips[0]);
    let options = ScanOptions { rate: 30.0, ..ScanOptions::default() };
    let plotted = [7, 16, 25];
    let never = AtomicBool::new(false);
    for modes in [skeleton.declared_modes(), vec![InheritMode::SegmentCompensate; skeleton.len()]] {
        let evaluation = Evaluation::new(&rig, Some(clip), &modes).unwrap();
        let analysis = |judged| {
            let request = CurveRequest { bones: &plotted, ghost: None, judged };
            analyze(&evaluation, request, &options, &|_, _| {}, &never).unwrap()
        };
        let (whole, chains) = (analysis(Judged::Every), analysis(Judged::CurveChains));
        assert_eq!(chains.times, whole.times);
        assert_eq!(chains.curves, whole.curves);
        let mut on_chains: Vec<usize> = plotted.to_vec();
        for &bone in &plotted {
            let mut at = bone;
            while let Some(parent) = skeleton.parent(at) {
                on_chains.push(parent);
                at = parent;
            }
        }
        for bone in on_chains {
            assert_eq!(chains.scan.bones[bone], whole.scan.bones[bone], "bone {bone}");
        }
    }
}

/// `max/min − 1` of the scale factors of `m`, from nalgebra's singular values (not bonescope's decomposition).
fn anisotropy(m: &DMat4) -> f64 {
    let cols = glam::DMat3::from_mat4(*m).to_cols_array();
    let singular = nalgebra::Matrix3::from_column_slice(&cols).singular_values();
    singular.max() / singular.min() - 1.0
}

#[test]
fn a_bone_is_non_uniform_beyond_its_tolerance_and_not_for_rounding() {
    // Constant scales 2e-3 and 5e-4 apart (each bone turning, so that its axes are not the parent's).
    let bones = vec![
        Bone::joint("squashed", None, Transform::from_trs(DVec3::ZERO, DQuat::IDENTITY, DVec3::new(1.0, 1.002, 1.0))),
        Bone::joint("rounded", None, Transform::from_trs(DVec3::ZERO, DQuat::IDENTITY, DVec3::new(1.0, 1.0005, 1.0))),
    ];
    let times: Arc<[f64]> = Arc::from([0.0, 1.0].as_slice());
    let turns = vec![Quat::IDENTITY, Quat::from_rotation_x(1.0)];
    let tracks = (0..2)
        .map(|bone| {
            let mut tracks = BoneTracks::new(bone);
            tracks.rotation = Some(Track::new(times.clone(), turns.clone(), Interpolation::Linear).unwrap());
            tracks
        })
        .collect();
    let rig = rig_of((Skeleton::new(bones).unwrap(), Clip::new(0, None, tracks, vec![])));
    let evaluation = Evaluation::declared(&rig, rig.clips.first());
    let listed = |tolerances: Tolerances| {
        let found = scan(&evaluation, &ScanOptions { rate: 4.0, tolerances }, &|_, _| {});
        found.bones.iter().map(|b| b.non_uniform_samples > 0).collect::<Vec<_>>()
    };
    assert_eq!(listed(Tolerances::default()), [true, false]);
    assert_eq!(listed(Tolerances { min_non_uniform: 1e-4, ..Tolerances::default() }), [true, true]);
    assert_eq!(listed(Tolerances { min_non_uniform: 3e-3, ..Tolerances::default() }), [false, false]);
}

/// Godot's mannequin scales legs and fingers by factors uniform to 1e-3 (exporter rounding), and a few bones by
/// more: a bone is listed non-uniform exactly where, at a sample where it is not stretched, nalgebra's singular
/// values of its model matrix lie more than 1e-3 apart.
#[test]
fn the_mannequin_s_non_uniform_bones_are_those_beyond_the_tolerance() {
    let path = common::corpus("realworld/godot_mannequiny.glb");
    let rig = match bonescope::import::load(&path) {
        Ok(rig) => rig,
        Err(e) => return eprintln!("skipping godot_mannequiny.glb: {e}"),
    };
    let options = ScanOptions::default();
    let tolerance = options.tolerances.min_non_uniform;
    let never = AtomicBool::new(false);
    let (mut listed, mut beside_the_tolerance) = (0, 0);
    for clip in &rig.clips {
        let evaluation = Evaluation::declared(&rig, Some(clip));
        let analysis = analyze(&evaluation, CurveRequest::default(), &options, &|_, _| {}, &never).unwrap();
        let mut largest = vec![0.0f64; rig.skeleton.len()];
        for (sample, &time) in analysis.times.iter().enumerate() {
            let pose = evaluation.pose_at(time);
            for (bone, model) in pose.model.model.iter().enumerate() {
                if !analysis.stretched_at(bone, sample) {
                    largest[bone] = largest[bone].max(anisotropy(model));
                }
            }
        }
        for (summary, &largest) in analysis.scan.bones.iter().zip(&largest) {
            let name = &rig.skeleton.bone(summary.index).name;
            // Rounding between the two decompositions is far below this margin.
            assert!((largest - tolerance).abs() > 1e-9, "{name} in {:?}: {largest} on the tolerance", clip.name);
            assert_eq!(summary.non_uniform_samples > 0, largest > tolerance, "{name} in {:?}: {largest}", clip.name);
            listed += usize::from(largest > tolerance);
            beside_the_tolerance += usize::from(largest > 1e-4 && largest <= tolerance);
        }
    }
    // Both kinds are there: bones listed, and bones the old tolerance of 1e-4 listed for rounding.
    assert!(listed > 0 && beside_the_tolerance > 0, "{listed} listed, {beside_the_tolerance} left out");
}
