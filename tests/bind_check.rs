//! The bind check on real files: skins bound under an axis conversion (glTF Z-up → Y-up), in centimetres under a
//! 0.01 conversion (Maya), or beside a moved mesh node are fine and not flagged; a joint bound elsewhere is.

mod common;

use bonescope::analysis::{BindTolerance, bind_mismatches};
use bonescope::eval::{Hierarchy, bind_model_matrices};
use bonescope::model::Rig;
use common::load_asset;
use glam::{DMat4, DQuat, DVec3};

fn flagged(rig: &Rig) -> Vec<String> {
    let hierarchy = Hierarchy::new(&rig.skeleton, &rig.skeleton.declared_modes());
    bind_mismatches(rig, &hierarchy, &BindTolerance::default()).into_iter().map(|m| m.name).collect()
}

#[test]
fn skins_bound_at_rest_are_not_flagged_whatever_their_bind_space() {
    for file in [
        "gltf-khronos/cesium_man.gltf",
        "gltf-khronos/Fox.glb",
        "blender/stretchy_full.glb",
        "fbx-ufbx-data/maya_mixed_inherit_mode_7700_ascii.fbx",
        "fbx-proanimationbank/locomotions.fbx",
    ] {
        assert_eq!(flagged(&load_asset(file)), Vec::<String>::new(), "{file}");
    }
}

#[test]
fn a_stored_pose_that_is_not_the_bind_pose_is_flagged() {
    // Blender writes an FBX's node transforms at its current frame: there the forearm is turned 20° from where
    // the mesh was bound (the .glb of the same rig stores the bind pose as its rest, and is not flagged).
    assert_eq!(flagged(&load_asset("blender/stretchy_full.fbx")), ["forearm", "hand"]);
}

#[test]
fn a_joint_bound_elsewhere_is_flagged_alone() {
    let mut rig = load_asset("gltf-khronos/cesium_man.gltf");
    // Move one joint's bind 5 cm and 10° in the skin's bind space (a copy of the file's rig, changed here).
    let joint = 7;
    let moved =
        DMat4::from_rotation_translation(DQuat::from_rotation_x(10f64.to_radians()), DVec3::new(0.0, 0.05, 0.0));
    rig.skins[0].inverse_bind[joint] = (rig.skins[0].inverse_bind[joint].inverse() * moved).inverse();
    let bone = rig.skins[0].joints[joint];
    assert_eq!(flagged(&rig), [rig.skeleton.bone(bone).name.clone()]);
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
