//! Typed errors of the library: one variant per kind of failure, so callers can branch on
//! it; every message is lowercase and starts with the bad input (file, joint, vertex, value).

use std::path::PathBuf;

/// What went wrong, with the input (file, joint, vertex, value) it concerns.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A file could not be read or written.
    #[error("{}: {reason}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The operating system's reason (part of the message, so not also a `source`).
        reason: std::io::Error,
    },
    /// Something read from a file is wrong: the file, then what ([`Error::in_file`]).
    #[error("{}: {problem}", path.display())]
    File {
        /// The file.
        path: PathBuf,
        /// What is wrong in it; match on it to tell the kinds apart.
        problem: Box<Error>,
    },
    /// A glTF file is malformed or uses something this reader does not support.
    #[error("{0}")]
    Gltf(String),
    /// A file name's extension names no format that can be written (`.ply`, `.obj`, `.glb`).
    #[error("{}: unknown output format; use .ply, .obj or .glb", .0.display())]
    OutputFormat(PathBuf),
    /// A skeleton is not a tree of uniquely named joints with finite transforms.
    #[error("{0}")]
    Skeleton(String),
    /// Skinned mesh data are inconsistent (lengths, indices, weights, non-finite values).
    #[error("{0}")]
    Mesh(String),
    /// A joint a joint model or measure needs is not in the skeleton.
    #[error("skeleton has no joint {joint:?}; {needed_for}")]
    MissingJoint {
        /// The joint's name.
        joint: String,
        /// What needs it, as the end of the message.
        needed_for: &'static str,
    },
    /// A joint's frame does not follow the WebXR convention the joint model poses with.
    #[error("joint {joint:?}: {problem}; joint angles need WebXR joint frames (−Z along the bone toward the tip, +Y on the back of the hand)")]
    JointFrame {
        /// The joint's name.
        joint: String,
        /// How its frame differs.
        problem: String,
    },
    /// A pose (angles, wrist, local rotations) has an unusable value.
    #[error("{0}")]
    Pose(String),
    /// A pose sequence is malformed (no keyframes, times going backwards, wrong joint model).
    #[error("{0}")]
    Sequence(String),
    /// The parameters of the built-in hand describe no hand.
    #[error("{0}")]
    HandParameter(String),
    /// The built-in hand's surface could not be meshed as asked.
    #[error("{0}")]
    Tessellation(String),
    /// No skin lies around a joint whose region is measured.
    #[error("joint {0:?}: no skin around it to measure")]
    NoSkin(String),
    /// A list of skinning methods is empty, longer than four, or repeats one.
    #[error("{0}")]
    Methods(String),
    /// An input configuration (filters, dropouts, tracker mount, gesture commands) is invalid.
    #[error("input configuration: {0}")]
    Config(String),
    /// A glove mapping table is invalid: the table's name, then what ([`Error::Glove`] or
    /// [`Error::UnknownName`] for a DOF or sensor it does not have).
    #[error("glove table {table:?}: {problem}")]
    GloveTable {
        /// The table's name (`glove` field).
        table: String,
        /// What is wrong in it; match on it to tell the kinds apart.
        problem: Box<Error>,
    },
    /// Glove data do not fit together: a table's sensors and entries, a glove CSV header.
    #[error("{0}")]
    Glove(String),
    /// A glove calibration is unusable: missing or degenerate sensor extremes, or a
    /// calibration recording in which sensors never moved.
    #[error("{0}")]
    Calibration(String),
    /// A gesture definition file is malformed: the file, then the gesture and condition.
    #[error("{file}: {problem}")]
    GestureDefinition {
        /// The file's path, or `gestures.json (built-in)`.
        file: String,
        /// What is wrong; match on it to tell the kinds apart.
        problem: GestureProblem,
    },
    /// An object's mesh is unusable: not OBJ, unreadable, no triangle with an area,
    /// coordinates that are not finite, indices out of range.
    #[error("{0}")]
    ObjectMesh(String),
    /// A scene file is malformed: the file, then the object and field.
    #[error("{file}: {problem}")]
    Scene {
        /// The file's path.
        file: String,
        /// What is wrong; match on it to tell the kinds apart.
        problem: SceneProblem,
    },
    /// A gesture classifier cannot be trained on the examples given (a class without
    /// examples, a class index out of range).
    #[error("training: {0}")]
    Training(String),
    /// A name (joint, DOF, node, method, joint model, gesture) is not known; lists the valid ones.
    #[error("unknown {kind} {name:?}; valid: {valid}")]
    UnknownName {
        /// What kind of name: "joint", "degree of freedom", "node".
        kind: &'static str,
        /// The name given.
        name: String,
        /// The valid names, comma-separated.
        valid: String,
    },
}

/// What is wrong in a scene file ([`Error::Scene`]); each names the object (or gesture) and
/// the field.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SceneProblem {
    /// The text is not JSON of the expected shape: serde's message names an unknown or
    /// missing field, with line and column.
    #[error("not a valid scene: {0}")]
    Json(String),
    /// Two objects have the same name.
    #[error("object {0:?} is defined twice")]
    DuplicateName(String),
    /// An object asked for by name (a grasp script's) is not in the scene.
    #[error("no object called {0:?}")]
    NoObject(String),
    /// A shape that is not `sphere`, `box`, `cylinder` or `mesh`.
    #[error("object {object:?}: unknown shape {shape:?}; valid: sphere, box, cylinder, mesh")]
    UnknownShape {
        /// The object.
        object: String,
        /// The shape given.
        shape: String,
    },
    /// A parameter the shape needs is absent.
    #[error("object {object:?}: a {shape} needs {field}")]
    Missing {
        /// The object.
        object: String,
        /// The parameter.
        field: &'static str,
        /// The shape.
        shape: String,
    },
    /// A parameter of another shape is given.
    #[error("object {object:?}: a {shape} takes no {field}")]
    NotForShape {
        /// The object.
        object: String,
        /// The parameter.
        field: &'static str,
        /// The shape.
        shape: String,
    },
    /// A number is NaN or infinite.
    #[error("object {object:?}: {field} is not a finite number")]
    NotFinite {
        /// The object (or the table, or a gesture).
        object: String,
        /// The field.
        field: &'static str,
    },
    /// A number outside its range: a size or mass not positive, friction negative,
    /// restitution outside 0–1, a rotation far from unit length.
    #[error("object {object:?}: {field} {value} is not {range}")]
    OutOfRange {
        /// The object (or a gesture).
        object: String,
        /// The field.
        field: &'static str,
        /// The value given.
        value: f32,
        /// What it must be.
        range: &'static str,
    },
    /// A mesh file that is not there.
    #[error("object {object:?}: mesh file {} not found", file.display())]
    MeshFile {
        /// The object.
        object: String,
        /// The file, resolved against the scene's folder.
        file: std::path::PathBuf,
    },
}

/// What is wrong in a gesture definition file ([`Error::GestureDefinition`]).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum GestureProblem {
    /// The text is not JSON of the expected shape (serde's message, with line and column).
    #[error("not valid gesture definitions: {0}")]
    Json(String),
    /// Two gestures have the same name.
    #[error("gesture {0:?} is defined twice")]
    DuplicateName(String),
    /// A gesture has no condition, class or model, so it would match every pose.
    #[error("gesture {0:?} has no condition, class or model")]
    NoCondition(String),
    /// A condition is not `<feature> <op> <number> [release <number>]`.
    #[error("gesture {gesture:?}, condition {condition:?}: expected `<feature> < or > <number> [release <number>]`")]
    Syntax {
        /// The gesture.
        gesture: String,
        /// The condition as written.
        condition: String,
    },
    /// A condition names no feature.
    #[error("gesture {gesture:?}, condition {condition:?}: unknown feature {feature:?}; valid: {valid}")]
    UnknownFeature {
        /// The gesture.
        gesture: String,
        /// The condition as written.
        condition: String,
        /// The name given.
        feature: String,
        /// The feature names, comma-separated.
        valid: String,
    },
    /// A condition compares with something other than `<` or `>`.
    #[error("gesture {gesture:?}, condition {condition:?}: unknown operator {operator:?}; use < or >")]
    BadOperator {
        /// The gesture.
        gesture: String,
        /// The condition as written.
        condition: String,
        /// The operator given.
        operator: String,
    },
    /// A threshold is not a finite number.
    #[error("gesture {gesture:?}, condition {condition:?}: threshold {value:?} is not a finite number")]
    BadThreshold {
        /// The gesture.
        gesture: String,
        /// The condition as written.
        condition: String,
        /// The threshold as written.
        value: String,
    },
    /// A release threshold is on the entering side of the start threshold, so the gesture
    /// would end as it starts.
    #[error("gesture {gesture:?}, condition {condition:?}: release {release} must be above the threshold for <, below it for >")]
    BadRelease {
        /// The gesture.
        gesture: String,
        /// The condition as written.
        condition: String,
        /// The release threshold.
        release: f32,
    },
    /// A classifier (the file's `classifier`, or a gesture's `model`) is malformed: the
    /// shapes of its weights do not fit, a number is not finite, an input is no feature.
    #[error("{what}: {problem}")]
    Classifier {
        /// `classifier`, or `gesture "<name>" model`.
        what: String,
        /// What is wrong.
        problem: String,
    },
    /// A gesture names a class the file's classifier does not have (or there is none).
    #[error("gesture {gesture:?}: class {class:?} is not one of the classifier's ({valid})")]
    UnknownClass {
        /// The gesture.
        gesture: String,
        /// The class named.
        class: String,
        /// The classifier's classes, comma-separated (empty without a classifier).
        valid: String,
    },
    /// A two-hand gesture names a one-hand gesture the set lacks.
    #[error("two-hand gesture {two_hand:?}: no gesture {gesture:?} in the set of each hand; valid: {valid}")]
    UnknownGesture {
        /// The two-hand gesture.
        two_hand: String,
        /// The one-hand gesture it names.
        gesture: String,
        /// The set's gesture names, comma-separated.
        valid: String,
    },
    /// A setting (`min_hold_s`, a hysteresis margin) is negative or not finite.
    #[error("{name} {value} is not a finite number ≥ 0")]
    BadSetting {
        /// The setting, `min_hold_s` or `hysteresis.<kind>`.
        name: String,
        /// Its value.
        value: f64,
    },
}

impl Error {
    /// A function that wraps an I/O error on `path` (for `map_err`).
    pub fn io(path: &std::path::Path) -> impl Fn(std::io::Error) -> Self + '_ {
        move |reason| Error::Io { path: path.into(), reason }
    }

    /// Attaches a file path so that the message names the input. Errors that already name
    /// a file are returned as they are.
    #[must_use]
    pub fn in_file(self, path: impl Into<PathBuf>) -> Self {
        match self {
            Error::Io { .. } | Error::File { .. } | Error::OutputFormat(_) | Error::GestureDefinition { .. } | Error::Scene { .. } => self,
            other => Error::File { path: path.into(), problem: Box::new(other) },
        }
    }
}

/// The library's result type.
pub type Result<T, E = Error> = std::result::Result<T, E>;
