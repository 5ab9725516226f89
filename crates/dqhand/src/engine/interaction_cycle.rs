//! One interaction cycle of the paper's Figure 1 for a hand: a pose drives the kinematics
//! layer once, whose bone transforms drive the skin layer.

use std::sync::Arc;

use crate::kinematics::{HandKinematics, JointModel, Pose};
use crate::model::Model;
use crate::skin::{Deformed, Method, MethodSet, SkinLayer};
use crate::Result;

/// A hand model's two stages together: [`HandKinematics`] (joint angles → one forward
/// kinematics pass → skinning transforms and their dual quaternions) and a [`SkinLayer`]
/// (LB, QB, DQB on those transforms).
///
/// [`Self::step`] is Figure 1 in code. The stages are also usable alone: a loop that only
/// needs the skeleton holds a [`HandKinematics`], and a skin layer can deform by any
/// kinematics layer's transforms. A new engine holds the rest pose, skinned with DQB.
///
/// ```
/// # #[cfg(feature = "hand")] {
/// use std::sync::Arc;
/// use dqhand::engine::Engine;
/// use dqhand::kinematics::{JointModel, Pose};
/// use dqhand::skin::Method;
///
/// let hand = Arc::new(dqhand::hand::build(&dqhand::hand::HandParams::default())?);
/// let mut engine = Engine::new(hand, JointModel::Full)?;
/// let mut pose = Pose::rest(JointModel::Full.dof_count());
/// pose.angles[3] = 1.2; // radians
/// engine.step(&pose);
/// let skin = engine.deformed(Method::Dqb).expect("DQB is in the default set");
/// assert_eq!(skin.positions().len(), engine.model().mesh.vertex_count());
/// # }
/// # Ok::<(), dqhand::Error>(())
/// ```
#[derive(Clone, Debug)]
pub struct Engine {
    model: Arc<Model>,
    kinematics: HandKinematics,
    skin: SkinLayer,
}

impl Engine {
    /// An engine posing joint angles of `joint_model` on `model`'s WebXR-named joints and
    /// skinning with DQB.
    ///
    /// # Errors
    /// As [`HandKinematics::new`]: the skeleton lacks a joint the model needs, or its joint
    /// frames are not WebXR's.
    pub fn new(model: Arc<Model>, joint_model: JointModel) -> Result<Self> {
        let kinematics = model.hand_kinematics(joint_model)?;
        let mut skin = SkinLayer::new(Arc::clone(&model.mesh), MethodSet::DQB);
        skin.deform(kinematics.layer());
        Ok(Self { model, kinematics, skin })
    }

    /// Switches the joint model, keeping limits (allocates: not per frame).
    ///
    /// # Errors
    /// As [`Self::new`]; the engine is unchanged then.
    pub fn set_joint_model(&mut self, joint_model: JointModel) -> Result<()> {
        let limits = self.kinematics.limits();
        self.kinematics = self.model.hand_kinematics(joint_model)?;
        self.kinematics.set_limits(limits);
        Ok(())
    }

    /// The methods [`Self::step`] skins with.
    pub fn set_methods(&mut self, methods: MethodSet) {
        self.skin.set_methods(methods);
    }

    /// One cycle: the kinematics layer poses `pose` once, then the skin layer deforms with
    /// every method of its set. Allocates nothing.
    ///
    /// # Panics
    /// If `pose` has another angle count than the joint model.
    pub fn step(&mut self, pose: &Pose) {
        self.kinematics.pose(pose);
        self.skin.deform(self.kinematics.layer());
    }

    /// The model.
    #[must_use]
    pub fn model(&self) -> &Arc<Model> {
        &self.model
    }

    /// The kinematics stage.
    #[must_use]
    pub fn kinematics(&self) -> &HandKinematics {
        &self.kinematics
    }

    /// The kinematics stage, to pose or set limits on.
    pub fn kinematics_mut(&mut self) -> &mut HandKinematics {
        &mut self.kinematics
    }

    /// The skin stage.
    #[must_use]
    pub fn skin(&self) -> &SkinLayer {
        &self.skin
    }

    /// The skin stage, to deform on its own (after posing through [`Self::kinematics_mut`]),
    /// or into the caller's buffers.
    pub fn skin_mut(&mut self) -> &mut SkinLayer {
        &mut self.skin
    }

    /// Deforms the current pose with `method` alone (whatever the set): for callers that
    /// time or measure one method. Allocates only the first time `method` is used.
    pub fn skin_with(&mut self, method: Method) -> &Deformed {
        let methods = self.skin.methods();
        self.skin.set_methods(MethodSet::new(&[method]).expect("one method is a set"));
        self.skin.deform(self.kinematics.layer());
        self.skin.set_methods(methods);
        self.skin.deformed(method).expect("deformed above")
    }

    /// The mesh as `method` last deformed it; `None` if `method` was never skinned.
    #[must_use]
    pub fn deformed(&self, method: Method) -> Option<&Deformed> {
        self.skin.deformed(method)
    }
}
