//! One hand of the 3D manipulation loop: its records (pipeline, recognition, the scene's
//! commands), its rendered hand solved against the scene, and its grasp.

use std::sync::Arc;

use glam::{Quat, Vec3};

use super::{CommandTable, GestureLoop};
use crate::collision::{fit_proxies, Contact, ContactConstraint, HandProxies, ObjectColliders, PROXY_MARGIN};
use crate::gesture::{Events, GestureSet};
use crate::grasp::{Grasp, GraspEvent, GraspParams};
use crate::input::{GloveMapper, InputConfig, Record, Rejection, Tracking};
use crate::kinematics::{HandKinematics, JointModel, Side};
use crate::model::Model;
use crate::physics::ScenePhysics;
use crate::scene::{Scene, SceneAction, SceneCommand};
use crate::Result;

/// One hand in a manipulation loop.
pub struct ManipulatingHand {
    input: GestureLoop,
    scene_commands: Option<CommandTable<SceneAction>>,
    pub(super) constraint: ContactConstraint,
    pub(super) grasp: Grasp,
    /// The hand's index among the physics' hands.
    pub(super) physics: usize,
    was_tracking: bool,
}

impl ManipulatingHand {
    /// `model` posed from records (as [`GestureLoop::new`]) among `scene`'s objects, its
    /// proxies added to `physics`.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn new(model: Arc<Model>, joint_model: JointModel, glove: Option<GloveMapper>, config: InputConfig, gestures: Option<GestureSet>, scene: &Scene, params: GraspParams, physics: &mut ScenePhysics, objects: Option<&mut ObjectColliders>) -> Result<Self> {
        let input = GestureLoop::new(model.clone(), joint_model, glove, config, gestures)?;
        let scene_commands = match input.gestures() {
            Some(set) if !scene.actions.is_empty() => Some(CommandTable::new(&scene.actions, set)?),
            _ => None,
        };
        let rendered = input.kinematics().clone();
        let proxies = HandProxies::new(&fit_proxies(&model, PROXY_MARGIN), rendered.skeleton());
        let physics = physics.add_hand(&proxies);
        if let Some(objects) = objects {
            let obstacle = objects.add_hand(&proxies);
            debug_assert_eq!(obstacle, physics, "a hand has one index in both");
        }
        Ok(Self {
            input,
            scene_commands,
            constraint: ContactConstraint::new(proxies, rendered),
            grasp: Grasp::new(params, scene.objects.len()),
            physics,
            was_tracking: false,
        })
    }

    /// Takes one record; returns its gesture events and the scene command they complete.
    pub(super) fn push(&mut self, record: &Record) -> std::result::Result<(Events<'_>, Option<SceneCommand>), Rejection> {
        let events = self.input.push(record)?;
        let command = self.scene_commands.as_mut().and_then(|table| table.update(record.time, events.clone()));
        Ok((events, command))
    }

    pub(super) fn reject(&mut self, rejection: Rejection) {
        self.input.reject(rejection);
    }

    /// The scene's actions bound to `gestures`, to be set with [`Self::set_gestures`].
    pub(super) fn rebind(&self, gestures: &GestureSet) -> Result<Option<CommandTable<SceneAction>>> {
        self.scene_commands.as_ref().map(|t| t.rebind(gestures)).transpose()
    }

    pub(super) fn set_gestures(&mut self, gestures: GestureSet, scene_commands: Option<CommandTable<SceneAction>>) {
        self.input.set_gestures(gestures);
        self.scene_commands = scene_commands;
    }

    /// Lets go and forgets the rendered hand (a scene reset).
    pub(super) fn reset(&mut self) {
        self.grasp.clear();
        self.constraint.restart();
    }

    /// The first half of a frame at `now`: the tracked pose, and the held object following it
    /// (or let go).
    pub(super) fn follow(&mut self, now: f64) -> Option<GraspEvent> {
        self.input.advance(now);
        let tracking = self.tracked();
        if tracking && !self.was_tracking {
            // Tracking came back (or began): the rendered hand starts from the tracked one.
            self.constraint.restart();
        }
        self.was_tracking = tracking;
        self.constraint.track(self.input.pipeline().pose(), self.input.kinematics().world());
        self.grasp.follow(now, tracking, self.constraint.closure(), self.constraint.tracked_world(), self.constraint.world())
    }

    /// The second half, with the objects where they are now: the rendered pose solved, and a
    /// grasp detected on it.
    pub(super) fn solve(&mut self, now: f64, objects: &mut ObjectColliders, poses: &[(Quat, Vec3)], detect: bool) -> Option<GraspEvent> {
        objects.solving(Some(self.physics));
        self.constraint.solve(objects, self.grasp.held(), now);
        let tracking = self.tracked();
        let c = &self.constraint;
        let wrist = self.input.kinematics().rig().wrist();
        detect.then(|| self.grasp.detect(now, tracking, c.contacts(), c.closure(), c.world(), c.tracked_world(), wrist, poses)).flatten()
    }

    /// Takes hold of `object` (at `pose`) with the other hand, neither alone.
    pub(super) fn take_with_other(&mut self, now: f64, object: usize, pose: (Quat, Vec3)) -> GraspEvent {
        let c = &self.constraint;
        let wrist = self.input.kinematics().rig().wrist();
        self.grasp.take(now, object, pose, false, c.contacts(), c.closure(), c.world(), c.tracked_world(), wrist)
    }

    /// The hand's gesture now, while it is tracked.
    pub(super) fn gesture(&self) -> Option<&str> {
        self.input.gesture().filter(|_| self.tracked())
    }

    /// Where the tracked wrist is (world, m).
    pub(super) fn wrist(&self) -> Vec3 {
        let wrist = self.input.kinematics().rig().wrist();
        Vec3::from(self.constraint.tracked_world()[wrist].translation)
    }

    /// How far the tracked wrist is from the rendered one (tracked less rendered, m): into
    /// what stops the rendered hand.
    pub(super) fn pushed(&self) -> Vec3 {
        let wrist = self.input.kinematics().rig().wrist();
        let c = &self.constraint;
        Vec3::from(c.tracked_world()[wrist].translation - c.world()[wrist].translation)
    }

    /// The hand's proxies where the rendered hand is, for the physics (and, with `objects`,
    /// as obstacles to the other hand); none while the hand is lost.
    pub(super) fn place(&self, physics: &mut ScenePhysics, objects: Option<&mut ObjectColliders>) {
        let world = self.tracked().then(|| self.constraint.world());
        physics.move_hand(self.physics, world);
        if let Some(objects) = objects {
            objects.move_hand(self.physics, world);
        }
    }

    /// Whether the hand is tracked now ([`Self::tracking`]).
    pub(super) fn tracked(&self) -> bool {
        self.tracking() == Tracking::Tracking
    }

    /// Which hand this is (its model's).
    #[must_use]
    pub fn side(&self) -> Side {
        self.input.pipeline().retargeter().side()
    }

    /// Whether the hand is tracked.
    #[must_use]
    pub fn tracking(&self) -> Tracking {
        self.input.pipeline().tracking()
    }

    /// The object held, if any: its index in scene order.
    #[must_use]
    pub fn held(&self) -> Option<usize> {
        self.grasp.held()
    }

    /// The grasp state (what is held, and whether by this hand alone).
    #[must_use]
    pub fn grasp(&self) -> &Grasp {
        &self.grasp
    }

    /// The rendered hand's contacts after the last frame.
    #[must_use]
    pub fn contacts(&self) -> &[Contact] {
        self.constraint.contacts()
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
