//! dqhand: a dual quaternion virtual hand (Chen, Zhu, Wan, Feng, "Dual quaternion based
//! virtual hand interaction modeling", Sci China Inf Sci 56:032103, 2013), as a library.
//!
//! A pose goes through the paper's two stages, each usable alone: the **kinematics layer**
//! ([`kinematics::HandKinematics`] for joint angles, [`kinematics::KinematicsLayer`] for any
//! skeleton: one forward kinematics pass, each bone's skinning transform and its unit dual
//! quaternion) and the **skin layer** ([`skin::SkinLayer`]: LB, QB, DQB or CoR on those transforms,
//! into its own buffers or the caller's). [`engine::Engine`] holds one of each for a hand; the
//! interaction loops ([`interaction::GestureLoop`], [`interaction::ManipulationLoop`]) hold
//! only kinematics.
//!
//! Modules from the bottom up, each importing only those above it in this list (the
//! paper's Figure 1, layer by layer; ARCHITECTURE.md draws it):
//! * [`math`] — dual quaternions and screws on top of glam;
//! * [`geometry`] — mesh helpers: normals, edges, closed surfaces, volume, winding number;
//! * [`kinematics`] — skeleton, joint models (`paper` 18 DOF, `full`), limits, poses, FK, and
//!   the kinematics layer;
//! * [`skin`] — the skinned mesh, the LB, QB, DQB and CoR deformers and the skin layer;
//! * [`model`] — a skeleton and the mesh bound to it;
//! * [`gltf_file`] — a glTF 2.0 file opened safely, for the importer and scene meshes;
//! * [`scene`] — the objects and table of the manipulation loop, from scene files;
//! * [`collision`] — collision proxies per bone (paper 4.2), the scene's shapes, and the
//!   contact constraint: continuous collision detection that keeps the rendered hand out of
//!   objects;
//! * [`grasp`] — grasping heuristics: grasp, hold (Kabsch), release;
//! * [`physics`] — the free objects under gravity on the table (rapier3d);
//! * [`hand`] — the built-in anatomical hand;
//! * [`io`] — glTF 2.0 in and out, PLY and OBJ out, pose files;
//! * [`input`] — records from gloves, trackers and hand tracking, turned into poses;
//! * [`gesture`] — the gesture library, pose sequences and recognition;
//! * [`engine`] — a hand's two stages together: pose → kinematics → skin;
//! * [`interaction`] — the gesture interaction loop: records → pose → recognised gestures;
//!   synthetic labelled sequences, and the loop's measures on them; the manipulation loop:
//!   records → pose → contacts → grasp → physics, and scripted grasp recordings;
//! * [`metrics`] — realism metrics of LB, QB, DQB and CoR.
//!
//! # Features
//! All on by default; without them (`default-features = false`) the core is `math`,
//! `geometry`, `kinematics`, `skin`, `model` and `engine`, on glam and thiserror alone.
//! * `gltf` — [`gltf_file`] and [`io`]: glTF 2.0 in and out, PLY and OBJ out, pose files;
//! * `hand` — [`hand`]: the parametric anatomical hand and its mesher;
//! * `interaction` — [`input`], [`gesture`], [`scene`], [`collision`], [`grasp`], [`physics`]
//!   and [`interaction`] (turns on `gltf` and `hand`);
//! * `metrics` — [`metrics`] (turns on `interaction`);
//! * `rayon` — [`skin::Deformer::deform_batch`], poses deformed across a thread pool;
//! * `synthetic` (not a default) — labelled recordings and scripted grasps made from the
//!   hand's own kinematics, and the loops' benchmarks on them (`interaction::synthetic`,
//!   `interaction::grasp_script`, `interaction::benchmark`): test fixtures, not input.
//!
//! Conventions: metres, seconds and radians; right-handed, +Y up (glTF); quaternions in files
//! are `[x, y, z, w]`; joints carry WebXR hand joint names. The types are glam's, re-exported
//! as [`glam`]. Minimum Rust: 1.89.

pub mod appearance;
mod error;
mod warning;
#[cfg(feature = "interaction")]
pub mod collision;
pub mod engine;
pub mod geometry;
#[cfg(feature = "interaction")]
pub mod gesture;
#[cfg(feature = "gltf")]
pub mod gltf_file;
#[cfg(feature = "interaction")]
pub mod grasp;
#[cfg(feature = "hand")]
pub mod hand;
#[cfg(feature = "interaction")]
pub mod input;
#[cfg(feature = "interaction")]
pub mod interaction;
#[cfg(feature = "gltf")]
pub mod io;
pub mod kinematics;
pub mod math;
#[cfg(feature = "metrics")]
pub mod metrics;
pub mod model;
#[cfg(feature = "interaction")]
pub mod physics;
#[cfg(feature = "interaction")]
pub mod scene;
pub mod skin;

/// The glam this crate's types are made of: use it rather than matching versions by hand.
pub use glam;

pub use error::{Error, GestureProblem, Result, SceneProblem};
pub use warning::Warning;
