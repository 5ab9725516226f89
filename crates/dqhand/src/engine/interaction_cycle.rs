//! One interaction cycle of the paper's Figure 1: a pose drives the kinematics layer, whose
//! bone transforms drive the skin layer (the collision layer and the interaction loops join
//! here in later issues).

use std::sync::Arc;

use glam::Affine3A;

use crate::kinematics::{forward_kinematics, HandRig, JointModel, Limits, Pose, PoseTarget, Skeleton, Transform};
use crate::model::Model;
use crate::skin::{skinning_transforms, Crew, Deformed, Deformer, Kernel, Method, MethodSet};
use crate::Result;

/// The virtual hand's engine: a model, its kinematics and its skin, with every per-frame
/// buffer allocated once.
///
/// [`Self::step`] is Figure 1 in code: pose → kinematics (local transforms, forward
/// kinematics, one skinning transform per bone, each computed once) → skin (each method in
/// [`Self::methods`]). The two stages are also public, [`Self::pose`] and [`Self::skin`], for
/// callers that time or measure one of them. `step`, `pose`, `pose_locals` and `skin`
/// allocate nothing; a new engine holds the rest pose, skinned with every method.
#[derive(Clone, Debug)]
pub struct Engine {
    model: Arc<Model>,
    /// The joint model resolved on the skeleton; `None` poses the model's own skeleton by
    /// local transforms only.
    rig: Option<HandRig>,
    limits: Limits,
    methods: MethodSet,
    locals: Vec<Transform>,
    world: Vec<Affine3A>,
    skinning: Vec<Affine3A>,
    /// One deformer and output per method, in [`Method::ALL`] order.
    deformers: [Deformer; 3],
    deformed: [Deformed; 3],
}

impl Engine {
    /// An engine that poses `model`'s own skeleton by local transforms ([`Self::pose_locals`]),
    /// for any skinned model.
    #[must_use]
    pub fn new(model: Arc<Model>) -> Self {
        let skeleton = &model.skeleton;
        let n = skeleton.len();
        let mut engine = Self {
            rig: None,
            limits: Limits::Anatomical,
            methods: MethodSet::DQB,
            locals: skeleton.rest_locals(),
            world: vec![Affine3A::IDENTITY; n],
            skinning: vec![Affine3A::IDENTITY; n],
            deformers: Method::ALL.map(|m| Deformer::new(m, &model.mesh)),
            deformed: Method::ALL.map(|_| Deformed::new(&model.mesh)),
            model,
        };
        engine.forward();
        for m in Method::ALL {
            engine.skin(m);
        }
        engine
    }

    /// An engine that poses joint angles of `joint_model` ([`Self::pose`]) on the anatomical
    /// chain of `model`'s WebXR-named joints.
    ///
    /// # Errors
    /// As [`HandRig::new`]: the skeleton lacks a joint the model needs, or its joint frames
    /// are not WebXR's.
    pub fn with_joint_model(model: Arc<Model>, joint_model: JointModel) -> Result<Self> {
        let mut engine = Self::new(model);
        engine.set_joint_model(joint_model)?;
        Ok(engine)
    }

    /// An engine for `target`: with its joint model for joint angles, on the model's own
    /// skeleton for local rotations.
    ///
    /// # Errors
    /// As [`Self::with_joint_model`].
    pub fn for_target(model: Arc<Model>, target: &PoseTarget) -> Result<Self> {
        match target {
            PoseTarget::Angles { model: joint_model, .. } => Self::with_joint_model(model, *joint_model),
            PoseTarget::LocalRotations(_) => Ok(Self::new(model)),
        }
    }

    /// Switches the joint model (allocates: not per frame).
    ///
    /// # Errors
    /// As [`HandRig::new`]; the engine is unchanged then.
    pub fn set_joint_model(&mut self, joint_model: JointModel) -> Result<()> {
        let rig = HandRig::new(&self.model.skeleton, joint_model)?;
        self.locals = rig.skeleton().rest_locals();
        self.rig = Some(rig);
        self.forward();
        Ok(())
    }

    /// Whether angles are clamped to the joint model's anatomical ranges.
    pub fn set_limits(&mut self, limits: Limits) {
        self.limits = limits;
    }

    /// The methods [`Self::step`] skins with.
    pub fn set_methods(&mut self, methods: MethodSet) {
        self.methods = methods;
    }

    /// Runs the skinning on `kernel` (to compare kernels; the fastest this CPU runs by default).
    pub fn use_kernel(&mut self, kernel: Kernel) {
        self.deformers = self.deformers.clone().map(|d| d.with_kernel(kernel));
    }

    /// Splits each deformation across `crew`'s threads (see [`Deformer::with_crew`]).
    pub fn use_crew(&mut self, crew: &Arc<Crew>) {
        self.deformers = self.deformers.clone().map(|d| d.with_crew(Arc::clone(crew)));
    }

    /// The model.
    #[must_use]
    pub fn model(&self) -> &Arc<Model> {
        &self.model
    }

    /// The joint model resolved on the skeleton, if angles can be posed.
    #[must_use]
    pub fn rig(&self) -> Option<&HandRig> {
        self.rig.as_ref()
    }

    /// The skeleton the engine poses: the rig's anatomical chain, else the model's own.
    #[must_use]
    pub fn skeleton(&self) -> &Skeleton {
        self.rig.as_ref().map_or(&self.model.skeleton, HandRig::skeleton)
    }

    /// Whether angles are clamped.
    #[must_use]
    pub fn limits(&self) -> Limits {
        self.limits
    }

    /// The methods [`Self::step`] skins with.
    #[must_use]
    pub fn methods(&self) -> MethodSet {
        self.methods
    }

    /// One cycle: [`Self::pose`], then [`Self::skin`] with every method of [`Self::methods`].
    ///
    /// # Panics
    /// As [`Self::pose`].
    pub fn step(&mut self, pose: &Pose) {
        self.pose(pose);
        let methods = self.methods;
        for &m in methods.as_slice() {
            self.skin(m);
        }
    }

    /// The kinematics layer for joint angles: local transforms of the rig (the wrist from
    /// the tracker, each DOF turned within the limits), then [`Self::pose_locals`]'s steps.
    ///
    /// # Panics
    /// If the engine has no joint model, or `pose` has another angle count than its model.
    pub fn pose(&mut self, pose: &Pose) {
        let rig = self.rig.as_ref().expect("an engine with a joint model poses joint angles");
        rig.locals(pose, self.limits, &mut self.locals);
        self.forward();
    }

    /// The kinematics layer for local transforms of [`Self::skeleton`]'s joints: forward
    /// kinematics (paper 4.3), then each joint's skinning transform `world · inverse_bind`
    /// (paper 4.4 step 1), each computed once.
    ///
    /// # Panics
    /// If `locals` does not have one transform per joint.
    pub fn pose_locals(&mut self, locals: &[Transform]) {
        self.locals.copy_from_slice(locals);
        self.forward();
    }

    /// Poses a resolved pose file; returns one warning per angle clamped to its limits.
    ///
    /// # Panics
    /// If the engine was not made for the target's kind ([`Self::for_target`]).
    pub fn pose_target(&mut self, target: &PoseTarget) -> Vec<String> {
        match target {
            PoseTarget::Angles { pose, .. } => {
                let rig = self.rig.as_ref().expect("an engine made for joint angles");
                let mut clamped_pose = pose.clone();
                let warnings = if self.limits == Limits::Anatomical {
                    let dofs: Vec<_> = rig.model().dofs().collect();
                    rig.clamp(&mut clamped_pose)
                        .into_iter()
                        .map(|i| format!("{} clamped to its range {}..{} degrees (use --no-limits to allow it)", dofs[i].name(), dofs[i].min_deg, dofs[i].max_deg))
                        .collect()
                } else {
                    Vec::new()
                };
                self.pose(&clamped_pose);
                warnings
            }
            PoseTarget::LocalRotations(rotations) => {
                assert!(self.rig.is_none(), "local rotations pose the model's own skeleton: an engine without a joint model");
                let mut locals = self.model.skeleton.rest_locals();
                for &(j, q) in rotations {
                    locals[j].rotation = q;
                }
                self.pose_locals(&locals);
                Vec::new()
            }
        }
    }

    fn forward(&mut self) {
        let skeleton = self.rig.as_ref().map_or(&self.model.skeleton, HandRig::skeleton);
        forward_kinematics(skeleton, &self.locals, &mut self.world);
        skinning_transforms(&self.world, self.model.mesh.inverse_bind(), &mut self.skinning);
    }

    /// The skin layer: deforms the mesh with `method` by the current skinning transforms.
    pub fn skin(&mut self, method: Method) -> &Deformed {
        let i = method.index();
        self.deformers[i].deform(&self.model.mesh, &self.skinning, &mut self.deformed[i]);
        &self.deformed[i]
    }

    /// The local transform of each joint of [`Self::skeleton`] in the current pose.
    #[must_use]
    pub fn locals(&self) -> &[Transform] {
        &self.locals
    }

    /// The world transform of each joint in the current pose.
    #[must_use]
    pub fn world(&self) -> &[Affine3A] {
        &self.world
    }

    /// The skinning transform `world · inverse_bind` of each joint in the current pose.
    #[must_use]
    pub fn skinning(&self) -> &[Affine3A] {
        &self.skinning
    }

    /// The mesh as `method` last deformed it.
    #[must_use]
    pub fn deformed(&self, method: Method) -> &Deformed {
        &self.deformed[method.index()]
    }
}
