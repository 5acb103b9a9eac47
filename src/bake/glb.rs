//! A [`GltfDocument`] encoded as a glTF 2.0 binary (GLB) through the `gltf` crate's JSON types and GLB writer.
//!
//! One buffer (the GLB's BIN chunk) holds every accessor, each in its own 4-byte-aligned buffer view. Accessors get
//! `min`/`max` where the specification requires them (positions, morph displacements, animation inputs), computed
//! from the very `f32` values written. Skin weights are made what the specification asks of them: each vertex's
//! weights sum to 1, a joint appears at most once among its non-zero weights, and zero weights point at joint 0.
//! Key times that round to the same `f32` keep their first key.

use std::collections::{BTreeMap, HashMap};

use gltf::json::{self, Index, validation::Checked::Valid, validation::USize64};
use json::accessor::{ComponentType, GenericComponentType, Type};
use serde_json::Value;

use super::document::{Animation, GltfDocument, Interpolation, MeshGroup, Node, Property, SkinOut};
use crate::model::Mesh;

/// The GLB bytes of `document`.
pub fn encode(document: &GltfDocument) -> Vec<u8> {
    let mut writer = Writer::default();
    writer.root.asset = json::Asset { generator: Some(document.generator.clone()), ..json::Asset::default() };
    let meshes: Vec<_> = document.meshes.iter().map(|m| writer.mesh(m, &document.skins)).collect();
    let skins: Vec<_> = document.skins.iter().map(|s| writer.skin(s)).collect();
    writer.nodes(&document.nodes, &meshes, &skins);
    for animation in &document.animations {
        writer.animation(animation);
    }
    writer.finish()
}

#[derive(Default)]
struct Writer {
    root: json::Root,
    bin: Vec<u8>,
    /// Animation input accessors already written, by their bits, so channels with the same key times share one.
    inputs: HashMap<Vec<u32>, Index<json::Accessor>>,
}

impl Writer {
    /// Appends `bytes` as a buffer view (aligned to 4 bytes) for `target`, returning the view.
    fn view(&mut self, bytes: &[u8], target: Option<json::buffer::Target>) -> Index<json::buffer::View> {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        let offset = self.bin.len();
        self.bin.extend_from_slice(bytes);
        self.root.push(json::buffer::View {
            buffer: Index::new(0),
            byte_length: USize64::from(bytes.len()),
            byte_offset: Some(USize64::from(offset)),
            byte_stride: None,
            name: None,
            target: target.map(Valid),
            extensions: None,
            extras: Default::default(),
        })
    }

    /// An accessor over `count` elements of `kind` made of `components`, with `bounds` as its min/max.
    fn accessor(
        &mut self,
        bytes: &[u8],
        count: usize,
        component: ComponentType,
        kind: Type,
        target: Option<json::buffer::Target>,
        bounds: Option<(Vec<f32>, Vec<f32>)>,
    ) -> Index<json::Accessor> {
        let view = self.view(bytes, target);
        let (min, max) = match bounds {
            Some((min, max)) => (Some(numbers(&min)), Some(numbers(&max))),
            None => (None, None),
        };
        self.root.push(json::Accessor {
            buffer_view: Some(view),
            byte_offset: None,
            count: USize64::from(count),
            component_type: Valid(GenericComponentType(component)),
            extensions: None,
            extras: Default::default(),
            type_: Valid(kind),
            min,
            max,
            name: None,
            normalized: false,
            sparse: None,
        })
    }

    /// `values` as float elements of `kind`, with min/max when `bounded`.
    fn floats(
        &mut self,
        values: &[f32],
        kind: Type,
        target: Option<json::buffer::Target>,
        bounded: bool,
    ) -> Index<json::Accessor> {
        let width = kind.multiplicity();
        let bounds = bounded.then(|| bounds(values, width));
        self.accessor(&le_bytes(values), values.len() / width, ComponentType::F32, kind, target, bounds)
    }

    fn mesh(&mut self, group: &MeshGroup, skins: &[SkinOut]) -> Index<json::Mesh> {
        let primitives = group.primitives.iter().map(|mesh| self.primitive(mesh, skins)).collect();
        let weights = (!group.weights.is_empty()).then(|| group.weights.clone());
        self.root.push(json::Mesh {
            extensions: None,
            extras: Default::default(),
            name: Some(group.name.clone()),
            primitives,
            weights,
        })
    }

    fn primitive(&mut self, mesh: &Mesh, skins: &[SkinOut]) -> json::mesh::Primitive {
        use json::mesh::Semantic;
        let array = Some(json::buffer::Target::ArrayBuffer);
        let mut attributes = BTreeMap::new();
        let positions: Vec<f32> = mesh.positions.iter().flat_map(|p| p.to_array()).collect();
        attributes.insert(Valid(Semantic::Positions), self.floats(&positions, Type::Vec3, array, true));
        if mesh.normals.len() == mesh.positions.len() && !mesh.normals.is_empty() {
            let normals: Vec<f32> =
                mesh.normals.iter().flat_map(|n| n.normalize_or(glam::Vec3::Y).to_array()).collect();
            attributes.insert(Valid(Semantic::Normals), self.floats(&normals, Type::Vec3, array, false));
        }
        if let Some(skin) = mesh.skin.and_then(|s| skins.get(s)).filter(|_| mesh.joints.len() == mesh.positions.len()) {
            let (joints, weights) = skin_attributes(mesh, &skin.joint_map);
            let joint_bytes: Vec<u8> = joints.iter().flat_map(|j| j.to_le_bytes()).collect();
            let joint_accessor =
                self.accessor(&joint_bytes, mesh.joints.len(), ComponentType::U16, Type::Vec4, array, None);
            attributes.insert(Valid(Semantic::Joints(0)), joint_accessor);
            attributes.insert(Valid(Semantic::Weights(0)), self.floats(&weights, Type::Vec4, array, false));
        }
        let indices = self.indices(&mesh.indices);
        let targets = mesh.morph_targets.iter().map(|target| {
            let offsets: Vec<f32> = target.offsets.iter().flat_map(|o| o.to_array()).collect();
            json::mesh::MorphTarget {
                positions: Some(self.floats(&offsets, Type::Vec3, array, true)),
                normals: None,
                tangents: None,
            }
        });
        let targets: Vec<_> = targets.collect();
        json::mesh::Primitive {
            attributes,
            extensions: None,
            extras: Default::default(),
            indices: Some(indices),
            material: None,
            mode: Valid(json::mesh::Mode::Triangles),
            targets: (!targets.is_empty()).then_some(targets),
        }
    }

    fn indices(&mut self, indices: &[u32]) -> Index<json::Accessor> {
        let target = Some(json::buffer::Target::ElementArrayBuffer);
        if indices.iter().all(|&i| i < u32::from(u16::MAX)) {
            let bytes: Vec<u8> = indices.iter().flat_map(|&i| (i as u16).to_le_bytes()).collect();
            self.accessor(&bytes, indices.len(), ComponentType::U16, Type::Scalar, target, None)
        } else {
            let bytes: Vec<u8> = indices.iter().flat_map(|i| i.to_le_bytes()).collect();
            self.accessor(&bytes, indices.len(), ComponentType::U32, Type::Scalar, target, None)
        }
    }

    fn skin(&mut self, skin: &SkinOut) -> Index<json::Skin> {
        let matrices: Vec<f32> = skin.inverse_bind.iter().flat_map(|m| m.to_cols_array().map(|v| v as f32)).collect();
        let inverse_bind_matrices = Some(self.floats(&matrices, Type::Mat4, None, false));
        self.root.push(json::Skin {
            extensions: None,
            extras: Default::default(),
            inverse_bind_matrices,
            joints: skin.joints.iter().map(|&j| Index::new(j as u32)).collect(),
            name: skin.name.clone(),
            skeleton: None,
        })
    }

    fn nodes(&mut self, nodes: &[Node], meshes: &[Index<json::Mesh>], skins: &[Index<json::Skin>]) {
        let mut children: Vec<Vec<Index<json::Node>>> = vec![Vec::new(); nodes.len()];
        let mut roots = Vec::new();
        for (i, node) in nodes.iter().enumerate() {
            match node.parent {
                Some(p) => children[p].push(Index::new(i as u32)),
                None => roots.push(Index::new(i as u32)),
            }
        }
        for (node, children) in nodes.iter().zip(children) {
            self.root.push(json::Node {
                name: Some(node.name.clone()),
                children: (!children.is_empty()).then_some(children),
                translation: (node.translation != [0.0; 3]).then_some(node.translation),
                rotation: (node.rotation != [0.0, 0.0, 0.0, 1.0]).then_some(json::scene::UnitQuaternion(node.rotation)),
                scale: (node.scale != [1.0; 3]).then_some(node.scale),
                mesh: node.mesh.map(|m| meshes[m]),
                skin: node.skin.map(|s| skins[s]),
                ..json::Node::default()
            });
        }
        let scene =
            self.root.push(json::Scene { extensions: None, extras: Default::default(), name: None, nodes: roots });
        self.root.scene = Some(scene);
    }

    fn animation(&mut self, animation: &Animation) {
        let mut samplers = Vec::new();
        let mut channels = Vec::new();
        for channel in &animation.channels {
            let kind = match channel.property {
                Property::Translation | Property::Scale => Type::Vec3,
                Property::Rotation => Type::Vec4,
                Property::Weights => Type::Scalar,
            };
            let input = self.input(&channel.times);
            let output = self.floats(&channel.values, kind, None, false);
            let sampler = Index::push(
                &mut samplers,
                json::animation::Sampler {
                    extensions: None,
                    extras: Default::default(),
                    input,
                    interpolation: Valid(match channel.interpolation {
                        Interpolation::Step => json::animation::Interpolation::Step,
                        Interpolation::Linear => json::animation::Interpolation::Linear,
                        Interpolation::CubicSpline => json::animation::Interpolation::CubicSpline,
                    }),
                    output,
                },
            );
            let path = match channel.property {
                Property::Translation => json::animation::Property::Translation,
                Property::Rotation => json::animation::Property::Rotation,
                Property::Scale => json::animation::Property::Scale,
                Property::Weights => json::animation::Property::MorphTargetWeights,
            };
            channels.push(json::animation::Channel {
                sampler,
                target: json::animation::Target {
                    extensions: None,
                    extras: Default::default(),
                    node: Index::new(channel.node as u32),
                    path: Valid(path),
                },
                extensions: None,
                extras: Default::default(),
            });
        }
        self.root.push(json::Animation {
            extensions: None,
            extras: Default::default(),
            channels,
            name: Some(animation.name.clone()),
            samplers,
        });
    }

    /// The input accessor of `times`, shared with earlier channels that have the same ones.
    fn input(&mut self, times: &[f32]) -> Index<json::Accessor> {
        let bits: Vec<u32> = times.iter().map(|t| t.to_bits()).collect();
        if let Some(&index) = self.inputs.get(&bits) {
            return index;
        }
        let index = self.floats(times, Type::Scalar, None, true);
        self.inputs.insert(bits, index);
        index
    }

    fn finish(mut self) -> Vec<u8> {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        if !self.bin.is_empty() {
            self.root.push(json::Buffer {
                byte_length: USize64::from(self.bin.len()),
                name: None,
                uri: None,
                extensions: None,
                extras: Default::default(),
            });
        }
        let json = self.root.to_vec().expect("glTF JSON of plain numbers and strings serialises");
        let glb = gltf::binary::Glb {
            header: gltf::binary::Header { magic: *b"glTF", version: 2, length: 0 },
            json: json.into(),
            bin: (!self.bin.is_empty()).then(|| self.bin.into()),
        };
        glb.to_vec().expect("writing to memory cannot fail")
    }
}

/// Per vertex: four joint indices (renumbered by `joint_map`) and four weights as glTF wants them (see the module's
/// documentation).
pub(super) fn skin_attributes(mesh: &Mesh, joint_map: &[u16]) -> (Vec<u16>, Vec<f32>) {
    let mut joints = Vec::with_capacity(mesh.joints.len() * 4);
    let mut weights = Vec::with_capacity(mesh.joints.len() * 4);
    for (indices, values) in mesh.joints.iter().zip(&mesh.weights) {
        let mut merged: Vec<(u16, f32)> = Vec::with_capacity(4);
        for (&joint, &weight) in indices.iter().zip(values) {
            let Some(&joint) = joint_map.get(usize::from(joint)).filter(|_| weight > 0.0 && weight.is_finite()) else {
                continue;
            };
            match merged.iter_mut().find(|(j, _)| *j == joint) {
                Some(entry) => entry.1 += weight,
                None => merged.push((joint, weight)),
            }
        }
        let total: f32 = merged.iter().map(|(_, w)| w).sum();
        if merged.is_empty() || total <= 0.0 {
            merged = vec![(0, 1.0)];
        }
        let total: f32 = merged.iter().map(|(_, w)| w).sum();
        for slot in 0..4 {
            let (joint, weight) = merged.get(slot).copied().unwrap_or((0, 0.0));
            joints.push(joint);
            weights.push(weight / total);
        }
    }
    (joints, weights)
}

/// Little-endian bytes of `values`.
fn le_bytes(values: &[f32]) -> Vec<u8> {
    values.iter().flat_map(|v| v.to_le_bytes()).collect()
}

/// Component-wise min and max of `width`-wide elements.
fn bounds(values: &[f32], width: usize) -> (Vec<f32>, Vec<f32>) {
    let mut min = vec![f32::INFINITY; width];
    let mut max = vec![f32::NEG_INFINITY; width];
    for element in values.chunks_exact(width) {
        for (c, &v) in element.iter().enumerate() {
            min[c] = min[c].min(v);
            max[c] = max[c].max(v);
        }
    }
    (min, max)
}

/// `values` as a JSON array.
fn numbers(values: &[f32]) -> Value {
    Value::from(values.iter().map(|&v| Value::from(v)).collect::<Vec<_>>())
}
