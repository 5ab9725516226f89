//! Scene files: a good scene read with its defaults, and every kind of bad input refused
//! with the object and field named (never a panic).

use std::path::Path;

use dqhand::scene::{MeshSource, ObjectMesh, ObjectShape, Scene, SceneCommand, DEFAULT_FRICTION, DEFAULT_RESTITUTION};
use dqhand::{Error, SceneProblem};
use glam::{Quat, Vec3};

fn parse(text: &str) -> dqhand::Result<Scene> {
    Scene::from_json(text, "scene.json", Path::new("."))
}

/// The scene with one object replaced by `object` (JSON text).
fn with_object(object: &str) -> String {
    format!(r#"{{"table": {{"height": 0.75}}, "objects": [{object}]}}"#)
}

fn problem(text: &str) -> (SceneProblem, String) {
    match parse(text) {
        Err(e @ Error::Scene { .. }) => {
            let message = e.to_string();
            let Error::Scene { problem, .. } = e else { unreachable!() };
            (problem, message)
        }
        other => panic!("{text}: expected a scene error, got {other:?}"),
    }
}

#[test]
fn a_scene_reads_with_its_defaults() {
    let dir = std::env::temp_dir().join(format!("dqhand-scene-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("teapot.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    let text = r#"{
      "table": {"height": 0.75},
      "objects": [
        {"name": "ball", "shape": "sphere", "radius": 0.04, "position": [0.1, 0.79, -0.3], "mass": 0.15},
        {"name": "cube", "shape": "box", "size": [0.05, 0.06, 0.07], "position": [0, 0.775, -0.3], "rotation": [0, 0.3826834, 0, 0.9238795], "mass": 0.1, "friction": 0.8, "restitution": 0.1},
        {"name": "mug", "shape": "cylinder", "radius": 0.04, "height": 0.1, "position": [-0.1, 0.8, -0.3], "mass": 0.3},
        {"name": "teapot", "shape": "mesh", "file": "teapot.obj", "position": [0, 0.75, -0.45], "mass": 0.6}
      ],
      "actions": [{"gesture": "open_palm", "hold_s": 1.0, "action": "reset"}]
    }"#;
    let path = dir.join("scene.json");
    std::fs::write(&path, text).unwrap();
    let scene = Scene::load(&path).unwrap();
    assert_eq!(scene.table.unwrap().height, 0.75);
    assert_eq!(scene.objects.len(), 4);
    let ball = scene.object("ball").unwrap();
    assert_eq!(ball.shape, ObjectShape::Sphere { radius: 0.04 });
    assert_eq!((ball.position, ball.rotation, ball.mass), (Vec3::new(0.1, 0.79, -0.3), Quat::IDENTITY, 0.15));
    assert_eq!((ball.friction, ball.restitution), (DEFAULT_FRICTION, DEFAULT_RESTITUTION));
    let cube = scene.object("cube").unwrap();
    assert_eq!(cube.shape, ObjectShape::Box { size: Vec3::new(0.05, 0.06, 0.07) });
    assert!((cube.rotation.length() - 1.0).abs() < 1e-6 && cube.rotation.angle_between(Quat::from_rotation_y(45f32.to_radians())) < 1e-4);
    assert_eq!((cube.friction, cube.restitution), (0.8, 0.1));
    assert_eq!(scene.object("mug").unwrap().shape, ObjectShape::Cylinder { radius: 0.04, height: 0.1 });
    assert_eq!(scene.object("teapot").unwrap().shape, ObjectShape::Mesh { source: MeshSource::File(dir.join("teapot.obj")), scale: 1.0 }, "relative to the scene file");
    assert_eq!((scene.actions[0].gesture.as_str(), scene.actions[0].hold_s, scene.actions[0].action), ("open_palm", 1.0, SceneCommand::Reset));
    // No table, no actions: both optional.
    let bare = parse(r#"{"objects": []}"#).unwrap();
    assert!(bare.table.is_none() && bare.objects.is_empty() && bare.actions.is_empty());
}

#[test]
fn bad_scenes_name_the_object_and_the_field() {
    let ball = |extra: &str| with_object(&format!(r#"{{"name": "ball", "shape": "sphere", "radius": 0.04, "position": [0, 1, 0], "mass": 0.2{extra}}}"#));
    let cases: Vec<(String, &str)> = vec![
        (ball(r#", "colour": "red""#), "unknown field `colour`"),
        (with_object(r#"{"name": "ball", "shape": "sphere", "position": [0, 1, 0], "mass": 0.2}"#), r#"object "ball": a sphere needs radius"#),
        (ball(r#", "height": 0.1"#), r#"object "ball": a sphere takes no height"#),
        (with_object(r#"{"name": "ball", "shape": "torus", "radius": 1, "position": [0, 1, 0], "mass": 0.2}"#), r#"unknown shape "torus""#),
        (with_object(r#"{"name": "ball", "shape": "sphere", "radius": 0.04, "position": [0, 1, 0], "mass": -1}"#), r#"object "ball": mass -1 is not more than 0"#),
        (with_object(r#"{"name": "ball", "shape": "sphere", "radius": 0, "position": [0, 1, 0], "mass": 1}"#), r#"object "ball": radius 0 is not more than 0"#),
        (with_object(r#"{"name": "box", "shape": "box", "size": [0.1, -0.1, 0.1], "position": [0, 1, 0], "mass": 1}"#), r#"object "box": size -0.1 is not more than 0"#),
        (with_object(r#"{"name": "ball", "shape": "sphere", "radius": 0.04, "position": [0, 1e39, 0], "mass": 0.2}"#), r#"object "ball": position is not a finite number"#),
        (ball(r#", "restitution": 2"#), r#"object "ball": restitution 2 is not 0 to 1"#),
        (ball(r#", "friction": -0.5"#), r#"object "ball": friction -0.5 is not 0 or more"#),
        (ball(r#", "rotation": [0, 0, 0, 2]"#), r#"object "ball": rotation 2 is not a unit quaternion"#),
        (with_object(r#"{"name": "pot", "shape": "mesh", "file": "no-such-teapot.obj", "position": [0, 1, 0], "mass": 1}"#), r#"object "pot": mesh file"#),
        (format!(r#"{{"objects": [{0}, {0}]}}"#, r#"{"name": "ball", "shape": "sphere", "radius": 0.04, "position": [0, 1, 0], "mass": 0.2}"#), r#"object "ball" is defined twice"#),
        (r#"{"table": {"height": 1e39}, "objects": []}"#.to_owned(), r#"object "table": height is not a finite number"#),
        (r#"{"objects": [], "actions": [{"gesture": "fist", "hold_s": -1, "action": "reset"}]}"#.to_owned(), r#"object "fist": hold_s -1 is not 0 or more seconds"#),
        (r#"{"objects": [], "actions": [{"gesture": "fist", "action": "explode"}]}"#.to_owned(), "unknown variant `explode`"),
        (r#"{"objects": [{"name": "ball""#.to_owned(), "not a valid scene"),
        ("[]".to_owned(), "not a valid scene"),
    ];
    for (text, needle) in cases {
        let (_, message) = problem(&text);
        assert!(message.starts_with("scene.json: "), "{message}");
        assert!(message.contains(needle), "{needle:?} not in {message:?} (for {text})");
    }
    // Kinds to match on, not only messages.
    assert!(matches!(problem(&ball(r#", "restitution": 2"#)).0, SceneProblem::OutOfRange { field: "restitution", .. }));
    let missing = Scene::load(Path::new("/no/such/scene.json")).unwrap_err().to_string();
    assert!(missing.starts_with("/no/such/scene.json: "), "{missing}");
}

/// The built-in scenes are compiled in, with their meshes: each is its file in `data/scenes`,
/// its mesh objects naming the built-in copy of the file (which reads the same), so a copied
/// or installed program needs no source tree.
#[test]
fn builtin_scenes_and_their_meshes_are_compiled_in() {
    let mut meshes = 0;
    for name in Scene::BUILTIN {
        let builtin = Scene::named(name).unwrap();
        let mut file = Scene::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("data/scenes").join(format!("{name}.json"))).unwrap();
        meshes += file.objects.iter().filter(|o| matches!(o.shape, ObjectShape::Mesh { .. })).count();
        for o in &mut file.objects {
            if let ObjectShape::Mesh { source: MeshSource::File(path), scale } = &o.shape {
                let relative = path.canonicalize().unwrap().strip_prefix(Path::new(env!("CARGO_MANIFEST_DIR")).join("data").canonicalize().unwrap()).unwrap().to_str().unwrap().to_owned();
                let built_in = ObjectMesh::BUILTIN.into_iter().find(|&m| m == relative).unwrap_or_else(|| panic!("{relative} is not built in"));
                assert_eq!(ObjectMesh::builtin(built_in).unwrap(), ObjectMesh::load(path).unwrap(), "{relative}");
                o.shape = ObjectShape::Mesh { source: MeshSource::Builtin(built_in), scale: *scale };
            }
        }
        assert_eq!(builtin, file, "{name}");
    }
    assert!(meshes > 0, "no built-in scene has a mesh object");
    let e = ObjectMesh::builtin("objects/kettle.obj").unwrap_err().to_string();
    assert!(e.contains("objects/kettle.obj") && e.contains("objects/teapot.obj"), "{e}");
    assert_eq!(MeshSource::Builtin("objects/teapot.obj").to_string(), "objects/teapot.obj (built in)");
}

fn teapot_path() -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("data/objects/teapot.obj")
}

/// The committed Utah teapot reads as a mesh of its size (12 cm tall, 24.5 cm spout to handle,
/// base on y = 0); its pole triangles without area are dropped, said in a warning.
#[test]
fn the_teapot_reads_as_a_mesh() {
    let mesh = ObjectMesh::load(&teapot_path()).unwrap();
    let (lo, hi) = mesh.vertices.iter().fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), v| (lo.min(*v), hi.max(*v)));
    assert!((lo.y).abs() < 1e-6 && (hi.y - 0.12).abs() < 1e-3 && ((hi - lo).x - 0.245).abs() < 1e-3, "{lo} {hi}");
    assert!(mesh.triangles.len() > 3000 && mesh.triangles.len() <= 4032, "{}", mesh.triangles.len());
    for t in &mesh.triangles {
        let [a, b, c] = t.map(|i| mesh.vertices[i as usize]);
        assert!((b - a).cross(c - a).length() > 0.0);
    }
    let dropped = 4032 - mesh.triangles.len();
    assert_eq!(mesh.warnings.contains(&dqhand::Warning::DegenerateTriangles { triangles: dropped }), dropped > 0, "{:?}", mesh.warnings);
}

/// Degenerate meshes: flat ones collide as surfaces (a warning), ones without a triangle of
/// any area, with non-finite coordinates or indices out of range are refused with the reason,
/// and a file that is not OBJ or not there is named.
#[test]
fn degenerate_meshes_are_repaired_or_refused_with_a_reason() {
    let plate = ObjectMesh::from_triangles(vec![Vec3::ZERO, Vec3::X, Vec3::Z, Vec3::new(1.0, 0.0, 1.0)], &[0, 2, 1, 1, 2, 3]).unwrap();
    assert_eq!(plate.triangles.len(), 2);
    assert!(plate.warnings.contains(&dqhand::Warning::FlatMesh), "{:?}", plate.warnings);
    let refused = |vertices: Vec<Vec3>, indices: &[u32]| ObjectMesh::from_triangles(vertices, indices).unwrap_err().to_string();
    assert!(refused(vec![Vec3::ZERO, Vec3::X, Vec3::X * 2.0], &[0, 1, 2]).contains("no triangle with an area"));
    assert!(refused(vec![Vec3::ZERO, Vec3::X, Vec3::new(f32::NAN, 0.0, 0.0)], &[0, 1, 2]).contains("vertex 2 is not finite"));
    assert!(refused(vec![Vec3::ZERO, Vec3::X, Vec3::Y], &[0, 1, 3]).contains("index 3 beyond the 3 vertices"));
    assert!(refused(vec![Vec3::ZERO, Vec3::X, Vec3::Y], &[0, 1]).contains("2 indices do not make whole triangles"));
    let dir = std::env::temp_dir().join(format!("dqhand-object-mesh-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let points = dir.join("points.obj");
    std::fs::write(&points, "v 0 0 0\nv 1 0 0\nv 0 1 0\np 1 2 3\n").unwrap();
    let e = ObjectMesh::load(&points).unwrap_err().to_string();
    assert!(e.starts_with(&points.display().to_string()) && e.contains("no triangle with an area"), "{e}");
    let bad_index = dir.join("bad-index.obj");
    std::fs::write(&bad_index, "v 0 0 0\nv 1 0 0\nf 1 2 9\n").unwrap();
    let e = ObjectMesh::load(&bad_index).unwrap_err().to_string();
    assert!(e.starts_with(&bad_index.display().to_string()), "{e}");
    let e = ObjectMesh::load(Path::new("teapot.stl")).unwrap_err().to_string();
    assert!(e.starts_with("teapot.stl: not a mesh file (.obj, .glb or .gltf)"), "{e}");
    let e = ObjectMesh::load(Path::new("/no/such/teapot.obj")).unwrap_err().to_string();
    assert!(e.starts_with("/no/such/teapot.obj"), "{e}");
}

/// A `.gltf` with one triangle (in a base64 `data:` buffer) under a node scaled by 2 and moved
/// by (1, 0, 0), under a parent turned 90° about +Y, and a second node that is a line (skipped).
fn gltf_json(scene: &str) -> String {
    // Three vertices (0,0,0), (1,0,0), (0,1,0), then indices 0 1 2 and two bytes of padding.
    let mut bin = Vec::new();
    for v in [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0] {
        bin.extend_from_slice(&v.to_le_bytes());
    }
    for i in [0u16, 1, 2, 0] {
        bin.extend_from_slice(&i.to_le_bytes());
    }
    use base64::Engine as _;
    let data = base64::engine::general_purpose::STANDARD.encode(&bin);
    let turn = [0.0, std::f32::consts::FRAC_1_SQRT_2, 0.0, std::f32::consts::FRAC_1_SQRT_2];
    format!(
        r#"{{"asset": {{"version": "2.0"}}, {scene}
            "nodes": [{{"rotation": {turn:?}, "children": [1, 2]}}, {{"mesh": 0, "translation": [1, 0, 0], "scale": [2, 2, 2]}}, {{"mesh": 1}}],
            "meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0}}, "indices": 1}}]}}, {{"primitives": [{{"attributes": {{"POSITION": 0}}, "mode": 1}}]}}],
            "accessors": [{{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]}},
                          {{"bufferView": 1, "componentType": 5123, "count": 3, "type": "SCALAR"}}],
            "bufferViews": [{{"buffer": 0, "byteOffset": 0, "byteLength": 36}}, {{"buffer": 0, "byteOffset": 36, "byteLength": 6}}],
            "buffers": [{{"byteLength": {}, "uri": "data:application/octet-stream;base64,{data}"}}]}}"#,
        bin.len()
    )
}

/// glTF meshes are placed by their nodes' world transforms (checked by hand: a turn of 90°
/// about +Y takes x to −z); primitives that are not triangles are skipped with a warning.
#[test]
fn a_gltf_mesh_reads_in_its_scene_frame() {
    let dir = std::env::temp_dir().join(format!("dqhand-gltf-mesh-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("triangle.gltf");
    std::fs::write(&path, gltf_json(r#""scene": 0, "scenes": [{"nodes": [0]}],"#)).unwrap();
    let mesh = ObjectMesh::load(&path).unwrap();
    // Local (x, y, z) → scaled and moved (2x + 1, 2y, 2z) → turned (2z, 2y, −(2x + 1)).
    let expected = [Vec3::new(0.0, 0.0, -1.0), Vec3::new(0.0, 0.0, -3.0), Vec3::new(0.0, 2.0, -1.0)];
    assert_eq!(mesh.triangles, [[0, 1, 2]]);
    for (v, e) in mesh.vertices.iter().zip(expected) {
        assert!(v.distance(e) < 1e-5, "{v} for {e}");
    }
    assert!(mesh.warnings.contains(&dqhand::Warning::NotTriangles { primitives: 1 }), "{:?}", mesh.warnings);
    // Without a scene, every node without a parent is a root; the same triangle.
    std::fs::write(&path, gltf_json("")).unwrap();
    assert_eq!(ObjectMesh::load(&path).unwrap().vertices.len(), 3);
    // Mirrored by its node (x scaled by −2), the triangle turns the other way round.
    std::fs::write(&path, gltf_json("").replace("[2, 2, 2]", "[-2, 2, 2]")).unwrap();
    assert_eq!(ObjectMesh::load(&path).unwrap().triangles, [[0, 2, 1]]);
    // A strip or a fan of three indices is that triangle (the line is still skipped).
    for mode in [5, 6] {
        std::fs::write(&path, gltf_json("").replace(r#""indices": 1}"#, &format!(r#""indices": 1, "mode": {mode}}}"#))).unwrap();
        let mesh = ObjectMesh::load(&path).unwrap();
        assert_eq!(mesh.triangles, [[0, 1, 2]], "mode {mode}");
        assert!(mesh.warnings.contains(&dqhand::Warning::NotTriangles { primitives: 1 }), "{:?}", mesh.warnings);
    }
}

/// The committed teapot written as `.glb` (by the project's writer) reads as the same mesh as
/// its OBJ (through tobj), and a scene can use it.
#[test]
fn the_teapot_reads_the_same_from_glb() {
    let obj = ObjectMesh::load(&teapot_path()).unwrap();
    let dir = std::env::temp_dir().join(format!("dqhand-teapot-glb-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let glb = dir.join("teapot.glb");
    let positions: Vec<[f32; 3]> = obj.vertices.iter().map(|v| v.to_array()).collect();
    let indices: Vec<u32> = obj.triangles.iter().flatten().copied().collect();
    dqhand::io::write_posed(&glb, &positions, &vec![[0.0, 1.0, 0.0]; positions.len()], &[], &indices).unwrap();
    let read = ObjectMesh::load(&glb).unwrap();
    assert_eq!(read.vertices, obj.vertices);
    assert_eq!(read.triangles, obj.triangles);
    std::fs::write(dir.join("scene.json"), r#"{"objects": [{"name": "teapot", "shape": "mesh", "file": "teapot.glb", "position": [0, 1, 0], "mass": 0.5}]}"#).unwrap();
    let scene = Scene::load(&dir.join("scene.json")).unwrap();
    dqhand::collision::ObjectColliders::new(&scene).unwrap();
}

/// Malformed glTF meshes are refused naming the file and the problem, never a panic: a
/// primitive naming an accessor that does not exist (it panicked inside the `gltf` crate), an
/// index out of range, a node hierarchy that loops (read once, no hang).
#[test]
fn malformed_gltf_meshes_are_refused_naming_the_file() {
    let dir = std::env::temp_dir().join(format!("dqhand-bad-gltf-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let refused = |name: &str, text: &str| {
        let path = dir.join(name);
        std::fs::write(&path, text).unwrap();
        let e = ObjectMesh::load(&path).unwrap_err().to_string();
        assert!(e.starts_with(&path.display().to_string()), "{e}");
        e
    };
    let e = refused("dangling.gltf", r#"{"asset":{"version":"2.0"},"meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}]}"#);
    assert!(e.contains("POSITION uses accessor 0, but there are 0"), "{e}");
    // The indices read from the first vertex's bytes: 1.0f32 makes index 16256.
    let e = refused("index.gltf", &gltf_json("").replace(r#"{"bufferView": 1, "componentType": 5123"#, r#"{"bufferView": 0, "byteOffset": 12, "componentType": 5123"#));
    assert!(e.contains("index 16256 is out of range for 3 vertices"), "{e}");
    // A node that is its ancestor's child: the scene's nodes are read once each.
    let looping = gltf_json(r#""scene": 0, "scenes": [{"nodes": [0]}],"#).replace(r#"{"mesh": 1}"#, r#"{"mesh": 1, "children": [0]}"#);
    let path = dir.join("loop.gltf");
    std::fs::write(&path, looping).unwrap();
    assert_eq!(ObjectMesh::load(&path).unwrap().vertices.len(), 3);
    // A stride shorter than the elements it steps over (the gltf crate's reader asserts).
    let e = refused("stride.gltf", &gltf_json("").replace(r#""byteOffset": 0, "byteLength": 36}"#, r#""byteOffset": 0, "byteLength": 36, "byteStride": 4}"#));
    assert!(e.contains("stride of 4 bytes, less than its 12-byte elements"), "{e}");
    let e = refused("junk.glb", "glTF not really");
    assert!(e.contains("glTF") || e.contains("GLB"), "{e}");
}
