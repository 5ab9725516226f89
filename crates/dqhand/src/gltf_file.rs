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
/// validating and would panic (found by fuzzing). A GLB container that does not parse is left
/// to `gltf`'s own error.
fn check_primitive_accessors(bytes: &[u8]) -> Result<()> {
    let json = match gltf::Glb::from_slice(bytes) {
        Ok(glb) => glb.json,
        // A GLB container the `gltf` crate refuses gets its own error from it.
        Err(_) if bytes.starts_with(b"glTF") => return Ok(()),
        Err(_) => bytes.into(),
    };
    // JSON that serde_json cannot read whole (a lone surrogate escape in a field the `gltf`
    // crate skips unread, found by fuzzing) is refused here, or it would go unchecked.
    let root: serde_json::Value = serde_json::from_slice(&json).map_err(|e| Error::Gltf(format!("not a valid glTF 2.0 file: {e}")))?;
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

/// The bytes of every buffer: the GLB binary chunk, a `data:` URI, or a file in `path`'s
/// folder (see [`buffer_file`]), read up to its declared length.
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
                let file = buffer_file(path, uri).map_err(|why| Error::Gltf(format!("buffer {} refers to {uri:?}: {why}", buffer.index())))?;
                read_at_most(&file, buffer.length()).map_err(|e| Error::Gltf(format!("buffer {} file {}: {e}", buffer.index(), file.display())))?
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
    // glTF allows any stride from 4 bytes; the `gltf` crate's reader asserts one element fits.
    let stride = view.stride().unwrap_or(elem);
    if stride < elem {
        return bad(format!("uses buffer view {} with a stride of {stride} bytes, less than its {elem}-byte elements", view.index()));
    }
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

/// What a primitive's index accessor may hold (the `gltf` crate reads no other).
pub const INDEX_KIND: (Dimensions, &[DataType]) = (Dimensions::Scalar, &[DataType::U8, DataType::U16, DataType::U32]);

/// A primitive's vertex order: its indices, read through `reader` (their accessor checked
/// with [`check_accessor`] against [`INDEX_KIND`]), or 0..n when it has none; each below its
/// `n` vertices. `what` names the primitive in the error.
///
/// # Errors
/// [`Error::Gltf`] for an index out of range.
pub fn vertex_order<'a, 's, F>(reader: &gltf::mesh::Reader<'a, 's, F>, n: usize, what: &str) -> Result<Vec<u32>>
where
    F: Clone + Fn(gltf::Buffer<'a>) -> Option<&'s [u8]>,
{
    let order: Vec<u32> = match reader.read_indices() {
        Some(i) => i.into_u32().collect(),
        None => (0..n as u32).collect(),
    };
    match order.iter().find(|&&i| i as usize >= n) {
        Some(i) => Err(Error::Gltf(format!("{what}: index {i} is out of range for {n} vertices"))),
        None => Ok(order),
    }
}

/// The file a buffer's `uri` names, if it may be read: a relative URI (percent-escapes
/// decoded) that stays inside the folder of the glTF at `path`, even through symbolic links,
/// naming a regular file. Anything else (another scheme, an absolute path, `..` out of the
/// folder, a device or a pipe, which could never end or never answer) is refused with why.
fn buffer_file(path: &Path, uri: &str) -> std::result::Result<std::path::PathBuf, String> {
    let decoded = percent_decode(uri).ok_or("a malformed percent-escape")?;
    let scheme = decoded.split_once(':').is_some_and(|(s, _)| !s.is_empty() && !s.contains(['/', '\\']));
    if scheme {
        return Err("only data: URIs and files beside the glTF are read".into());
    }
    let relative = Path::new(&decoded);
    if decoded.contains(['\\', '\0']) || !relative.components().all(|c| matches!(c, std::path::Component::Normal(_))) {
        return Err("not a plain relative path inside the glTF's folder".into());
    }
    let folder = path.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
    let folder = folder.canonicalize().map_err(|e| format!("the glTF's folder: {e}"))?;
    let file = folder.join(relative).canonicalize().map_err(|e| e.to_string())?;
    if !file.starts_with(&folder) {
        return Err("leads out of the glTF's folder".into());
    }
    if !file.metadata().map_err(|e| e.to_string())?.is_file() {
        return Err("not a regular file".into());
    }
    Ok(file)
}

/// The first `length` bytes of `file` (all of it when shorter; the caller checks the length).
fn read_at_most(file: &Path, length: usize) -> std::io::Result<Vec<u8>> {
    use std::io::Read as _;
    let mut data = Vec::with_capacity(length.min(1 << 20));
    std::fs::File::open(file)?.take(length as u64).read_to_end(&mut data)?;
    Ok(data)
}

/// `uri` with its `%XX` escapes decoded; `None` when an escape is malformed or the result is
/// not UTF-8.
fn percent_decode(uri: &str) -> Option<String> {
    let bytes = uri.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%' {
            let hex = bytes.get(i + 1..i + 3).filter(|h| h.iter().all(u8::is_ascii_hexdigit))?;
            out.push(u8::from_str_radix(std::str::from_utf8(hex).ok()?, 16).ok()?);
            i += 3;
        } else {
            out.push(bytes[i]);
            i += 1;
        }
    }
    String::from_utf8(out).ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_buffer_file_is_read_up_to_the_length_asked() {
        let file = std::env::temp_dir().join(format!("dqhand-read-at-most-{}", std::process::id()));
        std::fs::write(&file, [7u8; 100]).unwrap();
        assert_eq!(read_at_most(&file, 10).unwrap(), [7u8; 10]);
        assert_eq!(read_at_most(&file, 1000).unwrap().len(), 100);
    }

    #[test]
    fn percent_escapes_decode_or_are_refused() {
        assert_eq!(percent_decode("a%20b%2Fc").as_deref(), Some("a b/c"));
        assert_eq!(percent_decode("plain.bin").as_deref(), Some("plain.bin"));
        for bad in ["%", "%2", "%zz", "%+f", "%FF"] {
            assert_eq!(percent_decode(bad), None, "{bad}");
        }
    }
}
