//! glTF 2.0 export as `.glb`: the rigged, skinned model (rest pose, joint hierarchy, inverse
//! bind matrices, JOINTS/WEIGHTS; with its appearance, one primitive per skin region over the
//! same vertices, their materials and skin maps), or a posed static mesh. Vertex order and
//! count are kept.

use std::path::Path;

use serde_json::{json, Value};

use super::{check_lengths, write_bytes};
#[cfg(feature = "interaction")]
use crate::collision::ProxyShape;
use crate::appearance::{Appearance, SkinImage, SurfaceRegion};
use crate::model::Model;
use crate::Result;

const FLOAT: u32 = 5126;
const UNSIGNED_SHORT: u32 = 5123;
const UNSIGNED_INT: u32 = 5125;
const ARRAY_BUFFER: u32 = 34962;
const ELEMENT_ARRAY_BUFFER: u32 = 34963;

/// Accumulates the binary chunk, buffer views and accessors of one GLB.
#[derive(Default)]
struct Glb {
    bin: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
}

impl Glb {
    /// Appends `bytes` as a buffer view of their own (4-byte aligned); returns its index.
    fn view(&mut self, bytes: &[u8], target: Option<u32>) -> usize {
        while self.bin.len() % 4 != 0 {
            self.bin.push(0);
        }
        let mut view = json!({ "buffer": 0, "byteOffset": self.bin.len(), "byteLength": bytes.len() });
        if let Some(t) = target {
            view["target"] = json!(t);
        }
        self.bin.extend_from_slice(bytes);
        self.views.push(view);
        self.views.len() - 1
    }

    /// Appends one accessor over `bytes` (in a view of their own); returns its index.
    fn accessor(&mut self, bytes: &[u8], count: usize, component: u32, kind: &str, target: Option<u32>, bounds: Option<([f32; 3], [f32; 3])>) -> usize {
        let view = self.view(bytes, target);
        let mut acc = json!({ "bufferView": view, "componentType": component, "count": count, "type": kind });
        if let Some((min, max)) = bounds {
            acc["min"] = json!(min);
            acc["max"] = json!(max);
        }
        self.accessors.push(acc);
        self.accessors.len() - 1
    }

    fn floats<const N: usize>(&mut self, data: &[[f32; N]], kind: &str, target: Option<u32>) -> usize {
        let bytes: Vec<u8> = data.iter().flatten().flat_map(|f| f.to_le_bytes()).collect();
        self.accessor(&bytes, data.len(), FLOAT, kind, target, None)
    }

    fn positions(&mut self, p: &[[f32; 3]]) -> usize {
        let mut min = [f32::INFINITY; 3];
        let mut max = [f32::NEG_INFINITY; 3];
        for v in p {
            for c in 0..3 {
                min[c] = min[c].min(v[c]);
                max[c] = max[c].max(v[c]);
            }
        }
        let bytes: Vec<u8> = p.iter().flatten().flat_map(|f| f.to_le_bytes()).collect();
        self.accessor(&bytes, p.len(), FLOAT, "VEC3", Some(ARRAY_BUFFER), Some((min, max)))
    }

    fn indices(&mut self, i: &[u32]) -> usize {
        let bytes: Vec<u8> = i.iter().flat_map(|x| x.to_le_bytes()).collect();
        self.accessor(&bytes, i.len(), UNSIGNED_INT, "SCALAR", Some(ELEMENT_ARRAY_BUFFER), None)
    }

    /// Serialises the GLB container: header, JSON chunk (space-padded), BIN chunk.
    fn finish(mut self, mut doc: Value) -> Vec<u8> {
        while self.bin.len() % 4 != 0 {
            self.bin.push(0);
        }
        doc["asset"] = json!({ "version": "2.0", "generator": concat!("dqhand ", env!("CARGO_PKG_VERSION")) });
        doc["buffers"] = json!([{ "byteLength": self.bin.len() }]);
        doc["bufferViews"] = Value::Array(self.views);
        doc["accessors"] = Value::Array(self.accessors);
        let mut text = serde_json::to_vec(&doc).expect("JSON values serialise");
        while text.len() % 4 != 0 {
            text.push(b' ');
        }
        let total = 12 + 8 + text.len() + 8 + self.bin.len();
        let mut out = Vec::with_capacity(total);
        out.extend_from_slice(b"glTF");
        out.extend_from_slice(&2u32.to_le_bytes());
        out.extend_from_slice(&(total as u32).to_le_bytes());
        out.extend_from_slice(&(text.len() as u32).to_le_bytes());
        out.extend_from_slice(b"JSON");
        out.extend_from_slice(&text);
        out.extend_from_slice(&(self.bin.len() as u32).to_le_bytes());
        out.extend_from_slice(b"BIN\0");
        out.extend_from_slice(&self.bin);
        out
    }
}

/// The vertex attribute holding each vertex's centre of rotation (VEC3, float, bind space):
/// an application-specific attribute, which glTF 2.0 lets a name starting with `_` be
/// (loaders that do not know it ignore it; the validator accepts it).
pub const CENTRE_OF_ROTATION: &str = "_CENTRE_OF_ROTATION";

/// Bytes of `image` as an RGB PNG.
fn png(image: &SkinImage) -> Vec<u8> {
    let mut out = Vec::new();
    let mut encoder = ::png::Encoder::new(&mut out, image.width, image.height);
    encoder.set_color(::png::ColorType::Rgb);
    encoder.set_depth(::png::BitDepth::Eight);
    encoder.set_compression(::png::Compression::High);
    let mut writer = encoder.write_header().expect("a PNG header into memory");
    writer.write_image_data(&image.rgb).expect("an image of its own size into memory");
    writer.finish().expect("a PNG into memory");
    out
}

/// The materials, images, textures and samplers of `appearance`, one material per region in
/// [`SurfaceRegion::ALL`] order: physically based skin with sheen (the soft, forward-scattered
/// light of skin's fine hairs and oils, `KHR_materials_sheen`), and nails that are harder and
/// coated (`KHR_materials_clearcoat`), drawn with the back's maps, where the nails are painted.
fn appearance_materials(glb: &mut Glb, appearance: &Appearance) -> Value {
    let maps = appearance.maps();
    let images: Vec<Value> = maps.iter().flat_map(|m| [&m.albedo, &m.normal]).map(|image| json!({ "bufferView": glb.view(&png(image), None), "mimeType": "image/png" })).collect();
    let textures: Vec<Value> = (0..images.len()).map(|i| json!({ "sampler": 0, "source": i })).collect();
    let material = |region: SurfaceRegion| {
        let side = usize::from(region == SurfaceRegion::Palm);
        let (roughness, extensions) = match region {
            SurfaceRegion::Nail => (0.35, json!({ "KHR_materials_clearcoat": { "clearcoatFactor": 0.3, "clearcoatRoughnessFactor": 0.3 } })),
            _ => (0.6, json!({ "KHR_materials_sheen": { "sheenColorFactor": [0.9, 0.55, 0.45], "sheenRoughnessFactor": 0.5 } })),
        };
        json!({
            "name": region.name(),
            "pbrMetallicRoughness": { "baseColorTexture": { "index": 2 * side }, "metallicFactor": 0.0, "roughnessFactor": roughness },
            "normalTexture": { "index": 2 * side + 1 },
            "extensions": extensions,
        })
    };
    // Linear filtering with mipmaps, clamped: the UVs run to the map's edges at the wrist.
    const LINEAR: u32 = 9729;
    const LINEAR_MIPMAP_LINEAR: u32 = 9987;
    const CLAMP_TO_EDGE: u32 = 33071;
    json!({
        "materials": SurfaceRegion::ALL.map(material),
        "images": images,
        "textures": textures,
        "samplers": [{ "magFilter": LINEAR, "minFilter": LINEAR_MIPMAP_LINEAR, "wrapS": CLAMP_TO_EDGE, "wrapT": CLAMP_TO_EDGE }],
    })
}

/// A skin-toned, slightly rough PBR material.
fn skin_material() -> Value {
    json!([{ "name": "skin", "pbrMetallicRoughness": { "baseColorFactor": [0.87, 0.67, 0.56, 1.0], "metallicFactor": 0.0, "roughnessFactor": 0.6 } }])
}

/// Writes the model as a rigged, skinned GLB in its rest pose, which three.js and Blender load
/// and animate: the joint hierarchy as nodes (rest TRS), one skin with the inverse bind
/// matrices, a primitive with POSITION, NORMAL, TEXCOORD_0, JOINTS_0/WEIGHTS_0 (and
/// JOINTS_1/WEIGHTS_1 for vertices with more than four influences), and the CoR method's
/// centres of rotation as [`CENTRE_OF_ROTATION`] (computed here if the mesh has none yet), so
/// that whoever loads the file does not compute them again; a model with an appearance (the
/// built-in hand) has one primitive per region over those same attributes, with the
/// regions' materials and maps (`appearance_materials`). Built with the
/// `interaction` feature, each joint node with vertices of its own carries its collision proxy
/// (`collision::fit_proxies`) in the node's frame as `extras.dqhand_collision`:
/// `{"capsule": {"start", "end", "radius"}}` or `{"convex_hull": {"points", "triangles"}}`.
///
/// # Errors
/// [`crate::Error::Io`] if the file cannot be written.
pub fn write_skinned_glb(model: &Model, path: &Path) -> Result<()> {
    write_bytes(path, &skinned_glb(model))
}

/// The GLB [`write_skinned_glb`] writes, in memory (a server hands it to a page).
#[must_use]
pub fn skinned_glb(model: &Model) -> Vec<u8> {
    let mesh = &model.mesh;
    let skeleton = &model.skeleton;
    let mut glb = Glb::default();
    let positions = mesh.positions();
    let mut attributes = json!({
        "POSITION": glb.positions(&positions),
        "NORMAL": glb.floats(&mesh.normals(), "VEC3", Some(ARRAY_BUFFER)),
    });
    if !mesh.uvs().is_empty() {
        attributes["TEXCOORD_0"] = json!(glb.floats(mesh.uvs(), "VEC2", Some(ARRAY_BUFFER)));
    }
    let centres: Vec<[f32; 3]> = (0..positions.len()).map(|v| mesh.centre_of_rotation(v).to_array()).collect();
    attributes[CENTRE_OF_ROTATION] = json!(glb.floats(&centres, "VEC3", Some(ARRAY_BUFFER)));
    let sets = if mesh.max_influences() > 4 { 2 } else { 1 };
    for set in 0..sets {
        let mut joints = Vec::with_capacity(positions.len() * 8);
        let mut weights = Vec::with_capacity(positions.len() * 4);
        for v in 0..positions.len() {
            let infl: Vec<(usize, f32)> = mesh.influences(v).skip(set * 4).take(4).collect();
            for s in 0..4 {
                let (j, w) = infl.get(s).copied().unwrap_or((0, 0.0));
                joints.extend_from_slice(&(j as u16).to_le_bytes());
                weights.push(w);
            }
        }
        let ja = glb.accessor(&joints, positions.len(), UNSIGNED_SHORT, "VEC4", Some(ARRAY_BUFFER), None);
        let wa = glb.floats(&weights.chunks_exact(4).map(|c| [c[0], c[1], c[2], c[3]]).collect::<Vec<_>>(), "VEC4", Some(ARRAY_BUFFER));
        attributes[format!("JOINTS_{set}")] = json!(ja);
        attributes[format!("WEIGHTS_{set}")] = json!(wa);
    }
    // One primitive per region of the skin over the same vertices, or one for the whole mesh.
    let appearance = model.appearance.as_deref().filter(|a| !mesh.uvs().is_empty() && a.covers(mesh.indices().len()));
    let primitives: Vec<Value> = match appearance {
        Some(a) => a
            .regions
            .iter()
            .filter(|(_, r)| !r.is_empty())
            .map(|(region, r)| json!({ "attributes": attributes, "indices": glb.indices(&mesh.indices()[r.clone()]), "material": SurfaceRegion::ALL.iter().position(|x| x == region) }))
            .collect(),
        None => vec![json!({ "attributes": attributes, "indices": glb.indices(mesh.indices()), "material": 0 })],
    };
    let looks = appearance.map(|a| appearance_materials(&mut glb, a));
    let ibm: Vec<[f32; 16]> = mesh.inverse_bind().iter().map(|m| glam::Mat4::from(*m).to_cols_array()).collect();
    let ibm = glb.floats(&ibm, "MAT4", None);

    let joints = skeleton.joints();
    #[cfg(feature = "interaction")]
    let proxies = crate::collision::fit_proxies(model, crate::collision::PROXY_MARGIN);
    let mut nodes: Vec<Value> = joints
        .iter()
        .enumerate()
        .map(|(i, j)| {
            let mut node = json!({
                "name": j.name,
                "translation": j.rest.translation.to_array(),
                "rotation": j.rest.rotation.to_array(),
            });
            if j.rest.scale != glam::Vec3::ONE {
                node["scale"] = json!(j.rest.scale.to_array());
            }
            let children: Vec<usize> = (0..joints.len()).filter(|&c| joints[c].parent == Some(i)).collect();
            if !children.is_empty() {
                node["children"] = json!(children);
            }
            #[cfg(feature = "interaction")]
            if let Some(proxy) = proxies.iter().find(|p| p.joint == i) {
                node["extras"] = json!({ "dqhand_collision": proxy_json(&proxy.shape) });
            }
            node
        })
        .collect();
    let mesh_node = nodes.len();
    nodes.push(json!({ "name": "hand", "mesh": 0, "skin": 0 }));
    let mut roots: Vec<usize> = (0..joints.len()).filter(|&i| joints[i].parent.is_none()).collect();
    roots.push(mesh_node);
    let mut doc = json!({
        "scene": 0,
        "scenes": [{ "nodes": roots }],
        "nodes": nodes,
        // The model's description as the mesh's name: a loader shows what the file holds.
        "meshes": [{ "name": model.description, "primitives": primitives }],
        "materials": skin_material(),
        "skins": [{ "name": "hand", "inverseBindMatrices": ibm, "joints": (0..joints.len()).collect::<Vec<_>>(), "skeleton": roots[0] }],
    });
    if let Some(Value::Object(looks)) = looks {
        doc.as_object_mut().expect("an object").extend(looks);
        doc["extensionsUsed"] = json!(["KHR_materials_clearcoat", "KHR_materials_sheen"]);
    }
    glb.finish(doc)
}

#[cfg(feature = "interaction")]
fn proxy_json(shape: &ProxyShape) -> Value {
    match shape {
        ProxyShape::Capsule { start, end, radius } => {
            json!({ "capsule": { "start": start.to_array(), "end": end.to_array(), "radius": radius } })
        }
        ProxyShape::ConvexHull { points, triangles } => {
            let points: Vec<[f32; 3]> = points.iter().map(|p| p.to_array()).collect();
            json!({ "convex_hull": { "points": points, "triangles": triangles } })
        }
    }
}

/// Writes a posed static mesh (positions, normals, texture coordinates if any) as GLB.
///
/// * `positions`, `normals` — #V; `uvs` — #V or empty; `indices` — #F × 3.
///
/// # Errors
/// [`crate::Error::Io`] if the file cannot be written; [`crate::Error::Mesh`] if the
/// array lengths disagree.
pub fn write_posed_glb(path: &Path, positions: &[[f32; 3]], normals: &[[f32; 3]], uvs: &[[f32; 2]], indices: &[u32]) -> Result<()> {
    check_lengths(positions, normals, indices)?;
    let mut glb = Glb::default();
    let mut attributes = json!({
        "POSITION": glb.positions(positions),
        "NORMAL": glb.floats(normals, "VEC3", Some(ARRAY_BUFFER)),
    });
    if uvs.len() == positions.len() {
        attributes["TEXCOORD_0"] = json!(glb.floats(uvs, "VEC2", Some(ARRAY_BUFFER)));
    }
    let indices = glb.indices(indices);
    let doc = json!({
        "scene": 0,
        "scenes": [{ "nodes": [0] }],
        "nodes": [{ "name": "posed hand", "mesh": 0 }],
        "meshes": [{ "name": "posed hand", "primitives": [{ "attributes": attributes, "indices": indices, "material": 0 }] }],
        "materials": skin_material(),
    });
    write_bytes(path, &glb.finish(doc))
}
