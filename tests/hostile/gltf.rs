//! A small glTF writer for the hostile corpus: one binary buffer, accessors appended to it, the JSON built with
//! `serde_json`, written as a `.glb` or as a `.gltf` whose buffer is a separate file.

use serde_json::{Value, json};

/// A document being built.
pub struct Gltf {
    pub json: Value,
    pub bin: Vec<u8>,
}

impl Gltf {
    /// An empty document whose one scene lists `nodes[0]`.
    pub fn new() -> Self {
        let json = json!({
            "asset": {"version": "2.0"},
            "scene": 0,
            "scenes": [{"nodes": [0]}],
            "nodes": [],
            "bufferViews": [],
            "accessors": [],
        });
        Gltf { json, bin: Vec::new() }
    }

    /// Appends `bytes` as a buffer view and an accessor of `count` elements of `kind` (`VEC3`) and
    /// `component_type`; returns the accessor's index.
    pub fn accessor(&mut self, bytes: &[u8], component_type: u32, kind: &str, count: usize) -> usize {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        let view = push(
            &mut self.json["bufferViews"],
            json!({"buffer": 0, "byteOffset": self.bin.len(), "byteLength": bytes.len()}),
        );
        self.bin.extend_from_slice(bytes);
        push(
            &mut self.json["accessors"],
            json!({"bufferView": view, "componentType": component_type, "type": kind, "count": count}),
        )
    }

    /// Float elements of `kind`, `width` floats each.
    pub fn floats(&mut self, values: &[f32], kind: &str, width: usize) -> usize {
        let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
        self.accessor(&bytes, 5126, kind, values.len() / width)
    }

    /// Unsigned-short elements of `kind`, `width` each.
    pub fn u16s(&mut self, values: &[u16], kind: &str, width: usize) -> usize {
        let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
        self.accessor(&bytes, 5123, kind, values.len() / width)
    }

    /// Appends a node; returns its index.
    pub fn node(&mut self, node: Value) -> usize {
        push(&mut self.json["nodes"], node)
    }

    /// A mesh with one primitive of `attributes` (and `extra` fields: `indices`, `mode`); returns its index.
    pub fn mesh(&mut self, primitive: Value) -> usize {
        if self.json.get("meshes").is_none() {
            self.json["meshes"] = json!([]);
        }
        push(&mut self.json["meshes"], json!({"primitives": [primitive]}))
    }

    /// A triangle of three positions, with indices when `indices` is given.
    pub fn triangle_positions(&mut self) -> usize {
        self.floats(&[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0], "VEC3", 3)
    }

    /// The document as a GLB, its buffer the `BIN` chunk.
    pub fn glb(&self) -> Vec<u8> {
        let mut json = self.json.clone();
        json["buffers"] = json!([{"byteLength": self.bin.len()}]);
        glb(&serde_json::to_vec(&json).unwrap(), &self.bin)
    }

    /// The document as `.gltf` JSON whose buffer is the file `uri` (holding [`Gltf::bin`]).
    pub fn gltf_with_uri(&self, uri: &str) -> Vec<u8> {
        let mut json = self.json.clone();
        json["buffers"] = json!([{"byteLength": self.bin.len(), "uri": uri}]);
        serde_json::to_vec(&json).unwrap()
    }
}

/// Appends `item` to the JSON array `list`; returns its index.
fn push(list: &mut Value, item: Value) -> usize {
    let list = list.as_array_mut().expect("an array");
    list.push(item);
    list.len() - 1
}

/// A GLB container of `json` and `bin`, each padded to 4 bytes.
pub fn glb(json: &[u8], bin: &[u8]) -> Vec<u8> {
    let pad = |data: &[u8], fill: u8| {
        let mut data = data.to_vec();
        while !data.len().is_multiple_of(4) {
            data.push(fill);
        }
        data
    };
    let (json, bin) = (pad(json, b' '), pad(bin, 0));
    let total = 12 + 8 + json.len() + if bin.is_empty() { 0 } else { 8 + bin.len() };
    let mut out = b"glTF".to_vec();
    out.extend(2u32.to_le_bytes());
    out.extend((total as u32).to_le_bytes());
    out.extend((json.len() as u32).to_le_bytes());
    out.extend(0x4E4F_534Au32.to_le_bytes());
    out.extend(json);
    if !bin.is_empty() {
        out.extend((bin.len() as u32).to_le_bytes());
        out.extend(0x004E_4942u32.to_le_bytes());
        out.extend(bin);
    }
    out
}
