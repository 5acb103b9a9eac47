//! The parts of the glTF 2.0 JSON that bonescope reads, typed as leniently as the specification allows.
//!
//! Only what bonescope uses is declared: materials, textures, images, cameras and unknown extensions are never
//! deserialized, so nothing in them can stop a file from loading. What is declared follows the JSON schema's
//! optional fields and defaults, and keeps enumerations (`componentType`, `type`, `mode`, `interpolation`,
//! `path`) as the raw values, judged where they are used: an unknown accessor `type` on an accessor nothing reads
//! is no reason to refuse the file. Integers accept any JSON number with an integral value (`1.0` is `1`).

use std::collections::BTreeMap;
use std::fmt;

use serde::Deserialize;
use serde::de::{self, Deserializer, Visitor};

use super::uri::Uri;
use super::{Failure, Result};

/// A non-negative JSON integer: an index, a count, a byte offset. Written `1` or `1.0`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub(super) struct Uint(pub usize);

impl<'de> Deserialize<'de> for Uint {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> std::result::Result<Self, D::Error> {
        struct UintVisitor;

        impl Visitor<'_> for UintVisitor {
            type Value = Uint;

            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a non-negative integer")
            }

            fn visit_u64<E: de::Error>(self, v: u64) -> std::result::Result<Uint, E> {
                usize::try_from(v).map(Uint).map_err(|_| E::custom(format!("{v} is too large")))
            }

            fn visit_i64<E: de::Error>(self, v: i64) -> std::result::Result<Uint, E> {
                u64::try_from(v)
                    .map_err(|_| E::invalid_value(de::Unexpected::Signed(v), &self))
                    .and_then(|v| self.visit_u64(v))
            }

            fn visit_f64<E: de::Error>(self, v: f64) -> std::result::Result<Uint, E> {
                // 2^53: past it a double no longer holds every integer.
                const EXACT: f64 = 9_007_199_254_740_992.0;
                if v.fract() == 0.0 && (0.0..=EXACT).contains(&v) {
                    self.visit_u64(v as u64)
                } else {
                    Err(E::invalid_value(de::Unexpected::Float(v), &self))
                }
            }
        }

        deserializer.deserialize_any(UintVisitor)
    }
}

/// The document root.
#[derive(Debug, Deserialize)]
#[serde(rename_all = "camelCase")]
pub(super) struct Root {
    pub asset: Asset,
    #[serde(default)]
    pub extensions_required: Vec<String>,
    #[serde(default)]
    pub scene: Option<Uint>,
    #[serde(default)]
    pub scenes: Vec<Scene>,
    #[serde(default)]
    pub nodes: Vec<Node>,
    #[serde(default)]
    pub meshes: Vec<Mesh>,
    #[serde(default)]
    pub skins: Vec<Skin>,
    #[serde(default)]
    pub animations: Vec<Animation>,
    #[serde(default)]
    pub accessors: Vec<Accessor>,
    #[serde(default)]
    pub buffer_views: Vec<BufferView>,
    #[serde(default)]
    pub buffers: Vec<Buffer>,
}

#[derive(Debug, Deserialize)]
pub(super) struct Asset {
    pub version: String,
}

#[derive(Debug, Deserialize, Default)]
#[serde(default)]
pub(super) struct Scene {
    pub nodes: Vec<Uint>,
}

#[derive(Debug, Deserialize, Default)]
#[serde(default)]
pub(super) struct Node {
    pub name: Option<String>,
    pub children: Vec<Uint>,
    pub mesh: Option<Uint>,
    pub skin: Option<Uint>,
    pub matrix: Option<[f64; 16]>,
    pub translation: Option<[f64; 3]>,
    pub rotation: Option<[f64; 4]>,
    pub scale: Option<[f64; 3]>,
    /// Morph-target weights of this node's mesh, overriding the mesh's own.
    pub weights: Option<Vec<f64>>,
    /// Only whether the node has a camera counts (it is not framed as part of the figure), not what it is.
    pub camera: Option<de::IgnoredAny>,
    pub extensions: NodeExtensions,
}

#[derive(Debug, Deserialize, Default)]
#[serde(default)]
pub(super) struct NodeExtensions {
    /// A light of `KHR_lights_punctual` on the node; as for cameras, only its presence counts.
    #[serde(rename = "KHR_lights_punctual")]
    pub lights_punctual: Option<de::IgnoredAny>,
    /// `EXT_mesh_gpu_instancing`: the node's mesh drawn once per instance, each moved within the node.
    #[serde(rename = "EXT_mesh_gpu_instancing")]
    pub gpu_instancing: Option<Instancing>,
}

/// `EXT_mesh_gpu_instancing`: per instance, a translation, rotation and scale (`TRANSLATION`, `ROTATION`, `SCALE`
/// accessors of one count; one missing is the identity).
#[derive(Debug, Deserialize, Default)]
#[serde(default)]
pub(super) struct Instancing {
    pub attributes: Attributes,
}

#[derive(Debug, Deserialize, Default)]
#[serde(default)]
pub(super) struct Mesh {
    pub name: Option<String>,
    pub primitives: Vec<Primitive>,
    /// Default morph-target weights.
    pub weights: Vec<f64>,
}

/// Attribute semantics (`POSITION`, `JOINTS_0`, …) and the accessors holding them.
pub(super) type Attributes = BTreeMap<String, Uint>;

#[derive(Debug, Deserialize, Default)]
#[serde(default)]
pub(super) struct Primitive {
    pub attributes: Attributes,
    pub indices: Option<Uint>,
    /// Topology; 4 (triangles) when absent.
    pub mode: Option<Uint>,
    /// Morph targets: displaced attributes per target.
    pub targets: Vec<Attributes>,
    pub extensions: PrimitiveExtensions,
}

/// The extensions of a primitive bonescope reads.
#[derive(Debug, Default, Deserialize)]
pub(super) struct PrimitiveExtensions {
    #[serde(rename = "KHR_draco_mesh_compression", default)]
    pub draco: Option<DracoCompressed>,
}

#[derive(Debug, Deserialize, Default)]
#[serde(default, rename_all = "camelCase")]
pub(super) struct Skin {
    pub name: Option<String>,
    pub joints: Vec<Uint>,
    pub inverse_bind_matrices: Option<Uint>,
}

#[derive(Debug, Deserialize, Default)]
#[serde(default)]
pub(super) struct Animation {
    pub name: Option<String>,
    pub channels: Vec<Channel>,
    pub samplers: Vec<AnimationSampler>,
}

#[derive(Debug, Deserialize)]
pub(super) struct Channel {
    pub sampler: Uint,
    pub target: Target,
}

#[derive(Debug, Deserialize)]
pub(super) struct Target {
    /// Absent when an extension (`KHR_animation_pointer`) says what is animated.
    #[serde(default)]
    pub node: Option<Uint>,
    pub path: String,
    #[serde(default)]
    pub extensions: TargetExtensions,
}

#[derive(Debug, Deserialize, Default)]
pub(super) struct TargetExtensions {
    #[serde(rename = "KHR_animation_pointer", default)]
    pub animation_pointer: Option<AnimationPointer>,
}

#[derive(Debug, Deserialize)]
pub(super) struct AnimationPointer {
    /// A JSON pointer into the document, e.g. `/nodes/3/rotation`.
    pub pointer: String,
}

#[derive(Debug, Deserialize)]
pub(super) struct AnimationSampler {
    pub input: Uint,
    pub output: Uint,
    /// `LINEAR` when absent.
    #[serde(default)]
    pub interpolation: Option<String>,
}

#[derive(Debug, Deserialize)]
#[serde(rename_all = "camelCase")]
pub(super) struct Accessor {
    /// Absent: the elements are zeros (then usually replaced in part by `sparse`).
    #[serde(default)]
    pub buffer_view: Option<Uint>,
    #[serde(default)]
    pub byte_offset: Uint,
    pub component_type: Uint,
    #[serde(default)]
    pub normalized: bool,
    pub count: Uint,
    #[serde(rename = "type")]
    pub kind: String,
    #[serde(default)]
    pub sparse: Option<Sparse>,
}

#[derive(Debug, Deserialize)]
pub(super) struct Sparse {
    pub count: Uint,
    pub indices: SparseIndices,
    pub values: SparseValues,
}

#[derive(Debug, Deserialize)]
#[serde(rename_all = "camelCase")]
pub(super) struct SparseIndices {
    pub buffer_view: Uint,
    #[serde(default)]
    pub byte_offset: Uint,
    pub component_type: Uint,
}

#[derive(Debug, Deserialize)]
#[serde(rename_all = "camelCase")]
pub(super) struct SparseValues {
    pub buffer_view: Uint,
    #[serde(default)]
    pub byte_offset: Uint,
}

#[derive(Debug, Deserialize)]
#[serde(rename_all = "camelCase")]
pub(super) struct BufferView {
    pub buffer: Uint,
    #[serde(default)]
    pub byte_offset: Uint,
    pub byte_length: Uint,
    #[serde(default)]
    pub byte_stride: Option<Uint>,
    #[serde(default)]
    pub extensions: ViewExtensions,
}

/// The extensions of a buffer view bonescope reads.
#[derive(Debug, Default, Deserialize)]
pub(super) struct ViewExtensions {
    #[serde(rename = "EXT_meshopt_compression", default)]
    pub meshopt: Option<MeshoptCompressed>,
}

#[derive(Debug, Deserialize)]
#[serde(rename_all = "camelCase")]
pub(super) struct Buffer {
    /// Absent: the GLB `BIN` chunk (for `buffers[0]`) or data supplied some other way.
    #[serde(default)]
    pub uri: Option<Uri>,
    pub byte_length: Uint,
}

/// Looks up `list[index]` for the reference at `place` (`skins[0].joints[3]`, say), naming both when it is missing.
pub(super) fn item<'a, T>(list: &'a [T], index: Uint, kind: &str, place: impl fmt::Display) -> Result<&'a T> {
    list.get(index.0).ok_or_else(|| {
        Failure::at(
            place.to_string(),
            format!("refers to {kind}[{}], which does not exist ({} {kind})", index.0, list.len()),
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn integers_may_be_written_as_floats() {
        let parse = |text: &str| serde_json::from_str::<Uint>(text);
        assert_eq!(parse("3").unwrap(), Uint(3));
        assert_eq!(parse("3.0").unwrap(), Uint(3));
        assert_eq!(parse("3e0").unwrap(), Uint(3));
        for bad in ["3.5", "-1", "-1.0", "1e300", "\"3\"", "null"] {
            assert!(parse(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn only_the_read_parts_are_required() {
        let root: Root = serde_json::from_str(
            r#"{"asset": {"version": "2.0"}, "scenes": [{}], "materials": [{"bogus": true}],
                "animations": [{"channels": [{"sampler": 0, "target": {"path": "pointer",
                    "extensions": {"KHR_animation_pointer": {"pointer": "/materials/0/alphaCutoff"}}}}],
                    "samplers": [{"input": 0, "output": 1}]}],
                "accessors": [{"componentType": 5126, "count": 2.0, "type": "VEC7"}]}"#,
        )
        .unwrap();
        assert!(root.scenes[0].nodes.is_empty());
        assert_eq!(root.accessors[0].buffer_view, None);
        assert_eq!(root.accessors[0].kind, "VEC7");
        let target = &root.animations[0].channels[0].target;
        assert_eq!(target.node, None);
        assert_eq!(target.extensions.animation_pointer.as_ref().unwrap().pointer, "/materials/0/alphaCutoff");
    }
}

/// A view's `EXT_meshopt_compression`.
#[derive(Debug, Deserialize)]
#[serde(rename_all = "camelCase")]
pub(super) struct MeshoptCompressed {
    pub buffer: Uint,
    #[serde(default)]
    pub byte_offset: Uint,
    pub byte_length: Uint,
    pub byte_stride: Uint,
    pub count: Uint,
    pub mode: String,
    #[serde(default)]
    pub filter: Option<String>,
}

/// A primitive's `KHR_draco_mesh_compression`.
#[derive(Debug, Deserialize)]
#[serde(rename_all = "camelCase")]
pub(super) struct DracoCompressed {
    pub buffer_view: Uint,
    pub attributes: Attributes,
}

/// glTF's component types (`componentType`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum DataType {
    I8 = 5120,
    U8 = 5121,
    I16 = 5122,
    U16 = 5123,
    U32 = 5125,
    F32 = 5126,
}

impl DataType {
    pub fn from_code(code: Uint) -> Option<Self> {
        [Self::I8, Self::U8, Self::I16, Self::U16, Self::U32, Self::F32].into_iter().find(|t| *t as usize == code.0)
    }

    pub fn size(self) -> usize {
        match self {
            Self::I8 | Self::U8 => 1,
            Self::I16 | Self::U16 => 2,
            Self::U32 | Self::F32 => 4,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Self::I8 => "BYTE",
            Self::U8 => "UNSIGNED_BYTE",
            Self::I16 => "SHORT",
            Self::U16 => "UNSIGNED_SHORT",
            Self::U32 => "UNSIGNED_INT",
            Self::F32 => "FLOAT",
        }
    }
}
