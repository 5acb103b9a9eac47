//! `bonescope render` as a pipeline runs it: byte-identical pictures, modes that change them, reference checks with
//! diff images, sequences, and errors that name the problem.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use tempfile::TempDir;

fn bonescope(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_bonescope")).args(args).output().expect("bonescope runs")
}

fn succeeds(output: &Output) -> String {
    assert!(output.status.success(), "stderr: {}", String::from_utf8_lossy(&output.stderr));
    String::from_utf8_lossy(&output.stdout).into_owned()
}

fn path(dir: &TempDir, name: &str) -> PathBuf {
    dir.path().join(name)
}

fn arg(path: &Path) -> &str {
    path.to_str().expect("a UTF-8 temp path")
}

/// The demo rig at 0.5 s (the upper arm stretched, so the forearm shears), small to keep the tests quick.
fn render_demo(out: &Path, extra: &[&str]) -> Output {
    render_demo_at("0.5", out, extra)
}

fn render_demo_at(time: &str, out: &Path, extra: &[&str]) -> Output {
    let mut args = vec!["render", "--time", time, "--size", "480x270", "--show", "+boxes", "--out", arg(out)];
    args.extend_from_slice(extra);
    bonescope(&args)
}

#[test]
fn the_same_input_gives_the_same_bytes() {
    let dir = TempDir::new().unwrap();
    let (a, b) = (path(&dir, "a.png"), path(&dir, "b.png"));
    succeeds(&render_demo(&a, &[]));
    succeeds(&render_demo(&b, &[]));
    let (a, b) = (std::fs::read(a).unwrap(), std::fs::read(b).unwrap());
    assert!(a.len() > 1000, "a real picture, {} bytes", a.len());
    assert!(a == b, "two renders of the same input differ");
    let image = image::load_from_memory(&a).unwrap();
    assert_eq!((image.width(), image.height()), (480, 270));
}

#[test]
fn another_inheritance_mode_gives_another_picture() {
    let dir = TempDir::new().unwrap();
    let (full, compensated) = (path(&dir, "full.png"), path(&dir, "compensated.png"));
    succeeds(&render_demo(&full, &["--ghost", "none"]));
    succeeds(&render_demo(&compensated, &["--ghost", "none", "--inherit", "segment-compensate"]));
    let out = succeeds(&bonescope(&[
        "render",
        "--time",
        "0.5",
        "--size",
        "480x270",
        "--show",
        "+boxes",
        "--ghost",
        "none",
        "--inherit",
        "segment-compensate",
        "--reference",
        arg(&full),
        "--threshold",
        "100",
    ]));
    let percent: f64 = out.split(':').nth(1).unwrap().trim().split(' ').next().unwrap().parse().unwrap();
    // The forearm and hand, their boxes and the mesh around them move: a good part of the picture changes.
    assert!(percent > 0.5, "only {percent} % of the pixels changed:\n{out}");
    assert_ne!(std::fs::read(full).unwrap(), std::fs::read(compensated).unwrap());
}

#[test]
fn a_reference_passes_on_the_same_picture_and_fails_with_a_diff_image_on_a_changed_one() {
    let dir = TempDir::new().unwrap();
    let reference = path(&dir, "reference.png");
    succeeds(&render_demo(&reference, &[]));

    let same = path(&dir, "same.png");
    let out = succeeds(&render_demo(&same, &["--reference", arg(&reference)]));
    assert!(out.contains("0.0000 % of pixels differ (0 of 129600), within"), "{out}");
    assert!(!path(&dir, "same.diff.png").exists());

    let changed = path(&dir, "changed.png");
    let output = render_demo_at("1.0", &changed, &["--reference", arg(&reference)]);
    assert_eq!(output.status.code(), Some(1), "stderr: {}", String::from_utf8_lossy(&output.stderr));
    let out = String::from_utf8_lossy(&output.stdout);
    assert!(out.contains("over the threshold of 0.1 %"), "{out}");
    let diff = image::open(path(&dir, "changed.diff.png")).expect("a diff image beside --out").to_rgba8();
    let red = diff.pixels().filter(|p| p.0 == [255, 0, 0, 255]).count();
    assert!(red > 100, "{red} differing pixels marked");

    // A loose enough threshold lets the same change pass.
    succeeds(&render_demo_at("1.0", &changed, &["--reference", arg(&reference), "--threshold", "100"]));
}

#[test]
fn a_sequence_template_writes_one_file_per_frame_matching_single_renders() {
    let dir = TempDir::new().unwrap();
    let template = path(&dir, "seq_{frame}_{time}.png");
    let out = succeeds(&bonescope(&[
        "render",
        "--frames",
        "0:30:15",
        "--rate",
        "30",
        "--size",
        "320x180",
        "--out",
        arg(&template),
    ]));
    let mut written: Vec<String> =
        std::fs::read_dir(dir.path()).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    written.sort();
    assert_eq!(written, ["seq_0000_0.000.png", "seq_0015_0.500.png", "seq_0030_1.000.png"], "{out}");

    // Frame 15 of the sequence is what a single render at 0.5 s gives: the camera does not move with the pose.
    let single = path(&dir, "single.png");
    succeeds(&bonescope(&["render", "--time", "0.5", "--size", "320x180", "--out", arg(&single)]));
    assert!(std::fs::read(single).unwrap() == std::fs::read(path(&dir, "seq_0015_0.500.png")).unwrap());
}

#[test]
fn the_whole_window_shows_the_panels_and_differs_from_the_viewport() {
    let dir = TempDir::new().unwrap();
    let (window, viewport) = (path(&dir, "window.png"), path(&dir, "viewport.png"));
    succeeds(&render_demo(&window, &["--ui", "--select", "forearm"]));
    succeeds(&render_demo(&viewport, &["--select", "forearm"]));
    let window = image::open(window).unwrap();
    assert_eq!((window.width(), window.height()), (480, 270));
    assert_ne!(window.to_rgba8().into_raw(), image::open(viewport).unwrap().to_rgba8().into_raw());
}

#[test]
fn bad_requests_fail_with_a_message_that_names_the_problem() {
    let dir = TempDir::new().unwrap();
    let out = path(&dir, "x.png");
    let cases: [(&[&str], &str); 6] = [
        (&["render", "/no/such/file.glb", "--out", arg(&out)], "/no/such/file.glb"),
        (&["render", "--frames", "0:10:5", "--out", arg(&out)], "put {frame} or {time} in it"),
        (&["render", "--select", "elbow", "--out", arg(&out)], "no bone named `elbow`"),
        (&["render", "--size", "0x10", "--out", arg(&out)], "0×10"),
        (&["render", "--reference", "/no/such/reference.png"], "/no/such/reference.png"),
        (&["render", "--show", "bones,shear", "--out", arg(&out)], "unknown item `shear`"),
    ];
    for (args, expected) in cases {
        let output = bonescope(args);
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert_eq!(output.status.code(), Some(2), "{args:?}: {stderr}");
        assert!(stderr.contains(expected), "{args:?}: `{expected}` not in {stderr}");
    }
    assert!(!out.exists());
}
