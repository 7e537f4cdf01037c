//! Compressed geometry: EXT_meshopt_compression and KHR_draco_mesh_compression, decoded before
//! the document is read, so the rest of the loader sees plain accessors.
//!
//! Both work on the file's JSON and its loaded buffers:
//! - EXT_meshopt_compression compresses bufferViews. Each compressed view is decoded with
//!   meshoptimizer's reference decoder (the `meshopt` crate, which builds it from source), its
//!   filter (octahedral, quaternion, exponential, colour) undone, and the view is pointed at a
//!   new buffer holding the decoded bytes. Fallback buffers (`"fallback": true`, no data) are
//!   never read.
//! - KHR_draco_mesh_compression compresses primitives. Each one is decoded with the pure-Rust
//!   Draco decoder `draco-core`, and its attribute and index accessors (which carry only a
//!   count and a type) are pointed at new bufferViews of 32-bit floats and indices.
//!
//! Each decoded extension is then dropped from `extensionsUsed` and `extensionsRequired`.
//! Errors name the bufferView or the primitive and the reason.
//!
//! Nothing is reserved for a size the file claims before it is checked: a meshopt view's
//! `count * byteStride` against its byteLength, against the most its compressed bytes can
//! expand to (1024 times for attributes, from the format: a block of up to 256 vertices
//! costs at least one control byte per 4 bytes of stride; one byte per triangle or per index
//! for indices) and against the scene's budget of decoded bytes
//! ([`crate::scene::LoadOptions::max_decoded_bytes`]); a Draco stream is decoded under
//! `draco-core`'s `DecodeLimits` set to what is left of that budget.

use crate::scene::files::Files;
use crate::scene::SceneError;
use gltf::buffer::Data;
use serde_json::{json, Value};
use std::path::Path;

/// The meshopt extension's name.
pub(super) const MESHOPT: &str = "EXT_meshopt_compression";
/// The Draco extension's name.
pub(super) const DRACO: &str = "KHR_draco_mesh_compression";

/// The indices of the buffers the meshopt extension marks as fallbacks (placeholders with no
/// data, read only by loaders without the extension), so buffer loading skips them.
pub(super) fn fallback_buffers(raw: &Value) -> Vec<usize> {
    raw.get("buffers")
        .and_then(Value::as_array)
        .map(|buffers| {
            buffers
                .iter()
                .enumerate()
                .filter(|(_, b)| {
                    b.pointer(&format!("/extensions/{MESHOPT}/fallback"))
                        .and_then(Value::as_bool)
                        == Some(true)
                })
                .map(|(i, _)| i)
                .collect()
        })
        .unwrap_or_default()
}

/// Decodes every meshopt-compressed bufferView and Draco-compressed primitive of `raw`, adding
/// the decoded bytes to `buffers` and rewriting `raw` to point at them. Returns whether
/// anything was decoded.
pub(super) fn decode(
    path: &Path,
    raw: &mut Value,
    buffers: &mut Vec<Data>,
    files: &Files,
) -> Result<bool, SceneError> {
    let meshopt = decode_meshopt(path, raw, buffers, files)?;
    let draco = decode_draco(path, raw, buffers, files)?;
    for (done, name) in [(meshopt, MESHOPT), (draco, DRACO)] {
        if done {
            for list in ["extensionsUsed", "extensionsRequired"] {
                if let Some(Value::Array(names)) = raw.get_mut(list) {
                    names.retain(|n| n.as_str() != Some(name));
                }
            }
        }
    }
    Ok(meshopt || draco)
}

/// A non-negative integer member of `v`, or `default` when absent.
fn index(v: &Value, key: &str, default: Option<usize>) -> Result<usize, String> {
    match v.get(key) {
        None => default.ok_or_else(|| format!("has no {key}")),
        Some(x) => x
            .as_u64()
            .map(|x| x as usize)
            .ok_or_else(|| format!("{key} is not a non-negative integer")),
    }
}

/// `bytes[offset..offset + length]` of buffer `buffer`, checked.
fn slice(buffers: &[Data], buffer: usize, offset: usize, length: usize) -> Result<&[u8], String> {
    let data = buffers
        .get(buffer)
        .ok_or_else(|| format!("buffer {buffer} does not exist"))?;
    offset
        .checked_add(length)
        .and_then(|end| data.get(offset..end))
        .ok_or_else(|| {
            format!(
                "bytes {offset}..+{length} exceed buffer {buffer} ({} bytes)",
                data.len()
            )
        })
}

/// Decodes the meshopt-compressed views (see the module documentation).
fn decode_meshopt(
    path: &Path,
    raw: &mut Value,
    buffers: &mut Vec<Data>,
    files: &Files,
) -> Result<bool, SceneError> {
    let mut new_buffers = Vec::new();
    let Some(Value::Array(views)) = raw.get_mut("bufferViews") else {
        return Ok(false);
    };
    for (i, view) in views.iter_mut().enumerate() {
        let Some(ext) = view.pointer(&format!("/extensions/{MESHOPT}")).cloned() else {
            continue;
        };
        let element = format!("bufferView {i} ({MESHOPT})");
        let length = index(view, "byteLength", None)
            .map_err(|reason| SceneError::invalid(path, &element, reason))?;
        let bytes = meshopt_view(&ext, buffers, length, files)
            .map_err(|reason| SceneError::invalid(path, &element, reason))?;
        new_buffers.push(bytes);
        view["buffer"] = json!(buffers.len() + new_buffers.len() - 1);
        view["byteOffset"] = json!(0);
        if let Some(stride) = ext
            .get("byteStride")
            .filter(|_| ext.get("mode") == Some(&json!("ATTRIBUTES")))
        {
            view["byteStride"] = stride.clone();
        }
        if let Some(Value::Object(e)) = view.get_mut("extensions") {
            e.remove(MESHOPT);
        }
    }
    let any = !new_buffers.is_empty();
    for bytes in new_buffers {
        push_buffer(path, raw, buffers, bytes)?;
    }
    Ok(any)
}

/// Appends `bytes` as a new buffer, both to `buffers` and to the document's buffer list
/// (without a URI: it is never loaded from a source), and returns its index.
fn push_buffer(
    path: &Path,
    raw: &mut Value,
    buffers: &mut Vec<Data>,
    bytes: Vec<u8>,
) -> Result<usize, SceneError> {
    let list = raw
        .as_object_mut()
        .and_then(|doc| {
            doc.entry("buffers")
                .or_insert_with(|| json!([]))
                .as_array_mut()
        })
        .ok_or_else(|| SceneError::invalid(path, "buffers", "is not an array"))?;
    debug_assert_eq!(
        list.len(),
        buffers.len(),
        "one loaded buffer per buffer entry"
    );
    list.push(json!({"byteLength": bytes.len()}));
    buffers.push(Data(bytes));
    Ok(buffers.len() - 1)
}

/// The most bytes a meshopt vertex stream of `compressed` bytes can decode to: each block of
/// at most 256 vertices costs at least one control byte per 4 bytes of stride (version 1;
/// version 0 costs more), so a stream expands at most 4 x 256 = 1024 times.
const MESHOPT_MAX_EXPANSION: u64 = 1024;

/// The decoded bytes of one meshopt-compressed view of `length` bytes, from its extension
/// object; the claimed size is checked against `length`, against what the compressed bytes
/// can hold and against the budget of `files` before it is reserved.
fn meshopt_view(
    ext: &Value,
    buffers: &[Data],
    length: usize,
    files: &Files,
) -> Result<Vec<u8>, String> {
    let buffer = index(ext, "buffer", None)?;
    let offset = index(ext, "byteOffset", Some(0))?;
    let compressed = index(ext, "byteLength", None)?;
    let stride = index(ext, "byteStride", None)?;
    let count = index(ext, "count", None)?;
    let mode = ext.get("mode").and_then(Value::as_str).unwrap_or("");
    let filter = ext.get("filter").and_then(Value::as_str).unwrap_or("NONE");
    let source = slice(buffers, buffer, offset, compressed)?;
    let size = count
        .checked_mul(stride)
        .filter(|&s| s <= isize::MAX as usize)
        .ok_or_else(|| format!("{count} elements of {stride} bytes overflow"))?;
    if size != length {
        return Err(format!(
            "{count} elements of {stride} bytes are {size} bytes but its byteLength is {length}"
        ));
    }
    // What the compressed bytes can hold at most (the decoder's own minimum sizes for
    // indices: a header byte, one byte per triangle or index, and a tail).
    let backed = match mode {
        "ATTRIBUTES" => (source.len() as u64).saturating_mul(MESHOPT_MAX_EXPANSION) >= size as u64,
        "TRIANGLES" => source.len() >= 1 + count / 3 + 16,
        "INDICES" => source.len() >= 1 + count + 4,
        _ => true,
    };
    if !backed {
        return Err(format!(
            "claims {count} elements ({size} bytes) from {} compressed bytes, more than the \
             {mode} encoding can hold",
            source.len()
        ));
    }
    files.charge_decoded(size as u64)?;
    let mut out = vec![0u8; size];
    let code = match mode {
        "ATTRIBUTES" => {
            if stride == 0 || stride % 4 != 0 || stride > 256 {
                return Err(format!(
                    "byteStride {stride} is not a multiple of 4 from 4 to 256"
                ));
            }
            // SAFETY: `out` holds exactly `count * stride` bytes, which is what the decoder
            // writes for `count` vertices of `stride` bytes; `source` is a valid slice. The
            // decoder validates its input (meshoptimizer documents it as safe for untrusted
            // data) and returns non-zero instead of reading past `source`.
            unsafe {
                meshopt::ffi::meshopt_decodeVertexBuffer(
                    out.as_mut_ptr().cast(),
                    count,
                    stride,
                    source.as_ptr(),
                    source.len(),
                )
            }
        }
        "TRIANGLES" | "INDICES" => {
            if stride != 2 && stride != 4 {
                return Err(format!("byteStride {stride} of indices is not 2 or 4"));
            }
            if mode == "TRIANGLES" && count % 3 != 0 {
                return Err(format!("{count} triangle indices is not a multiple of 3"));
            }
            let decode = if mode == "TRIANGLES" {
                meshopt::ffi::meshopt_decodeIndexBuffer
            } else {
                meshopt::ffi::meshopt_decodeIndexSequence
            };
            // SAFETY: as above, `out` holds `count` indices of `stride` (2 or 4) bytes.
            unsafe {
                decode(
                    out.as_mut_ptr().cast(),
                    count,
                    stride,
                    source.as_ptr(),
                    source.len(),
                )
            }
        }
        other => return Err(format!("unknown mode {other:?}")),
    };
    if code != 0 {
        return Err(format!(
            "the meshopt decoder rejects the data (code {code})"
        ));
    }
    let filtered_stride_ok = match filter {
        "NONE" => true,
        "OCTAHEDRAL" | "COLOR" => stride == 4 || stride == 8,
        "QUATERNION" => stride == 8,
        "EXPONENTIAL" => stride % 4 == 0,
        other => return Err(format!("unknown filter {other:?}")),
    };
    if !filtered_stride_ok || (filter != "NONE" && mode != "ATTRIBUTES") {
        return Err(format!(
            "filter {filter} does not apply to mode {mode} with byteStride {stride}"
        ));
    }
    let filter_fn = match filter {
        "OCTAHEDRAL" => {
            Some(meshopt::ffi::meshopt_decodeFilterOct as unsafe extern "C" fn(_, _, _))
        }
        "QUATERNION" => {
            Some(meshopt::ffi::meshopt_decodeFilterQuat as unsafe extern "C" fn(_, _, _))
        }
        "EXPONENTIAL" => {
            Some(meshopt::ffi::meshopt_decodeFilterExp as unsafe extern "C" fn(_, _, _))
        }
        "COLOR" => Some(meshopt::ffi::meshopt_decodeFilterColor as unsafe extern "C" fn(_, _, _)),
        _ => None,
    };
    if let Some(f) = filter_fn {
        // SAFETY: `out` holds `count` elements of `stride` bytes, a stride the filter accepts
        // (checked above); the filter rewrites them in place.
        unsafe { f(out.as_mut_ptr().cast(), count, stride) };
    }
    Ok(out)
}

/// The number of components of an accessor `type` string.
fn type_components(ty: &str) -> Option<usize> {
    Some(match ty {
        "SCALAR" => 1,
        "VEC2" => 2,
        "VEC3" => 3,
        "VEC4" => 4,
        "MAT2" => 4,
        "MAT3" => 9,
        "MAT4" => 16,
        _ => return None,
    })
}

/// Decodes the Draco-compressed primitives (see the module documentation).
fn decode_draco(
    path: &Path,
    raw: &mut Value,
    buffers: &mut Vec<Data>,
    files: &Files,
) -> Result<bool, SceneError> {
    let mut any = false;
    let mesh_count = raw
        .get("meshes")
        .and_then(Value::as_array)
        .map_or(0, Vec::len);
    for m in 0..mesh_count {
        let prim_count = raw["meshes"][m]
            .get("primitives")
            .and_then(Value::as_array)
            .map_or(0, Vec::len);
        for p in 0..prim_count {
            let prim = &raw["meshes"][m]["primitives"][p];
            let Some(ext) = prim.pointer(&format!("/extensions/{DRACO}")).cloned() else {
                continue;
            };
            let element = format!("mesh {m}, primitive {p} ({DRACO})");
            let bad = |reason: String| SceneError::invalid(path, &element, reason);
            let prim = prim.clone();
            let decoded = draco_primitive(raw, &prim, &ext, buffers, files).map_err(bad)?;
            // One new buffer per primitive, one view per decoded accessor, 4-byte aligned.
            let mut bytes = Vec::new();
            let mut placed = Vec::new();
            for (accessor, data) in decoded {
                let offset = bytes.len();
                bytes.extend_from_slice(&data.bytes);
                bytes.resize(bytes.len().next_multiple_of(4), 0);
                placed.push((accessor, data, offset));
            }
            let buffer = push_buffer(path, raw, buffers, bytes)?;
            for (accessor, data, offset) in placed {
                let views = raw
                    .as_object_mut()
                    .and_then(|doc| {
                        doc.entry("bufferViews")
                            .or_insert_with(|| json!([]))
                            .as_array_mut()
                    })
                    .ok_or_else(|| SceneError::invalid(path, "bufferViews", "is not an array"))?;
                views.push(
                    json!({"buffer": buffer, "byteOffset": offset, "byteLength": data.bytes.len()}),
                );
                let view = views.len() - 1;
                let a = &mut raw["accessors"][accessor];
                a["bufferView"] = json!(view);
                a["byteOffset"] = json!(0);
                a["componentType"] = json!(data.component_type);
                a["count"] = json!(data.count);
                if let Some(obj) = a.as_object_mut() {
                    obj.remove("normalized");
                }
            }
            if let Some(Value::Object(e)) = raw["meshes"][m]["primitives"][p].get_mut("extensions")
            {
                e.remove(DRACO);
            }
            any = true;
        }
    }
    Ok(any)
}

/// One decoded accessor's data: little-endian bytes, their glTF component type, the count.
struct Decoded {
    bytes: Vec<u8>,
    component_type: u32,
    count: usize,
}

/// The decoded data of one Draco primitive, by accessor index: its attributes as floats and
/// its indices as 32-bit integers. The decoder works under limits set to the budget of
/// `files`, and what is converted is charged to it before it is reserved.
fn draco_primitive(
    raw: &Value,
    prim: &Value,
    ext: &Value,
    buffers: &[Data],
    files: &Files,
) -> Result<Vec<(usize, Decoded)>, String> {
    let view = index(ext, "bufferView", None)?;
    let v = raw
        .get("bufferViews")
        .and_then(|views| views.get(view))
        .ok_or_else(|| format!("bufferView {view} does not exist"))?;
    let source = slice(
        buffers,
        index(v, "buffer", None)?,
        index(v, "byteOffset", Some(0))?,
        index(v, "byteLength", None)?,
    )?;
    let mut mesh = draco_core::Mesh::new();
    let budget = files.decode_budget();
    let limits = draco_core::DecodeLimits::default()
        .with_max_decoded_bytes(budget)
        .with_max_points(budget / 4)
        .with_max_faces(budget / 12);
    draco_core::MeshDecoder::new()
        .decode(
            &mut draco_core::DecoderBuffer::new(source).with_limits(limits),
            &mut mesh,
        )
        .map_err(|e| format!("the Draco decoder rejects bufferView {view}: {e}"))?;
    let points = mesh.num_points();
    let mut out = Vec::new();
    let attributes = ext
        .get("attributes")
        .and_then(Value::as_object)
        .ok_or("has no attributes")?;
    for (semantic, id) in attributes {
        let id = id
            .as_u64()
            .ok_or_else(|| format!("attribute {semantic}'s id is not an integer"))?;
        let accessor = prim
            .pointer(&format!("/attributes/{semantic}"))
            .and_then(Value::as_u64)
            .ok_or_else(|| {
                format!("{semantic} is compressed but not an attribute of the primitive")
            })? as usize;
        let a = raw
            .get("accessors")
            .and_then(|x| x.get(accessor))
            .ok_or_else(|| format!("accessor {accessor} does not exist"))?;
        let n = a
            .get("type")
            .and_then(Value::as_str)
            .and_then(type_components)
            .ok_or_else(|| format!("accessor {accessor} has no valid type"))?;
        let attr = mesh
            .attribute_by_unique_id(id as u32)
            .ok_or_else(|| format!("the Draco data has no attribute {id} ({semantic})"))?;
        files.charge_decoded((points as u64).saturating_mul(n as u64 * 4))?;
        let mut values = attr.read_f32s(points, n);
        if a.get("normalized").and_then(Value::as_bool) == Some(true) {
            let scale = match attr.data_type() {
                draco_core::DataType::Int8 => 127.0,
                draco_core::DataType::Uint8 => 255.0,
                draco_core::DataType::Int16 => 32767.0,
                draco_core::DataType::Uint16 => 65535.0,
                _ => 1.0,
            };
            for v in &mut values {
                *v = (*v / scale).max(-1.0);
            }
        }
        out.push((
            accessor,
            Decoded {
                bytes: values.iter().flat_map(|v| v.to_le_bytes()).collect(),
                component_type: 5126,
                count: points,
            },
        ));
    }
    if let Some(indices) = prim.get("indices").and_then(Value::as_u64) {
        files.charge_decoded((mesh.num_faces() as u64).saturating_mul(12))?;
        let bytes: Vec<u8> = mesh
            .faces()
            .iter()
            .flat_map(|f| f.iter().flat_map(|p| p.0.to_le_bytes()))
            .collect();
        out.push((
            indices as usize,
            Decoded {
                count: mesh.num_faces() * 3,
                bytes,
                component_type: 5125,
            },
        ));
    }
    Ok(out)
}
