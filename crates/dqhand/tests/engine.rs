//! The engine step (the paper's Figure 1): what its two stages compute, against the layers
//! called one by one, what a new engine holds, and the skin layer writing into the caller's
//! buffers.

mod support;

use std::sync::{Arc, LazyLock};

use dqhand::engine::{Engine, ModelSource};
use dqhand::gesture::gesture;
use dqhand::hand::{build, HandParams};
use dqhand::kinematics::{skinning_transforms, HandRig, JointModel, Limits, PoseTarget};
use dqhand::model::Model;
use dqhand::skin::{Deformed, Deformer, Method, MethodSet, SkinLayer, VertexBuffers};
use glam::Quat;

static HAND: LazyLock<Arc<Model>> = LazyLock::new(|| Arc::new(build(&HandParams { vertices: 2000, ..HandParams::default() }).unwrap()));

#[test]
fn a_new_engine_holds_the_rest_mesh_skinned_with_dqb() {
    let engine = Engine::new(HAND.clone(), JointModel::Paper).unwrap();
    for (v, p) in engine.deformed(Method::Dqb).unwrap().positions().iter().enumerate() {
        assert_close!(*p, HAND.mesh.position(v).to_array(), 1e-5);
    }
    assert!(engine.deformed(Method::Lb).is_none(), "a method never in the set has no buffers");
    assert_eq!(engine.kinematics().layer().passes(), 0, "the rest pose is not a pass");
}

#[test]
fn a_step_is_the_rig_then_forward_kinematics_then_the_chosen_deformers() {
    let mut engine = Engine::new(HAND.clone(), JointModel::Full).unwrap();
    engine.set_methods(MethodSet::new(&[Method::Qb, Method::Lb]).unwrap());
    let pose = gesture("ok").unwrap().pose(JointModel::Full);
    let untouched = engine.deformed(Method::Dqb).unwrap().clone();
    engine.step(&pose);
    assert_eq!(engine.kinematics().layer().passes(), 1, "one forward kinematics pass per step");
    // The same frame, layer by layer.
    let rig = HandRig::new(&HAND.skeleton, JointModel::Full).unwrap();
    let world = support::world_of(&rig, &pose, Limits::Anatomical);
    let mut skinning = world.clone();
    skinning_transforms(&world, HAND.mesh.inverse_bind(), &mut skinning);
    assert_eq!(engine.kinematics().world(), world.as_slice());
    assert_eq!(engine.kinematics().skinning(), skinning.as_slice());
    for (q, m) in engine.kinematics().dual_quats().iter().zip(&skinning) {
        // Written from the definition: the rotation of the matrix, and ½ t q for the dual part.
        let (_, r, t) = m.to_scale_rotation_translation();
        let r = if r.dot(q.real) < 0.0 { -r } else { r };
        assert!(q.real.abs_diff_eq(r, 1e-6) && q.is_normalized(1e-5), "{q:?} vs {r:?}");
        assert!(q.translation().abs_diff_eq(t, 1e-5));
    }
    for m in [Method::Qb, Method::Lb] {
        let mut out = Deformed::new(&HAND.mesh);
        Deformer::new(m, &HAND.mesh).deform(&HAND.mesh, &skinning, &mut out);
        assert_eq!(engine.deformed(m).unwrap(), &out, "{m}");
    }
    assert_eq!(engine.deformed(Method::Dqb).unwrap(), &untouched, "a method not chosen is not skinned");
}

#[test]
fn dqb_from_the_kinematics_layers_dual_quaternions_equals_dqb_from_the_matrices() {
    let mut engine = Engine::new(HAND.clone(), JointModel::Full).unwrap();
    engine.step(&gesture("fist").unwrap().pose(JointModel::Full));
    let mut out = Deformed::new(&HAND.mesh);
    Deformer::new(Method::Dqb, &HAND.mesh).deform(&HAND.mesh, engine.kinematics().skinning(), &mut out);
    assert_eq!(engine.deformed(Method::Dqb).unwrap(), &out);
}

#[test]
fn the_skin_layer_writes_the_callers_buffers_as_its_own() {
    // A hand whose vertices end in a partial 16-vertex block: the tail is tested too.
    let hand = (2001..2100)
        .map(|vertices| Arc::new(build(&HandParams { vertices, ..HandParams::default() }).unwrap()))
        .find(|h| h.mesh.vertex_count() % 16 != 0)
        .expect("a vertex count that is no multiple of 16");
    let n = hand.mesh.vertex_count();
    let mut engine = Engine::new(hand.clone(), JointModel::Full).unwrap();
    engine.kinematics_mut().pose(&gesture("victory").unwrap().pose(JointModel::Full));
    let layer = engine.kinematics().layer().clone();
    let mut skin = SkinLayer::new(Arc::clone(&hand.mesh), MethodSet::PAPER);
    for m in Method::ALL {
        skin.set_methods(MethodSet::new(&[m]).unwrap());
        skin.deform(&layer);
        let own = skin.deformed(m).unwrap().clone();
        let (mut positions, mut normals) = (vec![f32::NAN; n * 3], vec![f32::NAN; n * 3]);
        skin.deform_into(m, &layer, VertexBuffers::Separate { positions: &mut positions, normals: Some(&mut normals) });
        assert_eq!(positions, own.positions().as_flattened(), "{m} positions");
        assert_eq!(normals, own.normals().as_flattened(), "{m} normals");
        let mut only = vec![f32::NAN; n * 3];
        skin.deform_into(m, &layer, VertexBuffers::Separate { positions: &mut only, normals: None });
        assert_eq!(only, own.positions().as_flattened(), "{m} positions only");
        let mut interleaved = vec![f32::NAN; n * 6];
        skin.deform_into(m, &layer, VertexBuffers::Interleaved(&mut interleaved));
        for (v, x) in interleaved.chunks(6).enumerate() {
            assert_eq!(x[..3], own.positions()[v], "{m} interleaved position {v}");
            assert_eq!(x[3..], own.normals()[v], "{m} interleaved normal {v}");
        }
    }
}

#[test]
#[should_panic(expected = "positions: #V × 3 floats")]
fn a_callers_buffer_of_the_wrong_size_is_refused() {
    let layer = HAND.kinematics();
    let mut skin = SkinLayer::new(Arc::clone(&HAND.mesh), MethodSet::DQB);
    let mut short = vec![0.0; 3];
    skin.deform_into(Method::Dqb, &layer, VertexBuffers::Separate { positions: &mut short, normals: None });
}

#[test]
fn a_pose_file_is_posed_on_its_joint_model_or_on_the_files_own_hierarchy() {
    let fist = gesture("fist").unwrap().pose(JointModel::Paper);
    let angles = PoseTarget::Angles { model: JointModel::Paper, pose: fist.clone() };
    let (layer, clamped) = HAND.pose_target(&angles, Limits::Anatomical).unwrap();
    assert!(clamped.is_empty());
    let rig = HandRig::new(&HAND.skeleton, JointModel::Paper).unwrap();
    assert_eq!(layer.world(), support::world_of(&rig, &fist, Limits::Anatomical).as_slice());
    let wrist = HAND.skeleton.find("wrist").unwrap();
    let turn = Quat::from_rotation_y(0.5);
    let rotations = PoseTarget::LocalRotations(vec![(wrist, turn)]);
    let (layer, clamped) = HAND.pose_target(&rotations, Limits::Anatomical).unwrap();
    assert!(clamped.is_empty());
    assert!(layer.world()[wrist].matrix3.abs_diff_eq(glam::Mat3A::from_quat(turn), 1e-6));
}

#[test]
fn an_angle_out_of_range_is_clamped_and_named() {
    let mut pose = gesture("fist").unwrap().pose(JointModel::Paper);
    pose.angles[0] = 3.0;
    let target = PoseTarget::Angles { model: JointModel::Paper, pose: pose.clone() };
    let (_, clamped) = HAND.pose_target(&target, Limits::Anatomical).unwrap();
    assert_eq!(clamped.len(), 1, "{clamped:?}");
    assert_eq!(clamped[0].dof, JointModel::Paper.dofs().next().unwrap().name());
    assert!(clamped[0].to_string().contains("clamped to its range"), "{}", clamped[0]);
    let (_, clamped) = HAND.pose_target(&target, Limits::Off).unwrap();
    assert!(clamped.is_empty());
}

#[test]
fn builtin_names_the_built_in_hand_and_anything_else_a_file() {
    assert_eq!("builtin".parse::<ModelSource>().unwrap(), ModelSource::Builtin(HandParams::default()));
    assert_eq!("hand.glb".parse::<ModelSource>().unwrap(), ModelSource::File("hand.glb".into()));
    assert_eq!(ModelSource::Builtin(HandParams::default()).to_string(), "builtin");
    let err = "missing.glb".parse::<ModelSource>().unwrap().load().unwrap_err().to_string();
    assert!(err.starts_with("missing.glb: "), "{err}");
}
