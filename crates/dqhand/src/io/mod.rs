//! Files: glTF 2.0 in and out, posed meshes as PLY and OBJ, pose files (JSON).

mod gltf_export;
mod gltf_import;
mod obj;
mod ply;
mod pose_file;

use std::path::Path;

pub use gltf_export::{skinned_glb, write_posed_glb, write_skinned_glb, CENTRE_OF_ROTATION};
pub use gltf_import::{load_gltf, load_gltf_slice};
pub use obj::write_obj;
pub use ply::write_ply;
pub use pose_file::{PoseFile, WristPose};

use crate::{Error, Result};

/// Writes a posed mesh, the format chosen by the extension: `.ply`, `.obj` or `.glb`.
///
/// # Errors
/// [`Error::OutputFormat`] for another extension, else as the writer.
pub fn write_posed(path: &Path, positions: &[[f32; 3]], normals: &[[f32; 3]], uvs: &[[f32; 2]], indices: &[u32]) -> Result<()> {
    match path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).as_deref() {
        Some("ply") => write_ply(path, positions, normals, indices),
        Some("obj") => write_obj(path, positions, normals, indices),
        Some("glb") => write_posed_glb(path, positions, normals, uvs, indices),
        _ => Err(Error::OutputFormat(path.into())),
    }
}

fn check_lengths(positions: &[[f32; 3]], normals: &[[f32; 3]], indices: &[u32]) -> Result<()> {
    if positions.len() != normals.len() || indices.len() % 3 != 0 {
        return Err(Error::Mesh(format!(
            "{} positions, {} normals and {} indices do not make a triangle mesh",
            positions.len(),
            normals.len(),
            indices.len()
        )));
    }
    Ok(())
}

/// Creates a file, returning it and a function that names the file in a later write error.
fn create(path: &Path) -> Result<(std::fs::File, impl Fn(std::io::Error) -> Error + '_)> {
    let file = std::fs::File::create(path).map_err(Error::io(path))?;
    Ok((file, Error::io(path)))
}

fn write_bytes(path: &Path, bytes: &[u8]) -> Result<()> {
    std::fs::write(path, bytes).map_err(Error::io(path))
}
