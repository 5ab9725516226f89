//! The gesture interaction loop: record → input pipeline (check, retarget or map, filter,
//! dropouts) → kinematics of the virtual hand → finger features → recogniser.
//!
//! Gestures are recognised on the *virtual* hand, after retargeting: one set of thresholds
//! then serves every source (gloves, joints, landmarks) and every user's hand size, and what
//! the user sees is what is recognised.

use std::sync::Arc;

use glam::Vec3;

use crate::gesture::{Events, GestureSet, HandFeatures, Recognizer};
use crate::kinematics::Side;
use crate::input::{GloveMapper, InputConfig, InputPipeline, Record, Rejection};
use crate::kinematics::{HandKinematics, JointModel, JointPositions};
use crate::model::Model;
use crate::Result;

/// One user's hand driving one virtual hand, with an optional gesture recogniser.
///
/// ```
/// use std::sync::Arc;
/// use dqhand::gesture::{gesture, GestureSet};
/// use dqhand::hand::{build, HandParams, Side};
/// use dqhand::input::{HandData, InputConfig, JointSet, Record, TrackedJoint};
/// use dqhand::interaction::GestureLoop;
/// use dqhand::kinematics::{JointModel, JointPositions};
///
/// let hand = Arc::new(build(&HandParams { vertices: 1000, ..Default::default() })?);
/// // What a hand tracker reports: the 25 WebXR joints of a hand making a fist.
/// let mut user = hand.hand_kinematics(JointModel::Full)?;
/// user.pose(&gesture("fist")?.pose(JointModel::Full));
/// let mut joints = JointSet::new();
/// for (i, position) in JointPositions::new(user.skeleton())?.read(user.world()).into_iter().enumerate() {
///     joints.set(i, TrackedJoint { position, orientation: None, radius: 0.0 });
/// }
/// let mut hands = GestureLoop::new(hand, JointModel::Full, None, InputConfig::default(), Some(GestureSet::builtin()))?;
/// let mut started = Vec::new();
/// for frame in 0..30u32 { // half a second at 60 Hz
///     let record = Record { time: f64::from(frame) / 60.0, side: Side::Right, hand: Some(HandData::Joints(joints)), tracker: None, arrival: None };
///     started.extend(hands.push(&record)?.map(|e| e.gesture.to_owned()));
///     assert_eq!(hands.kinematics().layer().passes(), u64::from(frame) + 1, "posed once per record");
/// }
/// assert_eq!(started, ["fist"]);
/// assert_eq!(hands.gesture(), Some("fist"));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub struct GestureLoop {
    model: Arc<Model>,
    pipeline: InputPipeline,
    kinematics: HandKinematics,
    joints: JointPositions,
    positions: [Vec3; 25],
    side: Side,
    recognizer: Option<Recognizer>,
}

impl GestureLoop {
    /// A loop posing `model` with `joint_model`; `gestures` turns recognition on.
    ///
    /// # Errors
    /// As [`Model::hand_kinematics`], [`InputPipeline::new`] and [`JointPositions::new`].
    pub fn new(model: Arc<Model>, joint_model: JointModel, glove: Option<GloveMapper>, config: InputConfig, gestures: Option<GestureSet>) -> Result<Self> {
        let kinematics = model.hand_kinematics(joint_model)?;
        let pipeline = InputPipeline::new(kinematics.rig(), glove, config)?;
        let joints = JointPositions::new(kinematics.skeleton())?;
        let side = pipeline.retargeter().side();
        Ok(Self { model, pipeline, kinematics, joints, positions: [Vec3::ZERO; 25], side, recognizer: gestures.map(Recognizer::new) })
    }

    /// Takes one record (its arrival time as in [`InputPipeline::push`]): poses the virtual
    /// hand once and, with recognition on, returns the gesture events it caused. Allocates
    /// nothing.
    ///
    /// # Errors
    /// The record's refusal; the hand keeps its pose.
    pub fn push(&mut self, record: &Record) -> Result<Events<'_>, Rejection> {
        if let Err(rejection) = self.pipeline.push(record) {
            // Bringing the hand up to the record's time may have relaxed a lost hand.
            self.repose();
            return Err(rejection);
        }
        self.repose();
        Ok(self.recognize(record.time))
    }

    /// Poses the virtual hand as the pipeline shows it: one forward kinematics pass.
    fn repose(&mut self) {
        self.kinematics.pose(self.pipeline.pose());
        self.positions = self.joints.read(self.kinematics.world());
    }

    fn recognize(&mut self, time: f64) -> Events<'_> {
        let Some(recognizer) = &mut self.recognizer else { return Events::none() };
        recognizer.update(time, &HandFeatures::from_positions(&self.positions, self.side))
    }

    /// The virtual hand's features after the last record: what the recogniser reads, and
    /// what a classifier is trained on.
    #[must_use]
    pub fn features(&self) -> HandFeatures {
        HandFeatures::from_positions(&self.positions, self.side)
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
    /// The hand is posed again only when its pose changed.
    pub fn advance(&mut self, now: f64) -> bool {
        let changed = self.pipeline.advance(now);
        if changed {
            self.repose();
        }
        changed
    }

    /// The current gesture, with recognition on.
    #[must_use]
    pub fn gesture(&self) -> Option<&str> {
        self.recognizer.as_ref().and_then(Recognizer::current)
    }

    /// The current gesture's index in [`Self::gestures`], with recognition on.
    #[must_use]
    pub fn gesture_index(&self) -> Option<usize> {
        self.recognizer.as_ref().and_then(Recognizer::current_index)
    }

    /// The gestures recognised, with recognition on.
    #[must_use]
    pub fn gestures(&self) -> Option<&GestureSet> {
        self.recognizer.as_ref().map(Recognizer::set)
    }

    /// Recognises `gestures` from now on (a gesture learned while the loop runs), starting
    /// with no gesture held; the hand and its input are unchanged.
    pub fn set_gestures(&mut self, gestures: GestureSet) {
        self.recognizer = Some(Recognizer::new(gestures));
    }

    /// The virtual hand's 25 WebXR joint positions after the last record.
    #[must_use]
    pub fn joint_positions(&self) -> &[Vec3; 25] {
        &self.positions
    }

    /// The virtual hand's model (its skeleton and the mesh a skin layer deforms).
    #[must_use]
    pub fn model(&self) -> &Arc<Model> {
        &self.model
    }

    /// The virtual hand's kinematics layer, posed once per record: its transforms drive a
    /// [`crate::skin::SkinLayer`] where the mesh is wanted.
    #[must_use]
    pub fn kinematics(&self) -> &HandKinematics {
        &self.kinematics
    }
}
