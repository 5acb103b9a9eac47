//! What a document needs once decoded, estimated from its declarations before a byte of data is read, against the
//! memory budget ([`budget`]).
//!
//! A glTF file is small for what it may describe: every channel reading one sampler gets a track of its own, every
//! node showing a mesh a copy of it to skin. The estimate counts what the rig will hold and evaluation will touch:
//! every node as a bone ([`budget::BONE_BYTES`]), every channel's keys decoded, every instance of a mesh with its
//! skinned copy; the largest of these names the refusal.

use std::collections::{HashMap, HashSet};

use super::Result;
use super::accessor::MAX_ZEROS;
use super::schema::{Root, Uint};
use crate::import::budget;

/// Bytes a vertex costs once read and skinned: position, normal, four joints, four weights and a dual-quaternion
/// weight as read, position and normal again as skinned at a time.
const VERTEX_BYTES: u64 = 12 + 12 + 8 + 16 + 4 + 24;
/// Bytes a key costs in a track, by what it animates (a morph-weight key holds one target's weight).
const VEC3_KEY: u64 = 12;
const ROTATION_KEY: u64 = 16;
const WEIGHT_KEY: u64 = 4;
/// A key time, shared by the tracks that read one input.
const TIME_BYTES: u64 = 8;
/// An inverse bind matrix in double precision.
const MATRIX_BYTES: u64 = 128;

/// One part of the need: its bytes, and where and what for (for the message).
struct Part {
    bytes: u64,
    place: Option<String>,
    what: String,
}

/// Refuses a document whose decoded rig would exceed the budget, naming its largest part.
pub(super) fn check(root: &Root) -> Result<()> {
    let parts = [bones(root), clips(root), meshes(root), skins(root)];
    let total = parts.iter().fold(0u64, |sum, part| sum.saturating_add(part.bytes));
    let largest = parts.iter().max_by_key(|part| part.bytes).expect("four parts");
    budget::check(total, largest.place.as_deref(), || largest.what.clone())
}

/// The elements `accessors[index]` can hold: its `count`, but no more than its buffer view has bytes (or, without
/// one, than the zeros bonescope fills in), as a count beyond those fails when read, naming its accessor (0 for an
/// accessor that does not exist, which fails the same way).
fn count(root: &Root, index: Uint) -> u64 {
    let Some(accessor) = root.accessors.get(index.0) else { return 0 };
    let room = match accessor.buffer_view {
        Some(view) => root.buffer_views.get(view.0).map_or(0, |v| v.byte_length.0),
        None => MAX_ZEROS,
    };
    (accessor.count.0 as u64).min(room as u64)
}

fn bones(root: &Root) -> Part {
    let nodes = root.nodes.len() as u64;
    Part { bytes: nodes.saturating_mul(budget::BONE_BYTES), place: None, what: format!("{nodes} nodes as bones") }
}

/// Every channel's keys; key times once per input and values once per output accessor (channels that share a
/// sampler share its decoded values).
fn clips(root: &Root) -> Part {
    let mut total = 0u64;
    let mut largest = (0u64, 0usize, 0u64);
    for (index, animation) in root.animations.iter().enumerate() {
        let mut bytes = 0u64;
        let mut keys = 0u64;
        let (mut inputs, mut outputs_read) = (HashSet::new(), HashSet::new());
        for channel in &animation.channels {
            let Some(sampler) = animation.samplers.get(channel.sampler.0) else { continue };
            let per_key = match channel.target.path.as_str() {
                "rotation" => ROTATION_KEY,
                "weights" => WEIGHT_KEY,
                _ => VEC3_KEY,
            };
            let outputs = count(root, sampler.output);
            keys = keys.saturating_add(outputs);
            // Morph weights are split into a track per target: they are not shared.
            if per_key == WEIGHT_KEY || outputs_read.insert((sampler.output, per_key)) {
                bytes = bytes.saturating_add(outputs.saturating_mul(per_key));
            }
            if inputs.insert(sampler.input) {
                bytes = bytes.saturating_add(count(root, sampler.input).saturating_mul(TIME_BYTES));
            }
        }
        total = total.saturating_add(bytes);
        if bytes > largest.0 {
            largest = (bytes, index, keys);
        }
    }
    let (_, index, keys) = largest;
    let channels = root.animations.get(index).map_or(0, |a| a.channels.len());
    Part {
        bytes: total,
        place: Some(format!("animations[{index}]")),
        what: format!("{channels} channels of {keys} keys in all"),
    }
}

/// Every mesh once per node showing it, as read and as skinned.
fn meshes(root: &Root) -> Part {
    let mut instances: HashMap<usize, u64> = HashMap::new();
    for node in &root.nodes {
        let Some(mesh) = node.mesh else { continue };
        // A node drawing its mesh once per `EXT_mesh_gpu_instancing` instance holds as many copies.
        let instancing = node.extensions.gpu_instancing.as_ref();
        let copies = instancing.and_then(|i| i.attributes.values().map(|&a| count(root, a)).max()).unwrap_or(1);
        *instances.entry(mesh.0).or_default() += copies;
    }
    let mut total = 0u64;
    let mut largest = (0u64, 0usize, 0u64, 0u64);
    for (&mesh, &shown) in &instances {
        let Some(declared) = root.meshes.get(mesh) else { continue };
        let mut vertices = 0u64;
        let mut bytes = 0u64;
        for primitive in &declared.primitives {
            let positions = primitive.attributes.get("POSITION").map_or(0, |&a| count(root, a));
            let targets = primitive.targets.len() as u64;
            let indices = primitive.indices.map_or(positions, |a| count(root, a));
            vertices = vertices.saturating_add(positions);
            let per_vertex = VERTEX_BYTES.saturating_add(targets.saturating_mul(VEC3_KEY));
            bytes =
                bytes.saturating_add(positions.saturating_mul(per_vertex)).saturating_add(indices.saturating_mul(4));
        }
        let bytes = bytes.saturating_mul(shown);
        total = total.saturating_add(bytes);
        if bytes > largest.0 {
            largest = (bytes, mesh, shown, vertices);
        }
    }
    let (_, mesh, shown, vertices) = largest;
    Part {
        bytes: total,
        place: Some(format!("meshes[{mesh}]")),
        what: format!(
            "{shown} instances of meshes[{mesh}] ({vertices} vertices), each read and skinned as its own mesh"
        ),
    }
}

/// Every skin's joints with their matrices; an accessor of inverse bind matrices is decoded once.
fn skins(root: &Root) -> Part {
    let joints: u64 = root.skins.iter().map(|s| s.joints.len() as u64).fold(0, u64::saturating_add);
    let accessors: HashSet<Uint> = root.skins.iter().filter_map(|s| s.inverse_bind_matrices).collect();
    let decoded = accessors.iter().map(|&a| count(root, a)).fold(0, u64::saturating_add);
    Part {
        bytes: joints.saturating_add(decoded).saturating_mul(MATRIX_BYTES),
        place: None,
        what: format!("{} skins of {joints} joints in all", root.skins.len()),
    }
}
