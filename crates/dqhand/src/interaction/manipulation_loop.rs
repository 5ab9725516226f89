//! The 3D manipulation loop (paper Figure 1, right; Figure 9): records drive the tracked
//! hand; its collision layer meets the scene's objects, which gives the rendered hand (it
//! never sinks in) and its contacts; grasping heuristics pick objects up, carry them and let
//! them go; the physics moves the rest. Gestures stay commands: the scene file's actions.
//!
//! One frame ([`ManipulationLoop::step`]) in order, each hand in turn where there are two:
//! 1. the tracked pose (records pushed since the last frame, tracking loss judged now);
//! 2. the held object follows the tracked hand, or is released; with two hands, what both
//!    hold takes the fit of both, a hand-over keeps what one lets go in the other, and the
//!    gestures of both hands are recognised;
//! 3. the rendered pose is solved against the objects where they now are (and the other hand,
//!    as last solved), and its proxies placed in the physics (none while the hand is lost: what
//!    rested on it falls);
//! 4. a grasp is detected on the rendered contacts (a hand's own, then one of both hands);
//! 5. the physics steps (the held objects moved by the hands), and the objects' poses are read.

use std::sync::Arc;

use glam::{Quat, Vec3};

use super::ManipulatingHand;
use crate::collision::{ObjectColliders, STOP_DISTANCE};
use crate::gesture::{Events, GestureSet, TwoHandEvent, TwoHandRecognizer};
use crate::grasp::{Grasp, GraspEvent, GraspParams};
use crate::input::{GloveMapper, InputConfig, Record, Rejection};
use crate::kinematics::{JointModel, Side};
use crate::math::rigid_fit;
use crate::model::Model;
use crate::physics::ScenePhysics;
use crate::scene::{Scene, SceneCommand};
use crate::skin::Crew;
use crate::{Error, Result};

/// The longest physics step taken at once, s: a stall in the records must not launch objects.
const MAX_STEP_S: f64 = 1.0 / 30.0;

/// Most holding points of one object: both hands' ([`Grasp::holding_points`]).
const MAX_HOLDING_POINTS: usize = 2 * crate::grasp::MAX_HOLDING_POINTS;

/// What a frame changed: per hand (in [`ManipulationLoop::hands`] order), and of both.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct HandEvents([Option<GraspEvent>; 2], [Option<TwoHandEvent>; 2]);

impl HandEvents {
    /// Hand `hand`'s grasp or release this frame.
    #[must_use]
    pub fn of(&self, hand: usize) -> Option<GraspEvent> {
        self.0.get(hand).copied().flatten()
    }

    /// Every hand's event: (hand, event).
    pub fn iter(&self) -> impl Iterator<Item = (usize, GraspEvent)> + '_ {
        self.0.iter().enumerate().filter_map(|(k, e)| e.map(|e| (k, e)))
    }

    /// The two-hand gesture that ended this frame and the one that began
    /// ([`ManipulationLoop::two_hand_gestures`]).
    pub fn two_hand(&self) -> impl Iterator<Item = TwoHandEvent> + '_ {
        self.1.iter().flatten().copied()
    }
}

/// One or two hands manipulating one scene.
pub struct ManipulationLoop {
    hands: Vec<ManipulatingHand>,
    /// The scene command the last record triggered.
    command: Option<SceneCommand>,
    objects: ObjectColliders,
    names: Vec<String>,
    physics: ScenePhysics,
    poses: Vec<(Quat, Vec3)>,
    params: GraspParams,
    /// How far apart the two hands' contacts were when they took an object between them.
    between: f32,
    /// Gestures of both hands, recognised in a loop of two with recognition on.
    two_hand: Option<TwoHandRecognizer>,
    last: Option<f64>,
    reset_due: bool,
}

/// An object let go this frame: the sums of the velocities its hands gave it, how many of
/// them moved it, and the physics' indices of the hands letting go of it.
#[derive(Clone, Copy)]
struct Released {
    object: usize,
    linvel: Vec3,
    angvel: Vec3,
    moved: f32,
    hands: [usize; 2],
    count: usize,
}

impl ManipulationLoop {
    /// A loop posing `model` with `joint_model` from records (as [`GestureLoop::new`]) in
    /// `scene`: one hand, which records of either side drive (the other side mirrored, as
    /// the [`crate::input::Retargeter`] does). With `gestures`, the scene's actions are
    /// commands.
    ///
    /// # Errors
    /// As [`GestureLoop::new`]; as [`ObjectColliders::new`] for the scene's meshes; a scene
    /// action naming a gesture not recognised ([`CommandTable::new`]).
    ///
    /// [`GestureLoop::new`]: super::GestureLoop::new
    /// [`CommandTable::new`]: super::CommandTable::new
    pub fn new(model: Arc<Model>, joint_model: JointModel, glove: Option<GloveMapper>, config: InputConfig, gestures: Option<GestureSet>, scene: &Scene, params: GraspParams) -> Result<Self> {
        Self::with_hands(vec![(model, glove)], joint_model, config, gestures, scene, params)
    }

    /// A loop of two hands: `hands`, a left and a right model each built as itself (and the
    /// glove mapping of each, if gloves drive them); a record drives the hand of its side.
    /// Each hand grasps by itself; both hold what they grasp together (see [`crate::grasp`]).
    /// With `gestures` (holding `open_palm`), the built-in two-hand gestures are recognised too
    /// ([`Self::set_two_hand_gestures`]).
    ///
    /// # Errors
    /// As [`Self::new`]; two models of one side.
    pub fn two_handed(hands: [(Arc<Model>, Option<GloveMapper>); 2], joint_model: JointModel, config: InputConfig, gestures: Option<GestureSet>, scene: &Scene, params: GraspParams) -> Result<Self> {
        let mut manip = Self::with_hands(hands.into(), joint_model, config, gestures, scene, params)?;
        let [a, b] = [0, 1].map(|k| manip.hands[k].side());
        if a == b {
            return Err(Error::HandParameter(format!("two hands must be a left and a right one; both are {}", a.name())));
        }
        manip.two_hand = manip.hands[0].input().gestures().and_then(|set| TwoHandRecognizer::builtin(set).ok());
        Ok(manip)
    }

    fn with_hands(models: Vec<(Arc<Model>, Option<GloveMapper>)>, joint_model: JointModel, config: InputConfig, gestures: Option<GestureSet>, scene: &Scene, params: GraspParams) -> Result<Self> {
        let mut objects = ObjectColliders::new(scene)?;
        let mut physics = ScenePhysics::new(scene, &objects);
        let two = models.len() > 1;
        let hands = models
            .into_iter()
            .map(|(model, glove)| ManipulatingHand::new(model, joint_model, glove, config.clone(), gestures.clone(), scene, params, &mut physics, two.then_some(&mut objects)))
            .collect::<Result<Vec<_>>>()?;
        let poses = (0..scene.objects.len()).map(|i| physics.pose(i)).collect();
        Ok(Self {
            hands,
            command: None,
            names: scene.objects.iter().map(|o| o.name.clone()).collect(),
            objects,
            physics,
            poses,
            params,
            between: 0.0,
            two_hand: None,
            last: None,
            reset_due: false,
        })
    }

    /// The same loop closing each hand's fingers across `crew`'s threads
    /// ([`ContactConstraint::set_crew`]: the same frames, sooner where fingers close on
    /// objects). One crew serves any number of loops; a second loop's frame that meets the
    /// crew busy runs on its own thread.
    ///
    /// [`ContactConstraint::set_crew`]: crate::collision::ContactConstraint::set_crew
    #[must_use]
    pub fn with_crew(mut self, crew: Arc<Crew>) -> Self {
        for hand in &mut self.hands {
            hand.constraint.set_crew(Some(Arc::clone(&crew)));
        }
        self
    }

    /// The hand a record of `side` drives: the one of that side, the only one in a loop of
    /// one.
    #[must_use]
    pub fn hand_of(&self, side: crate::kinematics::Side) -> usize {
        self.hands.iter().position(|h| h.side() == side).filter(|_| self.hands.len() > 1).unwrap_or(0)
    }

    /// Takes one record (as [`GestureLoop::push`]) into the hand of its side
    /// ([`Self::hand_of`]) and returns the gesture events it caused there; a scene action its
    /// gesture completes ([`Self::command`]) is carried out at the next [`Self::step`].
    /// Allocates nothing.
    ///
    /// # Errors
    /// The record's refusal; the hand keeps its pose.
    ///
    /// [`GestureLoop::push`]: super::GestureLoop::push
    pub fn push(&mut self, record: &Record) -> std::result::Result<Events<'_>, Rejection> {
        self.command = None;
        let k = self.hand_of(record.side);
        let (events, command) = self.hands[k].push(record)?;
        self.command = command;
        self.reset_due |= command == Some(SceneCommand::Reset);
        Ok(events)
    }

    /// Recognises `gestures` from now on ([`GestureLoop::set_gestures`]) on every hand; the
    /// scene's actions (of a loop made with gestures: one made without has none bound) are
    /// bound to them by name.
    ///
    /// # Errors
    /// A scene action naming a gesture `gestures` lacks; the loop is then unchanged.
    ///
    /// [`GestureLoop::set_gestures`]: super::GestureLoop::set_gestures
    pub fn set_gestures(&mut self, gestures: GestureSet) -> Result<()> {
        let tables = self.hands.iter().map(|h| h.rebind(&gestures)).collect::<Result<Vec<_>>>()?;
        for (hand, table) in self.hands.iter_mut().zip(tables) {
            hand.set_gestures(gestures.clone(), table);
        }
        Ok(())
    }

    /// Recognises `gestures` of both hands from now on (a loop of two hands with recognition
    /// on: made without, no hand has a gesture), in place of the built-in ones; `None`: none.
    pub fn set_two_hand_gestures(&mut self, gestures: Option<TwoHandRecognizer>) {
        self.two_hand = gestures;
    }

    /// The gestures of both hands recognised, if any ([`HandEvents::two_hand`] says when one
    /// begins and ends).
    #[must_use]
    pub fn two_hand_gestures(&self) -> Option<&TwoHandRecognizer> {
        self.two_hand.as_ref()
    }

    /// The scene command (a row of the scene's `actions`) that the last record triggered.
    #[must_use]
    pub fn command(&self) -> Option<SceneCommand> {
        self.command
    }

    /// Counts a record refused before it reached the loop (against the first hand: a refused
    /// record's side is not to be trusted).
    pub fn reject(&mut self, rejection: Rejection) {
        self.hands[0].reject(rejection);
    }

    /// Puts every object back where the scene file has it, at rest, and lets go.
    pub fn reset(&mut self) {
        self.reset_due = true;
    }

    /// One frame at `now` (s; the records' clock): see the module documentation. Returns
    /// the grasps and releases it caused. Its own work allocates nothing; rapier's step
    /// inside it allocates a few times a frame.
    pub fn step(&mut self, now: f64) -> HandEvents {
        let dt = self.last.map_or(1.0 / 60.0, |last| (now - last).clamp(0.0, MAX_STEP_S));
        self.last = Some(now);
        if std::mem::take(&mut self.reset_due) {
            self.physics.reset();
            self.hands.iter_mut().for_each(ManipulatingHand::reset);
            self.read_poses();
        }
        let mut events = HandEvents::default();
        for (k, hand) in self.hands.iter_mut().enumerate() {
            events.0[k] = hand.follow(now);
        }
        if let [a, b] = &mut self.hands[..] {
            share(now, [a, b], &self.poses, self.between + self.params.apart_m, &mut events);
            if let Some(two) = &mut self.two_hand {
                let (left, right) = if a.side() == Side::Left { (&*a, &*b) } else { (&*b, &*a) };
                events.1 = two.update(left.gesture(), right.gesture(), left.wrist().distance(right.wrist()));
            }
        }
        for hand in &self.hands {
            if let (Some(held), Some((q, t))) = (hand.grasp.held(), hand.grasp.target()) {
                let t = self.objects.above_table(held, q, t);
                // It stops at a hand that does not hold it (and is not handing it over).
                let to = parry3d::math::Pose::from_parts(t, q);
                let share = self.hands.iter().filter(|other| other.grasp.held() != Some(held)).map(|other| self.objects.free_share(held, other.physics, &to, STOP_DISTANCE)).fold(1.0, f32::min);
                let (q, t) = if share < 1.0 {
                    let (q0, t0) = self.poses[held];
                    (q0.slerp(q, share).normalize(), t0.lerp(t, share))
                } else {
                    (q, t)
                };
                self.objects.set_pose(held, q, t);
                self.poses[held] = (q, t);
            }
        }
        // Each hand solved against the objects and the other hand as last placed.
        let two = self.hands.len() > 1;
        for (k, hand) in self.hands.iter_mut().enumerate() {
            let detected = hand.solve(now, &mut self.objects, &self.poses, events.0[k].is_none());
            events.0[k] = events.0[k].or(detected);
            hand.place(&mut self.physics, two.then_some(&mut self.objects));
        }
        self.objects.solving(None);
        if let [a, b] = &mut self.hands[..] {
            let (ca, cb) = (&a.constraint, &b.constraint);
            let (pa, pb) = (a.pushed(), b.pushed());
            let tracked = a.tracked() && b.tracked();
            let free = events.0.iter().all(Option::is_none) && tracked;
            if let Some(object) = free.then(|| Grasp::find_two_handed(now, (&a.grasp, ca.contacts(), ca.closure(), pa), (&b.grasp, cb.contacts(), cb.closure(), pb))).flatten() {
                let pose = self.poses[object];
                events.0 = [a.take_with_other(now, object, pose), b.take_with_other(now, object, pose)].map(Some);
                self.between = a.grasp.contact_centre().zip(b.grasp.contact_centre()).map_or(0.0, |(p, q)| p.distance(q));
            }
        }
        self.apply(&events);
        self.physics.step(dt as f32);
        self.read_poses();
        events
    }

    /// The frame's grasps and releases into the rendered hands and the physics: an object
    /// no hand holds any more leaves with the velocity its hands gave it (the mean of those
    /// that moved it: a still or lost hand gives none, and must not halve the other's throw).
    fn apply(&mut self, events: &HandEvents) {
        let mut released: [Option<Released>; 2] = [None; 2];
        for (k, event) in events.iter() {
            match event {
                GraspEvent::Grasp { object } => self.hands[k].constraint.grip(object, &self.objects.objects()[object].pose),
                GraspEvent::Release { object, linvel, angvel } if self.hands.iter().all(|h| h.grasp.held() != Some(object)) => {
                    let moved = f32::from(u8::from(linvel != Vec3::ZERO));
                    let hand = self.hands[k].physics;
                    match released.iter_mut().flatten().find(|r| r.object == object) {
                        Some(r) => {
                            (r.linvel, r.angvel, r.moved) = (r.linvel + linvel, r.angvel + angvel, r.moved + moved);
                            (r.hands[1], r.count) = (hand, 2);
                        }
                        None => released[k] = Some(Released { object, linvel, angvel, moved, hands: [hand; 2], count: 1 }),
                    }
                }
                GraspEvent::Release { .. } => {}
            }
        }
        for r in released.into_iter().flatten() {
            let n = r.moved.max(1.0);
            self.physics.release(r.object, r.linvel / n, r.angvel / n, &r.hands[..r.count]);
        }
        for hand in &self.hands {
            if let Some(held) = hand.grasp.held() {
                let (q, t) = self.poses[held];
                self.physics.hold(held, q, t);
            }
        }
    }

    fn read_poses(&mut self) {
        for i in 0..self.poses.len() {
            let (q, t) = self.physics.pose(i);
            self.poses[i] = (q, t);
            self.objects.set_pose(i, q, t);
        }
    }

    /// The hands: one, or a left and a right one in the order given.
    #[must_use]
    pub fn hands(&self) -> &[ManipulatingHand] {
        &self.hands
    }

    /// The objects the last [`Self::step`] put back where the scene file has them, because
    /// they had left the room's reach ([`crate::physics::REACH_M`], or through the floor at
    /// [`crate::physics::FLOOR_Y`]): an application reports them.
    #[must_use]
    pub fn returned(&self) -> &[usize] {
        self.physics.returned()
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

}

/// Two hands on one object: when one lets go the other keeps it (rebased where it is) if
/// its grasp holds it alone, else lets go too; two hands that hold it between them let
/// go when their contacts are farther apart than `apart`; else the object takes the best rigid fit of both hands' points.
fn share(now: f64, [a, b]: [&mut ManipulatingHand; 2], poses: &[(Quat, Vec3)], apart: f32, events: &mut HandEvents) {
    for k in 0..2 {
        let other = if k == 0 { &mut *b } else { &mut *a };
        if let Some(GraspEvent::Release { object, .. }) = events.0[k] {
            if other.grasp.held() == Some(object) {
                if other.grasp.alone() {
                    other.grasp.rebase(poses[object]);
                } else {
                    events.0[1 - k] = other.grasp.let_go(now);
                }
            }
        }
    }
    let Some(object) = a.grasp.held().filter(|&o| b.grasp.held() == Some(o)) else { return };
    if !(a.tracked() && b.tracked()) {
        // A hand lost holds its points where it last had them: the object stays where it is
        // (as one hand's held object does while lost) until the grace time lets it go.
        a.grasp.set_target(poses[object]);
        b.grasp.set_target(poses[object]);
        return;
    }
    if !a.grasp.alone() && !b.grasp.alone() {
        let gap = a.grasp.contact_centre().zip(b.grasp.contact_centre()).map_or(0.0, |(p, q)| p.distance(q));
        if gap > apart {
            events.0 = [a.grasp.let_go(now), b.grasp.let_go(now)];
            return;
        }
    }
    let (mut from, mut to) = ([Vec3::ZERO; MAX_HOLDING_POINTS], [Vec3::ZERO; MAX_HOLDING_POINTS]);
    let mut n = 0;
    for (p, q) in a.grasp.holding_points().chain(b.grasp.holding_points()) {
        (from[n], to[n]) = (p, q);
        n += 1;
    }
    let fit = rigid_fit(&from[..n], &to[..n]);
    a.grasp.set_target(fit);
    b.grasp.set_target(fit);
}
