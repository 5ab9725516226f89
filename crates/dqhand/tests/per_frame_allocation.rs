//! The per-frame path allocates nothing: one engine step (pose → local transforms → forward
//! kinematics → skinning transforms and dual quaternions → deformation with each method),
//! with buffers made once beforehand; gesture features and recognition; the contact
//! constraint; and a good JSON record read from a file or a datagram. (The viewer's
//! session and live input: `crates/dqhand-stream/tests/per_frame_allocation.rs`.)

use std::sync::Arc;

use dqhand::engine::Engine;
use dqhand::gesture::{GestureSet, HandFeatures, Recognizer, Sequence};
use dqhand::hand::{build, HandParams, Side};
use dqhand::kinematics::{JointModel, JointPositions, Pose};
use dqhand::skin::MethodSet;
use dqhand::input::InputConfig;
use dqhand::collision::{fit_proxies, ContactConstraint, HandProxies, ObjectColliders, PROXY_MARGIN};
use dqhand::grasp::GraspParams;
use dqhand::interaction::grasp_script::{self, GraspTask};
use dqhand::interaction::synthetic::{generate, SyntheticParams};
use dqhand::interaction::ManipulationLoop;
use dqhand::scene::Scene;

#[path = "support/allocations.rs"]
mod allocations;

use allocations::allocations;

#[test]
fn an_engine_step_allocates_nothing() {
    let model = Arc::new(build(&HandParams::default()).unwrap());
    let mut engine = Engine::new(model, JointModel::Full).unwrap();
    engine.set_methods(MethodSet::ALL);
    let sequence = Sequence::gestures(JointModel::Full);
    let rest_wrist = engine.kinematics().rig().rest_wrist();
    let mut pose = Pose::rest(JointModel::Full.dof_count());
    let before = allocations();
    for f in 0..60 {
        sequence.sample(f as f32 * 0.35, rest_wrist, &mut pose);
        engine.step(&pose);
    }
    assert_eq!(allocations() - before, 0, "allocations during 60 engine steps");
}


#[test]
fn gesture_features_and_recognition_allocate_nothing() {
    let model = Arc::new(build(&HandParams { vertices: 2000, ..HandParams::default() }).unwrap());
    let mut hand = model.hand_kinematics(JointModel::Full).unwrap();
    let joints = JointPositions::new(hand.skeleton()).unwrap();
    let mut recognizer = Recognizer::new(GestureSet::builtin());
    let sequence = Sequence::gestures(JointModel::Full);
    let rest_wrist = hand.rig().rest_wrist();
    let mut pose = Pose::rest(JointModel::Full.dof_count());
    let mut events = 0;
    let before = allocations();
    for f in 0..600 {
        let t = f as f32 / 30.0;
        sequence.sample(t, rest_wrist, &mut pose);
        hand.pose(&pose);
        let features = HandFeatures::from_positions(&joints.read(hand.world()), Side::Right);
        events += recognizer.update(f64::from(t), &features).count();
    }
    assert_eq!(allocations() - before, 0, "allocations during 600 frames of features and recognition");
    assert!(events > 10, "the sequence's gestures were recognised: {events} events");
}


#[test]
fn reading_a_good_json_record_allocates_nothing() {
    use dqhand::input::json_record::{write_record, JsonRecordReader};
    let synthetic = generate(&SyntheticParams { seed: 4, holds: 2, idle_s: 0.5, ..SyntheticParams::default() }).unwrap();
    let mut text = Vec::new();
    for r in &synthetic.records {
        write_record(&mut text, r, &[] as &[&str]).unwrap();
    }
    let mut reader = JsonRecordReader::new(std::io::Cursor::new(text), Side::Right, Vec::new());
    let mut record = synthetic.records[0];
    reader.next_record(&mut record).unwrap().unwrap().unwrap();
    let before = allocations();
    let mut read = 0;
    while let Some(r) = reader.next_record(&mut record).unwrap() {
        r.unwrap();
        read += 1;
    }
    assert_eq!(allocations() - before, 0, "allocations reading {read} joints records");
}

#[test]
fn the_contact_constraint_allocates_nothing_per_frame() {
    // The manipulation loop's own per-frame work (track, solve the rendered pose against the
    // objects and the table, contacts) over a grasp of the ball, held as the loop holds it;
    // rapier's step, which allocates a few times a step inside the dependency, is left out.
    let model = Arc::new(build(&HandParams { vertices: 2000, ..HandParams::default() }).unwrap());
    let scene = Scene::named("grasp").unwrap();
    let objects = ObjectColliders::new(&scene).unwrap();
    let script = grasp_script::grasp(model.clone(), "grasp", &objects, &GraspTask::from_above("ball"), Side::Right).unwrap();
    let mut manip = ManipulationLoop::new(model.clone(), JointModel::Full, None, InputConfig::default(), None, &scene, GraspParams::default()).unwrap();
    let tracked = manip.input().kinematics().clone();
    let mut constraint = ContactConstraint::new(HandProxies::new(&fit_proxies(&model, PROXY_MARGIN), tracked.skeleton()), tracked);
    let (mut allocated, mut touching) = (0, 0);
    for (i, r) in script.records.iter().enumerate() {
        manip.push(r).unwrap();
        if let Some(dqhand::grasp::GraspEvent::Grasp { object }) = manip.step(r.time) {
            // As the loop does: the rendered hand keeps its grip on what it holds.
            constraint.grip(object, &manip.objects().objects()[object].pose);
        }
        let before = allocations();
        constraint.track(manip.input().pipeline().pose(), manip.input().kinematics().world());
        let held = manip.held();
        constraint.solve(manip.objects(), held, r.time);
        if i > 0 {
            allocated += allocations() - before;
        }
        touching += usize::from(!constraint.contacts().is_empty());
    }
    assert_eq!(allocated, 0, "allocations of the contact constraint over {} frames", script.records.len());
    assert!(touching > 30, "the hand touched the ball in {touching} frames");
}
