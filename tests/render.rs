//! `bonescope render` as a pipeline runs it: byte-identical pictures, modes that change them, reference checks with
//! diff images, sequences, and errors that name the problem.

mod common;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use common::{asset, bonescope};
use tempfile::TempDir;

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
fn the_background_is_the_viewports_or_transparent_on_request() {
    let dir = TempDir::new().unwrap();
    let (opaque, transparent) = (path(&dir, "opaque.png"), path(&dir, "transparent.png"));
    succeeds(&render_demo(&opaque, &[]));
    succeeds(&render_demo(&transparent, &["--transparent"]));
    let opaque = image::open(opaque).unwrap().to_rgba8();
    let transparent = image::open(transparent).unwrap().to_rgba8();
    // The bottom-left corner is empty (no grid line, no legend): the dark palette's background, or nothing.
    let corner = (2, 267);
    assert_eq!(opaque.get_pixel(corner.0, corner.1).0, [30, 32, 36, 255]);
    assert_eq!(transparent.get_pixel(corner.0, corner.1).0[3], 0);
    assert!(opaque.pixels().all(|p| p.0[3] == 255));
    assert!(transparent.pixels().any(|p| p.0[3] == 255), "the bones are opaque");
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
    let cases: [(&[&str], &str); 7] = [
        (&["render", "--out", "/no/such/dir/x.png"], "cannot write /no/such/dir/x.png"),
        (&["render", "/no/such/file.glb", "--out", arg(&out)], "/no/such/file.glb"),
        (&["render", "--frames", "0:10:5", "--out", arg(&out)], "put {frame} or {time} in it"),
        (&["render", "--select", "elbow", "--out", arg(&out)], "no bone named `elbow`"),
        (&["render", "--size", "0x10", "--out", arg(&out)], "0×10"),
        (&["render", "--reference", "/no/such/reference.png"], "/no/such/reference.png"),
        (&["render", "--show", "bones,sheer", "--out", arg(&out)], "unknown item `sheer`"),
    ];
    for (args, expected) in cases {
        let output = bonescope(args);
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert_eq!(output.status.code(), Some(2), "{args:?}: {stderr}");
        assert!(stderr.contains(expected), "{args:?}: `{expected}` not in {stderr}");
    }
    assert!(!out.exists());
}

/// The pictures of the README and `docs/app.md` are made by the `bonescope render … --out assets/readme/…` commands
/// `docs/app.md` shows: each is run again against the committed picture, so neither the pictures nor the commands go
/// stale.
#[test]
fn the_readme_pictures_are_what_their_commands_render() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let page = std::fs::read_to_string(root.join("docs/app.md")).unwrap();
    let commands: Vec<&str> = page
        .lines()
        .filter(|line| line.starts_with("bonescope render ") && line.contains("--out assets/readme/"))
        .collect();
    assert_eq!(commands.len(), 5, "docs/app.md shows five pictures' commands");
    let out = Path::new(env!("CARGO_TARGET_TMPDIR"));
    for command in commands {
        let mut args: Vec<String> = command.split_whitespace().skip(1).map(str::to_owned).collect();
        let at = args.iter().position(|a| a == "--out").unwrap();
        let picture = args[at + 1].clone();
        let name = Path::new(&picture).file_name().unwrap();
        args[at] = "--reference".to_owned();
        args.extend(["--out".to_owned(), out.join(name).display().to_string()]);
        let output = Command::new(env!("CARGO_BIN_EXE_bonescope")).current_dir(root).args(&args).output().unwrap();
        assert!(
            output.status.success(),
            "`{command}` no longer renders {picture} (new picture and diff in {}):\n{}{}",
            out.display(),
            String::from_utf8_lossy(&output.stdout),
            String::from_utf8_lossy(&output.stderr)
        );
    }
}

/// ozz's blend sample on ProAnimationBank's mocap: walk and run synced at `a` = 0.5 play one cycle of
/// (0.667 − 1.333)·0.5 + 1.333 = 1 s, so a sequence over two seconds repeats itself after one.
#[test]
fn a_synced_blend_sequence_repeats_with_the_blended_cycle() {
    let dir = TempDir::new().unwrap();
    let file = asset("fbx-proanimationbank/locomotions.fbx");
    let template = path(&dir, "blend_{frame}.png");
    // No legend: its caption states the time, which does differ.
    let args = ["--anim", "walk", "--blend", "run", "--weight", "0.5", "--sync", "--view", "side", "--show", "-legend"];
    let out = succeeds(&bonescope(
        &[&["render", arg(&file)], &args[..], &["--frames", "0:45:15", "--size", "320x180", "--out", arg(&template)]]
            .concat(),
    ));
    let frame = |n: &str| std::fs::read(path(&dir, &format!("blend_{n}.png"))).unwrap();
    assert!(frame("0000") == frame("0030"), "one cycle later the blend is where it started:\n{out}");
    assert!(frame("0015") == frame("0045"));
    assert!(frame("0000") != frame("0015"), "half a cycle later it is not");
}

/// The rows with a drawn pixel (one that is not the background, the colour of the top-left pixel), and the leftmost
/// and rightmost columns drawn.
fn drawn_rows_and_columns(image: &image::RgbaImage) -> (Vec<u32>, [u32; 2]) {
    let background = *image.get_pixel(0, 0);
    let drawn: Vec<(u32, u32)> =
        image.enumerate_pixels().filter(|(_, _, p)| **p != background).map(|(x, y, _)| (x, y)).collect();
    let mut rows: Vec<u32> = drawn.iter().map(|&(_, y)| y).collect();
    rows.dedup();
    let columns = drawn.iter().fold([u32::MAX, 0], |[l, r], &(x, _)| [l.min(x), r.max(x)]);
    (rows, columns)
}

/// The opening view of studio files frames the figure, not the cameras and helpers beside it (walk.fbx's "Producer"
/// cameras stand 150 m out) nor only part of it: with bones alone drawn, what is drawn is one figure (no gap of
/// more than 5 % of the height between drawn rows: no camera drawn far from it; a hip joint may leave a few rows
/// empty below the spine) between 30 % and 98 % of the picture's height, touching no edge.
#[test]
fn the_opening_view_frames_the_figure_whole() {
    let dir = TempDir::new().unwrap();
    let files = [
        "fbx-proanimationbank/walk.fbx",
        "fbx-ufbx-corpus/maya_human_ik_6100_binary.fbx",
        "fbx-proanimationbank/locomotions.fbx",
        "gltf-khronos/cesium_man.gltf",
        "fbx-ufbx-data/maya_mixed_inherit_mode_7700_ascii.fbx",
    ];
    for file in files {
        let out = path(&dir, "opening.png");
        succeeds(&bonescope(&["render", arg(&asset(file)), "--show", "bones", "--out", arg(&out)]));
        let image = image::open(&out).unwrap().to_rgba8();
        let (width, height) = image.dimensions();
        let (rows, [left, right]) = drawn_rows_and_columns(&image);
        let (Some(&top), Some(&bottom)) = (rows.first(), rows.last()) else { panic!("{file}: nothing drawn") };
        let gap = rows.windows(2).map(|pair| pair[1] - pair[0] - 1).max().unwrap_or(0);
        assert!(f64::from(gap) < 0.05 * f64::from(height), "{file}: something is drawn {gap} rows apart from the rest");
        let share = f64::from(bottom - top + 1) / f64::from(height);
        assert!((0.30..=0.98).contains(&share), "{file}: the figure is {:.1} % of the height", share * 100.0);
        assert!(left > 0 && top > 0 && right < width - 1 && bottom < height - 1, "{file}: cut at an edge");
    }
}

/// Axis triads and boxes have a smallest size on screen: at the opening view of CMU's walk (the whole walk framed,
/// the figure a quarter of the picture) and of ProAnimationBank's locomotions from the front, turning them on
/// changes more than 0.4 % of the picture (before they had a minimum, 28 pixels and 0.13 %).
#[test]
fn gizmos_are_visible_at_the_opening_view() {
    let dir = TempDir::new().unwrap();
    for (file, view) in [("bvh/cmu_12_01_walk.bvh", "persp"), ("fbx-proanimationbank/locomotions.fbx", "front")] {
        let file_path = asset(file);
        let render = |show: &str| {
            let out = path(&dir, &format!("{show}.png"));
            let args = ["render", arg(&file_path), "--view", view, "--show", show, "--out", arg(&out)];
            succeeds(&bonescope(&args));
            image::open(out).unwrap().to_rgba8()
        };
        let (bones, gizmos) = (render("bones"), render("bones,axes,boxes"));
        let changed = bones.pixels().zip(gizmos.pixels()).filter(|(a, b)| a != b).count();
        let percent = 100.0 * changed as f64 / f64::from(bones.width() * bones.height());
        assert!(percent > 0.4, "{file}: axes and boxes change {changed} pixels, {percent:.2} % of the picture");
    }
}

#[test]
fn axes_on_the_selection_draw_the_selected_bones_triad() {
    // What the Why? section's chain relies on: picking an ancestor shows its scale in its triad. Pixels of the Y
    // axis's green (80, 200, 90) count the triads of a render of the demo's bones with `axes=selected`.
    let dir = TempDir::new().unwrap();
    let greens = |extra: &[&str]| {
        let out = path(&dir, &format!("{}.png", extra.len()));
        let mut args = vec!["render", "--show", "bones,axes=selected", "--time", "0.5", "--out", arg(&out)];
        args.extend_from_slice(extra);
        succeeds(&bonescope(&args));
        let image = image::open(out).unwrap().to_rgba8();
        let near = |p: &image::Rgba<u8>| [80i32, 200, 90].iter().zip(p.0).all(|(&c, v)| (c - i32::from(v)).abs() <= 12);
        image.pixels().filter(|p| near(p)).count()
    };
    let (none, selected) = (greens(&[]), greens(&["--select", "forearm"]));
    assert!(none <= 2, "no triad without a selection: {none} green pixels");
    assert!(selected >= 10, "the selected forearm's chain's triads: {selected} green pixels");
}
