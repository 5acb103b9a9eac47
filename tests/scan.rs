//! Whole-clip scans on a clip whose answer is known by hand.

use std::sync::Arc;
use std::sync::atomic::{AtomicUsize, Ordering};

use bonescope::analysis::{ScanOptions, Subject, sample_times, scan};
use bonescope::eval::Hierarchy;
use bonescope::model::{Bone, BoneTracks, Clip, InheritMode, Interpolation, Skeleton, Track, Transform};
use glam::{DQuat, DVec3, Vec3};

/// A parent whose X scale grows linearly from 1 at t = 0 to 2 at t = 1, and a child turned 45° about Z.
fn growing_parent() -> (Skeleton, Clip) {
    let child_rest = Transform::from_trs(DVec3::X, DQuat::from_rotation_z(45f64.to_radians()), DVec3::ONE);
    let bones = vec![
        Bone { name: "parent".into(), node: 0, parent: None, rest: Transform::IDENTITY, inherit: InheritMode::Full },
        Bone { name: "child".into(), node: 1, parent: Some(0), rest: child_rest, inherit: InheritMode::Full },
    ];
    let mut tracks = BoneTracks::new(0);
    let times: Arc<[f64]> = Arc::from([0.0, 1.0].as_slice());
    tracks.scale = Some(Track::new(times, vec![Vec3::ONE, Vec3::new(2.0, 1.0, 1.0)], Interpolation::Linear).unwrap());
    (Skeleton::new(bones).unwrap(), Clip::new(0, Some("grow".into()), vec![tracks], vec![]))
}

#[test]
fn sample_times_are_keys_plus_the_rate_grid() {
    let (_, clip) = growing_parent();
    let times = sample_times(Some(&clip), 4.0);
    assert_eq!(times, vec![0.0, 0.25, 0.5, 0.75, 1.0]);
    assert_eq!(sample_times(None, 60.0), vec![0.0]);
}

#[test]
fn the_child_is_stretched_from_the_first_sample_after_zero_and_worst_at_the_end() {
    let (skeleton, clip) = growing_parent();
    let options = ScanOptions { rate: 10.0, ..ScanOptions::default() };
    let calls = AtomicUsize::new(0);
    let last = AtomicUsize::new(0);
    let progress = |done: usize, total: usize| {
        assert!(done <= total && total == 11);
        calls.fetch_add(1, Ordering::Relaxed);
        last.fetch_max(done, Ordering::Relaxed);
    };
    let hierarchy = Hierarchy::new(&skeleton, &skeleton.declared_modes());
    let result = scan(Subject::clip(&skeleton, Some(&clip)), &hierarchy, &options, &progress);
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
    let (skeleton, clip) = growing_parent();
    let hierarchy = Hierarchy::new(&skeleton, &[InheritMode::Full, InheritMode::SegmentCompensate]);
    let result = scan(Subject::clip(&skeleton, Some(&clip)), &hierarchy, &ScanOptions::default(), &|_, _| {});
    assert!(result.bones.iter().all(|b| !b.stretched()));
}

#[test]
fn stretched_spans_run_from_the_first_flagged_sample_to_the_end() {
    let (skeleton, clip) = growing_parent();
    let hierarchy = Hierarchy::new(&skeleton, &skeleton.declared_modes());
    let options = ScanOptions { rate: 10.0, ..ScanOptions::default() };
    let never = std::sync::atomic::AtomicBool::new(false);
    let request = bonescope::analysis::CurveRequest { bones: &[1], ghost: None };
    let analysis = bonescope::analysis::analyze(
        Subject::clip(&skeleton, Some(&clip)),
        &hierarchy,
        request,
        &options,
        &|_, _| {},
        &never,
    )
    .unwrap();
    assert_eq!(analysis.stretched_spans(Some(1)), vec![(0.1, 1.0)]);
    assert_eq!(analysis.stretched_spans(None), vec![(0.1, 1.0)]);
    assert!(analysis.stretched_spans(Some(0)).is_empty());
    assert_eq!(analysis.curves_of(1).unwrap().model.len(), 11);
}
