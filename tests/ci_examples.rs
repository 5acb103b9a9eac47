//! The CI examples of `.ci/examples` as their CI systems would take them: what keeps a broken file from hiding the
//! report (the scan steps and pods succeed with its error recorded; the report runs whatever the scans did), what
//! bounds the pods, and their exact `scan` and `report` command lines, run by the shell on a few shared assets and
//! one broken file; and the README's short CI lines, as a `set -e` job runs them.

mod common;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use bonescope::import::Format;
use common::asset;
use yaml_rust2::{Yaml, YamlLoader};

/// The documents of the example `name`.
fn example(name: &str) -> Vec<Yaml> {
    YamlLoader::load_from_str(&example_text(name)).unwrap()
}

fn example_text(name: &str) -> String {
    std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join(".ci/examples").join(name)).unwrap()
}

fn text(yaml: &Yaml) -> &str {
    yaml.as_str().unwrap_or_else(|| panic!("a string, got {yaml:?}"))
}

fn list(yaml: &Yaml) -> &[Yaml] {
    yaml.as_vec().map_or(&[], Vec::as_slice)
}

/// The library the examples scan, in a temporary folder: a file of each format the shared assets have (symbolic
/// links), and `broken.fbx`, which does not load.
fn library() -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    let exports = dir.path().join("exports");
    std::fs::create_dir_all(exports.join("props")).unwrap();
    for file in [
        "blender/stretchy_full.glb",
        "blender/stretchy_full.fbx",
        "gltf-khronos/SimpleSkin.gltf",
        "bvh/bvh_test2.bvh",
        "usd-openusd/usdSkel/doxygen/skinnedArm.usda",
    ] {
        let link = exports.join(Path::new(file).file_name().unwrap());
        std::os::unix::fs::symlink(asset(file), link).unwrap();
    }
    std::fs::write(exports.join("props/broken.fbx"), b"Kaydara FBX Binary  \0not the rest of an FBX").unwrap();
    dir
}

/// The animation files of [`library`]: its links and the broken file.
const LIBRARY_FILES: usize = 6;

/// Runs `script` with `shell` in `dir`, the `bonescope` under test first on the PATH, with `env`.
fn run_script(shell: &[&str], script: &str, dir: &Path, env: &[(String, String)]) -> Output {
    let bin = Path::new(env!("CARGO_BIN_EXE_bonescope")).parent().unwrap();
    let path = format!("{}:{}", bin.display(), std::env::var("PATH").unwrap_or_default());
    let output = Command::new(shell[0])
        .args(&shell[1..])
        .arg(script)
        .current_dir(dir)
        .env("PATH", path)
        .envs(env.iter().cloned())
        .output()
        .unwrap();
    println!("$ {script}{}", String::from_utf8_lossy(&output.stderr));
    output
}

/// The JSON lines a scan wrote to `path`.
fn records(path: &Path) -> Vec<serde_json::Value> {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    text.lines().map(|line| serde_json::from_str(line).unwrap()).collect()
}

/// What the shards wrote (`scan-*.jsonl` in `dir`, `expected` of them) holds every file of [`library`] once and the
/// broken file's error; the report's verdict (`code`) is 2, naming the broken file, and its JUnit file has the error.
fn assert_reported(dir: &Path, expected: usize, code: Option<i32>, stderr: &str, junit: &Path) {
    let shards: Vec<PathBuf> = (std::fs::read_dir(dir).unwrap())
        .map(|entry| entry.unwrap().path())
        .filter(|path| path.file_name().unwrap().to_string_lossy().starts_with("scan-"))
        .collect();
    assert_eq!(shards.len(), expected, "every shard wrote its lines: {shards:?}");
    let all: Vec<serde_json::Value> = shards.iter().flat_map(|path| records(path)).collect();
    assert_eq!(all.len(), LIBRARY_FILES, "{all:?}");
    let errors: Vec<&str> = all.iter().filter_map(|record| record["error"].as_str()).collect();
    assert!(errors.len() == 1 && errors[0].contains("broken.fbx"), "{errors:?}");
    assert_eq!(code, Some(2), "a file did not load: {stderr}");
    assert!(stderr.lines().any(|line| line.starts_with("error: ") && line.contains("broken.fbx")), "{stderr}");
    let junit = std::fs::read_to_string(junit).unwrap();
    assert!(junit.contains("<error") && junit.contains("broken.fbx"), "{junit}");
}

/// What bonescope's `.cargo/config.toml` sets `name` to in its `[env]`.
fn cargo_config_env(name: &str) -> String {
    let config = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join(".cargo/config.toml")).unwrap();
    let line = config.lines().find_map(|line| line.strip_prefix(&format!("{name} = "))).unwrap();
    line.trim_matches('"').to_owned()
}

/// The values a shell script gives `option` (`--include '*.fbx'`: `*.fbx`).
fn option_values<'a>(script: &'a str, option: &str) -> Vec<&'a str> {
    let words: Vec<&str> = script.split_whitespace().collect();
    words.windows(2).filter(|w| w[0] == option).map(|w| w[1].trim_matches(['\'', '"'])).collect()
}

/// The lines the README shows for CI (its first `sh` block after `## In CI`), which docs/ci.md shows too.
fn readme_ci_lines() -> String {
    let readme = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("README.md")).unwrap();
    let section = readme.split("\n## In CI\n").nth(1).expect("the README has a section `In CI`");
    section.split("```sh\n").nth(1).and_then(|block| block.split("```").next()).unwrap().to_owned()
}

/// The README's CI lines in a `set -e` shell: each machine's `scan` line (`$K` of the shards it names) records the
/// broken file and succeeds, then the report's lines give the JUnit file and the verdict 2; a folder with no
/// animation file fails the scan line.
#[test]
fn the_readmes_ci_lines_record_a_broken_file_in_a_set_e_job() {
    let lines = readme_ci_lines();
    let ci_page = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/ci.md")).unwrap();
    assert!(ci_page.contains(&lines), "docs/ci.md shows the README's CI lines");
    let (scan, report): (Vec<&str>, Vec<&str>) =
        lines.lines().filter(|line| !line.starts_with('#')).partition(|line| line.contains("bonescope scan"));
    let shards: usize = option_values(&scan.join(" "), "--shard")[0].split('/').nth(1).unwrap().parse().unwrap();
    const SET_E: &[&str] = &["bash", "-e", "-c"];
    let workspace = library();
    let dir = workspace.path();
    for k in 1..=shards {
        let output = run_script(SET_E, &scan.join("\n"), dir, &[("K".to_owned(), k.to_string())]);
        assert!(output.status.success(), "shard {k}: {}", String::from_utf8_lossy(&output.stderr));
    }
    let verdict = run_script(SET_E, &report.join("\n"), dir, &[]);
    let stderr = String::from_utf8_lossy(&verdict.stderr);
    assert_reported(dir, shards, verdict.status.code(), &stderr, &dir.join("bonescope.xml"));
    let empty = tempfile::tempdir().unwrap();
    std::fs::create_dir(empty.path().join("exports")).unwrap();
    let output = run_script(SET_E, &scan.join("\n"), empty.path(), &[("K".to_owned(), "1".to_owned())]);
    assert_eq!(output.status.code(), Some(1), "the scan line fails on an empty folder");
    assert_eq!(String::from_utf8_lossy(&output.stderr), "error: no animation files under exports\n");
}

mod github {
    use super::*;

    /// GitHub's shell for `run:` on Linux.
    const BASH: &[&str] = &["bash", "--noprofile", "--norc", "-eo", "pipefail", "-c"];

    fn steps(job: &Yaml) -> &[Yaml] {
        list(&job["steps"])
    }

    /// The step of `job` that uses the action `name` (`actions/upload-artifact`).
    fn uses<'a>(job: &'a Yaml, name: &str) -> Vec<&'a Yaml> {
        let of = |step: &&Yaml| step["uses"].as_str().is_some_and(|u| u.starts_with(&format!("{name}@")));
        steps(job).iter().filter(of).collect()
    }

    fn scripts(job: &Yaml) -> Vec<&str> {
        steps(job).iter().filter_map(|step| step["run"].as_str()).collect()
    }

    /// Whether `condition` (an `if:`) holds after a failed or skipped job or step, cancelled runs aside.
    fn runs_after_failure(condition: &Yaml) -> bool {
        condition.as_str().is_some_and(|c| c.contains("!cancelled()") || c.contains("always()"))
    }

    /// The variables of `env:` mappings, for the shell.
    fn variables(maps: &[&Yaml]) -> Vec<(String, String)> {
        let entries = maps.iter().filter_map(|map| map.as_hash()).flatten();
        entries.map(|(k, v)| (text(k).to_owned(), text(v).to_owned())).collect()
    }

    #[test]
    fn the_workflow_builds_once_and_reports_whatever_the_scans_found() {
        let workflow = &example("github-actions-scan.yml")[0];
        let jobs = &workflow["jobs"];
        let (build, scan, report) = (&jobs["build"], &jobs["scan"], &jobs["report"]);
        // One build, cached, with what .cargo/config.toml sets (`cargo install --git` does not read it).
        let cache = [uses(build, "actions/cache"), uses(build, "Swatinem/rust-cache")].concat();
        assert_eq!(cache.len(), 1, "the build is cached");
        assert!(scripts(build).iter().any(|s| s.contains("cargo install")));
        assert_eq!(text(&build["env"]["CFLAGS"]), cargo_config_env("CFLAGS"));
        assert_eq!(text(&uses(build, "actions/upload-artifact")[0]["with"]["name"]), "bonescope");
        for job in [scan, report] {
            assert!(scripts(job).iter().all(|s| !s.contains("cargo ")), "no job but build compiles");
            let downloads = uses(job, "actions/download-artifact");
            assert!(downloads.iter().any(|d| d["with"]["name"].as_str() == Some("bonescope")), "{downloads:?}");
        }
        assert_eq!(text(&scan["needs"]), "build");
        // The shard's lines are uploaded, and the report made, whatever a scan step did.
        let upload = uses(scan, "actions/upload-artifact");
        assert!(upload.len() == 1 && runs_after_failure(&upload[0]["if"]), "{upload:?}");
        assert!(list(&report["needs"]).iter().any(|need| text(need) == "scan"));
        assert!(runs_after_failure(&report["if"]), "{:?}", report["if"]);
        // Every animation format bonescope reads passes the scan's --include globs.
        let script = scripts(scan).into_iter().find(|s| s.contains("bonescope scan")).unwrap();
        let globs: Vec<glob::Pattern> =
            option_values(script, "--include").iter().map(|g| glob::Pattern::new(g).unwrap()).collect();
        for extension in Format::every_extension() {
            let name = format!("walk.{}", extension.to_uppercase());
            let options = glob::MatchOptions { case_sensitive: false, ..glob::MatchOptions::new() };
            assert!(globs.iter().any(|g| g.matches_with(&name, options)), "--include leaves out .{extension}");
        }
    }

    /// Every `run:` step of the scan jobs (each shard's, with the bonescope artifact where the download puts it),
    /// then of the report job, in one workspace: the lines of all shards, the report's verdict and JUnit file.
    #[test]
    fn the_scan_and_report_steps_record_a_broken_file_and_fail_the_report() {
        let workflow = &example("github-actions-scan.yml")[0];
        let (scan, report) = (&workflow["jobs"]["scan"], &workflow["jobs"]["report"]);
        let workspace = library();
        let dir = workspace.path();
        std::fs::create_dir(dir.join("bin")).unwrap();
        std::os::unix::fs::symlink(env!("CARGO_BIN_EXE_bonescope"), dir.join("bin/bonescope")).unwrap();
        let env = |job: &Yaml| {
            let mut env = variables(&[&workflow["env"], &job["env"]]);
            env.push(("GITHUB_PATH".to_owned(), dir.join("github_path").display().to_string()));
            env.push(("GITHUB_STEP_SUMMARY".to_owned(), dir.join("step_summary.md").display().to_string()));
            env
        };
        let shards: Vec<i64> = list(&scan["strategy"]["matrix"]["shard"]).iter().map(|s| s.as_i64().unwrap()).collect();
        for shard in &shards {
            for script in scripts(scan) {
                let script = script.replace("${{ matrix.shard }}", &shard.to_string());
                assert!(!script.contains("${{"), "an expression left in {script}");
                let output = run_script(BASH, &script, dir, &env(scan));
                assert!(
                    output.status.success(),
                    "shard {shard}: {script}: {}",
                    String::from_utf8_lossy(&output.stderr)
                );
            }
        }
        let mut last = None;
        for script in scripts(report) {
            assert!(!script.contains("${{"), "an expression left in {script}");
            last = Some(run_script(BASH, script, dir, &env(report)));
        }
        let verdict = last.expect("the report job runs a script");
        let stderr = String::from_utf8_lossy(&verdict.stderr);
        assert_reported(dir, shards.len(), verdict.status.code(), &stderr, &dir.join("bonescope.xml"));
        // The page, uploaded whatever the verdict, and the job summary that points to it.
        let page = std::fs::read_to_string(dir.join("bonescope-report.html")).unwrap();
        assert!(
            page.starts_with("<!DOCTYPE html>") && page.contains("class=\"refused\""),
            "the page lists the broken file"
        );
        let upload = uses(report, "actions/upload-artifact");
        assert!(upload.len() == 1 && runs_after_failure(&upload[0]["if"]), "{upload:?}");
        assert_eq!(text(&upload[0]["with"]["path"]), "bonescope-report.html");
        let summary = std::fs::read_to_string(dir.join("step_summary.md")).unwrap();
        assert!(summary.starts_with("## bonescope: fail (exit 2): 1 file could not be read"), "{summary}");
        assert!(summary.contains(text(&upload[0]["with"]["name"])), "the summary names the page's artifact");
    }
}

mod kubernetes {
    use super::*;

    /// The document of `kind` named `name`.
    fn resource<'a>(documents: &'a [Yaml], kind: &str, name: &str) -> &'a Yaml {
        let of = |d: &&Yaml| d["kind"].as_str() == Some(kind) && d["metadata"]["name"].as_str() == Some(name);
        documents.iter().find(of).unwrap_or_else(|| panic!("no {kind} {name}"))
    }

    fn container(job: &Yaml) -> &Yaml {
        &job["spec"]["template"]["spec"]["containers"][0]
    }

    /// The container's command and arguments, as its process gets them.
    fn command_line(job: &Yaml) -> Vec<&str> {
        let container = container(job);
        list(&container["command"]).iter().chain(list(&container["args"])).map(text).collect()
    }

    /// A quantity of Kubernetes (`8Gi`, `512Mi`) in bytes.
    fn quantity(yaml: &Yaml) -> u64 {
        let text = text(yaml);
        bonescope::import::budget::parse_size(&format!("{}B", text.trim_end_matches('B'))).unwrap()
    }

    /// The claim a volume of `job` named `volume` mounts.
    fn claim<'a>(job: &'a Yaml, volume: &str) -> &'a str {
        let volumes = list(&job["spec"]["template"]["spec"]["volumes"]);
        let named = volumes.iter().find(|v| v["name"].as_str() == Some(volume)).unwrap();
        text(&named["persistentVolumeClaim"]["claimName"])
    }

    #[test]
    fn the_scan_pods_are_bounded_and_the_report_is_a_job_after_them() {
        let documents = example("kubernetes-indexed-job.yaml");
        let (scan, report) =
            (resource(&documents, "Job", "bonescope-scan"), resource(&documents, "Job", "bonescope-report"));
        // Each pod within its limits, with options that stay inside them: a file per CPU at once, each file's
        // budget such that all of them together leave room.
        let resources = &container(scan)["resources"];
        let script = command_line(scan).join(" ");
        let jobs: u64 = option_values(&script, "--jobs")[0].parse().unwrap();
        let budget = bonescope::import::budget::parse_size(option_values(&script, "--max-memory")[0]).unwrap();
        assert_eq!(jobs.to_string(), text(&resources["limits"]["cpu"]), "--jobs is the CPU limit");
        assert!(jobs * budget < quantity(&resources["limits"]["memory"]), "--jobs × --max-memory within the limit");
        // A broken file does not fail its pod (it is recorded for the report); exit 2 that does is never retried.
        let rules = list(&scan["spec"]["podFailurePolicy"]["rules"]);
        let exit_2 = rules.iter().find(|r| list(&r["onExitCodes"]["values"]).contains(&Yaml::Integer(2))).unwrap();
        assert!(["FailJob", "FailIndex"].contains(&text(&exit_2["action"])), "{exit_2:?}");
        assert!(scan["spec"]["backoffLimitPerIndex"].as_i64().is_some_and(|n| n <= 3));
        // One volume that all pods write and the report reads.
        let reports = claim(scan, "reports");
        let volume = resource(&documents, "PersistentVolumeClaim", reports);
        assert!(list(&volume["spec"]["accessModes"]).iter().any(|m| text(m) == "ReadWriteMany"));
        assert_eq!(claim(report, "reports"), reports);
        assert!(command_line(report).join(" ").contains("bonescope report"));
        assert_eq!(report["spec"]["backoffLimit"].as_i64(), Some(0), "a verdict is not retried");
        let sequence = "kubectl wait --for=condition=complete --timeout=6h job/bonescope-scan";
        assert!(example_text("kubernetes-indexed-job.yaml").contains(sequence), "the header says how to sequence");
    }

    /// Runs `job`'s container command in `dir`, its volumes' mount paths turned into the folders of `dir` named
    /// as the volumes, with `env`.
    fn run_job(job: &Yaml, dir: &Path, env: &[(String, String)]) -> Output {
        let mounts = list(&container(job)["volumeMounts"]);
        let paths: Vec<(&str, String)> =
            mounts.iter().map(|m| (text(&m["mountPath"]), dir.join(text(&m["name"])).display().to_string())).collect();
        let mounted = |arg: &str| paths.iter().fold(arg.to_owned(), |arg, (at, to)| arg.replace(at, to));
        let command: Vec<String> = command_line(job).into_iter().map(mounted).collect();
        let (script, shell) = command.split_last().unwrap();
        run_script(&shell.iter().map(String::as_str).collect::<Vec<_>>(), script, dir, env)
    }

    /// Every index of the scan Job, then the report Job, with the volumes `library` (the library) and `reports`
    /// (empty) in one temporary folder.
    #[test]
    fn every_pod_records_a_broken_file_and_the_report_fails_on_it() {
        let documents = example("kubernetes-indexed-job.yaml");
        let (scan, report) =
            (resource(&documents, "Job", "bonescope-scan"), resource(&documents, "Job", "bonescope-report"));
        let folder = library();
        let dir = folder.path();
        std::fs::rename(dir.join("exports"), dir.join("library")).unwrap();
        std::fs::create_dir(dir.join("reports")).unwrap();
        let completions = scan["spec"]["completions"].as_i64().unwrap();
        for index in 0..completions {
            let output = run_job(scan, dir, &[("JOB_COMPLETION_INDEX".to_owned(), index.to_string())]);
            assert!(output.status.success(), "index {index}: {}", String::from_utf8_lossy(&output.stderr));
        }
        let verdict = run_job(report, dir, &[]);
        let stderr = String::from_utf8_lossy(&verdict.stderr);
        let reports = dir.join("reports");
        assert_reported(&reports, completions as usize, verdict.status.code(), &stderr, &reports.join("bonescope.xml"));
    }
}
