//! dqhand's engine for JavaScript, in WebAssembly: the built-in anatomical hand, its forward
//! kinematics and LB, QB or DQB skinning (paper Figure 1, the kinematics and skin layers), and
//! the gesture loop, with no server. The same library as the native `dqhand`, compiled for `wasm32-unknown-unknown`
//! and bound with wasm-bindgen; `make wasm` builds it into `target/wasm/` and a Node test checks
//! its frames and gesture events against the native commands'.
//!
//! ```js
//! import { Hand, wasmMemory } from "./dqhand_wasm.js";
//! const hand = Hand.builtin(0.19, 0.085, "right", "full");
//! const angles = new Float32Array(hand.dofCount);
//! angles[hand.dofNames().indexOf("index-finger-phalanx-proximal.flex")] = 1.2;
//! hand.step(angles);
//! // A view of the skinned positions in the module's memory: no copy. Take it again after any
//! // call but `step` (one that allocates may grow the memory, which detaches old views).
//! const positions = new Float32Array(wasmMemory().buffer, hand.positionsPtr(), 3 * hand.vertexCount);
//! ```

use std::sync::Arc;

use dqhand::engine::Engine;
use dqhand::gesture::GestureSet;
use dqhand::hand::{build, HandParams};
use dqhand::input::json_record::parse_record;
use dqhand::input::{InputConfig, Record};
use dqhand::grasp::GraspParams;
use dqhand::interaction::{frame_trace, GestureLoop, ManipulationLoop};
use dqhand::kinematics::{JointModel, Pose, Side};
use dqhand::scene::Scene;
use dqhand::skin::{Deformed, Deformer, Kernel, Method, MethodSet, SkinnedMesh};
use glam::Affine3A;
use wasm_bindgen::prelude::*;

/// A hand: its engine, the pose it was last given and the method it skins with.
#[wasm_bindgen]
pub struct Hand {
    engine: Engine,
    joint_model: JointModel,
    pose: Pose,
    method: Method,
}

/// `"left"` or `"right"`.
fn side_of(side: &str) -> Result<Side, JsError> {
    match side {
        "left" => Ok(Side::Left),
        "right" => Ok(Side::Right),
        other => Err(JsError::new(&format!("side {other:?}: expected \"left\" or \"right\""))),
    }
}

/// The library's error as a JavaScript `Error` with its one-line message.
fn js(e: dqhand::Error) -> JsError {
    JsError::new(&e.to_string())
}

#[wasm_bindgen]
impl Hand {
    /// The built-in hand of `length` (wrist crease to middle fingertip, m) and `breadth` (across
    /// the metacarpal heads, m), `"left"` or `"right"`, posed by joint model `"paper"` (18
    /// angles, the paper's Table 1) or `"full"` (23), in the rest pose, skinned with DQB.
    ///
    /// # Errors
    /// A side or joint model that is none of those, or measurements that are not a hand's.
    pub fn builtin(length: f32, breadth: f32, side: &str, joint_model: &str) -> Result<Hand, JsError> {
        let side = side_of(side)?;
        let joint_model = joint_model.parse::<JointModel>().map_err(js)?;
        let model = build(&HandParams { length, breadth, side, ..HandParams::default() }).map_err(js)?;
        let engine = Engine::new(Arc::new(model), joint_model).map_err(js)?;
        Ok(Hand { engine, joint_model, pose: Pose::rest(joint_model.dof_count()), method: Method::Dqb })
    }

    /// How many joint angles a pose has.
    #[wasm_bindgen(getter, js_name = dofCount)]
    pub fn dof_count(&self) -> usize {
        self.pose.angles.len()
    }

    /// The angles' names, `"<bone>.<flex|abd>"`, in the order [`Self::step`] takes them.
    #[wasm_bindgen(js_name = dofNames)]
    pub fn dof_names(&self) -> Vec<String> {
        self.joint_model.dofs().map(|d| d.name().to_string()).collect()
    }

    /// The mesh's vertex count.
    #[wasm_bindgen(getter, js_name = vertexCount)]
    pub fn vertex_count(&self) -> usize {
        self.engine.model().mesh.vertex_count()
    }

    /// The mesh's triangles, three vertex indices each (a copy: they never change).
    pub fn indices(&self) -> Vec<u32> {
        self.engine.model().mesh.indices().to_vec()
    }

    /// Skins with `"lb"`, `"qb"` or `"dqb"` from the next [`Self::step`] on (and now).
    ///
    /// # Errors
    /// Another name.
    #[wasm_bindgen(js_name = setMethod)]
    pub fn set_method(&mut self, method: &str) -> Result<(), JsError> {
        let method = method.parse::<Method>().map_err(js)?;
        self.engine.set_methods(MethodSet::new(&[method]).map_err(js)?);
        self.method = method;
        self.engine.step(&self.pose);
        Ok(())
    }

    /// Poses `angles` (radians, in [`Self::dof_names`]' order, clamped to the hand's anatomical
    /// limits) and skins the mesh: one kinematics pass, one skinning pass, nothing allocated.
    ///
    /// # Errors
    /// Another angle count than [`Self::dof_count`], or an angle that is not finite; the hand
    /// keeps its last pose then.
    pub fn step(&mut self, angles: &[f32]) -> Result<(), JsError> {
        if angles.len() != self.pose.angles.len() {
            return Err(JsError::new(&format!("angles: {} given, the {} joint model has {}", angles.len(), self.joint_model.as_str(), self.pose.angles.len())));
        }
        if let Some(i) = angles.iter().position(|a| !a.is_finite()) {
            return Err(JsError::new(&format!("angles[{i}] ({}): not a finite number", angles[i])));
        }
        self.pose.angles.copy_from_slice(angles);
        self.engine.step(&self.pose);
        Ok(())
    }

    /// Where the skinned positions start in [`wasm_memory`]: `3 * vertexCount` floats, x y z per
    /// vertex, metres, rewritten in place by each [`Self::step`]. Take the view again after any
    /// other call (a first `setMethod` to a method allocates its buffer, and any allocation may
    /// grow the memory, which detaches every view).
    ///
    /// # Errors
    /// None in practice: the hand is skinned from its construction on.
    #[wasm_bindgen(js_name = positionsPtr)]
    pub fn positions_ptr(&self) -> Result<*const f32, JsError> {
        Ok(self.skinned()?.positions().as_ptr().cast())
    }

    /// Where the skinned unit normals start in [`wasm_memory`], laid out as the positions.
    ///
    /// # Errors
    /// As [`Self::positions_ptr`].
    #[wasm_bindgen(js_name = normalsPtr)]
    pub fn normals_ptr(&self) -> Result<*const f32, JsError> {
        Ok(self.skinned()?.normals().as_ptr().cast())
    }

    /// The mesh as the current method last skinned it.
    fn skinned(&self) -> Result<&dqhand::skin::Deformed, JsError> {
        self.engine.deformed(self.method).ok_or_else(|| JsError::new(&format!("method {}: not skinned yet", self.method)))
    }
}

/// The built-in hand's skin alone, deformed by skinning transforms the caller gives (not the
/// hand's kinematics): for testing the deformers against a reference of one's own, with every
/// rotation, and for comparing the kernels this build has.
#[wasm_bindgen]
pub struct Skinner {
    mesh: Arc<SkinnedMesh>,
    method: Method,
    deformer: Deformer,
    out: Deformed,
    transforms: Vec<Affine3A>,
}

#[wasm_bindgen]
impl Skinner {
    /// The built-in hand's skin (as [`Hand::builtin`]), DQB with the fastest kernel this
    /// build has, every transform the identity.
    ///
    /// # Errors
    /// As [`Hand::builtin`].
    pub fn builtin(length: f32, breadth: f32, side: &str) -> Result<Skinner, JsError> {
        let model = build(&HandParams { length, breadth, side: side_of(side)?, ..HandParams::default() }).map_err(js)?;
        let mesh = model.mesh;
        let transforms = vec![Affine3A::IDENTITY; mesh.inverse_bind().len()];
        let (deformer, out) = (Deformer::new(Method::Dqb, &mesh), Deformed::new(&mesh));
        Ok(Skinner { mesh, method: Method::Dqb, deformer, out, transforms })
    }

    /// The kernels this build runs, slowest first (`"portable"`, and `"simd128"` in the SIMD
    /// build).
    pub fn kernels() -> Vec<String> {
        Kernel::ALL.into_iter().filter(|k| k.available()).map(|k| k.name().to_owned()).collect()
    }

    /// How many joints (transforms) the skin has.
    #[wasm_bindgen(getter, js_name = jointCount)]
    pub fn joint_count(&self) -> usize {
        self.transforms.len()
    }

    /// The mesh's vertex count.
    #[wasm_bindgen(getter, js_name = vertexCount)]
    pub fn vertex_count(&self) -> usize {
        self.mesh.vertex_count()
    }

    /// The rest positions, x y z per vertex (bind space, m): what the transforms move.
    #[wasm_bindgen(js_name = restPositions)]
    pub fn rest_positions(&self) -> Vec<f32> {
        self.mesh.positions().into_iter().flatten().collect()
    }

    /// The rest unit normals, laid out as the positions.
    #[wasm_bindgen(js_name = restNormals)]
    pub fn rest_normals(&self) -> Vec<f32> {
        self.mesh.normals().into_iter().flatten().collect()
    }

    /// Every vertex's influences as the deformers blend them, heaviest first (the one the
    /// quaternion methods align the others' signs to): `influenceCount` pairs of joint index
    /// and weight per vertex, unused pairs (−1, 0).
    pub fn influences(&self) -> Vec<f32> {
        let k = self.mesh.influences_per_vertex();
        let mut all = Vec::with_capacity(self.mesh.vertex_count() * k * 2);
        for v in 0..self.mesh.vertex_count() {
            let before = all.len();
            all.extend(self.mesh.influences(v).flat_map(|(j, w)| [j as f32, w]));
            all.resize(before + 2 * k, 0.0);
            for unused in all[before..].chunks_exact_mut(2).filter(|p| p[1] == 0.0) {
                unused[0] = -1.0;
            }
        }
        all
    }

    /// How many influences [`Self::influences`] gives each vertex.
    #[wasm_bindgen(getter, js_name = influenceCount)]
    pub fn influence_count(&self) -> usize {
        self.mesh.influences_per_vertex()
    }

    /// Deforms with `"lb"`, `"qb"` or `"dqb"` and kernel `kernel` (one of [`Self::kernels`])
    /// from the next [`Self::deform`] on.
    ///
    /// # Errors
    /// Another method, or a kernel this build does not run; nothing changes then.
    #[wasm_bindgen(js_name = setMethod)]
    pub fn set_method(&mut self, method: &str, kernel: &str) -> Result<(), JsError> {
        let method = method.parse::<Method>().map_err(js)?;
        let kernel = Kernel::named(kernel).filter(|k| k.available()).ok_or_else(|| JsError::new(&format!("kernel {kernel:?}: this build runs {}", Self::kernels().join(", "))))?;
        self.method = method;
        self.deformer = Deformer::new(method, &self.mesh).with_kernel(kernel);
        Ok(())
    }

    /// Deforms the skin by `transforms`: per joint the skinning transform (world × inverse
    /// bind) as the 3 × 4 matrix `[R | t]`, row by row (12 floats). Allocates nothing.
    ///
    /// # Errors
    /// Another length than 12 × `jointCount`, or a number that is not finite; the skin keeps
    /// its last deformation then.
    pub fn deform(&mut self, transforms: &[f32]) -> Result<(), JsError> {
        if transforms.len() != 12 * self.transforms.len() {
            return Err(JsError::new(&format!("transforms: {} floats given, {} joints need {}", transforms.len(), self.transforms.len(), 12 * self.transforms.len())));
        }
        if let Some(i) = transforms.iter().position(|a| !a.is_finite()) {
            return Err(JsError::new(&format!("transforms[{i}] ({}): not a finite number", transforms[i])));
        }
        for (t, m) in self.transforms.iter_mut().zip(transforms.chunks_exact(12)) {
            *t = Affine3A::from_cols_array(&[m[0], m[4], m[8], m[1], m[5], m[9], m[2], m[6], m[10], m[3], m[7], m[11]]);
        }
        self.deformer.deform(&self.mesh, &self.transforms[..], &mut self.out);
        Ok(())
    }

    /// Where the deformed positions start in [`wasm_memory`] (as [`Hand::positions_ptr`]).
    #[wasm_bindgen(js_name = positionsPtr)]
    pub fn positions_ptr(&self) -> *const f32 {
        self.out.positions().as_ptr().cast()
    }

    /// Where the deformed unit normals start in [`wasm_memory`].
    #[wasm_bindgen(js_name = normalsPtr)]
    pub fn normals_ptr(&self) -> *const f32 {
        self.out.normals().as_ptr().cast()
    }

    /// The method and kernel it deforms with, as `"dqb simd128"`.
    pub fn describe(&self) -> String {
        format!("{} {}", self.method, self.deformer.kernel().name())
    }
}

/// Reads one line of a recording into `record` (`side`: the hand of records that do not say):
/// `false` for a blank line; a line that cannot be read goes to `reject` (the loop counts it,
/// as the native one does) and is an error of one line.
fn read(line: &str, side: Side, record: &mut Record, reject: impl FnOnce(dqhand::input::Rejection)) -> Result<bool, JsError> {
    let line = line.trim();
    if line.is_empty() {
        return Ok(false);
    }
    parse_record::<&str>(line, side, &[], record).map_err(|rejection| {
        let message = JsError::new(&rejection.to_string());
        reject(rejection);
        message
    })?;
    Ok(true)
}

/// The module's memory, which [`Hand::positions_ptr`] and [`Hand::normals_ptr`] point into
/// (`wasmMemory`: the module's own export is already called `memory`).
#[wasm_bindgen(js_name = wasmMemory)]
pub fn wasm_memory() -> JsValue {
    wasm_bindgen::memory()
}

/// The gesture loop (the paper's gesture interaction): records of a user's hand (WebXR or
/// OpenXR joints, MediaPipe landmarks, as JSON lines, docs/formats.md) through the input
/// pipeline (checks, filters, retargeting onto the built-in hand), forward kinematics, the finger
/// features and the recogniser of the built-in gestures: the same loop as `dqhand replay`.
#[wasm_bindgen(js_name = GestureLoop)]
pub struct Gestures {
    inner: GestureLoop,
    side: Side,
    record: Record,
}

#[wasm_bindgen(js_class = GestureLoop)]
impl Gestures {
    /// A loop driving the built-in `side` hand (`"left"` or `"right"`: also the side of records
    /// that do not say), recognising the built-in gestures.
    ///
    /// # Errors
    /// Another side.
    #[wasm_bindgen(constructor)]
    pub fn new(side: &str) -> Result<Gestures, JsError> {
        let side = side_of(side)?;
        let model = build(&HandParams { side, ..HandParams::default() }).map_err(js)?;
        let inner = GestureLoop::new(Arc::new(model), JointModel::Full, None, InputConfig::default(), Some(GestureSet::builtin())).map_err(js)?;
        Ok(Gestures { inner, side, record: Record { time: 0.0, side, hand: None, tracker: None, arrival: None } })
    }

    /// One record (a line of a recording): the gesture events it starts or ends, as JSON
    /// lines, `dqhand replay`'s output (empty when none).
    ///
    /// # Errors
    /// A record that cannot be read or is refused (its problem on one line); the loop goes on
    /// as the native one does.
    pub fn push(&mut self, line: &str) -> Result<String, JsError> {
        if !read(line, self.side, &mut self.record, |r| self.inner.reject(r))? {
            return Ok(String::new());
        }
        match self.inner.push(&self.record) {
            Ok(events) => {
                let mut out = String::new();
                for event in events {
                    out.push_str(&serde_json::to_string(&event).map_err(|e| JsError::new(&e.to_string()))?);
                    out.push('\n');
                }
                Ok(out)
            }
            Err(rejection) => Err(JsError::new(&rejection.to_string())),
        }
    }
}

/// The manipulation loop (the paper's 3D manipulation): records of a user's hands drive the
/// built-in hand, or a left and a right one, in a scene; each frame solves the rendered hand
/// against the objects (continuous collision detection), its grasps and the physics. The same
/// loop as `dqhand grasp`.
#[wasm_bindgen(js_name = GraspLoop)]
pub struct Grasps {
    inner: ManipulationLoop,
    side: Side,
    record: Record,
}

#[wasm_bindgen(js_class = GraspLoop)]
impl Grasps {
    /// A loop in the built-in scene `scene` (`"grasp"`, `"objects"`) of the built-in right hand,
    /// or with `two_hands` of a left and a right one (records drive the hand of their side; a
    /// record that does not say drives the right one), with the default input configuration
    /// and grasp parameters: `dqhand grasp`'s with no `--config` (no glove: records of joints or
    /// landmarks).
    ///
    /// # Errors
    /// A scene that is not built in.
    #[wasm_bindgen(constructor)]
    pub fn new(scene: &str, two_hands: bool) -> Result<Grasps, JsError> {
        let scene = Scene::named(scene).map_err(js)?;
        let hand = |side| build(&HandParams { side, ..HandParams::default() }).map(Arc::new).map_err(js);
        let (config, params) = (InputConfig::default(), GraspParams::default());
        let inner = if two_hands {
            ManipulationLoop::two_handed([(hand(Side::Left)?, None), (hand(Side::Right)?, None)], JointModel::Full, config, None, &scene, params)
        } else {
            ManipulationLoop::new(hand(Side::Right)?, JointModel::Full, None, config, None, &scene, params)
        }
        .map_err(js)?;
        Ok(Grasps { inner, side: Side::Right, record: Record { time: 0.0, side: Side::Right, hand: None, tracker: None, arrival: None } })
    }

    /// One record (a line of a recording), taken in before the next [`Self::step`].
    ///
    /// # Errors
    /// A record that cannot be read or is refused (its problem on one line); the loop goes on
    /// as the native one does.
    pub fn push(&mut self, line: &str) -> Result<(), JsError> {
        if !read(line, self.side, &mut self.record, |r| self.inner.reject(r))? {
            return Ok(());
        }
        self.inner.push(&self.record).map(|_| ()).map_err(|rejection| JsError::new(&rejection.to_string()))
    }

    /// Advances the loop to `now` (s, on the records' clock) and returns the frame as a JSON
    /// line: `dqhand grasp --trace`'s (the rendered hands' contacts, what each holds, every
    /// object's pose).
    pub fn step(&mut self, now: f64) -> String {
        self.inner.step(now);
        frame_trace(now, &self.inner).to_string()
    }
}
