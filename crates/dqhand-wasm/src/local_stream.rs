//! The viewer's engine in the page itself: what `dqhand demo` runs for each viewer (a
//! `Session` posing and skinning the hand with the methods in view, the gesture sequence and
//! its timeline, the live input every viewer follows, a scene with one or two hands), run by
//! the page with no server, speaking the same messages: the hello, the topologies, binary
//! frames, `input` and `scene` messages. The page's live input (its camera, a WebXR session)
//! goes in as records; its commands (sliders, methods, heat map, timeline) as JSON text.

use std::sync::Arc;

use dqhand::gesture::GestureSet;
use dqhand::grasp::GraspParams;
use dqhand::hand::{build, HandParams};
use dqhand::input::{InputConfig, Record};
use dqhand::interaction::{GestureLoop, ManipulationLoop};
use dqhand::kinematics::Side;
use dqhand::scene::Scene;
use dqhand_stream::{Applied, Command, EngineSettings, FrameRate, InputView, LiveInput, Session, MAX_COMMAND_BYTES};
use wasm_bindgen::prelude::*;

use crate::{js, load_model, read};

/// Longest step of the engine's clock, s: after a stall (a hidden tab) it resumes, not races.
const MAX_STEP_S: f32 = 0.1;

/// One viewer's engine and the live input it follows, in the page.
#[wasm_bindgen]
pub struct LocalStream {
    session: Session,
    input: LiveInput,
    view: InputView,
    /// The latest frame of each hand shown, encoded.
    frames: [Vec<u8>; 2],
    /// Text messages for the page since it last took them.
    texts: Vec<String>,
    record: Record,
    /// The glove's sensor names: how a glove record names its values.
    sensors: Vec<String>,
    rate: FrameRate,
    /// The engine's clock: the steps' times added up (s).
    clock: f64,
}

#[wasm_bindgen]
impl LocalStream {
    /// The built-in right hand, with `two_hands` a left one too (both follow the live input's
    /// hand of their side), in `scene` (`""` for none, or a built-in scene's name). `right` and
    /// `left`, when given, are those hands already written as skinned glTF (`dqhand hand
    /// --out`, served as `hands/right.glb` and `hands/left.glb`): loaded, not generated, which
    /// takes most of a page's start. `config` is an input configuration (JSON text, as `dqhand
    /// demo --config` reads from a file; docs/formats.md), the defaults when absent or empty.
    ///
    /// # Errors
    /// A scene that is not built in; two hands with no scene (only a scene's loop drives two);
    /// a hand file that is not a skinned glTF hand; a configuration that is not one.
    #[wasm_bindgen(constructor)]
    pub fn new(scene: &str, two_hands: bool, right: Option<Vec<u8>>, left: Option<Vec<u8>>, config: Option<String>) -> Result<LocalStream, JsError> {
        let config = match config.as_deref().map(str::trim) {
            None | Some("") => InputConfig::default(),
            Some(text) => InputConfig::from_json(text).map_err(js)?,
        };
        let scene = (!scene.is_empty()).then(|| scene.to_owned());
        Self::build(&EngineSettings { hands: 1 + u8::from(two_hands), scene, config, ..EngineSettings::default() }, right, left)
    }

    /// The engine `dqhand demo` runs, from the settings it gives in `engine.json` (JSON text,
    /// [`EngineSettings`]): its hands (`right`, `left` as the server serves them), scene, joint
    /// model, configuration, gestures and glove, so that the records it relays drive this
    /// engine as they would its own.
    ///
    /// # Errors
    /// Settings that are not settings, or any of [`Self::new`]'s.
    #[wasm_bindgen(js_name = fromSettings)]
    pub fn from_settings(settings: &str, right: Option<Vec<u8>>, left: Option<Vec<u8>>) -> Result<LocalStream, JsError> {
        let settings = EngineSettings::from_json(settings).map_err(|e| JsError::new(&e.to_string()))?;
        let source = format!("{}, relayed by dqhand demo", settings.source);
        let mut stream = Self::build(&EngineSettings { source, ..settings }, right, left)?;
        stream.input = stream.input.following_arrivals();
        Ok(stream)
    }

    /// The settings [`Self::new`] runs with when given nothing (JSON text): `dqhand demo`'s
    /// defaults, a start for [`Self::from_settings`].
    #[wasm_bindgen(js_name = defaultSettings)]
    pub fn default_settings() -> String {
        EngineSettings::default().to_json()
    }

    fn build(settings: &EngineSettings, right: Option<Vec<u8>>, left: Option<Vec<u8>>) -> Result<LocalStream, JsError> {
        let (source, announce) = (settings.source.as_str(), settings.announce);
        let stream = |e: dqhand_stream::Error| JsError::new(&e.to_string());
        let hand = |side: Side, bytes: Option<Vec<u8>>| match bytes {
            Some(bytes) => load_model(&bytes, &format!("hands/{}.glb", side.name()), side),
            None => build(&HandParams { side, ..HandParams::default() }).map(Arc::new).map_err(js),
        };
        // The settings' own faults first: the hands take seconds to generate.
        if settings.hands == 2 && settings.scene.is_none() {
            return Err(JsError::new("two hands: only a scene drives two (give a scene)"));
        }
        let joint_model = settings.joint_model().map_err(stream)?;
        let (mapper, gestures) = (Some(settings.mapper().map_err(stream)?), Some(settings.gesture_set().map_err(stream)?));
        let scene = settings.scene.as_deref().map(Scene::named).transpose().map_err(js)?;
        let model = hand(Side::Right, right)?;
        let left = if settings.hands == 2 { Some(hand(Side::Left, left)?) } else { None };
        let config = settings.config.clone();
        let input = match (scene, &left) {
            (None, _) => LiveInput::new(GestureLoop::new(Arc::clone(&model), joint_model, mapper, config, gestures).map_err(js)?, source, announce),
            (Some(scene), left) => {
                let manip = match left {
                    Some(left) => ManipulationLoop::two_handed([(Arc::clone(left), mapper.clone()), (Arc::clone(&model), mapper)], joint_model, config, gestures, &scene, GraspParams::default()),
                    None => ManipulationLoop::new(Arc::clone(&model), joint_model, mapper, config, gestures, &scene, GraspParams::default()),
                }
                .map_err(js)?;
                LiveInput::with_scene(manip, source, announce)
            }
        }
        .map_err(stream)?;
        let session = Session::new(model, left.map(|l| (l, Side::Left)), joint_model).map_err(stream)?;
        let view = input.view();
        let record = Record { time: 0.0, side: Side::Right, hand: None, tracker: None, arrival: None };
        let sensors = settings.sensors().map_err(stream)?;
        Ok(LocalStream { session, input, view, frames: [Vec::new(), Vec::new()], texts: Vec::new(), record, sensors, rate: FrameRate::default(), clock: 0.0 })
    }

    /// Puts the scene's objects back where the scene has them: `dqhand demo`'s played
    /// recording started over (its relay says so in its place among the records).
    #[wasm_bindgen(js_name = resetScene)]
    pub fn reset_scene(&self) {
        self.input.reset_scene();
    }

    /// Recognises `gestures` (a gesture file's text) from now on: the set `dqhand demo` learned
    /// a gesture into, sent by its relay.
    ///
    /// # Errors
    /// Text that is not a gesture file, or one the input's commands do not fit.
    #[wasm_bindgen(js_name = setGestures)]
    pub fn set_gestures(&mut self, gestures: &str) -> Result<(), JsError> {
        let set = GestureSet::from_json(gestures, "the relayed gestures").map_err(js)?;
        self.input.set_gestures(set).map_err(|e| JsError::new(&e.to_string()))
    }

    /// The hello message (JSON text), as the server's first message.
    pub fn hello(&self) -> String {
        self.session.hello(MAX_COMMAND_BYTES, Some(&self.input))
    }

    /// How many hands are shown (1 or 2): the topologies the page reads.
    #[wasm_bindgen(getter, js_name = handCount)]
    pub fn hand_count(&self) -> usize {
        self.session.topologies().len()
    }

    /// Hand `k`'s encoded topology (a binary message, as the server's).
    pub fn topology(&self, k: usize) -> Vec<u8> {
        self.session.topologies().get(k).map(|t| t.encode()).unwrap_or_default()
    }

    /// A command of the page (JSON text, docs/protocol.md). Returns what the page must do
    /// itself: `""` nothing, `"record"` or `"stop-recording"` (the page records its own input).
    ///
    /// # Errors
    /// A command that cannot be read or applied, or one the page's engine does not do
    /// (learning a gesture live); the one-line message names it. Nothing changes then.
    pub fn command(&mut self, text: &str) -> Result<String, JsError> {
        let command = Command::parse_bounded(text).map_err(|e| JsError::new(&e))?;
        if matches!(command, Command::Ack { .. }) {
            return Ok(String::new());
        }
        match self.session.apply(&command).map_err(|e| JsError::new(&e.to_string()))? {
            Applied::Frame => Ok(String::new()),
            Applied::Hello => {
                self.texts.push(self.hello());
                Ok(String::new())
            }
            Applied::Record(on) => Ok(if on { "record" } else { "stop-recording" }.to_owned()),
            Applied::Learn(_) => Err(JsError::new("learn: learning a gesture needs dqhand demo (the page's engine does not learn yet)")),
        }
    }

    /// One record of the page's live input (a JSON line, docs/formats.md).
    ///
    /// # Errors
    /// A record that cannot be read or is refused; the input counts it and goes on.
    pub fn push(&mut self, line: &str) -> Result<(), JsError> {
        let input = &self.input;
        if read(line, Side::Right, &self.sensors, &mut self.record, |r| input.reject(r))? {
            input.push(&self.record, |_| {}).map_err(|r| JsError::new(&r.to_string()))?;
        }
        Ok(())
    }

    /// Advances the engine by `dt` seconds (the page's frame time): the timeline plays, the
    /// hands follow the live input (in a scene, the rendered hands), and each hand's frame is
    /// written. Returns how many frames ([`Self::frame_ptr`]); the text messages it made wait
    /// in [`Self::take_texts`].
    pub fn step(&mut self, dt: f32) -> usize {
        let dt = dt.clamp(0.0, MAX_STEP_S);
        self.session.advance(dt);
        let update = self.input.update(&mut self.session, &mut self.view);
        if update.hello {
            self.texts.push(self.hello());
        }
        self.texts.extend([update.message, update.scene].into_iter().flatten());
        self.clock += f64::from(dt);
        let fps = self.rate.tick(self.clock);
        self.session.render(fps, &mut self.frames[0]);
        1 + usize::from(self.session.render_second(fps, &mut self.frames[1]))
    }

    /// Where frame `k` of the last step starts in the module's memory (`wasmMemory`).
    #[wasm_bindgen(js_name = framePtr)]
    pub fn frame_ptr(&self, k: usize) -> *const u8 {
        self.frames[k.min(1)].as_ptr()
    }

    /// Frame `k`'s length in bytes.
    #[wasm_bindgen(js_name = frameLen)]
    pub fn frame_len(&self, k: usize) -> usize {
        self.frames[k.min(1)].len()
    }

    /// The text messages (JSON: hello, input, scene) made since the last call.
    #[wasm_bindgen(js_name = takeTexts)]
    pub fn take_texts(&mut self) -> Vec<String> {
        std::mem::take(&mut self.texts)
    }
}
