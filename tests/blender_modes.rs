//! The Blender modes evaluate as Blender does whatever format carries the rig: a bone's offset is the pose it was
//! bound in (Blender's rest), not the pose an FBX file's nodes happen to hold.

mod common;

use std::process::Command;

use bonescope::eval::{Evaluation, bind_pose};
use bonescope::math::shear_deg;
use bonescope::model::{InheritMode, Rig};
use common::{blender_python, load_asset};
use glam::{DMat3, DMat4};
use serde_json::Value;

const FILES: [&str; 2] = ["blender/stretchy_full.glb", "blender/stretchy_full.fbx"];

/// The forearm's model matrix under every bone's `mode` at every key time of the first clip.
fn forearm(rig: &Rig, mode: InheritMode) -> Vec<(f64, DMat4)> {
    let evaluation = Evaluation::new(rig, rig.clips.first(), &vec![mode; rig.skeleton.len()]).unwrap();
    let forearm = rig.skeleton.find("forearm").expect("a forearm");
    evaluation.key_times().into_iter().map(|t| (t, evaluation.pose_at(t).model.model[forearm])).collect()
}

#[test]
fn fix_shear_leaves_the_forearm_as_full_inheritance_in_every_format() {
    // Blender 4.5 (the test below asks it where it is installed): Fix Shear orthogonalises the parent's matrix
    // times the bone's rest offset; the upper arm's squash lies along the forearm's rest axes, so nothing shears
    // there and the forearm moves as under Full, in the glTF and in the FBX. The FBX's nodes hold a pose 20° from
    // the bind pose: taken as the offset, it sheared the parent's matrix and Fix Shear took 4.5° of stretch away.
    for file in FILES {
        let rig = load_asset(file);
        for ((time, full), (_, fixed)) in
            forearm(&rig, InheritMode::Full).into_iter().zip(forearm(&rig, InheritMode::BlenderFixShear))
        {
            // To the bind pose's single precision (the FBX's bind matrices are read back through an inverse).
            assert!(fixed.abs_diff_eq(full, 1e-6), "{file} at {time}: {fixed} against {full}");
        }
    }
}

#[test]
fn an_fbx_node_posed_away_from_its_bind_pose_rests_in_the_bind_pose() {
    let rig = load_asset("blender/stretchy_full.fbx");
    let forearm = rig.skeleton.find("forearm").unwrap();
    let (rest, bound) = (rig.skeleton.bone(forearm).rest.rotation, bind_pose(&rig)[forearm].rotation);
    assert!(rest.angle_between(bound).to_degrees() > 10.0, "the file's node holds another pose than its bind pose");
}

#[test]
fn blender_itself_plays_the_forearm_the_same_under_full_and_fix_shear() {
    // The oracle of the test above, asked of Blender: every bone's world matrix under FIX_SHEAR equals FULL's for
    // the forearm at every frame of both files (to Blender's single precision).
    let Some(python) = blender_python() else { return };
    let folder = tempfile::tempdir().unwrap();
    let script = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/blender/fix_shear.py");
    for file in FILES {
        let out = folder.path().join("played.json");
        let run = Command::new(&python).arg(&script).arg(common::asset(file)).arg(&out).output().unwrap();
        assert!(run.status.success(), "{file}: {}", String::from_utf8_lossy(&run.stderr));
        let played: Value = serde_json::from_slice(&std::fs::read(&out).unwrap()).unwrap();
        let matrix = |frame: &Value| {
            let entries: Vec<f64> = frame["forearm"].as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).collect();
            DMat4::from_cols_slice(&entries)
        };
        let (full, fixed) = (played["FULL"].as_array().unwrap(), played["FIX_SHEAR"].as_array().unwrap());
        assert!(full.len() > 10 && full.len() == fixed.len(), "{file}: {} frames", full.len());
        let mut sheared = false;
        for (frame, (a, b)) in full.iter().zip(fixed).enumerate() {
            let (a, b) = (matrix(a), matrix(b));
            assert!(a.abs_diff_eq(b, 1e-5), "{file} frame {frame}: FULL {a} FIX_SHEAR {b}");
            sheared |= shear_deg(&DMat3::from_mat4(a)) > 10.0;
        }
        assert!(sheared, "{file}: the forearm shears under both");
    }
}
