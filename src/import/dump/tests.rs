//! Dumps written from the demo rig under every mode read back as rigs that give back every matrix (the oracle is
//! the source's own evaluation, not the reader), in every layout; bad dumps fail with one line naming the place.

use std::path::Path;

use glam::DMat4;

use super::*;
use crate::eval::Evaluation;
use crate::export::DumpWriter;
use crate::import::{demo_rig, load_bytes};
use crate::model::InheritMode;

/// Single-precision keys, a few products deep, on a rig about 2.5 m across.
const EXACT: f64 = 2e-5;

/// `rig`'s first clip under `mode` at every frame: the times and each time's model matrices.
fn evaluated(rig: &Rig, mode: InheritMode) -> (Vec<f64>, Vec<Vec<DMat4>>) {
    let evaluation = Evaluation::new(rig, rig.clips.first(), &vec![mode; rig.skeleton.len()]).unwrap();
    let times = evaluation.times(30.0);
    let mut evaluator = evaluation.evaluator();
    let poses = times.iter().map(|&t| evaluator.evaluate(t).model.model.clone()).collect();
    (times, poses)
}

/// The dump of `poses` at `times` written by [`DumpWriter`].
fn written(rig: &Rig, syntax: Syntax, header: DumpHeader, times: &[f64], poses: &[Vec<DMat4>]) -> Vec<u8> {
    let mut writer = DumpWriter::new(Vec::new(), syntax, header, &rig.skeleton).unwrap();
    for (&time, pose) in times.iter().zip(poses) {
        writer.frame(time, pose).unwrap();
    }
    writer.finish().unwrap()
}

/// The largest difference between `poses` and the dump rig's own evaluation (full inheritance) at `times`.
fn largest_difference(dump: &Rig, times: &[f64], poses: &[Vec<DMat4>]) -> f64 {
    let evaluation = Evaluation::declared(dump, dump.clips.first());
    let mut evaluator = evaluation.evaluator();
    let mut largest = 0.0f64;
    for (&time, pose) in times.iter().zip(poses) {
        let got = &evaluator.evaluate(time).model.model;
        for (a, b) in got.iter().zip(pose) {
            largest = largest.max((*a - *b).to_cols_array().iter().fold(0.0, |m, d| m.max(d.abs())));
        }
    }
    largest
}

#[test]
fn a_dump_of_every_mode_reads_back_as_its_matrices() {
    let rig = demo_rig();
    for &mode in InheritMode::ALL {
        let (times, poses) = evaluated(&rig, mode);
        for syntax in [Syntax::Json, Syntax::Csv] {
            let header = DumpHeader { unit: rig.unit, clip: Some("stretch".into()), ..DumpHeader::default() };
            let bytes = written(&rig, syntax, header, &times, &poses);
            let dump = load_bytes(Path::new("demo.dump"), &bytes).unwrap_or_else(|e| panic!("{mode} {syntax:?}: {e}"));
            assert_eq!(dump.skeleton.len(), rig.skeleton.len());
            assert!(dump.skeleton.bones().iter().all(|b| b.inherit == InheritMode::Full), "no modes of its own");
            assert_eq!(dump.clips[0].name.as_deref(), Some("stretch"));
            let difference = largest_difference(&dump, &times, &poses);
            assert!(difference < EXACT, "{mode} {syntax:?}: {difference}");
        }
    }
}

#[test]
fn local_row_major_z_up_dumps_read_as_the_same_pose() {
    // Under componentwise the forearm's local matrix relative to its squashed parent shears at every time: kept.
    let rig = demo_rig();
    let (times, poses) = evaluated(&rig, InheritMode::Componentwise);
    let to_z_up = UpAxis::Z.to_y_up().inverse();
    let parents: Vec<Option<usize>> = rig.skeleton.bones().iter().map(|b| b.parent).collect();
    let local: Vec<Vec<DMat4>> = poses
        .iter()
        .map(|pose| {
            let parent_of = |i: usize| parents[i].map_or(to_z_up.inverse(), |p| pose[p]);
            (0..pose.len()).map(|i| parent_of(i).inverse() * pose[i]).collect()
        })
        .collect();
    let header =
        DumpHeader { space: DumpSpace::Local, order: MatrixOrder::RowMajor, up: Some(UpAxis::Z), ..Default::default() };
    let bytes = written(&rig, Syntax::Json, header, &times, &local);
    let dump = load_bytes(Path::new("local.dump.json"), &bytes).unwrap();
    assert!(dump.clips[0].tracks().iter().any(|t| t.stretch.is_some()), "a sheared local keeps its stretch");
    assert!(largest_difference(&dump, &times, &poses) < EXACT);
    assert!(dump.notes.iter().any(|n| n.contains("Z up")), "{:?}", dump.notes);
}

#[test]
fn bones_listed_children_first_are_put_parents_first() {
    let json = r#"{"format": "bonescope-pose-dump", "version": 1, "space": "world", "order": "column-major",
        "bones": [{"name": "child", "parent": "root"}, {"name": "root"}],
        "frames": [{"time": 0, "matrices": [[1,0,0,0, 0,1,0,0, 0,0,1,0, 1,2,3,1], [1,0,0,0, 0,1,0,0, 0,0,1,0, 1,0,0,1]]}]}"#;
    let rig = load_bytes(Path::new("swapped.dump.json"), json.as_bytes()).unwrap();
    let names: Vec<&str> = rig.skeleton.bones().iter().map(|b| b.name.as_str()).collect();
    assert_eq!(names, ["root", "child"]);
    assert!(rig.skeleton.bone(1).rest.translation.abs_diff_eq(DVec3::new(0.0, 2.0, 3.0), 1e-12));
}

/// The one-line error of loading `text` as `name`.
fn error(name: &str, text: &str) -> String {
    let error = load_bytes(Path::new(name), text.as_bytes()).unwrap_err().to_string();
    assert!(!error.contains('\n'), "one line: {error}");
    error
}

const IDENTITY: &str = "1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,0,1";

fn json(bones: &str, frames: &str) -> String {
    format!(
        r#"{{"format": "bonescope-pose-dump", "version": 1, "space": "world", "order": "column-major",
        "bones": [{bones}], "frames": [{frames}]}}"#
    )
}

#[test]
fn bad_json_dumps_name_the_file_and_the_place() {
    let bones = r#"{"name": "a"}, {"name": "b", "parent": "a"}"#;
    let frame = |t: &str, m: &str| format!(r#"{{"time": {t}, "matrices": [[{IDENTITY}], [{m}]]}}"#);
    let ragged = error("r.dump.json", &json(bones, &frame("0", "1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,0")));
    assert!(ragged.starts_with("r.dump.json: frames[0].matrices[1]: invalid length 15"), "{ragged}");
    let short = error("s.dump.json", &json(bones, r#"{"time": 0, "matrices": [[1,0,0,0,0,1,0,0,0,0,1,0,0,0,0,1]]}"#));
    assert_eq!(short, "s.dump.json: frames[0].matrices: 1 matrices for 2 bones");
    let unknown = error(
        "u.dump.json",
        &json(r#"{"name": "a", "parent": "x"}, {"name": "b", "parent": "y"}"#, &frame("0", IDENTITY)),
    );
    assert_eq!(unknown, "u.dump.json: parents that no bone is named: `x`, `y`");
    let times = format!("{},{}", frame("0.5", IDENTITY), frame("0.5", IDENTITY));
    let repeated = error("t.dump.json", &json(bones, &times));
    assert_eq!(repeated, "t.dump.json: frames[1].time: the time 0.5 does not come after the one before it (0.5)");
    let singular =
        json(bones, &format!(r#"{{"time": 0, "matrices": [[0,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,0,1], [{IDENTITY}]]}}"#));
    let singular = error("z.dump.json", &singular);
    assert_eq!(singular, "z.dump.json: frames[0].matrices[1]: the parent `a`'s matrix is singular at t = 0");
    let transposed = error("o.dump.json", &json(bones, &frame("0", "1,0,0,2, 0,1,0,0, 0,0,1,0, 0,0,0,1")));
    assert!(transposed.starts_with("o.dump.json: frames[0].matrices[1]: not an affine matrix"), "{transposed}");
    let looped = error(
        "l.dump.json",
        &json(r#"{"name": "a", "parent": "b"}, {"name": "b", "parent": "a"}"#, &frame("0", IDENTITY)),
    );
    assert_eq!(looped, "l.dump.json: bones[0]: `a` is its own ancestor");
    let version = error("v.dump.json", &json(bones, &frame("0", IDENTITY)).replace("\"version\": 1", "\"version\": 2"));
    assert!(version.starts_with("v.dump.json: format: version 2 of the pose dump format"), "{version}");
}

#[test]
fn bad_csv_dumps_name_the_file_and_the_line() {
    let head = "# bonescope-pose-dump 1; space=world; order=column-major\ntime,bone,parent,m0,m1,m2,m3,m4,m5,m6,m7,m8,m9,m10,m11,m12,m13,m14,m15\n";
    let row = |t: &str, bone: &str, parent: &str, m: &str| format!("{t},{bone},{parent},{m}\n");
    let good = format!("{head}{}{}", row("0", "a", "", IDENTITY), row("0", "b", "a", IDENTITY));
    assert_eq!(load_bytes(Path::new("g.dump.csv"), good.as_bytes()).unwrap().skeleton.len(), 2);
    let ragged = error("r.dump.csv", &format!("{good}{}", row("1", "a", "", "1,0,0")));
    assert_eq!(ragged, "r.dump.csv: line 5: 6 fields, expected 19 (time, bone, parent and 16 numbers)");
    let nan = error(
        "n.dump.csv",
        &format!(
            "{good}{}{}",
            row("1", "a", "", IDENTITY),
            row("1", "b", "a", &IDENTITY.replace("1,0,0,0,", "nan,0,0,0,"))
        ),
    );
    assert_eq!(nan, "n.dump.csv: line 6: a number is not finite");
    let missing = error("m.dump.csv", &format!("{good}{}{}", row("1", "a", "", IDENTITY), row("2", "a", "", IDENTITY)));
    assert_eq!(missing, "m.dump.csv: line 6: the time before (1) lists 1 bones, the first time 2");
    let back = format!("{good}{}{}", row("-1", "a", "", IDENTITY), row("-1", "b", "a", IDENTITY));
    assert_eq!(error("b.dump.csv", &back), "b.dump.csv: line 5: the time -1 does not come after the one before it (0)");
    let renamed =
        error("x.dump.csv", &format!("{good}{}{}", row("1", "a", "", IDENTITY), row("1", "c", "a", IDENTITY)));
    assert!(renamed.starts_with("x.dump.csv: line 6: bone `c` (parent `a`) where the first time has `b`"), "{renamed}");
    let header = error("h.dump.csv", &good.replace("space=world", "space=model"));
    assert_eq!(header, "h.dump.csv: line 1: the space `model` is not one of world, local");
}

#[test]
fn every_cut_and_flip_of_a_dump_reads_or_fails_without_panicking() {
    let rig = demo_rig();
    let (times, poses) = evaluated(&rig, InheritMode::Full);
    for syntax in [Syntax::Json, Syntax::Csv] {
        let bytes = written(&rig, syntax, DumpHeader::default(), &times[..3], &poses[..3]);
        for cut in 0..bytes.len() {
            let _ = load_bytes(Path::new("cut.dump"), &bytes[..cut]);
        }
        for (i, flip) in
            (0..bytes.len()).step_by(7).zip([b'-', b'e', b',', b'"', b'9', b'\n', b'{', b'n'].iter().cycle())
        {
            let mut flipped = bytes.clone();
            flipped[i] = *flip;
            let _ = load_bytes(Path::new("flip.dump"), &flipped);
        }
    }
}
