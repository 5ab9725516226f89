//! The engine step (the paper's Figure 1): what it computes, against the layers called one by
//! one, and what a new engine holds.

mod support;

use std::sync::{Arc, LazyLock};

use dqhand::engine::{Engine, ModelSource};
use dqhand::gesture::gesture;
use dqhand::hand::{build, HandParams};
use dqhand::kinematics::{HandRig, JointModel, Limits, PoseTarget};
use dqhand::model::Model;
use dqhand::skin::{skinning_transforms, Deformed, Deformer, Method, MethodSet};
use glam::Quat;

static HAND: LazyLock<Arc<Model>> = LazyLock::new(|| Arc::new(build(&HandParams { vertices: 2000, ..HandParams::default() }).unwrap()));

#[test]
fn a_new_engine_holds_the_rest_mesh_under_every_method() {
    let engine = Engine::with_joint_model(HAND.clone(), JointModel::Paper).unwrap();
    for m in Method::ALL {
        for (v, p) in engine.deformed(m).positions().iter().enumerate() {
            assert_close!(*p, HAND.mesh.position(v).to_array(), 1e-5);
        }
    }
}

#[test]
fn a_step_is_the_rig_then_forward_kinematics_then_the_chosen_deformers() {
    let mut engine = Engine::with_joint_model(HAND.clone(), JointModel::Full).unwrap();
    engine.set_methods(MethodSet::new(&[Method::Qb, Method::Lb]).unwrap());
    let pose = gesture("ok").unwrap().pose(JointModel::Full);
    let untouched = engine.deformed(Method::Dqb).clone();
    engine.step(&pose);
    // The same frame, layer by layer.
    let rig = HandRig::new(&HAND.skeleton, JointModel::Full).unwrap();
    let world = support::world_of(&rig, &pose, Limits::Anatomical);
    let mut skinning = world.clone();
    skinning_transforms(&world, HAND.mesh.inverse_bind(), &mut skinning);
    assert_eq!(engine.world(), world.as_slice());
    assert_eq!(engine.skinning(), skinning.as_slice());
    for m in [Method::Qb, Method::Lb] {
        let mut out = Deformed::new(&HAND.mesh);
        Deformer::new(m, &HAND.mesh).deform(&HAND.mesh, &skinning, &mut out);
        assert_eq!(engine.deformed(m), &out, "{m}");
    }
    assert_eq!(engine.deformed(Method::Dqb), &untouched, "a method not chosen is not skinned");
}

#[test]
fn an_engine_for_a_pose_file_picks_the_joint_model_or_the_files_own_hierarchy() {
    let angles = PoseTarget::Angles { model: JointModel::Paper, pose: gesture("fist").unwrap().pose(JointModel::Paper) };
    let engine = Engine::for_target(HAND.clone(), &angles).unwrap();
    assert_eq!(engine.rig().map(HandRig::model), Some(JointModel::Paper));
    let wrist = HAND.skeleton.find("wrist").unwrap();
    let turn = Quat::from_rotation_y(0.5);
    let rotations = PoseTarget::LocalRotations(vec![(wrist, turn)]);
    let mut engine = Engine::for_target(HAND.clone(), &rotations).unwrap();
    assert!(engine.rig().is_none());
    assert!(engine.pose_target(&rotations).is_empty());
    assert!(engine.world()[wrist].matrix3.abs_diff_eq(glam::Mat3A::from_quat(turn), 1e-6));
}

#[test]
fn builtin_names_the_built_in_hand_and_anything_else_a_file() {
    assert_eq!("builtin".parse::<ModelSource>().unwrap(), ModelSource::Builtin(HandParams::default()));
    assert_eq!("hand.glb".parse::<ModelSource>().unwrap(), ModelSource::File("hand.glb".into()));
    assert_eq!(ModelSource::Builtin(HandParams::default()).to_string(), "builtin");
    let err = "missing.glb".parse::<ModelSource>().unwrap().load().unwrap_err().to_string();
    assert!(err.starts_with("missing.glb: "), "{err}");
}
