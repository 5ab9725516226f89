//! Files: glTF export and re-import of the built-in hand, the WebXR generic hand, the PLY, OBJ
//! and GLB writers, malformed glTF input, and pose files.

mod support;

use std::path::{Path, PathBuf};

use dqhand::io::{self, PoseFile};
use dqhand::kinematics::{webxr, Limits, PoseTarget};
use dqhand::model::Model;
use dqhand::skin::{Deformed, Deformer, Method};
use dqhand::Error;
use glam::{Mat4, Quat, Vec3, Vec4};
use serde_json::{json, Value};

// ---------------------------------------------------------------------------------------------
// Helpers
// ---------------------------------------------------------------------------------------------

/// A fresh, empty directory for one test: the process id and the test name keep parallel
/// tests and concurrent runs apart.
fn temp_dir(test: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("dqhand-io-{}-{test}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("create temp dir");
    dir
}

fn builtin() -> Model {
    dqhand::hand::build(&Default::default()).expect("built-in hand builds")
}

/// The built-in hand written as a rigged GLB into `dir`; returns the model and the file.
fn exported_builtin(dir: &Path) -> (Model, PathBuf) {
    let model = builtin();
    let path = dir.join("hand.glb");
    io::write_skinned_glb(&model, &path).expect("export the built-in hand");
    (model, path)
}

fn pose_file(value: Value) -> PoseFile {
    serde_json::from_value(value).expect("a well-formed pose file")
}

/// Poses `model` with `target` and deforms it with `method`; returns positions and the
/// clamping warnings.
fn deform_with(model: &Model, target: &PoseTarget, limits: Limits, method: Method) -> (Vec<[f32; 3]>, Vec<dqhand::kinematics::ClampedAngle>) {
    let (skinning, warnings) = support::pose_skinning(model, target, limits).expect("pose the model");
    let mut out = Deformed::new(&model.mesh);
    Deformer::new(method, &model.mesh).deform(&model.mesh, &skinning, &mut out);
    (out.positions().to_vec(), warnings)
}

/// DQB positions of `model` posed by `pose` (anatomical limits).
fn dqb(model: &Model, pose: &PoseFile) -> Vec<[f32; 3]> {
    let target = pose.resolve(&model.skeleton).expect("resolve the pose");
    deform_with(model, &target, Limits::Anatomical, Method::Dqb).0
}

fn distance(a: [f32; 3], b: [f32; 3]) -> f32 {
    Vec3::from(a).distance(Vec3::from(b))
}

/// The largest distance between corresponding points of `a` and `b` over the vertices `of`.
fn max_moved(a: &[[f32; 3]], b: &[[f32; 3]], of: &[usize]) -> f32 {
    of.iter().map(|&v| distance(a[v], b[v])).fold(0.0, f32::max)
}

fn all_vertices(model: &Model) -> Vec<usize> {
    (0..model.mesh.vertex_count()).collect()
}

/// The vertices whose heaviest influence is a joint whose name satisfies `pick`.
fn vertices_bound_to(model: &Model, pick: impl Fn(&str) -> bool) -> Vec<usize> {
    let names: Vec<&str> = model.skeleton.names().collect();
    (0..model.mesh.vertex_count())
        .filter(|&v| model.mesh.influences(v).next().is_some_and(|(j, _)| pick(names[j])))
        .collect()
}

/// The influences of vertex `v`, heaviest first.
fn influences(model: &Model, v: usize) -> Vec<(usize, f32)> {
    model.mesh.influences(v).collect()
}

/// Loads `path` expecting an error; checks that loading does not panic and that the message
/// names the file and contains every one of `problem` (case-insensitive). Returns the message.
fn expect_load_error(path: &Path, problem: &[&str]) -> String {
    let result = std::panic::catch_unwind(|| io::load_gltf(path));
    let result = result.unwrap_or_else(|_| panic!("loading {} panicked instead of returning an error", path.display()));
    let message = match result {
        Ok(_) => panic!("{} loaded, but it is malformed", path.display()),
        Err(e) => e.to_string(),
    };
    assert!(message.contains(&path.display().to_string()), "error does not name the file {}: {message}", path.display());
    for word in problem {
        assert!(message.to_lowercase().contains(&word.to_lowercase()), "error does not say {word:?}: {message}");
    }
    message
}

// ---------------------------------------------------------------------------------------------
// A minimal skinned glTF with injectable faults
// ---------------------------------------------------------------------------------------------

/// What to break in the minimal glTF.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Fault {
    /// Nothing: a valid file.
    None,
    /// The primitive has no POSITION attribute.
    NoPosition,
    /// Vertex 2 is bound to joint 7 of a two-joint skin.
    JointOutOfRange,
    /// Vertex 1 has all weights zero.
    ZeroWeights,
    /// Vertex 3 has a NaN coordinate.
    NanPosition,
    /// The `tip` joint's inverse bind matrix is all zeros.
    ZeroInverseBind,
    /// An affine inverse bind matrix whose linear part is zero.
    SingularInverseBind,
    /// The last buffer view (the inverse bind matrices) ends 64 bytes past the buffer.
    ViewPastEnd,
    /// Vertex 0's weights sum to 0.7.
    UnnormalisedWeights,
    /// JOINTS_0 stored as floats, which glTF does not allow.
    JointsAsFloats,
    /// POSITION declared VEC2.
    PositionAsVec2,
    /// POSITION with `count` 0.
    ZeroCount,
    /// POSITION with a `count` whose byte size overflows 64 bits.
    HugeCount,
    /// An application's own attribute `_BATCHID` (glTF allows names starting with `_`).
    ForeignAttribute,
    /// The CoR centres of rotation, given (one per vertex).
    Centres,
    /// The CoR centres of rotation declared VEC2.
    CentresAsVec2,
    /// The CoR centres of rotation, one short of the vertices.
    CentresShort,
}

const FLOAT: u32 = 5126;
const UNSIGNED_SHORT: u32 = 5123;

/// The binary buffer of a glTF being built, with its views and accessors.
#[derive(Default)]
struct Bin {
    bytes: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
}

impl Bin {
    /// Appends `bytes` as a view with one accessor over it; returns the accessor index.
    fn accessor(&mut self, bytes: Vec<u8>, count: usize, component: u32, kind: &str) -> usize {
        while self.bytes.len() % 4 != 0 {
            self.bytes.push(0);
        }
        self.views.push(json!({ "buffer": 0, "byteOffset": self.bytes.len(), "byteLength": bytes.len() }));
        self.bytes.extend(bytes);
        self.accessors.push(json!({ "bufferView": self.views.len() - 1, "componentType": component, "count": count, "type": kind }));
        self.accessors.len() - 1
    }

    fn floats<const N: usize>(&mut self, data: &[[f32; N]], kind: &str) -> usize {
        let bytes = data.iter().flatten().flat_map(|f| f.to_le_bytes()).collect();
        self.accessor(bytes, data.len(), FLOAT, kind)
    }

    fn shorts<const N: usize>(&mut self, data: &[[u16; N]], kind: &str) -> usize {
        let bytes = data.iter().flatten().flat_map(|f| f.to_le_bytes()).collect();
        self.accessor(bytes, data.len(), UNSIGNED_SHORT, kind)
    }
}

/// Writes `model.gltf` and `model.bin` into `dir`: a unit quad (two triangles) skinned to two
/// joints, `root` and its child `tip`, its lower edge on `root` and its upper edge on `tip`,
/// with `fault` injected. Returns the `.gltf` path.
fn minimal_gltf(dir: &Path, fault: Fault) -> PathBuf {
    let mut positions = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]];
    let mut joints: Vec<[u16; 4]> = vec![[0, 0, 0, 0], [0, 0, 0, 0], [1, 0, 0, 0], [1, 0, 0, 0]];
    let mut weights: Vec<[f32; 4]> = vec![[1.0, 0.0, 0.0, 0.0]; 4];
    let mut inverse_bind = [Mat4::IDENTITY, Mat4::from_translation(Vec3::new(0.0, -0.5, 0.0))];
    match fault {
        Fault::JointOutOfRange => joints[2] = [7, 0, 0, 0],
        Fault::ZeroWeights => weights[1] = [0.0; 4],
        Fault::NanPosition => positions[3][1] = f32::NAN,
        Fault::ZeroInverseBind => inverse_bind[1] = Mat4::ZERO,
        Fault::SingularInverseBind => inverse_bind[1] = Mat4::from_cols(Vec4::ZERO, Vec4::ZERO, Vec4::ZERO, Vec4::W),
        Fault::UnnormalisedWeights => (joints[0], weights[0]) = ([0, 1, 0, 0], [0.5, 0.2, 0.0, 0.0]),
        _ => {}
    }

    let mut bin = Bin::default();
    let joints = if fault == Fault::JointsAsFloats {
        bin.floats(&joints.iter().map(|j| j.map(f32::from)).collect::<Vec<_>>(), "VEC4")
    } else {
        bin.shorts(&joints, "VEC4")
    };
    let mut attributes = json!({ "JOINTS_0": joints, "WEIGHTS_0": bin.floats(&weights, "VEC4") });
    if fault != Fault::NoPosition {
        let position = bin.floats(&positions, "VEC3");
        // glTF requires bounds on POSITION; NaN is skipped by f32::min/max.
        let bound = |pick: fn(f32, f32) -> f32, start: f32| {
            (0..3).map(|c| positions.iter().map(|p| p[c]).fold(start, pick)).collect::<Vec<_>>()
        };
        bin.accessors[position]["min"] = json!(bound(f32::min, f32::INFINITY));
        bin.accessors[position]["max"] = json!(bound(f32::max, f32::NEG_INFINITY));
        attributes["POSITION"] = json!(position);
    }
    let centres = [[0.5f32, 0.25, 0.0]; 4];
    match fault {
        Fault::ForeignAttribute => attributes["_BATCHID"] = json!(bin.floats(&[[0.0f32]; 4], "SCALAR")),
        Fault::Centres => attributes[io::CENTRE_OF_ROTATION] = json!(bin.floats(&centres, "VEC3")),
        Fault::CentresAsVec2 => attributes[io::CENTRE_OF_ROTATION] = json!(bin.floats(&[[0.5f32, 0.25]; 4], "VEC2")),
        Fault::CentresShort => attributes[io::CENTRE_OF_ROTATION] = json!(bin.floats(&centres[1..], "VEC3")),
        _ => {}
    }
    let indices = bin.shorts(&[0u16, 1, 2, 0, 2, 3].map(|i| [i]), "SCALAR");
    let ibm = bin.floats(&inverse_bind.map(|m| m.to_cols_array()), "MAT4");
    let position = attributes["POSITION"].as_u64().map(|i| &mut bin.accessors[i as usize]);
    match (fault, position) {
        (Fault::ViewPastEnd, _) => {
            let view = bin.views.last_mut().unwrap();
            view["byteLength"] = json!(view["byteLength"].as_u64().unwrap() + 64);
        }
        (Fault::PositionAsVec2, Some(p)) => p["type"] = json!("VEC2"),
        (Fault::ZeroCount, Some(p)) => p["count"] = json!(0),
        (Fault::HugeCount, Some(p)) => p["count"] = json!((1u64 << 62) + 1),
        _ => {}
    }

    let doc = json!({
        "asset": { "version": "2.0" },
        "scene": 0,
        "scenes": [{ "nodes": [0, 2] }],
        "nodes": [
            { "name": "root", "children": [1] },
            { "name": "tip", "translation": [0.0, 0.5, 0.0] },
            { "name": "quad", "mesh": 0, "skin": 0 },
        ],
        "meshes": [{ "name": "quad", "primitives": [{ "attributes": attributes, "indices": indices }] }],
        "skins": [{ "joints": [0, 1], "inverseBindMatrices": ibm }],
        "buffers": [{ "uri": "model.bin", "byteLength": bin.bytes.len() }],
        "bufferViews": bin.views,
        "accessors": bin.accessors,
    });
    let path = dir.join("model.gltf");
    std::fs::write(dir.join("model.bin"), &bin.bytes).expect("write model.bin");
    std::fs::write(&path, serde_json::to_string_pretty(&doc).unwrap()).expect("write model.gltf");
    path
}

/// Writes the minimal glTF with `fault` into a fresh directory named after `test`.
fn faulty_gltf(test: &str, fault: Fault) -> PathBuf {
    minimal_gltf(&temp_dir(test), fault)
}

// ---------------------------------------------------------------------------------------------
// Round trip of the built-in hand
// ---------------------------------------------------------------------------------------------

/// Asserts that `loaded` is `original` written and read back: same vertices in the same order,
/// triangles, normals, influences, joints and inverse bind matrices.
fn assert_same_model(original: &Model, loaded: &Model) {
    assert!(loaded.warnings.is_empty(), "warnings on re-import: {:?}", loaded.warnings);
    let (a, b) = (&original.mesh, &loaded.mesh);
    assert_eq!(b.vertex_count(), a.vertex_count());
    assert_eq!(b.indices(), a.indices());
    for v in 0..a.vertex_count() {
        assert!(a.position(v).distance(b.position(v)) <= 1e-6, "vertex {v} moved: {} vs {}", a.position(v), b.position(v));
        assert!(a.normal(v).distance(b.normal(v)) <= 1e-5, "normal of vertex {v} changed");
        let (ia, ib) = (influences(original, v), influences(loaded, v));
        assert_eq!(ia.len(), ib.len(), "vertex {v}: influences {ia:?} vs {ib:?}");
        for ((ja, wa), (jb, wb)) in ia.iter().zip(&ib) {
            assert!(ja == jb && (wa - wb).abs() <= 1e-6, "vertex {v}: influences {ia:?} vs {ib:?}");
        }
    }
    assert_eq!(b.uvs().len(), a.uvs().len());
    // CoR's centres ride in the file: read, not computed again, and the same.
    assert!(b.has_centres_of_rotation(), "the centres of rotation were not read");
    for v in 0..a.vertex_count() {
        assert_eq!(a.centre_of_rotation(v), b.centre_of_rotation(v), "centre of rotation of vertex {v}");
    }

    let joints = |m: &Model| m.skeleton.joints().iter().map(|j| (j.name.clone(), j.parent)).collect::<Vec<_>>();
    assert_eq!(joints(loaded), joints(original));
    for (j, (ma, mb)) in a.inverse_bind().iter().zip(b.inverse_bind()).enumerate() {
        assert!(ma.abs_diff_eq(*mb, 1e-6), "inverse bind matrix of joint {j} changed");
    }
}

#[test]
fn builtin_glb_round_trip_keeps_mesh_and_skeleton() {
    let (original, path) = exported_builtin(&temp_dir("round-trip-mesh"));
    let loaded = io::load_gltf(&path).expect("re-import the exported hand");
    assert_same_model(&original, &loaded);
    // The file says what it holds: the description rides in the mesh's name.
    let file = path.file_name().unwrap().to_string_lossy();
    assert_eq!(loaded.description, format!("{} (glTF file {file})", original.description));
}

#[test]
fn builtin_glb_round_trip_poses_the_same() {
    let (original, path) = exported_builtin(&temp_dir("round-trip-pose"));
    let loaded = io::load_gltf(&path).expect("re-import the exported hand");
    let pose = pose_file(json!({
        "wrist": { "translation": [0.1, -0.2, 0.05], "rotation": [0.0, 0.3826834, 0.0, 0.9238795] },
        "angles_deg": {
            "index-finger-phalanx-proximal.flex": 45,
            "index-finger-phalanx-intermediate.flex": 90,
            "middle-finger-phalanx-proximal.abd": 10,
            "thumb-metacarpal.flex": 30,
            "pinky-finger-phalanx-distal.flex": 60,
        },
    }));
    let (a, b) = (dqb(&original, &pose), dqb(&loaded, &pose));
    let moved = max_moved(&a, &b, &all_vertices(&original));
    assert!(moved <= 1e-5, "posed re-imported hand differs by {moved} m");
    // The pose really moved the hand.
    let rest = original.mesh.positions();
    assert!(max_moved(&a, &rest, &all_vertices(&original)) > 0.01);
}

// ---------------------------------------------------------------------------------------------
// Posed mesh writers
// ---------------------------------------------------------------------------------------------

/// Writes the built-in hand's rest mesh with `write_posed` to `dir/hand.<ext>`.
fn write_posed_builtin(dir: &Path, ext: &str) -> (Model, PathBuf) {
    let model = builtin();
    let path = dir.join(format!("hand.{ext}"));
    let m = &model.mesh;
    io::write_posed(&path, &m.positions(), &m.normals(), m.uvs(), m.indices()).expect("write the posed mesh");
    (model, path)
}

/// The number in a PLY header line `element <what> <n>`.
fn ply_count(header: &str, what: &str) -> usize {
    let prefix = format!("element {what} ");
    let line = header.lines().find_map(|l| l.strip_prefix(&prefix)).unwrap_or_else(|| panic!("no {prefix:?} line in {header}"));
    line.trim().parse().expect("element count")
}

#[test]
fn write_posed_ply_has_consistent_header_and_size() {
    let (model, path) = write_posed_builtin(&temp_dir("ply"), "ply");
    let bytes = std::fs::read(&path).unwrap();
    let end = b"end_header\n";
    let header_len = bytes.windows(end.len()).position(|w| w == end).expect("end_header") + end.len();
    let header = std::str::from_utf8(&bytes[..header_len]).expect("ASCII header");
    assert!(header.starts_with("ply\nformat binary_little_endian 1.0\n"), "{header}");
    let (vertices, faces) = (ply_count(header, "vertex"), ply_count(header, "face"));
    assert_eq!(vertices, model.mesh.vertex_count());
    assert_eq!(faces, model.mesh.triangle_count());
    // Six floats per vertex; per face one count byte and three u32 indices.
    assert_eq!(bytes.len(), header_len + vertices * 24 + faces * 13);
    let first = |c: usize| f32::from_le_bytes(bytes[header_len + 4 * c..][..4].try_into().unwrap());
    assert_eq!([first(0), first(1), first(2)], model.mesh.positions()[0]);
}

#[test]
fn write_posed_obj_has_one_line_per_element() {
    let (model, path) = write_posed_builtin(&temp_dir("obj"), "obj");
    let text = std::fs::read_to_string(&path).unwrap();
    let count = |prefix: &str| text.lines().filter(|l| l.starts_with(prefix)).count();
    assert_eq!(count("v "), model.mesh.vertex_count());
    assert_eq!(count("vn "), model.mesh.vertex_count());
    assert_eq!(count("f "), model.mesh.triangle_count());
    let n = model.mesh.vertex_count();
    for line in text.lines().filter(|l| l.starts_with("f ")) {
        for corner in line.split_whitespace().skip(1) {
            let (v, vn) = corner.split_once("//").expect("f v//vn");
            assert_eq!(v, vn);
            let v: usize = v.parse().unwrap();
            assert!((1..=n).contains(&v), "OBJ index {v} out of 1..={n}");
        }
    }
}

#[test]
fn write_posed_glb_parses_with_all_vertices() {
    let (model, path) = write_posed_builtin(&temp_dir("glb"), "glb");
    let bytes = std::fs::read(&path).unwrap();
    let gltf = gltf::Gltf::from_slice(&bytes).expect("a valid GLB");
    let prim = gltf.meshes().next().expect("a mesh").primitives().next().expect("a primitive");
    let position = prim.get(&gltf::Semantic::Positions).expect("POSITION");
    assert_eq!(position.count(), model.mesh.vertex_count());
    assert_eq!(prim.indices().expect("indices").count(), model.mesh.indices().len());
}

#[test]
fn write_posed_rejects_unknown_extension() {
    let dir = temp_dir("unknown-ext");
    let m = builtin().mesh;
    for name in ["hand.stl", "hand"] {
        let path = dir.join(name);
        let err = io::write_posed(&path, &m.positions(), &m.normals(), m.uvs(), m.indices()).expect_err("unknown format");
        let message = err.to_string();
        assert!(message.contains(&path.display().to_string()) && message.contains(".ply"), "{message}");
        assert!(!path.exists(), "{} was written", path.display());
    }
}

// ---------------------------------------------------------------------------------------------
// The WebXR generic hand
// ---------------------------------------------------------------------------------------------

/// The WebXR generic right hand: `DQHAND_WEBXR_HAND`, else the npm asset under third_party/.
fn webxr_hand() -> Model {
    let path = std::env::var_os("DQHAND_WEBXR_HAND").map_or_else(
        || {
            Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("../../third_party/node_modules/@webxr-input-profiles/assets/dist/profiles/generic-hand/right.glb")
        },
        PathBuf::from,
    );
    assert!(
        path.is_file(),
        "the WebXR generic hand {} is missing: run `make test` (it runs `npm ci` in third_party/), or set DQHAND_WEBXR_HAND",
        path.display()
    );
    io::load_gltf(&path).unwrap_or_else(|e| panic!("load the WebXR generic hand: {e}"))
}

#[test]
fn webxr_hand_loads_with_25_skinned_joints() {
    let model = webxr_hand();
    assert_eq!(model.mesh.vertex_count(), 1360);
    for name in webxr::JOINT_NAMES {
        assert!(model.skeleton.find(name).is_some(), "joint {name} missing");
    }
    // The skin's 25 joints, plus at most their non-skinned ancestors (the armature).
    let per_joint = model.mesh.vertices_per_joint();
    for (j, joint) in model.skeleton.joints().iter().enumerate() {
        if !webxr::JOINT_NAMES.contains(&joint.name.as_str()) {
            assert_eq!(per_joint[j], 0, "non-WebXR node {} has vertices", joint.name);
        }
    }
    assert!(model.mesh.bone_count() <= 25);
}

#[test]
fn webxr_hand_glb_round_trip() {
    let original = webxr_hand();
    let path = temp_dir("webxr-round-trip").join("right.glb");
    io::write_skinned_glb(&original, &path).expect("export the WebXR hand");
    let loaded = io::load_gltf(&path).expect("re-import it");
    assert_same_model(&original, &loaded);
    let pose = pose_file(json!({ "angles_deg": { "index-finger-phalanx-intermediate.flex": 90, "thumb-metacarpal.abd": 30 } }));
    let moved = max_moved(&dqb(&original, &pose), &dqb(&loaded, &pose), &all_vertices(&original));
    assert!(moved <= 1e-5, "posed re-imported hand differs by {moved} m");
}

#[test]
fn webxr_hand_bones_run_along_local_minus_z() {
    let model = webxr_hand();
    let world = model.skeleton.rest_world();
    let at = |name: &str| world[model.skeleton.find(name).expect("WebXR joint")];
    for pair in webxr::JOINT_NAMES[1..].windows(2) {
        let (joint, next) = (pair[0], pair[1]);
        if webxr::is_tip(joint) {
            continue;
        }
        let (m, n) = (at(joint), at(next));
        let along = Vec3::from(n.translation - m.translation);
        let minus_z = -Vec3::from(m.matrix3.z_axis);
        let angle = along.angle_between(minus_z).to_degrees();
        assert!(angle < 25.0, "{next} lies {angle:.1}° off {joint}'s −Z axis");
    }
}

#[test]
fn webxr_hand_flexing_the_index_moves_only_the_index() {
    let model = webxr_hand();
    let rest = dqb(&model, &PoseFile::default());
    let flexed = dqb(&model, &pose_file(json!({ "angles_deg": { "index-finger-phalanx-intermediate.flex": 90 } })));
    let tip = vertices_bound_to(&model, |n| n == "index-finger-phalanx-distal" || n == "index-finger-tip");
    let pinky = vertices_bound_to(&model, |n| n.starts_with("pinky-finger"));
    assert!(!tip.is_empty() && !pinky.is_empty());
    assert!(max_moved(&flexed, &rest, &tip) > 0.01, "the index tip did not move");
    let pinky_moved = max_moved(&flexed, &rest, &pinky);
    assert!(pinky_moved <= 1e-6, "pinky vertices moved by {pinky_moved} m");
}

#[test]
fn webxr_hand_local_rotations_pose_a_node() {
    let model = webxr_hand();
    let joint = "index-finger-phalanx-proximal";
    let rest_rotation = model.skeleton.joints()[model.skeleton.find(joint).unwrap()].rest.rotation;
    let turned = rest_rotation * Quat::from_rotation_x(-1.0);
    let pose = pose_file(json!({ "local_rotations": { joint: turned.to_array() } }));
    let target = pose.resolve(&model.skeleton).expect("resolve node names");
    assert!(matches!(&target, PoseTarget::LocalRotations(r) if r.len() == 1));
    let rest = dqb(&model, &PoseFile::default());
    let posed = deform_with(&model, &target, Limits::Anatomical, Method::Dqb).0;
    let index = vertices_bound_to(&model, |n| n == joint);
    let pinky = vertices_bound_to(&model, |n| n.starts_with("pinky-finger"));
    assert!(max_moved(&posed, &rest, &index) > 0.005, "the rotated node's vertices did not move");
    assert!(max_moved(&posed, &rest, &pinky) <= 1e-6, "pinky vertices moved");
}

#[test]
fn webxr_hand_unknown_node_lists_valid_names() {
    let model = webxr_hand();
    let pose = pose_file(json!({ "local_rotations": { "index-knuckle": [0.0, 0.0, 0.0, 1.0] } }));
    match pose.resolve(&model.skeleton) {
        Err(Error::UnknownName { kind, name, valid }) => {
            assert_eq!(kind, "node");
            assert_eq!(name, "index-knuckle");
            for joint in ["wrist", "index-finger-phalanx-proximal", "pinky-finger-tip"] {
                assert!(valid.contains(joint), "{joint} not among the valid names {valid}");
            }
        }
        other => panic!("expected an unknown node error, got {other:?}"),
    }
}

// ---------------------------------------------------------------------------------------------
// Malformed glTF input
// ---------------------------------------------------------------------------------------------

#[test]
fn minimal_gltf_fixture_loads() {
    let model = io::load_gltf(&faulty_gltf("fixture-ok", Fault::None)).expect("the intact fixture loads");
    assert_eq!(model.mesh.vertex_count(), 4);
    assert_eq!(model.mesh.triangle_count(), 2);
    assert_eq!(model.skeleton.names().collect::<Vec<_>>(), ["root", "tip"]);
    assert_eq!(model.skeleton.joints()[1].parent, Some(0));
    assert!(model.warnings.is_empty(), "{:?}", model.warnings);
    assert_eq!(influences(&model, 2), [(1, 1.0)]);
}

/// The exported built-in hand with its bytes changed by `mangle`.
fn mangled_glb(test: &str, mangle: impl FnOnce(&mut Vec<u8>)) -> PathBuf {
    let (_, path) = exported_builtin(&temp_dir(test));
    let mut bytes = std::fs::read(&path).unwrap();
    mangle(&mut bytes);
    std::fs::write(&path, &bytes).unwrap();
    path
}

fn set_u32(bytes: &mut [u8], at: usize, value: usize) {
    bytes[at..at + 4].copy_from_slice(&u32::try_from(value).unwrap().to_le_bytes());
}

#[test]
fn truncated_glb_cut_in_half_is_an_error() {
    expect_load_error(&mangled_glb("cut-half", |b| b.truncate(b.len() / 2)), &["truncated GLB"]);
}

#[test]
fn truncated_glb_missing_last_100_bytes_is_an_error() {
    expect_load_error(&mangled_glb("cut-100", |b| b.truncate(b.len() - 100)), &["truncated GLB", "bytes of the declared"]);
}

#[test]
fn truncated_glb_with_consistent_chunk_lengths_is_an_error() {
    // Cut the binary chunk short and fix up the container's lengths to match, so that only
    // the declared buffer length tells that data is missing.
    let path = mangled_glb("cut-consistent", |b| {
        b.truncate(b.len() - 100);
        let json_len = u32::from_le_bytes(b[12..16].try_into().unwrap()) as usize;
        let total = b.len();
        set_u32(b, 8, total);
        set_u32(b, 20 + json_len, total - (20 + json_len + 8));
    });
    expect_load_error(&path, &["buffer 0", "truncated"]);
}

#[test]
fn text_file_is_not_a_gltf() {
    let dir = temp_dir("not-gltf");
    for name in ["notes.glb", "notes.gltf"] {
        let path = dir.join(name);
        std::fs::write(&path, "These are not the droids you are looking for.\n").unwrap();
        expect_load_error(&path, &["not a valid glTF"]);
    }
}

#[test]
fn missing_file_is_an_error() {
    let path = temp_dir("missing").join("absent.glb");
    expect_load_error(&path, &[]);
    assert!(matches!(io::load_gltf(&path), Err(Error::Io { .. })));
}

#[test]
fn missing_position_is_an_error() {
    expect_load_error(&faulty_gltf("no-position", Fault::NoPosition), &["POSITION"]);
}

#[test]
fn joint_index_out_of_range_is_an_error() {
    expect_load_error(&faulty_gltf("joint-range", Fault::JointOutOfRange), &["vertex 2", "joint 7", "2 joints"]);
}

#[test]
fn vertex_without_weight_is_an_error() {
    expect_load_error(&faulty_gltf("zero-weights", Fault::ZeroWeights), &["vertex 1", "no positive weight"]);
}

#[test]
fn nan_position_is_an_error() {
    expect_load_error(&faulty_gltf("nan-position", Fault::NanPosition), &["vertex 3", "non-finite position"]);
}

#[test]
fn zero_inverse_bind_matrix_is_an_error() {
    expect_load_error(&faulty_gltf("zero-ibm", Fault::ZeroInverseBind), &["inverse bind matrix", "tip"]);
}

#[test]
fn singular_inverse_bind_matrix_is_an_error() {
    expect_load_error(&faulty_gltf("singular-ibm", Fault::SingularInverseBind), &["inverse bind matrix", "not invertible"]);
}

#[test]
fn buffer_view_past_end_of_buffer_is_an_error() {
    expect_load_error(&faulty_gltf("view-past-end", Fault::ViewPastEnd), &["buffer view", "past the end"]);
}

#[test]
fn joints_stored_as_floats_is_an_error() {
    expect_load_error(&faulty_gltf("joints-float", Fault::JointsAsFloats), &["JOINTS_0"]);
}

#[test]
fn an_applications_own_attribute_is_ignored_and_given_centres_are_kept() {
    let foreign = io::load_gltf(&faulty_gltf("foreign-attribute", Fault::ForeignAttribute)).expect("an attribute named _BATCHID is allowed");
    assert_eq!(foreign.mesh.vertex_count(), 4);
    assert!(!foreign.mesh.has_centres_of_rotation(), "none in the file: computed when first used");
    let given = io::load_gltf(&faulty_gltf("given-centres", Fault::Centres)).expect("centres of rotation load");
    assert!(given.mesh.has_centres_of_rotation());
    assert_eq!(given.mesh.centre_of_rotation(3).to_array(), [0.5, 0.25, 0.0]);
}

#[test]
fn centres_of_rotation_of_the_wrong_type_or_count_are_an_error() {
    expect_load_error(&faulty_gltf("centres-vec2", Fault::CentresAsVec2), &["_CENTRE_OF_ROTATION"]);
    expect_load_error(&faulty_gltf("centres-short", Fault::CentresShort), &["_CENTRE_OF_ROTATION", "count"]);
}

#[test]
fn position_of_the_wrong_type_is_an_error() {
    expect_load_error(&faulty_gltf("position-vec2", Fault::PositionAsVec2), &["POSITION"]);
}

#[test]
fn accessor_with_zero_count_is_an_error() {
    expect_load_error(&faulty_gltf("zero-count", Fault::ZeroCount), &["accessor", "no elements"]);
}

#[test]
fn accessor_with_overflowing_count_is_an_error() {
    expect_load_error(&faulty_gltf("huge-count", Fault::HugeCount), &["accessor"]);
}

#[test]
fn unnormalised_weights_load_with_a_warning() {
    let model = io::load_gltf(&faulty_gltf("unnormalised", Fault::UnnormalisedWeights)).expect("loads");
    assert!(model.warnings.contains(&dqhand::Warning::WeightsRenormalised { vertices: 1 }), "warnings: {:?}", model.warnings);
    let inf = influences(&model, 0);
    assert_eq!(inf.len(), 2, "{inf:?}");
    assert_eq!((inf[0].0, inf[1].0), (0, 1));
    assert!((inf[0].1 - 5.0 / 7.0).abs() < 1e-6 && (inf[1].1 - 2.0 / 7.0).abs() < 1e-6, "{inf:?}");
}

// ---------------------------------------------------------------------------------------------
// Pose files
// ---------------------------------------------------------------------------------------------

#[test]
fn pose_file_unknown_dof_lists_valid_names() {
    let pose = pose_file(json!({ "angles_deg": { "index-finger-knuckle.flex": 30 } }));
    match pose.resolve(&builtin().skeleton) {
        Err(e @ Error::UnknownName { .. }) => {
            let message = e.to_string();
            for part in ["degree of freedom", "index-finger-knuckle.flex", "index-finger-phalanx-intermediate.flex", "thumb-metacarpal.abd"] {
                assert!(message.contains(part), "{part:?} not in {message}");
            }
        }
        other => panic!("expected an unknown DOF error, got {other:?}"),
    }
}

#[test]
fn pose_file_invalid_json_names_the_file() {
    let path = temp_dir("pose-json").join("broken.pose.json");
    std::fs::write(&path, "{ \"angles_deg\": { \"index-finger-phalanx-proximal.flex\": 30, } ").unwrap();
    let message = PoseFile::load(&path).expect_err("invalid JSON").to_string();
    assert!(message.contains(&path.display().to_string()) && message.contains("not a valid pose file"), "{message}");
}

#[test]
fn pose_file_unknown_field_is_an_error() {
    let path = temp_dir("pose-field").join("typo.pose.json");
    std::fs::write(&path, r#"{ "angle_deg": { "index-finger-phalanx-proximal.flex": 30 } }"#).unwrap();
    let message = PoseFile::load(&path).expect_err("unknown field").to_string();
    assert!(message.contains(&path.display().to_string()) && message.contains("angle_deg"), "{message}");
}

#[test]
fn pose_file_mixing_angles_and_local_rotations_is_an_error() {
    let pose = pose_file(json!({
        "angles_deg": { "index-finger-phalanx-proximal.flex": 30 },
        "local_rotations": { "wrist": [0.0, 0.0, 0.0, 1.0] },
    }));
    let message = pose.resolve(&builtin().skeleton).expect_err("mixed pose").to_string();
    assert!(message.contains("local_rotations") && message.contains("angles_deg"), "{message}");
}

#[test]
fn pose_file_round_trips_through_json() {
    let path = temp_dir("pose-load").join("ok.pose.json");
    let value = json!({ "model": "full", "angles_deg": { "thumb-metacarpal.flex": 20, "index-finger-phalanx-proximal.flex": 30 } });
    std::fs::write(&path, value.to_string()).unwrap();
    assert_eq!(PoseFile::load(&path).expect("valid pose file"), pose_file(value));
}

#[test]
fn angle_beyond_limits_is_clamped_only_with_anatomical_limits() {
    let model = builtin();
    let dof = "index-finger-phalanx-intermediate.flex"; // 0..110 degrees
    let target = |deg: f32| pose_file(json!({ "angles_deg": { dof: deg } })).resolve(&model.skeleton).expect("resolve");
    let run = |deg: f32, limits: Limits| deform_with(&model, &target(deg), limits, Method::Dqb);

    let (clamped, warnings) = run(150.0, Limits::Anatomical);
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    assert!(warnings[0].dof == dof && warnings[0].to_string().contains("clamped"), "{warnings:?}");
    let (at_limit, no_warnings) = run(110.0, Limits::Anatomical);
    assert!(no_warnings.is_empty(), "{no_warnings:?}");
    let all = all_vertices(&model);
    assert!(max_moved(&clamped, &at_limit, &all) <= 1e-6, "clamped pose differs from the pose at the limit");

    let (free, free_warnings) = run(150.0, Limits::Off);
    assert!(free_warnings.is_empty(), "{free_warnings:?}");
    assert!(max_moved(&free, &clamped, &all) > 0.005, "Limits::Off clamped the angle");
}

#[test]
fn primitives_over_the_same_attributes_share_their_vertices() {
    // The minimal quad with its primitive listed twice, plus a second mesh node on the same
    // skin: 3 primitives over the same 4 vertices (one mesh in several materials, as dqhand
    // writes the built-in hand), their triangles kept in file order.
    let path = faulty_gltf("multi-primitive", Fault::None);
    let mut doc: Value = serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    let primitive = doc["meshes"][0]["primitives"][0].clone();
    doc["meshes"][0]["primitives"].as_array_mut().unwrap().push(primitive.clone());
    doc["meshes"].as_array_mut().unwrap().push(json!({ "name": "second", "primitives": [primitive] }));
    doc["nodes"].as_array_mut().unwrap().push(json!({ "name": "quad2", "mesh": 1, "skin": 0 }));
    doc["scenes"][0]["nodes"].as_array_mut().unwrap().push(json!(3));
    std::fs::write(&path, serde_json::to_string(&doc).unwrap()).unwrap();

    let model = io::load_gltf(&path).unwrap();
    let single = io::load_gltf(&faulty_gltf("single-primitive", Fault::None)).unwrap();
    assert_eq!(model.mesh.vertex_count(), 4);
    assert_eq!(model.mesh.triangle_count(), 6);
    let parts: Vec<_> = model.mesh.parts().iter().map(|p| (p.name.as_str(), p.vertices.clone(), p.indices.clone())).collect();
    assert_eq!(parts, vec![("quad", 0..4, 0..6), ("quad", 0..4, 6..12), ("second", 0..4, 12..18)]);
    for v in 0..4 {
        assert_eq!(model.mesh.position(v), single.mesh.position(v));
        assert_eq!(influences(&model, v), influences(&single, v));
    }
    // Each primitive's indices are its own, over the shared vertices.
    assert_eq!(&model.mesh.indices()[12..18], &single.mesh.indices()[..6]);
}

#[test]
fn primitives_over_their_own_attributes_are_concatenated_in_file_order() {
    // The quad again, over a copy of its POSITION accessor: its own vertices, after the first's.
    let path = faulty_gltf("copied-primitive", Fault::None);
    let mut doc: Value = serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    let mut primitive = doc["meshes"][0]["primitives"][0].clone();
    let position = primitive["attributes"]["POSITION"].as_u64().unwrap() as usize;
    let copy = doc["accessors"][position].clone();
    doc["accessors"].as_array_mut().unwrap().push(copy);
    primitive["attributes"]["POSITION"] = json!(doc["accessors"].as_array().unwrap().len() - 1);
    doc["meshes"][0]["primitives"].as_array_mut().unwrap().push(primitive);
    std::fs::write(&path, serde_json::to_string(&doc).unwrap()).unwrap();

    let model = io::load_gltf(&path).unwrap();
    let single = io::load_gltf(&faulty_gltf("single-primitive", Fault::None)).unwrap();
    assert_eq!(model.mesh.vertex_count(), 8);
    let parts: Vec<_> = model.mesh.parts().iter().map(|p| (p.vertices.clone(), p.indices.clone())).collect();
    assert_eq!(parts, vec![(0..4, 0..6), (4..8, 6..12)]);
    for v in 0..8 {
        assert_eq!(model.mesh.position(v), single.mesh.position(v % 4));
    }
    // The second primitive's indices are offset to its own vertices.
    let offset: Vec<u32> = single.mesh.indices()[..6].iter().map(|i| i + 4).collect();
    assert_eq!(&model.mesh.indices()[6..12], &offset[..]);
}

/// The minimal glTF with `edit` applied to its JSON; returns the path.
fn edited_gltf(test: &str, edit: impl FnOnce(&mut Value)) -> PathBuf {
    let path = faulty_gltf(test, Fault::None);
    let mut doc: Value = serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    edit(&mut doc);
    std::fs::write(&path, serde_json::to_string(&doc).unwrap()).unwrap();
    path
}

#[test]
fn a_mesh_without_hand_joints_poses_at_rest_from_an_empty_pose_file() {
    let model = io::load_gltf(&faulty_gltf("rest-no-hand", Fault::None)).unwrap();
    let out = dqb(&model, &PoseFile::default());
    for v in 0..model.mesh.vertex_count() {
        assert!(Vec3::from(out[v]).distance(model.mesh.position(v)) < 1e-6);
    }
}

#[test]
fn primitives_with_four_and_eight_influences_load_together() {
    let path = edited_gltf("mixed-sets", |doc| {
        let mut eight = doc["meshes"][0]["primitives"][0].clone();
        let attributes = &mut eight["attributes"];
        attributes["JOINTS_1"] = attributes["JOINTS_0"].clone();
        attributes["WEIGHTS_1"] = attributes["WEIGHTS_0"].clone();
        doc["meshes"][0]["primitives"].as_array_mut().unwrap().push(eight);
    });
    let model = io::load_gltf(&path).unwrap();
    assert_eq!(model.mesh.vertex_count(), 8);
    // The second primitive lists each influence twice: merged into one, the sum of 2
    // normalised with a warning, the same binding as the first primitive's.
    assert!(model.warnings.iter().any(|w| matches!(w, dqhand::Warning::WeightsRenormalised { .. })), "{:?}", model.warnings);
    for v in 0..4 {
        assert_eq!(influences(&model, v + 4), influences(&model, v));
    }
}

#[test]
fn joints_1_without_weights_1_is_an_error() {
    let path = edited_gltf("joints1-only", |doc| {
        let attributes = &mut doc["meshes"][0]["primitives"][0]["attributes"];
        attributes["JOINTS_1"] = attributes["JOINTS_0"].clone();
    });
    expect_load_error(&path, &["only one of JOINTS_1 and WEIGHTS_1"]);
}

#[test]
fn a_zero_node_rotation_is_an_error_and_a_non_unit_one_is_normalised() {
    let zero = edited_gltf("zero-rotation", |doc| doc["nodes"][1]["rotation"] = json!([0.0, 0.0, 0.0, 0.0]));
    expect_load_error(&zero, &["\"tip\"", "not a rotation"]);
    let scaled = edited_gltf("scaled-rotation", |doc| doc["nodes"][1]["rotation"] = json!([0.0, 0.0, 0.0, 2.0]));
    let model = io::load_gltf(&scaled).unwrap();
    assert!(model.warnings.iter().any(|w| matches!(w, dqhand::Warning::RotationNormalised { node, .. } if node.contains("tip"))), "{:?}", model.warnings);
    let tip = model.skeleton.find("tip").unwrap();
    assert!((model.skeleton.joints()[tip].rest.rotation.length() - 1.0).abs() < 1e-6);
}

#[test]
fn duplicate_node_names_are_renamed_with_a_warning() {
    let path = edited_gltf("duplicate-names", |doc| doc["nodes"][1]["name"] = json!("root"));
    let model = io::load_gltf(&path).unwrap();
    assert!(model.skeleton.find("root#1").is_some());
    assert!(model.warnings.iter().any(|w| matches!(w, dqhand::Warning::NodeRenamed { renamed, .. } if renamed == "root#1")), "{:?}", model.warnings);
}

#[test]
fn unused_broken_accessors_do_not_block_loading() {
    // An extra accessor nothing reads (as morph targets or animations would be), sparse and
    // without a buffer view.
    let path = edited_gltf("unused-accessor", |doc| {
        let sparse = json!({ "componentType": 5126, "count": 1, "type": "SCALAR", "sparse": { "count": 1, "indices": { "bufferView": 0, "componentType": 5123 }, "values": { "bufferView": 0 } } });
        doc["accessors"].as_array_mut().unwrap().push(sparse);
    });
    assert_eq!(io::load_gltf(&path).unwrap().mesh.vertex_count(), 4);
}

/// Issue 9 bug 2: a glTF whose nodes are stored in another pose than the one the mesh was
/// bound in (common in exported assets). Collision proxies and the metrics' joint regions
/// relate vertices to joints through the inverse bind matrices, not the node pose, so they
/// come out as for the hand stored in its bind pose.
#[test]
fn proxies_and_joint_regions_are_fitted_in_bind_space_when_the_node_pose_differs() {
    use dqhand::collision::{fit_proxies, ProxyShape, PROXY_MARGIN};
    use dqhand::metrics::JointRegion;
    let dir = temp_dir("bind-pose");
    let (model, _) = exported_builtin(&dir);
    let mut turned = model.clone();
    let pip = turned.skeleton.find("index-finger-phalanx-intermediate").unwrap();
    let mut joints = turned.skeleton.joints().to_vec();
    joints[pip].rest.rotation = joints[pip].rest.rotation * Quat::from_rotation_x(0.6);
    turned.skeleton = dqhand::kinematics::Skeleton::new(joints).unwrap();
    let path = dir.join("turned.glb");
    io::write_skinned_glb(&turned, &path).unwrap();
    let loaded = io::load_gltf(&path).unwrap();
    assert_ne!(loaded.skeleton.rest_world()[pip], model.skeleton.rest_world()[pip], "the node pose differs");
    let radius = |m: &Model, joint: usize| match fit_proxies(m, PROXY_MARGIN).into_iter().find(|p| p.joint == joint).unwrap().shape {
        ProxyShape::Capsule { radius, .. } => radius,
        other => panic!("expected a capsule, got {other:?}"),
    };
    for name in ["index-finger-phalanx-proximal", "index-finger-phalanx-intermediate", "index-finger-phalanx-distal"] {
        let j = model.skeleton.find(name).unwrap();
        assert_close!(radius(&loaded, j), radius(&model, j), 1e-4);
    }
    let region = |m: &Model| {
        JointRegion::new(&m.skeleton, &m.bind_world(), &m.mesh, "index-finger-phalanx-intermediate", "index-finger-phalanx-distal").unwrap()
    };
    let (a, b) = (region(&loaded), region(&model));
    assert_eq!(a.vertices, b.vertices);
    assert_close!(a.radius, b.radius, 1e-5);
}

/// Found by fuzzing: a primitive whose POSITION names a missing accessor made the `gltf`
/// crate's validation index out of bounds and panic; it is an error naming the file.
#[test]
fn a_primitive_with_a_missing_accessor_is_an_error_not_a_panic() {
    for (name, json) in [
        ("position", r#"{"asset":{"version":"2.0"},"meshes":[{"primitives":[{"attributes":{"POSITION":5}}]}],"nodes":[{"mesh":0}]}"#),
        ("indices", r#"{"asset":{"version":"2.0"},"accessors":[],"meshes":[{"primitives":[{"attributes":{},"indices":0}]}]}"#),
    ] {
        let e = io::load_gltf_slice(json.as_bytes(), Path::new("broken.gltf")).unwrap_err().to_string();
        assert!(e.starts_with("broken.gltf: mesh 0 primitive 0: ") && e.contains("uses accessor"), "{name}: {e}");
    }
}

/// Found by fuzzing: a GLB header declaring fewer bytes than the header itself overflowed a
/// subtraction in the `gltf` crate (a panic in debug builds); it is an error naming the file.
#[test]
fn a_glb_declaring_less_than_its_header_is_an_error_not_a_panic() {
    let mut glb = b"glTF".to_vec();
    glb.extend(2u32.to_le_bytes());
    glb.extend(0u32.to_le_bytes());
    glb.extend(b"\x10\0\0\0JSON{\"asset\":{}}  ");
    let e = io::load_gltf_slice(&glb, Path::new("short.glb")).unwrap_err().to_string();
    assert!(e.starts_with("short.glb: GLB header declares 0 bytes"), "{e}");
}

/// The minimal glTF with its buffer's `uri` replaced (the file `model.bin` stays beside it).
fn gltf_with_buffer_uri(test: &str, uri: &str) -> PathBuf {
    let path = faulty_gltf(test, Fault::None);
    let mut doc: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    doc["buffers"][0]["uri"] = json!(uri);
    std::fs::write(&path, doc.to_string()).unwrap();
    path
}

/// A buffer URI reads only a regular file inside the glTF's folder: a device that never ends
/// or never answers, an absolute path, `..` out of the folder (plain, percent-escaped or
/// through a symbolic link), another scheme and a pipe are refused with the URI named, at
/// once.
#[test]
fn buffer_uris_stay_inside_the_models_folder() {
    for (test, uri) in [
        ("uri-dev-zero", "/dev/zero"),
        ("uri-dev-stdin", "/dev/stdin"),
        ("uri-absolute", "/etc/hostname"),
        ("uri-parent", "../model.bin"),
        ("uri-parent-escaped", "%2E%2E/model.bin"),
        ("uri-inner-parent", "sub/../../model.bin"),
        ("uri-scheme", "file:///etc/hostname"),
        ("uri-http", "http://example.com/model.bin"),
        ("uri-bad-escape", "model%zz.bin"),
    ] {
        let path = gltf_with_buffer_uri(test, uri);
        expect_load_error(&path, &["buffer 0", &format!("{uri:?}")]);
    }
    // A symbolic link beside the model that leads out of its folder, and a named pipe.
    let path = gltf_with_buffer_uri("uri-symlink", "link.bin");
    let outside = temp_dir("uri-symlink-target").join("secret.bin");
    std::fs::write(&outside, [0u8; 4096]).unwrap();
    std::os::unix::fs::symlink(&outside, path.with_file_name("link.bin")).unwrap();
    expect_load_error(&path, &["\"link.bin\"", "out of the glTF's folder"]);
    let path = gltf_with_buffer_uri("uri-fifo", "pipe.bin");
    let fifo = path.with_file_name("pipe.bin");
    assert!(std::process::Command::new("mkfifo").arg(&fifo).status().unwrap().success());
    expect_load_error(&path, &["\"pipe.bin\"", "not a regular file"]);
}

/// A buffer file far longer than the buffer's declared length (sparse, 1 GiB) loads (only the
/// declared bytes are read: `gltf_file`'s unit test), and percent-escaped names are decoded.
#[test]
fn buffer_files_longer_than_declared_load_and_escaped_names_decode() {
    let path = gltf_with_buffer_uri("uri-escaped-name", "model%20data.bin");
    let bin = path.with_file_name("model.bin");
    let big = path.with_file_name("model data.bin");
    std::fs::copy(&bin, &big).unwrap();
    std::fs::OpenOptions::new().write(true).open(&big).unwrap().set_len(1 << 30).unwrap();
    io::load_gltf(&path).unwrap();
}

/// A buffer view whose stride is shorter than the elements read through it is refused (the
/// `gltf` crate's reader asserts on it).
#[test]
fn a_stride_shorter_than_an_element_is_an_error() {
    let path = faulty_gltf("short-stride", Fault::None);
    let mut doc: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    for view in doc["bufferViews"].as_array_mut().unwrap() {
        view["byteStride"] = json!(4);
    }
    std::fs::write(&path, doc.to_string()).unwrap();
    expect_load_error(&path, &["stride of 4 bytes"]);
}

/// A lone surrogate escape in a field the `gltf` crate skips unread once hid a dangling
/// POSITION accessor from the check that keeps that crate from panicking (found by fuzzing):
/// such JSON is refused as invalid.
#[test]
fn a_lone_surrogate_does_not_hide_a_dangling_accessor() {
    let dir = temp_dir("lone-surrogate");
    for name in ["surrogate.gltf", "surrogate.glb"] {
        let json = r#"{"asset":{"version":"2.0"},"unknown":"\ud800\u0041","meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}]}"#;
        let bytes = if name.ends_with(".glb") {
            let mut json = json.as_bytes().to_vec();
            json.resize(json.len().next_multiple_of(4), b' ');
            let mut glb = b"glTF".to_vec();
            glb.extend(2u32.to_le_bytes());
            glb.extend(((12 + 8 + json.len()) as u32).to_le_bytes());
            glb.extend((json.len() as u32).to_le_bytes());
            glb.extend(b"JSON");
            glb.extend(json);
            glb
        } else {
            json.as_bytes().to_vec()
        };
        let path = dir.join(name);
        std::fs::write(&path, bytes).unwrap();
        expect_load_error(&path, &["not a valid glTF", "surrogate"]);
    }
}
