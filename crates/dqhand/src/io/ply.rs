//! Posed meshes as binary PLY (positions, normals, triangles), vertex order kept.

use std::io::Write;
use std::path::Path;

use super::{check_lengths, create};
use crate::Result;

/// Writes a triangle mesh with per-vertex normals as little-endian binary PLY.
///
/// * `positions`, `normals` — #V each; `indices` — #F × 3.
///
/// # Errors
/// [`crate::Error::Io`] if the file cannot be written; [`crate::Error::Mesh`] if the
/// array lengths disagree.
pub fn write_ply(path: &Path, positions: &[[f32; 3]], normals: &[[f32; 3]], indices: &[u32]) -> Result<()> {
    check_lengths(positions, normals, indices)?;
    let (mut out, finish) = create(path)?;
    let mut body = Vec::with_capacity(positions.len() * 24 + indices.len() / 3 * 13 + 256);
    write!(
        body,
        "ply\nformat binary_little_endian 1.0\ncomment dqhand posed mesh\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\nproperty float nx\nproperty float ny\nproperty float nz\nelement face {}\nproperty list uchar uint vertex_indices\nend_header\n",
        positions.len(),
        indices.len() / 3
    )
    .expect("writing to a Vec cannot fail");
    for (p, n) in positions.iter().zip(normals) {
        for c in p.iter().chain(n) {
            body.extend_from_slice(&c.to_le_bytes());
        }
    }
    for t in indices.chunks_exact(3) {
        body.push(3);
        for i in t {
            body.extend_from_slice(&i.to_le_bytes());
        }
    }
    out.write_all(&body).map_err(|e| finish(e))
}
