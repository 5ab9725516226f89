//! Kinematics layer (paper 4.3): skeleton, joint models and limits, poses, forward kinematics.

mod forward_kinematics;
mod hand_rig;
mod joint_model;
mod joint_positions;
mod pose;
mod pose_target;
mod skeleton;
mod transform;
pub mod webxr;

pub use forward_kinematics::forward_kinematics;
pub use hand_rig::{HandRig, Limits, RigDof};
pub use joint_model::{Dof, JointModel, Motion};
pub use joint_positions::JointPositions;
pub use pose::Pose;
pub use pose_target::PoseTarget;
pub use skeleton::{Joint, Skeleton};
pub use transform::Transform;
