//! Helpers shared by the integration tests: the shared assets, the `bonescope` command, the app under egui_kittest,
//! and the geometry comparisons with the authoring tools' own. (Each test crate uses some of them.)
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use bonescope::model::Rig;
use glam::DVec3;
use rayon::prelude::*;
use serde_json::Value;

/// Every shared asset with animation or skins, as the bake tests take them (the FBX corpus and the validator's suite
/// have their own tests).
pub const ANIMATED: &[&str] = &[
    "blender/stretchy_full.glb",
    "blender/stretchy_noinherit.glb",
    "blender/stretchy_full.fbx",
    "blender/stretchy_noinherit.fbx",
    "blender/stretchy_full.bvh",
    "gltf-khronos/Fox.glb",
    "gltf-khronos/SimpleSkin.gltf",
    "gltf-khronos/box_animated.gltf",
    "gltf-khronos/cesium_man.gltf",
    "gltf-khronos/interpolation_test.gltf",
    "gltf-khronos/rigged_simple.gltf",
    "fbx-proanimationbank/locomotions.fbx",
    "fbx-proanimationbank/skeleton.fbx",
    "fbx-proanimationbank/walk.fbx",
    "fbx-proanimationbank/crossarms.fbx",
    "fbx-ufbx-data/maya_mixed_inherit_mode_7700_ascii.fbx",
    "fbx-ufbx-data/maya_anim_no_inherit_scale_7700_ascii.fbx",
    "fbx-ufbx-data/maya_scale_no_inherit_6100_ascii.fbx",
    "fbx-ufbx-data/maya_scale_no_inherit_7700_ascii.fbx",
    "fbx-ufbx-data/maya_scale_no_inherit_step_7700_ascii.fbx",
    "fbx-ufbx-data/maya_static_no_inherit_scale_7700_ascii.fbx",
    "fbx-ufbx-data/maya_anim_interpolation_7700_ascii.fbx",
    "fbx-ufbx-data/maya_advanced_skinned_pivot_7700_binary.fbx",
    "fbx-ufbx-data/max7_skin_5000_binary.fbx",
    "fbx-ufbx-data/max_transformed_skin_7500_binary.fbx",
    "fbx-ufbx-data/blender_293_half_skinned_7400_binary.fbx",
    "bvh/cmu_12_01_walk.bvh",
    "bvh/bvh_test2.bvh",
    "bvh/standard_skeleton.bvh",
    "bvh/rotation_first_root.bvh",
    "bvh/full_precision_frame_time.bvh",
];

/// The shared assets' folder beside the repository.
pub fn assets() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/assets")
}

/// A file of the shared assets (`FOLDER/NAME`).
pub fn asset(path: &str) -> PathBuf {
    assets().join(path)
}

/// A file of the shared corpus (`FOLDER/NAME`: whole sets of files, `blender-io/`, `realworld/`).
pub fn corpus(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/corpus").join(path)
}

/// A file of the shared assets (`FOLDER/NAME`), loaded; panics with the import error.
pub fn load_asset(path: &str) -> Rig {
    bonescope::import::load(&asset(path)).unwrap_or_else(|e| panic!("{e}"))
}

/// The Python with Blender's module that `BONESCOPE_BLENDER_PYTHON` names (`.ci/run` installs it pinned); `None`,
/// saying that the calling test is skipped and why, where there is none.
pub fn blender_python() -> Option<PathBuf> {
    let hint = "a Python 3.11 with Blender's module (`pip install \"bpy==4.5.*\"` in a virtual environment; .ci/run \
                does) to judge bonescope by Blender";
    python_with("BONESCOPE_BLENDER_PYTHON", "bpy", hint)
}

/// The Python with Pixar's USD module that `BONESCOPE_USD_PYTHON` names (`.ci/run` installs `usd-core` pinned);
/// `None`, saying that the calling test is skipped and why, where there is none.
pub fn usd_python() -> Option<PathBuf> {
    let hint = "a Python with Pixar's USD (`pip install \"usd-core==26.11\"` in a virtual environment; .ci/run does) to \
                judge bonescope by usd-core";
    python_with("BONESCOPE_USD_PYTHON", "pxr", hint)
}

/// The Python that the environment variable `variable` names, if it imports `module`.
fn python_with(variable: &str, module: &str, hint: &str) -> Option<PathBuf> {
    let python = std::env::var_os(variable).map(PathBuf::from);
    let imports = |python: &PathBuf| {
        Command::new(python).args(["-c", &format!("import {module}")]).output().is_ok_and(|o| o.status.success())
    };
    let found = python.filter(imports);
    if found.is_none() {
        eprintln!("skipped: set {variable} to {hint}");
    }
    found
}

/// The `bonescope` command run with `args`.
pub fn bonescope(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_bonescope")).args(args).output().expect("bonescope runs")
}

/// The JSON a successful command printed.
pub fn json(output: &Output) -> Value {
    assert!(output.status.success(), "stderr: {}", String::from_utf8_lossy(&output.stderr));
    serde_json::from_slice(&output.stdout).expect("valid JSON")
}

/// Processes pending input and lets the background analysis it started finish; the UI has not caught up yet (see
/// [`settle`]).
#[cfg(feature = "gui")]
pub fn finish_analysis(harness: &mut egui_kittest::Harness<'static, bonescope::app::BonescopeApp>) {
    harness.step();
    harness.state_mut().settle();
}

/// [`finish_analysis`], then lets the UI catch up. (A bare `run()` while the analysis runs would keep stepping until
/// kittest gives up.) A frame may start more work (the Layers panel checks the bind of an edited document the frame
/// after the edit), so this waits again whenever the UI is still busy, however slow the machine.
#[cfg(feature = "gui")]
pub fn settle(harness: &mut egui_kittest::Harness<'static, bonescope::app::BonescopeApp>) {
    for _ in 0..8 {
        finish_analysis(harness);
        if harness.try_run().is_ok() {
            return;
        }
    }
    panic!("the app still repaints after 8 rounds of finished background work");
}

/// The vertex positions (`v` lines) of a Wavefront OBJ file.
pub fn obj_positions(path: &Path) -> Vec<DVec3> {
    let text = std::fs::read_to_string(path).unwrap();
    text.lines()
        .filter_map(|l| l.strip_prefix("v "))
        .map(|l| {
            let v: Vec<f64> = l.split_whitespace().map(|x| x.parse().unwrap()).collect();
            DVec3::new(v[0], v[1], v[2])
        })
        .collect()
}

/// The diagonal of the bounding box.
pub fn size(points: &[DVec3]) -> f64 {
    let lo = points.iter().fold(DVec3::INFINITY, |a, &p| a.min(p));
    let hi = points.iter().fold(DVec3::NEG_INFINITY, |a, &p| a.max(p));
    (hi - lo).length()
}

/// The largest distance from a point of either set to the nearest point of the other (the Hausdorff distance);
/// infinite when one set is empty and the other not.
pub fn hausdorff(a: &[DVec3], b: &[DVec3]) -> f64 {
    let one_way = |from: &[DVec3], to: &[DVec3]| {
        from.par_iter()
            .map(|p| to.iter().map(|q| p.distance_squared(*q)).fold(f64::INFINITY, f64::min))
            .reduce(|| 0.0, f64::max)
            .sqrt()
    };
    if a.is_empty() || b.is_empty() {
        return if a.len() == b.len() { 0.0 } else { f64::INFINITY };
    }
    one_way(a, b).max(one_way(b, a))
}
