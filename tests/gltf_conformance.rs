//! The Khronos glTF-Validator's own test files as bonescope's glTF acceptance suite.
//!
//! Every file beside a `*.report.json` is run through `bonescope inspect FILE --time 0.5 --format json`, the
//! command a user runs first. A file the validator reports with no errors is valid glTF 2.0 and must load, with
//! every number in the report finite; any other file must load or exit 2 with one line naming the file. Nothing may
//! take more than a second or crash. The counts per area are printed (`cargo test --test gltf_conformance --
//! --nocapture`).

mod common;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

use common::asset;
use rayon::prelude::*;
use serde_json::Value;

fn corpus() -> PathBuf {
    asset("gltf-validator-tests")
}

/// One test file and the validator's verdict on it.
struct Case {
    file: PathBuf,
    /// The folder below the corpus, e.g. `base/data/accessor`.
    area: String,
    valid: bool,
}

fn cases() -> Vec<Case> {
    let mut reports = Vec::new();
    collect_reports(&corpus(), &mut reports);
    reports.sort();
    reports
        .into_iter()
        .map(|report| {
            let text = std::fs::read_to_string(&report).expect("a readable report");
            let verdict: Value = serde_json::from_str(&text).expect("a JSON report");
            let errors = verdict["issues"]["numErrors"].as_u64().expect("issues.numErrors");
            let file = report.with_file_name(report.file_name().unwrap().to_str().unwrap().replace(".report.json", ""));
            let area = file.parent().unwrap().strip_prefix(corpus()).unwrap().display().to_string();
            Case { file, area, valid: errors == 0 }
        })
        .collect()
}

fn collect_reports(folder: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(folder).expect("a readable folder") {
        let path = entry.expect("a folder entry").path();
        if path.is_dir() {
            collect_reports(&path, out);
        } else if path.to_str().is_some_and(|p| p.ends_with(".report.json")) {
            out.push(path);
        }
    }
}

/// What `inspect` did with a file.
enum Outcome {
    Loaded,
    /// Exit 2 with one line naming the file.
    Refused(String),
    /// Anything else: a crash, a non-finite number, an unnamed error, too slow.
    Broken(String),
}

const TIME_LIMIT: Duration = Duration::from_secs(1);

fn inspect(case: &Case) -> Outcome {
    let start = Instant::now();
    let output = Command::new(env!("CARGO_BIN_EXE_bonescope"))
        .args(["inspect", "--time", "0.5", "--format", "json"])
        .arg(&case.file)
        .output()
        .expect("bonescope runs");
    let elapsed = start.elapsed();
    let stderr = String::from_utf8_lossy(&output.stderr).trim().to_owned();
    if elapsed > TIME_LIMIT {
        return Outcome::Broken(format!("took {elapsed:?}"));
    }
    match output.status.code() {
        Some(0) => match serde_json::from_slice::<Value>(&output.stdout) {
            Ok(report) => match non_finite(&report, "") {
                Some(place) => Outcome::Broken(format!("a number that is not finite at {place}")),
                None => Outcome::Loaded,
            },
            Err(e) => Outcome::Broken(format!("output is not JSON: {e}")),
        },
        Some(2) if stderr.lines().count() == 1 && stderr.contains(&*case.file.to_string_lossy()) => {
            Outcome::Refused(stderr)
        }
        code => Outcome::Broken(format!("exit {code:?}: {stderr}")),
    }
}

/// The first place in `inspect`'s JSON where a number should be and is not: serde_json writes NaN and infinities
/// as `null`, and the only fields that may be null are the optional ones named here.
fn non_finite(value: &Value, place: &str) -> Option<String> {
    const OPTIONAL: &[&str] = &["parent", "name", "animation", "blend", "additive", "crossfade", "shake"];
    match value {
        Value::Null if !OPTIONAL.iter().any(|key| place.ends_with(&format!(".{key}"))) => Some(place.to_owned()),
        Value::Array(items) => items.iter().enumerate().find_map(|(i, v)| non_finite(v, &format!("{place}[{i}]"))),
        Value::Object(fields) => fields.iter().find_map(|(k, v)| non_finite(v, &format!("{place}.{k}"))),
        _ => None,
    }
}

#[derive(Default)]
struct Tally {
    valid_loaded: usize,
    valid: usize,
    invalid_loaded: usize,
    invalid_refused: usize,
}

#[test]
fn every_file_the_validator_accepts_loads_and_none_breaks() {
    let cases = cases();
    assert!(cases.len() >= 372, "the corpus has {} reports; is ../shared/assets there?", cases.len());
    let outcomes: Vec<Outcome> = cases.par_iter().map(inspect).collect();
    let mut tallies: BTreeMap<&str, Tally> = BTreeMap::new();
    let mut failures = Vec::new();
    for (case, outcome) in cases.iter().zip(&outcomes) {
        let tally = tallies.entry(&case.area).or_default();
        let name = case.file.strip_prefix(corpus()).unwrap().display();
        tally.valid += usize::from(case.valid);
        match (outcome, case.valid) {
            (Outcome::Loaded, true) => tally.valid_loaded += 1,
            (Outcome::Loaded, false) => tally.invalid_loaded += 1,
            (Outcome::Refused(_), false) => tally.invalid_refused += 1,
            (Outcome::Refused(why), true) => failures.push(format!("valid {name} refused: {why}")),
            (Outcome::Broken(why), _) => failures.push(format!("{name}: {why}")),
        }
    }
    println!("{:<58} {:>11} {:>16} {:>15}", "area", "valid", "invalid loaded", "invalid refused");
    for (area, t) in &tallies {
        let valid = format!("{}/{}", t.valid_loaded, t.valid);
        println!("{area:<58} {valid:>11} {:>16} {:>15}", t.invalid_loaded, t.invalid_refused);
    }
    let total = |f: fn(&Tally) -> usize| tallies.values().map(f).sum::<usize>();
    println!(
        "all: {} of {} valid files load; of {} invalid files {} load and {} are refused cleanly",
        total(|t| t.valid_loaded),
        total(|t| t.valid),
        cases.len() - total(|t| t.valid),
        total(|t| t.invalid_loaded),
        total(|t| t.invalid_refused)
    );
    assert!(failures.is_empty(), "{} files failed:\n{}", failures.len(), failures.join("\n"));
}

// ---------------------------------------------------------------------------------------------------------------
// The `gltf` crate as an independent reader

/// The files to compare: the shared sample assets and the validator's valid files.
fn oracle_files() -> Vec<PathBuf> {
    let assets = corpus().join("..");
    let samples = ["gltf-khronos", "blender"].into_iter().flat_map(|folder| {
        let entries = std::fs::read_dir(assets.join(folder)).expect("a shared asset folder");
        entries.map(|e| e.expect("a folder entry").path())
    });
    let valid = cases().into_iter().filter(|c| c.valid).map(|c| c.file);
    let mut files: Vec<PathBuf> =
        samples.filter(|p| p.extension().is_some_and(|e| e == "gltf" || e == "glb")).chain(valid).collect();
    files.sort();
    files
}

/// The buffers of a document the `gltf` crate parsed: the GLB blob, `data:` URIs, files beside it.
fn oracle_buffers(gltf: &gltf::Gltf, folder: &Path) -> Option<Vec<Vec<u8>>> {
    use base64::Engine as _;
    gltf.buffers()
        .map(|buffer| match buffer.source() {
            gltf::buffer::Source::Bin => gltf.blob.clone(),
            gltf::buffer::Source::Uri(uri) => match uri.split_once(";base64,") {
                Some((_, data)) => base64::engine::general_purpose::STANDARD.decode(data).ok(),
                None => std::fs::read(folder.join(uri)).ok(),
            },
        })
        .collect()
}

/// Compares every value bonescope read from `path` with the `gltf` crate's reading of the same file; `None` when
/// the crate refuses the file (it is stricter than the specification).
fn compare_with_the_gltf_crate(path: &Path) -> Option<usize> {
    let gltf = gltf::Gltf::open(path).ok()?;
    let buffers = oracle_buffers(&gltf, path.parent().unwrap())?;
    let rig = bonescope::import::load(path).unwrap_or_else(|e| panic!("{e}"));
    let data = |buffer: gltf::Buffer| buffers.get(buffer.index()).map(Vec::as_slice);
    let name = path.display();
    let mut compared = 0;
    let nodes: Vec<gltf::Node> = gltf.nodes().collect();
    // Meshes, in bonescope's order: bones parents first, each node's triangle primitives in file order.
    let primitives = rig
        .skeleton
        .bones()
        .iter()
        .filter_map(|bone| nodes[bone.node].mesh())
        .flat_map(|mesh| mesh.primitives().filter(|p| p.mode() == gltf::mesh::Mode::Triangles).collect::<Vec<_>>());
    for (mesh, primitive) in rig.meshes.iter().zip(primitives) {
        let reader = primitive.reader(data);
        let positions: Vec<glam::Vec3> = reader.read_positions()?.map(glam::Vec3::from_array).collect();
        assert_eq!(mesh.positions, positions, "{name}: positions of {}", mesh.name);
        if mesh.skin.is_some() {
            let joints: Vec<[u16; 4]> = reader.read_joints(0)?.into_u16().collect();
            // bonescope normalises weights that do not sum to 1, as glTF requires.
            let weights: Vec<[f32; 4]> = reader
                .read_weights(0)?
                .into_f32()
                .map(|w| bonescope::model::normalized_weights(w).unwrap_or(w))
                .collect();
            assert_eq!((&mesh.joints, &mesh.weights), (&joints, &weights), "{name}: skinning of {}", mesh.name);
        }
        compared += 1;
    }
    for (skin, ours) in gltf.skins().zip(&rig.skins) {
        let expected: Vec<glam::DMat4> = match skin.reader(data).read_inverse_bind_matrices() {
            Some(matrices) => matrices
                .take(ours.joints.len())
                .map(|m| glam::DMat4::from_cols_array_2d(&m.map(|c| c.map(f64::from))))
                .collect(),
            None => vec![glam::DMat4::IDENTITY; ours.joints.len()],
        };
        assert_eq!(ours.inverse_bind, expected, "{name}: skin {}", skin.index());
        compared += 1;
    }
    for (animation, clip) in gltf.animations().zip(&rig.clips) {
        for channel in animation.channels() {
            let Some(tracks) = rig.skeleton.find_node(channel.target().node().index()).and_then(|b| clip.tracks_of(b))
            else {
                continue;
            };
            let reader = channel.reader(data);
            let times: Vec<f64> = reader.read_inputs()?.map(f64::from).collect();
            let place = format!("{name}: animation {} channel {}", animation.index(), channel.index());
            use gltf::animation::util::ReadOutputs;
            let read_times = match reader.read_outputs()? {
                ReadOutputs::Translations(values) => {
                    let track = tracks.translation.as_ref().unwrap();
                    assert_eq!(track.values(), values.map(glam::Vec3::from_array).collect::<Vec<_>>(), "{place}");
                    track.times()
                }
                ReadOutputs::Scales(values) => {
                    let track = tracks.scale.as_ref().unwrap();
                    assert_eq!(track.values(), values.map(glam::Vec3::from_array).collect::<Vec<_>>(), "{place}");
                    track.times()
                }
                ReadOutputs::Rotations(values) => {
                    let track = tracks.rotation.as_ref().unwrap();
                    let values: Vec<glam::Quat> = values.into_f32().map(glam::Quat::from_array).collect();
                    assert_eq!(track.values(), values, "{place}");
                    track.times()
                }
                ReadOutputs::MorphTargetWeights(_) => continue,
            };
            assert_eq!(read_times, times, "{place}: key times");
            compared += 1;
        }
    }
    Some(compared)
}

#[test]
fn every_value_read_equals_the_gltf_crates_reading() {
    let files = oracle_files();
    let results: Vec<(PathBuf, Option<usize>)> =
        files.into_par_iter().map(|f| (f.clone(), compare_with_the_gltf_crate(&f))).collect();
    let compared: Vec<&(PathBuf, Option<usize>)> = results.iter().filter(|(_, n)| n.is_some()).collect();
    let values: usize = compared.iter().filter_map(|(_, n)| *n).sum();
    println!(
        "{} of {} files compared with the gltf crate ({values} meshes, skins and channels); it refuses the rest",
        compared.len(),
        results.len()
    );
    for sample in ["Fox.glb", "cesium_man.gltf", "interpolation_test.gltf", "stretchy_full.glb"] {
        assert!(compared.iter().any(|(p, _)| p.ends_with(sample)), "{sample} was not compared");
    }
    assert!(values >= 100, "only {values} values compared");
}
