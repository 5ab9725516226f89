//! Viewers of two hands: a session with a second hand streams its topology and frames after
//! the first's, and a live input of two hands drives each by the side of its records (the
//! right hand shown first), reporting both hands' state and what each holds.

use std::collections::BTreeSet;
use std::sync::{Arc, LazyLock};

use glam::Vec3;
use serde_json::Value;

use dqhand::collision::ObjectColliders;
use dqhand::gesture::GestureSet;
use dqhand::grasp::GraspParams;
use dqhand::hand::{build, HandParams, Side};
use dqhand::input::{HandData, InputConfig, Record};
use dqhand::interaction::grasp_script;
use dqhand::interaction::ManipulationLoop;
use dqhand::kinematics::{JointModel, Pose};
use dqhand::math::DualQuat;
use dqhand::model::Model;
use dqhand::scene::Scene;
use dqhand_stream::{FrameView, LiveInput, Session, Topology};

static RIGHT: LazyLock<Arc<Model>> = LazyLock::new(|| Arc::new(build(&HandParams { vertices: 1500, ..HandParams::default() }).unwrap()));
static LEFT: LazyLock<Arc<Model>> = LazyLock::new(|| Arc::new(build(&HandParams { vertices: 1500, side: Side::Left, ..HandParams::default() }).unwrap()));

fn two_hand_session() -> Session {
    Session::new(RIGHT.clone(), Some((LEFT.clone(), Side::Left)), JointModel::Full).unwrap()
}

/// The first hand's frame and the second's, rendered now.
fn frames(session: &mut Session) -> (FrameView, Option<FrameView>) {
    let (mut first, mut second) = (Vec::new(), Vec::new());
    session.render(60.0, &mut first);
    let has_second = session.render_second(60.0, &mut second);
    (FrameView::parse(&first).unwrap(), has_second.then(|| FrameView::parse(&second).unwrap()))
}

fn mean_x(positions: &[f32]) -> f32 {
    positions.chunks_exact(3).map(|p| p[0]).sum::<f32>() / (positions.len() / 3) as f32
}

#[test]
fn a_session_of_two_hands_sends_the_second_hand_after_the_first() {
    let mut session = two_hand_session();
    let hello: Value = serde_json::from_str(&session.hello(1 << 16, None)).unwrap();
    assert_eq!(hello["second_hand"]["side"], "left");
    assert_eq!(hello["second_hand"]["vertices"], LEFT.mesh.vertex_count());
    let topologies: Vec<Topology> = session.topologies().iter().map(|t| Topology::parse(&t.encode()).unwrap()).collect();
    assert_eq!(topologies.iter().map(|t| t.hand).collect::<Vec<_>>(), [0, 1]);
    assert_eq!(topologies[1].vertex_count as usize, LEFT.mesh.vertex_count());
    assert_eq!(topologies[1].indices, LEFT.mesh.indices());

    let (first, second) = frames(&mut session);
    let second = second.expect("a second hand's frame");
    assert!(!first.header.second && second.header.second);
    assert_eq!(second.header.sequence, first.header.sequence + 1, "one sequence for both hands' frames");
    // Built as itself, the left hand at rest is the right one's mirror image (x → −x).
    let (r, l) = (mean_x(&first.meshes[0][0]), mean_x(&second.meshes[0][0]));
    assert!(r.abs() > 0.003 && (r + l).abs() < 0.1 * r.abs(), "mean x: right {r}, left {l}");

    // The second hand follows its own pose only; the first keeps its own.
    let before = frames(&mut session).0.header.wrist;
    let mut pose = Pose::rest(JointModel::Full.dof_count());
    pose.wrist = Some(DualQuat::from_rotation_translation(glam::Quat::IDENTITY, Vec3::new(-0.3, 1.0, -0.2)));
    session.follow_second(&pose, JointModel::Full);
    let (first, second) = frames(&mut session);
    assert_eq!(&second.unwrap().header.wrist[..3], &[-0.3, 1.0, -0.2]);
    assert_eq!(first.header.wrist, before);

    // The view's settings apply to both hands: the joint model (the DOF count), the methods and
    // the joint limits.
    for command in [r#"{"type":"joint_model","name":"paper"}"#, r#"{"type":"view","methods":["lb","dqb"]}"#, r#"{"type":"limits","on":false}"#] {
        session.apply(&dqhand_stream::Command::parse(command).unwrap()).unwrap();
    }
    let (first, second) = frames(&mut session);
    let second = second.unwrap();
    for h in [&first.header, &second.header] {
        assert_eq!((h.dof_count as usize, h.methods.len(), h.state & dqhand_stream::frame::STATE_LIMITS), (JointModel::Paper.dof_count(), 2, 0));
    }

    // Without a second hand, no second frame and no sequence number skipped (the transport's
    // flow control counts the frames it sends).
    let mut one = Session::new(RIGHT.clone(), None, JointModel::Full).unwrap();
    let sequences: Vec<u32> = (0..3)
        .map(|_| {
            assert!(!one.render_second(60.0, &mut Vec::new()), "no second hand, no second frame");
            frames(&mut one).0.header.sequence
        })
        .collect();
    assert_eq!(sequences, [0, 1, 2]);
    let hello: Value = serde_json::from_str(&one.hello(1 << 16, None)).unwrap();
    assert!(hello["second_hand"].is_null());
}

#[test]
fn a_live_input_of_two_hands_drives_each_viewer_hand_by_side() {
    let scene = Scene::named("two-hands").unwrap();
    let objects = ObjectColliders::new(&scene).unwrap();
    let script = grasp_script::carry_between([&LEFT, &RIGHT], "two-hands", &objects, "box", 0.12, Vec3::new(0.0, 0.0, -0.2)).unwrap();
    // Records pushed as fast as the test runs: none is late, none is lost.
    let config = InputConfig { grace_s: 1e6, max_latency_s: 1e6, ..InputConfig::default() };
    let hands = [(LEFT.clone(), None), (RIGHT.clone(), None)];
    let manip = ManipulationLoop::two_handed(hands, JointModel::Full, config, Some(GestureSet::builtin()), &scene, GraspParams::default()).unwrap();
    let input = LiveInput::with_scene(manip, "test", true).unwrap();
    assert!(input.two_hands());
    let mut session = two_hand_session();
    let mut view = input.view();
    let (mut inputs, mut scenes) = (Vec::new(), Vec::new());
    let mut last = [None; 2];
    for r in &script.records {
        input.push(r, |_| {}).unwrap();
        if let Some(HandData::Joints(joints)) = &r.hand {
            last[usize::from(r.side == Side::Right)] = joints.get(0).map(|j| j.position);
        }
        let update = input.update(&mut session, &mut view);
        inputs.extend(update.message.map(|m| serde_json::from_str::<Value>(&m).unwrap()));
        scenes.extend(update.scene.map(|m| serde_json::from_str::<Value>(&m).unwrap()));
    }
    // Each viewer hand is where its side's last record put the wrist (the rendered hand stops
    // at the box, so within a few centimetres).
    let (first, second) = frames(&mut session);
    for (frame, side) in [(first, 1), (second.unwrap(), 0)] {
        let wrist = Vec3::from_slice(&frame.header.wrist[..3]);
        let tracked = last[side].expect("records of both sides");
        assert!(wrist.distance(tracked) < 0.05, "side {side}: shown {wrist}, tracked {tracked}");
    }
    let state = inputs.last().unwrap();
    assert_eq!(state["side"], "right");
    let sides: Vec<_> = state["hands"].as_array().unwrap().iter().map(|h| (h["side"].as_str().unwrap(), h["tracking"].as_str().unwrap())).collect();
    assert_eq!(sides, [("right", "tracking"), ("left", "tracking")]);
    // The box is held by both hands at some point, and the contacts name their hands.
    let both = scenes.iter().any(|s| s["holding"]["left"] == "box" && s["holding"]["right"] == "box");
    assert!(both, "never held by both hands: {:?}", scenes.iter().map(|s| s["holding"].to_string()).collect::<std::collections::BTreeSet<_>>());
    let hands: std::collections::BTreeSet<&str> = scenes.iter().flat_map(|s| s["contacts"].as_array().unwrap()).map(|c| c["hand"].as_str().unwrap()).collect();
    assert_eq!(hands.into_iter().collect::<Vec<_>>(), ["left", "right"]);
    // Events name their hand.
    let named: Vec<&str> = inputs.iter().flat_map(|m| m["events"].as_array().unwrap()).map(|e| e["hand"].as_str().unwrap()).collect();
    assert!(named.contains(&"left") && named.contains(&"right") && named.contains(&"both"), "events named {named:?}");
}

#[test]
fn only_the_right_hand_commands_the_view() {
    use dqhand::interaction::synthetic::{generate, SyntheticParams};
    // Every gesture of the library held in turn (thumbs up among them: the default `next_method`
    // action), first by the user's left hand alone, then by the right.
    let sequence = |side, seed| {
        let hand = HandParams { side, ..HandParams::default() };
        generate(&SyntheticParams { seed, hand: Some(hand), holds: 13, idle_s: 0.5, ..SyntheticParams::default() }).unwrap().records
    };
    let config = InputConfig { grace_s: 1e6, max_latency_s: 1e6, ..InputConfig::default() };
    let scene = Scene::named("two-hands").unwrap();
    let manip = ManipulationLoop::two_handed([(LEFT.clone(), None), (RIGHT.clone(), None)], JointModel::Full, config, Some(GestureSet::builtin()), &scene, GraspParams::default()).unwrap();
    let input = LiveInput::with_scene(manip, "test", true).unwrap();
    let mut session = two_hand_session();
    let mut view = input.view();
    let left = sequence(Side::Left, 3);
    let end = left.last().unwrap().time;
    let mut left_gestures = BTreeSet::new();
    // Plays `records` (shifted in time) into the input, the viewer updated after each; returns
    // the viewer actions reported, and collects the left hand's gestures.
    fn play(input: &LiveInput, session: &mut Session, view: &mut dqhand_stream::InputView, records: &[Record], shift: f64, gestures: &mut BTreeSet<String>) -> usize {
        let mut actions = 0;
        for r in records {
            input.push(&Record { time: r.time + shift, ..*r }, |_| {}).unwrap();
            if let Some(m) = input.update(session, view).message {
                let m: Value = serde_json::from_str(&m).unwrap();
                gestures.extend(m["events"].as_array().unwrap().iter().filter(|e| e["hand"] == "left").map(|e| e["gesture"].as_str().unwrap().to_owned()));
                actions += m["actions"].as_array().unwrap().len();
            }
        }
        actions
    }
    let left_actions = play(&input, &mut session, &mut view, &left, 0.0, &mut left_gestures);
    assert!(left_gestures.contains("thumbs_up"), "the left hand's gestures: {left_gestures:?}");
    assert_eq!((left_actions, session.methods().as_slice()), (0, &[dqhand::skin::Method::Dqb][..]), "the left hand's thumbs up changed the view");
    let right_actions = play(&input, &mut session, &mut view, &sequence(Side::Right, 4), end + 1.0, &mut BTreeSet::new());
    assert!(right_actions > 0 && session.methods().as_slice() != [dqhand::skin::Method::Dqb], "the right hand's thumbs up did not change the view");
}
