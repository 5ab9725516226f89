//! The gesture interaction loop: record → input pipeline (check, retarget or map, filter,
//! dropouts) → kinematics of the virtual hand → finger features → recogniser.
//!
//! Gestures are recognised on the *virtual* hand, after retargeting: one set of thresholds
//! then serves every source (gloves, joints, landmarks) and every user's hand size, and what
//! the user sees is what is recognised.

use std::sync::Arc;

use glam::Vec3;

use crate::engine::Engine;
use crate::gesture::{Events, GestureSet, HandFeatures, Recognizer};
use crate::hand::Side;
use super::CommandTable;
use crate::input::{Action, GestureAction, GloveMapper, InputConfig, InputPipeline, Record, Rejection};
use crate::kinematics::{JointModel, JointPositions};
use crate::model::Model;
use crate::Result;

/// One user's hand driving one virtual hand, with an optional gesture recogniser.
pub struct GestureLoop {
    pipeline: InputPipeline,
    engine: Engine,
    joints: JointPositions,
    positions: [Vec3; 25],
    side: Side,
    recognizer: Option<Recognizer>,
    commands: Option<CommandTable<GestureAction>>,
    /// The command the last record triggered.
    action: Option<Action>,
}

impl GestureLoop {
    /// A loop posing `model` with `joint_model`; `gestures` turns recognition on.
    ///
    /// # Errors
    /// As [`Engine::with_joint_model`], [`InputPipeline::new`] and [`JointPositions::new`].
    pub fn new(model: Arc<Model>, joint_model: JointModel, glove: Option<GloveMapper>, config: InputConfig, gestures: Option<GestureSet>) -> Result<Self> {
        let engine = Engine::with_joint_model(model, joint_model)?;
        let rig = engine.rig().expect("an engine with a joint model has a rig");
        let pipeline = InputPipeline::new(rig, glove, config)?;
        let joints = JointPositions::new(engine.skeleton())?;
        let side = pipeline.retargeter().side();
        Ok(Self { pipeline, engine, joints, positions: [Vec3::ZERO; 25], side, recognizer: gestures.map(Recognizer::new), commands: None, action: None })
    }

    /// The loop with the configuration's `actions` as its commands ([`Self::action`]), where
    /// gestures drive a viewer; without recognition there are none.
    ///
    /// # Errors
    /// As [`CommandTable::new`]: an action naming a gesture the loop does not recognise.
    pub fn with_commands(mut self) -> Result<Self> {
        if let Some(recognizer) = &self.recognizer {
            self.commands = Some(CommandTable::new(&self.pipeline.config().actions, recognizer.set())?);
        }
        Ok(self)
    }

    /// Takes one record (`arrival`: see [`InputPipeline::push`]): poses the virtual hand and,
    /// with recognition on, returns the gesture events it caused (and sets [`Self::action`]).
    /// Allocates nothing.
    ///
    /// # Errors
    /// The record's refusal; the hand keeps its pose.
    pub fn push(&mut self, record: &Record, arrival: Option<f64>) -> Result<Events<'_>, Rejection> {
        self.action = None;
        self.pipeline.push(record, arrival)?;
        self.engine.pose(self.pipeline.pose());
        self.positions = self.joints.read(self.engine.world());
        Ok(self.recognize(record.time))
    }

    fn recognize(&mut self, time: f64) -> Events<'_> {
        let features = HandFeatures::from_positions(&self.positions, self.side);
        let Some(recognizer) = &mut self.recognizer else { return Events::none() };
        let events = recognizer.update(time, &features);
        if let Some(commands) = &mut self.commands {
            self.action = commands.update(time, events.clone());
        }
        events
    }

    /// The command (a row of the configuration's `actions`) that the last record triggered.
    #[must_use]
    pub fn action(&self) -> Option<Action> {
        self.action
    }

    /// The input pipeline (pose, tracking state, rejections).
    #[must_use]
    pub fn pipeline(&self) -> &InputPipeline {
        &self.pipeline
    }

    /// Counts a record refused before it reached the loop.
    pub fn reject(&mut self, rejection: Rejection) {
        self.pipeline.reject(rejection);
    }

    /// Marks the hand lost after the grace time without records, and relaxes it after
    /// `rest_after_s` more ([`InputPipeline::advance`]): whether the pose to show changed.
    pub fn advance(&mut self, now: f64) -> bool {
        self.pipeline.advance(now)
    }

    /// The current gesture, with recognition on.
    #[must_use]
    pub fn gesture(&self) -> Option<&str> {
        self.recognizer.as_ref().and_then(Recognizer::current)
    }

    /// The gestures recognised, with recognition on.
    #[must_use]
    pub fn gestures(&self) -> Option<&GestureSet> {
        self.recognizer.as_ref().map(Recognizer::set)
    }

    /// The virtual hand's 25 WebXR joint positions after the last record.
    #[must_use]
    pub fn joint_positions(&self) -> &[Vec3; 25] {
        &self.positions
    }

    /// The engine that poses the virtual hand.
    #[must_use]
    pub fn engine(&self) -> &Engine {
        &self.engine
    }

    /// The engine that poses the virtual hand (kinematics only; skin it with
    /// [`Engine::skin`] when the mesh is wanted).
    pub fn engine_mut(&mut self) -> &mut Engine {
        &mut self.engine
    }
}
