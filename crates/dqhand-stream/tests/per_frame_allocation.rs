//! The viewer's per-frame path allocates nothing: a viewer session's frame (playback, three
//! methods, heat map, encoding), and a live record through the gesture loop (check,
//! retarget, filter, kinematics, features, recogniser, the viewer's gesture actions) into the
//! input every viewer follows (also with a scene: contact constraint, grasp, physics).

use std::sync::Arc;

use dqhand::collision::ObjectColliders;
use dqhand::gesture::GestureSet;
use dqhand::grasp::GraspParams;
use dqhand::hand::{build, HandParams, Side};
use dqhand::input::{InputConfig, Record};
use dqhand::interaction::grasp_script::{self, GraspTask};
use dqhand::interaction::synthetic::{generate, SyntheticParams};
use dqhand::interaction::{GestureLoop, ManipulationLoop};
use dqhand::kinematics::JointModel;
use dqhand::scene::Scene;
use dqhand_stream::{Command, LiveInput, Session};

#[path = "../../dqhand/tests/support/allocations.rs"]
mod allocations;

use allocations::allocations;

#[test]
fn a_viewer_session_frame_allocates_nothing() {
    let model = Arc::new(build(&HandParams { vertices: 2000, ..HandParams::default() }).unwrap());
    let mut session = Session::new(model, None, JointModel::Full).unwrap();
    for c in [r#"{"type":"view","methods":["lb","qb","dqb"]}"#, r#"{"type":"heatmap","on":true}"#] {
        session.apply(&Command::parse(c).unwrap()).unwrap();
    }
    let mut frame = Vec::new();
    session.render(120.0, &mut frame);
    let before = allocations();
    for _ in 0..30 {
        session.advance(1.0 / 30.0);
        session.render(120.0, &mut frame);
    }
    assert_eq!(allocations() - before, 0, "allocations during 30 session frames");
    session.apply(&Command::parse(r#"{"type":"gesture","name":"fist"}"#).unwrap()).unwrap();
    let before = allocations();
    for _ in 0..30 {
        session.advance(1.0 / 30.0);
        session.render(120.0, &mut frame);
    }
    assert_eq!(allocations() - before, 0, "allocations during 30 frames of a move to a gesture");
}

#[test]
fn a_two_hand_session_frame_allocates_nothing() {
    let model = |side| Arc::new(build(&HandParams { vertices: 2000, side, ..HandParams::default() }).unwrap());
    let mut session = Session::new(model(Side::Right), Some((model(Side::Left), Side::Left)), JointModel::Full).unwrap();
    session.apply(&Command::parse(r#"{"type":"heatmap","on":true}"#).unwrap()).unwrap();
    let (mut first, mut second) = (Vec::new(), Vec::new());
    let pose = dqhand::kinematics::Pose::rest(JointModel::Full.dof_count());
    session.render(120.0, &mut first);
    assert!(session.render_second(120.0, &mut second));
    let before = allocations();
    for _ in 0..30 {
        session.follow_second(&pose, JointModel::Full);
        session.render(120.0, &mut first);
        session.render_second(120.0, &mut second);
    }
    assert_eq!(allocations() - before, 0, "allocations during 30 frames of two hands");
}

#[test]
fn a_live_record_and_a_viewer_update_without_news_allocate_nothing() {
    let model = Arc::new(build(&HandParams { vertices: 2000, ..HandParams::default() }).unwrap());
    let synthetic = generate(&SyntheticParams { seed: 9, holds: 4, idle_s: 1.0, ..SyntheticParams::default() }).unwrap();
    // A long grace time: a descheduled test thread must not mark the hand lost (news).
    let config = InputConfig { grace_s: 1e6, ..InputConfig::default() };
    let gesture_loop = GestureLoop::new(model.clone(), JointModel::Full, None, config, Some(GestureSet::builtin())).unwrap();
    let input = LiveInput::new(gesture_loop, "test", true).unwrap();
    let mut session = Session::new(model, None, JointModel::Full).unwrap();
    let mut view = input.view();
    let taken = push_live(&input, &synthetic.records);
    assert!(taken > 300, "{taken} records taken");
    assert!(input.update(&mut session, &mut view).message.is_some(), "the first update reports the state");
    let before = allocations();
    for _ in 0..30 {
        assert!(input.update(&mut session, &mut view).message.is_none());
    }
    assert_eq!(allocations() - before, 0, "allocations during 30 viewer updates without news");
}

#[test]
#[ignore = "rapier3d's PhysicsWorld::step allocates a few times a step inside the dependency (about 7 a frame with the grasp scene at rest); the loop's own work does not (the_contact_constraint_allocates_nothing_per_frame)"]
fn a_live_record_through_a_scene_allocates_nothing() {
    let model = Arc::new(build(&HandParams { vertices: 2000, ..HandParams::default() }).unwrap());
    let scene = Scene::named("grasp").unwrap();
    let objects = ObjectColliders::new(&scene).unwrap();
    let script = grasp_script::grasp(model.clone(), "grasp", &objects, &GraspTask::from_above("ball"), Side::Right).unwrap();
    let config = InputConfig { grace_s: 1e6, ..InputConfig::default() };
    let manip = ManipulationLoop::new(model, JointModel::Full, None, config, Some(GestureSet::builtin()), &scene, GraspParams::default()).unwrap();
    let input = LiveInput::with_scene(manip, "test", true).unwrap();
    let taken = push_live(&input, &script.records);
    assert!(taken > 100, "{taken} records taken");
}

/// Pushes `records` into `input` live, the first ten to warm up; asserts that the rest
/// allocated nothing and returns how many of them were taken.
fn push_live(input: &LiveInput, records: &[Record]) -> usize {
    let (warm_up, rest) = records.split_at(10);
    for r in warm_up {
        input.push(r, |_| {}).unwrap();
    }
    let before = allocations();
    let taken = rest.iter().filter(|r| input.push(r, |_| {}).is_ok()).count();
    assert_eq!(allocations() - before, 0, "allocations during {} live records", rest.len());
    taken
}
