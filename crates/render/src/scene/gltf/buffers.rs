//! The file's buffers (external files, data URIs, the GLB binary chunk) and bufferViews,
//! checked against each other, and the Loader's reading of accessors (their layouts, bounds and
//! the decoded bytes they are charged for).

use super::{accessors, compression, uri_label, Loader};
use crate::scene::files::{Files, Uri};
use crate::scene::SceneError;
use gltf::accessor::{DataType, Dimensions};
use std::path::Path;

/// Loads every buffer of `document` (external files, data URIs, the GLB binary chunk), except
/// the meshopt fallback buffers `fallbacks`, which are placeholders without data (left empty).
/// Each holds exactly its `byteLength` bytes: a file is checked to be at least that long
/// before they are reserved, and nothing past them is read.
pub(super) fn load_buffers(
    path: &Path,
    files: &Files,
    document: &gltf::Document,
    mut blob: Option<Vec<u8>>,
    fallbacks: &[usize],
) -> Result<Vec<gltf::buffer::Data>, SceneError> {
    let mut buffers = Vec::new();
    for buffer in document.buffers() {
        if fallbacks.contains(&buffer.index()) {
            buffers.push(gltf::buffer::Data(Vec::new()));
            continue;
        }
        let length = buffer.length();
        let (element, data) = match buffer.source() {
            gltf::buffer::Source::Bin => {
                let element = format!("buffer {} (GLB binary chunk)", buffer.index());
                let data = blob.take().ok_or_else(|| {
                    SceneError::invalid(path, &element, "the GLB file has no binary chunk")
                })?;
                (element, data)
            }
            gltf::buffer::Source::Uri(uri) => {
                let element = format!(
                    "buffer {} ({})",
                    buffer.index(),
                    uri_label(files.folder(), uri)
                );
                let data = match files.uri(uri, &format!("buffer {}", buffer.index()))? {
                    Uri::Data(bytes, _) => bytes,
                    Uri::File(file) => files.read_prefix(&file, length as u64, &element)?,
                };
                (element, data)
            }
        };
        if data.len() < length {
            return Err(SceneError::invalid(
                path,
                element,
                format!("holds {} bytes but byteLength is {length}", data.len()),
            ));
        }
        let mut data = data;
        data.truncate(length);
        buffers.push(gltf::buffer::Data(data));
    }
    Ok(buffers)
}

/// Checks that every bufferView lies within its buffer, and that none (after decompression)
/// reads a meshopt fallback buffer.
pub(super) fn check_views(
    path: &Path,
    document: &gltf::Document,
    buffers: &[gltf::buffer::Data],
    fallbacks: &[usize],
) -> Result<(), SceneError> {
    for view in document.views() {
        if fallbacks.contains(&view.buffer().index()) {
            return Err(SceneError::invalid(
                path,
                format!("bufferView {}", view.index()),
                format!(
                    "reads buffer {}, a {} fallback without data, but is not compressed",
                    view.buffer().index(),
                    compression::MESHOPT
                ),
            ));
        }
        let end = view.offset().checked_add(view.length());
        let have = buffers[view.buffer().index()].len();
        if end.is_none_or(|e| e > have) {
            return Err(SceneError::invalid(
                path,
                format!("bufferView {}", view.index()),
                format!(
                    "bytes {}..+{} exceed buffer {} ({have} bytes)",
                    view.offset(),
                    view.length(),
                    view.buffer().index()
                ),
            ));
        }
    }
    Ok(())
}

impl Loader<'_> {
    /// Checks that `accessor` has one of the `allowed` layouts and lies within its view.
    /// The values of vertex attribute `name` of primitive `element` (`accessor`), of `N`
    /// components of one of the types `allowed`, and `count` of them if given.
    pub(super) fn attribute<const N: usize>(
        &self,
        accessor: &gltf::Accessor,
        element: &str,
        name: &str,
        allowed: &[accessors::Component],
        count: Option<usize>,
    ) -> Result<Vec<[f32; N]>, SceneError> {
        let element = format!("{element}, {name} (accessor {})", accessor.index());
        // What the values will take, charged before they are read (the accessor itself is
        // checked against its bufferView by the read).
        self.files
            .charge_expanded((accessor.count() as u64).saturating_mul(4 * N as u64))
            .map_err(|r| self.bad(&element, r))?;
        let values = accessors::read::<N>(accessor, &self.buffers, allowed)
            .map_err(|r| self.bad(&element, r))?;
        match count {
            Some(n) if values.len() != n => Err(self.bad(
                element,
                format!("{} values for {n} positions", values.len()),
            )),
            _ => Ok(values),
        }
    }

    pub(super) fn check_accessor(
        &self,
        accessor: &gltf::Accessor,
        element: &str,
        allowed: &[(Dimensions, DataType)],
    ) -> Result<(), SceneError> {
        let element = format!("{element} (accessor {})", accessor.index());
        if accessor.sparse().is_some() {
            return Err(self.bad(element, "sparse accessors are not supported"));
        }
        let layout = (accessor.dimensions(), accessor.data_type());
        if !allowed.contains(&layout) {
            return Err(self.bad(
                element,
                format!("unexpected layout {layout:?} (allowed: {allowed:?})"),
            ));
        }
        let count = accessor.count();
        if count == 0 {
            return Err(self.bad(element, "count is 0"));
        }
        // The indices will be read as 32-bit values.
        self.files
            .charge_expanded((count as u64).saturating_mul(4))
            .map_err(|r| self.bad(&element, r))?;
        let Some(view) = accessor.view() else {
            return Err(self.bad(element, "has no bufferView"));
        };
        let size = accessor.size();
        let stride = view.stride().unwrap_or(size);
        if stride < size {
            return Err(self.bad(
                element,
                format!("byteStride {stride} is smaller than an element ({size} bytes)"),
            ));
        }
        let end = (count - 1)
            .checked_mul(stride)
            .and_then(|x| x.checked_add(size))
            .and_then(|x| x.checked_add(accessor.offset()));
        if end.is_none_or(|e| e > view.length()) {
            return Err(self.bad(
                element,
                format!(
                    "{count} elements from byte {} (stride {stride}) overrun bufferView {} \
                     ({} bytes)",
                    accessor.offset(),
                    view.index(),
                    view.length()
                ),
            ));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::super::test_docs::{load_err, test_doc, write_external};

    use crate::scene::Scene;

    use serde_json::json;

    #[test]
    fn missing_bin_names_the_buffer_file() {
        let dir = tempfile::tempdir().unwrap();
        let (doc, bin) = test_doc();
        let path = write_external(dir.path(), doc, &bin);
        std::fs::remove_file(dir.path().join("scene data.bin")).unwrap();
        let err = Scene::load(&path).unwrap_err().to_string();
        assert!(
            err.contains("external.gltf") && err.contains("buffer 0"),
            "{err}"
        );
        assert!(err.contains("scene data.bin"), "{err}");
    }

    #[test]
    fn accessor_out_of_range_names_mesh_and_primitive() {
        let (mut doc, bin) = test_doc();
        doc["accessors"][0]["count"] = json!(400);
        let err = load_err(doc, &bin);
        assert!(
            err.contains("mesh \"quad\" (0), primitive 0, POSITION") && err.contains("overrun"),
            "{err}"
        );
        let (mut doc, bin) = test_doc();
        doc["bufferViews"][0]["byteLength"] = json!(100_000);
        let err = load_err(doc, &bin);
        assert!(err.contains("bufferView 0"), "{err}");
        let (mut doc, bin) = test_doc();
        doc["accessors"][3]["componentType"] = json!(5126); // float indices
        let err = load_err(doc, &bin);
        assert!(err.contains("primitive 0, indices"), "{err}");
    }
}
