//! `EXT_meshopt_compression`: buffer views stored compressed by meshoptimizer's codecs, as gltfpack writes them
//! (keyframes included). A compressed view says where its bytes lie (`buffer`, `byteOffset`, `byteLength`) and what
//! they decode to: `count` elements of `byteStride` bytes, by `mode` (`ATTRIBUTES` vertex data, `TRIANGLES` an index
//! buffer, `INDICES` an index sequence), then `filter` (`OCTAHEDRAL` unit vectors, `QUATERNION` rotations,
//! `EXPONENTIAL` floats as exponent and mantissa). The view's own buffer is a fallback that may hold nothing; once
//! decoded, the view reads as any other. Decoding is meshoptimizer's own (the `meshopt` crate), which is safe on
//! untrusted input: a broken stream is an error, never a read outside it.

use super::schema::MeshoptCompressed;

impl MeshoptCompressed {
    /// The bytes it decodes to: `count × byteStride`.
    pub fn decoded_len(&self) -> Option<usize> {
        self.count.0.checked_mul(self.byte_stride.0)
    }

    /// Decodes `encoded` (the bytes it points at) into the view's bytes.
    pub fn decode(&self, encoded: &[u8]) -> Result<Vec<u8>, String> {
        let (count, stride) = (self.count.0, self.byte_stride.0);
        let decoded = match self.mode.as_str() {
            "ATTRIBUTES" => attributes(encoded, count, stride, self.filter.as_deref().unwrap_or("NONE"))?,
            "TRIANGLES" | "INDICES" => indices(encoded, count, stride, self.mode == "TRIANGLES")?,
            mode => return Err(format!("mode `{mode}` is not ATTRIBUTES, TRIANGLES or INDICES")),
        };
        Ok(decoded)
    }
}

/// `count` vertices of `stride` bytes (a multiple of 4, at most 256), filtered.
fn attributes(encoded: &[u8], count: usize, stride: usize, filter: &str) -> Result<Vec<u8>, String> {
    if stride == 0 || !stride.is_multiple_of(4) || stride > 256 {
        return Err(format!("byteStride {stride} is not a multiple of 4 up to 256"));
    }
    // Words, so that the filters read their 16- and 32-bit components aligned.
    let mut words = vec![0u32; count * stride / 4];
    // SAFETY: `words` holds `count × stride` bytes, exactly what the decoder writes; it reads `encoded` within its
    // length and fails (a non-zero result) on a stream that does not decode to that many vertices.
    let failed = unsafe {
        meshopt::ffi::meshopt_decodeVertexBuffer(
            words.as_mut_ptr().cast(),
            count,
            stride,
            encoded.as_ptr(),
            encoded.len(),
        )
    };
    if failed != 0 {
        return Err(format!("the vertex stream does not decode to {count} elements of {stride} bytes"));
    }
    let pointer = words.as_mut_ptr().cast();
    // SAFETY: each filter rewrites `count` elements of `stride` bytes in place, within `words`; the strides are the
    // ones its documentation allows, checked first.
    match filter {
        "NONE" => {}
        "OCTAHEDRAL" if stride == 4 || stride == 8 => unsafe {
            meshopt::ffi::meshopt_decodeFilterOct(pointer, count, stride)
        },
        "QUATERNION" if stride == 8 => unsafe { meshopt::ffi::meshopt_decodeFilterQuat(pointer, count, stride) },
        "EXPONENTIAL" => unsafe { meshopt::ffi::meshopt_decodeFilterExp(pointer, count, stride) },
        filter => return Err(format!("filter `{filter}` with byteStride {stride} is not one the extension defines")),
    }
    Ok(words.iter().flat_map(|w| w.to_ne_bytes()).collect())
}

/// `count` indices of `stride` bytes (2 or 4): a triangle list's index buffer or an index sequence.
fn indices(encoded: &[u8], count: usize, stride: usize, triangles: bool) -> Result<Vec<u8>, String> {
    let failed = |e: meshopt::Error| format!("the index stream does not decode to {count} indices: {e}");
    if triangles && !count.is_multiple_of(3) {
        return Err(format!("{count} indices are not whole triangles"));
    }
    match (stride, triangles) {
        (2, true) => Ok(bytes(meshopt::decode_index_buffer::<u16>(encoded, count).map_err(failed)?, u16::to_le_bytes)),
        (4, true) => Ok(bytes(meshopt::decode_index_buffer::<u32>(encoded, count).map_err(failed)?, u32::to_le_bytes)),
        (2, false) => {
            Ok(bytes(meshopt::decode_index_sequence::<u16>(encoded, count).map_err(failed)?, u16::to_le_bytes))
        }
        (4, false) => {
            Ok(bytes(meshopt::decode_index_sequence::<u32>(encoded, count).map_err(failed)?, u32::to_le_bytes))
        }
        _ => Err(format!("byteStride {stride} of indices is not 2 or 4")),
    }
}

/// Values as little-endian bytes.
fn bytes<T, const N: usize>(values: Vec<T>, to_bytes: fn(T) -> [u8; N]) -> Vec<u8> {
    values.into_iter().flat_map(to_bytes).collect()
}
