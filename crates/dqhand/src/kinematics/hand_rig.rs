//! The hand rig: a joint model bound to a concrete skeleton with WebXR joint names.
//!
//! It resolves each degree of freedom to a joint index and a rotation axis in that joint's
//! frame once, so turning a [`Pose`] into local transforms each frame is a short loop.

use glam::{Affine3A, Quat, Vec3};

use super::{webxr, JointModel, Motion, Pose, Skeleton, Transform};
use crate::math::DualQuat;
use crate::{Error, Result};

/// One degree of freedom resolved on a skeleton: the joint it turns and the axis, in that
/// joint's frame, it turns about.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RigDof {
    /// Index of the joint in the rig's skeleton.
    pub joint: usize,
    /// Unit rotation axis in the joint's rest frame.
    pub axis: Vec3,
    /// Lower limit, radians.
    pub min: f32,
    /// Upper limit, radians.
    pub max: f32,
}

impl RigDof {
    /// `rotation` turned by `angle` about this DOF's axis, after the turns before it: the
    /// one composition rule of posing (`rest · R(abd) · R(flex)`), shared by
    /// [`HandRig::locals`] and whoever solves angles for a rig.
    #[must_use]
    pub fn turn(&self, rotation: Quat, angle: f32) -> Quat {
        (rotation * Quat::from_axis_angle(self.axis, angle)).normalize()
    }
}

/// Whether joint limits are applied when posing.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Limits {
    /// Angles are clamped to the joint model's anatomical ranges (the default).
    #[default]
    Anatomical,
    /// Angles are used as given.
    Off,
}

/// A [`JointModel`] resolved on a skeleton whose joints carry WebXR names.
#[derive(Clone, Debug, PartialEq)]
pub struct HandRig {
    skeleton: Skeleton,
    model: JointModel,
    dofs: Vec<RigDof>,
    wrist: usize,
    /// The wrist's rest world pose.
    rest_wrist: DualQuat,
    /// Inverse rest world transform of the wrist's parent (fixed: only the wrist and below
    /// move), which turns a world wrist pose into a local one.
    wrist_parent_inverse: Affine3A,
}

impl HandRig {
    /// Resolves `model` on `skeleton`. A skeleton whose WebXR joints are stored as siblings
    /// (as WebXR and the generic-hand asset do) is first re-parented into the anatomical chain
    /// wrist → metacarpal → phalanges, keeping every rest transform; a joint whose anatomical
    /// parent is missing hangs from the nearest ancestor in the chain that exists.
    ///
    /// Flexion turns a bone about its −X axis, which is right only in WebXR joint frames (−Z
    /// along the bone toward the tip); a rig in another convention (Blender's +Y along the
    /// bone) would flex sideways, so its frames are checked and refused.
    ///
    /// # Errors
    /// [`Error::MissingJoint`] if a joint the model needs is missing, [`Error::JointFrame`]
    /// if a moving joint's −Z axis is more than 45° from its bone, [`Error::Skeleton`] if
    /// re-parenting makes a cycle.
    pub fn new(skeleton: &Skeleton, model: JointModel) -> Result<Self> {
        let nearest_parent = |name: &str| {
            let mut parent = webxr::anatomical_parent(name);
            while let Some(p) = parent.filter(|p| skeleton.find(p).is_none()) {
                parent = webxr::anatomical_parent(p);
            }
            parent
        };
        let skeleton = skeleton.reparented(nearest_parent)?;
        let wrist = skeleton.find("wrist").ok_or_else(|| missing("wrist"))?;
        let world = skeleton.rest_world();
        let pos = |name: &str| -> Option<Vec3> { skeleton.find(name).map(|i| world[i].translation.into()) };
        // Radial points from the little finger toward the index; palmar is the wrist's −Y.
        let radial: Vec3 = match (pos("index-finger-phalanx-proximal"), pos("pinky-finger-phalanx-proximal")) {
            (Some(i), Some(p)) => (i - p).normalize_or_zero(),
            _ => Vec3::ZERO,
        };
        let palmar = -Vec3::from(world[wrist].matrix3.y_axis).normalize_or_zero();
        let mut dofs = Vec::new();
        for d in model.dofs() {
            let joint = skeleton.find(d.bone).ok_or_else(|| missing(d.bone))?;
            check_frame(&skeleton, &world, d.bone)?;
            let axis = match d.motion {
                Motion::Flex => Vec3::NEG_X,
                Motion::Abd => {
                    let away = match d.bone {
                        b if b.starts_with("thumb") => palmar,
                        b if b.starts_with("ring") || b.starts_with("pinky") => -radial,
                        _ => radial,
                    };
                    Vec3::Y * abduction_sign(&skeleton, &world, d.bone, away)
                }
            };
            dofs.push(RigDof { joint, axis, min: d.min_deg.to_radians(), max: d.max_deg.to_radians() });
        }
        let wrist_parent_inverse = skeleton.joints()[wrist].parent.map_or(Affine3A::IDENTITY, |p| world[p].inverse());
        let (_, rotation, translation) = world[wrist].to_scale_rotation_translation();
        let rest_wrist = DualQuat::from_rotation_translation(rotation.normalize(), translation);
        Ok(Self { skeleton, model, dofs, wrist, rest_wrist, wrist_parent_inverse })
    }

    /// The anatomical skeleton the rig poses (same joint indices as the input skeleton).
    #[must_use]
    pub fn skeleton(&self) -> &Skeleton {
        &self.skeleton
    }

    /// The joint model.
    #[must_use]
    pub fn model(&self) -> JointModel {
        self.model
    }

    /// The wrist's world pose at rest: what a pose without a wrist is posed with.
    #[must_use]
    pub fn rest_wrist(&self) -> DualQuat {
        self.rest_wrist
    }

    /// The degrees of freedom in the joint model's order, resolved on the skeleton.
    #[must_use]
    pub fn dofs(&self) -> &[RigDof] {
        &self.dofs
    }

    /// Index of the wrist joint.
    #[must_use]
    pub fn wrist(&self) -> usize {
        self.wrist
    }

    /// Clamps the pose's angles to the anatomical ranges; returns the indices of the DOFs that
    /// were out of range.
    ///
    /// # Panics
    /// If the pose has the wrong number of angles.
    pub fn clamp(&self, pose: &mut Pose) -> Vec<usize> {
        assert_eq!(pose.angles.len(), self.dofs.len(), "pose angle count");
        let mut clamped = Vec::new();
        for (i, (a, d)) in pose.angles.iter_mut().zip(&self.dofs).enumerate() {
            let c = a.clamp(d.min, d.max);
            if c != *a {
                clamped.push(i);
                *a = c;
            }
        }
        clamped
    }

    /// Writes the local transform of every joint for `pose`: the rest transforms, the wrist
    /// replaced by the tracker pose, each moving joint turned by `rest · R(abd) · R(flex)`.
    ///
    /// * `locals` — #joints output, overwritten. Allocates nothing.
    ///
    /// # Panics
    /// If `locals` or `pose.angles` have the wrong length.
    pub fn locals(&self, pose: &Pose, limits: Limits, locals: &mut [Transform]) {
        assert_eq!(pose.angles.len(), self.dofs.len(), "pose angle count");
        assert_eq!(locals.len(), self.skeleton.len(), "locals: one per joint");
        for (l, j) in locals.iter_mut().zip(self.skeleton.joints()) {
            *l = j.rest;
        }
        if let Some(w) = pose.wrist {
            let (rotation, translation) = w.to_rotation_translation();
            let local = self.wrist_parent_inverse * Affine3A::from_rotation_translation(rotation, translation);
            locals[self.wrist] = Transform { scale: locals[self.wrist].scale, ..Transform::from_affine(&local) };
        }
        self.turn(pose, limits, 0..self.dofs.len(), locals);
    }

    /// [`Self::locals`] of only the joints `joints` (none of them the wrist), which `dofs`
    /// (ascending indices into the pose) are all the DOFs of: a closing finger's, whose other
    /// joints keep what they were. Allocates nothing.
    ///
    /// # Panics
    /// If `locals` or `pose.angles` have the wrong length.
    pub fn locals_of(&self, pose: &Pose, limits: Limits, joints: &[usize], dofs: &[usize], locals: &mut [Transform]) {
        assert_eq!(pose.angles.len(), self.dofs.len(), "pose angle count");
        assert_eq!(locals.len(), self.skeleton.len(), "locals: one per joint");
        for &j in joints {
            locals[j] = self.skeleton.joints()[j].rest;
        }
        self.turn(pose, limits, dofs.iter().copied(), locals);
    }

    /// Turns each joint of DOFs `dofs` (ascending) by its angle in `pose`: `rest · R(abd) · R(flex)`.
    fn turn(&self, pose: &Pose, limits: Limits, dofs: impl Iterator<Item = usize>, locals: &mut [Transform]) {
        for i in dofs {
            let (a, d) = (pose.angles[i], &self.dofs[i]);
            let angle = match limits {
                Limits::Anatomical => a.clamp(d.min, d.max),
                Limits::Off => a,
            };
            let l = &mut locals[d.joint];
            l.rotation = d.turn(l.rotation, angle);
        }
    }
}

/// The joint after `bone` along its finger (its child in the anatomical chain), if the
/// skeleton has it.
fn next_joint(skeleton: &Skeleton, bone: &str) -> Option<usize> {
    let i = webxr::JOINT_NAMES.iter().position(|&n| n == bone)?;
    webxr::JOINT_NAMES.get(i + 1).filter(|n| webxr::anatomical_parent(n) == Some(bone)).and_then(|n| skeleton.find(n))
}

/// Checks that `bone`'s −Z axis runs along the bone toward the next joint (within 45°).
fn check_frame(skeleton: &Skeleton, world: &[Affine3A], bone: &str) -> Result<()> {
    let (Some(j), Some(c)) = (skeleton.find(bone), next_joint(skeleton, bone)) else { return Ok(()) };
    let along = Vec3::from(world[c].translation - world[j].translation);
    let minus_z = -Vec3::from(world[j].matrix3.z_axis);
    if along.length() < 1e-6 || minus_z.length() < 1e-6 {
        return Ok(());
    }
    let angle = minus_z.angle_between(along).to_degrees();
    if angle > 45.0 {
        return Err(Error::JointFrame {
            joint: bone.to_owned(),
            problem: format!("its −Z axis is {angle:.0}° from the bone toward {:?}", skeleton.joints()[c].name),
        });
    }
    Ok(())
}

/// +1 if turning `bone` about its +Y axis moves the next joint of its finger away along
/// `away`, else −1.
fn abduction_sign(skeleton: &Skeleton, world: &[Affine3A], bone: &str, away: Vec3) -> f32 {
    let (Some(joint), Some(child)) = (skeleton.find(bone), next_joint(skeleton, bone)) else { return 1.0 };
    let tip: Vec3 = world[child].translation.into();
    let turned = world[joint] * Affine3A::from_rotation_y(0.1) * world[joint].inverse();
    if (turned.transform_point3(tip) - tip).dot(away) >= 0.0 {
        1.0
    } else {
        -1.0
    }
}

fn missing(name: &str) -> Error {
    Error::MissingJoint { joint: name.into(), needed_for: "joint angles need the WebXR hand joint names" }
}
