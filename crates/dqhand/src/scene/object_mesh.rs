//! The triangle mesh of a scene object (`"shape": "mesh"`), from OBJ (tobj: every object of
//! the file, faces fanned into triangles) or glTF 2.0 (`.glb`, `.gltf`: every triangle
//! primitive of the meshes of the default scene, placed by its nodes' transforms), cleaned for
//! collision: triangles without area dropped (a warning says how many).
//! A mesh need not be closed (the Utah teapot is not) or have a volume (a plate modelled as
//! one sheet): it then collides as a surface, and a warning says so.
//!
//! The meshes the built-in scenes name ship inside the crate ([`ObjectMesh::BUILTIN`]): a
//! copied or installed program finds them without the source tree.

use std::io::BufRead;
use std::path::Path;

use glam::{Mat4, Vec3};
use gltf::accessor::{DataType, Dimensions};

use crate::Warning;
use crate::gltf_file;
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
    /// What was repaired or is unusual (dropped triangles, no volume).
    pub warnings: Vec<Warning>,
}

/// The meshes compiled into the crate, by their path under its `data/` folder (where the
/// built-in scenes, in `data/scenes/`, find them).
const BUILTIN_MESHES: [(&str, &[u8]); 1] = [("objects/teapot.obj", include_bytes!("../../data/objects/teapot.obj"))];

impl ObjectMesh {
    /// The meshes that ship with the crate, compiled in, by their path under its `data/`
    /// folder: the Utah teapot of the built-in scenes (`objects/teapot.obj`).
    pub const BUILTIN: [&'static str; 1] = [BUILTIN_MESHES[0].0];

    /// Reads `path`, an `.obj`, `.glb` or `.gltf` file.
    ///
    /// # Errors
    /// [`Error::File`] wrapping [`Error::ObjectMesh`] or [`Error::Gltf`] (another extension, a
    /// file the reader refuses, coordinates that are not finite, indices out of range, no
    /// triangle with an area), or [`Error::Io`].
    pub fn load(path: &Path) -> Result<Self> {
        match extension(path).as_deref() {
            Some("obj") => {
                let file = std::fs::File::open(path).map_err(Error::io(path))?;
                Self::from_obj_reader(&mut std::io::BufReader::new(file), path)
            }
            Some("glb" | "gltf") => Self::from_gltf_slice(&std::fs::read(path).map_err(Error::io(path))?, path),
            _ => Err(not_a_mesh_file(path)),
        }
    }

    /// The built-in mesh `name` ([`Self::BUILTIN`]), from the copy compiled in.
    ///
    /// # Errors
    /// [`Error::UnknownName`] for another name; none otherwise (a test reads each).
    pub fn builtin(name: &str) -> Result<Self> {
        let Some(&(name, bytes)) = BUILTIN_MESHES.iter().find(|(n, _)| *n == name) else {
            return Err(Error::UnknownName { kind: "built-in mesh", name: name.to_owned(), valid: Self::BUILTIN.join(", ") });
        };
        let path = Path::new(name);
        match extension(path).as_deref() {
            Some("obj") => Self::from_obj_reader(&mut &bytes[..], path),
            Some("glb" | "gltf") => Self::from_gltf_slice(bytes, path),
            _ => Err(not_a_mesh_file(path)),
        }
    }

    /// A mesh from OBJ text being read; `path` names it in errors. Material libraries are not
    /// read (only the shape matters).
    ///
    /// # Errors
    /// As [`Self::load`].
    pub fn from_obj_reader(reader: &mut impl BufRead, path: &Path) -> Result<Self> {
        let (vertices, indices) = read_obj(reader, path)?;
        Self::from_triangles(vertices, &indices).map_err(|e| e.in_file(path))
    }

    /// A mesh from glTF bytes (`.glb`, or `.gltf` JSON) already in memory; `path` names them
    /// in errors and is where a `.gltf`'s buffer files are looked up.
    ///
    /// # Errors
    /// As [`Self::load`], the file already read.
    pub fn from_gltf_slice(bytes: &[u8], path: &Path) -> Result<Self> {
        let read = read_gltf(bytes, path).and_then(|(vertices, indices, mut warnings)| {
            let mut mesh = Self::from_triangles(vertices, &indices)?;
            warnings.append(&mut mesh.warnings);
            mesh.warnings = warnings;
            Ok(mesh)
        });
        read.map_err(|e| e.in_file(path))
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
            warnings.push(Warning::DegenerateTriangles { triangles: dropped });
        }
        let (lo, hi) = vertices.iter().fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), v| (lo.min(*v), hi.max(*v)));
        if (hi - lo).min_element() < MIN_THICKNESS {
            warnings.push(Warning::FlatMesh);
        }
        Ok(Self { vertices, triangles, warnings })
    }
}

fn extension(path: &Path) -> Option<String> {
    path.extension().map(|e| e.to_string_lossy().to_ascii_lowercase())
}

fn not_a_mesh_file(path: &Path) -> Error {
    Error::ObjectMesh("not a mesh file (.obj, .glb or .gltf)".into()).in_file(path)
}

/// An OBJ's positions and triangles (every object of the file; faces fanned into triangles);
/// `path` names it in errors.
fn read_obj(reader: &mut impl BufRead, path: &Path) -> Result<(Vec<Vec3>, Vec<u32>)> {
    let options = tobj::LoadOptions { triangulate: true, ignore_points: true, ignore_lines: true, ..Default::default() };
    let no_materials = |_: &Path| Err(tobj::LoadError::OpenFileFailed);
    let (models, _materials) = tobj::load_obj_buf(reader, &options, no_materials).map_err(|e| match e {
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

/// A glTF's triangles, in the frame of its default scene (else its first; else every node
/// that has no parent): each mesh node's primitives placed by the node's world transform (a
/// mirroring one reverses their winding, as glTF says). Strips and fans are split into
/// triangles; points and lines are skipped (a warning says how many).
fn read_gltf(bytes: &[u8], path: &Path) -> Result<(Vec<Vec3>, Vec<u32>, Vec<Warning>)> {
    let (gltf, buffers) = gltf_file::open(bytes, path)?;
    let get = |b: gltf::Buffer<'_>| buffers.get(b.index()).map(Vec::as_slice);
    let mut roots: Vec<(gltf::Node<'_>, Mat4)> = match gltf.default_scene().or_else(|| gltf.scenes().next()) {
        Some(scene) => scene.nodes().map(|n| (n, Mat4::IDENTITY)).collect(),
        None => {
            let children: std::collections::HashSet<usize> = gltf.nodes().flat_map(|n| n.children().map(|c| c.index())).collect();
            gltf.nodes().filter(|n| !children.contains(&n.index())).map(|n| (n, Mat4::IDENTITY)).collect()
        }
    };
    let (mut vertices, mut indices, mut skipped) = (Vec::new(), Vec::new(), 0);
    // Each node once, whatever its place in the hierarchy (a file may make a cycle of it).
    let mut seen = vec![false; gltf.nodes().len()];
    while let Some((node, parent)) = roots.pop() {
        if std::mem::replace(&mut seen[node.index()], true) {
            continue;
        }
        let world = parent * Mat4::from_cols_array_2d(&node.transform().matrix());
        roots.extend(node.children().map(|c| (c, world)));
        let Some(mesh) = node.mesh() else { continue };
        let mirrored = world.determinant() < 0.0;
        for prim in mesh.primitives() {
            use gltf::mesh::Mode;
            if !matches!(prim.mode(), Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan) {
                skipped += 1;
                continue;
            }
            let what = format!("mesh {} primitive {}", mesh.index(), prim.index());
            gltf_file::check_accessor(prim.get(&gltf::Semantic::Positions), &format!("{what} POSITION"), (Dimensions::Vec3, &[DataType::F32]), &buffers)?;
            gltf_file::check_accessor(prim.indices(), &format!("{what} index"), gltf_file::INDEX_KIND, &buffers)?;
            let reader = prim.reader(get);
            let positions = reader.read_positions().ok_or_else(|| Error::Gltf(format!("{what} has no POSITION accessor")))?;
            let base = vertices.len() as u32;
            vertices.extend(positions.map(|p| world.transform_point3(Vec3::from(p))));
            let order = gltf_file::vertex_order(&reader, vertices.len() - base as usize, &what)?;
            let triangle = |k: usize| -> [u32; 3] {
                match prim.mode() {
                    // Every other triangle of a strip turns the other way.
                    Mode::TriangleStrip if k % 2 == 1 => [order[k + 1], order[k], order[k + 2]],
                    Mode::TriangleStrip => [order[k], order[k + 1], order[k + 2]],
                    Mode::TriangleFan => [order[0], order[k + 1], order[k + 2]],
                    _ => [order[3 * k], order[3 * k + 1], order[3 * k + 2]],
                }
            };
            let count = match prim.mode() {
                Mode::Triangles => order.len() / 3,
                _ => order.len().saturating_sub(2),
            };
            if prim.mode() == Mode::Triangles && order.len() % 3 != 0 {
                return Err(Error::Gltf(format!("{what}: {} indices do not make whole triangles", order.len())));
            }
            for k in 0..count {
                let [a, b, c] = triangle(k);
                let [a, b, c] = if mirrored { [a, c, b] } else { [a, b, c] };
                indices.extend([base + a, base + b, base + c]);
            }
        }
    }
    let warnings = if skipped > 0 { vec![Warning::NotTriangles { primitives: skipped }] } else { Vec::new() };
    Ok((vertices, indices, warnings))
}
