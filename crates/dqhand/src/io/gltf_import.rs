//! glTF 2.0 import (`.glb` and `.gltf`) of a skinned mesh, parsed with the `gltf` crate.
//!
//! Reads the node hierarchy (the skin's joints and their ancestors), inverse bind matrices,
//! and every triangle primitive of the meshes bound to the first skin: POSITION, NORMAL,
//! TEXCOORD_0, JOINTS_0/1 and WEIGHTS_0/1, and the CoR method's centres of rotation where
//! dqhand wrote them ([`super::CENTRE_OF_ROTATION`]; computed when first used where any
//! primitive lacks them). Primitives are concatenated in file order, those over the same
//! vertex attributes (one mesh in several materials) sharing their vertices, so vertex order
//! and count are kept. Every accessor is bounds-checked before it is read, so a
//! truncated or inconsistent file gives an error, never a panic.

use std::collections::HashMap;
use std::path::Path;

use glam::{Affine3A, Mat4, Quat, Vec3};
use gltf::accessor::{DataType, Dimensions};
use gltf::Semantic;

use super::CENTRE_OF_ROTATION;
use crate::Warning;
use crate::gltf_file::{self, check_accessor};
use crate::kinematics::{Joint, Skeleton, Transform};
use crate::model::Model;
use crate::skin::{MeshData, Part, SkinnedMesh};
use crate::{Error, Result};

/// Loads the first skinned mesh of a glTF 2.0 file.
///
/// # Errors
/// [`Error::Io`] if the file cannot be read, [`Error::File`] naming the file and the problem
/// for anything malformed or unsupported (see the module docs).
pub fn load_gltf(path: &Path) -> Result<Model> {
    let bytes = std::fs::read(path).map_err(Error::io(path))?;
    load_gltf_slice(&bytes, path)
}

/// Loads the first skinned mesh of a glTF 2.0 file already in memory (`.glb` bytes, or
/// `.gltf` JSON). `path` names the input in errors and is where relative buffer URIs of a
/// `.gltf` are looked up.
///
/// # Errors
/// As [`load_gltf`], except that reading `path` itself is not attempted.
pub fn load_gltf_slice(bytes: &[u8], path: &Path) -> Result<Model> {
    parse(bytes, path).map_err(|e| e.in_file(path))
}

fn parse(bytes: &[u8], path: &Path) -> Result<Model> {
    let bad = |m: String| Error::Gltf(m);
    let (gltf, buffers) = gltf_file::open(bytes, path)?;
    let get = |b: gltf::Buffer<'_>| buffers.get(b.index()).map(Vec::as_slice);

    let skinned: Vec<gltf::Node<'_>> = gltf.nodes().filter(|n| n.mesh().is_some() && n.skin().is_some()).collect();
    let first = skinned.first().ok_or_else(|| bad("no skinned mesh: no node has both a mesh and a skin".into()))?;
    let skin = first.skin().expect("filtered on skin");
    let mut warnings = Vec::new();
    let other = skinned.iter().filter(|n| n.skin().map(|s| s.index()) != Some(skin.index())).count();
    if other > 0 {
        warnings.push(Warning::OtherSkinsIgnored { nodes: other, skin: skin.index() });
    }

    // Skeleton: the skin's joints and all their ancestors, in node order.
    let mut parent = HashMap::new();
    for node in gltf.nodes() {
        for child in node.children() {
            parent.insert(child.index(), node.index());
        }
    }
    let mut keep = vec![false; gltf.nodes().len()];
    for joint in skin.joints() {
        let mut n = Some(joint.index());
        while let Some(i) = n {
            if keep[i] {
                break;
            }
            keep[i] = true;
            n = parent.get(&i).copied();
        }
    }
    let node_to_joint: HashMap<usize, usize> =
        keep.iter().enumerate().filter(|(_, &k)| k).enumerate().map(|(j, (n, _))| (n, j)).collect();
    let mut joints = Vec::with_capacity(node_to_joint.len());
    let mut names = std::collections::HashSet::new();
    for node in gltf.nodes().filter(|n| keep[n.index()]) {
        let (t, r, s) = node.transform().decomposed();
        let mut name = node.name().map_or_else(|| format!("node{}", node.index()), str::to_owned);
        if !names.insert(name.clone()) {
            let renamed = format!("{name}#{}", node.index());
            warnings.push(Warning::NodeRenamed { node: node.index(), name: name.clone(), renamed: renamed.clone() });
            name = renamed;
            names.insert(name.clone());
        }
        let rotation = Quat::from_array(r);
        let norm = rotation.length();
        if !norm.is_finite() || norm < 1e-6 {
            return Err(bad(format!("node {name:?} has rotation {r:?}, which is not a rotation")));
        }
        if (norm - 1.0).abs() > 1e-3 {
            warnings.push(Warning::RotationNormalised { node: name.clone(), norm });
        }
        joints.push(Joint {
            name,
            parent: parent.get(&node.index()).and_then(|p| node_to_joint.get(p)).copied(),
            rest: Transform { translation: Vec3::from(t), rotation: rotation / norm, scale: Vec3::from(s) },
        });
    }
    let skeleton = Skeleton::new(joints)?;

    let skin_joints: Vec<usize> = skin.joints().map(|n| node_to_joint[&n.index()]).collect();
    let mut inverse_bind = vec![Affine3A::IDENTITY; skeleton.len()];
    check_accessor(skin.inverse_bind_matrices(), &format!("skin {} inverse bind matrix", skin.index()), (Dimensions::Mat4, &[DataType::F32]), &buffers)?;
    if let Some(ibm) = skin.reader(get).read_inverse_bind_matrices() {
        let ibm: Vec<[[f32; 4]; 4]> = ibm.collect();
        if ibm.len() != skin_joints.len() {
            return Err(bad(format!("skin has {} joints but {} inverse bind matrices", skin_joints.len(), ibm.len())));
        }
        for (k, m) in ibm.iter().enumerate() {
            let m = Mat4::from_cols_array_2d(m);
            if m.row(3) != glam::Vec4::W {
                return Err(bad(format!("inverse bind matrix of joint {:?} is not affine", skeleton.joints()[skin_joints[k]].name)));
            }
            inverse_bind[skin_joints[k]] = Affine3A::from_mat4(m);
        }
    }

    // Joints outside the skin (ancestors of its joints) deform nothing, but the bind pose
    // must place them too: they keep their rest offset from their parent's bind pose.
    let mut in_skin = vec![false; skeleton.len()];
    skin_joints.iter().for_each(|&j| in_skin[j] = true);
    let mut bind_world = vec![Affine3A::IDENTITY; skeleton.len()];
    for &j in skeleton.order() {
        let joint = &skeleton.joints()[j];
        if in_skin[j] {
            let det = inverse_bind[j].matrix3.determinant();
            if !inverse_bind[j].is_finite() || det.abs() < 1e-12 {
                return Err(bad(format!("inverse bind matrix of joint {:?} is not invertible (determinant {det})", joint.name)));
            }
            bind_world[j] = inverse_bind[j].inverse();
        } else {
            bind_world[j] = joint.parent.map_or(Affine3A::IDENTITY, |p| bind_world[p]) * joint.rest.to_affine();
            inverse_bind[j] = bind_world[j].inverse();
        }
    }
    let mut data = MeshData { inverse_bind, ..MeshData::default() };
    let mut stride = 0;
    let mut primitives = Vec::new();
    for node in &skinned {
        if node.skin().map(|s| s.index()) != Some(skin.index()) {
            continue;
        }
        let mesh = node.mesh().expect("filtered on mesh");
        for prim in mesh.primitives() {
            if prim.mode() != gltf::mesh::Mode::Triangles {
                return Err(bad(format!("mesh {:?} primitive {} uses mode {:?}; only triangles are supported", mesh.name().unwrap_or(""), prim.index(), prim.mode())));
            }
            stride = stride.max(4 * influence_sets(&prim, mesh.name().unwrap_or(""))?);
            primitives.push((mesh.name().unwrap_or("mesh").to_owned(), prim));
        }
    }
    // CoR's centres, kept only if every primitive has them (else computed when first used).
    let mut all_centres: Vec<[f32; 3]> = Vec::new();
    // Each set of vertex attributes read: its accessors, first vertex and vertex count.
    let mut shared: Vec<(Vec<(String, usize)>, usize, usize)> = Vec::new();
    for (name, prim) in &primitives {
        let where_ = format!("mesh {name:?} primitive {}", prim.index());
        let sets = influence_sets(prim, name)?;
        let (vec3, uv, small_uint) = (&[DataType::F32][..], &[DataType::F32, DataType::U8, DataType::U16][..], &[DataType::U8, DataType::U16][..]);
        let mut kinds = vec![
            (Semantic::Positions, "POSITION", (Dimensions::Vec3, vec3)),
            (Semantic::Normals, "NORMAL", (Dimensions::Vec3, vec3)),
            (Semantic::TexCoords(0), "TEXCOORD_0", (Dimensions::Vec2, uv)),
        ];
        for set in 0..sets as u32 {
            let labels = [["JOINTS_0", "WEIGHTS_0"], ["JOINTS_1", "WEIGHTS_1"]][set as usize];
            kinds.push((Semantic::Joints(set), labels[0], (Dimensions::Vec4, small_uint)));
            kinds.push((Semantic::Weights(set), labels[1], (Dimensions::Vec4, uv)));
        }
        let centre = Semantic::Extras(CENTRE_OF_ROTATION[1..].to_owned());
        kinds.push((centre.clone(), CENTRE_OF_ROTATION, (Dimensions::Vec3, vec3)));
        for (semantic, label, kind) in kinds {
            check_accessor(prim.get(&semantic), &format!("{where_} {label}"), kind, &buffers)?;
        }
        check_accessor(prim.indices(), &format!("{where_} index"), gltf_file::INDEX_KIND, &buffers)?;
        let reader = prim.reader(get);
        // A primitive over the same vertex attributes as an earlier one (one mesh in several
        // materials, as dqhand writes the built-in hand) shares its vertices.
        let key: Vec<(String, usize)> = prim.attributes().map(|(semantic, a)| (semantic.to_string(), a.index())).collect();
        if let Some(&(_, base, n)) = shared.iter().find(|(k, _, _)| *k == key) {
            let indices = gltf_file::vertex_order(&reader, n, &where_)?;
            let start = data.indices.len();
            data.parts.push(Part { name: name.clone(), vertices: base..base + n, indices: start..start + indices.len() });
            data.indices.extend(indices.iter().map(|&i| i + base as u32));
            continue;
        }
        let positions: Vec<[f32; 3]> =
            reader.read_positions().ok_or_else(|| bad(format!("{where_} has no POSITION accessor")))?.collect();
        let n = positions.len();
        let base = data.positions.len() as u32;
        let mut influences = vec![(0u32, 0f32); n * stride];
        for set in 0..sets {
            let js = reader.read_joints(set as u32).ok_or_else(|| bad(format!("{where_} has no JOINTS_{set} accessor")))?;
            let ws = reader.read_weights(set as u32).ok_or_else(|| bad(format!("{where_} has no WEIGHTS_{set} accessor")))?;
            let (js, ws): (Vec<[u16; 4]>, Vec<[f32; 4]>) = (js.into_u16().collect(), ws.into_f32().collect());
            if js.len() != n || ws.len() != n {
                return Err(bad(format!("{where_}: JOINTS_{set}/WEIGHTS_{set} have {}/{} entries for {n} vertices", js.len(), ws.len())));
            }
            for v in 0..n {
                for c in 0..4 {
                    let j = usize::from(js[v][c]);
                    let w = ws[v][c];
                    let joint = match skin_joints.get(j) {
                        Some(&s) => s as u32,
                        None if w == 0.0 => 0,
                        None => return Err(bad(format!("{where_}: vertex {v} uses joint {j}, but the skin has {} joints", skin_joints.len()))),
                    };
                    influences[v * stride + set * 4 + c] = (joint, w);
                }
            }
        }
        let normals: Option<Vec<[f32; 3]>> = reader.read_normals().map(Iterator::collect);
        let centres: Option<Vec<[f32; 3]>> = prim.get(&centre).and_then(|a| gltf::accessor::Iter::new(a, get)).map(Iterator::collect);
        let uvs: Option<Vec<[f32; 2]>> = reader.read_tex_coords(0).map(|t| t.into_f32().collect());
        let indices = gltf_file::vertex_order(&reader, n, &where_)?;
        if normals.as_ref().is_some_and(|v| v.len() != n) || uvs.as_ref().is_some_and(|v| v.len() != n) || centres.as_ref().is_some_and(|v| v.len() != n) {
            return Err(bad(format!("{where_}: NORMAL, TEXCOORD_0 or {CENTRE_OF_ROTATION} count differs from POSITION ({n})")));
        }
        let start = data.indices.len();
        shared.push((key, base as usize, n));
        data.parts.push(Part { name: name.clone(), vertices: base as usize..base as usize + n, indices: start..start + indices.len() });
        data.indices.extend(indices.iter().map(|i| i + base));
        // Normals and UVs are kept only if every primitive has them.
        match normals {
            Some(v) if data.normals.len() == base as usize => data.normals.extend(v),
            _ => data.normals.clear(),
        }
        match uvs {
            Some(v) if data.uvs.len() == base as usize => data.uvs.extend(v),
            _ => data.uvs.clear(),
        }
        match centres {
            Some(v) if all_centres.len() == base as usize => all_centres.extend(v),
            _ => all_centres.clear(),
        }
        data.positions.extend(positions);
        data.joints.extend(influences.iter().map(|i| i.0));
        data.weights.extend(influences.iter().map(|i| i.1));
    }
    if data.normals.len() != data.positions.len() && !data.normals.is_empty() {
        data.normals.clear();
    }
    if data.uvs.len() != data.positions.len() {
        data.uvs.clear();
    }
    data.stride = stride.max(1);
    let n = data.positions.len();
    let (mut mesh, mesh_warnings) = SkinnedMesh::new(data)?;
    if all_centres.len() == n {
        mesh = mesh.with_centres_of_rotation(&all_centres).map_err(|e| bad(format!("{CENTRE_OF_ROTATION}: {e}")))?;
    }
    warnings.extend(mesh_warnings);
    let name = path.file_name().map_or_else(|| path.display().to_string(), |f| f.to_string_lossy().into_owned());
    // A named mesh says what the file holds (dqhand names it with the model's description);
    // kept to one short line, as descriptions are shown.
    let mesh_name: String = first.mesh().and_then(|m| m.name()).unwrap_or("").chars().filter(|c| !c.is_control()).take(120).collect();
    let description = if mesh_name.trim().is_empty() { format!("glTF file {name}") } else { format!("{} (glTF file {name})", mesh_name.trim()) };
    Ok(Model { description, skeleton, mesh: std::sync::Arc::new(mesh), warnings, appearance: None })
}

/// How many JOINTS/WEIGHTS sets (of four influences) a primitive has: 1 or 2.
fn influence_sets(prim: &gltf::Primitive<'_>, mesh: &str) -> Result<usize> {
    let has = |s: Semantic| prim.get(&s).is_some();
    match (has(Semantic::Joints(1)), has(Semantic::Weights(1))) {
        (false, false) => Ok(1),
        (true, true) => Ok(2),
        _ => Err(Error::Gltf(format!("mesh {mesh:?} primitive {} has only one of JOINTS_1 and WEIGHTS_1", prim.index()))),
    }
}
