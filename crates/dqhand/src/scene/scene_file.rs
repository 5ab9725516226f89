//! Scene files: the objects the hand manipulates, the table they stand on, and the gestures
//! that command the scene (paper Figure 9: a ball and the Utah teapot on a table). JSON, metres,
//! glTF axes (+Y up), quaternions `[x, y, z, w]`:
//!
//! ```json
//! {
//!   "table": {"height": 0.75},
//!   "objects": [
//!     {"name": "ball", "shape": "sphere", "radius": 0.04, "position": [0.1, 0.79, -0.3], "mass": 0.15},
//!     {"name": "cube", "shape": "box", "size": [0.05, 0.05, 0.05], "position": [0, 0.775, -0.3],
//!      "rotation": [0, 0.383, 0, 0.924], "mass": 0.1, "friction": 0.8, "restitution": 0.1},
//!     {"name": "mug", "shape": "cylinder", "radius": 0.04, "height": 0.1, "position": [-0.1, 0.8, -0.3], "mass": 0.3},
//!     {"name": "teapot", "shape": "mesh", "file": "teapot.obj", "scale": 0.6,
//!      "position": [0, 0.75, -0.45], "mass": 0.6}
//!   ],
//!   "actions": [{"gesture": "open_palm", "hold_s": 1.0, "action": "reset"}]
//! }
//! ```
//!
//! Every field is checked when the file is read, and the first problem is named with its
//! object and field: unknown fields, a missing shape parameter, a non-positive size or mass,
//! a friction or restitution out of range, a rotation far from unit length, NaN, two objects
//! of one name, a mesh file that is not there. A mesh path is relative to the scene file; its
//! optional `scale` (default 1) scales the file's coordinates.
//!
//! The built-in scenes ([`Scene::BUILTIN`]) and the meshes they name are compiled in: a copied
//! or installed program has them without the source tree.

use std::fmt;
use std::path::{Component, Path, PathBuf};

use glam::{Quat, Vec3};
use serde::{Deserialize, Serialize};

use super::ObjectMesh;
use crate::{Error, Result, SceneProblem};

/// Default friction coefficient (rubber-ish on wood).
pub const DEFAULT_FRICTION: f32 = 0.7;
/// Default coefficient of restitution.
pub const DEFAULT_RESTITUTION: f32 = 0.3;

/// A scene: the table, the objects on it, and the gesture commands.
#[derive(Clone, Debug, PartialEq)]
pub struct Scene {
    /// The table, its top at `height` (+Y up), when there is one.
    pub table: Option<Table>,
    /// The objects, in file order, with distinct names.
    pub objects: Vec<SceneObject>,
    /// Held gestures that command the scene.
    pub actions: Vec<SceneAction>,
}

/// The table the objects stand on: its top is the plane y = `height`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Table {
    /// Height of the top, metres.
    pub height: f32,
}

/// One object of the scene, at rest where the file puts it.
#[derive(Clone, Debug, PartialEq)]
pub struct SceneObject {
    /// Its name (traces and the viewer use it).
    pub name: String,
    /// Its shape, in its own frame.
    pub shape: ObjectShape,
    /// Where its frame is, metres.
    pub position: Vec3,
    /// How its frame is turned (unit).
    pub rotation: Quat,
    /// Mass, kilograms (> 0).
    pub mass: f32,
    /// Coulomb friction coefficient (≥ 0).
    pub friction: f32,
    /// Coefficient of restitution (0–1).
    pub restitution: f32,
}

/// An object's shape, centred on its frame's origin (a mesh: as its file has it).
#[derive(Clone, Debug, PartialEq)]
pub enum ObjectShape {
    /// A ball.
    Sphere {
        /// Metres.
        radius: f32,
    },
    /// A box.
    Box {
        /// Edge lengths along x, y, z, metres.
        size: Vec3,
    },
    /// An upright cylinder (axis +Y).
    Cylinder {
        /// Metres.
        radius: f32,
        /// Metres, along +Y.
        height: f32,
    },
    /// A triangle mesh (an `.obj`, `.glb` or `.gltf` file, or one built in; read with
    /// [`MeshSource::load`]).
    Mesh {
        /// Where its triangles come from.
        source: MeshSource,
        /// Uniform scale applied to the file's coordinates (files come in any unit).
        scale: f32,
    },
}

/// Where a mesh object's triangles come from.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum MeshSource {
    /// A file, resolved against the scene file's folder.
    File(PathBuf),
    /// A mesh compiled into the crate ([`ObjectMesh::BUILTIN`]), named by a built-in scene.
    Builtin(&'static str),
}

impl MeshSource {
    /// Reads the mesh.
    ///
    /// # Errors
    /// As [`ObjectMesh::load`] for a file.
    pub fn load(&self) -> Result<ObjectMesh> {
        match self {
            Self::File(path) => ObjectMesh::load(path),
            Self::Builtin(name) => ObjectMesh::builtin(name),
        }
    }
}

impl fmt::Display for MeshSource {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::File(path) => write!(f, "{}", path.display()),
            Self::Builtin(name) => write!(f, "{name} (built in)"),
        }
    }
}

/// A held gesture that commands the scene.
#[derive(Clone, Debug, PartialEq)]
pub struct SceneAction {
    /// The gesture's name.
    pub gesture: String,
    /// Seconds it must be held.
    pub hold_s: f32,
    /// What it does.
    pub action: SceneCommand,
}

/// What a scene gesture does.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum SceneCommand {
    /// Every object back where the file puts it, at rest.
    Reset,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SceneJson {
    #[serde(default)]
    table: Option<TableJson>,
    objects: Vec<ObjectJson>,
    #[serde(default)]
    actions: Vec<ActionJson>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct TableJson {
    height: f32,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ObjectJson {
    name: String,
    shape: String,
    #[serde(default)]
    radius: Option<f32>,
    #[serde(default)]
    size: Option<[f32; 3]>,
    #[serde(default)]
    height: Option<f32>,
    #[serde(default)]
    file: Option<PathBuf>,
    #[serde(default)]
    scale: Option<f32>,
    position: [f32; 3],
    #[serde(default)]
    rotation: Option<[f32; 4]>,
    mass: f32,
    #[serde(default)]
    friction: Option<f32>,
    #[serde(default)]
    restitution: Option<f32>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ActionJson {
    gesture: String,
    #[serde(default)]
    hold_s: f32,
    action: SceneCommand,
}

/// Shape parameters each shape takes (the others must be absent).
const SHAPES: [(&str, &[&str]); 4] = [("sphere", &["radius"]), ("box", &["size"]), ("cylinder", &["radius", "height"]), ("mesh", &["file", "scale"])];

/// The built-in scenes' files (`data/scenes/`), compiled in.
const BUILTIN_SCENES: [(&str, &str); 3] = [
    ("grasp", include_str!("../../data/scenes/grasp.json")),
    ("objects", include_str!("../../data/scenes/objects.json")),
    ("two-hands", include_str!("../../data/scenes/two-hands.json")),
];

/// Where a scene's mesh paths start: a folder, or (a built-in scene) `data/scenes/` of the
/// crate, whose meshes are compiled in.
#[derive(Clone, Copy)]
enum Folder<'a> {
    Path(&'a Path),
    Builtin,
}

impl Scene {
    /// The scenes that ship with the crate (`data/scenes/`, compiled in): `grasp` (the paper's
    /// Figure 9: a ball and the Utah teapot on a table), `objects` (every kind of object) and
    /// `two-hands` (a 40 cm box and a bar, for two hands).
    pub const BUILTIN: [&'static str; 3] = [BUILTIN_SCENES[0].0, BUILTIN_SCENES[1].0, BUILTIN_SCENES[2].0];

    /// A built-in scene by name ([`Self::BUILTIN`]; its meshes built in too), else the scene
    /// file at that path.
    ///
    /// ```
    /// use dqhand::scene::{ObjectShape, Scene};
    ///
    /// let scene = Scene::named("grasp")?; // the paper's Figure 9
    /// let table = scene.table.expect("the grasp scene has a table").height;
    /// let ball = scene.object("ball").expect("a ball");
    /// assert!(matches!(ball.shape, ObjectShape::Sphere { radius } if ball.position.y - radius >= table - 1e-6));
    /// let teapot = scene.object("teapot").expect("and the Utah teapot");
    /// let ObjectShape::Mesh { source, .. } = &teapot.shape else { panic!("the teapot is a mesh") };
    /// assert!(!source.load()?.triangles.is_empty(), "its mesh is compiled in");
    /// assert!(Scene::named("no-such-scene.json").is_err());
    /// # Ok::<(), dqhand::Error>(())
    /// ```
    ///
    /// # Errors
    /// As [`Self::load`].
    pub fn named(name: &str) -> Result<Self> {
        match BUILTIN_SCENES.iter().find(|(n, _)| *n == name) {
            Some((name, text)) => Self::parse(text, &format!("{name} (built-in scene)"), Folder::Builtin),
            None => Self::load(Path::new(name)),
        }
    }

    /// Reads a scene file.
    ///
    /// # Errors
    /// [`Error::Io`] if it cannot be read; [`Error::Scene`] naming the first problem.
    pub fn load(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path).map_err(Error::io(path))?;
        Self::from_json(&text, &path.display().to_string(), path.parent().unwrap_or(Path::new(".")))
    }

    /// Parses a scene; `file` names it in errors, `folder` is where mesh paths start.
    ///
    /// # Errors
    /// [`Error::Scene`] naming the first problem.
    pub fn from_json(text: &str, file: &str, folder: &Path) -> Result<Self> {
        Self::parse(text, file, Folder::Path(folder))
    }

    fn parse(text: &str, file: &str, folder: Folder<'_>) -> Result<Self> {
        let fail = |problem| Error::Scene { file: file.to_owned(), problem };
        let json: SceneJson = serde_json::from_str(text).map_err(|e| fail(SceneProblem::Json(e.to_string())))?;
        let table = match json.table {
            Some(t) => Some(Table { height: finite("table", "height", t.height).map_err(fail)? }),
            None => None,
        };
        let mut objects: Vec<SceneObject> = Vec::with_capacity(json.objects.len());
        for o in json.objects {
            if objects.iter().any(|p| p.name == o.name) {
                return Err(fail(SceneProblem::DuplicateName(o.name)));
            }
            objects.push(object(o, folder).map_err(fail)?);
        }
        let actions = json
            .actions
            .into_iter()
            .map(|a| {
                let hold_s = finite(&a.gesture, "hold_s", a.hold_s)?;
                if hold_s < 0.0 {
                    return Err(SceneProblem::OutOfRange { object: a.gesture, field: "hold_s", value: hold_s, range: "0 or more seconds" });
                }
                Ok(SceneAction { gesture: a.gesture, hold_s, action: a.action })
            })
            .collect::<std::result::Result<_, _>>()
            .map_err(fail)?;
        Ok(Self { table, objects, actions })
    }

    /// The object called `name`.
    #[must_use]
    pub fn object(&self, name: &str) -> Option<&SceneObject> {
        self.objects.iter().find(|o| o.name == name)
    }
}

fn object(o: ObjectJson, folder: Folder<'_>) -> std::result::Result<SceneObject, SceneProblem> {
    let name = o.name.as_str();
    let Some((_, parameters)) = SHAPES.iter().find(|(s, _)| *s == o.shape) else {
        return Err(SceneProblem::UnknownShape { object: o.name.clone(), shape: o.shape.clone() });
    };
    let given = [("radius", o.radius.is_some()), ("size", o.size.is_some()), ("height", o.height.is_some()), ("file", o.file.is_some()), ("scale", o.scale.is_some())];
    for (field, present) in given {
        let wanted = parameters.contains(&field);
        if wanted && !present && field != "scale" {
            return Err(SceneProblem::Missing { object: o.name.clone(), field, shape: o.shape.clone() });
        }
        if present && !wanted {
            return Err(SceneProblem::NotForShape { object: o.name.clone(), field, shape: o.shape.clone() });
        }
    }
    let length = |field, v: Option<f32>| positive(name, field, v.expect("checked present"));
    let shape = match o.shape.as_str() {
        "sphere" => ObjectShape::Sphere { radius: length("radius", o.radius)? },
        "box" => {
            let [x, y, z] = o.size.expect("checked present");
            ObjectShape::Box { size: Vec3::new(positive(name, "size", x)?, positive(name, "size", y)?, positive(name, "size", z)?) }
        }
        "cylinder" => ObjectShape::Cylinder { radius: length("radius", o.radius)?, height: length("height", o.height)? },
        _ => {
            let file = o.file.as_deref().expect("checked present");
            let source = match folder {
                Folder::Path(folder) => Some(folder.join(file)).filter(|f| f.is_file()).map(MeshSource::File),
                Folder::Builtin => builtin_mesh(file).map(MeshSource::Builtin),
            };
            let Some(source) = source else {
                let folder = match folder {
                    Folder::Path(folder) => folder,
                    Folder::Builtin => Path::new("scenes"),
                };
                return Err(SceneProblem::MeshFile { object: o.name.clone(), file: folder.join(file) });
            };
            ObjectShape::Mesh { source, scale: positive(name, "scale", o.scale.unwrap_or(1.0))? }
        }
    };
    let mut position = Vec3::ZERO;
    for (p, v) in position.as_mut().iter_mut().zip(o.position) {
        *p = finite(name, "position", v)?;
    }
    let rotation = match o.rotation {
        None => Quat::IDENTITY,
        Some(q) => {
            for v in q {
                finite(name, "rotation", v)?;
            }
            let q = Quat::from_array(q);
            if (q.length() - 1.0).abs() > 0.01 {
                return Err(SceneProblem::OutOfRange { object: o.name.clone(), field: "rotation", value: q.length(), range: "a unit quaternion [x, y, z, w] (length 1)" });
            }
            q.normalize()
        }
    };
    let mass = positive(name, "mass", o.mass)?;
    let friction = finite(name, "friction", o.friction.unwrap_or(DEFAULT_FRICTION))?;
    if friction < 0.0 {
        return Err(SceneProblem::OutOfRange { object: o.name.clone(), field: "friction", value: friction, range: "0 or more" });
    }
    let restitution = finite(name, "restitution", o.restitution.unwrap_or(DEFAULT_RESTITUTION))?;
    if !(0.0..=1.0).contains(&restitution) {
        return Err(SceneProblem::OutOfRange { object: o.name.clone(), field: "restitution", value: restitution, range: "0 to 1" });
    }
    Ok(SceneObject { name: o.name, shape, position, rotation, mass, friction, restitution })
}

/// The built-in mesh a built-in scene's `file` names: the path resolved against `scenes/`,
/// within the crate's `data/` (`../objects/teapot.obj` is `objects/teapot.obj`).
fn builtin_mesh(file: &Path) -> Option<&'static str> {
    let mut parts = vec!["scenes"];
    for c in file.components() {
        match c {
            Component::Normal(part) => parts.push(part.to_str()?),
            Component::ParentDir => {
                parts.pop()?;
            }
            Component::CurDir => {}
            Component::RootDir | Component::Prefix(_) => return None,
        }
    }
    let path = parts.join("/");
    ObjectMesh::BUILTIN.into_iter().find(|&m| m == path)
}

fn finite(object: &str, field: &'static str, value: f32) -> std::result::Result<f32, SceneProblem> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(SceneProblem::NotFinite { object: object.to_owned(), field })
    }
}

fn positive(object: &str, field: &'static str, value: f32) -> std::result::Result<f32, SceneProblem> {
    if finite(object, field, value)? > 0.0 {
        Ok(value)
    } else {
        Err(SceneProblem::OutOfRange { object: object.to_owned(), field, value, range: "more than 0" })
    }
}
