//! Posed meshes as Wavefront OBJ (positions, normals, triangles), vertex order kept.

use std::io::Write;
use std::path::Path;

use super::{check_lengths, create};
use crate::Result;

/// Writes a triangle mesh with per-vertex normals as OBJ text (`v`, `vn`, `f a//a`).
///
/// * `positions`, `normals` — #V each; `indices` — #F × 3.
///
/// # Errors
/// [`crate::Error::Io`] if the file cannot be written; [`crate::Error::Mesh`] if the
/// array lengths disagree.
pub fn write_obj(path: &Path, positions: &[[f32; 3]], normals: &[[f32; 3]], indices: &[u32]) -> Result<()> {
    check_lengths(positions, normals, indices)?;
    let (out, finish) = create(path)?;
    let mut w = std::io::BufWriter::new(out);
    let mut body = || -> std::io::Result<()> {
        writeln!(w, "# dqhand posed mesh: {} vertices, {} triangles", positions.len(), indices.len() / 3)?;
        for p in positions {
            writeln!(w, "v {} {} {}", p[0], p[1], p[2])?;
        }
        for n in normals {
            writeln!(w, "vn {} {} {}", n[0], n[1], n[2])?;
        }
        for t in indices.chunks_exact(3) {
            let [a, b, c] = [t[0] + 1, t[1] + 1, t[2] + 1];
            writeln!(w, "f {a}//{a} {b}//{b} {c}//{c}")?;
        }
        w.flush()
    };
    body().map_err(|e| finish(e))
}
