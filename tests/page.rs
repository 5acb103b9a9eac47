//! The page a library scan makes for people (`report --format html|markdown`, `scan --format html`): what it shows
//! is the JSON lines it came from, its pictures are the evaluation's, and a real browser (Debian's Chromium,
//! headless: `.ci/run` installs it) loads it without an error, sorts it and shows it as the reference image does.

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;

use bonescope::analysis::report::{AnimationScan, FileScan};
use bonescope::analysis::sketch::{CURVE_POINTS, SHEAR_STEP_DEG, STEPS, Sketch};
use bonescope::analysis::{Assessment, ScanOptions};
use bonescope::eval::Evaluation;
use common::{asset, bonescope, corpus};

/// A small library: Blender's squash-and-stretch rig, Godot's mannequin (ten clips), and a glTF its validator
/// refuses (a negative key time), named as the tests run them (from the repository).
fn library() -> Vec<String> {
    let files = [
        asset("blender/stretchy_full.glb"),
        corpus("realworld/godot_mannequiny.glb"),
        asset("gltf-validator-tests/base/data/animation_data/invalid_input_values.gltf"),
    ];
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    files.iter().map(|f| f.strip_prefix(root).unwrap_or(f).to_string_lossy().into_owned()).collect()
}

/// The library scanned with `--explain` as JSON lines, in a file of `dir`, and the reports read back.
fn scanned(dir: &Path) -> (PathBuf, Vec<FileScan>) {
    let mut args = vec!["scan", "--explain", "--format", "jsonl"];
    let files = library();
    args.extend(files.iter().map(String::as_str));
    let out = bonescope(&args);
    assert_eq!(out.status.code(), Some(2), "one file is refused: {}", String::from_utf8_lossy(&out.stderr));
    let lines = dir.join("library.jsonl");
    std::fs::write(&lines, &out.stdout).unwrap();
    let text = String::from_utf8(out.stdout).unwrap();
    let reports = text.lines().map(|l| serde_json::from_str(l).unwrap()).collect();
    (lines, reports)
}

/// `report LINES --format FORMAT` with `extra`, its output as text.
fn report(lines: &Path, format: &str, extra: &[&str]) -> String {
    let mut args = vec!["report", lines.to_str().unwrap(), "--format", format];
    args.extend_from_slice(extra);
    let out = bonescope(&args);
    assert_eq!(out.status.code(), Some(2), "the refused file decides: {}", String::from_utf8_lossy(&out.stderr));
    String::from_utf8(out.stdout).unwrap()
}

/// The page's rows in the order written: each row's markup.
fn rows(page: &str) -> Vec<&str> {
    let body = &page[page.find("<tbody>").unwrap()..page.find("</tbody>").unwrap()];
    body.split("<tr").skip(1).collect()
}

/// The value of `attribute` in the first tag of `markup`.
fn attribute<'a>(markup: &'a str, attribute: &str) -> &'a str {
    let from = markup.find(&format!("{attribute}=\"")).unwrap() + attribute.len() + 2;
    &markup[from..from + markup[from..].find('"').unwrap()]
}

/// Every clip and refused file has a row, refused first, then the worst shear first; each row prints its clip's
/// worst shear and every stretched bone's worst shear, time and frame, and flagged samples as the JSON lines hold
/// them; the page needs nothing from outside itself.
#[test]
fn the_page_shows_what_the_json_lines_hold_and_needs_nothing_else() {
    let dir = tempfile::tempdir().unwrap();
    let (lines, reports) = scanned(dir.path());
    let page = report(&lines, "html", &[]);
    for outside in ["<link", " src=", "href=", "@import", "url("] {
        assert!(!page.contains(outside), "the page fetches something: {outside}");
    }
    let clips: Vec<(&str, &AnimationScan)> =
        reports.iter().flat_map(|f| f.animations.iter().map(move |a| (f.file.as_str(), a))).collect();
    let refused: Vec<&FileScan> = reports.iter().filter(|f| f.error.is_some()).collect();
    let rows = rows(&page);
    assert_eq!(rows.len(), clips.len() + refused.len());
    assert_eq!((clips.len(), refused.len()), (12, 1), "the stretchy rig's 2 clips, the mannequin's 10, one refused");
    assert!(rows[0].contains("class=\"refused\"") && rows[0].contains("key time 0 (-1) is negative"));
    let worst: Vec<f64> = rows[1..].iter().map(|r| attribute(r, "data-worst").parse().unwrap()).collect();
    assert!(worst.windows(2).all(|w| w[0] >= w[1]), "worst first: {worst:?}");
    for (file, clip) in &clips {
        let name = clip.animation.as_ref().and_then(|a| a.name.clone()).unwrap();
        let row = rows.iter().find(|r| attribute(r, "data-file") == *file && r.contains(&format!("<td>{name}<br>")));
        let row = row.unwrap_or_else(|| panic!("{file} `{name}` has a row"));
        let clip_worst = clip.stretched.first().map_or(0.0, |b| b.summary.worst_shear_deg);
        assert!(row.contains(&format!("<td class=\"num\">{clip_worst:.3}°</td>")), "{file} `{name}`");
        let rate = clip.animation.as_ref().unwrap().frame_rate;
        for bone in &clip.stretched {
            let s = &bone.summary;
            let at = bonescope::model::At { time: s.worst_shear_time, rate: Some(rate) };
            let line = format!("<b>{}</b> <span class=\"num\">{:.3}°</span> at {at}", bone.name, s.worst_shear_deg);
            assert!(row.contains(&line), "{file} `{name}`: {line}");
            assert!(row.contains(&format!(", flagged {}/{}", s.flagged_samples, clip.samples)), "{}", bone.name);
        }
        for explained in &clip.explained {
            assert!(row.contains(&explained.line.replace('&', "&amp;")), "{}", explained.line);
            // Both answers: as authored (the rig inherits fully: it already plays so), and the removal.
            assert_eq!(explained.answers.len(), 2, "{:?}", explained.answers);
            assert!(explained.answers[0].starts_with("to play it as authored in any engine: it already does"));
            assert!(
                explained.answers.iter().all(|a| row.contains(&a.replace('&', "&amp;"))),
                "{:?}",
                explained.answers
            );
        }
    }
    let flagged: usize = clips.iter().map(|(_, c)| c.stretched.len()).sum();
    let stretched_clips = clips.iter().filter(|(_, c)| !c.stretched.is_empty()).count();
    let summary = format!(
        "3 files, 12 clips: {stretched_clips} clips with {flagged} stretched bones, 1 file refused; without \
         --fail-above: fail (exit 2): 1 file could not be read"
    );
    assert!(page.contains(&summary), "{summary}");
}

/// The figure a row draws is the evaluation's own: every bone of the figure at the worst bone's worst time, seen
/// from the front, in the steps of the frame, with its shear where stretched; each curve holds the shear at evenly
/// spaced times from the clip's start to its end.
#[test]
fn a_sketch_is_the_figure_at_the_worst_moment_and_the_curves_the_shear_over_the_clip() {
    let rig = common::load_asset("blender/stretchy_full.glb");
    let options = ScanOptions::default();
    let source = Evaluation::declared(&rig, rig.clips.first());
    let scan = bonescope::analysis::scan(&source, &options, &|_, _| {});
    let sketch = Sketch::of(&source, &scan, &options.tolerances).expect("the rig stretches");
    let worst = scan.stretched_worst_first()[0];
    assert_eq!(sketch.time, worst.worst_shear_time);
    let model = source.pose_at(sketch.time).model.model;
    let figure: Vec<usize> = (0..rig.skeleton.len()).filter(|&b| rig.skeleton.figure()[b]).collect();
    assert_eq!(sketch.bones.len(), figure.len());
    let [x0, y0, x1, y1] = sketch.frame;
    let side = (x1 - x0).max(y1 - y0);
    for (drawn, &bone) in sketch.bones.iter().zip(&figure) {
        let origin = model[bone].w_axis;
        let steps = |v: f64, min: f64| (v - min) / side * f64::from(STEPS);
        assert!((f64::from(drawn[1]) - steps(origin.x, x0)).abs() <= 0.5, "{}", rig.skeleton.bone(bone).name);
        assert!((f64::from(drawn[2]) - steps(origin.y, y0)).abs() <= 0.5, "{}", rig.skeleton.bone(bone).name);
        let assessed = Assessment::of(&model[bone], &options.tolerances);
        let shear = if assessed.findings.stretched { assessed.shear_deg } else { 0.0 };
        assert!((f64::from(drawn[3]) * SHEAR_STEP_DEG - shear).abs() <= SHEAR_STEP_DEG / 2.0);
        if let Some(parent) = rig.skeleton.parent(bone).filter(|&p| rig.skeleton.figure()[p]) {
            assert_eq!(drawn[0], figure.iter().position(|&b| b == parent).unwrap() as i32);
        }
    }
    assert_eq!(figure[sketch.worst], worst.index);
    // The worst bone's drawn shear is the scan's worst, to the sketch's step.
    let drawn = f64::from(sketch.bones[sketch.worst][3]) * SHEAR_STEP_DEG;
    assert!((drawn - worst.worst_shear_deg).abs() <= SHEAR_STEP_DEG / 2.0, "{drawn} against {}", worst.worst_shear_deg);
    let span = source.span();
    for (curve, bone) in sketch.curves.iter().zip(scan.stretched_worst_first()) {
        assert_eq!(curve.len(), CURVE_POINTS);
        for (i, time) in [(0, span.start), (CURVE_POINTS - 1, span.end)] {
            let shear = Assessment::of(&source.pose_at(time).model.model[bone.index], &options.tolerances).shear_deg;
            assert!((f64::from(curve[i]) * SHEAR_STEP_DEG - shear).abs() <= SHEAR_STEP_DEG / 2.0);
        }
        let highest = f64::from(*curve.iter().max().unwrap()) * SHEAR_STEP_DEG;
        assert!(highest <= bone.worst_shear_deg + SHEAR_STEP_DEG / 2.0, "no sample passes the refined worst");
    }
}

/// The job summary: the verdict as its heading, the worst rows (the refused file first), and where the page is.
#[test]
fn the_markdown_summary_gives_the_verdict_the_worst_rows_and_the_page() {
    let dir = tempfile::tempdir().unwrap();
    let (lines, _) = scanned(dir.path());
    let summary = report(&lines, "markdown", &["--fail-above", "5", "--page", "[report.html](report.html)"]);
    assert!(summary.starts_with("## bonescope: fail (exit 2): 1 file could not be read\n"), "{summary}");
    let rows: Vec<&str> = summary.lines().filter(|l| l.starts_with("| ") && !l.starts_with("| worst")).collect();
    assert_eq!(rows.len(), 13, "{summary}");
    assert!(rows[0].starts_with("| refused | `../shared/assets/gltf-validator-tests/"), "{}", rows[0]);
    assert!(
        rows[1].starts_with("| 18.666° | `../shared/assets/blender/stretchy_full.glb` | squash\\_stretch | forearm")
    );
    assert!(summary.ends_with("Every clip, with a picture of its worst moment: [report.html](report.html)\n"));
}

/// A report read back may come from anywhere: a sketch whose numbers make no figure (parents and the worst bone out
/// of range, coordinates at the ends of their type, a frame of infinities, a curve of one point) still makes a page.
#[test]
fn a_page_of_nonsense_sketches_is_still_a_page() {
    let dir = tempfile::tempdir().unwrap();
    let bone = r#"{"name":"b","index":0,"worst_shear_deg":3.0,"worst_shear_time":0.5,"worst_stretch_deg":1.0,
        "flagged_samples":1,"first_flagged_time":0.5,"non_uniform_samples":0,"mirrored_samples":0,
        "degenerate_samples":0}"#
        .replace(char::is_whitespace, "");
    let sketch = r#"{"time":0.5,"frame":[-1e308,0,1e308,1],"bones":[[7,2147483647,-2147483648,-5],[-9,0,0,4294967]],
        "worst":99,"curves":[[4294967295],[]]}"#
        .replace(char::is_whitespace, "");
    let line = format!(
        r#"{{"file":"odd<&>.glb","error":null,"animations":[{{"animation":null,"inherit":"declared","rate":60,"samples":1,"stretched":[{bone},{bone}],"non_uniform":[],"mirrored":[],"degenerate":[],"sketch":{sketch}}}]}}"#
    );
    let lines = dir.path().join("odd.jsonl");
    std::fs::write(&lines, format!("{line}\n")).unwrap();
    let out = bonescope(&["report", lines.to_str().unwrap(), "--format", "html"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let page = String::from_utf8(out.stdout).unwrap();
    assert!(page.contains("odd&lt;&amp;&gt;.glb") && !page.contains("odd<&>"), "names are escaped");
    assert!(page.contains("<svg") && page.ends_with("</html>"));
}

/// Debian's Chromium, where installed (`.ci/run` installs it); `None`, saying the calling test is skipped, where not.
fn chromium() -> Option<PathBuf> {
    let found = ["chromium", "chromium-browser"].iter().find_map(|name| {
        let ok = Command::new(name).arg("--version").output().is_ok_and(|o| o.status.success());
        ok.then(|| PathBuf::from(name))
    });
    if found.is_none() {
        eprintln!("skipped: no Chromium (Debian's package `chromium`; .ci/run installs it)");
    }
    found
}

/// Chromium, headless, on `url` with `args`: what it printed to standard output and standard error.
fn headless(chromium: &Path, url: &str, args: &[&str]) -> (String, String) {
    let out = Command::new(chromium)
        .args(["--headless", "--no-sandbox", "--disable-gpu", "--hide-scrollbars", "--enable-logging=stderr", "--v=0"])
        .args(["--window-size=1280,800", "--virtual-time-budget=2000"])
        .args(args)
        .arg(url)
        .output()
        .expect("chromium runs");
    (String::from_utf8_lossy(&out.stdout).into_owned(), String::from_utf8_lossy(&out.stderr).into_owned())
}

/// In a real browser: the page loads without a console message, sorting by worst shear puts the squash-and-stretch
/// rig's forearm first, by file puts the files in order, a filter hides the other rows, and at 1280×800 it looks
/// as the reference image does (looked at; `UPDATE_SNAPSHOTS=1` writes it anew).
#[test]
fn in_chromium_the_page_loads_cleanly_sorts_filters_and_looks_as_it_should() {
    let Some(chromium) = chromium() else { return };
    let dir = tempfile::tempdir().unwrap();
    let (lines, _) = scanned(dir.path());
    let html = dir.path().join("report.html");
    std::fs::write(&html, report(&lines, "html", &[])).unwrap();
    let url = format!("file://{}", html.display());
    let (dom, log) = headless(&chromium, &format!("{url}#sort=worst"), &["--dump-dom"]);
    let console: Vec<&str> = log.lines().filter(|l| l.contains("CONSOLE") || l.contains("Uncaught")).collect();
    assert!(console.is_empty(), "console: {console:?}");
    let sorted = rows(&dom);
    assert!(sorted[0].contains("class=\"refused\""));
    assert_eq!(attribute(sorted[1], "data-file"), "../shared/assets/blender/stretchy_full.glb");
    let first_bone = &sorted[1][sorted[1].find("<b>").unwrap() + 3..sorted[1].find("</b>").unwrap()];
    assert_eq!(first_bone, "forearm");
    let (dom, _) = headless(&chromium, &format!("{url}#sort=file"), &["--dump-dom"]);
    let files: Vec<String> = rows(&dom).iter().map(|r| attribute(r, "data-file").to_owned()).collect();
    assert!(files.windows(2).all(|w| w[0] <= w[1]), "{files:?}");
    let shown = |dom: &str| rows(dom).into_iter().filter(|r| !r.contains(" hidden")).count();
    let (dom, _) = headless(&chromium, &format!("{url}#filter=air_jump"), &["--dump-dom"]);
    assert_eq!(shown(&dom), 2, "the mannequin's two air-jump clips");
    // It opens on the problems (the refused file and the 10 clips with a stretched bone); all 13 rows on request.
    assert_eq!(shown(&headless(&chromium, &url, &["--dump-dom"]).0), 11);
    assert_eq!(shown(&headless(&chromium, &format!("{url}#stretched=0"), &["--dump-dom"]).0), 13);
    let screenshot = dir.path().join("page.png");
    headless(&chromium, &url, &[&format!("--screenshot={}", screenshot.display())]);
    looks_as_the_reference(&screenshot, "report_page");
}

/// How far a channel may differ before a pixel counts as changed, and the share of changed pixels a screenshot may
/// hold: text antialiasing moves a few edge pixels between runs, a changed layout moves thousands.
const CHANNEL_TOLERANCE: u8 = 24;
const CHANGED_SHARE: f64 = 0.005;

/// `screenshot` against `assets/readme/NAME.png`, the README's picture (written where `UPDATE_SNAPSHOTS` is set, or
/// where there is none).
fn looks_as_the_reference(screenshot: &Path, name: &str) {
    let reference = Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("assets/readme/{name}.png"));
    if std::env::var_os("UPDATE_SNAPSHOTS").is_some() || !reference.exists() {
        std::fs::copy(screenshot, &reference).unwrap();
        eprintln!("wrote {}: look at it", reference.display());
        return;
    }
    let (got, want) = (image::open(screenshot).unwrap().to_rgb8(), image::open(&reference).unwrap().to_rgb8());
    assert_eq!(got.dimensions(), want.dimensions(), "{name}: the screenshot's size");
    let changed = got
        .pixels()
        .zip(want.pixels())
        .filter(|(a, b)| a.0.iter().zip(b.0).any(|(x, y)| x.abs_diff(y) > CHANNEL_TOLERANCE))
        .count();
    let share = changed as f64 / f64::from(got.width() * got.height());
    if share > CHANGED_SHARE {
        let kept = reference.with_extension("new.png");
        std::fs::copy(screenshot, &kept).unwrap();
        panic!("{name}: {:.2} % of the pixels changed; the new screenshot is {}", 100.0 * share, kept.display());
    }
}
