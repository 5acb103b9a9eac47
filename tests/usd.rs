//! USD files as Pixar's own USD evaluates them: every joint's world transform at every time code of every shared
//! USD file equals what `usd-core`'s UsdSkel computes (`tests/usd/joint_transforms.py`) to 1e-6 of the model's size.

mod common;
#[path = "../benches/support/generated_gltf.rs"]
#[allow(dead_code)]
mod generated_gltf;

use std::io::{Read, Seek, SeekFrom};
use std::path::{Path, PathBuf};
use std::process::Command;

use bonescope::analysis::{BindTolerance, check_bind};
use bonescope::diff::{Pairs, compare, comparison_times};
use bonescope::eval::Evaluation;
use bonescope::import::{Options, Space, load_with};
use bonescope::model::Rig;
use common::{assets, usd_python};
use glam::DMat4;
use openusd::usdc::blocks::Blocks;
use serde_json::Value;

/// Every USD file of the shared assets, sorted.
fn usd_files() -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = walkdir::WalkDir::new(assets())
        .into_iter()
        .filter_map(Result::ok)
        .map(|e| e.into_path())
        .filter(|p| p.extension().is_some_and(|e| ["usd", "usda", "usdc", "usdz"].contains(&&*e.to_string_lossy())))
        .collect();
    files.sort();
    files
}

/// What `script` of `tests/usd/` finds of `file`, run by usd-core: the JSON it prints, and the numbers it writes
/// beside it (64-bit little-endian floats: every pose of a long clip, which as JSON would be hundreds of megabytes),
/// read `width` at a time.
fn usd_core(python: &Path, script: &str, file: &Path, width: usize) -> (Value, Numbers) {
    let numbers = tempfile::NamedTempFile::new().unwrap();
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/usd").join(script);
    let output = Command::new(python).arg(script).arg(file).arg(numbers.path()).output().expect("python runs");
    assert!(output.status.success(), "{}: {}", file.display(), String::from_utf8_lossy(&output.stderr));
    let reader = std::io::BufReader::new(std::fs::File::open(numbers.path()).unwrap());
    (serde_json::from_slice(&output.stdout).expect("JSON"), Numbers { reader, width })
}

/// Numbers a usd-core script wrote, read in groups of `width` (a matrix's 16, a point's 3).
struct Numbers {
    reader: std::io::BufReader<std::fs::File>,
    width: usize,
}

impl Iterator for Numbers {
    type Item = Vec<f64>;

    fn next(&mut self) -> Option<Vec<f64>> {
        let mut bytes = vec![0u8; 8 * self.width];
        self.reader.read_exact(&mut bytes).ok()?;
        Some(bytes.chunks_exact(8).map(|b| f64::from_le_bytes(b.try_into().unwrap())).collect())
    }
}

/// A row-vector USD matrix, flattened by rows, as a column-vector one.
fn matrix(numbers: &[f64]) -> DMat4 {
    DMat4::from_cols_slice(numbers)
}

#[test]
fn every_joint_is_where_usd_core_puts_it_at_every_time_code() {
    let Some(python) = usd_python() else { return };
    let mut compared = 0;
    for file in usd_files() {
        let rig = load_with(&file, &Options { space: Space::File }).unwrap_or_else(|e| panic!("{e}"));
        compared += joints_as_usd_core(&python, &file, &rig);
    }
    assert!(compared > 500, "{compared} skeleton poses compared");
}

#[test]
fn a_skeleton_under_a_moving_xform_moves_with_it() {
    // A character's Xform carried through a shot (translated and turned over time, its angles written as whole
    // numbers), its skeleton's spine turning too: the joints are where usd-core puts them at every time code. The
    // same animation bound where `SkelBindingAPI` is not applied plays for neither.
    let Some(python) = usd_python() else { return };
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("shot.usda");
    std::fs::write(
        &file,
        r#"#usda 1.0
(
    startTimeCode = 0
    endTimeCode = 10
    timeCodesPerSecond = 10
)
def Xform "Shot"
{
    double3 xformOp:translate.timeSamples = { 0: (0, 0, 0), 5: (2, 0, 1), 10: (4, 1, 0) }
    float xformOp:rotateY.timeSamples = { 0: 0, 10: 90 }
    uniform token[] xformOpOrder = ["xformOp:translate", "xformOp:rotateY"]
    def SkelRoot "Character"
    {
        def Skeleton "Skel" (
            prepend apiSchemas = ["SkelBindingAPI"]
        )
        {
            uniform token[] joints = ["hips", "hips/spine"]
            uniform matrix4d[] restTransforms = [((1, 0, 0, 0), (0, 1, 0, 0), (0, 0, 1, 0), (0, 1, 0, 1)), ((1, 0, 0, 0), (0, 1, 0, 0), (0, 0, 1, 0), (0, 0.5, 0, 1))]
            rel skel:animationSource = </Shot/Character/Skel/Anim>
            def SkelAnimation "Anim"
            {
                uniform token[] joints = ["hips/spine"]
                float3[] translations = [(0, 0.5, 0)]
                quatf[] rotations.timeSamples = { 0: [(1, 0, 0, 0)], 10: [(0.70710677, 0, 0, 0.70710677)] }
                half3[] scales = [(1, 1, 1)]
            }
        }
    }
}
"#,
    )
    .unwrap();
    let rig = load_with(&file, &Options { space: Space::File }).unwrap();
    assert_eq!(joints_as_usd_core(&python, &file, &rig), 11, "every time code");
    let text = std::fs::read_to_string(&file).unwrap();
    std::fs::write(&file, text.replace("prepend apiSchemas = [\"SkelBindingAPI\"]", "")).unwrap();
    let rig = load_with(&file, &Options { space: Space::File }).unwrap();
    assert_eq!(joints_as_usd_core(&python, &file, &rig), 11);
    assert!(rig.clips[0].tracks().iter().all(|t| t.bone == 0), "only the skeleton's node moves");
}

/// Compares every joint's world transform in `rig` (loaded from `file` in its own space) with usd-core's
/// (`tests/usd/joint_transforms.py`) at every time code; how many skeleton poses were compared.
fn joints_as_usd_core(python: &Path, file: &Path, rig: &Rig) -> usize {
    let (reference, mut matrices) = usd_core(python, "joint_transforms.py", file, 16);
    let rate = reference["time_codes_per_second"].as_f64().unwrap();
    let evaluation = Evaluation::declared(rig, rig.clips.first());
    // A time code `c` is at `c / rate` on the stage's clock; an attribute's default value holds from its start.
    let start = evaluation.span().start;
    let size = evaluation.size(&evaluation.times(rate));
    // bonescope normalises rotation keys, as engines do; UsdSkel makes a matrix of the quaternion as authored
    // (Pixar's test arm writes (0.7071, 0.7071, 0, 0), 1.5e-6 short): that much more is allowed, per unit.
    let off_unit = rig.clips.iter().flat_map(|c| c.tracks()).filter_map(|t| t.rotation.as_ref());
    let off_unit =
        off_unit.flat_map(|r| r.values().iter()).fold(0.0f64, |m, q| m.max(f64::from((q.length() - 1.0).abs())));
    let tolerance = (1e-6 + 4.0 * off_unit) * size;
    // Each skeleton's bones: its node, then its joints in their order.
    let (mut bone, mut compared) = (0, 0);
    for skeleton in reference["skeletons"].as_array().unwrap() {
        let joints = skeleton["joints"].as_array().unwrap().len();
        assert_eq!(rig.skeleton.bone(bone).name, skeleton["path"].as_str().unwrap().rsplit('/').next().unwrap());
        for code in skeleton["time_codes"].as_array().unwrap() {
            let time = code.as_f64().map_or(start, |code| code / rate);
            let pose = evaluation.pose_at(time).model.model;
            for j in 0..joints {
                let (ours, theirs) = (pose[bone + 1 + j], matrix(&matrices.next().expect("a matrix per joint")));
                let apart = (ours - theirs).to_cols_array().iter().fold(0.0f64, |m, v| m.max(v.abs()));
                assert!(
                    apart <= tolerance,
                    "{}: joint {j} of {} at {time} s: {apart} apart (size {size})\nours {ours}\ntheirs {theirs}",
                    file.display(),
                    skeleton["path"]
                );
            }
            compared += 1;
        }
        bone += 1 + joints;
    }
    assert!(matrices.next().is_none(), "{}: usd-core wrote matrices for no joint", file.display());
    compared
}

/// The worst shear of `bone` over the first clip of `file`, and when, as `scan` finds it.
fn worst_shear(file: &str, bone: &str) -> (f64, f64) {
    let rig = common::load_asset(file);
    let evaluation = Evaluation::declared(&rig, rig.clips.first());
    let options = bonescope::analysis::ScanOptions::default();
    let scan = bonescope::analysis::scan(&evaluation, &options, &|_, _| {});
    let summary = &scan.bones[rig.skeleton.find(bone).unwrap()];
    (summary.worst_shear_deg, summary.worst_shear_time)
}

#[test]
fn blenders_usd_export_shears_as_its_gltf_export_and_both_encodings_agree() {
    // Blender's USD export samples every frame; its glTF export keys the same curves as cubic splines: the forearm's
    // worst shear is the same within what the two samplings make of it (18.77° at time code 17 as usd-core computes
    // it, 17/30 s on the stage's own clock; 18.66° at 0.55 s from the glTF's cubic keys, the same frame's
    // neighbourhood on its clock).
    let (usd, usd_time) = worst_shear("blender/stretchy_full.usdc", "forearm");
    let (gltf, _) = worst_shear("blender/stretchy_full.glb", "forearm");
    assert!((usd - 18.768).abs() < 1e-3 && (usd_time - 17.0 / 30.0).abs() < 1e-9, "{usd}° at {usd_time} s");
    assert!((usd - gltf).abs() < 0.15, "USD {usd}°, glTF {gltf}°");
    for name in ["stretchy_full", "stretchy_noinherit"] {
        let [text, binary] = ["usda", "usdc"].map(|ext| worst_shear(&format!("blender/{name}.{ext}"), "forearm"));
        assert_eq!(text, binary, "{name}: the text and binary encodings hold the same numbers");
    }
}

#[test]
fn skinned_and_blend_shaped_points_are_pixars_baked_ones() {
    // Pixar's own tests bake their skinning and blend shapes with `UsdSkel.BakeSkinning` into
    // `baseline/*.baked.usda`; Blender's exports are baked here the same way (`tests/usd/bake_skinning.py`). The points
    // bonescope deforms from the unbaked file are those, in the world, at every time code. (`GroundTruth` is Pixar's
    // expected result written as animated points, a point cache bonescope reads at the start only: not compared.)
    let Some(python) = usd_python() else { return };
    let folder = common::asset("usd-openusd/usdSkel/testenv/testUsdSkelBakeSkinning");
    let mut pairs: Vec<(PathBuf, PathBuf)> = ["lbs", "dqs", "blendshapes", "blendshapesWithNormals"]
        .iter()
        .map(|name| (folder.join(format!("{name}.usda")), folder.join(format!("baseline/{name}.baked.usda"))))
        .collect();
    let baked = tempfile::tempdir().unwrap();
    for name in ["stretchy_full.usdc", "stretchy_noinherit.usda"] {
        let (file, out) = (common::asset(&format!("blender/{name}")), baked.path().join(format!("{name}.baked.usda")));
        let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/usd/bake_skinning.py");
        let status = Command::new(&python).arg(script).arg(&file).arg(&out).status().expect("python runs");
        assert!(status.success(), "usd-core baked {name}");
        pairs.push((file, out));
    }
    for (file, baked) in pairs {
        let compared = points_as_baked(&python, &file, &baked);
        assert!(compared > 1000, "{}: {compared} points compared", file.display());
    }
}

/// Compares every point bonescope deforms from `file` with usd-core's world points of `baked`
/// (`tests/usd/world_points.py`) at every time code, to 1e-5 of the model's size; how many were compared.
fn points_as_baked(python: &Path, file: &Path, baked: &Path) -> usize {
    let rig = load_with(file, &Options { space: Space::File }).unwrap();
    let (baked, mut points) = usd_core(python, "world_points.py", baked, 3);
    let clip = rig.clips.first();
    let rate = clip.map(|c| c.frame_rate()).unwrap_or(24.0);
    let evaluation = Evaluation::declared(&rig, clip);
    let size = evaluation.size(&evaluation.times(rate));
    let mut compared = 0;
    // bonescope's meshes are the stage's, in its traversal order.
    for (mesh, baked_mesh) in baked["meshes"].as_array().unwrap().iter().enumerate() {
        let path = baked_mesh["path"].as_str().unwrap();
        // A mesh is named as its prim, or as a bake's `customData` keeps its name (its prim the name as USD spells it).
        let name = &rig.meshes[mesh].name;
        assert!(
            [name.clone(), bonescope::diff::usd_identifier(name)].iter().any(|n| path.ends_with(&format!("/{n}"))),
            "{path}"
        );
        let count = baked_mesh["points"].as_u64().unwrap() as usize;
        for code in baked["time_codes"].as_array().unwrap() {
            let code = code.as_f64().unwrap();
            let theirs: Vec<Vec<f64>> = points.by_ref().take(count).collect();
            assert_eq!(theirs.len(), count, "{path} at code {code}: usd-core's points end early");
            if path.starts_with("/GroundTruth") {
                continue;
            }
            let pose = evaluation.pose_at(code / rate);
            let mut ours = Vec::new();
            evaluation.skin(&pose, mesh, &mut ours);
            assert_eq!(ours.len(), count, "{}: {path}: bonescope's vertices and usd-core's points", file.display());
            for (v, theirs) in theirs.iter().enumerate() {
                let apart = (ours[v] - glam::DVec3::from_slice(theirs)).length();
                assert!(
                    apart <= 1e-5 * size,
                    "{}: {path} vertex {v} at code {code}: {apart} apart ({size})",
                    file.display()
                );
                compared += 1;
            }
        }
    }
    assert!(points.next().is_none(), "{}: usd-core wrote points for no mesh", file.display());
    compared
}

#[test]
fn a_bind_scaled_entry_by_entry_as_maya_usd_wrote_it_is_named_broken() {
    // Maya USD's `-unit m` export multiplied every entry of `bindTransforms` and `restTransforms` by the unit factor
    // (`tests/usd/unit_bug.py` writes Blender's scene so with usd-core): the bind check names every weighted joint's
    // bind as no rigid transform, the import notes both attributes, and `diff` against the file written right shows
    // the skin scrambled while every bone is where it was.
    let Some(python) = usd_python() else { return };
    let dir = tempfile::tempdir().unwrap();
    let (good, bad) = (common::asset("blender/stretchy_full.usda"), dir.path().join("unit_m.usda"));
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/usd/unit_bug.py");
    let status = Command::new(python).arg(script).arg(&good).arg(&bad).status().expect("python runs");
    assert!(status.success());
    let (good, bad) = (load_with(&good, &Options::default()).unwrap(), load_with(&bad, &Options::default()).unwrap());
    for attribute in ["restTransforms", "bindTransforms"] {
        let note = bad.notes.iter().find(|n| n.starts_with(attribute)).expect("a note");
        assert!(note.contains("8 of 8 joints") && note.contains("(0, 0, 0, 0.01)"), "{note}");
    }
    assert!(good.notes.iter().all(|n| !n.contains("rigid")), "{:?}", good.notes);
    let (a, b) = (Evaluation::declared(&good, good.clips.first()), Evaluation::declared(&bad, bad.clips.first()));
    let check = check_bind(&b, &BindTolerance::default());
    let weighted: Vec<&str> = (0..bad.skins.len())
        .flat_map(|s| bad.skins[s].joints.iter().zip(bad.weighted_joints(s)).filter(|(_, w)| *w).map(|(&j, _)| j))
        .map(|j| bad.skeleton.bone(j).name.as_str())
        .collect();
    let broken: Vec<&str> = check.broken.iter().map(|m| m.name.as_str()).collect();
    assert!(weighted.len() >= 5 && broken.len() == weighted.len(), "{broken:?} of {weighted:?}");
    let scaled = |row: [f64; 4]| row[..3] == [0.0; 3] && (row[3] - 0.01).abs() < 1e-15;
    assert!(check.broken.iter().all(|m| m.last_row.is_some_and(scaled)), "{:?}", check.broken);
    assert!(
        check.broken[0].says().contains("last row (0, 0, 0, 0.01), not (0, 0, 0, 1)"),
        "{}",
        check.broken[0].says()
    );
    assert!(check_bind(&a, &BindTolerance::default()).broken.is_empty());
    let pairs = Pairs::by_name(&a, &b);
    let compared = compare(&a, &b, &pairs, &comparison_times(&a, &b, 30.0));
    assert!(compared.bones.iter().all(|bone| bone.position.max < 1e-9), "every bone where it was");
    let skin = compared.meshes[0].distance.max / compared.rig_size;
    assert!(skin > 0.5, "the skin lands {skin} of the rig's size away");
}

/// The one-line error of loading `file`, which must fail.
fn refused(file: &Path) -> String {
    let error = bonescope::import::load(file).expect_err("refused").to_string();
    assert!(!error.contains('\n'), "one line: {error}");
    error
}

#[test]
fn a_hostile_stage_reads_nothing_outside_its_folder_and_fails_in_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let (root, inside) = (dir.path(), dir.path().join("shots"));
    std::fs::create_dir(&inside).unwrap();
    let skeleton = "#usda 1.0\n(\n    defaultPrim = \"Rig\"\n)\ndef Skeleton \"Rig\"\n{\n    uniform token[] joints = [\"a\"]\n    \
                    uniform matrix4d[] restTransforms = [( (1, 0, 0, 0), (0, 1, 0, 0), (0, 0, 1, 0), (0, 0, 0, 1) )]\n}\n";
    // A skeleton outside the folder, referenced from inside it: not read, so not there.
    std::fs::write(root.join("secret.usda"), skeleton).unwrap();
    let referencing = inside.join("shot.usda");
    std::fs::write(&referencing, "#usda 1.0\ndef \"Shot\" (\n    prepend references = @../secret.usda@\n)\n{\n}\n")
        .unwrap();
    match bonescope::import::load(&referencing) {
        Ok(rig) => assert!(rig.skeleton.is_empty(), "the outside skeleton was read"),
        Err(error) => assert!(!error.to_string().contains('\n'), "{error}"),
    }
    // The same skeleton beside the file is read.
    std::fs::write(inside.join("rig.usda"), skeleton).unwrap();
    std::fs::write(&referencing, "#usda 1.0\ndef \"Shot\" (\n    prepend references = @./rig.usda@\n)\n{\n}\n")
        .unwrap();
    assert_eq!(bonescope::import::load(&referencing).unwrap().skeleton.len(), 2, "the node and its joint");
    // Sublayers that include each other end.
    let (a, b) = (inside.join("a.usda"), inside.join("b.usda"));
    std::fs::write(&a, "#usda 1.0\n(\n    subLayers = [@./b.usda@]\n)\n").unwrap();
    std::fs::write(&b, "#usda 1.0\n(\n    subLayers = [@./a.usda@]\n)\n").unwrap();
    if let Err(error) = bonescope::import::load(&a) {
        assert!(!error.to_string().contains('\n'), "{error}");
    }
    // A binary layer cut in half.
    let usdc = std::fs::read(common::asset("blender/stretchy_full.usdc")).unwrap();
    let cut = inside.join("cut.usdc");
    std::fs::write(&cut, &usdc[..usdc.len() / 2]).unwrap();
    assert!(refused(&cut).contains("cut.usdc"));
    // Samples a trillion time codes apart would be a trillion frames: refused by the memory budget.
    let far = inside.join("far.usda");
    let bound = skeleton
        .replace("Skeleton \"Rig\"\n", "Skeleton \"Rig\" (\n    prepend apiSchemas = [\"SkelBindingAPI\"]\n)\n");
    let animated = bound.replace(
        "\n}\n",
        "\n    rel skel:animationSource = </Rig/Anim>\n    def SkelAnimation \"Anim\"\n    {\n        uniform token[] joints = [\"a\"]\n        \
         float3[] translations.timeSamples = {\n            1: [(0, 0, 0)],\n            1000000000000: [(1, 0, 0)],\n        }\n    }\n}\n",
    );
    std::fs::write(&far, animated).unwrap();
    let error = refused(&far);
    assert!(error.contains("--max-memory"), "{error}");
    // A rest transform that is not a number, and names that hold escape codes, are said in one escaped line.
    let nan = inside.join("nan.usda");
    std::fs::write(&nan, skeleton.replace("( (1, 0, 0, 0)", "( (nan, 0, 0, 0)").replace("[\"a\"]", "[\"a\\x1b[2J\"]"))
        .unwrap();
    let error = refused(&nan);
    assert!(error.contains("is not finite") && !error.contains('\x1b'), "{error}");
}

/// An attribute of a type USD does not know (Pixar's `jointInfluences.usda` writes `flaot[]`): usd-core keeps it, its
/// value as text no schema reads, and reads the rest of the file; bonescope skips it with a note naming it. Values of
/// every shape are passed over, brackets nested as deep as a text layer may nest them included; one that never
/// closes leaves the file refused.
#[test]
fn an_attribute_of_an_unknown_type_is_skipped_with_a_note() {
    let pixar = assets().join("usd-openusd/usdSkel/testenv/testUsdSkelSkinningQuery/jointInfluences.usda");
    let rig = bonescope::import::load(&pixar).unwrap_or_else(|e| panic!("{e}"));
    let cases = "/JointInfluences/ErrorCases";
    let note = format!(
        "attributes of types USD does not know, skipped: {cases}/MismatchedElementSize.primvars:skel:jointWeights \
         (flaot[]), {cases}/InvalidElementSize.primvars:skel:jointWeights (flaot[])"
    );
    assert!(rig.notes.contains(&note), "{:?}", rig.notes);
    let names: Vec<&str> = rig.skeleton.bones().iter().map(|b| b.name.as_str()).collect();
    assert_eq!(names, ["Skel1", "Skel2", "Skel3"]);

    let dir = tempfile::tempdir().unwrap();
    let deep = format!("{}{}", "[".repeat(250), "]".repeat(250));
    let layer = |values: &str| {
        format!(
            "#usda 1.0\ndef Skeleton \"Rig\"\n{{\n    uniform token[] joints = [\"a\"]\n    {values}\n    \
             uniform matrix4d[] restTransforms = [( (1, 0, 0, 0), (0, 1, 0, 0), (0, 0, 1, 0), (0, 2, 0, 1) )]\n}}\n"
        )
    };
    let values = [
        "flaot a = -inf",
        "flaot3 b = (1, 2, 3)",
        "flaot[] c = [[1], [2, (3)]] (\n        elementSize = 2\n    )",
        "flaot[] d.timeSamples = { 0: [1], 1: [2] }",
        &format!("flaot e = {deep}"),
    ];
    let file = dir.path().join("unknown.usda");
    std::fs::write(&file, layer(&values.join("\n    "))).unwrap();
    let rig = bonescope::import::load(&file).unwrap_or_else(|e| panic!("{e}"));
    let note = "attributes of types USD does not know, skipped: /Rig.a (flaot), /Rig.b (flaot3), /Rig.c (flaot[]), \
                /Rig.d (flaot[]), /Rig.e (flaot)";
    assert!(rig.notes.iter().any(|n| n == note), "{:?}", rig.notes);
    let joint = rig.skeleton.find("a").expect("the joint after them");
    assert_eq!(rig.skeleton.bone(joint).rest.translation, glam::DVec3::new(0.0, 2.0, 0.0));
    let unclosed = dir.path().join("unclosed.usda");
    std::fs::write(&unclosed, layer("flaot[] c = [[1], [2")).unwrap();
    assert!(refused(&unclosed).contains("unclosed.usda"));
}

/// The `.usdc` reader reads through blocks of the file it keeps (`openusd::usdc::blocks`): reads of every size, near
/// the last (a kept block) and anywhere in a file of twice as many blocks as are kept, after seeks of each kind,
/// read what the file holds there, and nothing past its end.
#[test]
fn the_crate_readers_blocks_read_what_the_file_holds() {
    let file: Vec<u8> = (0..((1 << 16) * 64 + 123)).map(|i| (i * 7 % 251) as u8).collect();
    let mut blocks = Blocks::new(std::io::Cursor::new(file.clone())).unwrap();
    let mut state = 12345u64;
    for _ in 0..2000 {
        state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        let anywhere = (state >> 33) as usize % (file.len() + 10);
        let here = blocks.stream_position().unwrap() as usize;
        let start = if state.is_multiple_of(4) { anywhere } else { (here + anywhere % 100_000).saturating_sub(50_000) };
        let size = [1, 8, 100, (1 << 16) - 1, 1 << 16, 3 << 16][(state >> 20) as usize % 6];
        match (state >> 8) % 3 {
            0 => blocks.seek(SeekFrom::Start(start as u64)).unwrap(),
            1 => blocks.seek(SeekFrom::End(start as i64 - file.len() as i64)).unwrap(),
            _ => blocks.seek(SeekFrom::Current(start as i64 - here as i64)).unwrap(),
        };
        let mut got = vec![0; size];
        let mut filled = 0;
        while filled < size {
            match blocks.read(&mut got[filled..]).unwrap() {
                0 => break,
                read => filled += read,
            }
        }
        let end = (start + size).min(file.len()).max(start.min(file.len()));
        assert_eq!(&got[..filled], &file[start.min(file.len())..end], "{size} bytes at {start}");
    }
    assert!(blocks.seek(SeekFrom::Current(-(file.len() as i64) - 1)).is_err());
}

#[test]
fn the_budget_bounds_what_a_binary_layer_s_samples_hold_at_once_not_their_sum() {
    // 2,000 time codes of 20 joints' translations, each an array of its own (480 kB decoded in all), of which the
    // reading keeps one moving joint's column (24 kB): streamed, a sample is given back to the budget once read, so
    // the file loads within 400 KiB, less than its samples take together, and is refused in one line below what it
    // holds at once.
    let Some(python) = usd_python() else { return };
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("long.usdc");
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/usd/long_clip.py");
    let status = Command::new(python).arg(script).arg(&file).status().expect("python runs");
    assert!(status.success());
    let file = file.to_str().unwrap();
    let loaded = common::bonescope(&["inspect", file, "--time", "0.5", "--max-memory", "400K"]);
    assert!(loaded.status.success(), "{}", String::from_utf8_lossy(&loaded.stderr));
    let refused = common::bonescope(&["inspect", file, "--time", "0.5", "--max-memory", "64K"]);
    let said = String::from_utf8_lossy(&refused.stderr);
    assert_eq!(refused.status.code(), Some(2), "{said}");
    assert_eq!(said.lines().count(), 1, "{said}");
    assert!(said.contains("long.usdc") && said.contains("the limit is 64 KiB (--max-memory)"), "{said}");
}

/// What Pixar's validators find in `file` (see `tests/usd/compliance.py`): each error as `validator: message`.
fn validation_errors(python: &Path, file: &Path) -> Vec<String> {
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/usd/compliance.py");
    let output = Command::new(python).arg(script).arg(file).output().expect("python runs");
    assert!(output.status.success(), "{}: {}", file.display(), String::from_utf8_lossy(&output.stderr));
    let found: Value = serde_json::from_slice(&output.stdout).expect("JSON");
    assert!(found["validators"].as_u64().unwrap() >= 20, "usd-core's validators load: {found}");
    let errors = found["errors"].as_array().unwrap().iter();
    errors.map(|e| format!("{}: {}", e["validator"].as_str().unwrap(), e["message"].as_str().unwrap())).collect()
}

#[test]
fn a_usd_bake_plays_in_usd_core_as_its_source_within_its_report() {
    // Each source baked to USD by the command line, its report measured on the file read back by bonescope. usd-core
    // puts every joint where bonescope reads it at every time code (1e-6 of the rig's size) and skins every point
    // as bonescope does (`UsdSkel.BakeSkinning`, 1e-5): so usd-core plays the source within the report's worst, plus
    // that. Pixar's validators find nothing wrong in any of the three encodings. The generated 200-bone rig too, at
    // each of its 6,001 time codes.
    let Some(python) = usd_python() else { return };
    let dir = tempfile::tempdir().unwrap();
    let generated = dir.path().join("generated.glb");
    std::fs::write(&generated, generated_gltf::glb(generated_gltf::Squashes::Sparse)).unwrap();
    let sources = [
        (common::asset("blender/stretchy_full.glb"), "usdc"),
        (common::asset("blender/stretchy_noinherit.fbx"), "usda"),
        (common::asset("fbx-ufbx-data/maya_mixed_inherit_mode_7700_ascii.fbx"), "usdz"),
        (common::corpus("realworld/godot_mannequiny.glb"), "usdc"),
        (common::corpus("realworld/usdwg_BrainStem.usdz"), "usdc"),
        (generated, "usdc"),
    ];
    for (k, (source, extension)) in sources.iter().enumerate() {
        let out = dir.path().join(format!("baked{k}.{extension}"));
        let (source, out_arg) = (source.display().to_string(), out.display().to_string());
        let report = common::json(&common::bonescope(&["bake", &source, "--out", &out_arg, "--format", "json"]));
        let (worst, size) =
            (report["animations"][0]["worst"]["max"].as_f64().unwrap(), report["rig_size"].as_f64().unwrap());
        // UsdSkel's half-precision scales bound it: 2⁻¹¹ of a joint's reach, and the keys' tolerance.
        assert!(worst <= 1e-3 * size, "{source}: worst {worst} of a rig {size} across");
        let back = load_with(&out, &Options { space: Space::File }).unwrap_or_else(|e| panic!("{e}"));
        assert!(joints_as_usd_core(&python, &out, &back) > 0, "{source}: poses compared");
        // usd-core's skinned points of every vertex at every time code: bounded (BrainStem's 34.9 s skin would be 77
        // million points, and its baked stage gigabytes); its joints are compared all the same.
        let points: usize = back.meshes.iter().map(|m| m.positions.len()).sum();
        let codes = back.clips.first().map_or(1.0, |c| c.span().length() * c.frame_rate() + 1.0);
        if points > 0 && points as f64 * codes <= 5e6 {
            let skinned = dir.path().join(format!("skinned{k}.usdc"));
            let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/usd/bake_skinning.py");
            let status = Command::new(&python).arg(script).arg(&out).arg(&skinned).status().expect("python runs");
            assert!(status.success(), "usd-core baked the skinning of {source}'s bake");
            assert!(points_as_baked(&python, &out, &skinned) > 0, "{source}: points compared");
        }
        let errors = validation_errors(&python, &out);
        assert!(errors.is_empty(), "{source}: {errors:#?}");
    }
}
