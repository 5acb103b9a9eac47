//! A bounds-checked accessor reader.
//!
//! Before a byte is read, the accessor's element type is checked against what its use allows (the spec's
//! tables), and its whole range (`offset + stride·(count−1) + element size`) against its buffer view, and the view
//! against its buffer. Every allocation is then one element per `count`, which the range check has tied to bytes
//! actually present. Sparse accessors are refused: nothing bonescope reads uses them in practice.

use glam::{DMat4, Quat, Vec3};
use gltf::accessor::{DataType, Dimensions};

use super::{Failure, Result};

/// An allowed component type and whether it must be `normalized`.
type Component = (DataType, bool);

const FLOAT: &[Component] = &[(DataType::F32, false)];
/// Rotation and morph-weight outputs: float, or signed or unsigned normalized bytes and shorts.
const FLOAT_OR_NORMALIZED: &[Component] =
    &[(DataType::F32, false), (DataType::I8, true), (DataType::U8, true), (DataType::I16, true), (DataType::U16, true)];
/// `WEIGHTS_0`: float, or unsigned normalized bytes and shorts.
const FLOAT_OR_UNORM: &[Component] = &[(DataType::F32, false), (DataType::U8, true), (DataType::U16, true)];
const JOINT_INDEX: &[Component] = &[(DataType::U8, false), (DataType::U16, false)];
const VERTEX_INDEX: &[Component] = &[(DataType::U8, false), (DataType::U16, false), (DataType::U32, false)];

/// The checked bytes of an accessor: `count` elements, `stride` apart, the last one ending the slice.
struct Elements<'a> {
    bytes: &'a [u8],
    stride: usize,
    data_type: DataType,
    normalized: bool,
}

/// Keyframe times (`SCALAR` float), widened to seconds in `f64`.
pub(super) fn times(accessor: &gltf::Accessor, buffers: &[Vec<u8>]) -> Result<Vec<f64>> {
    let elements = checked(accessor, buffers, Dimensions::Scalar, FLOAT, "keyframe times")?;
    Ok(elements.floats::<1>().map(|[t]| f64::from(t)).collect())
}

/// `VEC3` float: translations, scales, positions.
pub(super) fn vec3s(accessor: &gltf::Accessor, buffers: &[Vec<u8>], what: &str) -> Result<Vec<Vec3>> {
    let elements = checked(accessor, buffers, Dimensions::Vec3, FLOAT, what)?;
    Ok(elements.floats::<3>().map(Vec3::from_array).collect())
}

/// `VEC4` quaternions `[x, y, z, w]`, float or normalized integers (decoded, not renormalized).
pub(super) fn rotations(accessor: &gltf::Accessor, buffers: &[Vec<u8>]) -> Result<Vec<Quat>> {
    let elements = checked(accessor, buffers, Dimensions::Vec4, FLOAT_OR_NORMALIZED, "rotation output")?;
    Ok(elements.floats::<4>().map(Quat::from_array).collect())
}

/// Checks a morph-weight output accessor without reading it (the weights are not evaluated).
pub(super) fn check_morph_weights(accessor: &gltf::Accessor, buffers: &[Vec<u8>]) -> Result<()> {
    checked(accessor, buffers, Dimensions::Scalar, FLOAT_OR_NORMALIZED, "morph-weight output").map(drop)
}

/// `MAT4` float, column-major as glTF stores it.
pub(super) fn matrices(accessor: &gltf::Accessor, buffers: &[Vec<u8>]) -> Result<Vec<DMat4>> {
    let elements = checked(accessor, buffers, Dimensions::Mat4, FLOAT, "inverse bind matrices")?;
    Ok(elements.floats::<16>().map(|m| DMat4::from_cols_array(&m.map(f64::from))).collect())
}

/// `JOINTS_0`: four unsigned byte or short joint indices per vertex.
pub(super) fn joints(accessor: &gltf::Accessor, buffers: &[Vec<u8>]) -> Result<Vec<[u16; 4]>> {
    let elements = checked(accessor, buffers, Dimensions::Vec4, JOINT_INDEX, "JOINTS_0")?;
    // Both allowed types fit in u16.
    Ok(elements.uints::<4>().map(|j| j.map(|i| i as u16)).collect())
}

/// `WEIGHTS_0`: four weights per vertex, float or unsigned normalized.
pub(super) fn weights(accessor: &gltf::Accessor, buffers: &[Vec<u8>]) -> Result<Vec<[f32; 4]>> {
    let elements = checked(accessor, buffers, Dimensions::Vec4, FLOAT_OR_UNORM, "WEIGHTS_0")?;
    Ok(elements.floats::<4>().collect())
}

/// Vertex indices (`SCALAR` unsigned byte, short or int).
pub(super) fn indices(accessor: &gltf::Accessor, buffers: &[Vec<u8>]) -> Result<Vec<u32>> {
    let elements = checked(accessor, buffers, Dimensions::Scalar, VERTEX_INDEX, "indices")?;
    Ok(elements.uints::<1>().map(|[i]| i).collect())
}

/// Checks type and range of `accessor` for a use that allows `dimensions` and `allowed` component types.
fn checked<'a>(
    accessor: &gltf::Accessor,
    buffers: &'a [Vec<u8>],
    dimensions: Dimensions,
    allowed: &[Component],
    what: &str,
) -> Result<Elements<'a>> {
    let place = format!("accessors[{}]", accessor.index());
    let component = (accessor.data_type(), accessor.normalized());
    if accessor.dimensions() != dimensions || !allowed.contains(&component) {
        let expected = allowed.iter().map(|&c| component_name(c)).collect::<Vec<_>>().join(" or ");
        let found = format!("{} of {}", type_name(accessor.dimensions()), component_name(component));
        let message = format!("{what} must be {} of {expected}, found {found}", type_name(dimensions));
        return Err(Failure::at(place, message));
    }
    if accessor.sparse().is_some() {
        return Err(Failure::at(place, "sparse accessors are not supported"));
    }
    let Some(view) = accessor.view() else {
        return Err(Failure::at(place, "has no bufferView"));
    };
    let view_bytes = view_bytes(&view, buffers)?;
    let element_size = accessor.size();
    let stride = view.stride().unwrap_or(element_size);
    if stride < element_size {
        let message =
            format!("bufferViews[{}] has byteStride {stride}, less than the element size {element_size}", view.index());
        return Err(Failure::at(place, message));
    }
    let count = accessor.count();
    let end = count
        .checked_sub(1)
        .ok_or_else(|| Failure::at(&place, "count is 0"))?
        .checked_mul(stride)
        .and_then(|n| n.checked_add(accessor.offset()))
        .and_then(|n| n.checked_add(element_size));
    let Some(bytes) = end.and_then(|end| view_bytes.get(accessor.offset()..end)) else {
        let message = format!(
            "{count} elements of {element_size} bytes (stride {stride}) from byteOffset {} \
             do not fit in bufferViews[{}] ({} bytes)",
            accessor.offset(),
            view.index(),
            view_bytes.len()
        );
        return Err(Failure::at(place, message));
    };
    Ok(Elements { bytes, stride, data_type: component.0, normalized: component.1 })
}

/// The bytes of a buffer view, checked to lie inside its buffer.
fn view_bytes<'a>(view: &gltf::buffer::View, buffers: &'a [Vec<u8>]) -> Result<&'a [u8]> {
    let buffer = buffers.get(view.buffer().index()).map_or(&[][..], Vec::as_slice);
    let end = view.offset().checked_add(view.length());
    end.and_then(|end| buffer.get(view.offset()..end)).ok_or_else(|| {
        let message = format!(
            "bytes {}..{} lie outside buffers[{}] ({} bytes)",
            view.offset(),
            view.offset().saturating_add(view.length()),
            view.buffer().index(),
            buffer.len()
        );
        Failure::at(format!("bufferViews[{}]", view.index()), message)
    })
}

impl Elements<'_> {
    /// Each element's first `N` components, as the spec decodes them into floats.
    fn floats<const N: usize>(&self) -> impl Iterator<Item = [f32; N]> + '_ {
        self.components::<N>().map(|components| components.map(|c| decode_float(self.data_type, self.normalized, c)))
    }

    /// Each element's first `N` components as unsigned integers.
    fn uints<const N: usize>(&self) -> impl Iterator<Item = [u32; N]> + '_ {
        self.components::<N>().map(|components| components.map(|c| decode_uint(self.data_type, c)))
    }

    /// The bytes of each element's first `N` components.
    fn components<const N: usize>(&self) -> impl Iterator<Item = [&[u8]; N]> + '_ {
        let size = self.data_type.size();
        // `bytes` holds `count` elements exactly: `chunks` yields `count` slices, each at least one element long.
        self.bytes.chunks(self.stride).map(move |element| {
            let mut components = element.chunks_exact(size);
            std::array::from_fn(|_| components.next().unwrap_or_default())
        })
    }
}

/// One component as a float: floats as stored, normalized integers by the spec's rules (`max(c/127, −1)`,
/// `c/255`, `max(c/32767, −1)`, `c/65535`), other integers by value.
fn decode_float(data_type: DataType, normalized: bool, bytes: &[u8]) -> f32 {
    let (value, scale) = match data_type {
        DataType::F32 => return f32::from_le_bytes(array(bytes)),
        DataType::I8 => (f32::from(i8::from_le_bytes(array(bytes))), 127.0),
        DataType::U8 => (f32::from(bytes.first().copied().unwrap_or_default()), 255.0),
        DataType::I16 => (f32::from(i16::from_le_bytes(array(bytes))), 32767.0),
        DataType::U16 => (f32::from(u16::from_le_bytes(array(bytes))), 65535.0),
        DataType::U32 => return decode_uint(data_type, bytes) as f32,
    };
    if normalized { (value / scale).max(-1.0) } else { value }
}

fn decode_uint(data_type: DataType, bytes: &[u8]) -> u32 {
    match data_type {
        DataType::U8 => u32::from(u8::from_le_bytes(array(bytes))),
        DataType::U16 => u32::from(u16::from_le_bytes(array(bytes))),
        DataType::U32 => u32::from_le_bytes(array(bytes)),
        // Not allowed for any integer use (see the `Component` tables).
        DataType::I8 | DataType::I16 | DataType::F32 => 0,
    }
}

/// The first `N` bytes (the caller passes a component of exactly the type's size).
fn array<const N: usize>(bytes: &[u8]) -> [u8; N] {
    bytes.first_chunk().copied().unwrap_or([0; N])
}

fn type_name(dimensions: Dimensions) -> &'static str {
    match dimensions {
        Dimensions::Scalar => "SCALAR",
        Dimensions::Vec2 => "VEC2",
        Dimensions::Vec3 => "VEC3",
        Dimensions::Vec4 => "VEC4",
        Dimensions::Mat2 => "MAT2",
        Dimensions::Mat3 => "MAT3",
        Dimensions::Mat4 => "MAT4",
    }
}

fn component_name((data_type, normalized): Component) -> String {
    let name = match data_type {
        DataType::I8 => "BYTE",
        DataType::U8 => "UNSIGNED_BYTE",
        DataType::I16 => "SHORT",
        DataType::U16 => "UNSIGNED_SHORT",
        DataType::U32 => "UNSIGNED_INT",
        DataType::F32 => "FLOAT",
    };
    if normalized { format!("normalized {name}") } else { name.to_owned() }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normalized_integers_decode_per_spec() {
        let i16s = |v: i16| decode_float(DataType::I16, true, &v.to_le_bytes());
        assert_eq!(i16s(32767), 1.0);
        assert_eq!(i16s(-32767), -1.0);
        assert_eq!(i16s(-32768), -1.0, "clamped to −1");
        assert_eq!(i16s(16384), 16384.0 / 32767.0);
        let i8s = |v: i8| decode_float(DataType::I8, true, &v.to_le_bytes());
        assert_eq!((i8s(127), i8s(-128), i8s(64)), (1.0, -1.0, 64.0 / 127.0));
        assert_eq!(decode_float(DataType::U8, true, &[255]), 1.0);
        assert_eq!(decode_float(DataType::U8, true, &[51]), 0.2);
        assert_eq!(decode_float(DataType::U16, true, &65535u16.to_le_bytes()), 1.0);
        assert_eq!(decode_float(DataType::F32, false, &1.5f32.to_le_bytes()), 1.5);
        assert_eq!(decode_float(DataType::U16, false, &300u16.to_le_bytes()), 300.0);
    }

    #[test]
    fn strided_elements_read_only_their_components() {
        // Two VEC2 u16 elements with stride 6: [1, 2, pad], [3, 4].
        let bytes = [1, 0, 2, 0, 0xEE, 0xEE, 3, 0, 4, 0];
        let elements = Elements { bytes: &bytes, stride: 6, data_type: DataType::U16, normalized: false };
        assert_eq!(elements.uints::<2>().collect::<Vec<_>>(), vec![[1, 2], [3, 4]]);
    }
}
