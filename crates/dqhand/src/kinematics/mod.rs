//! Kinematics layer (paper 4.3): skeleton, joint models and limits, poses, forward
//! kinematics, and the layer that poses once per pose ([`KinematicsLayer`],
//! [`HandKinematics`]).

mod forward_kinematics;
mod hand_kinematics;
mod hand_part;
mod hand_rig;
mod joint_model;
mod joint_positions;
mod kinematics_layer;
mod pose;
mod pose_target;
mod side;
mod skeleton;
mod skinning_transforms;
mod transform;
pub mod webxr;

pub use forward_kinematics::{forward_kinematics, forward_kinematics_of};
pub use hand_kinematics::{ClampedAngle, HandKinematics};
pub use hand_part::{HandPart, FINGERS};
pub use hand_rig::{HandRig, Limits, RigDof};
pub use joint_model::{Dof, JointModel, Motion};
pub use joint_positions::JointPositions;
pub use kinematics_layer::KinematicsLayer;
pub use pose::Pose;
pub use pose_target::PoseTarget;
pub use side::Side;
pub use skeleton::{Joint, Skeleton};
pub use skinning_transforms::skinning_transforms;
pub use transform::Transform;
