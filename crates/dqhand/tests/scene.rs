//! Scene files: a good scene read with its defaults, and every kind of bad input refused
//! with the object and field named (never a panic).

use std::path::Path;

use dqhand::scene::{ObjectMesh, ObjectShape, Scene, SceneCommand, DEFAULT_FRICTION, DEFAULT_RESTITUTION};
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
    assert_eq!(scene.object("teapot").unwrap().shape, ObjectShape::Mesh { file: dir.join("teapot.obj"), scale: 1.0 }, "relative to the scene file");
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
    assert_eq!(mesh.warnings.iter().any(|w| w.contains(&format!("{dropped} triangles without area dropped"))), dropped > 0, "{:?}", mesh.warnings);
}

/// Degenerate meshes: flat ones collide as surfaces (a warning), ones without a triangle of
/// any area, with non-finite coordinates or indices out of range are refused with the reason,
/// and a file that is not OBJ or not there is named.
#[test]
fn degenerate_meshes_are_repaired_or_refused_with_a_reason() {
    let plate = ObjectMesh::from_triangles(vec![Vec3::ZERO, Vec3::X, Vec3::Z, Vec3::new(1.0, 0.0, 1.0)], &[0, 2, 1, 1, 2, 3]).unwrap();
    assert_eq!(plate.triangles.len(), 2);
    assert!(plate.warnings.iter().any(|w| w.contains("flat (no volume)")), "{:?}", plate.warnings);
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
    assert!(e.starts_with("teapot.stl: not an OBJ file"), "{e}");
    let e = ObjectMesh::load(Path::new("/no/such/teapot.obj")).unwrap_err().to_string();
    assert!(e.starts_with("/no/such/teapot.obj"), "{e}");
}
