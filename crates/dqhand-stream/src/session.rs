//! One viewer's engine: the pose a person is editing or a sequence is playing, posed and
//! skinned with the chosen methods each frame and written as a binary frame.
//!
//! The engine is the single source of truth: the page only draws what a frame carries and
//! sends [`Command`]s back. All per-frame buffers are allocated when the session starts.

use std::sync::Arc;
use web_time::Instant;

use glam::{EulerRot, Quat, Vec3};
use serde_json::json;

use crate::frame::{FrameHeader, FrameWriter, Topology, STATE_LIMITS, STATE_PLAYING, VERSION};
use crate::{Action, Command, LearnRequest, LiveInput};
use dqhand::engine::Engine;
use dqhand::gesture::{gesture, Sequence, GESTURES};
use dqhand::hand::Side;
use dqhand::kinematics::{HandRig, JointModel, Limits, Pose};
use dqhand::math::DualQuat;
use dqhand::metrics::VertexDistortion;
use dqhand::model::Model;
use dqhand::skin::{Method, MethodSet};
use crate::{Error, Result};

/// Length of a move to a gesture chosen without a duration, seconds.
pub const GESTURE_SECONDS: f32 = 0.6;

/// What applying a command changed, for the transport.
#[derive(Clone, Debug, PartialEq)]
pub enum Applied {
    /// The pose or view changed; the next frame shows it.
    Frame,
    /// The joint model changed: send [`Session::hello`] again (the DOF list is new).
    Hello,
    /// Start (true) or stop recording the live input: the transport's to do.
    Record(bool),
    /// Learn a gesture from the live input: the transport's to do.
    Learn(LearnRequest),
}

/// The state of one connected viewer: the pose source (edits, the timeline, a move to a
/// gesture) of its own [`Engine`], and the view; with a live input of two hands, the second
/// hand too, which follows that input only.
pub struct Session {
    hand: ShownHand,
    pose: Pose,
    /// The second hand, its side and its pose (the live input's other hand).
    second: Option<(ShownHand, Side, Pose)>,
    /// The wrist set by the user, kept over sequence playback (which leaves the wrist alone).
    wrist: Option<DualQuat>,
    heatmap: bool,
    timeline: Sequence,
    time: f32,
    playing: bool,
    transition: Option<(Sequence, f32)>,
    sequence: u32,
}

/// One hand drawn by a viewer: its engine and the buffers its frames are written from.
struct ShownHand {
    engine: Engine,
    /// One distortion buffer per method, in [`Method::ALL`] order.
    distortion: [Vec<f32>; 4],
    vertex_distortion: VertexDistortion,
    joints: Vec<[f32; 3]>,
}

impl ShownHand {
    fn new(model: Arc<Model>, joint_model: JointModel) -> Result<Self> {
        let mesh = &model.mesh;
        let n = mesh.vertex_count();
        let vertex_distortion = VertexDistortion::new(&mesh.positions(), mesh.indices());
        let engine = Engine::new(model, joint_model)?;
        let joints = vec![[0.0; 3]; engine.kinematics().skeleton().len()];
        Ok(Self { engine, distortion: Method::ALL.map(|_| vec![0.0; n]), vertex_distortion, joints })
    }

    fn topology(&self, hand: u16) -> Topology {
        Topology {
            hand,
            vertex_count: self.engine.model().mesh.vertex_count() as u32,
            indices: self.engine.model().mesh.indices().to_vec(),
            parents: self.engine.kinematics().skeleton().joints().iter().map(|j| j.parent).collect(),
        }
    }

    /// Poses and skins `pose` with the methods in view (and their distortion with the heat
    /// map on) and writes its frame, on `header`'s scalars, into `out`. Allocates nothing once
    /// `out` has held a frame.
    fn render(&mut self, pose: &Pose, mut header: FrameHeader, out: &mut Vec<u8>) {
        let start = Instant::now();
        self.engine.step(pose);
        let methods = self.engine.skin().methods();
        if header.distortion {
            for &m in methods.as_slice() {
                self.vertex_distortion.compute(self.engine.deformed(m).expect("the methods in view are skinned").positions(), &mut self.distortion[m.index()]);
            }
        }
        for (j, w) in self.joints.iter_mut().zip(self.engine.kinematics().world()) {
            *j = w.translation.into();
        }
        let (rotation, translation) = pose.wrist.unwrap_or(self.engine.kinematics().rig().rest_wrist()).to_rotation_translation();
        header.wrist[..3].copy_from_slice(&translation.to_array());
        header.wrist[3..].copy_from_slice(&rotation.to_array());
        header.engine_us = start.elapsed().as_secs_f32() * 1e6;
        header.vertex_count = self.engine.model().mesh.vertex_count() as u32;
        header.joint_count = self.joints.len() as u32;
        header.dof_count = pose.angles.len() as u32;
        header.methods = methods;
        let mut w = FrameWriter::begin(out, header);
        w.floats(&pose.angles).floats(self.joints.as_flattened());
        for &m in methods.as_slice() {
            let deformed = self.engine.deformed(m).expect("the methods in view are skinned");
            w.floats(deformed.positions().as_flattened()).floats(deformed.normals().as_flattened());
            if header.distortion {
                w.floats(&self.distortion[m.index()]);
            }
        }
        w.finish();
    }
}

impl Session {
    /// A session on `model` with the `joint_model`'s DOFs, showing DQB and playing the
    /// bundled gesture sequence; with `second`, a second hand (of the other side) that
    /// follows the live input ([`Self::follow_second`]).
    ///
    /// # Errors
    /// As [`Engine::new`]: [`dqhand::Error::MissingJoint`] if a model's skeleton lacks
    /// the WebXR hand joints, [`dqhand::Error::JointFrame`] if its joint frames are not WebXR's.
    pub fn new(model: Arc<Model>, second: Option<(Arc<Model>, Side)>, joint_model: JointModel) -> Result<Self> {
        let second = second.map(|(m, side)| ShownHand::new(m, joint_model).map(|h| (h, side, Pose::rest(joint_model.dof_count())))).transpose()?;
        Ok(Self {
            hand: ShownHand::new(model, joint_model)?,
            pose: Pose::rest(joint_model.dof_count()),
            second,
            wrist: None,
            heatmap: false,
            timeline: Sequence::gestures(joint_model),
            time: 0.0,
            playing: true,
            transition: None,
            sequence: 0,
        })
    }

    /// The JSON greeting: the model, the DOFs with their ranges, the gestures, sequences and
    /// methods the page can ask for, the live input driving the hand and its scene, if any.
    #[must_use]
    pub fn hello(&self, max_message_bytes: usize, input: Option<&LiveInput>) -> String {
        let model = self.joint_model();
        let (description, mesh) = (&self.hand.engine.model().description, &self.hand.engine.model().mesh);
        let dofs: Vec<_> = model
            .dofs()
            .map(|d| json!({ "name": d.name(), "joint": d.joint, "min_deg": d.min_deg, "max_deg": d.max_deg }))
            .collect();
        json!({
            "type": "hello",
            "version": VERSION,
            "description": description,
            "vertices": mesh.vertex_count(),
            "triangles": mesh.triangle_count(),
            "joints": self.hand.engine.kinematics().skeleton().names().collect::<Vec<_>>(),
            "second_hand": self.second.as_ref().map(|(h, side, _)| {
                let model = h.engine.model();
                json!({ "side": side.name(), "description": model.description, "vertices": model.mesh.vertex_count(), "triangles": model.mesh.triangle_count() })
            }),
            "joint_model": model.as_str(),
            "joint_models": JointModel::ALL.map(JointModel::as_str),
            "dofs": dofs,
            "gestures": GESTURES.map(|g| g.name),
            "sequence": { "name": self.timeline.name(), "duration": self.timeline.duration() },
            "methods": Method::ALL.map(Method::as_str),
            "gesture_seconds": GESTURE_SECONDS,
            "max_message_bytes": max_message_bytes,
            "input": input.and_then(LiveInput::describe),
            "scene": input.and_then(LiveInput::scene),
        })
        .to_string()
    }

    /// The mesh and skeleton structure of each hand (the second hand's after the first's),
    /// sent once after the first hello.
    #[must_use]
    pub fn topologies(&self) -> Vec<Topology> {
        std::iter::once(self.hand.topology(0)).chain(self.second.as_ref().map(|(h, _, _)| h.topology(1))).collect()
    }

    /// The pose shown now.
    #[must_use]
    pub fn pose(&self) -> &Pose {
        &self.pose
    }

    /// The joint model of the pose.
    #[must_use]
    pub fn joint_model(&self) -> JointModel {
        self.rig().model()
    }

    fn rig(&self) -> &HandRig {
        self.hand.engine.kinematics().rig()
    }

    /// Each hand's engine: the first, then the second if any.
    fn engines(&mut self) -> impl Iterator<Item = &mut Engine> {
        std::iter::once(&mut self.hand.engine).chain(self.second.as_mut().map(|(h, _, _)| &mut h.engine))
    }

    /// Shows `methods` on every hand.
    fn set_methods(&mut self, methods: MethodSet) {
        self.engines().for_each(|e| e.set_methods(methods));
    }

    /// What a pose without a wrist stands for.
    fn rest_wrist(&self) -> DualQuat {
        self.rig().rest_wrist()
    }

    /// Applies one command from the page. Acks are the transport's business and change
    /// nothing here.
    ///
    /// # Errors
    /// [`Error::Command`] or [`dqhand::Error::UnknownName`] naming the bad value; the session is
    /// unchanged then.
    pub fn apply(&mut self, command: &Command) -> Result<Applied> {
        match command {
            Command::Ack { .. } => {}
            Command::View { methods } => {
                let set = MethodSet::parse(methods).map_err(|e| match e {
                    dqhand::Error::Methods(why) => Error::Command(format!("view: {why}")),
                    other => other.into(),
                })?;
                self.set_methods(set);
            }
            Command::JointModel { name } => {
                let model: JointModel = name.parse()?;
                if model != self.joint_model() {
                    self.set_joint_model(model)?;
                    return Ok(Applied::Hello);
                }
            }
            Command::Angle { dof, deg } => {
                let i = self.joint_model().dof_index(dof)?;
                let d = self.joint_model().dofs().nth(i).expect("index from the model");
                let (lo, hi) = match self.hand.engine.kinematics().limits() {
                    Limits::Anatomical => (d.min_deg, d.max_deg),
                    Limits::Off => (-180.0, 180.0),
                };
                finite("angle", &[*deg])?;
                self.stop();
                self.pose.angles[i] = deg.clamp(lo, hi).to_radians();
            }
            Command::Wrist { translation, rotation_deg } => {
                finite("wrist", translation)?;
                finite("wrist", rotation_deg)?;
                let [x, y, z] = rotation_deg.map(f32::to_radians);
                let rotation = Quat::from_euler(EulerRot::ZYX, z, y, x);
                self.stop();
                self.wrist = Some(DualQuat::from_rotation_translation(rotation, Vec3::from(*translation)));
                self.pose.wrist = self.wrist;
            }
            Command::Gesture { name, seconds } => {
                let g = gesture(name)?;
                let seconds = seconds.unwrap_or(GESTURE_SECONDS);
                if !(0.0..=10.0).contains(&seconds) {
                    return Err(Error::Command(format!("gesture: {seconds} seconds (0 to 10)")));
                }
                self.stop();
                let model = self.joint_model();
                let mut to = g.pose(model);
                to.wrist = self.wrist;
                self.transition = Some((Sequence::transition(model, &self.pose, to, seconds), 0.0));
            }
            Command::Play {} => {
                self.transition = None;
                if self.time >= self.timeline.duration() {
                    self.time = 0.0;
                }
                self.playing = true;
            }
            Command::Pause {} => self.playing = false,
            Command::Seek { time } => {
                finite("seek", &[*time])?;
                self.transition = None;
                self.time = time.clamp(0.0, self.timeline.duration());
                self.sample_timeline();
            }
            Command::Heatmap { on } => self.heatmap = *on,
            Command::Limits { on } => {
                let limits = if *on { Limits::Anatomical } else { Limits::Off };
                self.engines().for_each(|e| e.kinematics_mut().set_limits(limits));
            }
            Command::Rest {} => {
                self.stop();
                self.wrist = None;
                self.pose = Pose::rest(self.joint_model().dof_count());
            }
            Command::Record { on } => return Ok(Applied::Record(*on)),
            Command::Learn { name, seconds, not } => return LearnRequest::new(name, *seconds, *not).map(Applied::Learn).map_err(Error::Command),
        }
        Ok(Applied::Frame)
    }

    /// Shows `pose` (of `model`) from the live input: the timeline and any move stop, and
    /// the angles of DOFs the two joint models share are taken. Allocates nothing.
    pub fn follow(&mut self, pose: &Pose, model: JointModel) {
        self.stop();
        model.carry_angles(&pose.angles, self.joint_model(), &mut self.pose.angles);
        self.wrist = pose.wrist;
        self.pose.wrist = pose.wrist;
    }

    /// Shows `pose` (of `model`) on the second hand, if the session has one. Allocates nothing.
    pub fn follow_second(&mut self, pose: &Pose, model: JointModel) {
        let to = self.joint_model();
        if let Some((_, _, shown)) = &mut self.second {
            model.carry_angles(&pose.angles, to, &mut shown.angles);
            shown.wrist = pose.wrist;
        }
    }

    /// Applies a gesture command to the view: `next_method` shows the method after the first
    /// one in view alone (of all four), `split_view` shows all four side by side,
    /// `toggle_heatmap` turns the distortion heat map on or
    /// off.
    pub fn act(&mut self, action: Action) {
        match action {
            Action::NextMethod => {
                let first = self.methods().as_slice()[0];
                let next = Method::ALL[(first.index() + 1) % Method::ALL.len()];
                self.set_methods(MethodSet::new(&[next]).expect("one method is a valid set"));
            }
            Action::SplitView => self.set_methods(MethodSet::ALL),
            Action::ToggleHeatmap => self.heatmap = !self.heatmap,
        }
    }

    /// Whether the distortion heat map is on.
    #[must_use]
    pub fn heatmap(&self) -> bool {
        self.heatmap
    }

    /// The methods in view.
    #[must_use]
    pub fn methods(&self) -> MethodSet {
        self.hand.engine.skin().methods()
    }

    fn stop(&mut self) {
        self.playing = false;
        self.transition = None;
    }

    fn set_joint_model(&mut self, model: JointModel) -> Result<()> {
        let old = self.joint_model();
        // `pose`'s angles in `model`'s DOFs, with `wrist`.
        let carried = |pose: &Pose, wrist: Option<DualQuat>| {
            let mut to = Pose::rest(model.dof_count());
            old.carry_angles(&pose.angles, model, &mut to.angles);
            Pose { wrist, ..to }
        };
        self.hand.engine.set_joint_model(model)?;
        if let Some((hand, _, pose)) = &mut self.second {
            if let Err(e) = hand.engine.set_joint_model(model) {
                // Both hands or neither: the first goes back to the model it had.
                self.hand.engine.set_joint_model(old).expect("the joint model it had");
                return Err(e.into());
            }
            *pose = carried(pose, pose.wrist);
        }
        self.pose = carried(&self.pose, self.wrist);
        self.timeline = Sequence::gestures(model);
        self.time = self.time.min(self.timeline.duration());
        self.transition = None;
        Ok(())
    }

    fn sample_timeline(&mut self) {
        self.timeline.sample(self.time, self.rest_wrist(), &mut self.pose);
        self.pose.wrist = self.wrist;
    }

    /// Advances the timeline (looping) or the move to a gesture by `dt` seconds.
    pub fn advance(&mut self, dt: f32) {
        let rest_wrist = self.rest_wrist();
        if let Some((sequence, elapsed)) = &mut self.transition {
            *elapsed += dt;
            sequence.sample(*elapsed, rest_wrist, &mut self.pose);
            if *elapsed >= sequence.duration() {
                self.transition = None;
            }
        } else if self.playing {
            let d = self.timeline.duration();
            self.time = if d > 0.0 { (self.time + dt) % d } else { 0.0 };
            self.sample_timeline();
        }
    }

    /// Poses and skins the current pose with the methods in view and writes the frame into
    /// `out` (cleared first). Allocates nothing once `out` has held a frame.
    ///
    /// * `engine_fps` — the rate the transport is achieving, reported to the page.
    pub fn render(&mut self, engine_fps: f32, out: &mut Vec<u8>) {
        let header = self.header(engine_fps);
        self.hand.render(&self.pose, header, out);
    }

    /// As [`Self::render`], the second hand's frame, if the session has a second hand
    /// (`false`: none, `out` untouched).
    pub fn render_second(&mut self, engine_fps: f32, out: &mut Vec<u8>) -> bool {
        // No second hand takes no sequence number: the transport counts the frames it sends.
        let Some(header) = self.second.is_some().then(|| FrameHeader { second: true, ..self.header(engine_fps) }) else { return false };
        let (hand, _, pose) = self.second.as_mut().expect("checked above");
        hand.render(pose, header, out);
        true
    }

    /// The scalars of the next frame (its sequence number taken).
    fn header(&mut self, engine_fps: f32) -> FrameHeader {
        let sequence = self.sequence;
        self.sequence = self.sequence.wrapping_add(1);
        FrameHeader {
            sequence,
            distortion: self.heatmap,
            engine_fps,
            time: self.time,
            duration: self.timeline.duration(),
            state: if self.playing { STATE_PLAYING } else { 0 } | if self.hand.engine.kinematics().limits() == Limits::Anatomical { STATE_LIMITS } else { 0 },
            ..FrameHeader::default()
        }
    }
}

fn finite(what: &str, values: &[f32]) -> Result<()> {
    match values.iter().find(|v| !v.is_finite()) {
        Some(v) => Err(Error::Command(format!("{what}: {v} is not a finite number"))),
        None => Ok(()),
    }
}
