//! Hostile and huge files never take bonescope down: every case of the generated corpus (`hostile/corpus.rs`) goes
//! through the built binary's `inspect` (table and JSON), `scan` (JSON with `--explain`, and JUnit) and `export`,
//! each under a 2 GiB address-space limit and a time limit; none may panic, abort, hang, print a number that is not
//! finite or an error that is not one escaped line naming the file and the place.

#[path = "hostile/corpus.rs"]
mod corpus;
#[path = "hostile/gltf.rs"]
mod gltf;
#[path = "hostile/usd.rs"]
mod usd;

use std::path::Path;
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

use bonescope::app::{BonescopeApp, Document, Settings};
use corpus::{Case, Expect};
use egui_kittest::kittest::Queryable;
use serde_json::Value;

/// The extensions of files a folder scan takes as animations.
const ANIMATION_EXTENSIONS: [&str; 8] = [".gltf", ".glb", ".fbx", ".bvh", ".usd", ".usda", ".usdc", ".usdz"];

/// The address space each run may take (`RLIMIT_AS`), in KiB as `ulimit -v` counts.
const ADDRESS_SPACE_KIB: u64 = 2 << 20;
/// Far above the 5 s a file under 64 MB may take, for a machine that runs other builds beside the test; a hang
/// still fails.
const TIME_LIMIT: Duration = Duration::from_secs(30);

/// One run of the binary: its output, and the command for messages.
struct Run {
    output: Output,
    what: String,
}

/// Runs `bonescope args` under the address-space and time limits (a run past the time limit is killed and fails).
fn bonescope(args: &[&str]) -> Run {
    let what = format!("bonescope {}", args.join(" "));
    let mut command = Command::new("sh");
    command
        .arg("-c")
        .arg(format!("ulimit -v {ADDRESS_SPACE_KIB} && exec \"$0\" \"$@\""))
        .arg(env!("CARGO_BIN_EXE_bonescope"))
        .args(args)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    let start = Instant::now();
    let mut child = command.spawn().expect("sh runs");
    // Outputs are read on threads so a large one cannot block the child while the clock runs.
    let mut stdout = child.stdout.take().unwrap();
    let mut stderr = child.stderr.take().unwrap();
    let out = std::thread::spawn(move || read_all(&mut stdout));
    let err = std::thread::spawn(move || read_all(&mut stderr));
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status;
        }
        if start.elapsed() > TIME_LIMIT {
            child.kill().unwrap();
            panic!("{what}: still running after {TIME_LIMIT:?} (a hang)");
        }
        std::thread::sleep(Duration::from_millis(5));
    };
    let output = Output { status, stdout: out.join().unwrap(), stderr: err.join().unwrap() };
    Run { output, what }
}

fn read_all(reader: &mut impl std::io::Read) -> Vec<u8> {
    let mut bytes = Vec::new();
    reader.read_to_end(&mut bytes).unwrap();
    bytes
}

/// Checks what every run must satisfy, whatever the case: exit 0 or 2 (not a signal, not a panic's 101), nothing on
/// standard error but whole, escaped lines, no stray control character on standard output.
fn check_run(run: &Run) -> Result<(), String> {
    let what = &run.what;
    let code =
        run.output.status.code().ok_or_else(|| format!("{what}: killed by a signal ({:?})", run.output.status))?;
    let stderr =
        String::from_utf8(run.output.stderr.clone()).map_err(|_| format!("{what}: standard error is not UTF-8"))?;
    if !matches!(code, 0 | 2) {
        return Err(format!("{what}: exit {code}: {stderr}"));
    }
    if stderr.contains("panicked") {
        return Err(format!("{what}: panicked: {stderr}"));
    }
    if let Some(c) = stderr.chars().find(|&c| c.is_control() && c != '\n') {
        return Err(format!("{what}: control character {c:?} on standard error: {stderr:?}"));
    }
    let stdout = String::from_utf8_lossy(&run.output.stdout);
    if let Some(c) = stdout.chars().find(|&c| c.is_control() && !matches!(c, '\n' | '\t')) {
        return Err(format!("{what}: control character {c:?} on standard output"));
    }
    Ok(())
}

/// The error line of a refusal: exactly one line, naming the file and holding `needle`.
fn check_refusal(run: &Run, file: &Path, needle: &str) -> Result<(), String> {
    let what = &run.what;
    let stderr = String::from_utf8_lossy(&run.output.stderr);
    let lines: Vec<&str> = stderr.lines().filter(|l| !l.starts_with("warning:")).collect();
    let name = escaped_name(file);
    match lines[..] {
        [line] if line.contains(&name) && line.contains(needle) => Ok(()),
        _ => Err(format!("{what}: expected one line naming `{name}` and `{needle}`, got {stderr:?}")),
    }
}

/// A file's name as bonescope prints it: control characters escaped.
fn escaped_name(file: &Path) -> String {
    file.file_name()
        .unwrap()
        .to_string_lossy()
        .chars()
        .map(|c| if c.is_control() { format!("\\x{:02x}", c as u32) } else { c.to_string() })
        .collect()
}

/// Numbers in JSON that are `null` where a number belongs: every `null` except under the keys that may be null.
fn json_nulls(value: &Value, key: &str, found: &mut Vec<String>) {
    const NULLABLE: &[&str] = &[
        "name",
        "parent",
        "animation",
        "blend",
        "additive",
        "crossfade",
        "shake",
        "error",
        "vertices",
        "first_flagged_time",
        "skin",
    ];
    match value {
        Value::Null if !NULLABLE.contains(&key) => found.push(key.to_owned()),
        Value::Array(items) => items.iter().for_each(|v| json_nulls(v, key, found)),
        Value::Object(map) => map.iter().for_each(|(k, v)| json_nulls(v, k, found)),
        _ => {}
    }
}

/// JSON output with no number that is not finite (serde_json writes those as `null`).
fn check_json(run: &Run) -> Result<(), String> {
    if !run.output.status.success() {
        return Ok(());
    }
    let text = String::from_utf8_lossy(&run.output.stdout);
    let value: Value = serde_json::from_str(&text).map_err(|e| format!("{}: not JSON: {e}", run.what))?;
    let mut nulls = Vec::new();
    json_nulls(&value, "", &mut nulls);
    if nulls.is_empty() { Ok(()) } else { Err(format!("{}: null numbers under {nulls:?}", run.what)) }
}

/// Text output (tables, OBJ) with no `NaN` or `inf`.
fn check_text(what: &str, text: &str) -> Result<(), String> {
    let bad = text.split(|c: char| c.is_whitespace() || c == ',').find(|w| {
        let w = w.trim_start_matches(['-', '+']);
        w.eq_ignore_ascii_case("nan") || w.eq_ignore_ascii_case("inf") || w.eq_ignore_ascii_case("infinity")
    });
    match bad {
        Some(word) => Err(format!("{what}: `{word}` printed")),
        None => Ok(()),
    }
}

/// The JUnit report parses as XML.
fn check_junit(run: &Run) -> Result<(), String> {
    let mut reader = quick_xml::Reader::from_reader(&run.output.stdout[..]);
    let mut buffer = Vec::new();
    loop {
        match reader.read_event_into(&mut buffer) {
            Ok(quick_xml::events::Event::Eof) => return Ok(()),
            Ok(quick_xml::events::Event::Text(text)) => {
                text.decode().map_err(|e| format!("{}: JUnit text does not decode: {e}", run.what))?;
            }
            Ok(_) => {}
            Err(e) => return Err(format!("{}: JUnit is not XML: {e}", run.what)),
        }
        buffer.clear();
    }
}

/// Every command on one case; what went wrong, if anything.
fn check_case(case: &Case, file: &Path, out: &Path) -> Vec<String> {
    let f = file.to_str().unwrap();
    let obj = out.join(format!("{}.obj", case.name));
    let runs = [
        (bonescope(&["inspect", f]), "table"),
        (bonescope(&["inspect", f, "--format", "json"]), "json"),
        (bonescope(&["scan", f, "--explain", "--format", "json"]), "json"),
        (bonescope(&["scan", f, "--format", "junit"]), "junit"),
        (bonescope(&["export", f, "--time", "0", "--format", "obj", "--out", obj.to_str().unwrap()]), "obj"),
    ];
    let mut problems = Vec::new();
    for (run, kind) in &runs {
        let mut checks = vec![check_run(run)];
        let scan = run.what.starts_with("bonescope scan");
        match *kind {
            "json" => checks.push(check_json(run)),
            "junit" => checks.push(check_junit(run)),
            "obj" if run.output.status.success() => {
                checks.push(check_text(&run.what, &std::fs::read_to_string(&obj).unwrap_or_default()))
            }
            _ => checks.push(check_text(&run.what, &String::from_utf8_lossy(&run.output.stdout))),
        }
        checks.push(check_expectation(case, file, run, scan));
        problems.extend(checks.into_iter().filter_map(Result::err));
    }
    problems
}

/// The run did what the case expects: loaded (with its note), or was refused in one line naming the place.
fn check_expectation(case: &Case, file: &Path, run: &Run, scan: bool) -> Result<(), String> {
    let code = run.output.status.code();
    let stderr = String::from_utf8_lossy(&run.output.stderr);
    if run.what.starts_with("bonescope export") && code == Some(2) && stderr.contains("no meshes to export") {
        // A rig without meshes loads, and has nothing to export.
        return if matches!(case.expect, Expect::Refused(_)) { Err(format!("{}: loaded", run.what)) } else { Ok(()) };
    }
    let budget = "the limit is";
    let refusal = |needle| {
        if code != Some(2) {
            return Err(format!("{}: expected a refusal (exit 2), got {code:?}", run.what));
        }
        if scan { Ok(()) } else { check_refusal(run, file, needle) }
    };
    match case.expect {
        Expect::Refused(needle) => refusal(needle),
        Expect::LoadsOrBudget if code == Some(2) => refusal(budget),
        Expect::Loads(_) | Expect::LoadsOrBudget if code != Some(0) => {
            Err(format!("{}: expected to load, exit {code:?}: {stderr}", run.what))
        }
        Expect::Loads(note) if !note.is_empty() && run.what.contains("--format json") && !scan => {
            let text = String::from_utf8_lossy(&run.output.stdout);
            if text.contains(note) { Ok(()) } else { Err(format!("{}: no note with `{note}`", run.what)) }
        }
        _ => Ok(()),
    }
}

#[test]
fn every_hostile_file_is_loaded_or_refused_in_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    std::fs::create_dir_all(&out).unwrap();
    let mut problems = Vec::new();
    let mut categories = std::collections::BTreeSet::new();
    for case in corpus::all() {
        categories.insert(case.category);
        let file = case.write(dir.path());
        let start = Instant::now();
        problems.extend(check_case(&case, &file, &out));
        println!("{:<28} {:>8.2} s", case.name, start.elapsed().as_secs_f64());
    }
    assert_eq!(categories.into_iter().collect::<Vec<_>>(), [1, 2, 3, 4, 5, 6, 8]);
    assert!(problems.is_empty(), "{} problems:\n{}", problems.len(), problems.join("\n"));
}

/// The scan of one file alone, as JSON.
fn scan_alone(file: &Path) -> Value {
    let run = bonescope(&["scan", file.to_str().unwrap(), "--format", "json"]);
    check_run(&run).unwrap();
    serde_json::from_slice::<Vec<Value>>(&run.output.stdout).unwrap().remove(0)
}

#[test]
fn a_library_with_hostile_files_reports_every_file_and_the_others_as_alone() {
    let dir = tempfile::tempdir().unwrap();
    let library = dir.path().join("library");
    let mut expected = Vec::new();
    for case in corpus::all().into_iter().filter(|c| !c.huge) {
        let main = case.write(&library);
        // What a case writes beside its main file counts too where it is named as an animation (USD sublayers).
        let beside = case.entries.iter().map(|(name, _)| *name).filter(|&name| name != case.main);
        let animations = beside.filter(|name| ANIMATION_EXTENSIONS.iter().any(|e| name.ends_with(e)));
        expected.extend(animations.map(|name| library.join(case.name).join(name)));
        expected.push(main);
    }
    let good = library.join("good/walk.glb");
    std::fs::create_dir_all(good.parent().unwrap()).unwrap();
    std::fs::write(&good, corpus::good_gltf()).unwrap();
    std::fs::write(library.join("good/notes.txt"), "not an animation").unwrap();
    let renamed = library.join("good/take.txt");
    std::fs::write(
        &renamed,
        "HIERARCHY\nROOT r\n{\nOFFSET 0 0 0\nCHANNELS 1 Zrotation\n}\nMOTION\nFrames: 1\nFrame Time: 0.1\n5\n",
    )
    .unwrap();
    expected.extend([good.clone(), renamed]);
    expected.sort();

    let run = bonescope(&["scan", library.to_str().unwrap(), "--format", "json"]);
    check_run(&run).unwrap();
    assert_eq!(run.output.status.code(), Some(2), "hostile files are errors");
    let files: Vec<Value> = serde_json::from_slice(&run.output.stdout).unwrap();
    let mut scanned: Vec<&str> = files.iter().map(|f| f["file"].as_str().unwrap()).collect();
    scanned.sort();
    let expected: Vec<String> = expected
        .iter()
        .map(|p| {
            p.to_str()
                .unwrap()
                .chars()
                .map(|c| if c.is_control() { format!("\\x{:02x}", c as u32) } else { c.to_string() })
                .collect()
        })
        .collect();
    assert_eq!(scanned, expected, "every file named as an animation, or recognised; not the text or the buffers");
    // Every refusal is an error record, and the error lines on standard error are one per file that failed.
    let errors = files.iter().filter(|f| !f["error"].is_null()).count();
    let error_lines = String::from_utf8_lossy(&run.output.stderr).lines().filter(|l| l.starts_with("error:")).count();
    assert_eq!(error_lines, errors);
    let good_record = files.iter().find(|f| f["file"] == good.to_str().unwrap()).unwrap();
    assert!(good_record["error"].is_null());
    assert!(!good_record["animations"][0]["stretched"].as_array().unwrap().is_empty(), "the good file has findings");
    assert_eq!(good_record, &scan_alone(&good), "reported as alone");
}

#[test]
fn renders_of_hostile_files_finish_or_are_refused_in_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let names = ["gltf_names", "gltf_strip", "gltf_nan_position", "bvh_extra_row", "gltf_huge_scales", "fifo_file"];
    for case in corpus::all().into_iter().filter(|c| names.contains(&c.name)) {
        let file = case.write(dir.path());
        let png = dir.path().join(format!("{}.png", case.name));
        let run = bonescope(&["render", file.to_str().unwrap(), "--size", "160x120", "--out", png.to_str().unwrap()]);
        check_run(&run).unwrap();
        match case.expect {
            Expect::Refused(needle) => check_refusal(&run, &file, needle).unwrap(),
            _ => assert!(
                run.output.status.success() && png.exists(),
                "{}: {}",
                run.what,
                String::from_utf8_lossy(&run.output.stderr)
            ),
        }
    }
}

#[test]
fn option_values_that_would_overflow_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("walk.glb");
    std::fs::write(&file, corpus::good_gltf()).unwrap();
    let f = file.to_str().unwrap();
    let run = bonescope(&["inspect", f, "--shake", "node1", "--shake-param", "amplitude=1e308", "--format", "json"]);
    check_run(&run).unwrap();
    assert_eq!(run.output.status.code(), Some(2));
    // A usage error, as clap words them: the error on one line, then where to find help.
    let stderr = String::from_utf8_lossy(&run.output.stderr);
    let first = stderr.lines().next().unwrap_or_default();
    assert!(first.contains("amplitude must be a number from -1e6 to 1e6, got 1e308"), "{stderr}");
    // The largest amplitude allowed, on every bone below, at several times: every number finite.
    let run = bonescope(&[
        "inspect",
        f,
        "--shake",
        "node0",
        "--shake-param",
        "amplitude=1e6",
        "--shake-param",
        "attenuation=1e6",
        "--time",
        "0.3",
        "--time",
        "0.9",
        "--format",
        "json",
    ]);
    check_run(&run).unwrap();
    assert!(run.output.status.success());
    check_json(&run).unwrap();
}

#[test]
fn a_bvh_of_too_many_joints_is_refused_before_they_are_read() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("wide.bvh");
    // 10,000 joints and the root, 4 KiB each: 40 MiB.
    std::fs::write(&file, corpus::wide_bvh(10_000)).unwrap();
    let f = file.to_str().unwrap();
    let run = bonescope(&["inspect", f, "--max-memory", "32M"]);
    check_run(&run).unwrap();
    check_refusal(&run, &file, "needs ~39 MiB for 10001 joints; the limit is 32 MiB").unwrap();
    let run = bonescope(&["inspect", f, "--max-memory", "64M"]);
    assert!(run.output.status.success(), "{}", String::from_utf8_lossy(&run.output.stderr));
}

#[test]
fn the_memory_budget_refuses_with_its_figures_and_max_memory_sets_it() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("shared.glb");
    // 200 channels sharing one sampler of 100,000 keys: its translations decoded once (1,200,000 bytes), 800,000
    // bytes of key times and 201 bones of 4 KiB (823,296 bytes): 2,823,296 bytes, 2.7 MiB, the animation the
    // largest part.
    std::fs::write(&file, corpus::shared_sampler(200, 100_000)).unwrap();
    let f = file.to_str().unwrap();
    let run = bonescope(&["inspect", f, "--max-memory", "2M"]);
    check_run(&run).unwrap();
    check_refusal(&run, &file, "animations[0]: needs ~2.7 MiB for 200 channels of 20000000 keys in all").unwrap();
    assert!(String::from_utf8_lossy(&run.output.stderr).contains("the limit is 2.0 MiB (--max-memory)"));
    let run = bonescope(&["scan", f, "--max-memory", "32MiB"]);
    check_run(&run).unwrap();
    assert!(run.output.status.success(), "{}", String::from_utf8_lossy(&run.output.stderr));
    // A binary USD layer's arrays are charged from their headers' counts before they are read.
    let usdc = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/assets/blender/stretchy_full.usdc");
    let run = bonescope(&["inspect", usdc.to_str().unwrap(), "--max-memory", "20K"]);
    check_run(&run).unwrap();
    check_refusal(&run, &usdc, "for the arrays read from its layers; the limit is 20 KiB (--max-memory)").unwrap();
    let run = bonescope(&["inspect", usdc.to_str().unwrap(), "--max-memory", "1M"]);
    assert!(run.output.status.success(), "{}", String::from_utf8_lossy(&run.output.stderr));
}

/// How many frames the app may take to settle: the demo's whole-clip analysis, run beside the frames, shows a spinner
/// until it lands (about 20 frames here).
const ANALYSED: u64 = 200;

#[test]
fn the_app_keeps_its_document_through_every_refused_file() {
    let dir = tempfile::tempdir().unwrap();
    let good = dir.path().join("good.glb");
    std::fs::write(&good, corpus::good_gltf()).unwrap();
    let mut harness = egui_kittest::Harness::builder()
        .with_size(egui::vec2(1000.0, 700.0))
        .with_max_steps(ANALYSED)
        .build_eframe(|_cc| BonescopeApp::new(Settings::default(), Document::demo()));
    harness.state_mut().open(&good);
    harness.run();
    assert_eq!(harness.state().session.doc.path.as_deref(), Some(good.as_path()));
    let refused = corpus::all().into_iter().filter(|c| !c.huge && matches!(c.expect, Expect::Refused(_)));
    for case in refused {
        let file = case.write(dir.path());
        harness.state_mut().open(&file);
        harness.run();
        assert_eq!(
            harness.state().session.doc.path.as_deref(),
            Some(good.as_path()),
            "{}: the document stays",
            case.name
        );
    }
    // The latest refusals are shown (at most four notifications are): a pipe's, opened last.
    harness.state_mut().open(&dir.path().join("fifo_file/a.gltf"));
    harness.run();
    harness.get_by_label_contains("fifo_file/a.gltf: not a regular file");
    // A notification names a file whose name would retitle a terminal, escaped (in an app of its own: at most four
    // notifications are shown).
    let mut harness = egui_kittest::Harness::builder()
        .with_size(egui::vec2(1000.0, 700.0))
        .with_max_steps(ANALYSED)
        .build_eframe(|_cc| BonescopeApp::new(Settings::default(), Document::demo()));
    let evil = corpus::all().into_iter().find(|c| c.name == "file_name").unwrap().write(dir.path());
    harness.state_mut().open(&evil);
    harness.run();
    harness.get_by_label_contains("\\x1b]0;pwned\\x07\\x1b[2J.bvh: line 2");
}
