//! The 3D manipulation loop (paper Figure 1, right; Figure 9): records drive the tracked
//! hand; its collision layer meets the scene's objects, which gives the rendered hand (it
//! never sinks in) and its contacts; grasping heuristics pick objects up, carry them and let
//! them go; the physics moves the rest. Gestures stay commands: the scene file's actions.
//!
//! One frame ([`ManipulationLoop::step`]) in order:
//! 1. the tracked pose (records pushed since the last frame, tracking loss judged now);
//! 2. the held object follows the tracked hand, or is released;
//! 3. the rendered pose is solved against the objects where they now are;
//! 4. a grasp is detected on the rendered contacts;
//! 5. the physics steps (the held object moved by the hand), and the objects' poses are read.

use std::sync::Arc;

use glam::{Quat, Vec3};

use super::{CommandTable, GestureLoop};
use crate::collision::{fit_proxies, Contact, ContactConstraint, HandProxies, ObjectColliders, PROXY_MARGIN};
use crate::gesture::{Events, GestureSet};
use crate::grasp::{Grasp, GraspEvent, GraspParams};
use crate::input::{GloveMapper, InputConfig, Record, Rejection, Tracking};
use crate::kinematics::{HandKinematics, JointModel};
use crate::model::Model;
use crate::physics::ScenePhysics;
use crate::scene::{Scene, SceneAction, SceneCommand};
use crate::Result;

/// The longest physics step taken at once, s: a stall in the records must not launch objects.
const MAX_STEP_S: f64 = 1.0 / 30.0;

/// One hand manipulating one scene.
pub struct ManipulationLoop {
    input: GestureLoop,
    scene_commands: Option<CommandTable<SceneAction>>,
    /// The scene command the last record triggered.
    command: Option<SceneCommand>,
    objects: ObjectColliders,
    names: Vec<String>,
    constraint: ContactConstraint,
    grasp: Grasp,
    physics: ScenePhysics,
    poses: Vec<(Quat, Vec3)>,
    last: Option<f64>,
    reset_due: bool,
    was_tracking: bool,
}

impl ManipulationLoop {
    /// A loop posing `model` with `joint_model` from records (as [`GestureLoop::new`]) in
    /// `scene`. With `gestures`, the scene's actions are commands.
    ///
    /// # Errors
    /// As [`GestureLoop::new`]; as [`ObjectColliders::new`] for the scene's meshes; a scene
    /// action naming a gesture not recognised ([`CommandTable::new`]).
    pub fn new(model: Arc<Model>, joint_model: JointModel, glove: Option<GloveMapper>, config: InputConfig, gestures: Option<GestureSet>, scene: &Scene, params: GraspParams) -> Result<Self> {
        let input = GestureLoop::new(model.clone(), joint_model, glove, config, gestures)?;
        let scene_commands = match input.gestures() {
            Some(set) if !scene.actions.is_empty() => Some(CommandTable::new(&scene.actions, set)?),
            _ => None,
        };
        let rendered = input.kinematics().clone();
        let proxies = HandProxies::new(&fit_proxies(&model, PROXY_MARGIN), rendered.skeleton());
        let constraint = ContactConstraint::new(proxies.clone(), rendered);
        let objects = ObjectColliders::new(scene)?;
        let mut physics = ScenePhysics::new(scene, &objects);
        physics.add_hand(&proxies);
        let n = scene.objects.len();
        let poses = (0..n).map(|i| physics.pose(i)).collect();
        Ok(Self {
            input,
            scene_commands,
            command: None,
            names: scene.objects.iter().map(|o| o.name.clone()).collect(),
            objects,
            constraint,
            grasp: Grasp::new(params, n),
            physics,
            poses,
            last: None,
            reset_due: false,
            was_tracking: false,
        })
    }

    /// Takes one record (as [`GestureLoop::push`]) and returns the gesture events
    /// it caused; a scene action its gesture completes ([`Self::command`]) is carried out at
    /// the next [`Self::step`]. Allocates nothing.
    ///
    /// # Errors
    /// The record's refusal; the hand keeps its pose.
    pub fn push(&mut self, record: &Record) -> std::result::Result<Events<'_>, Rejection> {
        self.command = None;
        let events = self.input.push(record)?;
        if let Some(table) = &mut self.scene_commands {
            self.command = table.update(record.time, events.clone());
            self.reset_due |= self.command == Some(SceneCommand::Reset);
        }
        Ok(events)
    }

    /// Recognises `gestures` from now on ([`GestureLoop::set_gestures`]); the scene's actions
    /// (of a loop made with gestures: one made without has none bound) are bound to them by
    /// name.
    ///
    /// # Errors
    /// A scene action naming a gesture `gestures` lacks; the loop is then unchanged.
    pub fn set_gestures(&mut self, gestures: GestureSet) -> Result<()> {
        let scene_commands = self.scene_commands.as_ref().map(|t| t.rebind(&gestures)).transpose()?;
        self.input.set_gestures(gestures);
        self.scene_commands = scene_commands;
        Ok(())
    }

    /// The scene command (a row of the scene's `actions`) that the last record triggered.
    #[must_use]
    pub fn command(&self) -> Option<SceneCommand> {
        self.command
    }

    /// Counts a record refused before it reached the loop.
    pub fn reject(&mut self, rejection: Rejection) {
        self.input.reject(rejection);
    }

    /// Puts every object back where the scene file has it, at rest, and lets go.
    pub fn reset(&mut self) {
        self.reset_due = true;
    }

    /// One frame at `now` (s; the records' clock): see the module documentation. Returns
    /// the grasp or release it caused. Its own work allocates nothing; rapier's step inside
    /// it allocates a few times a frame.
    pub fn step(&mut self, now: f64) -> Option<GraspEvent> {
        self.input.advance(now);
        let dt = self.last.map_or(1.0 / 60.0, |last| (now - last).clamp(0.0, MAX_STEP_S));
        self.last = Some(now);
        if std::mem::take(&mut self.reset_due) {
            self.physics.reset();
            self.grasp.clear();
            self.constraint.restart();
            self.read_poses();
        }
        let tracking = self.tracking() == Tracking::Tracking;
        if tracking && !self.was_tracking {
            // Tracking came back (or began): the rendered hand starts from the tracked one.
            self.constraint.restart();
        }
        self.was_tracking = tracking;
        let tracked = self.input.kinematics();
        self.constraint.track(self.input.pipeline().pose(), tracked.world());
        let mut event = self.grasp.follow(now, tracking, self.constraint.closure(), self.constraint.tracked_world(), self.constraint.world());
        if let Some((q, t)) = self.grasp.target() {
            let held = self.grasp.held().expect("a target is a held object's");
            let t = self.objects.above_table(held, q, t);
            self.objects.set_pose(held, q, t);
            self.poses[held] = (q, t);
        }
        self.constraint.solve(&self.objects, self.grasp.held(), now);
        if event.is_none() {
            event = self.grasp.detect(now, tracking, self.constraint.contacts(), self.constraint.closure(), self.constraint.world(), self.constraint.tracked_world(), tracked.rig().wrist(), &self.poses);
        }
        match event {
            Some(GraspEvent::Grasp { object }) => self.constraint.grip(object, &self.objects.objects()[object].pose),
            Some(GraspEvent::Release { object, linvel, angvel }) => self.physics.release(object, linvel, angvel),
            None => {}
        }
        if let Some(held) = self.grasp.held() {
            let (q, t) = self.poses[held];
            self.physics.hold(held, q, t);
        }
        self.physics.move_hand(self.constraint.world());
        self.physics.step(dt as f32);
        self.read_poses();
        event
    }

    fn read_poses(&mut self) {
        for i in 0..self.poses.len() {
            let (q, t) = self.physics.pose(i);
            self.poses[i] = (q, t);
            self.objects.set_pose(i, q, t);
        }
    }

    /// Whether the hand is tracked.
    #[must_use]
    pub fn tracking(&self) -> Tracking {
        self.input.pipeline().tracking()
    }

    /// The objects the last [`Self::step`] put back where the scene file has them, because
    /// they had left the room's reach ([`crate::physics::REACH_M`], or through the floor at
    /// [`crate::physics::FLOOR_Y`]): an application reports them.
    #[must_use]
    pub fn returned(&self) -> &[usize] {
        self.physics.returned()
    }

    /// The object held, if any: its index in scene order (its name in [`Self::names`]).
    #[must_use]
    pub fn held(&self) -> Option<usize> {
        self.grasp.held()
    }

    /// The rendered hand's contacts after the last frame.
    #[must_use]
    pub fn contacts(&self) -> &[Contact] {
        self.constraint.contacts()
    }

    /// The objects' names, in scene order.
    #[must_use]
    pub fn names(&self) -> &[String] {
        &self.names
    }

    /// Each object's pose after the last frame (rotation, translation), in scene order.
    #[must_use]
    pub fn poses(&self) -> &[(Quat, Vec3)] {
        &self.poses
    }

    /// The objects' shapes, where they are after the last frame.
    #[must_use]
    pub fn objects(&self) -> &ObjectColliders {
        &self.objects
    }

    /// The contact constraint (the tracked and rendered poses, finger closures).
    #[must_use]
    pub fn constraint(&self) -> &ContactConstraint {
        &self.constraint
    }

    /// The rendered hand's kinematics layer, posed once per frame by the contact constraint:
    /// what a [`crate::skin::SkinLayer`] deforms for the hand the user sees.
    #[must_use]
    pub fn rendered(&self) -> &HandKinematics {
        self.constraint.kinematics()
    }

    /// The gesture loop under it (pipeline, recognised gesture).
    #[must_use]
    pub fn input(&self) -> &GestureLoop {
        &self.input
    }
}
