//! The generated glTF that loading is measured on: 200 bones in branching chains, 6,000 frames at 60 Hz (100 s)
//! with a rotation key on every bone at every frame, about 20 MB, the size of a long mocap take or a game's whole
//! locomotion set. It is made here rather than stored, the same bytes every time (closed-form curves, no
//! randomness), through the `gltf` crate's JSON types and GLB writer, so the file is what a conforming exporter
//! writes and not what bonescope's reader happens to accept.
//!
//! As exporters write them: key times are single precision (`k / 60` rounded to `f32`, which misses the 60 Hz grid
//! by up to a few microseconds), every sampler shares one time accessor, and each accessor has its own buffer view.
//! The root walks, and some bones squash and stretch ([`Squashes`]), so bones below them shear and an analysis has
//! work.
//! The root also carries a skinned mesh, a small square plate at every joint (loaders such as assimp refuse a file
//! without one).
//! Two containers of the same document: [`glb`] (binary, what large files are shipped as) and [`gltf_embedded`]
//! (JSON with the buffer as a base64 `data:` URI, a third larger and all of it through the JSON parser).

use std::borrow::Cow;
use std::f64::consts::TAU;

use base64::Engine as _;
use gltf::binary::{Glb, Header};
use gltf::json::accessor::{ComponentType, GenericComponentType, Type};
use gltf::json::animation::{Channel, Interpolation, Property, Sampler, Target};
use gltf::json::mesh::{Mode, Primitive, Semantic};
use gltf::json::validation::Checked::Valid;
use gltf::json::validation::USize64;
use gltf::json::{self, Accessor, Index, Value};

pub const BONES: usize = 200;
pub const FRAMES: usize = 6_000;
pub const FRAME_RATE: f64 = 60.0;

/// Bones per chain: the spine is one, and 19 more hang off the spine's bones in turn.
const CHAIN: usize = 10;
/// Which bones squash and stretch.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Squashes {
    /// Every 25th bone (8 of them): the loading benchmarks' rig, 20 bones flagged.
    Sparse,
    /// The fifth bone of every limb (the 19 chains off the spine): a production clip of squash-and-stretch limbs,
    /// the five bones below each squash flagged (95 in all).
    EveryLimb,
    /// The sixth bone of every chain, the spine's too: a rig the explanation's speed was not tuned on, whose spine
    /// squash shears the chains hanging below it as well.
    SixthOfEveryChain,
}

impl Squashes {
    fn squashes(self, bone: usize) -> bool {
        match self {
            Squashes::Sparse => bone % 25 == 24,
            Squashes::EveryLimb => bone >= CHAIN && bone % CHAIN == 4,
            Squashes::SixthOfEveryChain => bone % CHAIN == 5,
        }
    }

    /// The name the file is written under by `write_generated_gltf`.
    pub fn file_stem(self) -> &'static str {
        match self {
            Squashes::Sparse => "generated_200x6000",
            Squashes::EveryLimb => "generated_limbs_200x6000",
            Squashes::SixthOfEveryChain => "generated_sixth_200x6000",
        }
    }
}

/// The document as binary glTF (`.glb`).
pub fn glb(squashes: Squashes) -> Vec<u8> {
    glb_of(document(None, squashes, false))
}

/// The same with every node resting at the clip's first frame, off its bind (the skin's inverse bind matrices stay
/// the unturned pose's), as exporters that store the first frame as the rest write it: a bind check then searches
/// the clip for the frame that is the bind pose.
pub fn glb_posed(squashes: Squashes) -> Vec<u8> {
    glb_of(document(None, squashes, true))
}

fn glb_of((root, bin): (json::Root, Vec<u8>)) -> Vec<u8> {
    let json = root.to_vec().expect("the document serializes");
    let glb = Glb {
        header: Header { magic: *b"glTF", version: 2, length: 0 },
        json: Cow::Owned(json),
        bin: Some(Cow::Owned(bin)),
    };
    glb.to_vec().expect("a GLB writes into memory")
}

/// The document as JSON glTF (`.gltf`) with its buffer embedded as a base64 `data:` URI.
pub fn gltf_embedded(squashes: Squashes) -> Vec<u8> {
    let (_, bin) = document(None, squashes, false);
    let uri = format!("data:application/octet-stream;base64,{}", base64::engine::general_purpose::STANDARD.encode(bin));
    document(Some(uri), squashes, false).0.to_vec().expect("the document serializes")
}

/// The JSON document and its binary buffer; `uri` is the buffer's URI (`None`: the GLB `BIN` chunk); `posed`: the
/// nodes rest at the first frame.
fn document(uri: Option<String>, squashes: Squashes, posed: bool) -> (json::Root, Vec<u8>) {
    let mut doc = Document { root: json::Root::default(), bin: Vec::new() };
    doc.root.asset.generator = Some("bonescope benches/support/generated_gltf.rs".to_owned());
    let nodes = doc.skeleton(posed);
    doc.skinned_plates(&nodes);
    doc.animation(&nodes, squashes);
    let byte_length = USize64::from(doc.bin.len());
    doc.root.push(json::Buffer { byte_length, name: None, uri, extensions: None, extras: Default::default() });
    (doc.root, doc.bin)
}

struct Document {
    root: json::Root,
    bin: Vec<u8>,
}

impl Document {
    /// The bones as nodes of the scene, parents first: the spine from the root up, then the other chains, each
    /// hanging off a spine bone (so the spine branches nine ways); resting at the first frame where `posed`.
    fn skeleton(&mut self, posed: bool) -> Vec<Index<json::Node>> {
        let parents: Vec<Option<usize>> = (0..BONES).map(parent).collect();
        let nodes: Vec<Index<json::Node>> = (0..BONES)
            .map(|bone| {
                let children: Vec<Index<json::Node>> = (0..BONES)
                    .filter(|&child| parents[child] == Some(bone))
                    .map(|child| Index::new(child as u32))
                    .collect();
                let rotation = posed.then(|| json::scene::UnitQuaternion(rotation(bone, 0.0)));
                self.root.push(json::Node {
                    name: Some(bone_name(bone)),
                    translation: Some(rest_offset(bone)),
                    rotation,
                    children: (!children.is_empty()).then_some(children),
                    ..Default::default()
                })
            })
            .collect();
        let scene = self.root.push(json::Scene {
            nodes: vec![nodes[0]],
            name: None,
            extensions: None,
            extras: Default::default(),
        });
        self.root.scene = Some(scene);
        nodes
    }

    /// A mesh on the root node skinned to every bone: a square plate 4 cm wide around each joint, bound to it alone.
    fn skinned_plates(&mut self, nodes: &[Index<json::Node>]) {
        let joints_at = rest_positions();
        let corners = [[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]].map(|[x, z]| [0.02 * x, 0.0, 0.02 * z]);
        let positions: Vec<f32> =
            joints_at.iter().flat_map(|at| corners.iter().flat_map(move |c| [0, 1, 2].map(|i| at[i] + c[i]))).collect();
        let (min, max) = bounds(&positions);
        let positions = self.accessor(&positions, Type::Vec3, Some((min, max)));
        let joints: Vec<u16> = (0..BONES as u16).flat_map(|bone| [[bone, 0, 0, 0]; 4].into_iter().flatten()).collect();
        let joints = self.accessor(&joints, Type::Vec4, None);
        let weights: Vec<f32> = [1.0, 0.0, 0.0, 0.0].repeat(4 * BONES);
        let weights = self.accessor(&weights, Type::Vec4, None);
        let indices: Vec<u16> = (0..BONES as u16).flat_map(|bone| [0, 1, 2, 0, 2, 3].map(|i| 4 * bone + i)).collect();
        let indices = self.accessor(&indices, Type::Scalar, None);
        // Bones rest unrotated, so binding is undoing each joint's rest position.
        let inverse_binds: Vec<f32> = joints_at
            .iter()
            .flat_map(|at| glam::Mat4::from_translation(-glam::Vec3::from_array(*at)).to_cols_array())
            .collect();
        let inverse_binds = self.accessor(&inverse_binds, Type::Mat4, None);
        let attributes =
            [(Semantic::Positions, positions), (Semantic::Joints(0), joints), (Semantic::Weights(0), weights)];
        let primitive = Primitive {
            attributes: attributes.into_iter().map(|(semantic, accessor)| (Valid(semantic), accessor)).collect(),
            indices: Some(indices),
            material: None,
            mode: Valid(Mode::Triangles),
            targets: None,
            extensions: None,
            extras: Default::default(),
        };
        let mesh = self.root.push(json::Mesh {
            name: Some("plates".to_owned()),
            primitives: vec![primitive],
            weights: None,
            extensions: None,
            extras: Default::default(),
        });
        let skin = self.root.push(json::Skin {
            name: None,
            joints: nodes.to_vec(),
            inverse_bind_matrices: Some(inverse_binds),
            skeleton: Some(nodes[0]),
            extensions: None,
            extras: Default::default(),
        });
        let root = &mut self.root.nodes[nodes[0].value()];
        root.mesh = Some(mesh);
        root.skin = Some(skin);
    }

    /// One clip: a rotation on every bone, the root's translation, and scale on the bones that `squashes`, all keyed
    /// at every frame.
    fn animation(&mut self, nodes: &[Index<json::Node>], squashes: Squashes) {
        let times: Vec<f32> = (0..FRAMES).map(|k| time(k) as f32).collect();
        let (first, last) = (times[0], times[FRAMES - 1]);
        let input = self.accessor(&times, Type::Scalar, Some((Value::from(vec![first]), Value::from(vec![last]))));
        let mut animation = json::Animation {
            name: Some("generated".to_owned()),
            channels: Vec::new(),
            samplers: Vec::new(),
            extensions: None,
            extras: Default::default(),
        };
        let mut channel = |node: Index<json::Node>, path: Property, output: Index<Accessor>| {
            let sampler = Index::push(
                &mut animation.samplers,
                Sampler {
                    input,
                    output,
                    interpolation: Valid(Interpolation::Linear),
                    extensions: None,
                    extras: Default::default(),
                },
            );
            let target = Target { node, path: Valid(path), extensions: None, extras: Default::default() };
            animation.channels.push(Channel { sampler, target, extensions: None, extras: Default::default() });
        };
        let walk: Vec<f32> = (0..FRAMES).flat_map(|k| walk(time(k))).collect();
        channel(nodes[0], Property::Translation, self.accessor(&walk, Type::Vec3, None));
        for (bone, &node) in nodes.iter().enumerate() {
            let rotations: Vec<f32> = (0..FRAMES).flat_map(|k| rotation(bone, time(k))).collect();
            channel(node, Property::Rotation, self.accessor(&rotations, Type::Vec4, None));
            if squashes.squashes(bone) {
                let scales: Vec<f32> = (0..FRAMES).flat_map(|k| squash(bone, time(k))).collect();
                channel(node, Property::Scale, self.accessor(&scales, Type::Vec3, None));
            }
        }
        self.root.push(animation);
    }

    /// An accessor of `values` (`type_` elements) in a buffer view of its own at the end of the buffer.
    fn accessor<T: Component>(
        &mut self,
        values: &[T],
        type_: Type,
        min_max: Option<(Value, Value)>,
    ) -> Index<Accessor> {
        // Every accessor starts on a multiple of 4 bytes, as the specification asks of float data.
        self.bin.resize(self.bin.len().next_multiple_of(4), 0);
        let offset = self.bin.len();
        values.iter().for_each(|v| v.write(&mut self.bin));
        let view = self.root.push(json::buffer::View {
            buffer: Index::new(0),
            byte_length: USize64::from(self.bin.len() - offset),
            byte_offset: Some(USize64::from(offset)),
            byte_stride: None,
            name: None,
            target: None,
            extensions: None,
            extras: Default::default(),
        });
        let (min, max) = min_max.unzip();
        self.root.push(Accessor {
            buffer_view: Some(view),
            byte_offset: None,
            count: USize64::from(values.len() / type_.multiplicity()),
            component_type: Valid(GenericComponentType(T::TYPE)),
            type_: Valid(type_),
            min,
            max,
            name: None,
            normalized: false,
            sparse: None,
            extensions: None,
            extras: Default::default(),
        })
    }
}

/// A component type an accessor can hold, written little-endian.
trait Component: Copy {
    const TYPE: ComponentType;
    fn write(self, out: &mut Vec<u8>);
}

impl Component for f32 {
    const TYPE: ComponentType = ComponentType::F32;
    fn write(self, out: &mut Vec<u8>) {
        out.extend(self.to_le_bytes());
    }
}

impl Component for u16 {
    const TYPE: ComponentType = ComponentType::U16;
    fn write(self, out: &mut Vec<u8>) {
        out.extend(self.to_le_bytes());
    }
}

/// The parent of `bone`: the previous bone in its chain, or for a chain's first bone a spine bone (chains take the
/// spine's bones above the root in turn).
fn parent(bone: usize) -> Option<usize> {
    match (bone / CHAIN, bone % CHAIN) {
        (0, 0) => None,
        (chain, 0) => Some(1 + (chain - 1) % (CHAIN - 1)),
        _ => Some(bone - 1),
    }
}

fn bone_name(bone: usize) -> String {
    match bone / CHAIN {
        0 => format!("spine{}", bone % CHAIN),
        chain => format!("limb{chain}_{}", bone % CHAIN),
    }
}

/// Where `bone` sits on its parent: up the spine and chains, each chain starting out sideways in its own direction.
fn rest_offset(bone: usize) -> [f32; 3] {
    match (bone / CHAIN, bone % CHAIN) {
        (0, 0) => [0.0, 1.0, 0.0],
        (chain, 0) if chain > 0 => {
            let angle = chain as f64 * TAU / 19.0;
            [(0.1 * angle.cos()) as f32, 0.0, (0.1 * angle.sin()) as f32]
        }
        _ => [0.0, 0.08, 0.0],
    }
}

/// Every bone's position at rest, in the model's space.
fn rest_positions() -> Vec<[f32; 3]> {
    let mut at: Vec<[f32; 3]> = Vec::with_capacity(BONES);
    for bone in 0..BONES {
        let base = parent(bone).map_or([0.0; 3], |p| at[p]);
        let offset = rest_offset(bone);
        at.push([0, 1, 2].map(|i| base[i] + offset[i]));
    }
    at
}

/// The componentwise minimum and maximum of 3D points (`POSITION` accessors must state them).
fn bounds(points: &[f32]) -> (Value, Value) {
    let fold = |pick: fn(f32, f32) -> f32, start: f32| {
        points.chunks(3).fold([start; 3], |acc, p| [0, 1, 2].map(|i| pick(acc[i], p[i])))
    };
    (Value::from(fold(f32::min, f32::INFINITY).to_vec()), Value::from(fold(f32::max, f32::NEG_INFINITY).to_vec()))
}

/// Frame `k`'s time in seconds, before it is rounded to `f32` as an exporter stores it.
fn time(k: usize) -> f64 {
    k as f64 / FRAME_RATE
}

/// The root's position: forward at 1 m/s, bobbing twice a step.
fn walk(t: f64) -> [f32; 3] {
    [(0.05 * (TAU * 0.5 * t).sin()) as f32, (1.0 + 0.03 * (TAU * 2.0 * t).sin()) as f32, t as f32]
}

/// A swing of up to 0.6 rad about an axis of the bone's own, at a frequency and phase of its own.
fn rotation(bone: usize, t: f64) -> [f32; 4] {
    let b = bone as f64;
    let axis = glam::DVec3::new(b.sin(), (1.3 * b).cos(), 0.5).normalize();
    let frequency = 0.5 + 0.1 * (bone % 7) as f64;
    let angle = 0.6 * (TAU * frequency * t + b).sin();
    glam::DQuat::from_axis_angle(axis, angle).as_quat().to_array()
}

/// Squash and stretch along the bone: longer and thinner, then shorter and wider, volume kept.
fn squash(bone: usize, t: f64) -> [f32; 3] {
    let along = 1.0 + 0.3 * (TAU * 0.8 * t + bone as f64).sin();
    let across = along.recip().sqrt();
    [across as f32, along as f32, across as f32]
}
