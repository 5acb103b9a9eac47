//! `KHR_draco_mesh_compression`: a primitive's geometry compressed by Google's Draco (gltf-transform, gltfpack and
//! Blender write it). The primitive names the buffer view holding the stream and, per attribute, the id of the
//! Draco attribute that holds it; its accessors keep their count, component type and normalisation. Decoded by the
//! `draco-core` crate (pure Rust, its output capped by the memory budget), each attribute and the triangles are laid
//! out as their accessors describe and read through them, as if they lay in a buffer.

use draco_core::{DecodeLimits, DecoderBuffer, Mesh, MeshDecoder, PointIndex};

use super::schema::{Accessor, DataType, DracoCompressed, Primitive, Root, Uint};

/// The bytes each accessor of `primitive` reads, decoded from `stream`: `(accessor, bytes)`, tightly packed in the
/// accessor's layout, its attributes' and its indices'. `limit` caps the decoded bytes.
pub(super) fn decode(
    stream: &[u8],
    compressed: &DracoCompressed,
    primitive: &Primitive,
    root: &Root,
    limit: u64,
) -> Result<Vec<(usize, Vec<u8>)>, String> {
    let mut limits = DecodeLimits::default();
    limits.max_decoded_bytes = limit;
    let mut mesh = Mesh::new();
    let mut buffer = DecoderBuffer::new(stream).with_limits(limits);
    MeshDecoder::new().decode(&mut buffer, &mut mesh).map_err(|e| format!("the Draco stream does not decode: {e}"))?;
    let accessor = |index: Uint| root.accessors.get(index.0).ok_or(format!("accessors[{}] does not exist", index.0));
    let mut supplied = Vec::new();
    for (semantic, id) in &compressed.attributes {
        let Some(&index) = primitive.attributes.get(semantic) else { continue };
        supplied.push((index.0, attribute(&mesh, id.0, accessor(index)?).map_err(|e| format!("{semantic}: {e}"))?));
    }
    if let Some(index) = primitive.indices {
        supplied.push((index.0, indices(&mesh, accessor(index)?)?));
    }
    Ok(supplied)
}

/// The values of Draco attribute `id`, one per point, laid out as `accessor` reads them.
fn attribute(mesh: &Mesh, id: usize, accessor: &Accessor) -> Result<Vec<u8>, String> {
    let attribute = u32::try_from(id).ok().and_then(|id| mesh.attribute_by_unique_id(id));
    let attribute = attribute.ok_or(format!("the stream has no attribute {id}"))?;
    let (points, components) = (mesh.num_points(), components(&accessor.kind)?);
    if points != accessor.count.0 {
        return Err(format!("{points} points decoded for an accessor of count {}", accessor.count.0));
    }
    let data_type = DataType::from_code(accessor.component_type);
    if data_type == Some(DataType::F32) {
        return Ok(attribute.read_f32s(points, components).iter().flat_map(|v| v.to_le_bytes()).collect());
    }
    let width = attribute.data_type().byte_length();
    if data_type.map(DataType::size) != Some(width) || attribute.num_components() as usize != components {
        let decoded = format!("{:?} × {}", attribute.data_type(), attribute.num_components());
        return Err(format!("decoded as {decoded}, not as its accessor says"));
    }
    let (data, stride, size) = (attribute.buffer().data(), attribute.byte_stride() as usize, components * width);
    let mut bytes = Vec::with_capacity(points * size);
    for point in 0..points {
        let at = attribute.mapped_index(PointIndex(point as u32)).0 as usize * stride;
        bytes.extend_from_slice(data.get(at..at + size).ok_or("a value lies outside the decoded data")?);
    }
    Ok(bytes)
}

/// The mesh's triangles as the indices `accessor` reads (unsigned bytes, shorts or ints).
fn indices(mesh: &Mesh, accessor: &Accessor) -> Result<Vec<u8>, String> {
    if mesh.num_faces() * 3 != accessor.count.0 {
        return Err(format!("{} triangles decoded for {} indices", mesh.num_faces(), accessor.count.0));
    }
    let index_type = DataType::from_code(accessor.component_type)
        .filter(|t| [DataType::U8, DataType::U16, DataType::U32].contains(t));
    let width = index_type
        .map(DataType::size)
        .ok_or(format!("componentType {} is no index type", accessor.component_type.0))?;
    let mut bytes = Vec::with_capacity(accessor.count.0 * width);
    for index in mesh.faces().iter().flatten().map(|p| p.0) {
        if width < 4 && index >> (8 * width) != 0 {
            return Err(format!("index {index} does not fit componentType {}", accessor.component_type.0));
        }
        bytes.extend_from_slice(&index.to_le_bytes()[..width]);
    }
    Ok(bytes)
}

/// The components of an accessor `type`.
fn components(kind: &str) -> Result<usize, String> {
    match kind {
        "SCALAR" => Ok(1),
        "VEC2" => Ok(2),
        "VEC3" => Ok(3),
        "VEC4" => Ok(4),
        other => Err(format!("type {other} is no vertex attribute")),
    }
}
