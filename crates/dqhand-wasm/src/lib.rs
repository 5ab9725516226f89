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
use dqhand::interaction::GestureLoop;
use dqhand::kinematics::{JointModel, Pose, Side};
use dqhand::skin::{Method, MethodSet};
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
        if line.trim().is_empty() {
            return Ok(String::new());
        }
        if let Err(rejection) = parse_record::<&str>(line.trim(), self.side, &[], &mut self.record) {
            let message = rejection.to_string();
            self.inner.reject(rejection);
            return Err(JsError::new(&message));
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
