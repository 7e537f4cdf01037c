//! Reading glTF vertex accessors as floats, with every component type the core specification
//! and KHR_mesh_quantization allow, sparse accessors, and accessors without a bufferView.
//!
//! A component of an integer type is read as its value when the accessor is not `normalized`
//! (quantized positions and texture coordinates, which the node transform or a texture
//! transform scales back), and mapped to `[0, 1]` or `[-1, 1]` when it is, with the
//! specification's rules (its section 3.11, "Animations", gives them for all types):
//! `u8 / 255`, `u16 / 65535`, `max(i8 / 127, -1)`, `max(i16 / 32767, -1)`.
//!
//! Every byte range is checked against its bufferView and buffer before it is read, and every
//! count against the bytes that back it before anything is reserved (an accessor without a
//! bufferView may not claim more elements than the file's buffers could hold), so a
//! malformed file gives an error naming what is wrong instead of a panic or an exhausted
//! memory.

use gltf::accessor::{DataType, Dimensions};
use gltf::buffer::Data;

/// A component type an attribute may use: the data type and whether it is normalized.
pub(super) type Component = (DataType, bool);

/// 32-bit floats.
pub(super) const FLOAT: Component = (DataType::F32, false);

/// Component types of POSITION (core: float; KHR_mesh_quantization: any 8- or 16-bit integer,
/// normalized or not).
pub(super) const POSITION: &[Component] = &[
    FLOAT,
    (DataType::I8, false),
    (DataType::I8, true),
    (DataType::U8, false),
    (DataType::U8, true),
    (DataType::I16, false),
    (DataType::I16, true),
    (DataType::U16, false),
    (DataType::U16, true),
];

/// Component types of NORMAL and TANGENT (core: float; KHR_mesh_quantization: normalized
/// signed 8- or 16-bit integers).
pub(super) const DIRECTION: &[Component] = &[FLOAT, (DataType::I8, true), (DataType::I16, true)];

/// Component types of TEXCOORD_n (core: float, normalized unsigned 8- and 16-bit integers;
/// KHR_mesh_quantization adds the signed ones and the unnormalized ones).
pub(super) const TEXCOORD: &[Component] = POSITION;

/// Component types of JOINTS_n (unsigned 8- and 16-bit integers, not normalized).
pub(super) const JOINTS: &[Component] = &[(DataType::U8, false), (DataType::U16, false)];

/// Component types of a skin's inverseBindMatrices (float).
pub(super) const MATRIX: &[Component] = &[FLOAT];

/// Component types of COLOR_0 and WEIGHTS_n (core: float, normalized unsigned 8- and 16-bit
/// integers).
pub(super) const COLOR: &[Component] = &[FLOAT, (DataType::U8, true), (DataType::U16, true)];

/// The number of components of an accessor type.
fn components(d: Dimensions) -> usize {
    match d {
        Dimensions::Scalar => 1,
        Dimensions::Vec2 => 2,
        Dimensions::Vec3 => 3,
        Dimensions::Vec4 => 4,
        Dimensions::Mat2 => 4,
        Dimensions::Mat3 => 9,
        Dimensions::Mat4 => 16,
    }
}

/// Size in bytes of one component of type `t`.
fn component_size(t: DataType) -> usize {
    match t {
        DataType::I8 | DataType::U8 => 1,
        DataType::I16 | DataType::U16 => 2,
        DataType::U32 | DataType::F32 => 4,
    }
}

/// One component at the start of `b` (which holds at least its size), as a float, normalized
/// if `normalized`.
#[inline]
fn component(b: &[u8], t: DataType, normalized: bool) -> f32 {
    match (t, normalized) {
        (DataType::F32, _) => f32::from_le_bytes([b[0], b[1], b[2], b[3]]),
        (DataType::U32, _) => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f32,
        (DataType::I8, false) => b[0] as i8 as f32,
        (DataType::I8, true) => (b[0] as i8 as f32 / 127.0).max(-1.0),
        (DataType::U8, false) => b[0] as f32,
        (DataType::U8, true) => b[0] as f32 / 255.0,
        (DataType::I16, n) => {
            let v = i16::from_le_bytes([b[0], b[1]]) as f32;
            if n {
                (v / 32767.0).max(-1.0)
            } else {
                v
            }
        }
        (DataType::U16, n) => {
            let v = u16::from_le_bytes([b[0], b[1]]) as f32;
            if n {
                v / 65535.0
            } else {
                v
            }
        }
    }
}

/// The bytes of `count` elements of `element_size` bytes, `stride` apart, from byte `offset`
/// of `view`, checked against the view and its buffer.
fn view_range<'a>(
    view: &gltf::buffer::View,
    buffers: &'a [Data],
    offset: usize,
    count: usize,
    element_size: usize,
    stride: usize,
) -> Result<&'a [u8], String> {
    let buffer = buffers
        .get(view.buffer().index())
        .ok_or_else(|| format!("bufferView {} has no buffer", view.index()))?;
    let span = count
        .checked_sub(1)
        .map_or(Some(0), |last| {
            last.checked_mul(stride)
                .and_then(|x| x.checked_add(element_size))
        })
        .and_then(|x| x.checked_add(offset));
    match span {
        Some(end) if end <= view.length() => {}
        _ => {
            return Err(format!(
                "{count} elements from byte {offset} (stride {stride}) overrun bufferView {} \
                 ({} bytes)",
                view.index(),
                view.length()
            ))
        }
    }
    let start = view.offset();
    let end = start.checked_add(view.length());
    match end {
        Some(end) if end <= buffer.len() => Ok(&buffer[start..end][offset..]),
        _ => Err(format!(
            "bufferView {} (bytes {start}..+{}) exceeds buffer {} ({} bytes)",
            view.index(),
            view.length(),
            view.buffer().index(),
            buffer.len()
        )),
    }
}

/// Reads `accessor` as `N`-component float vectors. Its type must have `N` components and its
/// component type must be one of `allowed`; the reason is returned otherwise (the caller
/// names the element).
pub(super) fn read<const N: usize>(
    accessor: &gltf::Accessor,
    buffers: &[Data],
    allowed: &[Component],
) -> Result<Vec<[f32; N]>, String> {
    let (values, n) = read_flat(accessor, buffers, &[N], allowed)?;
    debug_assert_eq!(n, N);
    Ok(values
        .chunks_exact(N)
        .map(|c| std::array::from_fn(|i| c[i]))
        .collect())
}

/// Reads `accessor` as a flat list of floats with its number of components, which must be one
/// of `widths`, and its component type one of `allowed`.
fn read_flat(
    accessor: &gltf::Accessor,
    buffers: &[Data],
    widths: &[usize],
    allowed: &[Component],
) -> Result<(Vec<f32>, usize), String> {
    let n = components(accessor.dimensions());
    let ty = accessor.data_type();
    let normalized = accessor.normalized();
    if !widths.contains(&n) || !allowed.contains(&(ty, normalized)) {
        let list = allowed
            .iter()
            .map(|(t, norm)| format!("{t:?}{}", if *norm { " normalized" } else { "" }))
            .collect::<Vec<_>>()
            .join(", ");
        return Err(format!(
            "unexpected layout {:?} of {ty:?}{} (allowed: {widths:?} components of {list})",
            accessor.dimensions(),
            if normalized { " normalized" } else { "" }
        ));
    }
    let count = accessor.count();
    if count == 0 {
        return Err("count is 0".into());
    }
    let size = component_size(ty);
    let element = n * size;
    let mut values = match accessor.view() {
        // No bufferView: all zeros (then usually replaced by a sparse substitution). Nothing
        // in the file backs the zeros, so there may be no more of them than the file's
        // buffers could hold had they been written out.
        None => {
            let held: usize = buffers.iter().map(|b| b.len()).sum();
            match count.checked_mul(element) {
                Some(bytes) if bytes <= held => vec![0.0; count * n],
                _ => {
                    return Err(format!(
                        "has no bufferView and claims {count} elements of {element} bytes, more \
                         than the file's buffers hold ({held} bytes)"
                    ))
                }
            }
        }
        Some(view) => {
            let stride = view.stride().unwrap_or(element);
            if stride < element {
                return Err(format!(
                    "byteStride {stride} is smaller than an element ({element} bytes)"
                ));
            }
            let bytes = view_range(&view, buffers, accessor.offset(), count, element, stride)?;
            let mut values = Vec::with_capacity(count * n);
            for i in 0..count {
                let e = &bytes[i * stride..i * stride + element];
                values.extend(e.chunks_exact(size).map(|c| component(c, ty, normalized)));
            }
            values
        }
    };
    if let Some(sparse) = accessor.sparse() {
        substitute(&sparse, buffers, count, n, ty, normalized, &mut values)?;
    }
    if values.iter().any(|v| !v.is_finite()) {
        return Err("contains a non-finite value".into());
    }
    Ok((values, n))
}

/// Applies a sparse accessor's substitutions to `values` (`count` elements of `n` components
/// of type `ty`).
fn substitute(
    sparse: &gltf::accessor::sparse::Sparse,
    buffers: &[Data],
    count: usize,
    n: usize,
    ty: DataType,
    normalized: bool,
    values: &mut [f32],
) -> Result<(), String> {
    let k = sparse.count();
    if k > count {
        return Err(format!(
            "sparse count {k} is more than the accessor's count {count}"
        ));
    }
    let indices = sparse.indices();
    let index_type = match indices.index_type() {
        gltf::accessor::sparse::IndexType::U8 => DataType::U8,
        gltf::accessor::sparse::IndexType::U16 => DataType::U16,
        gltf::accessor::sparse::IndexType::U32 => DataType::U32,
    };
    let isize = component_size(index_type);
    let ibytes = view_range(&indices.view(), buffers, indices.offset(), k, isize, isize)
        .map_err(|e| format!("sparse indices: {e}"))?;
    let element = n * component_size(ty);
    let vals = sparse.values();
    let vbytes = view_range(&vals.view(), buffers, vals.offset(), k, element, element)
        .map_err(|e| format!("sparse values: {e}"))?;
    for j in 0..k {
        let i = component(&ibytes[j * isize..], index_type, false) as usize;
        if i >= count {
            return Err(format!("sparse index {i} out of range ({count} elements)"));
        }
        let e = &vbytes[j * element..(j + 1) * element];
        for (c, b) in e.chunks_exact(component_size(ty)).enumerate() {
            values[i * n + c] = component(b, ty, normalized);
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    /// A document with one buffer holding `bin` and the given accessors and views.
    fn document(
        bin: &[u8],
        views: serde_json::Value,
        accessors: serde_json::Value,
    ) -> gltf::Document {
        let doc = json!({
            "asset": {"version": "2.0"},
            "buffers": [{"byteLength": bin.len()}],
            "bufferViews": views,
            "accessors": accessors,
        });
        let root: gltf::json::Root = serde_json::from_value(doc).unwrap();
        gltf::Document::from_json(root).unwrap()
    }

    fn data(bin: &[u8]) -> Vec<Data> {
        vec![Data(bin.to_vec())]
    }

    #[test]
    fn integer_components_normalized_and_not() {
        // i16 normalized: 32767 -> 1, -32768 -> -1 (clamped), 0 -> 0; u8 unnormalized.
        let mut bin = Vec::new();
        for v in [32767i16, -32768, 0, 16384] {
            bin.extend(v.to_le_bytes());
        }
        bin.extend([7u8, 255, 0, 0]);
        let doc = document(
            &bin,
            json!([{"buffer": 0, "byteOffset": 0, "byteLength": 8},
                   {"buffer": 0, "byteOffset": 8, "byteLength": 4}]),
            json!([
                {"bufferView": 0, "componentType": 5122, "normalized": true, "count": 2, "type": "VEC2"},
                {"bufferView": 1, "componentType": 5121, "count": 2, "type": "VEC2"},
            ]),
        );
        let b = data(&bin);
        let a = doc.accessors().next().unwrap();
        let v = read::<2>(&a, &b, POSITION).unwrap();
        assert_eq!(v, vec![[1.0, -1.0], [0.0, 16384.0 / 32767.0]]);
        let a = doc.accessors().nth(1).unwrap();
        assert_eq!(
            read::<2>(&a, &b, POSITION).unwrap(),
            vec![[7.0, 255.0], [0.0, 0.0]]
        );
        // Unnormalized u8 is not a direction, and a VEC2 is not a VEC3.
        assert!(read::<2>(&a, &b, DIRECTION)
            .unwrap_err()
            .contains("unexpected layout"));
        assert!(read::<3>(&a, &b, POSITION).is_err());
    }

    #[test]
    fn strides_sparse_and_zeros() {
        // Two interleaved u8-normalized RGB colours with stride 4, then a sparse substitution
        // of element 1 of a viewless accessor.
        let mut bin = vec![255u8, 0, 51, 9, 0, 255, 0, 9];
        bin.extend([1u8, 0, 0, 0]); // sparse index 1 (u8, padded)
        bin.extend(2.5f32.to_le_bytes());
        let doc = document(
            &bin,
            json!([{"buffer": 0, "byteOffset": 0, "byteLength": 8, "byteStride": 4},
                   {"buffer": 0, "byteOffset": 8, "byteLength": 1},
                   {"buffer": 0, "byteOffset": 12, "byteLength": 4}]),
            json!([
                {"bufferView": 0, "componentType": 5121, "normalized": true, "count": 2, "type": "VEC3"},
                {"componentType": 5126, "count": 3, "type": "SCALAR",
                 "sparse": {"count": 1, "indices": {"bufferView": 1, "componentType": 5121},
                            "values": {"bufferView": 2}}},
            ]),
        );
        let b = data(&bin);
        let a = doc.accessors().next().unwrap();
        assert_eq!(
            read::<3>(&a, &b, TEXCOORD).unwrap(),
            vec![[1.0, 0.0, 0.2], [0.0, 1.0, 0.0]]
        );
        let a = doc.accessors().nth(1).unwrap();
        assert_eq!(
            read::<1>(&a, &b, &[FLOAT]).unwrap(),
            vec![[0.0], [2.5], [0.0]]
        );
    }

    #[test]
    fn overruns_and_non_finite_values_are_errors() {
        let bin: Vec<u8> = [1.0f32, f32::NAN, 3.0]
            .iter()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        let doc = document(
            &bin,
            json!([{"buffer": 0, "byteOffset": 0, "byteLength": 12}]),
            json!([
                {"bufferView": 0, "componentType": 5126, "count": 2, "type": "VEC2"},
                {"bufferView": 0, "componentType": 5126, "count": 1, "type": "VEC3"},
            ]),
        );
        let b = data(&bin);
        let over = read::<2>(&doc.accessors().next().unwrap(), &b, &[FLOAT]).unwrap_err();
        assert!(over.contains("overrun bufferView 0"), "{over}");
        let nan = read::<3>(&doc.accessors().nth(1).unwrap(), &b, &[FLOAT]).unwrap_err();
        assert!(nan.contains("non-finite"), "{nan}");
        // A buffer shorter than its view is caught too.
        let short = read::<3>(&doc.accessors().nth(1).unwrap(), &data(&bin[..8]), &[FLOAT]);
        assert!(short.unwrap_err().contains("exceeds buffer 0"));
    }
}
