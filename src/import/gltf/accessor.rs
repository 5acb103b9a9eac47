//! A bounds-checked accessor reader, with sparse accessors and accessors without a buffer view.
//!
//! Before a byte is read, the accessor's element type is checked against what its use allows (the spec's tables,
//! and `KHR_mesh_quantization`'s for vertex attributes), and its whole range (`offset + stride·(count−1) + element
//! size`) against its buffer view, and the view against its buffer. An accessor without a `bufferView` is zeros;
//! `sparse` then replaces the elements it lists (indices strictly increasing, each below `count`). Allocations are
//! one element per `count`, which the range check ties to bytes present, except for zeros: those are capped at
//! [`MAX_ZEROS`] bytes so a tiny hostile file cannot ask for gigabytes.

use std::borrow::Cow;
use std::ops::Range;
use std::sync::OnceLock;

use glam::{DMat4, Quat, Vec3};

use super::buffers::Buffers;
use super::draco;
use super::schema::{self, DataType, Root, Uint};
use super::{Failure, Result};

/// The most bytes of elements an accessor may hold without a buffer view behind them.
pub(super) const MAX_ZEROS: usize = 64 << 20;

/// An allowed component type and whether it must be `normalized`.
type Component = (DataType, bool);

const FLOAT: &[Component] = &[(DataType::F32, false)];
/// Rotation and morph-weight outputs: float, or signed or unsigned normalized bytes and shorts.
const FLOAT_OR_NORMALIZED: &[Component] =
    &[(DataType::F32, false), (DataType::I8, true), (DataType::U8, true), (DataType::I16, true), (DataType::U16, true)];
/// `WEIGHTS_n`: float, or unsigned normalized bytes and shorts.
const FLOAT_OR_UNORM: &[Component] = &[(DataType::F32, false), (DataType::U8, true), (DataType::U16, true)];
/// `POSITION` and morph-target displacements with `KHR_mesh_quantization`: float, or bytes and shorts, signed or
/// not, normalized or not.
const QUANTIZED: &[Component] = &[
    (DataType::F32, false),
    (DataType::I8, false),
    (DataType::I8, true),
    (DataType::U8, false),
    (DataType::U8, true),
    (DataType::I16, false),
    (DataType::I16, true),
    (DataType::U16, false),
    (DataType::U16, true),
];
const JOINT_INDEX: &[Component] = &[(DataType::U8, false), (DataType::U16, false)];
const VERTEX_INDEX: &[Component] = &[(DataType::U8, false), (DataType::U16, false), (DataType::U32, false)];
const SPARSE_INDEX: &[DataType] = &[DataType::U8, DataType::U16, DataType::U32];

/// What a use of an accessor allows: its `type` (and so `N` components per element) and component types.
struct Use {
    what: &'static str,
    kind: &'static str,
    components: &'static [Component],
}

const TIMES: Use = Use { what: "keyframe times", kind: "SCALAR", components: FLOAT };
const ROTATIONS: Use = Use { what: "rotation output", kind: "VEC4", components: FLOAT_OR_NORMALIZED };
const MORPH_WEIGHTS: Use = Use { what: "morph-weight output", kind: "SCALAR", components: FLOAT_OR_NORMALIZED };
const MATRICES: Use = Use { what: "inverse bind matrices", kind: "MAT4", components: FLOAT };
const JOINTS: Use = Use { what: "JOINTS_0/JOINTS_1", kind: "VEC4", components: JOINT_INDEX };
const WEIGHTS: Use = Use { what: "WEIGHTS_0/WEIGHTS_1", kind: "VEC4", components: FLOAT_OR_UNORM };
const INDICES: Use = Use { what: "indices", kind: "SCALAR", components: VERTEX_INDEX };

/// The accessors of a document and the buffers behind them.
pub(super) struct Accessors<'a> {
    root: &'a Root,
    buffers: &'a Buffers<'a>,
    /// Per buffer view, its bytes once decoded, where `EXT_meshopt_compression` compresses it.
    decoded: Vec<OnceLock<std::result::Result<Vec<u8>, String>>>,
    /// Per accessor, the bytes a `KHR_draco_mesh_compression` primitive decoded for it (tightly packed).
    supplied: Vec<OnceLock<Vec<u8>>>,
}

impl<'a> Accessors<'a> {
    pub fn new(root: &'a Root, buffers: &'a Buffers<'a>) -> Self {
        let decoded = root.buffer_views.iter().map(|_| OnceLock::new()).collect();
        Accessors { root, buffers, decoded, supplied: root.accessors.iter().map(|_| OnceLock::new()).collect() }
    }

    /// Decodes a Draco-compressed primitive (at `place`): its accessors then read what it decodes to.
    pub fn supply_draco(
        &self,
        primitive: &schema::Primitive,
        compressed: &schema::DracoCompressed,
        place: &str,
    ) -> Result<()> {
        let place = format!("{place}.extensions.KHR_draco_mesh_compression");
        let stream = self.view(compressed.buffer_view, &place)?;
        let supplied = draco::decode(&stream, compressed, primitive, self.root, crate::import::budget::limit())
            .map_err(|why| Failure::at(&place, why))?;
        for (accessor, bytes) in supplied {
            // An accessor two primitives share keeps the first one's bytes.
            let _ = self.supplied.get(accessor).map(|cell| cell.set(bytes));
        }
        Ok(())
    }

    /// Decodes the meshopt-compressed buffer view of `accessors[index]`, if it has one, so that a stream that does
    /// not decode is known before the accessor is read.
    pub fn decodes(&self, index: Uint, user: &str) -> Result<()> {
        let view = self.root.accessors.get(index.0).and_then(|a| a.buffer_view);
        let compressed = view.and_then(|v| Some((v, self.root.buffer_views.get(v.0)?.extensions.meshopt.as_ref()?)));
        compressed.map_or(Ok(()), |(view, compressed)| self.decoded(view, compressed, user).map(|_| ()))
    }

    /// The whole of `bufferViews[index]`, for `user`.
    fn view(&self, index: Uint, user: &str) -> Result<Cow<'_, [u8]>> {
        let view = schema::item(&self.root.buffer_views, index, "bufferViews", user)?;
        let range = self.view_range(view, &format!("bufferViews[{}]", index.0), user)?;
        self.view_bytes(index, view, range, user)
    }

    /// The bytes of `bufferViews[index]` (`view`) in `range` of its buffer, or of what it decodes to where meshopt
    /// compresses it ([`Accessors::view_range`] says which), for `user`.
    fn view_bytes(
        &self,
        index: Uint,
        view: &schema::BufferView,
        range: Range<usize>,
        user: &str,
    ) -> Result<Cow<'_, [u8]>> {
        match &view.extensions.meshopt {
            Some(compressed) => Ok(Cow::Borrowed(&self.decoded(index, compressed, user)?[range])),
            None => self.buffers.read(view.buffer, range, user),
        }
    }

    /// Keyframe times (`SCALAR` float), widened to seconds in `f64`.
    pub fn times(&self, index: Uint, user: &str) -> Result<Vec<f64>> {
        self.read(index, user, &TIMES, |[t]: [f32; 1]| f64::from(t))
    }

    /// `VEC3` float: translation and scale outputs.
    pub fn vec3s(&self, index: Uint, user: &str, what: &'static str) -> Result<Vec<Vec3>> {
        let vec3s = Use { what, kind: "VEC3", components: FLOAT };
        self.read(index, user, &vec3s, Vec3::from_array)
    }

    /// `VEC3` positions or morph-target displacements, float or quantized.
    pub fn positions(&self, index: Uint, user: &str, what: &'static str) -> Result<Vec<Vec3>> {
        let positions = Use { what, kind: "VEC3", components: QUANTIZED };
        self.read(index, user, &positions, Vec3::from_array)
    }

    /// `VEC4` quaternions `[x, y, z, w]`, float or normalized integers (decoded, not renormalized).
    pub fn rotations(&self, index: Uint, user: &str) -> Result<Vec<Quat>> {
        self.read(index, user, &ROTATIONS, Quat::from_array)
    }

    /// Morph-target weights (`SCALAR`, float or normalized).
    pub fn morph_weights(&self, index: Uint, user: &str) -> Result<Vec<f32>> {
        self.read(index, user, &MORPH_WEIGHTS, |[w]: [f32; 1]| w)
    }

    /// `MAT4` float, column-major as glTF stores it.
    pub fn matrices(&self, index: Uint, user: &str) -> Result<Vec<DMat4>> {
        self.read(index, user, &MATRICES, |m: [f32; 16]| DMat4::from_cols_array(&m.map(f64::from)))
    }

    /// `JOINTS_n`: four unsigned byte or short joint indices per vertex.
    pub fn joints(&self, index: Uint, user: &str) -> Result<Vec<[u16; 4]>> {
        // Both allowed types fit in u16.
        self.read(index, user, &JOINTS, |j: [u32; 4]| j.map(|i| i as u16))
    }

    /// `WEIGHTS_n`: four weights per vertex, float or unsigned normalized.
    pub fn weights(&self, index: Uint, user: &str) -> Result<Vec<[f32; 4]>> {
        self.read(index, user, &WEIGHTS, |w: [f32; 4]| w)
    }

    /// Vertex indices (`SCALAR` unsigned byte, short or int).
    pub fn indices(&self, index: Uint, user: &str) -> Result<Vec<u32>> {
        self.read(index, user, &INDICES, |[i]: [u32; 1]| i)
    }

    /// The first buffer that `accessors[index]` reads and that has no source in the file (see
    /// [`Buffers::has_source`]); `None` when every one has, or when a reference is broken (reading says so).
    pub fn unsupplied_buffer(&self, index: Uint) -> Option<Uint> {
        let accessor = self.root.accessors.get(index.0)?;
        let sparse = accessor.sparse.iter().flat_map(|s| [s.indices.buffer_view, s.values.buffer_view]);
        let views = accessor.buffer_view.into_iter().chain(sparse);
        let buffer = |view: &schema::BufferView| view.extensions.meshopt.as_ref().map_or(view.buffer, |c| c.buffer);
        let buffers = views.filter_map(|v| self.root.buffer_views.get(v.0)).map(buffer);
        buffers.into_iter().find(|&b| !self.buffers.has_source(b))
    }

    /// Every element of `accessors[index]`, used by `user` as `usage` allows, with its sparse substitutions, each
    /// made into what the caller keeps by `element` as it is decoded.
    fn read<T: Decode, const N: usize, U: Clone>(
        &self,
        index: Uint,
        user: &str,
        usage: &Use,
        element: impl Fn([T; N]) -> U,
    ) -> Result<Vec<U>> {
        let accessor = schema::item(&self.root.accessors, index, "accessors", user)?;
        let place = format!("accessors[{}]", index.0);
        let data_type = check_type(accessor, usage, &place)?;
        let count = accessor.count.0;
        let layout = Layout { data_type, normalized: accessor.normalized, components: N };
        if let Some(bytes) = self.supplied[index.0].get() {
            if bytes.len() != count * layout.element_size() {
                return Err(Failure::at(place, "the Draco stream decoded to another size than its count"));
            }
            let elements = Elements { bytes: Cow::Borrowed(bytes), stride: layout.element_size(), layout };
            return Ok(elements.decode(&element));
        }
        let mut elements = match accessor.buffer_view {
            Some(view) => {
                let layout = Layout { data_type, normalized: accessor.normalized, components: N };
                self.elements(view, accessor.byte_offset.0, count, layout, true, &place)?.decode(&element)
            }
            None => zeros(count, size_of::<[T; N]>(), element([T::default(); N]), &place)?,
        };
        if let Some(sparse) = &accessor.sparse {
            let layout = Layout { data_type, normalized: accessor.normalized, components: N };
            self.substitute(sparse, layout, &element, &mut elements, &format!("{place}.sparse"))?;
        }
        Ok(elements)
    }

    /// Replaces the elements that `sparse` lists by its values (laid out as `layout`).
    fn substitute<T: Decode, const N: usize, U>(
        &self,
        sparse: &schema::Sparse,
        layout: Layout,
        element: &impl Fn([T; N]) -> U,
        elements: &mut [U],
        place: &str,
    ) -> Result<()> {
        let count = sparse.count.0;
        if count == 0 || count > elements.len() {
            return Err(Failure::at(place, format!("count {count} is not in 1..={}", elements.len())));
        }
        let indices = &sparse.indices;
        let index_type = DataType::from_code(indices.component_type).filter(|t| SPARSE_INDEX.contains(t));
        let Some(index_type) = index_type else {
            let message = format!("componentType {} is not an unsigned integer type", indices.component_type.0);
            return Err(Failure::at(format!("{place}.indices"), message));
        };
        let index_layout = Layout { data_type: index_type, normalized: false, components: 1 };
        let index_place = format!("{place}.indices");
        let positions =
            self.elements(indices.buffer_view, indices.byte_offset.0, count, index_layout, false, &index_place)?;
        let values = &sparse.values;
        let value_place = format!("{place}.values");
        let values = self.elements(values.buffer_view, values.byte_offset.0, count, layout, false, &value_place)?;
        let mut previous = None;
        let positions = positions.decode(|[position]: [u32; 1]| position as usize);
        for (k, (position, value)) in positions.into_iter().zip(values.decode(element)).enumerate() {
            if previous.is_some_and(|p| position <= p) || position >= elements.len() {
                let message = format!(
                    "index {k} is {position}: indices must increase strictly and stay below count {}",
                    elements.len()
                );
                return Err(Failure::at(index_place, message));
            }
            elements[position] = value;
            previous = Some(position);
        }
        Ok(())
    }

    /// The checked bytes of `count` elements laid out as `layout` from `offset` in `bufferViews[view]`; `strided`
    /// honours the view's `byteStride` (sparse data is always tightly packed). Only those bytes are read.
    fn elements(
        &self,
        view_index: Uint,
        offset: usize,
        count: usize,
        layout: Layout,
        strided: bool,
        place: &str,
    ) -> Result<Elements<'_>> {
        let view = schema::item(&self.root.buffer_views, view_index, "bufferViews", place)?;
        let view_place = format!("bufferViews[{}]", view_index.0);
        let view_range = self.view_range(view, &view_place, place)?;
        let element_size = layout.element_size();
        let stride = match view.byte_stride {
            Some(stride) if strided => stride.0,
            _ => element_size,
        };
        if stride < element_size {
            let message = format!("{view_place} has byteStride {stride}, less than the element size {element_size}");
            return Err(Failure::at(place, message));
        }
        let end = match count.checked_sub(1) {
            None => Some(offset),
            Some(last) => {
                last.checked_mul(stride).and_then(|n| n.checked_add(offset)).and_then(|n| n.checked_add(element_size))
            }
        };
        let Some(end) = end.filter(|&end| offset <= end && end <= view_range.len()) else {
            let message = format!(
                "{count} elements of {element_size} bytes (stride {stride}) from byteOffset {offset} do not fit in \
                 {view_place} ({} bytes)",
                view_range.len()
            );
            return Err(Failure::at(place, message));
        };
        let range = view_range.start + offset..view_range.start + end;
        let bytes = self.view_bytes(view_index, view, range, place)?;
        Ok(Elements { bytes, stride, layout })
    }

    /// The bytes `bufferViews[index]` decodes to under `EXT_meshopt_compression`, decoded on first use.
    fn decoded(&self, index: Uint, compressed: &schema::MeshoptCompressed, user: &str) -> Result<&[u8]> {
        let place = format!("bufferViews[{}].extensions.EXT_meshopt_compression", index.0);
        let decoded = self.decoded[index.0].get_or_init(|| {
            let (offset, length) = (compressed.byte_offset.0, compressed.byte_length.0);
            let range = offset..offset.checked_add(length).ok_or("byteOffset + byteLength overflows")?;
            let buffer_len = self.buffers.len(compressed.buffer, &place).map_err(|f| f.message)?;
            if range.end > buffer_len {
                return Err(format!(
                    "bytes {}..{} lie outside buffers[{}]",
                    range.start, range.end, compressed.buffer.0
                ));
            }
            let encoded = self.buffers.read(compressed.buffer, range, &place).map_err(|f| f.message)?;
            compressed.decode(&encoded)
        });
        decoded.as_deref().map_err(|why| Failure::at(user, format!("{place}: {why}")))
    }

    /// Where a buffer view (at `place`) lies in its buffer, checked to lie inside it; `user` needs it. A view
    /// `EXT_meshopt_compression` compresses is its decoded bytes, `count × byteStride` from 0.
    fn view_range(&self, view: &schema::BufferView, place: &str, user: &str) -> Result<Range<usize>> {
        if let Some(compressed) = &view.extensions.meshopt {
            let length = compressed.decoded_len().filter(|&n| n == view.byte_length.0);
            return length.map(|n| 0..n).ok_or_else(|| {
                let message = format!("decodes to count × byteStride bytes, not its byteLength {}", view.byte_length.0);
                Failure::at(place, message)
            });
        }
        let buffer_len = self.buffers.len(view.buffer, user)?;
        let (offset, length) = (view.byte_offset.0, view.byte_length.0);
        offset.checked_add(length).filter(|&end| end <= buffer_len).map(|end| offset..end).ok_or_else(|| {
            let message = format!(
                "bytes {offset}..{} lie outside buffers[{}] ({buffer_len} bytes)",
                offset.saturating_add(length),
                view.buffer.0,
            );
            Failure::at(place, message)
        })
    }
}

/// Checks the accessor's `type` and component type against `usage`.
fn check_type(accessor: &schema::Accessor, usage: &Use, place: &str) -> Result<DataType> {
    let data_type = DataType::from_code(accessor.component_type);
    let allowed = data_type.is_some_and(|t| usage.components.contains(&(t, accessor.normalized)));
    match data_type {
        Some(data_type) if allowed && accessor.kind == usage.kind => Ok(data_type),
        _ => {
            let expected = usage.components.iter().map(|&c| component_name(c)).collect::<Vec<_>>().join(" or ");
            let found_type = data_type.map_or_else(
                || format!("componentType {}", accessor.component_type.0),
                |t| component_name((t, accessor.normalized)),
            );
            let message =
                format!("{} must be {} of {expected}, found {} of {found_type}", usage.what, usage.kind, accessor.kind);
            Err(Failure::at(place, message))
        }
    }
}

/// `count` copies of `zero`, elements of `size` bytes each in the file, within [`MAX_ZEROS`].
fn zeros<U: Clone>(count: usize, size: usize, zero: U, place: &str) -> Result<Vec<U>> {
    if count.checked_mul(size).is_none_or(|bytes| bytes > MAX_ZEROS) {
        let message = format!(
            "{count} elements without a bufferView would take more than the {} MiB bonescope fills with zeros",
            MAX_ZEROS >> 20
        );
        return Err(Failure::at(place, message));
    }
    Ok(vec![zero; count])
}

/// How one element is stored.
#[derive(Clone, Copy)]
struct Layout {
    data_type: DataType,
    normalized: bool,
    components: usize,
}

impl Layout {
    fn element_size(self) -> usize {
        self.data_type.size() * self.components
    }
}

/// The checked bytes of some elements: `stride` apart, the last one ending the slice.
struct Elements<'a> {
    bytes: Cow<'a, [u8]>,
    stride: usize,
    layout: Layout,
}

impl Elements<'_> {
    /// Each element's `N` components, decoded and made into what the reader keeps by `element`.
    fn decode<T: Decode, const N: usize, U>(&self, element: impl Fn([T; N]) -> U) -> Vec<U> {
        // A loop per component type, so that each knows how its components decode (the match inside
        // `Decode::decode` folds away) and how wide they are.
        match self.layout.data_type {
            DataType::I8 => self.decode_as::<T, N, U, 1>(DataType::I8, element),
            DataType::U8 => self.decode_as::<T, N, U, 1>(DataType::U8, element),
            DataType::I16 => self.decode_as::<T, N, U, 2>(DataType::I16, element),
            DataType::U16 => self.decode_as::<T, N, U, 2>(DataType::U16, element),
            DataType::U32 => self.decode_as::<T, N, U, 4>(DataType::U32, element),
            DataType::F32 => self.decode_as::<T, N, U, 4>(DataType::F32, element),
        }
    }

    /// [`Elements::decode`] for components of `data_type`, `SIZE` bytes each.
    #[inline(always)]
    fn decode_as<T: Decode, const N: usize, U, const SIZE: usize>(
        &self,
        data_type: DataType,
        element: impl Fn([T; N]) -> U,
    ) -> Vec<U> {
        let normalized = self.layout.normalized;
        // `bytes` ends with the last element: `chunks` yields each element, the last one possibly without padding.
        let decode = |bytes: &[u8]| {
            element(std::array::from_fn(|i| {
                let component = bytes.get(i * SIZE..).and_then(<[u8]>::first_chunk::<SIZE>);
                T::decode(data_type, normalized, component.unwrap_or(&[0; SIZE]))
            }))
        };
        self.bytes.chunks(self.stride).map(decode).collect()
    }
}

/// A component as a reader wants it.
trait Decode: Copy + Default {
    fn decode(data_type: DataType, normalized: bool, bytes: &[u8]) -> Self;
}

impl Decode for f32 {
    /// Floats as stored, normalized integers by the spec's rules (`max(c/127, −1)`, `c/255`, `max(c/32767, −1)`,
    /// `c/65535`), other integers by value.
    fn decode(data_type: DataType, normalized: bool, bytes: &[u8]) -> f32 {
        let (value, scale) = match data_type {
            DataType::F32 => return f32::from_le_bytes(array(bytes)),
            DataType::I8 => (f32::from(i8::from_le_bytes(array(bytes))), 127.0),
            DataType::U8 => (f32::from(bytes.first().copied().unwrap_or_default()), 255.0),
            DataType::I16 => (f32::from(i16::from_le_bytes(array(bytes))), 32767.0),
            DataType::U16 => (f32::from(u16::from_le_bytes(array(bytes))), 65535.0),
            DataType::U32 => return u32::decode(data_type, normalized, bytes) as f32,
        };
        if normalized { (value / scale).max(-1.0) } else { value }
    }
}

impl Decode for u32 {
    fn decode(data_type: DataType, _normalized: bool, bytes: &[u8]) -> u32 {
        match data_type {
            DataType::U8 => u32::from(u8::from_le_bytes(array(bytes))),
            DataType::U16 => u32::from(u16::from_le_bytes(array(bytes))),
            DataType::U32 => u32::from_le_bytes(array(bytes)),
            // Not allowed for any integer use (see the `Component` tables).
            DataType::I8 | DataType::I16 | DataType::F32 => 0,
        }
    }
}

/// The first `N` bytes (the caller passes a component of exactly the type's size).
fn array<const N: usize>(bytes: &[u8]) -> [u8; N] {
    bytes.first_chunk().copied().unwrap_or([0; N])
}

fn component_name((data_type, normalized): Component) -> String {
    if normalized { format!("normalized {}", data_type.name()) } else { data_type.name().to_owned() }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn float(data_type: DataType, normalized: bool, bytes: &[u8]) -> f32 {
        f32::decode(data_type, normalized, bytes)
    }

    #[test]
    fn normalized_integers_decode_per_spec() {
        let i16s = |v: i16| float(DataType::I16, true, &v.to_le_bytes());
        assert_eq!(i16s(32767), 1.0);
        assert_eq!(i16s(-32767), -1.0);
        assert_eq!(i16s(-32768), -1.0, "clamped to −1");
        assert_eq!(i16s(16384), 16384.0 / 32767.0);
        let i8s = |v: i8| float(DataType::I8, true, &v.to_le_bytes());
        assert_eq!((i8s(127), i8s(-128), i8s(64)), (1.0, -1.0, 64.0 / 127.0));
        assert_eq!(float(DataType::U8, true, &[255]), 1.0);
        assert_eq!(float(DataType::U8, true, &[51]), 0.2);
        assert_eq!(float(DataType::U16, true, &65535u16.to_le_bytes()), 1.0);
        assert_eq!(float(DataType::F32, false, &1.5f32.to_le_bytes()), 1.5);
        assert_eq!(float(DataType::U16, false, &300u16.to_le_bytes()), 300.0);
        assert_eq!(float(DataType::I8, false, &(-3i8).to_le_bytes()), -3.0, "quantized, not normalized");
    }

    #[test]
    fn strided_elements_read_only_their_components() {
        // Two VEC2 u16 elements with stride 6: [1, 2, pad], [3, 4].
        let bytes = [1, 0, 2, 0, 0xEE, 0xEE, 3, 0, 4, 0];
        let layout = Layout { data_type: DataType::U16, normalized: false, components: 2 };
        let elements = Elements { bytes: Cow::Borrowed(&bytes), stride: 6, layout };
        assert_eq!(elements.decode(|e: [u32; 2]| e), vec![[1, 2], [3, 4]]);
    }

    #[test]
    fn zeros_are_capped() {
        assert_eq!(zeros(2, 12, [0.0; 3], "a").unwrap(), vec![[0.0; 3]; 2]);
        assert!(zeros(usize::MAX / 2, 64, [0.0; 16], "a").is_err());
        assert!(zeros(2_000_000, 64, [0.0; 16], "a").is_err());
    }
}
