//! A glTF 2.0 file opened safely with the `gltf` crate: what would make the crate panic is
//! refused first, buffers are read, and every accessor is bounds-checked before it is read, so
//! a truncated or inconsistent file gives an error, never a panic. The skinned-model importer
//! (`io`) and scene object meshes (`scene`) both read files through it.

use std::path::Path;

use base64::Engine as _;
use gltf::accessor::{DataType, Dimensions};

use crate::{Error, Result};

/// Opens a glTF 2.0 file in memory (`.glb` bytes or `.gltf` JSON) with the `gltf` crate,
/// refusing first what would make that crate panic, and reads its buffers. `path` is where
/// relative buffer URIs are looked up.
///
/// # Errors
/// [`Error::Gltf`]: a truncated or inconsistent GLB header, a primitive naming an accessor
/// that does not exist, anything the `gltf` crate refuses, a buffer that cannot be read or is
/// shorter than declared.
pub fn open(bytes: &[u8], path: &Path) -> Result<(gltf::Gltf, Vec<Vec<u8>>)> {
    let bad = |m: String| Error::Gltf(m);
    if bytes.len() >= 12 && &bytes[..4] == b"glTF" {
        let declared = u32::from_le_bytes([bytes[8], bytes[9], bytes[10], bytes[11]]) as usize;
        if declared > bytes.len() {
            return Err(bad(format!("truncated GLB: {} bytes of the declared {declared}", bytes.len())));
        }
        // The `gltf` crate subtracts the header from the declared length unchecked (found by
        // fuzzing: an overflow panic in debug builds).
        if declared < 12 {
            return Err(bad(format!("GLB header declares {declared} bytes, less than the 12-byte header itself")));
        }
    }
    check_primitive_accessors(bytes)?;
    let gltf = gltf::Gltf::from_slice(bytes).map_err(|e| bad(format!("not a valid glTF 2.0 file: {e}")))?;
    let buffers = load_buffers(&gltf, path)?;
    Ok((gltf, buffers))
}

/// Refuses a mesh primitive whose attribute or index accessor does not exist, before the `gltf`
/// crate validates the file: gltf-json 1.4 indexes the POSITION accessor unchecked while
/// validating and would panic (found by fuzzing). JSON that does not parse is left to `gltf`'s
/// own error.
fn check_primitive_accessors(bytes: &[u8]) -> Result<()> {
    let json = match gltf::Glb::from_slice(bytes) {
        Ok(glb) => glb.json,
        Err(_) => bytes.into(),
    };
    let Ok(root) = serde_json::from_slice::<serde_json::Value>(&json) else { return Ok(()) };
    let accessors = root["accessors"].as_array().map_or(0, Vec::len);
    for (m, mesh) in root["meshes"].as_array().into_iter().flatten().enumerate() {
        for (p, primitive) in mesh["primitives"].as_array().into_iter().flatten().enumerate() {
            let attributes = primitive["attributes"].as_object().into_iter().flatten();
            let used = attributes.map(|(name, a)| (name.as_str(), a)).chain(primitive.get("indices").map(|i| ("indices", i)));
            for (name, index) in used {
                if index.as_u64().is_some_and(|i| i >= accessors as u64) {
                    return Err(Error::Gltf(format!("mesh {m} primitive {p}: {name} uses accessor {index}, but there are {accessors}")));
                }
            }
        }
    }
    Ok(())
}

/// The bytes of every buffer: the GLB binary chunk, a `data:` URI, or a file beside `path`.
fn load_buffers(gltf: &gltf::Gltf, path: &Path) -> Result<Vec<Vec<u8>>> {
    let mut out = Vec::new();
    for buffer in gltf.buffers() {
        let data = match buffer.source() {
            gltf::buffer::Source::Bin => {
                gltf.blob.clone().ok_or_else(|| Error::Gltf(format!("buffer {} refers to a GLB binary chunk the file does not have", buffer.index())))?
            }
            gltf::buffer::Source::Uri(uri) if uri.starts_with("data:") => {
                let b64 = uri.split_once(";base64,").map(|s| s.1).ok_or_else(|| {
                    Error::Gltf(format!("buffer {} has a data URI that is not base64", buffer.index()))
                })?;
                base64::engine::general_purpose::STANDARD
                    .decode(b64)
                    .map_err(|e| Error::Gltf(format!("buffer {} has invalid base64: {e}", buffer.index())))?
            }
            gltf::buffer::Source::Uri(uri) => {
                if uri.contains("://") {
                    return Err(Error::Gltf(format!("buffer {} refers to {uri:?}; only local files are read", buffer.index())));
                }
                let file = path.parent().unwrap_or(Path::new(".")).join(uri);
                std::fs::read(&file).map_err(|e| Error::Gltf(format!("buffer {} file {}: {e}", buffer.index(), file.display())))?
            }
        };
        if data.len() < buffer.length() {
            return Err(Error::Gltf(format!(
                "buffer {} is truncated: {} bytes of the declared {}",
                buffer.index(),
                data.len(),
                buffer.length()
            )));
        }
        out.push(data);
    }
    Ok(out)
}

/// Checks an accessor that is about to be read: the element type glTF prescribes for its use
/// (the `gltf` crate's readers support no other), at least one element, no sparse storage,
/// and elements inside its buffer view and the view inside its buffer, so that reading it
/// cannot go out of bounds. `None` (an absent optional attribute) passes.
pub fn check_accessor(a: Option<gltf::Accessor<'_>>, what: &str, kind: (Dimensions, &[DataType]), buffers: &[Vec<u8>]) -> Result<()> {
    let Some(a) = a else { return Ok(()) };
    let i = a.index();
    let bad = |m: String| Err(Error::Gltf(format!("{what} accessor {i} {m}")));
    let (dims, types) = kind;
    if a.dimensions() != dims || !types.contains(&a.data_type()) {
        return bad(format!("is {:?} {:?}; expected {dims:?} of {types:?}", a.dimensions(), a.data_type()));
    }
    if a.sparse().is_some() {
        return bad("is sparse; sparse accessors are not supported".into());
    }
    let Some(view) = a.view() else { return bad("has no buffer view".into()) };
    let buffer = &buffers[view.buffer().index()];
    if view.offset().checked_add(view.length()).is_none_or(|end| end > buffer.len()) {
        return bad(format!(
            "uses buffer view {} (bytes {}..{}), which reaches past the end of buffer {} ({} bytes)",
            view.index(),
            view.offset(),
            view.offset().saturating_add(view.length()),
            view.buffer().index(),
            buffer.len()
        ));
    }
    let elem = a.dimensions().multiplicity() * a.data_type().size();
    let stride = view.stride().unwrap_or(elem);
    let end = (a.count().checked_sub(1))
        .and_then(|last| stride.checked_mul(last))
        .and_then(|x| x.checked_add(a.offset()))
        .and_then(|x| x.checked_add(elem));
    match end {
        None if a.count() == 0 => bad("has no elements".into()),
        Some(end) if end <= view.length() => Ok(()),
        _ => bad(format!("({} elements) reaches past the end of buffer view {}", a.count(), view.index())),
    }
}
