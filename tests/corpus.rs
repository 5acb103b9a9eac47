//! One scene, one answer: Blender's own glTF-IO test scenes, each exported by Blender to glb, FBX and USD
//! (`../shared/corpus/blender-io`), read on each file's own clock, against Blender's evaluated bone heads
//! (`heads.json`: frame `f` of a scene at `f / fps` seconds, world heads in metres, Y up) and against each other.
//!
//! Blender's exporters do not all write the scene's timeline. Its glTF exporter writes each action on the scene's
//! clock, its USD exporter the timeline itself; its FBX exporter writes each action as a take that starts at 0,
//! whatever frame the action starts at, so an FBX take meets the other files once its start is aligned with theirs
//! (`diff --align start`). Where a scene animates through drivers, NLA strips or several armatures, a file may hold
//! no clip that plays the timeline: [`EXPORTS`] lists the clips that do, and says why the others are not there.

mod common;

use std::collections::BTreeMap;
use std::path::PathBuf;

use bonescope::diff::{Align, Clips, FileSide, diff_files};
use bonescope::eval::Evaluation;
use bonescope::import;
use bonescope::model::{Clip, ModeChoice, Rig};
use glam::DVec3;
use serde_json::Value;

/// The corpus folder beside the repository.
fn corpus() -> PathBuf {
    common::assets().join("../corpus/blender-io")
}

/// How far a head may lie from Blender's, metres: the files store single precision, and a chain of twenty bones
/// (RobotExpressive's fingers, whose USD rotations are floats) carries a rounding of each; 5.2e-6 m measured there.
const HEAD_TOLERANCE: f64 = 1e-5;

/// How far two exports of one scene may lie apart, a fraction of the rig's size.
const DIFF_TOLERANCE: f64 = 0.05 / 100.0;

/// Each scene's exports whose clip plays Blender's timeline: `(scene, [glb clip, FBX clip, USD clip])`, `None`
/// where the file holds no such clip (why, beside it). A USD export holds one clip, the stage's.
const EXPORTS: &[(&str, [Option<&str>; 3])] = &[
    ("00_extras", [Some("ArmatureAction"), Some("Armature|ArmatureAction"), Some("ArmatureAction")]),
    ("00_extras_action", [Some("ArmatureAction"), Some("Armature|ArmatureAction"), Some("ArmatureAction")]),
    ("00_parented_to_bone_and_animated", [Some("ArmatureAction"), Some("Armature|ArmatureAction"), Some("0")]),
    ("00_scene_export", [Some("ArmatureAction"), Some("Armature|ArmatureAction"), Some("0")]),
    // Two armatures, each with a bone `Bone`: Blender's heads name one of them.
    ("00_slide_with_driver", [None, None, None]),
    // Blender's glTF exporter failed on this scene (summary.json).
    ("03_skinned_cylinder", [None, Some("Root|SkeletonAnimation"), Some("0")]),
    // A driver over the action's range: the glTF and FBX exporters bake another motion than the timeline's.
    ("12_anim_range_driver", [None, None, Some("0")]),
    // The timeline plays NLA strips: no one action the glTF or FBX exporter wrote is it.
    ("26_nla_export_mode", [None, None, Some("0")]),
    ("31_interpolation_sampled", [Some("ArmatureAction"), Some("Armature|ArmatureAction"), Some("0")]),
    // Two armatures, each with a bone `Bone`: Blender's heads name one of them.
    ("30_baking_animation", [None, None, None]),
    // The timeline plays NLA strips: no one action the glTF or FBX exporter wrote is it.
    ("RobotExpressive", [None, None, Some("0")]),
    // The exporters write every action of the objects; the timeline keeps the armature still.
    ("XX_blender_global_test", [None, None, Some("0")]),
    // Drivers mix three actions on the timeline; the glTF and FBX exporters write each alone.
    ("00_drivers_multiple_actions", [None, None, Some("0")]),
];

/// Exports whose clip moves the armature alone where the scene's timeline moves other objects too: their heads are
/// Blender's, the other objects stand still (Blender's glTF and FBX exporters write each object's action as an
/// animation or a take of its own).
const ARMATURE_ONLY: &[(&str, &str)] = &[
    ("00_parented_to_bone_and_animated", "fbx"),
    ("00_scene_export", "glb"),
    ("00_scene_export", "fbx"),
    ("31_interpolation_sampled", "fbx"),
];

/// The formats, in the order of [`EXPORTS`].
const FORMATS: [&str; 3] = ["glb", "fbx", "usdc"];

/// Blender's evaluation of one scene: its rate and, per frame, each bone's head.
struct Heads {
    fps: f64,
    frames: BTreeMap<i64, BTreeMap<String, DVec3>>,
}

fn heads() -> BTreeMap<String, Heads> {
    let text = std::fs::read_to_string(corpus().join("heads.json")).expect("heads.json");
    let json: Value = serde_json::from_str(&text).unwrap();
    let point =
        |v: &Value| DVec3::from_slice(&v.as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect::<Vec<_>>());
    let scenes = json.as_object().unwrap().iter().map(|(scene, v)| {
        let frames = v["frames"].as_object().unwrap().iter().map(|(frame, bones)| {
            let bones = bones.as_object().unwrap().iter().map(|(name, head)| (name.clone(), point(head))).collect();
            (frame.parse().unwrap(), bones)
        });
        (scene.clone(), Heads { fps: v["fps"].as_f64().unwrap(), frames: frames.collect() })
    });
    scenes.collect()
}

/// One export of a scene with the clip that plays its timeline.
struct Export {
    file: PathBuf,
    rig: Rig,
    clip: usize,
}

impl Export {
    fn clip(&self) -> &Clip {
        &self.rig.clips[self.clip]
    }

    /// The export as one side of a comparison, on its clip.
    fn side(&self) -> FileSide<'_> {
        FileSide::new(self.file.display().to_string(), &self.rig, ModeChoice::Declared, Some(self.clip))
    }
}

/// The exports of `scene` that play its timeline, in the order of [`FORMATS`].
fn exports(scene: &str, clips: &[Option<&str>; 3]) -> Vec<(&'static str, Export)> {
    let mut found = Vec::new();
    for (format, clip) in FORMATS.into_iter().zip(clips) {
        let Some(clip) = clip else { continue };
        let file = corpus().join(format!("{scene}.{format}"));
        let rig = import::load(&file).unwrap_or_else(|e| panic!("{e}"));
        let clip = rig.clip_named(clip).map(|c| c.index).unwrap_or_else(|why| panic!("{}: {why}", file.display()));
        found.push((format, Export { file, rig, clip }));
    }
    found
}

/// How many seconds later than its clock says an export plays to meet the scene's timeline: an FBX take from its
/// first export's start (what `--align start` does), the others on their own clocks.
fn delay(format: &str, export: &Export, reference: &Export) -> f64 {
    if format == "fbx" { reference.clip().span().start - export.clip().span().start } else { 0.0 }
}

#[test]
fn every_export_that_plays_the_timeline_has_blenders_heads_at_f_over_fps() {
    let heads = heads();
    let listed: Vec<&str> = EXPORTS.iter().map(|(scene, _)| *scene).collect();
    assert!(heads.keys().all(|scene| listed.contains(&scene.as_str())), "every scene of heads.json is listed");
    let mut checked = 0;
    for (scene, clips) in EXPORTS {
        let blender = &heads[*scene];
        let found = exports(scene, clips);
        let Some((_, reference)) = found.iter().find(|(format, _)| *format != "fbx") else { continue };
        for (format, export) in &found {
            let evaluation =
                Evaluation::declared(&export.rig, Some(export.clip())).delayed(delay(format, export, reference));
            let skeleton = &export.rig.skeleton;
            for (frame, bones) in &blender.frames {
                let time = *frame as f64 / blender.fps;
                let model = evaluation.pose_at(time).model.model;
                for (name, head) in bones {
                    let bone = skeleton.find(name).or_else(|| skeleton.find(&name.replace('.', "_")));
                    let bone = bone.unwrap_or_else(|| panic!("{}: no bone `{name}`", export.file.display()));
                    let got = model[bone].w_axis.truncate();
                    let error = (got - *head).abs().max_element();
                    assert!(
                        error < HEAD_TOLERANCE,
                        "{} at frame {frame} ({time} s): `{name}` at {got}, Blender's at {head} ({error:e} m off)",
                        export.file.display()
                    );
                    checked += 1;
                }
            }
        }
    }
    assert!(checked > 300, "{checked} heads checked");
}

#[test]
fn two_exports_of_one_scene_differ_by_nothing_but_their_conventions() {
    let heads = heads();
    let mut compared = 0;
    for (scene, clips) in EXPORTS {
        let mut found = exports(scene, clips);
        let Some(reference) = found.iter().position(|(format, _)| *format != "fbx") else { continue };
        let reference = found.remove(reference);
        found.insert(0, reference);
        found.retain(|(format, _)| !ARMATURE_ONLY.contains(&(scene, format)));
        let reference = &found[0].1;
        for (i, (format_a, a)) in found.iter().enumerate() {
            for (format_b, b) in &found[i + 1..] {
                // B onto A's clock: each onto the timeline's, then back by A's own delay.
                let align = Align::Delay(delay(format_b, b, reference) - delay(format_a, a, reference));
                // At the scene's frames (and the files' keys): between frames each format interpolates its own way
                // (Blender's sampled interpolation is a key per frame in every file, stepped in the glTF export).
                let rate = heads[*scene].fps;
                let diff = diff_files(&a.side(), &b.side(), Clips::Chosen, &[], rate, align).unwrap();
                let [animation] = &diff.animations[..] else { panic!("one pair of clips") };
                let what = format!("{scene}: {format_a} against {format_b}");
                assert!(animation.samples > 1, "{what}: compared at {} times", animation.samples);
                let worst = animation.worst.max / animation.rig_size;
                assert!(worst < DIFF_TOLERANCE, "{what}: {:.4} % at {} s", 100.0 * worst, animation.worst.time);
                let (mut seen_a, mut seen_b) = (Vec::new(), Vec::new());
                for bone in &animation.bones {
                    assert!(
                        !seen_a.contains(&bone.a) && !seen_b.contains(&bone.b),
                        "{what}: `{}` paired twice",
                        bone.name
                    );
                    seen_a.push(bone.a);
                    seen_b.push(bone.b);
                }
                compared += 1;
            }
        }
    }
    assert_eq!(compared, 9, "every pair of exports that play one timeline");
}

#[test]
fn blenders_glb_and_usd_differ_in_the_armatures_frame_reported_once() {
    // Blender's USD exporter turns the armature a quarter about X against its glTF exporter's: the one difference
    // between the two files, reported as a convention, not as a motion.
    let found = exports("00_extras", &EXPORTS[0].1);
    let (glb, usd) = (&found[0].1, &found[2].1);
    let diff = diff_files(&glb.side(), &usd.side(), Clips::Chosen, &[], 60.0, Align::Clocks).unwrap();
    let animation = &diff.animations[0];
    assert!(animation.worst.max < 1e-12, "{:?}", animation.worst);
    let turned: Vec<&str> =
        animation.bones.iter().filter(|b| b.convention.is_some()).map(|b| b.name.as_str()).collect();
    assert_eq!(turned, ["Armature"]);
    let convention = animation.bones[0].convention.unwrap();
    assert!(
        (convention.turn_deg - 90.0).abs() < 1e-6 && (convention.axis.x.abs() - 1.0).abs() < 1e-9,
        "{convention:?}"
    );
    let pair = animation.bones.iter().find(|b| b.name == "Bone.001").expect("`Bone.001` pairs with USD's `Bone_001`");
    assert_eq!(pair.name_b.as_deref(), Some("Bone_001"));
}
