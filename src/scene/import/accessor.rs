//! Reading glTF accessors (glTF 2.0 §3.6.2) with every offset, stride and count checked
//! against the buffer it points into, so that a malformed file is an error, never a
//! panic or an allocation of what a count merely claims.

use ::gltf::accessor::{Accessor, DataType, Dimensions};
use ::gltf::buffer::View;

/// The bytes of `view` within the loaded `buffers`.
pub(super) fn view_bytes<'b>(view: &View<'_>, buffers: &'b [Vec<u8>]) -> Result<&'b [u8], String> {
    let buffer = view.buffer().index();
    let data = buffers.get(buffer).ok_or_else(|| {
        format!(
            "bufferView {} names buffer {buffer}, which was not loaded",
            view.index()
        )
    })?;
    view.offset()
        .checked_add(view.length())
        .and_then(|end| data.get(view.offset()..end))
        .ok_or_else(|| {
            format!(
                "bufferView {} (bytes {}..{}+{}) lies outside buffer {buffer}, which holds {} bytes",
                view.index(),
                view.offset(),
                view.offset(),
                view.length(),
                data.len()
            )
        })
}

/// Whether an attribute's integer components may be normalized integers (glTF 2.0
/// §3.6.2.1, accessor `normalized`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Normalized {
    /// Integers taken as they are (indices).
    Never,
    /// Integers that stand for [0, 1] or [-1, 1] (`NORMAL` under `KHR_mesh_quantization`).
    Always,
    /// Either, as the accessor's `normalized` says (`POSITION` and `TEXCOORD_n` under
    /// `KHR_mesh_quantization`).
    Either,
}

/// What an attribute may hold.
pub(super) struct Expect<'a> {
    /// The attribute, for messages (`POSITION`, `TEXCOORD_0`, `indices`).
    pub name: &'a str,
    /// Its element type.
    pub dimensions: Dimensions,
    /// The component types allowed (glTF 2.0 §3.7.2.1, table "Meshes", widened by
    /// `KHR_mesh_quantization` where the caller allows it).
    pub types: &'static [DataType],
    /// Whether its integer components may be normalized.
    pub normalized: Normalized,
}

/// Reads `accessor` as `f64` components, `count × components` of them, after checking
/// its type against `expect` and every byte range against the buffers. Sparse accessors
/// are applied on top of their base (or of zeros). The caller bounds `count` first: an
/// accessor without a bufferView allocates it whatever the file holds.
pub(super) fn read(
    accessor: &Accessor<'_>,
    expect: &Expect,
    buffers: &[Vec<u8>],
) -> Result<Vec<f64>, String> {
    let name = expect.name;
    let index = accessor.index();
    let fail = |message: String| format!("{name} (accessor {index}): {message}");
    if accessor.dimensions() != expect.dimensions {
        return Err(fail(format!(
            "holds {:?} elements, expected {:?}",
            accessor.dimensions(),
            expect.dimensions
        )));
    }
    let data_type = accessor.data_type();
    if !expect.types.contains(&data_type) {
        return Err(fail(format!(
            "holds {data_type:?} components, expected one of {:?}",
            expect.types
        )));
    }
    // `normalized` only means something for integers (glTF 2.0 §5.1, accessor.normalized:
    // it must not be true for FLOAT); a float accessor that sets it is read as floats.
    let normalized = data_type != DataType::F32 && accessor.normalized();
    let allowed = match expect.normalized {
        Normalized::Never => !normalized,
        Normalized::Always => normalized || data_type == DataType::F32,
        Normalized::Either => true,
    };
    if !allowed {
        return Err(fail(format!(
            "its {data_type:?} components are {}normalized, which this attribute does not allow",
            if normalized { "" } else { "not " }
        )));
    }
    let components = expect.dimensions.multiplicity();
    let count = accessor.count();
    let total = count
        .checked_mul(components)
        .ok_or_else(|| fail(format!("count {count} is absurd")))?;
    let element = data_type.size() * components;
    let mut values = match accessor.view() {
        Some(view) => {
            let bytes = view_bytes(&view, buffers).map_err(&fail)?;
            let stride = view.stride().unwrap_or(element);
            if stride < element {
                return Err(fail(format!(
                    "the byteStride {stride} of bufferView {} is smaller than one element ({element} bytes)",
                    view.index()
                )));
            }
            decode(
                bytes,
                accessor.offset(),
                stride,
                count,
                components,
                data_type,
                normalized,
            )
            .ok_or_else(|| {
                fail(format!(
                    "{count} elements of {element} bytes every {stride} from byte {} do not fit in bufferView {} ({} bytes)",
                    accessor.offset(),
                    view.index(),
                    bytes.len()
                ))
            })?
        }
        // Only sparse values are stored; the caller has bounded `count`.
        None if accessor.sparse().is_some() => vec![0.0; total],
        None => return Err(fail("has no bufferView (and is not sparse)".into())),
    };
    if let Some(sparse) = accessor.sparse() {
        let sparse_count = sparse.count();
        let indices = sparse.indices();
        let index_type = match indices.index_type() {
            ::gltf::accessor::sparse::IndexType::U8 => DataType::U8,
            ::gltf::accessor::sparse::IndexType::U16 => DataType::U16,
            ::gltf::accessor::sparse::IndexType::U32 => DataType::U32,
        };
        let index_bytes = view_bytes(&indices.view(), buffers).map_err(&fail)?;
        let targets = decode(
            index_bytes,
            indices.offset(),
            index_type.size(),
            sparse_count,
            1,
            index_type,
            false,
        )
        .ok_or_else(|| {
            fail(format!(
                "its {sparse_count} sparse indices do not fit in their bufferView"
            ))
        })?;
        let values_view = sparse.values().view();
        let value_bytes = view_bytes(&values_view, buffers).map_err(&fail)?;
        let replacements = decode(
            value_bytes,
            sparse.values().offset(),
            element,
            sparse_count,
            components,
            data_type,
            normalized,
        )
        .ok_or_else(|| {
            fail(format!(
                "its {sparse_count} sparse values do not fit in their bufferView"
            ))
        })?;
        for (k, target) in targets.iter().enumerate() {
            let target = *target as usize;
            if target >= count {
                return Err(fail(format!(
                    "sparse index {target} is out of range ({count} elements)"
                )));
            }
            values[target * components..(target + 1) * components]
                .copy_from_slice(&replacements[k * components..(k + 1) * components]);
        }
    }
    debug_assert_eq!(values.len(), total);
    Ok(values)
}

/// Decodes `count` elements of `components` little-endian components each, the first at
/// `offset` and one every `stride` bytes; `None` when they do not fit in `bytes`.
/// Normalized integers become reals as glTF 2.0 §3.11 ("Animations", the table every
/// normalized accessor follows, `KHR_mesh_quantization` included) says: `c / 255`,
/// `c / 65535` unsigned, `max(c / 127, -1)`, `max(c / 32767, -1)` signed.
fn decode(
    bytes: &[u8],
    offset: usize,
    stride: usize,
    count: usize,
    components: usize,
    data_type: DataType,
    normalized: bool,
) -> Option<Vec<f64>> {
    let size = data_type.size();
    if count > 0 {
        let last = stride.checked_mul(count - 1)?.checked_add(offset)?;
        let end = last.checked_add(size.checked_mul(components)?)?;
        if end > bytes.len() {
            return None;
        }
    }
    let mut values = Vec::with_capacity(count * components);
    for i in 0..count {
        let start = offset + i * stride;
        for c in 0..components {
            let at = start + c * size;
            let b = &bytes[at..at + size];
            let value = match data_type {
                DataType::F32 => f64::from(f32::from_le_bytes([b[0], b[1], b[2], b[3]])),
                DataType::U8 if normalized => f64::from(b[0]) / 255.0,
                DataType::U8 => f64::from(b[0]),
                DataType::I8 if normalized => (f64::from(b[0] as i8) / 127.0).max(-1.0),
                DataType::I8 => f64::from(b[0] as i8),
                DataType::U16 if normalized => {
                    f64::from(u16::from_le_bytes([b[0], b[1]])) / 65535.0
                }
                DataType::U16 => f64::from(u16::from_le_bytes([b[0], b[1]])),
                DataType::I16 if normalized => {
                    (f64::from(i16::from_le_bytes([b[0], b[1]])) / 32767.0).max(-1.0)
                }
                DataType::I16 => f64::from(i16::from_le_bytes([b[0], b[1]])),
                DataType::U32 => f64::from(u32::from_le_bytes([b[0], b[1], b[2], b[3]])),
            };
            values.push(value);
        }
    }
    Some(values)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn decode_reads_strided_little_endian_components() {
        let mut bytes = vec![0u8; 2];
        for v in [1.5f32, -2.0, 9.0, 3.25] {
            bytes.extend_from_slice(&v.to_le_bytes());
        }
        let values = decode(&bytes, 2, 8, 2, 1, DataType::F32, false).expect("fits");
        assert_eq!(values, vec![1.5, 9.0]);
        assert!(decode(&bytes, 2, 8, 3, 1, DataType::F32, false).is_none());
        assert!(decode(&bytes, 2, usize::MAX, 3, 1, DataType::F32, false).is_none());
        let normalized = decode(&[0, 255, 0, 128], 0, 2, 2, 2, DataType::U8, true).expect("fits");
        assert_eq!(normalized, vec![0.0, 1.0, 0.0, 128.0 / 255.0]);
    }
}
