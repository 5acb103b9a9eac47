//! `explain` against the analysis and `diff` applied for real: every fix's "shear left" is what a scan of the
//! changed evaluation reports (the mode given with `--inherit-bone`, the scale made uniform with `--uniform-scale`,
//! the clip baked by `bonescope bake` and read back from its file), and every cost is the largest difference `diff`
//! measures between the two evaluations (skinned vertices, and the probe points of bones no mesh shows), on the
//! demo, the Blender squash-and-stretch rig, the Maya mixed-inheritance file and the generated 200-bone rig.

mod common;

#[path = "../benches/support/generated_gltf.rs"]
#[allow(dead_code)]
mod generated_gltf;

use bonescope::analysis::{ClipScan, ScanOptions, scan, scan_analysis};
use bonescope::diff::{PROBE_FRACTION, Pairs, compare_at_size, comparison_times};
use bonescope::eval::{Evaluation, LayerStack, Layers};
use bonescope::explain::{Change, Costs, Explanation, Fix, Measured, Question, Scale, explain};
use bonescope::model::{InheritMode, Rig};
use common::{asset, bonescope, json, load_asset};
use glam::DMat4;

/// The rule a fix's cost follows, applied to `diff`'s own comparison of `a` with `b` `finer` times as often as at
/// `rate`: the largest vertex distance of any mesh, and the largest probe distance of any bone of the figure.
fn visible_distance(a: &Evaluation, b: &Evaluation, rate: f64, finer: f64) -> (f64, bool) {
    // Costs are measured against the rig as it is (the source's size over the times at `rate` sets the probe
    // points' reach).
    let size = a.size(&comparison_times(a, b, rate));
    let times = comparison_times(a, b, rate * finer);
    let comparison = compare_at_size(a, b, &Pairs::by_name(a, b), &times, size);
    let figure = a.rig.skeleton.figure();
    let skin = comparison.meshes.iter().map(|m| m.distance.max).fold(0.0, f64::max);
    let of_figure = comparison.bones.iter().filter(|d| figure[d.a]).map(|d| d.probe.max);
    let bones = of_figure.fold(0.0, f64::max);
    (skin.max(bones), comparison.meshes.is_empty() || bones > skin)
}

/// How far `fixed` moves anything of `source` at `times`, found here from the two evaluations' poses and skins
/// alone: the origin of every bone of the figure and the points `probe` out along each of its axes (each in its own
/// pose), and every vertex of every mesh (bones and meshes matched by name).
fn moved_for_real(source: &Evaluation, fixed: &Evaluation, times: &[f64], probe: f64) -> f64 {
    let (a, b) = (source.skeleton(), fixed.skeleton());
    let figure = a.figure();
    let bones: Vec<(usize, usize)> =
        (0..a.len()).filter(|&i| figure[i]).filter_map(|i| Some((i, b.find(&a.bone(i).name)?))).collect();
    let named = |name: &str| fixed.rig.meshes.iter().position(|m| m.name == name);
    let meshes: Vec<(usize, usize)> =
        source.rig.meshes.iter().enumerate().filter_map(|(i, m)| Some((i, named(&m.name)?))).collect();
    let (mut on_a, mut on_b) = (source.evaluator(), fixed.evaluator());
    let (mut skin_a, mut skin_b) = (Vec::new(), Vec::new());
    let mut largest: f64 = 0.0;
    for &time in times {
        on_a.evaluate(time);
        on_b.evaluate(time);
        let (ma, mb) = (&on_a.pose.model.model, &on_b.pose.model.model);
        for &(i, j) in &bones {
            // The origin, and the point `probe` out along each axis, each placed in its own pose.
            let origin = |m: &DMat4| m.w_axis.truncate();
            largest = largest.max(origin(&ma[i]).distance(origin(&mb[j])));
            for axis in 0..3 {
                let along = |m: &DMat4| origin(m) + m.col(axis).truncate().normalize_or_zero() * probe;
                largest = largest.max(along(&ma[i]).distance(along(&mb[j])));
            }
        }
        for &(i, j) in &meshes {
            source.skin(&on_a.pose, i, &mut skin_a);
            fixed.skin(&on_b.pose, j, &mut skin_b);
            skin_a.iter().zip(&skin_b).for_each(|(p, q)| largest = largest.max(p.distance(*q)));
        }
    }
    largest
}

/// `fix` of `bone` checked against `fixed`, the same change made independently: the bone's worst shear and flag
/// in a scan of `fixed`, and the cost `diff` measures.
fn check_fix(source: &Evaluation, fixed: &Evaluation, bone_in_fixed: usize, fix: &Fix, options: &ScanOptions) {
    let scanned: ClipScan = scan(fixed, options, &|_, _| {});
    let summary = &scanned.bones[bone_in_fixed];
    assert!(
        (summary.worst_shear_deg - fix.shear_left_deg).abs() < 1e-9,
        "{}: {} against {fix:?}",
        fix.label,
        summary.worst_shear_deg
    );
    assert_eq!(summary.stretched(), !fix.removes, "{}", fix.label);
    let cost = fix.cost.distance;
    let (sampled, on_bones) = visible_distance(source, fixed, options.rate, 1.0);
    let tolerance = 1e-12 * source.size(&[0.0]).max(1.0);
    assert!(cost.max >= sampled - tolerance, "{}: {sampled} at the times compared, costed {cost:?}", fix.label);
    if cost.max == sampled {
        assert_eq!(on_bones, fix.cost.measured == Measured::Bones, "{}", fix.label);
    }
    // What the change moves at the cost's time, found without `diff`: the cost is a distance there, between the
    // times compared where it is larger than at them.
    let times = comparison_times(source, fixed, options.rate);
    let probe = PROBE_FRACTION * source.size(&times);
    let moved = moved_for_real(source, fixed, &[cost.time], probe);
    assert!((cost.max - moved).abs() <= tolerance, "{}: moves {moved} at {}, costed {cost:?}", fix.label, cost.time);
    // Nowhere on a grid eight times finer does it move further than a hundredth of a percent beyond.
    let (finer, _) = visible_distance(source, fixed, options.rate, 8.0);
    assert!(finer <= cost.max * (1.0 + 1e-4) + tolerance, "{}: moves {finer}, costed {cost:?}", fix.label);
}

/// What `fix` of `bone` says of the other bones, against scans of the rig before and with the change: every bone
/// whose flag changes, or whose worst shear moves by more than the shear tolerance while flagged, with its figures.
fn check_elsewhere(before: &ClipScan, after: &ClipScan, bone: usize, fix: &Fix, options: &ScanOptions) {
    let tolerance = options.tolerances.min_shear_deg;
    let expected: Vec<usize> = (0..before.bones.len())
        .filter(|&b| b != bone)
        .filter(|&b| {
            let (was, now) = (&before.bones[b], &after.bones[b]);
            let flagged = was.stretched() || now.stretched();
            was.stretched() != now.stretched()
                || (flagged && (now.worst_shear_deg - was.worst_shear_deg).abs() > tolerance)
        })
        .collect();
    let listed: Vec<usize> = fix.elsewhere.iter().map(|e| e.bone).collect();
    assert_eq!(listed, expected, "{}", fix.label);
    for other in &fix.elsewhere {
        let now = &after.bones[other.bone];
        assert!((other.after_deg - now.worst_shear_deg).abs() < 1e-9, "{}: {other:?}", fix.label);
        assert_eq!(other.flagged_after, now.stretched(), "{}: {other:?}", fix.label);
    }
}

/// The bake fixes of `explanation` (of `source`, the first clip of the file at `path`) against the files
/// `bonescope bake` writes for them: scanned and compared from the files.
fn check_bakes(path: &std::path::Path, source: &Evaluation, explanation: &Explanation, options: &ScanOptions) {
    let dir = tempfile::tempdir().unwrap();
    for fix in explanation.fixes.iter().filter(|f| matches!(f.change, Change::Bake { .. })) {
        let Change::Bake { strategy } = fix.change else { unreachable!() };
        let out = dir.path().join(format!("{strategy:?}.glb"));
        let file = path.to_str().unwrap();
        let strategy = format!("{strategy:?}").to_lowercase();
        let baked = bonescope(&["bake", file, "--anim", "0", "--strategy", &strategy, "--out", out.to_str().unwrap()]);
        assert!(baked.status.success(), "{}", String::from_utf8_lossy(&baked.stderr));
        let baked: Rig = bonescope::import::load(&out).unwrap();
        let fixed = Evaluation::declared(&baked, baked.clips.first());
        check_fix(source, &fixed, baked.skeleton.find(&explanation.name).unwrap(), fix, options);
    }
}

/// `change` made to `source` with the library's own evaluation types (`None` for a bake, which needs its file).
fn made_again<'a>(source: &Evaluation<'a>, change: Change) -> Option<Evaluation<'a>> {
    match change {
        Change::Mode { bone, mode } => {
            let mut modes = source.modes().to_vec();
            modes[bone] = mode;
            Some(source.with_modes(&modes).unwrap())
        }
        Change::UniformScale { bone } => {
            let layers = Layers { uniform_scale: vec![bone], ..Layers::default() };
            Some(source.clone().with_layers(LayerStack::new(source.rig, &layers).unwrap()))
        }
        Change::Bake { .. } => None,
    }
}

/// Every mode and uniform-scale fix of every explained bone of `source`, made again here with the library's own
/// evaluation types, checked ([`check_fix`]). Returns the explanations.
fn check_fixes_in_memory(source: &Evaluation, options: &ScanOptions) -> Vec<Explanation> {
    let before = scan_analysis(source, options);
    let explained = explain(source, &before, Question::default(), options);
    assert!(!explained.is_empty(), "something is flagged");
    for explanation in &explained {
        assert!(!explanation.fixes.is_empty(), "{}", explanation.name);
        for fix in &explanation.fixes {
            if let Some(fixed) = made_again(source, fix.change) {
                check_fix(source, &fixed, explanation.bone, fix, options);
                check_elsewhere(&before.scan, &scan(&fixed, options, &|_, _| {}), explanation.bone, fix, options);
            }
        }
    }
    explained
}

#[test]
fn on_the_demo_every_fix_is_what_the_analysis_and_diff_say_of_it_applied() {
    let rig = bonescope::import::demo_rig();
    let source = Evaluation::declared(&rig, rig.clips.first());
    let explained = check_fixes_in_memory(&source, &ScanOptions::default());
    let forearm = explained.iter().find(|e| e.name == "forearm").expect("the demo's forearm shears");
    let cause = forearm.causes.at.main_cause().expect("a main cause");
    assert_ne!(cause.name, "forearm", "the forearm's own scale is uniform: an ancestor's squash shears it");
    assert!(forearm.fixes[0].removes, "some fix removes the shear: {:?}", forearm.fixes[0]);
}

#[test]
fn on_the_blender_rig_every_fix_holds_and_the_bakes_hold_as_the_files_bake_writes() {
    let path = asset("blender/stretchy_full.glb");
    let rig = load_asset("blender/stretchy_full.glb");
    let options = ScanOptions::default();
    let source = Evaluation::declared(&rig, rig.clips.first());
    let explained = check_fixes_in_memory(&source, &options);
    let forearm = explained.iter().find(|e| e.name == "forearm").unwrap();
    assert_eq!(forearm.causes.at.main_cause().map(|l| l.name.as_str()), Some("chest"), "the chest squashes");
    // The same scene as FBX (its frames baked by Blender's exporter, a conversion node above the armature).
    let fbx = load_asset("blender/stretchy_full.fbx");
    let from_fbx = check_fixes_in_memory(&Evaluation::declared(&fbx, fbx.clips.first()), &options);
    let names = |explained: &[Explanation]| explained.iter().map(|e| e.name.clone()).collect::<Vec<_>>();
    assert_eq!(names(&from_fbx), names(&explained), "the same bones shear, in the same order");
    // And as Blender's USD export (UsdSkel: every joint inherits fully).
    let usd = load_asset("blender/stretchy_full.usdc");
    let from_usd = check_fixes_in_memory(&Evaluation::declared(&usd, usd.clips.first()), &options);
    assert!(names(&from_usd).contains(&"forearm".to_owned()), "{:?}", names(&from_usd));
    check_bakes(&path, &source, forearm, &options);
    // The same through the command line: a mode given to one bone, a scale made uniform.
    let shear_with = |extra: &[&str]| {
        let mut args = vec!["scan", path.to_str().unwrap(), "--anim", "0", "--format", "json"];
        args.extend_from_slice(extra);
        let report = json(&bonescope(&args));
        let stretched = report[0]["animations"][0]["stretched"].as_array().unwrap().clone();
        stretched.iter().find(|b| b["name"] == "forearm").map_or(0.0, |b| b["worst_shear_deg"].as_f64().unwrap())
    };
    for fix in forearm.fixes.iter().filter(|f| f.removes || matches!(f.change, Change::UniformScale { .. })) {
        let shear = match fix.change {
            Change::Mode { bone, mode } => {
                shear_with(&["--inherit-bone", &format!("{}={mode}", rig.skeleton.bone(bone).name)])
            }
            Change::UniformScale { bone } => shear_with(&["--uniform-scale", &rig.skeleton.bone(bone).name]),
            Change::Bake { .. } => continue,
        };
        let expected = if fix.removes { 0.0 } else { fix.shear_left_deg };
        assert!((shear - expected).abs() < 1e-9, "{}: the scan says {shear}", fix.label);
    }
}

#[test]
fn on_the_maya_file_explain_names_the_modes_that_matter_and_their_cost() {
    // Maya's segment scale compensate on Left_Tip, Right and Right_Tip: an engine that ignores it (full) shears
    // them or moves the skin, and explain says how much, bone by bone.
    let file = "fbx-ufbx-data/maya_mixed_inherit_mode_7700_ascii.fbx";
    let rig = load_asset(file);
    let source = Evaluation::declared(&rig, rig.clips.first());
    let explained = check_fixes_in_memory(&source, &ScanOptions::default());
    // Where modes other than full are declared, the bakes differ from the clip: both as the files say.
    for explanation in &explained {
        check_bakes(&asset(file), &source, explanation, &ScanOptions::default());
    }
    let compensated: Vec<usize> =
        (0..rig.skeleton.len()).filter(|&b| rig.skeleton.bone(b).inherit == InheritMode::SegmentCompensate).collect();
    assert!(!compensated.is_empty());
    let as_full: Vec<&Fix> = explained
        .iter()
        .flat_map(|e| &e.fixes)
        .filter(|f| matches!(f.change, Change::Mode { bone, mode: InheritMode::Full } if compensated.contains(&bone)))
        .collect();
    assert!(as_full.iter().any(|f| f.cost.distance.max > 0.0), "some declared mode matters: {as_full:?}");
    // The file is in centimetres, 18 cm tall: no fix moves anything by more than the rig's size (when the unit
    // was compensated with the scales its author set, `Mid → segment-compensate` cost 12.9 m).
    let size = source.size(&source.times(ScanOptions::default().rate));
    for fix in explained.iter().flat_map(|e| &e.fixes) {
        assert!(fix.cost.distance.max < size, "{}: {:?} on a rig of {size}", fix.label, fix.cost);
    }
    let table = bonescope(&["explain", asset(file).to_str().unwrap()]);
    assert!(table.status.success(), "{}", String::from_utf8_lossy(&table.stderr));
    let text = String::from_utf8(table.stdout).unwrap();
    for bone in &compensated {
        let name = &rig.skeleton.bone(*bone).name;
        if as_full.iter().any(|f| matches!(f.change, Change::Mode { bone: b, .. } if b == *bone)) {
            assert!(
                text.contains(&format!("mode on the chain: {name} is segment-compensate; as full")),
                "{name}:\n{text}"
            );
        }
    }
}

#[test]
fn on_the_generated_rig_the_fixes_of_a_sheared_bone_hold() {
    // 200 bones, every 25th squashing, 6,000 frames: the last flagged bone (the mildest shear) explained at its
    // key times, its four best fixes other than a bake made again here, and its bakes written by `bonescope bake`.
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("generated.glb");
    std::fs::write(&path, generated_gltf::glb(generated_gltf::Squashes::Sparse)).unwrap();
    let rig = bonescope::import::load(&path).unwrap();
    let options = ScanOptions { rate: 0.0, ..ScanOptions::default() };
    let source = Evaluation::declared(&rig, rig.clips.first());
    let before = scan_analysis(&source, &options);
    let flagged = before.scan.stretched_worst_first();
    let bone = flagged.last().expect("the squashes shear the bones below them").index;
    let explained = explain(&source, &before, Question { bones: Some(&[bone]), ..Question::default() }, &options);
    let explanation = &explained[0];
    let cause = explanation.causes.at.main_cause().expect("a squash causes it");
    assert!(rig.skeleton.is_in_subtree(bone, cause.bone) && cause.bone != bone, "{cause:?}");
    for fix in explanation.fixes.iter().filter(|f| !matches!(f.change, Change::Bake { .. })).take(4) {
        check_fix(&source, &made_again(&source, fix.change).unwrap(), bone, fix, &options);
    }
    check_bakes(&path, &source, explanation, &options);
}

#[test]
fn the_command_line_explains_in_a_table_in_json_and_in_a_scan() {
    let path = asset("blender/stretchy_full.glb");
    let file = path.to_str().unwrap();
    let report = json(&bonescope(&["explain", file, "--bone", "neck", "--format", "json"]));
    let neck = &report["bones"][0];
    assert_eq!(neck["name"], "neck");
    assert_eq!(report["bones"].as_array().unwrap().len(), 1, "only the bone asked for");
    let chain = neck["causes"]["at"]["chain"].as_array().unwrap();
    assert_eq!(chain.last().unwrap()["name"], "neck", "the chain ends at the bone: {chain:?}");
    assert!(neck["fixes"][0]["cost"]["distance"]["max"].as_f64().is_some(), "{neck}");
    // At a time asked for, the chain is shown there.
    let at = json(&bonescope(&["explain", file, "--bone", "neck", "--time", "1", "--format", "json"]));
    assert_eq!(at["bones"][0]["causes"]["at"]["time"], 1.0);
    // Through layers: the table says which, the JSON echoes them.
    let layered = bonescope(&["explain", file, "--bone", "forearm", "--uniform-scale", "chest"]);
    assert!(String::from_utf8_lossy(&layered.stdout).contains("  layers: uniform scale `chest`"));
    let layered =
        json(&bonescope(&["explain", file, "--bone", "forearm", "--uniform-scale", "chest", "--format", "json"]));
    assert_eq!(layered["layers"]["uniform_scale"].as_array().map(Vec::len), Some(1));
    let unknown = bonescope(&["explain", file, "--bone", "tail"]);
    assert_eq!(unknown.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&unknown.stderr).contains("--bone: no bone named `tail`"));
    let by_index = json(&bonescope(&["explain", file, "--bone", &neck["bone"].to_string(), "--format", "json"]));
    assert_eq!(by_index["bones"][0]["name"], "neck", "a bone by its index too");
    // scan --explain: a line per stretched bone in the table, the brief in the JSON lines.
    let scanned = bonescope(&["scan", file, "--explain"]);
    let text = String::from_utf8(scanned.stdout).unwrap();
    assert!(text.contains("  why: forearm: chest's scale ("), "{text}");
    let lines = bonescope(&["scan", file, "--explain", "--format", "jsonl"]);
    let record: serde_json::Value =
        serde_json::from_slice(lines.stdout.split(|&b| b == b'\n').next().unwrap()).unwrap();
    let explained = record["animations"][0]["explained"].as_array().unwrap();
    let stretched = record["animations"][0]["stretched"].as_array().unwrap();
    assert_eq!(explained.len(), stretched.len());
    assert_eq!(explained[0]["main_cause"], "chest");
    // JUnit: each stretched bone's failure says why.
    let junit = String::from_utf8(bonescope(&["scan", file, "--explain", "--format", "junit"]).stdout).unwrap();
    assert!(
        junit.contains("why: forearm: chest&apos;s scale") || junit.contains("why: forearm: chest's scale"),
        "{junit}"
    );
    assert!(explained[0]["fix_cost"].as_f64().unwrap() > 0.0 && explained[0]["best_fix"].is_string());
}

#[test]
fn costing_only_the_contenders_finds_the_same_best_fix() {
    // `scan --explain` makes and costs only the fixes that can rank first (in the order of their cost's lower
    // bound, each compared only until it passes the cheapest found); the best fix is the one the whole ranking
    // finds: on shared files and on a generated rig of long chains that shear below every tenth bone. A scale measured
    // before (as the app measures it, once for every Why?) changes nothing.
    let rigs = [
        "blender/stretchy_full.glb",
        "blender/stretchy_noinherit.fbx",
        "blender/stretchy_full.usdc",
        "fbx-ufbx-data/maya_mixed_inherit_mode_7700_ascii.fbx",
    ]
    .map(|file| (file.to_owned(), load_asset(file)))
    .into_iter()
    .chain([("stress_rig(40, 120, 5)".to_owned(), bonescope::import::stress_rig(40, 120, 5))]);
    for (file, rig) in rigs {
        let options = ScanOptions::default();
        let source = Evaluation::declared(&rig, rig.clips.first());
        let before = scan_analysis(&source, &options);
        let every = explain(&source, &before, Question::default(), &options);
        let best = explain(&source, &before, Question { costs: Costs::Best, ..Question::default() }, &options);
        assert!(!every.is_empty(), "{file}");
        for (all, brief) in every.iter().zip(&best) {
            assert_eq!(all.best_fix(), brief.best_fix(), "{file}: {}", all.name);
            assert!(brief.fixes.len() <= all.fixes.len());
        }
        // The app measures the scale once, after the analysis, for every Why?: what it explains is the same.
        let scale = Scale::of(&source, options.rate);
        let question = Question { costs: Costs::Best, scale: Some(&scale), ..Question::default() };
        assert_eq!(explain(&source, &before, question, &options), best, "{file}: with the scale measured before");
        let question = Question { scale: Some(&scale), ..Question::default() };
        assert_eq!(explain(&source, &before, question, &options), every, "{file}: with the scale measured before");
    }
}

/// A glTF rig with no skin: `upper` scaled (2, 1, 1), its child `fore` one unit along X turning about Z from 0° to
/// 90° over a second, and a plain node `hand` one unit along X under `fore` (with `tip` one unit further where
/// `with_tip`).
fn turning_arm(with_tip: bool) -> Vec<u8> {
    use base64::Engine as _;
    let times = [0.0f32, 0.5, 1.0];
    let turn = |degrees: f32| {
        let half = degrees.to_radians() / 2.0;
        [0.0, 0.0, half.sin(), half.cos()]
    };
    let rotations = [turn(0.0), turn(45.0), turn(90.0)];
    let bin: Vec<u8> = times.iter().chain(rotations.as_flattened()).flat_map(|v| v.to_le_bytes()).collect();
    let uri = format!("data:application/octet-stream;base64,{}", base64::prelude::BASE64_STANDARD.encode(&bin));
    let hand_children = if with_tip { serde_json::json!([3]) } else { serde_json::json!([]) };
    let document = serde_json::json!({
        "asset": {"version": "2.0"},
        "scenes": [{"nodes": [0]}],
        "nodes": [
            {"name": "upper", "scale": [2.0, 1.0, 1.0], "children": [1]},
            {"name": "fore", "translation": [1.0, 0.0, 0.0], "children": [2]},
            {"name": "hand", "translation": [1.0, 0.0, 0.0], "children": hand_children},
            {"name": "tip", "translation": [1.0, 0.0, 0.0]}
        ],
        "buffers": [{"byteLength": bin.len(), "uri": uri}],
        "bufferViews": [{"buffer": 0, "byteLength": 12}, {"buffer": 0, "byteOffset": 12, "byteLength": 48}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 3, "type": "SCALAR", "min": [0.0], "max": [1.0]},
            {"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC4"}
        ],
        "animations": [{"name": "turn", "samplers": [{"input": 0, "output": 1}],
                        "channels": [{"sampler": 0, "target": {"node": 1, "path": "rotation"}}]}]
    });
    document.to_string().into_bytes()
}

#[test]
fn a_plain_node_under_a_turning_bone_is_of_the_figure_and_every_fix_pays_for_moving_it() {
    for with_tip in [false, true] {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("arm.gltf");
        std::fs::write(&path, turning_arm(with_tip)).unwrap();
        let rig = bonescope::import::load(&path).unwrap();
        let figure = rig.skeleton.figure();
        let tip = rig.skeleton.find("tip");
        for bone in ["hand"].into_iter().chain(tip.map(|_| "tip")) {
            assert!(figure[rig.skeleton.find(bone).unwrap()], "{bone} carries the chain on: of the figure");
        }
        let source = Evaluation::declared(&rig, rig.clips.first());
        let explained = check_fixes_in_memory(&source, &ScanOptions::default());
        let fore = explained.iter().find(|e| e.name == "fore").expect("the turn under the squash shears fore");
        // Made by hand: at 0 s the hand is at x = 2·(1 + 1) = 4 under full inheritance, and at x = 2 + 1 = 3 when
        // fore compensates its parent's scale; at 1 s, (2, 1) against (2, 1): the hand moves 1 m at worst.
        let compensate = fore.fixes.iter().find(
            |f| matches!(f.change, Change::Mode { bone, mode: InheritMode::SegmentCompensate } if bone == fore.bone),
        );
        let compensate = compensate.expect("segment-compensate is among fore's fixes");
        let reach = if with_tip { 2.0 } else { 1.0 };
        assert!(compensate.cost.distance.max >= reach - 1e-9, "the chain's end moves {reach}: {compensate:?}");
    }
}

/// The table's fixes under two headings: the modes of the tool that wrote the file first (Blender's for Blender's
/// FBX, Maya's segment-compensate and full for Maya's), the others under "other modes"; both answers said first;
/// a fix that changes nothing left out unless `--all` asks for every one.
#[test]
fn explain_answers_both_questions_and_offers_the_files_own_modes_first() {
    let table = |file: &str, extra: &[&str]| {
        let path = asset(file);
        let mut args = vec!["explain", path.to_str().unwrap()];
        args.extend_from_slice(extra);
        let output = bonescope(&args);
        assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));
        String::from_utf8(output.stdout).unwrap()
    };
    // The fix rows of the table headed `heading`, each row's label.
    let rows = |text: &str, heading: &str| -> Vec<String> {
        let lines = text.lines().skip_while(|l| !l.trim_start().starts_with(heading)).skip(1);
        let rows = lines.take_while(|l| l.starts_with("    ") && !l.trim_start().starts_with("other modes"));
        rows.map(|l| l.trim().split("  ").next().unwrap().to_owned()).collect()
    };
    let mode_of = |label: &str| label.split(" → ").nth(1).map(|m| m.parse::<InheritMode>().unwrap());

    let blender = table("blender/stretchy_full.fbx", &["--bone", "forearm"]);
    assert!(blender.contains("  to play it as authored in any engine: bake exact, no visible change\n"), "{blender}");
    assert!(blender.contains("  to remove the shear: forearm → blender-aligned, moves the skin"), "{blender}");
    assert!(blender.contains("— no fix under 1 % of the rig"), "{blender}");
    let first = rows(&blender, "fixes, best first");
    let blenders = |m: InheritMode| m == InheritMode::Full || m.is_blender();
    assert!(first.iter().filter_map(|l| mode_of(l)).all(blenders), "{first:?}");
    let other = rows(&blender, "other modes");
    assert!(!other.is_empty() && other.iter().filter_map(|l| mode_of(l)).all(|m| !blenders(m)), "{other:?}");
    // Fix Shear leaves the forearm's shear where it was and moves nothing visibly: listed only on asking.
    assert!(!blender.contains("forearm → blender-fix-shear"), "{blender}");
    assert!(
        table("blender/stretchy_full.fbx", &["--bone", "forearm", "--all"]).contains("forearm → blender-fix-shear")
    );

    let maya = table("fbx-ufbx-data/maya_mixed_inherit_mode_7700_ascii.fbx", &["--bone", "Right_Tip"]);
    let first = rows(&maya, "fixes, best first");
    let maya_modes = [InheritMode::Full, InheritMode::SegmentCompensate];
    assert!(first.iter().filter_map(|l| mode_of(l)).all(|m| maya_modes.contains(&m)), "{first:?}");
    assert!(maya.contains("  to remove the shear: Mid → segment-compensate"), "{maya}");

    // A glTF names no tool of its own: every mode is among the first.
    let gltf = table("blender/stretchy_full.glb", &["--bone", "forearm"]);
    assert!(!gltf.contains("other modes"), "{gltf}");
}

/// The shear of `bone` in `evaluation` at `time`, with the scales of `uniform` made uniform by the library's own
/// layer (nothing of the explanation's own arithmetic).
fn shear_with_uniform(evaluation: &Evaluation, uniform: &[usize], bone: usize, time: f64) -> f64 {
    let layers = Layers { uniform_scale: uniform.to_vec(), ..Layers::default() };
    let made = evaluation.clone().with_layers(LayerStack::new(evaluation.rig, &layers).unwrap());
    bonescope::math::shear_deg(&glam::DMat3::from_mat4(made.pose_at(time).model.model[bone]))
}

/// On every real-world file nobody here wrote, every clip's worst bones: the cause a headline names takes shear
/// away (one bone's squash made uniform lowers it by more than half the shear tolerance; bones named together,
/// made uniform together, leave it under the tolerance), and no bone is listed non-uniform whose scale factors
/// stay within the non-uniform tolerance at every time scanned.
#[test]
fn on_real_files_the_headline_cause_contributes_and_the_non_uniform_list_carries_no_rounding() {
    let options = ScanOptions::default();
    let tolerance = options.tolerances.min_shear_deg;
    let (mut named_one, mut named_together) = (0, 0);
    for entry in std::fs::read_dir(common::corpus("realworld")).unwrap() {
        let path = entry.unwrap().path();
        let Ok(rig) = bonescope::import::load(&path) else { continue };
        for clip in &rig.clips {
            let source = Evaluation::declared(&rig, Some(clip));
            let analysis = scan_analysis(&source, &options);
            let report = bonescope::analysis::report::AnimationScan::new(
                &rig.skeleton,
                Some(clip),
                "declared".into(),
                options.rate,
                analysis.scan.clone(),
            );
            let worst: Vec<usize> = analysis.scan.stretched_worst_first().iter().take(3).map(|b| b.index).collect();
            let question = Question { bones: Some(&worst), costs: Costs::Best, ..Question::default() };
            for explained in explain(&source, &analysis, question, &options) {
                let at = &explained.causes.at;
                let (bone, time, shear) = (explained.bone, at.time, at.shear_deg);
                let place = format!("{}: {} `{}` at {time}", path.display(), explained.name, clip.label());
                assert!((shear_with_uniform(&source, &[], bone, time) - shear).abs() < 1e-9, "{place}");
                if let Some(cause) = at.main_cause() {
                    let left = shear_with_uniform(&source, &[cause.bone], bone, time);
                    assert!(shear - left > 0.5 * tolerance, "{place}: {} leaves {left}° of {shear}°", cause.name);
                    named_one += 1;
                } else if !at.together().is_empty() {
                    let together: Vec<usize> = at.together().iter().map(|l| l.bone).collect();
                    let left = shear_with_uniform(&source, &together, bone, time);
                    assert!(left <= tolerance, "{place}: {together:?} together leave {left}°");
                    assert!(explained.headline(rig.unit).contains(" together"), "{}", explained.headline(rig.unit));
                    named_together += 1;
                }
            }
            for name in &report.non_uniform {
                let bone = rig.skeleton.find(name).unwrap();
                let unequal = analysis.times.iter().any(|&time| {
                    let m = source.pose_at(time).model.model[bone];
                    let k = [m.x_axis, m.y_axis, m.z_axis].map(|c| c.truncate().length());
                    let (min, max) =
                        (k.iter().copied().fold(f64::INFINITY, f64::min), k.iter().copied().fold(0.0, f64::max));
                    max / min - 1.0 > options.tolerances.min_non_uniform
                });
                assert!(unequal, "{}: {name} listed non-uniform in `{}`", path.display(), clip.label());
            }
        }
    }
    assert!(named_one > 0 && named_together > 0, "{named_one} single causes, {named_together} named together");
}
