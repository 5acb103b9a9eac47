//! `bonescope fit` right by construction: bonescope's own evaluation under each of the nine modes, written as a
//! pose dump with noise at single precision, fits back to that mode on every bone; a dump that drops scale
//! entirely fits no mode and says so; bad dumps fail with one line.

mod common;

use std::path::Path;

use bonescope::eval::Evaluation;
use bonescope::export::DumpWriter;
use bonescope::fit::{DEFAULT_TOLERANCE, Fit, Residual, fit};
use bonescope::import::dump::{DumpHeader, Syntax};
use bonescope::import::{demo_rig, load_bytes};
use bonescope::model::{Choice, InheritMode, ModeChoice, Rig, affine};
use common::{asset, bonescope, json, load_asset};
use glam::{DMat3, DMat4};

/// Every bone's model matrix of `rig`'s first clip under `mode` at every frame.
fn poses(rig: &Rig, mode: InheritMode) -> (Vec<f64>, Vec<Vec<DMat4>>) {
    let evaluation = Evaluation::new(rig, rig.clips.first(), &vec![mode; rig.skeleton.len()]).unwrap();
    let times = evaluation.times(30.0);
    let mut evaluator = evaluation.evaluator();
    (times.clone(), times.iter().map(|&t| evaluator.evaluate(t).model.model.clone()).collect())
}

/// `m` with every number moved by up to one unit in the last place of single precision, pseudo-randomly.
fn noisy(m: &DMat4, seed: &mut u64) -> DMat4 {
    let mut numbers = m.to_cols_array();
    for n in numbers.iter_mut().take(15) {
        *seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        let unit = (*seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0;
        *n *= 1.0 + unit * f64::from(f32::EPSILON);
    }
    DMat4::from_cols_array(&numbers)
}

/// The dump of `poses` at `times`, read back.
fn dump_of(rig: &Rig, times: &[f64], poses: &[Vec<DMat4>], syntax: Syntax) -> Rig {
    let header = DumpHeader { unit: rig.unit, ..DumpHeader::default() };
    let mut writer = DumpWriter::new(Vec::new(), syntax, header, &rig.skeleton).unwrap();
    for (&time, pose) in times.iter().zip(poses) {
        writer.frame(time, pose).unwrap();
    }
    load_bytes(Path::new("noisy.dump"), &writer.finish().unwrap()).unwrap()
}

fn fitted(rig: &Rig, dump: &Rig) -> Fit {
    fit(&Evaluation::declared(rig, rig.clips.first()), dump, |size| DEFAULT_TOLERANCE * size).unwrap()
}

/// Every mode of `rig`, dumped with noise (JSON and CSV in turn), fits back on every bone, and matters on some.
fn fits_back(rig: &Rig, name: &str) {
    for (k, &mode) in InheritMode::ALL.iter().enumerate() {
        let (times, poses) = poses(rig, mode);
        let mut seed = k as u64 + 1;
        let noisy_poses: Vec<Vec<DMat4>> =
            poses.iter().map(|pose| pose.iter().map(|m| noisy(m, &mut seed)).collect()).collect();
        let syntax = if k % 2 == 0 { Syntax::Json } else { Syntax::Csv };
        let found = fitted(rig, &dump_of(rig, &times, &noisy_poses, syntax));
        for bone in &found.bones {
            assert!(bone.fits.contains(&ModeChoice::Mode(mode)), "{name} {mode}: `{}` fits {:?}", bone.name, bone.fits);
        }
        assert!(found.fits.contains(&ModeChoice::Mode(mode)), "{name} {mode}: {:?}", found.fits);
        assert!(found.miss.is_none());
        let mattering = found.bones.iter().filter(|b| !b.any).count();
        assert!(mattering > 0, "{name} {mode}: the mode matters somewhere");
        // Where the mode matters, a mode that moves the bone further than the tolerance is not said to fit.
        assert!(found.fits.len() < ModeChoice::ALL.len(), "{name} {mode}: {:?}", found.fits);
    }
}

#[test]
fn every_mode_of_the_demo_rig_fits_back() {
    fits_back(&demo_rig(), "demo");
}

#[test]
fn every_mode_of_the_stretchy_rigs_fits_back() {
    fits_back(&load_asset("blender/stretchy_full.glb"), "stretchy_full.glb");
    fits_back(&load_asset("blender/stretchy_noinherit.fbx"), "stretchy_noinherit.fbx");
}

#[test]
fn modes_that_differ_on_the_demo_rig_tell_apart() {
    // The demo's forearm bends under a squashing upper arm: full shears it, componentwise and segment-compensate
    // do not, and each dump names its own mode alone among those three.
    let rig = demo_rig();
    for mode in [InheritMode::Full, InheritMode::Componentwise, InheritMode::SegmentCompensate] {
        let (times, poses) = poses(&rig, mode);
        let found = fitted(&rig, &dump_of(&rig, &times, &poses, Syntax::Json));
        let forearm = found.bones.iter().find(|b| b.name == "forearm").unwrap();
        let others = [InheritMode::Full, InheritMode::Componentwise, InheritMode::SegmentCompensate];
        for other in others.into_iter().filter(|&o| o != mode) {
            assert!(!forearm.fits.contains(&ModeChoice::Mode(other)), "{mode}: {:?}", forearm.fits);
        }
    }
}

/// The rigid chain of `rig`'s first clip at every frame: `G = G_parent · T · R`, every scale dropped.
fn scale_dropped(rig: &Rig) -> (Vec<f64>, Vec<Vec<DMat4>>) {
    let evaluation = Evaluation::declared(rig, rig.clips.first());
    let times = evaluation.times(30.0);
    let mut evaluator = evaluation.evaluator();
    let poses = times
        .iter()
        .map(|&t| {
            let local = &evaluator.evaluate(t).local;
            let mut rigid: Vec<DMat4> = Vec::with_capacity(local.len());
            for (i, l) in local.iter().enumerate() {
                let own = affine(DMat3::from_quat(l.rotation), l.translation);
                rigid.push(rig.skeleton.parent(i).map_or(own, |p| rigid[p] * own));
            }
            rigid
        })
        .collect();
    (times, poses)
}

#[test]
fn a_dump_that_drops_scale_fits_no_mode_and_says_so() {
    for rig in [demo_rig(), load_asset("blender/stretchy_full.glb")] {
        let (times, poses) = scale_dropped(&rig);
        let found = fitted(&rig, &dump_of(&rig, &times, &poses, Syntax::Json));
        assert!(found.fits.is_empty(), "{:?}", found.fits);
        let miss = found.miss.expect("a first miss");
        assert_eq!(miss.residual, Residual::ScaleDropped, "{miss:?}");
    }
}

#[test]
fn the_command_gates_on_the_fit_and_refuses_bad_dumps() {
    let folder = tempfile::tempdir().unwrap();
    let source = asset("blender/stretchy_full.glb");
    let source = source.to_str().unwrap();
    let rig = load_asset("blender/stretchy_full.glb");
    let dropped = folder.path().join("dropped.dump.json");
    let (times, poses) = scale_dropped(&rig);
    let mut writer = DumpWriter::new(Vec::new(), Syntax::Json, DumpHeader::default(), &rig.skeleton).unwrap();
    times.iter().zip(&poses).for_each(|(&t, p)| writer.frame(t, p).unwrap());
    std::fs::write(&dropped, writer.finish().unwrap()).unwrap();
    let out = bonescope(&["fit", source, dropped.to_str().unwrap()]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(1), "{text}");
    assert!(text.contains("no mode fits every bone") && text.contains("scale dropped"), "{text}");

    // bonescope's own dump, written by `inspect --format dump-csv`, fits as JSON with exit 0.
    let own = folder.path().join("own.dump.csv");
    let written = bonescope(&["inspect", source, "--format", "dump-csv", "--inherit", "componentwise"]);
    std::fs::write(&own, &written.stdout).unwrap();
    let report = json(&bonescope(&["fit", source, own.to_str().unwrap(), "--format", "json"]));
    let fits: Vec<&str> = report["fits"].as_array().unwrap().iter().map(|f| f.as_str().unwrap()).collect();
    assert!(fits.contains(&ModeChoice::Mode(InheritMode::Componentwise).id()), "{fits:?}");

    let bad = folder.path().join("bad.dump.json");
    let text = std::fs::read_to_string(&own).unwrap().replacen("space=world", "space=sideways", 1);
    std::fs::write(&bad, text).unwrap();
    let out = bonescope(&["fit", source, bad.to_str().unwrap()]);
    let error = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2));
    assert_eq!(error.lines().count(), 1, "{error}");
    assert!(error.contains("bad.dump.json: line 1: the space `sideways` is not one of world, local"), "{error}");
}

#[test]
fn a_dump_in_centimetres_fits_its_source_in_metres() {
    // A runtime that reads the file in centimetres puts the unit above the roots: S(100)·W for every bone.
    let rig = load_asset("blender/stretchy_full.glb");
    let (times, poses) = poses(&rig, InheritMode::Componentwise);
    let centimetres = DMat4::from_scale(glam::DVec3::splat(100.0));
    let scaled: Vec<Vec<DMat4>> = poses.iter().map(|pose| pose.iter().map(|m| centimetres * *m).collect()).collect();
    let header = DumpHeader { unit: "cm".parse().ok(), ..DumpHeader::default() };
    let mut writer = DumpWriter::new(Vec::new(), Syntax::Csv, header, &rig.skeleton).unwrap();
    times.iter().zip(&scaled).for_each(|(&t, p)| writer.frame(t, p).unwrap());
    let dump = load_bytes(Path::new("cm.dump.csv"), &writer.finish().unwrap()).unwrap();
    let found = fitted(&rig, &dump);
    assert!(found.fits.contains(&ModeChoice::Mode(InheritMode::Componentwise)), "{:?}", found.fits);
    assert!((found.rig_size / 100.0 - 2.05).abs() < 0.01, "measured in the dump's unit: {}", found.rig_size);
}

#[test]
fn a_dump_is_a_file_like_any_other_for_inspect_scan_and_diff() {
    let folder = tempfile::tempdir().unwrap();
    let source = asset("blender/stretchy_full.glb");
    let source = source.to_str().unwrap();
    let dump = folder.path().join("stretchy.dump.json");
    let written = bonescope(&["inspect", source, "--anim", "squash_stretch", "--format", "dump"]);
    assert!(written.status.success());
    std::fs::write(&dump, &written.stdout).unwrap();
    let dump = dump.to_str().unwrap();
    // At the dump's times (every frame, the source's keys among them) the two agree to single precision; the clip
    // pairs by the name the dump gives it.
    let diff = json(&bonescope(&["diff", source, dump, "--rate", "0", "--format", "json"]));
    let animations = diff["animations"].as_array().unwrap();
    assert_eq!(animations.len(), 1, "{diff}");
    assert!(animations[0]["worst"]["max"].as_f64().unwrap() < 1e-5, "{}", animations[0]["worst"]);
    // Read as a rig (full inheritance), the dump shears where the source does.
    let scan = json(&bonescope(&["scan", dump, "--format", "json"]));
    let stretched: Vec<&str> =
        scan[0]["animations"][0]["stretched"].as_array().unwrap().iter().map(|b| b["name"].as_str().unwrap()).collect();
    assert_eq!(stretched, ["forearm", "hand", "neck", "head"], "{scan}");
    let inspect = json(&bonescope(&["inspect", dump, "--time", "1", "--format", "json"]));
    assert_eq!(inspect["samples"][0]["bones"].as_array().unwrap().len(), 10, "{inspect}");
}

#[test]
fn the_readmes_dump_is_what_inspect_writes() {
    // The README shows `fit` on a dump bonescope wrote of Blender's rig under `componentwise` (as Unreal composes):
    // the committed file is what the command writes today.
    let source = asset("blender/stretchy_full.glb").display().to_string();
    let args = ["inspect", &source, "--anim", "squash_stretch", "--inherit", "componentwise", "--format", "dump"];
    let run = bonescope(&args);
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    let committed = Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/dumps/stretchy_full_componentwise.dump.json");
    let committed = std::fs::read_to_string(committed).unwrap();
    let version = |text: &str| text.replacen(env!("CARGO_PKG_VERSION"), "VERSION", 1);
    assert_eq!(
        version(&String::from_utf8(run.stdout).unwrap()),
        version(&committed),
        "regenerate with: bonescope {}",
        args.join(" ")
    );
}
