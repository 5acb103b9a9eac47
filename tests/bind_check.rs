//! The bind check on real files: skins bound under an axis conversion (glTF Z-up → Y-up), in centimetres under a
//! 0.01 conversion (Maya), or beside a moved mesh node are fine; skins whose stored pose is not their bind pose
//! (Blender's current frame, a Max or Maya scene posed after binding) are posed, not broken; a joint whose bind
//! matrix alone was moved breaks the skin.

mod common;

use bonescope::analysis::{BindCheck, BindTolerance, check_bind};
use bonescope::eval::{Evaluation, bind_model_matrices};
use bonescope::model::Rig;
use common::load_asset;
use glam::{DMat4, DQuat, DVec3};

fn checked(rig: &Rig) -> BindCheck {
    check_bind(&Evaluation::declared(rig, rig.clips.first()), &BindTolerance::default())
}

fn names(mismatches: &[bonescope::analysis::BindMismatch]) -> Vec<&str> {
    mismatches.iter().map(|m| m.name.as_str()).collect()
}

#[test]
fn skins_bound_at_rest_are_neither_broken_nor_posed() {
    for file in [
        "gltf-khronos/cesium_man.gltf",
        "gltf-khronos/Fox.glb",
        "blender/stretchy_full.glb",
        "fbx-ufbx-data/maya_mixed_inherit_mode_7700_ascii.fbx",
        "fbx-proanimationbank/locomotions.fbx",
    ] {
        assert_eq!(checked(&load_asset(file)), BindCheck::default(), "{file}");
    }
}

#[test]
fn skins_stored_in_another_pose_than_their_bind_are_posed_not_broken() {
    // Blender writes an FBX's node transforms at its current frame, where the forearm is turned 20° from where the
    // mesh was bound (the hand follows it); the .glb of the same rig stores the bind pose as its rest. 3ds Max's
    // scene was posed after binding (its mesh node moved too, which its skin ignores); Maya's dual-quaternion
    // demo twists joint2 170° and moves it 1 cm, with no animation. Their children (where the skin has any) still
    // agree with them: posed, not bound elsewhere.
    for (file, posed, angle) in [
        ("blender/stretchy_full.fbx", vec!["forearm"], 20.0),
        ("fbx-ufbx-data/max_transformed_skin_7500_binary.fbx", vec!["Bone002", "Bone003", "Bone004"], 21.69),
        ("fbx-ufbx-corpus/maya_dual_quaternion_7500_ascii.fbx", vec!["joint2"], 170.0),
    ] {
        let check = checked(&load_asset(file));
        assert!(check.broken.is_empty(), "{file}: {check:?}");
        assert_eq!(names(&check.posed), posed, "{file}");
        let widest = check.posed.iter().map(|m| m.gap.angle_deg).fold(0.0, f64::max);
        assert!((widest - angle).abs() < 0.01, "{file}: {widest}°");
        // None of their clips passes through the bind pose.
        assert_eq!(check.bind_frame, None, "{file}");
    }
}

#[test]
fn a_joint_whose_bind_matrix_alone_moved_breaks_the_skin() {
    let mut rig = load_asset("gltf-khronos/cesium_man.gltf");
    // Move joint 5's bind (node16, above node17) 5 cm and 10° in the skin's bind space (a copy of the file's rig,
    // changed here): node17, bound where it was, is left behind by it and witnesses it.
    let joint = 5;
    let moved =
        DMat4::from_rotation_translation(DQuat::from_rotation_x(10f64.to_radians()), DVec3::new(0.0, 0.05, 0.0));
    rig.skins[0].inverse_bind[joint] = (rig.skins[0].inverse_bind[joint].inverse() * moved).inverse();
    let check = checked(&rig);
    assert_eq!(names(&check.broken), [rig.skeleton.bone(rig.skins[0].joints[joint]).name.as_str()]);
    let gap = check.broken[0].gap;
    assert!((gap.distance - 0.05).abs() < 1e-6 && (gap.angle_deg - 10.0).abs() < 1e-4, "{gap:?}");
    assert!(check.posed.is_empty(), "{check:?}");
}

#[test]
fn the_bind_pose_is_drawn_where_the_character_is() {
    // Cesium Man's skin lives under a Z-up → Y-up node: its bind pose in model space is its rest pose, standing.
    let rig = load_asset("gltf-khronos/cesium_man.gltf");
    let bind = bind_model_matrices(&rig);
    let rest = rig.skeleton.rest_model_matrices();
    for &joint in &rig.skins[0].joints {
        let (b, r) = (bind[joint].w_axis.truncate(), rest[joint].w_axis.truncate());
        assert!(b.distance(r) < 1e-5, "{}: {b} vs {r}", rig.skeleton.bone(joint).name);
    }
}
