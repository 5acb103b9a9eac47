//! The hostile corpus: malformed, extreme and amplifying BVH, FBX, glTF and USD files (`usd.rs`), made on the fly (nothing stored),
//! one [`Case`] per way a file can attack, grouped by the categories of what must never happen (1 memory, 2 time,
//! 3 non-finite numbers, 4 malformed files read as another rig, 5 control characters, 6 reading outside the file's
//! folder, 8 leniency; category 7, a scanned library, is built from these by the test).

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use serde_json::json;

use super::gltf::Gltf;

/// What a case's folder holds besides plain files.
pub enum Entry {
    File(Vec<u8>),
    /// A symbolic link to this target (relative to the link's folder, or absolute).
    Symlink(PathBuf),
    /// A named pipe (which blocks whoever opens it for reading).
    Fifo,
}

/// What bonescope must make of a case.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Expect {
    /// Loads (exit 0); the notes hold this text when it is not empty.
    Loads(&'static str),
    /// Refused: exit 2, one line naming the file and holding this text (the place, or the budget's figure).
    Refused(&'static str),
    /// Either loads, or is refused by the memory budget (which one depends on the machine's memory).
    LoadsOrBudget,
}

pub struct Case {
    pub name: &'static str,
    pub category: u8,
    /// The file to open, relative to the case's folder.
    pub main: &'static str,
    pub entries: Vec<(&'static str, Entry)>,
    pub expect: Expect,
    /// Among the huge cases measured in BENCHMARKS.md.
    pub huge: bool,
}

impl Case {
    pub fn new(name: &'static str, category: u8, main: &'static str, bytes: Vec<u8>, expect: Expect) -> Self {
        Case { name, category, main, entries: vec![(main, Entry::File(bytes))], expect, huge: false }
    }

    pub fn huge(mut self) -> Self {
        self.huge = true;
        self
    }

    pub fn with(mut self, name: &'static str, entry: Entry) -> Self {
        self.entries.push((name, entry));
        self
    }

    /// Writes the case into `dir/<name>/`; returns the path of its main file. A file `secret.bin` is written
    /// beside the case folders (in `dir/outside/`) for cases that try to read it.
    pub fn write(&self, dir: &Path) -> PathBuf {
        let folder = dir.join(self.name);
        std::fs::create_dir_all(&folder).unwrap();
        let outside = dir.join("outside");
        std::fs::create_dir_all(&outside).unwrap();
        std::fs::write(outside.join("secret.bin"), vec![0u8; 4096]).unwrap();
        for (name, entry) in &self.entries {
            let path = folder.join(name);
            std::fs::create_dir_all(path.parent().unwrap()).unwrap();
            match entry {
                Entry::File(bytes) => std::fs::write(&path, bytes).unwrap(),
                Entry::Symlink(target) => std::os::unix::fs::symlink(target, &path).unwrap(),
                Entry::Fifo => {
                    let made = std::process::Command::new("mkfifo").arg(&path).status().unwrap();
                    assert!(made.success(), "mkfifo {}", path.display());
                }
            }
        }
        folder.join(self.main)
    }
}

/// Every case.
pub fn all() -> Vec<Case> {
    let mut cases = Vec::new();
    cases.extend(memory());
    cases.extend(time());
    cases.extend(non_finite());
    cases.extend(malformed());
    cases.extend(control_characters());
    cases.extend(outside_the_folder());
    cases.extend(leniency());
    cases.extend(super::usd::cases());
    cases
}

/// A well-formed animated glTF (a chain of three nodes whose scales grow non-uniformly: stretched bones to report),
/// to scan beside the hostile files.
pub fn good_gltf() -> Vec<u8> {
    let mut g = Gltf::new();
    let input = g.floats(&[0.0, 1.0], "SCALAR", 1);
    let output = g.floats(&[1.0, 1.0, 1.0, 2.0, 1.0, 0.5], "VEC3", 3);
    let rotation = g.floats(&[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.383, 0.924], "VEC4", 4);
    let mut channels = Vec::new();
    for n in 0..3 {
        let children: Vec<usize> = if n < 2 { vec![n + 1] } else { vec![] };
        g.node(json!({"children": children, "translation": [0.0, 1.0, 0.0]}));
        channels.push(json!({"sampler": 0, "target": {"node": n, "path": "scale"}}));
        channels.push(json!({"sampler": 1, "target": {"node": n, "path": "rotation"}}));
    }
    let samplers = json!([{"input": input, "output": output}, {"input": input, "output": rotation}]);
    g.json["animations"] = json!([{"samplers": samplers, "channels": channels}]);
    g.glb()
}

// -------------------------------------------------------------------------------------------------------------
// 1. Memory amplification

fn memory() -> Vec<Case> {
    vec![
        Case::new("gltf_shared_sampler", 1, "a.glb", shared_sampler(2_000, 100_000), Expect::LoadsOrBudget).huge(),
        Case::new("gltf_instances", 1, "a.glb", instances(20_000, 100_000), Expect::LoadsOrBudget).huge(),
        Case::new("gltf_shared_ibm", 1, "a.glb", shared_inverse_binds(2_000, 100_000), Expect::Loads("")).huge(),
        Case::new("bvh_million_joints", 1, "a.bvh", wide_bvh(1_000_000), Expect::LoadsOrBudget).huge(),
        Case::new("fbx_instances", 1, "a.fbx", fbx_instances(20_000, 100_000), Expect::LoadsOrBudget).huge(),
    ]
}

/// `channels` nodes whose translation channels all share one sampler of `keys` keys.
pub fn shared_sampler(channels: usize, keys: usize) -> Vec<u8> {
    let mut g = Gltf::new();
    let times: Vec<f32> = (0..keys).map(|k| k as f32 / 30.0).collect();
    let values: Vec<f32> = (0..keys * 3).map(|i| (i % 7) as f32).collect();
    let input = g.floats(&times, "SCALAR", 1);
    let output = g.floats(&values, "VEC3", 3);
    let children: Vec<usize> = (1..=channels).collect();
    g.node(json!({"children": children}));
    for _ in 0..channels {
        g.node(json!({}));
    }
    let channels: Vec<_> =
        (1..=channels).map(|n| json!({"sampler": 0, "target": {"node": n, "path": "translation"}})).collect();
    g.json["animations"] = json!([{"samplers": [{"input": input, "output": output}], "channels": channels}]);
    g.glb()
}

/// `instances` nodes showing one mesh of `vertices` vertices.
fn instances(instances: usize, vertices: usize) -> Vec<u8> {
    let mut g = Gltf::new();
    let positions: Vec<f32> = (0..vertices * 3).map(|i| (i % 11) as f32).collect();
    let position = g.floats(&positions, "VEC3", 3);
    g.mesh(json!({"attributes": {"POSITION": position}}));
    let children: Vec<usize> = (1..=instances).collect();
    g.node(json!({"children": children}));
    for _ in 0..instances {
        g.node(json!({"mesh": 0}));
    }
    g.glb()
}

/// `skins` skins of one joint each, all reading one accessor of `matrices` inverse bind matrices.
fn shared_inverse_binds(skins: usize, matrices: usize) -> Vec<u8> {
    let mut g = Gltf::new();
    let identity = [1.0f32, 0., 0., 0., 0., 1., 0., 0., 0., 0., 1., 0., 0., 0., 0., 1.];
    let all: Vec<f32> = (0..matrices).flat_map(|_| identity).collect();
    let accessor = g.floats(&all, "MAT4", 16);
    g.node(json!({"children": [1]}));
    g.node(json!({}));
    g.json["skins"] =
        json!((0..skins).map(|_| json!({"joints": [1], "inverseBindMatrices": accessor})).collect::<Vec<_>>());
    g.glb()
}

/// A BVH whose root has `joints` children, one frame.
pub fn wide_bvh(joints: usize) -> Vec<u8> {
    let mut text = String::from("HIERARCHY\nROOT r\n{\nOFFSET 0 0 0\nCHANNELS 3 Xposition Yposition Zposition\n");
    for j in 0..joints {
        writeln!(text, "JOINT j{j}\n{{\nOFFSET 0 1 0\nCHANNELS 0\n}}").unwrap();
    }
    text.push_str("}\nMOTION\nFrames: 1\nFrame Time: 0.033333\n0 0 0\n");
    text.into_bytes()
}

/// An ASCII FBX of `instances` models sharing one geometry of `vertices` vertices.
fn fbx_instances(instances: usize, vertices: usize) -> Vec<u8> {
    let coordinates: Vec<String> = (0..vertices * 3).map(|i| (i % 5).to_string()).collect();
    let indices: Vec<String> = (0..vertices - vertices % 3)
        .map(|i| if i % 3 == 2 { (-(i as i64) - 1).to_string() } else { i.to_string() })
        .collect();
    let mut objects = format!(
        "\tGeometry: 1, \"Geometry::g\", \"Mesh\" {{\n\t\tVertices: *{} {{\n\t\t\ta: {}\n\t\t}}\n\
         \t\tPolygonVertexIndex: *{} {{\n\t\t\ta: {}\n\t\t}}\n\t}}\n",
        coordinates.len(),
        coordinates.join(","),
        indices.len(),
        indices.join(","),
    );
    let mut connections = String::new();
    for i in 0..instances {
        let id = 100 + i;
        writeln!(objects, "\tModel: {id}, \"Model::m{i}\", \"Mesh\" {{\n\t\tVersion: 232\n\t}}").unwrap();
        writeln!(connections, "\tC: \"OO\",{id},0\n\tC: \"OO\",1,{id}").unwrap();
    }
    ascii_fbx(&objects, &connections).into_bytes()
}

// -------------------------------------------------------------------------------------------------------------
// 2. Time

fn time() -> Vec<Case> {
    vec![
        Case::new("fbx_binary_nested", 2, "a.fbx", binary_fbx_nested(100_000), Expect::Refused("nested deeper")),
        Case::new("fbx_ascii_nested", 2, "a.fbx", ascii_fbx_nested(100_000), Expect::Refused("nested deeper")),
        Case::new("bvh_nested", 2, "a.bvh", nested_bvh(100_000), Expect::Loads("")),
        Case::new("gltf_nested", 2, "a.gltf", nested_gltf(100_000), Expect::Loads("")),
        Case::new("gltf_deep_json", 2, "a.gltf", deep_json(100_000), Expect::Loads("")),
        Case::new("bvh_long", 2, "a.bvh", long_bvh(60 << 20), Expect::Loads("")).huge(),
        Case::new("gltf_long", 2, "a.glb", long_gltf(60 << 20), Expect::LoadsOrBudget).huge(),
    ]
}

/// A binary FBX 7.4 of `depth` records, each the only child of the one before.
fn binary_fbx_nested(depth: usize) -> Vec<u8> {
    const HEADER: usize = 27;
    const RECORD: usize = 13 + 1;
    let mut out = b"Kaydara FBX Binary  \0\x1a\0".to_vec();
    out.extend(7400u32.to_le_bytes());
    // Record k starts at HEADER + k·RECORD; the null records closing the lists follow the innermost one.
    let total = HEADER + depth * RECORD + depth * 13;
    for k in 0..depth {
        let end = total - k * 13;
        out.extend((end as u32).to_le_bytes());
        out.extend(0u32.to_le_bytes());
        out.extend(0u32.to_le_bytes());
        out.push(1);
        out.push(b'N');
    }
    out.resize(total + 13, 0);
    out
}

/// An ASCII FBX of `depth` nested blocks.
fn ascii_fbx_nested(depth: usize) -> Vec<u8> {
    let mut text = String::from("; FBX 7.4.0 project file\nObjects:  {\n");
    text.push_str(&"N: {\n".repeat(depth));
    text.push_str(&"}\n".repeat(depth + 1));
    text.into_bytes()
}

/// A BVH chain of `depth` joints.
fn nested_bvh(depth: usize) -> Vec<u8> {
    let mut text = String::from("HIERARCHY\nROOT r\n{\nOFFSET 0 0 0\nCHANNELS 3 Zrotation Xrotation Yrotation\n");
    for j in 0..depth {
        writeln!(text, "JOINT j{j}\n{{\nOFFSET 0 0.001 0").unwrap();
    }
    text.push_str(&"}\n".repeat(depth + 1));
    text.push_str("MOTION\nFrames: 2\nFrame Time: 0.1\n0 0 0\n10 20 30\n");
    text.into_bytes()
}

/// A glTF chain of `depth` nodes.
fn nested_gltf(depth: usize) -> Vec<u8> {
    let mut g = Gltf::new();
    for n in 0..depth {
        let children: Vec<usize> = if n + 1 < depth { vec![n + 1] } else { vec![] };
        g.node(json!({"children": children, "translation": [0.0, 0.01, 0.0]}));
    }
    serde_json::to_vec(&g.json).unwrap()
}

/// A glTF whose `extras` (which bonescope never reads) are arrays nested `depth` deep.
fn deep_json(depth: usize) -> Vec<u8> {
    let nested = format!("{}{}", "[".repeat(depth), "]".repeat(depth));
    format!("{{\"asset\": {{\"version\": \"2.0\"}}, \"extras\": {nested}}}").into_bytes()
}

/// A BVH of about `size` bytes: 30 joints, as many frames as fit.
fn long_bvh(size: usize) -> Vec<u8> {
    let mut text = String::from(
        "HIERARCHY\nROOT r\n{\nOFFSET 0 0 0\nCHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n",
    );
    for j in 0..29 {
        writeln!(text, "JOINT j{j}\n{{\nOFFSET 0 1 0\nCHANNELS 3 Zrotation Xrotation Yrotation").unwrap();
    }
    text.push_str(&"}\n".repeat(30));
    let row: String = (0..93).map(|i| format!("{:.4} ", (i as f64 * 0.37).sin() * 40.0)).collect::<String>() + "\n";
    let frames = size / row.len();
    write!(text, "MOTION\nFrames: {frames}\nFrame Time: 0.008333\n").unwrap();
    text.reserve(size);
    for _ in 0..frames {
        text.push_str(&row);
    }
    text.into_bytes()
}

/// A GLB of about `size` bytes: 100 chained nodes with rotation and translation channels of as many keys as fit.
fn long_gltf(size: usize) -> Vec<u8> {
    const NODES: usize = 100;
    let keys = size / (NODES * 28 + 4);
    let mut g = Gltf::new();
    let times: Vec<f32> = (0..keys).map(|k| k as f32 / 120.0).collect();
    let input = g.floats(&times, "SCALAR", 1);
    let mut samplers = Vec::new();
    let mut channels = Vec::new();
    for n in 0..NODES {
        let rotations: Vec<f32> = (0..keys)
            .flat_map(|k| {
                let half = (k as f32 * 0.01 + n as f32).sin() * 0.5;
                [half.sin(), 0.0, 0.0, half.cos()]
            })
            .collect();
        let translations: Vec<f32> = (0..keys).flat_map(|k| [0.0, 1.0 + (k % 10) as f32 * 0.01, 0.0]).collect();
        let rotation = g.floats(&rotations, "VEC4", 4);
        let translation = g.floats(&translations, "VEC3", 3);
        for (output, path) in [(rotation, "rotation"), (translation, "translation")] {
            channels.push(json!({"sampler": samplers.len(), "target": {"node": n, "path": path}}));
            samplers.push(json!({"input": input, "output": output}));
        }
        let children: Vec<usize> = if n + 1 < NODES { vec![n + 1] } else { vec![] };
        g.node(json!({"children": children}));
    }
    g.json["animations"] = json!([{"samplers": samplers, "channels": channels}]);
    g.glb()
}

// -------------------------------------------------------------------------------------------------------------
// 3. Non-finite numbers

fn non_finite() -> Vec<Case> {
    vec![
        Case::new("bvh_huge_offsets", 3, "a.bvh", bvh_chain_offsets("1e308", 4), Expect::Refused("j")),
        Case::new("fbx_huge_scale", 3, "a.fbx", fbx_chain_scale("1e300", 3), Expect::Refused("n")),
        Case::new("fbx_zero_scale", 3, "a.fbx", fbx_chain_scale("0", 3), Expect::Loads("")),
        Case::new("gltf_huge_scales", 3, "a.gltf", gltf_chain_scale(1e30, 12), Expect::Refused("node")),
        Case::new("gltf_zero_scale_skin", 3, "a.glb", gltf_zero_scale_skin(), Expect::Loads("")),
        Case::new("gltf_huge_animated_scale", 3, "a.glb", gltf_animated_scale(1e30, 12), Expect::Refused("node")),
    ]
}

fn bvh_chain_offsets(offset: &str, depth: usize) -> Vec<u8> {
    let mut text = String::from("HIERARCHY\nROOT r\n{\nOFFSET 0 0 0\nCHANNELS 3 Zrotation Xrotation Yrotation\n");
    for j in 0..depth {
        writeln!(text, "JOINT j{j}\n{{\nOFFSET {offset} {offset} 0\nCHANNELS 3 Zrotation Xrotation Yrotation").unwrap();
    }
    text.push_str(&"}\n".repeat(depth + 1));
    let row = "10 20 30 ".repeat(depth + 1);
    write!(text, "MOTION\nFrames: 2\nFrame Time: 0.1\n{row}\n{row}\n").unwrap();
    text.into_bytes()
}

/// An ASCII FBX chain of `depth` nulls, each scaled by `scale`.
fn fbx_chain_scale(scale: &str, depth: usize) -> Vec<u8> {
    let mut objects = String::new();
    let mut connections = String::new();
    for i in 0..depth {
        let id = i + 1;
        write!(
            objects,
            "\tModel: {id}, \"Model::n{i}\", \"Null\" {{\n\t\tVersion: 232\n\t\tProperties70:  {{\n\
             \t\t\tP: \"Lcl Translation\", \"Lcl Translation\", \"\", \"A\",1,2,3\n\
             \t\t\tP: \"Lcl Scaling\", \"Lcl Scaling\", \"\", \"A\",{scale},{scale},{scale}\n\t\t}}\n\t}}\n"
        )
        .unwrap();
        writeln!(connections, "\tC: \"OO\",{id},{i}").unwrap();
    }
    ascii_fbx(&objects, &connections).into_bytes()
}

/// A glTF chain of `depth` nodes scaled by `scale`.
fn gltf_chain_scale(scale: f64, depth: usize) -> Vec<u8> {
    let mut g = Gltf::new();
    for n in 0..depth {
        let children: Vec<usize> = if n + 1 < depth { vec![n + 1] } else { vec![] };
        g.node(json!({"children": children, "scale": [scale, scale, scale], "translation": [1.0, 0.0, 0.0]}));
    }
    serde_json::to_vec(&g.json).unwrap()
}

/// A skinned triangle whose joint has a zero scale at rest (its inverse bind matrix the identity).
fn gltf_zero_scale_skin() -> Vec<u8> {
    let mut g = Gltf::new();
    let position = g.triangle_positions();
    let joints = g.u16s(&[0; 12], "VEC4", 4);
    let weights = g.floats(&[1.0, 0.0, 0.0, 0.0].repeat(3), "VEC4", 4);
    let identity = [1.0f32, 0., 0., 0., 0., 1., 0., 0., 0., 0., 1., 0., 0., 0., 0., 1.];
    let ibm = g.floats(&identity, "MAT4", 16);
    g.mesh(json!({"attributes": {"POSITION": position, "JOINTS_0": joints, "WEIGHTS_0": weights}}));
    g.node(json!({"children": [1, 2]}));
    g.node(json!({"scale": [0.0, 0.0, 0.0]}));
    g.node(json!({"mesh": 0, "skin": 0}));
    g.json["skins"] = json!([{"joints": [1], "inverseBindMatrices": ibm}]);
    g.glb()
}

/// A glTF chain of `depth` nodes, each with a scale channel going from 1 to `scale`.
fn gltf_animated_scale(scale: f32, depth: usize) -> Vec<u8> {
    let mut g = Gltf::new();
    let input = g.floats(&[0.0, 1.0], "SCALAR", 1);
    let output = g.floats(&[1.0, 1.0, 1.0, scale, scale, scale], "VEC3", 3);
    let mut channels = Vec::new();
    for n in 0..depth {
        let children: Vec<usize> = if n + 1 < depth { vec![n + 1] } else { vec![] };
        g.node(json!({"children": children, "translation": [1.0, 0.0, 0.0]}));
        channels.push(json!({"sampler": 0, "target": {"node": n, "path": "scale"}}));
    }
    g.json["animations"] = json!([{"samplers": [{"input": input, "output": output}], "channels": channels}]);
    g.glb()
}

// -------------------------------------------------------------------------------------------------------------
// 4. Malformed files

fn malformed() -> Vec<Case> {
    let good = String::from_utf8(fbx_chain_scale("1", 3)).unwrap();
    let missing_open = good.replacen("Properties70:  {", "Properties70:  ", 1);
    let missing_close = good.replacen("\t\t}\n\t}\n", "\t\t}\n", 1);
    let extra_close = good.replacen("\t\t}\n\t}\n", "\t\t}\n\t}\n\t}\n", 1);
    let mut scale = Gltf::new();
    scale.node(json!({"scale": [1e39, 1.0, 1.0]}));
    let mut matrix = Gltf::new();
    matrix.node(json!({"matrix": [1e39, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]}));
    vec![
        Case::new("fbx_missing_open", 4, "a.fbx", missing_open.into_bytes(), Expect::Refused("line")),
        Case::new("fbx_missing_close", 4, "a.fbx", missing_close.into_bytes(), Expect::Refused("line")),
        Case::new("fbx_extra_close", 4, "a.fbx", extra_close.into_bytes(), Expect::Refused("line")),
        Case::new(
            "gltf_scale_1e39",
            4,
            "a.gltf",
            serde_json::to_vec(&scale.json).unwrap(),
            Expect::Refused("nodes[0].scale"),
        ),
        Case::new(
            "gltf_matrix_1e39",
            4,
            "a.gltf",
            serde_json::to_vec(&matrix.json).unwrap(),
            Expect::Refused("nodes[0].matrix"),
        ),
        Case::new("glb_bad_magic", 4, "a.glb", b"glTX\x02\0\0\0\x0c\0\0\0".to_vec(), Expect::Refused("a.glb")),
        Case::new("gltf_empty", 4, "a.gltf", Vec::new(), Expect::Refused("a.gltf")),
        Case::new(
            "gltf_not_json",
            4,
            "a.gltf",
            b"solid cube\nfacet normal 0 0 1\n".to_vec(),
            Expect::Refused("a.gltf"),
        ),
    ]
}

// -------------------------------------------------------------------------------------------------------------
// 5. Control characters

/// A name meant to retitle and clear a terminal, with a NUL and a line break, and long.
pub const EVIL: &str = "\u{1b}]0;pwned\u{7}\u{1b}[2J\u{0}line\nbreak\r";

fn control_characters() -> Vec<Case> {
    let long = format!("{EVIL}{}", "x".repeat(10_000));
    let mut names = Gltf::new();
    names.node(json!({"name": EVIL, "children": [1]}));
    names.node(json!({"name": long}));
    let mut required = Gltf::new();
    required.node(json!({}));
    required.json["extensionsRequired"] = json!([EVIL]);
    let mut uri = Gltf::new();
    uri.node(json!({"mesh": 0}));
    let position = uri.triangle_positions();
    uri.mesh(json!({"attributes": {"POSITION": position}}));
    let bvh_names = format!(
        "HIERARCHY\nROOT {EVIL}\n{{\nOFFSET 0 0 0\nCHANNELS 1 Zrotation\n}}\nMOTION\nFrames: 1\nFrame Time: 0.1\n0\n"
    )
    .replace("\nbreak\r", "");
    let mut bvh_bytes = b"HIERARCHY\nROOT \xff\xfe\x1b[2J\x07\n{\nOFFSET 0 0 0\n".to_vec();
    bvh_bytes.extend(b"\x1b]0;keyword\x07 1 2\n}\nMOTION\n");
    let fbx_names =
        String::from_utf8(fbx_chain_scale("1", 2)).unwrap().replace("Model::n1", "Model::\u{1b}]0;pwned\u{7}\u{1b}[2J");
    let mut fbx_record = binary_fbx_nested(3);
    fbx_record[27 + 13] = 0x1b;
    let cut = fbx_record.len() - 20;
    fbx_record.truncate(cut);
    vec![
        Case::new("gltf_names", 5, "a.gltf", serde_json::to_vec(&names.json).unwrap(), Expect::Loads("")),
        Case::new(
            "gltf_required_name",
            5,
            "a.gltf",
            serde_json::to_vec(&required.json).unwrap(),
            Expect::Refused("extensionsRequired[0]"),
        ),
        Case::new(
            "gltf_uri",
            5,
            "a.gltf",
            uri.gltf_with_uri("%1B]0;pwned%07%1B[2J.bin"),
            Expect::Refused("buffers[0]"),
        ),
        Case::new("bvh_names", 5, "a.bvh", bvh_names.into_bytes(), Expect::Loads("")),
        Case::new("bvh_keyword", 5, "a.bvh", bvh_bytes, Expect::Refused("line 5")),
        Case::new("fbx_names", 5, "a.fbx", fbx_names.into_bytes(), Expect::Loads("")),
        Case::new("fbx_record_name", 5, "a.fbx", fbx_record, Expect::Refused("byte")),
        Case::new(
            "file_name",
            5,
            "\u{1b}]0;pwned\u{7}\u{1b}[2J.bvh",
            b"HIERARCHY\n\x1b[2J\n".to_vec(),
            Expect::Refused("line 2"),
        ),
    ]
}

// -------------------------------------------------------------------------------------------------------------
// 6. Outside the file's folder

fn outside_the_folder() -> Vec<Case> {
    let mut g = Gltf::new();
    g.node(json!({"mesh": 0}));
    let position = g.triangle_positions();
    g.mesh(json!({"attributes": {"POSITION": position}}));
    let bin = g.bin.clone();
    let case = |name, uri, expect| Case::new(name, 6, "a.gltf", g.gltf_with_uri(uri), expect);
    vec![
        case("gltf_symlink_out", "data.bin", Expect::Refused("buffers[0]"))
            .with("data.bin", Entry::Symlink("../outside/secret.bin".into())),
        case("gltf_symlinked_folder", "sub/secret.bin", Expect::Refused("buffers[0]"))
            .with("sub", Entry::Symlink("../outside".into())),
        case("gltf_dev_zero", "zero.bin", Expect::Refused("buffers[0]"))
            .with("zero.bin", Entry::Symlink("/dev/zero".into())),
        case("gltf_fifo", "fifo.bin", Expect::Refused("buffers[0]")).with("fifo.bin", Entry::Fifo),
        case("gltf_folder", "sub", Expect::Refused("buffers[0]")).with("sub/x.bin", Entry::File(bin.clone())),
        case("gltf_symlink_in", "link.bin", Expect::Loads(""))
            .with("data/real.bin", Entry::File(bin))
            .with("link.bin", Entry::Symlink("data/real.bin".into())),
        Case {
            name: "fifo_file",
            category: 6,
            main: "a.gltf",
            entries: vec![("a.gltf", Entry::Fifo)],
            expect: Expect::Refused("a.gltf"),
            huge: false,
        },
    ]
}

// -------------------------------------------------------------------------------------------------------------
// 8. Leniency

fn leniency() -> Vec<Case> {
    let bvh = |rows: usize| {
        let mut text = String::from(
            "HIERARCHY\nROOT r\n{\nOFFSET 0 0 0\nCHANNELS 1 Zrotation\n}\nMOTION\nFrames: 2\nFrame Time: 0.1\n",
        );
        text.push_str(&"5\n".repeat(rows));
        text.into_bytes()
    };
    let primitive = |mode: u32, positions: &[f32], indices: Option<&[u16]>| {
        let mut g = Gltf::new();
        g.node(json!({"mesh": 0}));
        let position = g.floats(positions, "VEC3", 3);
        let mut primitive = json!({"attributes": {"POSITION": position}, "mode": mode});
        if let Some(indices) = indices {
            primitive["indices"] = json!(g.u16s(indices, "SCALAR", 1));
        }
        g.mesh(primitive);
        g.glb()
    };
    let square = [0.0f32, 0., 0., 1., 0., 0., 1., 1., 0., 0., 1., 0.];
    let nan = [0.0f32, 0., 0., 1., 0., 0., f32::NAN, 1., 0., 0., 1., 0., 1., 1., 0.];
    let incomplete: Vec<u16> = (0..35).map(|i| i % 4).collect();
    let required = |name: &str| {
        let mut g = Gltf::new();
        g.node(json!({}));
        g.json["extensionsRequired"] = json!([name]);
        g.json["extensionsUsed"] = json!([name]);
        serde_json::to_vec(&g.json).unwrap()
    };
    vec![
        Case::new("bvh_extra_row", 8, "a.bvh", bvh(3), Expect::Loads("more")),
        Case::new("bvh_missing_row", 8, "a.bvh", bvh(1), Expect::Refused("line")),
        Case::new("gltf_strip", 8, "a.glb", primitive(5, &square, None), Expect::Loads("")),
        Case::new("gltf_fan", 8, "a.glb", primitive(6, &square, None), Expect::Loads("")),
        Case::new(
            "gltf_incomplete_triangle",
            8,
            "a.glb",
            primitive(4, &square, Some(&incomplete)),
            Expect::Loads("incomplete"),
        ),
        Case::new("gltf_nan_position", 8, "a.glb", primitive(4, &nan, None), Expect::Loads("not finite")),
        Case::new(
            "gltf_techniques",
            8,
            "a.gltf",
            required("KHR_techniques_webgl"),
            Expect::Loads("KHR_techniques_webgl"),
        ),
        Case::new("gltf_draco", 8, "a.glb", undecodable_draco(), Expect::Loads("compressed geometry does not decode")),
        Case::new(
            "gltf_meshopt",
            8,
            "a.glb",
            undecodable_meshopt(),
            Expect::Loads("compressed geometry does not decode"),
        ),
        Case::new("gltf_nan_weight", 8, "a.glb", nan_weight(), Expect::Loads("not finite")),
        Case::new("fbx_nan_vertex", 8, "a.fbx", fbx_nan_vertex(), Expect::Loads("not finite")),
        Case::new("gltf_eight_influences", 8, "a.glb", eight_influences(), Expect::Loads("more than 4 influences")),
    ]
}

/// A triangle with a vertex at NaN, shown by one mesh node.
/// A triangle whose Draco stream (`KHR_draco_mesh_compression`) is not one: the mesh is left out, the file loads.
fn undecodable_draco() -> Vec<u8> {
    let mut g = Gltf::new();
    let stream = g.floats(&[1.0; 16], "SCALAR", 1);
    let position = g.floats(&[0.0; 9], "VEC3", 3);
    g.json["accessors"][position].as_object_mut().unwrap().remove("bufferView");
    let draco = json!({"KHR_draco_mesh_compression": {"bufferView": stream, "attributes": {"POSITION": 0}}});
    g.mesh(json!({"attributes": {"POSITION": position}, "extensions": draco}));
    g.node(json!({"mesh": 0}));
    g.json["extensionsRequired"] = json!(["KHR_draco_mesh_compression"]);
    g.glb()
}

/// A triangle whose positions lie in a buffer view `EXT_meshopt_compression` says holds them compressed, over bytes
/// that are not a vertex stream: the mesh is left out, the file loads.
fn undecodable_meshopt() -> Vec<u8> {
    let mut g = Gltf::new();
    let position = g.floats(&[0.5; 9], "VEC3", 3);
    let compressed = json!({"buffer": 0, "byteLength": 36, "byteStride": 12, "count": 3, "mode": "ATTRIBUTES"});
    g.json["bufferViews"][position]["extensions"] = json!({"EXT_meshopt_compression": compressed});
    g.mesh(json!({"attributes": {"POSITION": position}}));
    g.node(json!({"mesh": 0}));
    g.json["extensionsRequired"] = json!(["EXT_meshopt_compression"]);
    g.glb()
}

fn fbx_nan_vertex() -> Vec<u8> {
    let objects = "\tGeometry: 1, \"Geometry::g\", \"Mesh\" {\n\t\tVertices: *9 {\n\t\t\ta: 0,0,0,1,0,0,nan,1,0\n\t\t}\n\
                   \t\tPolygonVertexIndex: *3 {\n\t\t\ta: 0,1,-3\n\t\t}\n\t}\n\
                   \tModel: 100, \"Model::m\", \"Mesh\" {\n\t\tVersion: 232\n\t}\n";
    ascii_fbx(objects, "\tC: \"OO\",100,0\n\tC: \"OO\",1,100\n").into_bytes()
}

/// A skinned triangle whose first vertex has eight influences (`JOINTS_1`/`WEIGHTS_1`), on eight joints.
fn eight_influences() -> Vec<u8> {
    let mut g = Gltf::new();
    let position = g.triangle_positions();
    let joints_0 = g.u16s(&[0, 1, 2, 3, 0, 0, 0, 0, 0, 0, 0, 0], "VEC4", 4);
    let joints_1 = g.u16s(&[4, 5, 6, 7, 0, 0, 0, 0, 0, 0, 0, 0], "VEC4", 4);
    let weights_0 = g.floats(&[0.125, 0.125, 0.125, 0.125, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0], "VEC4", 4);
    let weights_1 = g.floats(&[0.125, 0.125, 0.125, 0.125, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0], "VEC4", 4);
    g.mesh(json!({"attributes": {
        "POSITION": position, "JOINTS_0": joints_0, "WEIGHTS_0": weights_0, "JOINTS_1": joints_1, "WEIGHTS_1": weights_1,
    }}));
    g.node(json!({"children": [1, 2, 3, 4, 5, 6, 7, 8, 9]}));
    for _ in 0..8 {
        g.node(json!({}));
    }
    g.node(json!({"mesh": 0, "skin": 0}));
    g.json["skins"] = json!([{"joints": [1, 2, 3, 4, 5, 6, 7, 8]}]);
    g.glb()
}

/// A skinned triangle one of whose vertices has a NaN weight.
fn nan_weight() -> Vec<u8> {
    let mut g = Gltf::new();
    let position = g.triangle_positions();
    let joints = g.u16s(&[0; 12], "VEC4", 4);
    let weights = g.floats(&[1.0, 0.0, 0.0, 0.0, f32::NAN, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0], "VEC4", 4);
    g.mesh(json!({"attributes": {"POSITION": position, "JOINTS_0": joints, "WEIGHTS_0": weights}}));
    g.node(json!({"children": [1, 2]}));
    g.node(json!({}));
    g.node(json!({"mesh": 0, "skin": 0}));
    g.json["skins"] = json!([{"joints": [1]}]);
    g.glb()
}

/// An ASCII FBX 7.4 file of these objects and connections.
fn ascii_fbx(objects: &str, connections: &str) -> String {
    format!(
        "; FBX 7.4.0 project file\nFBXHeaderExtension:  {{\n\tFBXHeaderVersion: 1003\n\tFBXVersion: 7400\n}}\n\
         Objects:  {{\n{objects}}}\nConnections:  {{\n{connections}}}\n"
    )
}
