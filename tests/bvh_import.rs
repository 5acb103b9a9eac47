//! The BVH importer: every shared BVH file against its MANIFEST, a hand-written file whose model matrices are
//! computed by hand below, and broken or hostile files that must fail naming the line.

mod common;

use std::path::Path;

use bonescope::eval::{Hierarchy, Pose};
use bonescope::import::{self, ImportError};
use bonescope::model::{NodeRole, Rig};
use common::asset;
use glam::{DMat3, DMat4, DVec3};
use rand::{RngExt, SeedableRng};
use rand_xorshift::XorShiftRng;

// ---------------------------------------------------------------------------------------------------------------
// The shared files

/// One row of a manifest: file, joints (ROOT + JOINT), end sites, frames, frame time as written, rotation orders.
type Row = (&'static str, usize, usize, usize, f64, &'static [&'static str]);

/// `bvh/MANIFEST.md` and `blender/README.md`.
const MANIFEST: &[Row] = &[
    ("bvh/cmu_12_01_walk.bvh", 31, 7, 524, 0.0083333, &["ZYX"]),
    ("bvh/bvh_test2.bvh", 23, 5, 61, 0.008333, &["YXZ"]),
    ("bvh/bvh_test3.bvh", 60, 13, 100, 0.008333, &["XYZ", "YXZ"]),
    ("bvh/standard_skeleton.bvh", 24, 5, 1, 0.008333, &["ZYX"]),
    ("bvh/rotation_first_root.bvh", 4, 2, 4, 0.04, &["XYZ", "ZXY"]),
    ("bvh/full_precision_frame_time.bvh", 2, 1, 3, 0.0417083750417, &["ZYX"]),
    ("blender/stretchy_full.bvh", 8, 2, 61, 0.033333, &["XYZ"]),
];

#[test]
fn every_shared_bvh_matches_its_manifest() {
    for &(file, joints, end_sites, frames, frame_time, orders) in MANIFEST {
        let rig = import::load(&asset(file)).unwrap_or_else(|e| panic!("{e}"));
        let roles: Vec<NodeRole> = rig.skeleton.bones().iter().map(|b| b.role).collect();
        let ends = roles.iter().filter(|r| **r == NodeRole::EndSite).count();
        assert_eq!((rig.skeleton.len() - ends, ends), (joints, end_sites), "{file}: joints and end sites");
        assert!(roles.iter().all(|r| r.is_figure()), "{file}: a BVH holds nothing but the figure");
        let named_ends = rig.skeleton.bones().iter().filter(|b| b.name.ends_with("_end"));
        assert!(named_ends.clone().all(|b| b.role == NodeRole::EndSite) && named_ends.count() == ends, "{file}");
        assert_eq!(rig.clips.len(), 1, "{file}");
        let clip = &rig.clips[0];
        let times = clip.key_times();
        assert_eq!(times.len(), frames, "{file}: frames");
        // Frame k at k · Frame Time, exactly as written (no rounding of the frame time).
        for (k, &t) in times.iter().enumerate() {
            assert_eq!(t, k as f64 * frame_time, "{file}: frame {k}");
        }
        assert_eq!(clip.span().length(), (frames - 1) as f64 * frame_time, "{file}");
        let listed = rig.notes.iter().find(|n| n.starts_with("rotation orders")).expect("a note on rotation orders");
        for order in orders {
            assert!(listed.contains(order), "{file}: {order} in `{listed}`");
        }
    }
    // "120 fps, ≈4.4 s".
    let walk = import::load(&asset("bvh/cmu_12_01_walk.bvh")).unwrap();
    assert!((walk.clips[0].span().length() - 4.4).abs() < 0.05);
}

#[test]
fn the_full_precision_frame_time_is_kept() {
    let rig = import::load(&asset("bvh/full_precision_frame_time.bvh")).unwrap();
    assert_eq!(rig.clips[0].key_times(), [0.0, 0.0417083750417, 2.0 * 0.0417083750417]);
}

#[test]
fn a_root_with_rotations_before_positions_reads_its_position_channels() {
    // rotation_first_root.bvh: `CHANNELS 6 Zrotation Xrotation Yrotation Xposition Yposition Zposition`, first
    // frame `5 -3 0 10 50 -20 …`: the root stands at (10, 50, −20), turned Rz(5°)·Rx(−3°)·Ry(0°).
    let rig = import::load(&asset("bvh/rotation_first_root.bvh")).unwrap();
    let hierarchy = Hierarchy::new(&rig.skeleton, &rig.skeleton.declared_modes()).unwrap();
    let mut pose = Pose::default();
    pose.evaluate(&rig.skeleton, rig.clips.first(), &hierarchy, 0.0);
    let root = pose.model.model[0];
    assert!(root.w_axis.truncate().abs_diff_eq(DVec3::new(10.0, 50.0, -20.0), 1e-5));
    let expected = DMat3::from_rotation_z(5f64.to_radians()) * DMat3::from_rotation_x(-3f64.to_radians());
    assert!(DMat3::from_mat4(root).abs_diff_eq(expected, 1e-6));
}

// ---------------------------------------------------------------------------------------------------------------
// A file written here, evaluated by hand

/// Windows line endings, tabs, runs of spaces, lower-case keywords, a brace on the ROOT line, interleaved channels.
const HAND: &str = "HIERARCHY\r\nROOT Hips {\r\n\tOFFSET   1 2\t3\r\n\tCHANNELS 6 Zrotation Xposition Yrotation Yposition \
                    Xrotation Zposition\r\n\tjoint Arm\r\n\t{\r\n\t\toffset 0 5 0\r\n\t\tCHANNELS 3 Xrotation \
                    Zrotation  Yrotation \r\n\t\tEnd Site\r\n\t\t{\r\n\t\t\tOFFSET 0 2 0\r\n\t\t}\r\n\t}\r\n}\r\n\
                    MOTION\r\nFrames:\t2\r\nFrame Time: 0.5\r\n0 0 0 0 0 0 0 0 0\r\n  90 10 90 20 0 30\t90 90 0  \r\n";

fn load_text(name: &str, text: &str) -> Result<Rig, ImportError> {
    import::load_bytes(Path::new(name), text.as_bytes())
}

fn affine(columns: [[f64; 3]; 3], t: [f64; 3]) -> DMat4 {
    let [x, y, z] = columns.map(DVec3::from_array);
    DMat4::from_cols(x.extend(0.0), y.extend(0.0), z.extend(0.0), DVec3::from_array(t).extend(1.0))
}

#[test]
fn hand_written_bvh_matches_matrices_computed_by_hand() {
    let rig = load_text("hand.bvh", HAND).unwrap();
    let names: Vec<&str> = rig.skeleton.bones().iter().map(|b| b.name.as_str()).collect();
    assert_eq!(names, ["Hips", "Arm", "Arm_end"]);
    let hierarchy = Hierarchy::new(&rig.skeleton, &rig.skeleton.declared_modes()).unwrap();
    let mut pose = Pose::default();
    let model = |pose: &mut Pose, t: f64| {
        pose.evaluate(&rig.skeleton, rig.clips.first(), &hierarchy, t);
        pose.model.model.clone()
    };

    // Frame 0: every channel 0. The root's position channels replace its OFFSET (1, 2, 3) with (0, 0, 0).
    let m = model(&mut pose, 0.0);
    assert!(m[0].abs_diff_eq(DMat4::IDENTITY, 1e-12));
    assert!(m[1].abs_diff_eq(DMat4::from_translation(DVec3::new(0.0, 5.0, 0.0)), 1e-12));
    assert!(m[2].abs_diff_eq(DMat4::from_translation(DVec3::new(0.0, 7.0, 0.0)), 1e-12));

    // Frame 1 (t = 0.5). Hips: Zrot 90, Xpos 10, Yrot 90, Ypos 20, Xrot 0, Zpos 30, so t = (10, 20, 30) and
    //   R_hips = Rz(90)·Ry(90)·Rx(0). Rz(90) rows (0 −1 0)(1 0 0)(0 0 1); Ry(90) rows (0 0 1)(0 1 0)(−1 0 0).
    //   Product rows (0 −1 0)(0 0 1)(−1 0 0), i.e. columns (0 0 −1), (−1 0 0), (0 1 0).
    // Arm: Xrot 90, Zrot 90, Yrot 0, so R_arm = Rx(90)·Rz(90). Rx(90) rows (1 0 0)(0 0 −1)(0 1 0), Rz(90) as above.
    //   Product rows (0 −1 0)(0 0 −1)(1 0 0), i.e. columns (0 0 1), (−1 0 0), (0 −1 0). Translation: OFFSET (0 5 0).
    //   W_arm = W_hips·L_arm: t = (10 20 30) + R_hips·(0 5 0) = (10 20 30) + 5·(−1 0 0) = (5 20 30);
    //   R_hips·R_arm: rows of R_hips dotted with columns of R_arm give rows (0 0 1)(1 0 0)(0 1 0),
    //   i.e. columns (0 1 0), (0 0 1), (1 0 0).
    // Arm_end: W_arm·T(0 2 0): t = (5 20 30) + 2·(0 0 1) = (5 20 32), the same rotation.
    let m = model(&mut pose, 0.5);
    let hips = affine([[0.0, 0.0, -1.0], [-1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], [10.0, 20.0, 30.0]);
    let arm = affine([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]], [5.0, 20.0, 30.0]);
    let end = affine([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]], [5.0, 20.0, 32.0]);
    for (got, want, name) in [(m[0], hips, "Hips"), (m[1], arm, "Arm"), (m[2], end, "Arm_end")] {
        assert!(got.abs_diff_eq(want, 1e-6), "{name}: {got:?} != {want:?}");
    }

    // Half-way between the frames the root's translation is interpolated linearly: (5, 10, 15).
    let m = model(&mut pose, 0.25);
    assert!(m[0].w_axis.truncate().abs_diff_eq(DVec3::new(5.0, 10.0, 15.0), 1e-6));
}

#[test]
fn lone_carriage_returns_end_lines_too() {
    let rig = load_text("mac.bvh", &HAND.replace("\r\n", "\r")).unwrap();
    assert_eq!(rig.clips[0].key_times(), [0.0, 0.5]);
}

#[test]
fn rows_beyond_the_declared_frames_are_read_with_a_note() {
    // One row more than `Frames:` says (assimp's Boxing_Toes.bvh is such a file): both rows are frames, as other
    // readers take them; the second row is the one the two-frame file has.
    let rig = load_text("extra.bvh", &HAND.replace("Frames:\t2", "Frames: 1")).unwrap();
    let full = load_text("hand.bvh", HAND).unwrap();
    assert_eq!(rig.clips[0].key_times(), full.clips[0].key_times());
    assert_eq!(rig.clips[0].tracks(), full.clips[0].tracks());
    assert!(rig.notes.iter().any(|n| n.contains("2 rows, 1 more than its `Frames: 1`")), "{:?}", rig.notes);
}

#[test]
fn bvh_is_recognised_by_content_whatever_the_name() {
    let rig = load_text("motion.fbx", &format!("\u{feff}\r\n  {HAND}")).unwrap();
    assert_eq!(rig.skeleton.len(), 3);
}

// ---------------------------------------------------------------------------------------------------------------
// Broken and hostile files

fn assert_fails(text: &str, place: &str, message: &str) {
    let error = load_text("broken.bvh", text).expect_err("a broken file must not load");
    assert_eq!(error.path, Path::new("broken.bvh"));
    assert_eq!(error.place.as_deref(), Some(place), "{error}");
    assert!(error.message.contains(message), "`{}` should contain `{message}`", error.message);
}

#[test]
fn wrong_counts_name_the_line_and_frame() {
    // The hand file has its motion header on lines 16–17 and frames on lines 18–19.
    assert_fails(
        &HAND.replace("Frames:\t2", "Frames: 3"),
        "line 19",
        "the file ends after 2 frames, but the header declares 3",
    );
    assert_fails(&HAND.replace("90 90 0  ", "90 90"), "line 19", "frame 1: 8 numbers, expected 9");
    assert_fails(&HAND.replace("90 10 90", "90 ten 90"), "line 19", "frame 1: `ten` is not a finite number");
    assert_fails(&HAND.replace("90 10 90", "90 NaN 90"), "line 19", "`NaN` is not a finite number");
    assert_fails(&HAND.replace("CHANNELS 3", "CHANNELS 4"), "line 8", "CHANNELS 4 names 3 channels");
    assert_fails(&HAND.replace("CHANNELS 3", "CHANNELS 7"), "line 8", "CHANNELS needs a count from 0 to 6");
    assert_fails(&HAND.replace("Yrotation \r", "Wrotation \r"), "line 8", "unknown channel `Wrotation`");
    assert_fails(
        &HAND.replace("Zrotation  Yrotation", "Zrotation Xrotation"),
        "line 8",
        "channel Xrotation listed twice",
    );
    assert_fails(&HAND.replace("OFFSET   1 2\t3", "OFFSET 1 2"), "line 3", "OFFSET needs 3 numbers, found 2");
    assert_fails(&HAND.replace("\t\toffset 0 5 0\r\n", ""), "line 12", "`Arm` has no OFFSET");
    assert_fails(&HAND.replace("Frame Time: 0.5", "Frame Time: 0"), "line 17", "Frame Time must be above 0");
    assert_fails(&HAND.replace("Frame Time: 0.5", "Frame Time: -inf"), "line 17", "is not a finite number");
    assert_fails(&HAND.replace("Frames:\t2", "Frames: -2"), "line 16", "is not a whole number");
    assert_fails(&HAND.replace("joint Arm", "ROOT Arm"), "line 5", "ROOT inside another joint");
    assert_fails(&HAND.replace("}\r\nMOTION", "MOTION"), "line 14", "MOTION before the `}` of `Hips`");
    assert_fails(
        &HAND.replace("\t\t\tOFFSET 0 2 0", "\t\t\tCHANNELS 1 Xrotation"),
        "line 11",
        "an End Site has no CHANNELS",
    );
    assert_fails("HIERARCHY\nJOINT a\n", "line 2", "JOINT outside any ROOT");
    assert_fails("HIERARCHY\nROOT a\nOFFSET 0 0 0\n", "line 3", "expected `{` after `a`");
    assert_fails("HIERARCHY\n}\n", "line 2", "`}` without a matching `{`");
    assert_fails("HIERARCHY\nROOT a\n{\n", "line 3", "the file ends before MOTION");
    assert_fails("HIERARCHY\r\n", "line 1", "the file ends before MOTION");
    assert_fails("HIERARCHY extra\n", "line 1", "expected `HIERARCHY`");
}

#[test]
fn a_header_claiming_four_billion_frames_fails_at_the_end_of_the_file() {
    let started = std::time::Instant::now();
    assert_fails(
        &HAND.replace("Frames:\t2", "Frames: 4294967296"),
        "line 19",
        "the file ends after 2 frames, but the header declares 4294967296",
    );
    assert_fails(&HAND.replace("Frames:\t2", "Frames: 99999999999999999999"), "line 16", "is not a whole number");
    assert!(started.elapsed().as_secs() < 2, "nothing sized by the claim");
}

#[test]
fn zero_frames_is_a_skeleton_without_animation() {
    let text =
        HAND.replace("Frames:\t2", "Frames: 0").replace("0 0 0 0 0 0 0 0 0\r\n  90 10 90 20 0 30\t90 90 0  \r\n", "");
    let rig = load_text("still.bvh", &text).unwrap();
    assert!(rig.clips.is_empty());
    assert_eq!(rig.skeleton.len(), 3);
}

#[test]
fn every_prefix_and_random_mutations_fail_cleanly() {
    let bytes = std::fs::read(asset("bvh/rotation_first_root.bvh")).unwrap();
    let path = Path::new("cut.bvh");
    for cut in 0..bytes.len() {
        // A prefix may still be a whole file (cut in the last frame's trailing whitespace); it must never panic.
        if let Err(e) = import::load_bytes(path, &bytes[..cut]) {
            assert_eq!(e.path, path);
        }
    }
    let mut noise = XorShiftRng::seed_from_u64(0x2545_f491_4f6c_dd1d);
    let alphabet = b" \t\r\n{}0123456789.-+eE:ROOTJOINTEndSiteOFFSETCHANNELSXYZrotationposition";
    for _ in 0..2000 {
        let mut mutated = bytes.clone();
        for _ in 0..1 + noise.random_range(0..4) {
            let at = noise.random_range(0..mutated.len());
            match noise.random_range(0..3) {
                0 => mutated[at] = alphabet[noise.random_range(0..alphabet.len())],
                1 => drop(mutated.remove(at)),
                _ => mutated.insert(at, alphabet[noise.random_range(0..alphabet.len())]),
            }
        }
        let _ = import::load_bytes(path, &mutated);
    }
}
