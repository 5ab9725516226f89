//! dqhand's engine for JavaScript, in WebAssembly, with no server: the built-in anatomical
//! hand posed by joint angles and skinned with LB, QB, DQB or CoR ([`Hand`]: paper Figure 1, the
//! kinematics and skin layers), its skin alone under transforms of one's own ([`Skinner`]), and
//! both interaction loops, one or two hands driven by tracked hands in a scene or none
//! ([`Interaction`]). The same library as the native `dqhand`, compiled for
//! `wasm32-unknown-unknown` and bound with wasm-bindgen; `make wasm` builds it into
//! `target/wasm/`, and Node tests check its skins, gesture events and grasps against the native
//! commands'. The npm package `dqhand` (packages/dqhand) wraps it for three.js.
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

mod local_stream;

use std::sync::Arc;

use dqhand::engine::Engine;
use dqhand::gesture::{EventKind, GestureSet, TwoHandEvent};
use dqhand::grasp::GraspEvent;
use dqhand::hand::{build, HandParams};
use dqhand::input::array_record::{joints_record, landmarks_record};
use dqhand::input::json_record::parse_record;
use dqhand::input::{rest_side, InputConfig, Record};
use dqhand::grasp::GraspParams;
use dqhand::interaction::{frame_trace, scene_shapes, ManipulationLoop};
use dqhand::io::load_gltf_slice;
use dqhand::kinematics::{JointModel, Pose, Side};
use dqhand::model::Model;
use dqhand::scene::Scene;
use dqhand::skin::{Deformed, Deformer, Kernel, Method, MethodSet, SkinLayer, SkinnedMesh};
use glam::Affine3A;
use wasm_bindgen::prelude::*;

pub use local_stream::LocalStream;

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

/// A skinned glTF hand from `bytes`, given as the `side` one; `name` names the file in errors
/// and in its description.
fn load_model(bytes: &[u8], name: &str, side: Side) -> Result<Arc<Model>, JsError> {
    let model = load_gltf_slice(bytes, std::path::Path::new(name)).map_err(js)?;
    match rest_side(&model.skeleton) {
        Ok(found) if found == side => Ok(Arc::new(model)),
        Ok(found) => Err(JsError::new(&format!("{name}: the file holds a {} hand, given as the {} one", found.name(), side.name()))),
        Err(e) => Err(JsError::new(&format!("{name}: {e}"))),
    }
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

    /// Skins with `"lb"`, `"qb"`, `"dqb"` or `"cor"` from the next [`Self::step`] on (and now).
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

    /// The next [`Self::step`] does not follow the last one: a joint twisted past 180° is
    /// skinned the shortest way, as if the pose were the first (`SkinLayer::forget_previous_frame`).
    /// Each step otherwise follows the one before it, as frames of one motion.
    #[wasm_bindgen(js_name = forgetPreviousFrame)]
    pub fn forget_previous_frame(&mut self) {
        self.engine.skin_mut().forget_previous_frame();
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

    /// Deforms with `"lb"`, `"qb"`, `"dqb"` or `"cor"` and kernel `kernel` (one of [`Self::kernels`])
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

    /// Deforms normals too (`true`, the default) or positions only, from the next
    /// [`Self::deform`] on (take views again: the buffers are new).
    #[wasm_bindgen(js_name = setNormals)]
    pub fn set_normals(&mut self, on: bool) {
        self.out = if on { Deformed::new(&self.mesh) } else { Deformed::positions_only(&self.mesh) };
    }

    /// The next [`Self::deform`] does not follow the last one: its quaternion signs take the
    /// shortest path, as after [`Self::set_method`] (`Deformer::forget_previous_frame`).
    #[wasm_bindgen(js_name = forgetPreviousFrame)]
    pub fn forget_previous_frame(&mut self) {
        self.deformer.forget_previous_frame();
    }

    /// Deforms the skin by `transforms`: per joint the skinning transform (world × inverse
    /// bind) as the 3 × 4 matrix `[R | t]`, row by row (12 floats). Allocates nothing. Each
    /// call follows the one before it, as frames of one motion do: a joint twisted past 180°
    /// in steps of under 60° is blended the way it turned (up to 270°); a pose unrelated to the
    /// last wants [`Self::forget_previous_frame`] first.
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

/// Reads one line of a recording into `record` (`side`: the hand of records that do not say;
/// `sensors`: the glove's, naming a glove record's values):
/// `false` for a blank line; a line that cannot be read goes to `reject` (the loop counts it,
/// as the native one does) and is an error of one line.
fn read<S: AsRef<str>>(line: &str, side: Side, sensors: &[S], record: &mut Record, reject: impl FnOnce(dqhand::input::Rejection)) -> Result<bool, JsError> {
    let line = line.trim();
    if line.is_empty() {
        return Ok(false);
    }
    parse_record(line, side, sensors, record).map_err(|rejection| {
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

/// A user's hands in the page: one built-in hand (or a left and a right one) driven by tracked
/// hands (WebXR joints, MediaPipe landmarks, recorded lines), their gestures recognised, in a
/// scene or none, each rendered hand skinned where the page reads it with no copy. The paper's
/// two loops in one: gesture interaction, and 3D manipulation when the scene has objects (the
/// rendered hands stop on the objects and on each other, grasp and carry; `dqhand grasp`'s loop).
///
/// Per frame: push each tracked hand's record, then [`Self::step`]; read the skins through
/// [`Self::positions_ptr`] and [`Self::normals_ptr`], the objects through [`Self::poses_ptr`],
/// the events through [`Self::take_events`] when `step` says there are some. Nothing of that
/// allocates in the module (its memory does not grow, so views of it stay valid).
#[wasm_bindgen]
pub struct Interaction {
    manip: ManipulationLoop,
    skins: Vec<SkinLayer>,
    method: Method,
    record: Record,
    /// Events since the last [`Self::take_events`], JSON lines.
    events: String,
    event_count: usize,
    /// x y z, qx qy qz qw per object after the last step.
    poses: Vec<f32>,
}

#[wasm_bindgen]
impl Interaction {
    /// Hands `"right"`, `"left"` or `"both"` (each built as itself, of `length` and `breadth`
    /// m, as [`Hand::builtin`], default 0.19 and 0.085), in `scene`: `""` for none, a built-in
    /// scene's name (`"grasp"`, `"objects"`, `"two-hands"`), or a scene file's JSON text
    /// (docs/formats.md; shapes only: a page has no files for mesh objects). The rendered
    /// hands are skinned with DQB.
    ///
    /// # Errors
    /// Other hands, a scene that is not built in or cannot be read (its problem on one line),
    /// measurements that are not a hand's.
    #[wasm_bindgen(constructor)]
    pub fn new(hands: &str, scene: &str, length: Option<f32>, breadth: Option<f32>) -> Result<Interaction, JsError> {
        let defaults = HandParams::default();
        let (length, breadth) = (length.unwrap_or(defaults.length), breadth.unwrap_or(defaults.breadth));
        let hand = |side| build(&HandParams { length, breadth, side, ..HandParams::default() }).map(Arc::new).map_err(js);
        let models = match hands {
            "both" => vec![hand(Side::Left)?, hand(Side::Right)?],
            one => vec![hand(side_of(one).map_err(|_| JsError::new(&format!("hands {one:?}: expected \"left\", \"right\" or \"both\"")))?)?],
        };
        Self::with_hands(models, scene)
    }

    /// Hands from skinned glTF 2.0 files (`.glb` bytes or `.gltf` JSON with embedded buffers),
    /// `right`, `left` or both, whose skeletons have the 25 WebXR hand joints (the built-in
    /// hand as `dqhand hand --out` writes it, the WebXR input profiles' generic hands), in
    /// `scene` as [`Self::new`]. Loading a written hand skips generating it, most of the
    /// time a built-in hand takes to start (seconds in WebAssembly).
    ///
    /// # Errors
    /// Neither file given; a file that is not a skinned glTF (its problem on one line, naming
    /// the file's side); a hand that is not of the side it was given as; a scene as
    /// [`Self::new`].
    #[wasm_bindgen(js_name = withModels)]
    pub fn with_models(scene: &str, right: Option<Vec<u8>>, left: Option<Vec<u8>>) -> Result<Interaction, JsError> {
        let given: Vec<(Vec<u8>, Side)> = [(left, Side::Left), (right, Side::Right)].into_iter().filter_map(|(b, side)| b.map(|b| (b, side))).collect();
        if given.is_empty() {
            return Err(JsError::new("withModels: no model given (a right one, a left one or both)"));
        }
        let models = given.iter().map(|(bytes, side)| load_model(bytes, &format!("{} model", side.name()), *side)).collect::<Result<Vec<_>, _>>()?;
        Self::with_hands(models, scene)
    }

    /// The loop of `models` (one hand, or a left and a right one in that order) in `scene`.
    fn with_hands(models: Vec<Arc<Model>>, scene: &str) -> Result<Interaction, JsError> {
        let scene = match scene.trim_start() {
            "" => Scene { table: None, objects: Vec::new(), actions: Vec::new() },
            text if text.starts_with('{') => Scene::from_json(text, "scene", std::path::Path::new("")).map_err(js)?,
            name => Scene::named(name).map_err(js)?,
        };
        let (config, params, gestures) = (InputConfig::default(), GraspParams::default(), Some(GestureSet::builtin()));
        let manip = match <[Arc<Model>; 2]>::try_from(models) {
            Ok([left, right]) => ManipulationLoop::two_handed([(left, None), (right, None)], JointModel::Full, config, gestures, &scene, params),
            Err(mut one) => ManipulationLoop::new(one.remove(0), JointModel::Full, None, config, gestures, &scene, params),
        }
        .map_err(js)?;
        let skins = manip
            .hands()
            .iter()
            .map(|h| {
                let mut skin = SkinLayer::new(Arc::clone(&h.input().model().mesh), MethodSet::DQB);
                skin.deform(h.rendered().layer());
                skin
            })
            .collect();
        let side = manip.hands()[0].side();
        let poses = vec![0.0; 7 * manip.names().len()];
        let mut interaction = Interaction { manip, skins, method: Method::Dqb, record: Record { time: 0.0, side, hand: None, tracker: None, arrival: None }, events: String::new(), event_count: 0, poses };
        interaction.read_poses();
        Ok(interaction)
    }

    /// How many hands (1 or 2; of two, the left one is hand 0).
    #[wasm_bindgen(getter, js_name = handCount)]
    pub fn hand_count(&self) -> usize {
        self.skins.len()
    }

    /// Hand `k`'s side, `"left"` or `"right"`.
    pub fn side(&self, k: usize) -> String {
        self.manip.hands()[k.min(self.skins.len() - 1)].side().name().to_owned()
    }

    /// Hand `k`'s vertex count.
    #[wasm_bindgen(js_name = vertexCount)]
    pub fn vertex_count(&self, k: usize) -> usize {
        self.skin(k).mesh().vertex_count()
    }

    /// Hand `k`'s triangles, three vertex indices each (a copy: they never change).
    pub fn indices(&self, k: usize) -> Vec<u32> {
        self.skin(k).mesh().indices().to_vec()
    }

    /// Skins with `"lb"`, `"qb"`, `"dqb"` or `"cor"` from now on. Allocates the method's buffers the
    /// first time: take views of the memory again after it.
    ///
    /// # Errors
    /// Another name.
    #[wasm_bindgen(js_name = setMethod)]
    pub fn set_method(&mut self, method: &str) -> Result<(), JsError> {
        let method = method.parse::<Method>().map_err(js)?;
        for (skin, hand) in self.skins.iter_mut().zip(self.manip.hands()) {
            skin.set_methods(MethodSet::new(&[method]).map_err(js)?);
            skin.deform(hand.rendered().layer());
        }
        self.method = method;
        Ok(())
    }

    /// Where hand `k`'s skinned positions start in [`wasm_memory`]: `3 * vertexCount(k)` floats,
    /// x y z per vertex, world metres, rewritten in place by each [`Self::step`].
    #[wasm_bindgen(js_name = positionsPtr)]
    pub fn positions_ptr(&self, k: usize) -> *const f32 {
        self.deformed(k).positions().as_ptr().cast()
    }

    /// Where hand `k`'s skinned unit normals start, laid out as the positions.
    #[wasm_bindgen(js_name = normalsPtr)]
    pub fn normals_ptr(&self, k: usize) -> *const f32 {
        self.deformed(k).normals().as_ptr().cast()
    }

    /// One record of WebXR hand tracking: the 25 joints of `side`'s hand at `t` (s), as
    /// `XRFrame.fillPoses` writes them (16 floats per joint, column-major, in the reference
    /// space the scene is in: metres, +Y up) and `fillJointRadii` (25 floats, or empty).
    ///
    /// # Errors
    /// A record that is refused (the problem on one line; the loop counts it and goes on).
    #[wasm_bindgen(js_name = pushJoints)]
    pub fn push_joints(&mut self, side: &str, t: f64, matrices: &[f32], radii: &[f32]) -> Result<(), JsError> {
        let side = side_of(side)?;
        let read = joints_record(t, side, matrices, radii, &mut self.record);
        self.take(read)
    }

    /// One record of MediaPipe Hands: `side`'s 21 world landmarks at `t` (s), x y z each,
    /// metres, in the engine's axes (`+Y` up; docs/formats.md says how the camera's map).
    ///
    /// # Errors
    /// As [`Self::push_joints`].
    #[wasm_bindgen(js_name = pushLandmarks)]
    pub fn push_landmarks(&mut self, side: &str, t: f64, landmarks: &[f32]) -> Result<(), JsError> {
        let side = side_of(side)?;
        let read = landmarks_record(t, side, landmarks, &mut self.record);
        self.take(read)
    }

    /// One line of a recording (docs/formats.md: joints, landmarks; a line that does not say
    /// drives the first hand's side). Blank lines are skipped.
    ///
    /// # Errors
    /// As [`Self::push_joints`].
    #[wasm_bindgen(js_name = pushLine)]
    pub fn push_line(&mut self, line: &str) -> Result<(), JsError> {
        let side = self.manip.hands()[0].side();
        if read::<&str>(line, side, &[], &mut self.record, |r| self.manip.reject(r))? {
            self.take(Ok(()))?;
        }
        Ok(())
    }

    /// Advances to `now` (s, on the records' clock): each rendered hand follows its tracked
    /// one, stopped by the objects and the other hand, grasps, carries and lets go, the
    /// physics steps, and the skins are deformed. Returns how many events are waiting
    /// ([`Self::take_events`]).
    pub fn step(&mut self, now: f64) -> usize {
        let events = self.manip.step(now);
        for (k, event) in events.iter() {
            let side = self.manip.hands()[k].side().name();
            let line = match event {
                GraspEvent::Grasp { object } => format!(r#"{{"t":{now},"hand":"{side}","event":"grasp","object":{}}}"#, json_str(&self.manip.names()[object])),
                GraspEvent::Release { object, linvel, angvel } => format!(
                    r#"{{"t":{now},"hand":"{side}","event":"release","object":{},"linvel":{:?},"angvel":{:?}}}"#,
                    json_str(&self.manip.names()[object]),
                    linvel.to_array(),
                    angvel.to_array()
                ),
            };
            self.add_event(&line);
        }
        for event in events.two_hand() {
            let (kind, g) = match event {
                TwoHandEvent::Start(g) => ("start", g),
                TwoHandEvent::End(g) => ("end", g),
            };
            let name = self.manip.two_hand_gestures().map_or("", |r| r.gestures()[g].name.as_str());
            let line = format!(r#"{{"t":{now},"hand":"both","event":"{kind}","gesture":{}}}"#, json_str(name));
            self.add_event(&line);
        }
        for (skin, hand) in self.skins.iter_mut().zip(self.manip.hands()) {
            skin.deform(hand.rendered().layer());
        }
        self.read_poses();
        self.event_count
    }

    /// The events since the last call, JSON lines: `{"t", "hand", "event": "start" | "end",
    /// "gesture"}` (`hand` `"both"` for a gesture of both hands), `{"t", "hand", "event":
    /// "grasp", "object"}`, `{"t", "hand", "event": "release", "object", "linvel", "angvel"}`.
    #[wasm_bindgen(js_name = takeEvents)]
    pub fn take_events(&mut self) -> String {
        self.event_count = 0;
        std::mem::take(&mut self.events)
    }

    /// Hand `k`'s tracking: `"waiting"` (no record yet), `"tracking"` or `"lost"`.
    pub fn tracking(&self, k: usize) -> String {
        self.manip.hands()[k.min(self.skins.len() - 1)].tracking().as_str().to_owned()
    }

    /// Hand `k`'s current gesture, if any.
    pub fn gesture(&self, k: usize) -> Option<String> {
        self.manip.hands()[k.min(self.skins.len() - 1)].input().gesture().map(str::to_owned)
    }

    /// The object hand `k` holds (its index), or −1.
    pub fn held(&self, k: usize) -> i32 {
        self.manip.hands()[k.min(self.skins.len() - 1)].held().map_or(-1, |i| i as i32)
    }

    /// The scene's table and objects' shapes as JSON (`dqhand::interaction::scene_shapes`,
    /// the objects in the order of [`Self::poses_ptr`]).
    pub fn scene(&self) -> String {
        scene_shapes(&self.manip, usize::MAX).to_string()
    }

    /// How many objects the scene has.
    #[wasm_bindgen(getter, js_name = objectCount)]
    pub fn object_count(&self) -> usize {
        self.manip.names().len()
    }

    /// Where the objects' poses start in [`wasm_memory`]: 7 floats per object, position x y z
    /// (m) and rotation x y z w, rewritten by each [`Self::step`].
    #[wasm_bindgen(js_name = posesPtr)]
    pub fn poses_ptr(&self) -> *const f32 {
        self.poses.as_ptr()
    }

    /// Every object back where the scene puts it, at rest (on the next [`Self::step`]).
    pub fn reset(&mut self) {
        self.manip.reset();
    }

    /// The last frame as `dqhand grasp --trace` writes it at `now` (the time given to the last
    /// [`Self::step`]): the rendered hands' contacts, what each holds, every object's pose.
    pub fn trace(&self, now: f64) -> String {
        frame_trace(now, &self.manip).to_string()
    }

    /// Records taken and refused so far, over every hand.
    pub fn counts(&self) -> Vec<f64> {
        let (accepted, refused) = self.manip.hands().iter().fold((0, 0), |(a, r), h| (a + h.input().pipeline().accepted(), r + h.input().pipeline().rejections().total()));
        vec![accepted as f64, refused as f64]
    }
}

impl Interaction {
    fn skin(&self, k: usize) -> &SkinLayer {
        &self.skins[k.min(self.skins.len() - 1)]
    }

    fn deformed(&self, k: usize) -> &Deformed {
        self.skin(k).deformed(self.method).expect("every skin is deformed with its method from its construction on")
    }

    /// A record read into `self.record` (or refused) into the loop; its gesture events logged.
    fn take(&mut self, read: Result<(), dqhand::input::Rejection>) -> Result<(), JsError> {
        if let Err(rejection) = read {
            let message = JsError::new(&rejection.to_string());
            self.manip.reject(rejection);
            return Err(message);
        }
        let side = self.manip.hands()[self.manip.hand_of(self.record.side)].side().name();
        let mut lines = [None, None];
        match self.manip.push(&self.record) {
            Ok(events) => {
                for (line, e) in lines.iter_mut().zip(events) {
                    let kind = if e.event == EventKind::Start { "start" } else { "end" };
                    *line = Some(format!(r#"{{"t":{},"hand":"{side}","event":"{kind}","gesture":{}}}"#, e.t, json_str(e.gesture)));
                }
            }
            Err(rejection) => return Err(JsError::new(&rejection.to_string())),
        }
        for line in lines.into_iter().flatten() {
            self.add_event(&line);
        }
        Ok(())
    }

    fn add_event(&mut self, line: &str) {
        self.events.push_str(line);
        self.events.push('\n');
        self.event_count += 1;
    }

    fn read_poses(&mut self) {
        for (out, (q, p)) in self.poses.chunks_exact_mut(7).zip(self.manip.poses()) {
            out[..3].copy_from_slice(&p.to_array());
            out[3..].copy_from_slice(&q.to_array());
        }
    }
}

/// `s` as a JSON string (quoted and escaped).
fn json_str(s: &str) -> String {
    serde_json::Value::from(s).to_string()
}
