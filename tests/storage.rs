//! The stretch-quaternion storage report (`analysis::storage`) on rigs whose answer is known.

use std::sync::Arc;

use bonescope::analysis::ScanOptions;
use bonescope::analysis::storage::{StorageOptions, StorageReport, storage_report};
use bonescope::eval::Evaluation;
use bonescope::import::demo_rig;
use bonescope::math::decompose;
use bonescope::model::{
    Bone, BoneTracks, Clip, InheritMode, Interpolation, Mesh, Rig, Skeleton, Skin, Track, Transform,
};
use glam::{DMat3, DMat4, DQuat, DVec3, Vec3};

/// A parent held at scale (2, 1, 1) for two keys, and a child 1 along X turned 45° about Z that compensates its
/// parent's scale (Maya's segment scale compensate), skinning one vertex 1 along each of its X and Y axes.
///
/// The child's model matrix is `T(2, 0, 0)·Rz(45°)` (its offset scaled, its axes not), its parent's `diag(2, 1, 1)`:
/// the local matrix an exporter writes, `W_parent⁻¹·W`, is `T(1, 0, 0)·diag(½, 1, 1)·Rz(45°)`, which shears.
fn compensating_child() -> Rig {
    let rest =
        |translation: DVec3, turn: f64| Transform::from_trs(translation, DQuat::from_rotation_z(turn), DVec3::ONE);
    let bones = vec![
        Bone::joint("parent", None, Transform::IDENTITY),
        Bone {
            node: 1,
            inherit: InheritMode::SegmentCompensate,
            ..Bone::joint("child", Some(0), rest(DVec3::X, std::f64::consts::FRAC_PI_4))
        },
    ];
    let skeleton = Skeleton::new(bones).unwrap();
    let mut tracks = BoneTracks::new(0);
    let times: Arc<[f64]> = Arc::from([0.0, 1.0].as_slice());
    tracks.scale = Some(Track::new(times, vec![Vec3::new(2.0, 1.0, 1.0); 2], Interpolation::Linear).unwrap());
    let child_rest = skeleton.rest_model_matrices()[1];
    let positions = [DVec3::X, DVec3::Y].map(|p| child_rest.transform_point3(p).as_vec3()).to_vec();
    let mesh = Mesh {
        name: "two points".into(),
        bone: 0,
        skin: Some(0),
        joints: vec![[0, 0, 0, 0]; 2],
        weights: vec![[1.0, 0.0, 0.0, 0.0]; 2],
        positions,
        ..Mesh::default()
    };
    Rig {
        clips: vec![Clip::new(0, Some("held".into()), vec![tracks], vec![])],
        skins: vec![Skin { name: None, joints: vec![1], inverse_bind: vec![child_rest.inverse()], node_bind: None }],
        meshes: vec![mesh],
        skeleton,
        ..Rig::default()
    }
}

fn report(rig: &Rig, modes: &[InheritMode], rate: f64) -> StorageReport {
    let options = StorageOptions { rate, ..StorageOptions::default() };
    storage_report(&Evaluation::new(rig, rig.clips.first(), modes).unwrap(), &options)
}

#[test]
fn a_compensating_child_needs_the_stretch_channel() {
    let rig = compensating_child();
    let r = report(&rig, &rig.skeleton.declared_modes(), 0.0);
    // Two frames (the keys), two bones; the child is stretched at both.
    assert_eq!((r.frames, r.bones), (2, 2));
    assert_eq!(r.marked.len(), 1);
    assert_eq!((r.marked[0].name.as_str(), r.marked[0].stretched_frames), ("child", 2));
    // 2 frames × 2 bones × 40 bytes; plus 2 frames × 1 marked bone × 16 bytes.
    assert_eq!((r.bytes_trs, r.bytes_with_stretch), (160, 192));
    // The stretch-quaternion recomposition is exact up to f32 rounding of the stored components.
    assert!(r.reconstruction.bone_axes.max < 1e-6, "{:?}", r.reconstruction);
    assert!(r.reconstruction.vertices.unwrap().max < 1e-6);
    // Dropping U: the runtime rebuilds diag(2,1,1)·T(1,0,0)·R·K instead of diag(2,1,1)·T(1,0,0)·A with
    // A = diag(½,1,1)·Rz(45°) = R·U·K·Uᵀ. At the probes 0, X, Y, Z the error is |diag(2,1,1)·(R·K − A)·p|.
    let a = DMat3::from_diagonal(DVec3::new(0.5, 1.0, 1.0))
        * DMat3::from_quat(DQuat::from_rotation_z(std::f64::consts::FRAC_PI_4));
    let parts = decompose(&DMat4::from_mat3(a));
    let rk = DMat3::from_quat(parts.rotation) * DMat3::from_diagonal(parts.sign * parts.scale);
    let error = |p: DVec3| (DMat3::from_diagonal(DVec3::new(2.0, 1.0, 1.0)) * (rk - a) * p).length();
    let [x, y, z] = [error(DVec3::X), error(DVec3::Y), error(DVec3::Z)];
    // Two frames, two bones, four probes each: the parent and the child's origin and Z probe are exact.
    let (max, mean) = (x.max(y), (x + y) * 2.0 / 16.0);
    assert!(x.max(y) > 0.3 && z < 1e-12, "{x} {y} {z}");
    assert!((r.trs_only.bone_axes.max - max).abs() < 1e-6, "{:?} vs {max}", r.trs_only);
    assert!((r.trs_only.bone_axes.mean - mean).abs() < 1e-6, "{:?} vs {mean}", r.trs_only);
    // The vertices sit at the child's X and Y probes.
    let vertices = r.trs_only.vertices.unwrap();
    assert!((vertices.max - max).abs() < 1e-6 && (vertices.mean - (x + y) / 2.0).abs() < 1e-6, "{vertices:?}");
}

#[test]
fn under_full_inheritance_the_runtime_needs_no_stretch_channel() {
    // The same clip with the child inheriting fully: its model matrix shears, but T·R·K locals chained with full
    // inheritance reproduce it, so nothing is marked and both runtimes are exact up to rounding.
    let rig = compensating_child();
    let r = report(&rig, &[InheritMode::Full; 2], 0.0);
    assert!(r.marked.is_empty());
    assert_eq!(r.bytes_trs, r.bytes_with_stretch);
    assert!(r.trs_only.bone_axes.max < 1e-6 && r.trs_only == r.reconstruction);
}

#[test]
fn the_demo_arm_under_compensation_marks_the_forearm() {
    let rig = demo_rig();
    let r = report(&rig, &[InheritMode::SegmentCompensate; 4], ScanOptions::default().rate);
    let marked: Vec<&str> = r.marked.iter().map(|m| m.name.as_str()).collect();
    assert_eq!(marked, ["forearm"]);
    assert!(r.reconstruction.bone_axes.max < 1e-5);
    assert!(r.trs_only.bone_axes.max > 100.0 * r.reconstruction.bone_axes.max);
    assert!(r.trs_only.vertices.unwrap().max > 1e-3);
    let full = report(&rig, &[InheritMode::Full; 4], ScanOptions::default().rate);
    assert!(full.marked.is_empty());
}

#[test]
fn a_rig_without_a_clip_or_meshes_reports_its_rest_pose() {
    let mut rig = demo_rig();
    rig.clips.clear();
    rig.meshes.clear();
    let r = report(&rig, &rig.skeleton.declared_modes(), 60.0);
    assert_eq!((r.frames, r.bones, r.bytes_trs), (1, 4, 160));
    assert!(r.reconstruction.vertices.is_none());
}
