//! The triangle mesh of a scene object (`"shape": "mesh"`), from OBJ (tobj: every object of
//! the file, faces fanned into triangles), cleaned for collision: triangles without area
//! dropped (a warning says how many).
//! A mesh need not be closed (the Utah teapot is not) or have a volume (a plate modelled as
//! one sheet): it then collides as a surface, and a warning says so.

use std::path::Path;

use glam::Vec3;

use crate::{Error, Result};

/// Triangles with less area than this (square metres) are degenerate: a 0.1 mm sliver.
const MIN_AREA: f32 = 1e-10;
/// A mesh thinner than this along an axis of its bounding box has no volume, metres.
const MIN_THICKNESS: f32 = 1e-5;

/// A triangle mesh in its object's frame, metres.
#[derive(Clone, Debug, PartialEq)]
pub struct ObjectMesh {
    /// Vertex positions.
    pub vertices: Vec<Vec3>,
    /// Triangles, counter-clockwise seen from outside, indexing `vertices`.
    pub triangles: Vec<[u32; 3]>,
    /// What was repaired or is unusual (dropped triangles, no volume), one line each.
    pub warnings: Vec<String>,
}

impl ObjectMesh {
    /// Reads `path`, an `.obj` file.
    ///
    /// # Errors
    /// [`Error::File`] wrapping [`Error::ObjectMesh`] (another extension, a file the reader
    /// refuses, coordinates that are not finite, indices out of range, no triangle with an
    /// area), or [`Error::Io`].
    pub fn load(path: &Path) -> Result<Self> {
        let is_obj = path.extension().is_some_and(|e| e.eq_ignore_ascii_case("obj"));
        if !is_obj {
            return Err(Error::ObjectMesh("not an OBJ file (.obj)".into()).in_file(path));
        }
        let (vertices, indices) = read_obj(path)?;
        Self::from_triangles(vertices, &indices).map_err(|e| e.in_file(path))
    }

    /// A mesh from `vertices` and a flat triangle index list, checked and cleaned.
    ///
    /// # Errors
    /// [`Error::ObjectMesh`]: coordinates that are not finite, an index out of range, an
    /// index count not a multiple of 3, or no triangle with an area.
    pub fn from_triangles(vertices: Vec<Vec3>, indices: &[u32]) -> Result<Self> {
        let bad = |why: String| Err(Error::ObjectMesh(why));
        if let Some(i) = vertices.iter().position(|v| !v.is_finite()) {
            return bad(format!("vertex {i} is not finite"));
        }
        if indices.len() % 3 != 0 {
            return bad(format!("{} indices do not make whole triangles", indices.len()));
        }
        if let Some(&i) = indices.iter().find(|&&i| i as usize >= vertices.len()) {
            return bad(format!("index {i} beyond the {} vertices", vertices.len()));
        }
        let mut triangles = Vec::with_capacity(indices.len() / 3);
        let mut dropped = 0;
        for t in indices.chunks_exact(3) {
            let [a, b, c] = [t[0], t[1], t[2]].map(|i| vertices[i as usize]);
            if (b - a).cross(c - a).length() * 0.5 < MIN_AREA {
                dropped += 1;
            } else {
                triangles.push([t[0], t[1], t[2]]);
            }
        }
        if triangles.is_empty() {
            return bad(format!("no triangle with an area (of {})", indices.len() / 3));
        }
        let mut warnings = Vec::new();
        if dropped > 0 {
            warnings.push(format!("{dropped} triangles without area dropped"));
        }
        let (lo, hi) = vertices.iter().fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), v| (lo.min(*v), hi.max(*v)));
        if (hi - lo).min_element() < MIN_THICKNESS {
            warnings.push("flat (no volume): it collides as a surface".into());
        }
        Ok(Self { vertices, triangles, warnings })
    }
}

/// An OBJ's positions and triangles (every object of the file; faces fanned into triangles).
fn read_obj(path: &Path) -> Result<(Vec<Vec3>, Vec<u32>)> {
    let options = tobj::LoadOptions { triangulate: true, ignore_points: true, ignore_lines: true, ..Default::default() };
    let (models, _materials) = tobj::load_obj(path, &options).map_err(|e| match e {
        tobj::LoadError::OpenFileFailed | tobj::LoadError::ReadError => Error::io(path)(std::io::Error::other(e.to_string())),
        other => Error::ObjectMesh(format!("not a readable OBJ: {other}")).in_file(path),
    })?;
    let (mut vertices, mut indices) = (Vec::new(), Vec::new());
    for model in models {
        let base = vertices.len() as u32;
        vertices.extend(model.mesh.positions.chunks_exact(3).map(|p| Vec3::new(p[0], p[1], p[2])));
        indices.extend(model.mesh.indices.iter().map(|i| base + i));
    }
    Ok((vertices, indices))
}
