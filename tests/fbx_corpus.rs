//! ufbx's public test corpus (`../shared/assets/fbx-ufbx-corpus`, its README) as bonescope's FBX acceptance suite:
//! 1. every FBX loads, except that a file named `_fail` may be refused (cleanly: an error naming the file, never a
//!    panic and never a bare "Failed to load");
//! 2. every OBJ the authoring tool exported of a scene equals bonescope's evaluation of the same frame (`NAME_N.obj`:
//!    frame N at the file's frame rate; `NAME.obj`: the pose stored in the file), for every FBX version and encoding
//!    of that scene, within 1e-4 of the model's size (the OBJ's `ufbx:` markers loosen it), except the references
//!    that show what bonescope does not evaluate (listed by category with the reason, never skipped silently) and the
//!    known differences listed below with their reasons. A known difference that starts to match fails the test too,
//!    so the list only shrinks.
//!
//! The measure is the symmetric nearest-vertex distance (Hausdorff distance between the vertex sets) over the
//! reference's bounding-box diagonal: the OBJs do not always keep the FBX's vertex order.

mod common;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use bonescope::eval::skinning::skin_meshes;
use bonescope::eval::{Hierarchy, Pose};
use bonescope::import::{self, Options, Space};
use bonescope::model::Rig;
use common::{asset, hausdorff, size};
use glam::DVec3;
use rayon::prelude::*;

fn corpus() -> PathBuf {
    asset("fbx-ufbx-corpus")
}

/// Files of the corpus with extension `ext`, sorted.
fn files(ext: &str) -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(corpus())
        .expect("../shared/assets/fbx-ufbx-corpus is there")
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e.eq_ignore_ascii_case(ext)))
        .collect();
    files.sort();
    files
}

fn stem(path: &Path) -> String {
    path.file_stem().unwrap().to_string_lossy().into_owned()
}

/// References that show what bonescope does not evaluate, by name: (pattern in the OBJ's name, category, reason).
const OUT_OF_SCOPE: &[(&str, &str, &str)] = &[
    ("_subsurf", "subdivision surfaces", "the OBJ is the subdivided surface; bonescope draws the cage"),
    ("_crease", "subdivision surfaces", "creases only matter to a subdivided surface"),
    ("_cache_", "geometry caches", "point caches are external files (not in the corpus) and not skeletal animation"),
    ("marvelous_", "geometry caches", "Marvelous Designer cloth is a point cache"),
    ("nurbs", "NURBS", "NURBS surfaces and curves are not meshes; bonescope does not tessellate them"),
    ("zbrush_", "ZBrush/Revit scenes", "ZBrush polygroup and vertex-colour scenes, no skeleton"),
    ("revit_", "ZBrush/Revit scenes", "Revit architectural scenes, no skeleton"),
    ("blender_340_y_up", "other axes", "Blender wrote this OBJ in other axes than its FBX"),
    ("blender_340_z_up", "other axes", "Blender wrote this OBJ in other axes than its FBX"),
    ("synthetic_vertex_gaps", "unused vertices", "the OBJ leaves out vertices no face uses; the FBX keeps them"),
    ("_obj", "OBJ-reader tests", "ufbx's tests of its own OBJ reader: an OBJ as input, no FBX scene"),
    (
        "lefthanded",
        "left-handed axes",
        "references for ufbx's conversion to left-handed axes, which bonescope does not do",
    ),
    ("_noex_", "no extrapolation", "references for ufbx's option to evaluate curves without their extrapolation"),
    ("maya_poses_bind", "stored poses", "the mesh in one of the file's stored poses, not an animation frame"),
];

/// References whose frame is not `NAME_N` of the scene's default take (ufbx's tests name the take and time):
/// (OBJ name, FBX name suffix after `_VERSION_FORMAT`, take name, seconds).
const NAMED_TAKES: &[(&str, &str, &str, f64)] = &[
    ("blender_279_sausage_base_0", "", "Base", 0.0),
    ("blender_279_sausage_spin_15", "", "Spin", 15.0 / 24.0),
    ("blender_279_sausage_wiggle_20", "", "Wiggle", 20.0 / 24.0),
    // The takes of these files start at frames 1, 20 and 40; ufbx's test gives the file times.
    ("maya_game_sausage_wiggle_10", "_wiggle", "", 10.0 / 24.0),
    ("maya_game_sausage_wiggle_18", "_wiggle", "", 18.0 / 24.0),
    ("maya_game_sausage_spin_7", "_spin", "", 27.0 / 24.0),
    ("maya_game_sausage_spin_15", "_spin", "", 35.0 / 24.0),
    ("maya_game_sausage_deform_8", "_deform", "", 48.0 / 24.0),
    ("maya_game_sausage_deform_15", "_deform", "", 55.0 / 24.0),
];

/// Comparisons known to differ today, by OBJ name and FBX name (empty: every FBX of the scene), with the reason.
const KNOWN_DIFFERENCES: &[(&str, &str, &str)] = &[
    ("maya_instanced_skin_0", "maya_instanced_skin_6100_ascii", INSTANCED_6100),
    ("maya_instanced_skin_0", "maya_instanced_skin_6100_binary", INSTANCED_6100),
    ("maya_instanced_skin_4", "maya_instanced_skin_6100_ascii", INSTANCED_6100),
    ("maya_instanced_skin_4", "maya_instanced_skin_6100_binary", INSTANCED_6100),
    ("maya_instanced_skin_8", "maya_instanced_skin_6100_ascii", INSTANCED_6100),
    ("maya_instanced_skin_8", "maya_instanced_skin_6100_binary", INSTANCED_6100),
    ("maya_anim_layers_over_acc_orders_18", "", UFBX_DIFFERS),
    ("maya_axes_anim_5", "", UFBX_DIFFERS),
    ("maya_axes_anim_8", "", UFBX_DIFFERS),
];

/// Measured (ufbx 0.23.1): bonescope's vertices equal ufbx's own `evaluate_scene` with skinning to 7e-7 of the
/// model at the reference's frame, and both differ from the OBJ by 0.1 of the model at every frame near it: the gap
/// lies in ufbx's reading of these files (an animation-layer stack over several rotation orders; a Z-up scene),
/// which bonescope takes as it is, not in bonescope's evaluation, frame convention or comparison.
const UFBX_DIFFERS: &str = "ufbx's own evaluation differs from the OBJ as much as bonescope's (which equals ufbx's)";

/// ufbx's own test skips these: in FBX 6.1 the skin is attached to the first instance only.
const INSTANCED_6100: &str = "FBX 6.1 attaches the skin to one instance only (ufbx's own test skips 6100 files)";

/// One OBJ reference: which scene, which frame, and what its markers say.
struct Reference {
    obj: PathBuf,
    /// The scene's name (the FBX files are `SCENE_VERSION_FORMAT.fbx`, or `SCENE_VERSION_FORMAT<suffix>.fbx`).
    scene: String,
    suffix: &'static str,
    when: When,
    /// The OBJ's vertices, in file units.
    positions: Vec<DVec3>,
    /// The skinned result is also moved by the mesh node's transform (`ufbx:transform_skin`).
    transform_skin: bool,
    /// Relative tolerance after the markers.
    tolerance: f64,
}

/// Which pose of the scene a reference shows.
#[derive(Clone, Copy)]
enum When {
    /// `NAME.obj`: the pose stored in the file.
    Stored,
    /// `NAME_N.obj`: frame N of the default take at the file's frame rate.
    Frame(u32),
    /// A take whose name contains the given text (the default take when empty), at a time in seconds.
    Take(&'static str, f64),
}

impl Reference {
    fn read(obj: &Path, fbx_stems: &[String]) -> Option<Reference> {
        let name = stem(obj);
        let named = NAMED_TAKES.iter().find(|t| t.0 == name);
        let (scene, suffix, when) = if let Some(&(_, suffix, take, seconds)) = named {
            let scene = fbx_stems
                .iter()
                .find_map(|s| scene_of(s.strip_suffix(suffix).filter(|_| !suffix.is_empty())?))
                .or_else(|| name.rsplitn(3, '_').nth(2))?;
            (scene.to_owned(), suffix, When::Take(take, seconds))
        } else if has_fbx(&name, fbx_stems) {
            (name, "", When::Stored)
        } else {
            let (base, n) = name.rsplit_once('_')?;
            let n: u32 = n.parse().ok()?;
            has_fbx(base, fbx_stems).then(|| (base.to_owned(), "", When::Frame(n)))?
        };
        let text = String::from_utf8_lossy(&std::fs::read(obj).unwrap()).into_owned();
        let mut positions = Vec::new();
        let (mut transform_skin, mut scale, mut absolute) = (false, 1.0, None);
        for line in text.lines() {
            if let Some(v) = line.strip_prefix("v ") {
                let v: Vec<f64> = v.split_whitespace().take(3).map(|x| x.parse().unwrap()).collect();
                positions.push(DVec3::new(v[0], v[1], v[2]));
            } else if let Some(marker) = line.strip_prefix("# ufbx:") {
                let marker = marker.trim();
                transform_skin |= marker == "transform_skin";
                if let Some(s) = marker.strip_prefix("position_scale=") {
                    scale = s.parse().unwrap();
                }
                if let Some(t) = marker.strip_prefix("tolerance=") {
                    absolute = Some(t.parse::<f64>().unwrap());
                }
            }
        }
        let size = size(&positions);
        // ufbx's runner scales both sides by `position_scale` before an absolute comparison, so a scale below 1
        // allows 1/S times the error; `tolerance` is that comparison's absolute bound in file units.
        let tolerance = (DEFAULT_TOLERANCE / scale).max(absolute.map_or(0.0, |t| t / size));
        Some(Reference { obj: obj.to_owned(), scene, suffix, when, positions, transform_skin, tolerance })
    }

    fn name(&self) -> String {
        stem(&self.obj)
    }

    /// Whether `fbx_stem` is a file of this reference's scene.
    fn shows(&self, fbx_stem: &str) -> bool {
        let stem = if self.suffix.is_empty() { Some(fbx_stem) } else { fbx_stem.strip_suffix(self.suffix) };
        stem.and_then(scene_of) == Some(self.scene.as_str())
    }
}

/// 1e-4 of the model's size, as the issue and ufbx's runner (absolute 1e-4 on centimetre models of ~1 unit) ask.
const DEFAULT_TOLERANCE: f64 = 1e-4;

/// Whether some FBX of the corpus is `name_VERSION_FORMAT`.
fn has_fbx(name: &str, fbx_stems: &[String]) -> bool {
    fbx_stems.iter().any(|s| scene_of(s) == Some(name))
}

/// `NAME` of `NAME_VERSION_FORMAT`.
fn scene_of(fbx_stem: &str) -> Option<&str> {
    let (rest, format) = fbx_stem.rsplit_once('_')?;
    let (name, version) = rest.rsplit_once('_')?;
    let numeric = !version.is_empty() && version.bytes().all(|b| b.is_ascii_digit());
    (numeric && matches!(format, "ascii" | "binary")).then_some(name)
}

/// The clip and time of `when` in bonescope's rig of `fbx`: the take ufbx evaluates (the one named, else the stack
/// the file marks current), at the file's frame rate, on the file's own clock (as ufbx's tests give the times).
fn clip_time(fbx: &Path, rig: &Rig, when: When) -> (Option<usize>, f64) {
    let bytes = std::fs::read(fbx).unwrap();
    let scene = ufbx::load_memory(&bytes, import::fbx_load_opts(&Options { space: Space::File }, bytes.len())).unwrap();
    let fps = scene.settings.frames_per_second;
    let fps = if fps.is_finite() && fps > 0.0 { fps } else { 30.0 };
    let default_layer = scene.anim.layers.first().map(|l| l.element.element_id);
    let is_default = |s: &ufbx::AnimStack| s.anim.layers.first().map(|l| l.element.element_id) == default_layer;
    let (take, seconds) = match when {
        When::Stored => return (None, 0.0),
        When::Frame(frame) => ("", f64::from(frame) / fps),
        When::Take(take, seconds) => (take, seconds),
    };
    let stack = scene
        .anim_stacks
        .iter()
        .position(|s| if take.is_empty() { is_default(s) } else { s.element.name.contains(take) })
        .filter(|&i| i < rig.clips.len());
    (stack, seconds)
}

/// Every vertex of every mesh of `fbx` as bonescope evaluates `reference`'s pose, in the file's own space.
fn evaluated(fbx: &Path, rig: &Rig, reference: &Reference) -> Vec<DVec3> {
    let (clip, time) = clip_time(fbx, rig, reference.when);
    let hierarchy = Hierarchy::new(&rig.skeleton, &rig.skeleton.declared_modes()).unwrap();
    let mut pose = Pose::default();
    pose.evaluate(&rig.skeleton, clip.map(|c| &rig.clips[c]), &hierarchy, time);
    skin_meshes(rig, &pose.model.model, &pose.morph).concat()
}

struct Comparison {
    obj: String,
    fbx: String,
    /// Relative error, tolerance.
    error: f64,
    tolerance: f64,
    transform_skin: bool,
}

#[test]
fn every_fbx_loads_and_matches_the_authoring_tools_geometry() {
    let fbx_files = files("fbx");
    let fbx_stems: Vec<String> = fbx_files.iter().map(|p| stem(p)).collect();
    assert!(fbx_files.len() >= 680, "expected ufbx's corpus, found {} FBX files", fbx_files.len());

    // 1. Loading.
    let loaded: Vec<(String, Result<Rig, String>)> = fbx_files
        .par_iter()
        .map(|path| {
            let result = import::load_with(path, &Options { space: Space::File }).map_err(|e| e.to_string());
            (stem(path), result)
        })
        .collect();
    let mut load_failures = Vec::new();
    let mut counts = BTreeMap::<&str, usize>::new();
    for (name, result) in &loaded {
        let meant_to_fail = name.contains("_fail");
        match result {
            Ok(_) => {
                *counts.entry(if meant_to_fail { "_fail files that load" } else { "files that load" }).or_default() += 1
            }
            Err(e) if meant_to_fail => {
                *counts.entry("_fail files refused").or_default() += 1;
                if e.ends_with("Failed to load") {
                    load_failures.push(format!("{name}: refused without ufbx's account: {e}"));
                }
            }
            Err(e) => load_failures.push(format!("{name}: {e}")),
        }
    }
    println!("loading {} FBX files: {counts:?}", loaded.len());
    let rigs: BTreeMap<&str, &Rig> =
        loaded.iter().filter_map(|(name, r)| Some((name.as_str(), r.as_ref().ok()?))).collect();

    // 2. Geometry.
    let mut out_of_scope = BTreeMap::<(&str, &str), Vec<String>>::new();
    let mut references = Vec::new();
    let mut unmatched = Vec::new();
    for obj in files("obj") {
        let name = stem(&obj);
        if let Some(&(_, category, reason)) = OUT_OF_SCOPE.iter().find(|(pattern, ..)| name.contains(pattern)) {
            out_of_scope.entry((category, reason)).or_default().push(name);
        } else if let Some(reference) = Reference::read(&obj, &fbx_stems) {
            references.push(reference);
        } else {
            unmatched.push(name);
        }
    }
    let comparisons: Vec<Comparison> = references
        .iter()
        .flat_map(|r| fbx_files.iter().filter(move |f| r.shows(&stem(f))).map(move |f| (r, f)))
        .filter_map(|(reference, fbx)| {
            let rig = rigs.get(stem(fbx).as_str())?;
            let ours = evaluated(fbx, rig, reference);
            let error = hausdorff(&ours, &reference.positions) / size(&reference.positions);
            Some(Comparison {
                obj: reference.name(),
                fbx: stem(fbx),
                error,
                tolerance: reference.tolerance,
                transform_skin: reference.transform_skin,
            })
        })
        .collect();

    let known = |c: &Comparison| {
        KNOWN_DIFFERENCES.iter().find(|(obj, fbx, _)| *obj == c.obj && (fbx.is_empty() || *fbx == c.fbx))
    };
    let mut by_tool = BTreeMap::<&str, [usize; 3]>::new();
    let mut regressions = Vec::new();
    let mut fixed = Vec::new();
    for c in &comparisons {
        let within = c.error <= c.tolerance;
        let tool = c.obj.split('_').next().unwrap_or("other");
        let row = by_tool.entry(tool).or_default();
        row[0] += 1;
        row[if within { 1 } else { 2 }] += 1;
        let marker = if c.transform_skin { " (transform_skin)" } else { "" };
        match (within, known(c)) {
            (false, None) => {
                regressions.push(format!("{} vs {}: {:.2e} > {:.0e}{marker}", c.obj, c.fbx, c.error, c.tolerance))
            }
            (true, Some(_)) => fixed.push(format!("{} vs {}: {:.2e} now matches", c.obj, c.fbx, c.error)),
            (false, Some((.., reason))) => println!("known: {} vs {}: {:.2e} ({reason})", c.obj, c.fbx, c.error),
            (true, None) => {}
        }
    }
    println!("\nOBJ comparisons by authoring tool (compared / within tolerance / not):");
    for (tool, [n, ok, bad]) in &by_tool {
        println!("  {tool:<14} {n:>4} {ok:>4} {bad:>4}");
    }
    let (n, ok) = (comparisons.len(), comparisons.iter().filter(|c| c.error <= c.tolerance).count());
    println!("  {:<14} {n:>4} {ok:>4} {:>4}", "all", n - ok);
    println!("\nout of scope (OBJ references not compared):");
    for ((category, reason), names) in &out_of_scope {
        println!("  {category}: {} ({reason})", names.len());
    }

    assert!(unmatched.is_empty(), "OBJs without an FBX of the same scene and not listed out of scope: {unmatched:?}");

    assert!(load_failures.is_empty(), "files that must load:\n{}", load_failures.join("\n"));
    assert!(regressions.is_empty(), "{} comparisons differ:\n{}", regressions.len(), regressions.join("\n"));
    assert!(fixed.is_empty(), "known differences that now match (remove them from the list):\n{}", fixed.join("\n"));
}

#[test]
fn synthetic_bind_to_root_shows_the_stored_pose_not_frame_0() {
    // ufbx's synthetic file connects its skin deformer and clusters to the root node as well as to the mesh (ufbx
    // ignores those connections, with a warning: its own test checks only that). Each cluster's `Transform` is
    // the mesh node relative to the cluster's bone (ufbx's `mesh_node_to_bone`), and the skin is dual quaternion.
    // Its OBJ shows the pose the file stores, `joint2` turned 49.5459° (Maya's current frame when it saved, between
    // frames 4 and 5 of the take, which turns the joint from 64.20274° at frame 1 to -108.0638° at frame 40):
    // bonescope's stored pose matches it to rounding. Frame 0 of the take (the curve held at its first key) is
    // another pose: the same skin, worked by hand with `joint2` at 64.20274°, is 0.08465 of the model away.
    let fbx = corpus().join("synthetic_bind_to_root_7700_ascii.fbx");
    let rig = import::load_with(&fbx, &Options { space: Space::File }).unwrap();
    let reference = common::obj_positions(&corpus().join("synthetic_bind_to_root.obj"));
    let joint2 = rig.skeleton.bones().iter().position(|b| b.name == "joint2").unwrap();
    let error_at = |clip: Option<usize>| {
        let hierarchy = Hierarchy::new(&rig.skeleton, &rig.skeleton.declared_modes()).unwrap();
        let mut pose = Pose::default();
        pose.evaluate(&rig.skeleton, clip.map(|c| &rig.clips[c]), &hierarchy, 0.0);
        let turned = pose.local[joint2].rotation.to_axis_angle().1.to_degrees();
        let vertices = skin_meshes(&rig, &pose.model.model, &pose.morph).concat();
        (turned, hausdorff(&vertices, &reference) / size(&reference))
    };
    let (turned, stored) = error_at(None);
    assert!((turned - 49.5459027633167).abs() < 1e-9 && stored < 1e-6, "stored pose: {turned}°, {stored:e}");
    let (turned, frame_0) = error_at(Some(0));
    assert!((turned - 64.20274).abs() < 1e-4 && (frame_0 - 0.08465).abs() < 1e-4, "frame 0: {turned}°, {frame_0}");
}
