//! The viewer stream: the binary format (golden vectors shared with the page's tests, round
//! trips, refusals) and a session's behaviour against the engine it wraps.

#[path = "../../dqhand/tests/support/mod.rs"]
mod support;

use std::path::PathBuf;
use std::sync::{Arc, LazyLock};

use dqhand::gesture::{gesture, Keyframe, Sequence, GESTURES};
use dqhand::hand::{build, HandParams};
use dqhand::kinematics::{HandRig, JointModel, Limits, Pose};
use dqhand::math::DualQuat;
use dqhand::metrics::VertexDistortion;
use dqhand::model::Model;
use dqhand::kinematics::skinning_transforms;
use dqhand::skin::{Deformed, Deformer, Method, MethodSet};
use dqhand_stream::frame::{STATE_LIMITS, STATE_PLAYING};
use dqhand_stream::{Applied, Command, FrameHeader, FrameView, FrameWriter, Session, Topology};
use proptest::prelude::*;

static HAND: LazyLock<Arc<Model>> = LazyLock::new(|| Arc::new(build(&HandParams { vertices: 3000, ..HandParams::default() }).unwrap()));

fn fixtures() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../viewer/tests/fixtures")
}

/// Compares with the committed file (the page's protocol test reads the same file);
/// `DQHAND_UPDATE_GOLDEN=1` rewrites it.
fn golden(name: &str, bytes: &[u8]) {
    let path = fixtures().join(name);
    if std::env::var_os("DQHAND_UPDATE_GOLDEN").is_some() {
        std::fs::write(&path, bytes).unwrap();
    }
    let expected = std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    assert_eq!(bytes, expected.as_slice(), "{name} differs from the golden file (format changed?)");
}

/// The frame in viewer/tests/fixtures/frame-v2.bin: 2 vertices, 2 joints, 3 DOFs, LB and DQB
/// with distortion; every value distinct so a misplaced field shows.
fn sample_frame() -> (FrameHeader, Vec<u8>) {
    let header = FrameHeader {
        sequence: 7,
        vertex_count: 2,
        joint_count: 2,
        dof_count: 3,
        methods: MethodSet::new(&[Method::Lb, Method::Dqb]).unwrap(),
        distortion: true,
        second: false,
        engine_us: 123.5,
        engine_fps: 120.0,
        time: 1.25,
        duration: 21.0,
        state: STATE_PLAYING | STATE_LIMITS,
        wrist: [0.1, 0.2, 0.3, 0.0, 0.0, 0.0, 1.0],
    };
    let mut out = Vec::new();
    let mut w = FrameWriter::begin(&mut out, header);
    w.floats(&[0.5, -0.25, 1.0]).floats(&[0.0, 0.0, 0.0, 0.0, 0.0, -0.05]);
    for m in 0..2 {
        let base = 10.0 * (m + 1) as f32;
        let positions: Vec<f32> = (0..6).map(|i| base + i as f32).collect();
        w.floats(&positions).floats(&[0.0, 1.0, 0.0, 0.0, 0.0, 1.0]).floats(&[0.125 * (m + 1) as f32, 0.0]);
    }
    w.finish();
    (header, out)
}

#[test]
fn frame_format_matches_the_golden_vector_and_reads_back() {
    let (header, bytes) = sample_frame();
    golden("frame-v2.bin", &bytes);
    assert_eq!(bytes.len(), header.byte_len());
    assert_eq!(&bytes[..4], b"DQHF");
    let view = FrameView::parse(&bytes).unwrap();
    assert_eq!(view.header, header);
    assert_eq!(view.angles, [0.5, -0.25, 1.0]);
    assert_eq!(view.joints[5], -0.05);
    assert_eq!(view.meshes.len(), 2);
    assert_eq!(view.meshes[1][0][0], 20.0);
    assert_eq!(view.meshes[1][2], [0.25, 0.0]);
}

#[test]
fn topology_format_matches_the_golden_vector_and_reads_back() {
    let topology = Topology { hand: 0, vertex_count: 4, indices: vec![0, 1, 2, 2, 1, 3], parents: vec![None, Some(0), Some(1)] };
    let bytes = topology.encode();
    golden("topology-v2.bin", &bytes);
    assert_eq!(Topology::parse(&bytes).unwrap(), topology);
    // The second hand's says so; there is no third.
    let second = Topology { hand: 1, ..topology.clone() };
    assert_eq!(Topology::parse(&second.encode()).unwrap(), second);
    let third = Topology { hand: 2, ..topology }.encode();
    assert!(Topology::parse(&third).unwrap_err().to_string().contains("unknown to version 2"));
}

#[test]
fn malformed_messages_are_refused_with_the_reason() {
    let (_, frame) = sample_frame();
    let refuse = |bytes: &[u8], expect: &str| {
        let e = FrameView::parse(bytes).unwrap_err().to_string();
        assert!(e.contains(expect), "{e:?} should mention {expect:?}");
    };
    refuse(&frame[..frame.len() - 4], "bytes, the header announces");
    refuse(&[frame.as_slice(), &[0; 4]].concat(), "bytes, the header announces");
    refuse(&frame[..10], "truncated");
    refuse(b"", "truncated");
    let mut wrong = frame.clone();
    wrong[0] = b'X';
    refuse(&wrong, "wrong magic");
    let mut version = frame.clone();
    version[4] = 9;
    refuse(&version, "version 9");
    // Version 1's frame, a mesh count before three codes, is refused by its version.
    let mut v1 = frame.clone();
    v1[4] = 1;
    refuse(&v1, "version 1, this reader knows 2");
    let mut method = frame.clone();
    method[25] = 7;
    refuse(&method, "mesh 1: method code 7");
    let mut none = frame.clone();
    none[24] = 255;
    refuse(&none, "no meshes");
    // Issue 9 bug 4: a repeated method, or a gap in the list, is refused.
    let mut repeated = frame.clone();
    repeated[25] = repeated[24];
    refuse(&repeated, "given twice");
    // Found by fuzzing: flag bits a reader does not know could change the layout.
    let mut flags = frame.clone();
    flags[7] = 1;
    refuse(&flags, "unknown to version 2");
    let mut gap = frame.clone();
    (gap[25], gap[26]) = (255, 1);
    refuse(&gap, "mesh 2: method code 1 after the last mesh (1)");
    // Codes are checked before repeats, as the page's reader does (viewer/tests/protocol.test.ts).
    let mut order = frame.clone();
    order[24..28].copy_from_slice(&[0, 0, 255, 1]);
    refuse(&order, "mesh 3: method code 1 after the last mesh (2)");

    let topology = Topology { hand: 0, vertex_count: 2, indices: vec![0, 1, 2], parents: vec![None] }.encode();
    assert!(Topology::parse(&topology).unwrap_err().to_string().contains("index 2 with 2 vertices"));
    let own_parent = Topology { hand: 0, vertex_count: 3, indices: vec![0, 1, 2], parents: vec![Some(0)] }.encode();
    assert!(Topology::parse(&own_parent).unwrap_err().to_string().contains("parent 0"));
    assert!(Topology::parse(&frame).unwrap_err().to_string().contains("wrong magic"));
}

proptest! {
    #[test]
    fn frames_round_trip(
        vertices in 0u32..20, joints in 0u32..5, dofs in 0u32..6, meshes in 1usize..=4,
        distortion: bool, second: bool, sequence: u32, time in 0f32..100.0, seed in 0u32..1000,
    ) {
        let order: Vec<Method> = (0..meshes).map(|i| Method::ALL[(i + seed as usize) % Method::ALL.len()]).collect();
        let methods = MethodSet::new(&order).unwrap();
        let header = FrameHeader { sequence, vertex_count: vertices, joint_count: joints, dof_count: dofs, methods, distortion, second, time, ..FrameHeader::default() };
        let values: Vec<f32> = (0..(header.byte_len() - 76) / 4).map(|i| (i as f32 + seed as f32) * 0.5).collect();
        let mut out = Vec::new();
        let mut w = FrameWriter::begin(&mut out, header);
        w.floats(&values);
        w.finish();
        let view = FrameView::parse(&out).unwrap();
        prop_assert_eq!(view.header, header);
        let mut read: Vec<f32> = view.angles.clone();
        read.extend(&view.joints);
        for [p, n, d] in &view.meshes {
            read.extend(p.iter().chain(n).chain(d));
        }
        prop_assert_eq!(read, values);
    }
}

fn command(json: &str) -> Command {
    Command::parse(json).unwrap_or_else(|e| panic!("{json}: {e}"))
}

fn frame(session: &mut Session) -> FrameView {
    let mut out = Vec::new();
    session.render(60.0, &mut out);
    FrameView::parse(&out).unwrap()
}

fn paused() -> Session {
    let mut s = Session::new(HAND.clone(), None, JointModel::Full).unwrap();
    s.apply(&Command::Pause {}).unwrap();
    s.apply(&Command::Rest {}).unwrap();
    s
}

#[test]
fn a_frame_carries_what_the_engine_computes_for_the_pose() {
    let mut s = paused();
    s.apply(&command(r#"{"type":"angle","dof":"index-finger-phalanx-intermediate.flex","deg":90}"#)).unwrap();
    s.apply(&command(r#"{"type":"view","methods":["qb","dqb"]}"#)).unwrap();
    let f = frame(&mut s);
    assert_eq!(f.header.methods.as_slice(), [Method::Qb, Method::Dqb]);
    assert_eq!(f.header.vertex_count as usize, HAND.mesh.vertex_count());
    assert_eq!(f.header.state & STATE_PLAYING, 0);
    // The same pose through the engine directly.
    let rig = HandRig::new(&HAND.skeleton, JointModel::Full).unwrap();
    let mut pose = Pose::rest(JointModel::Full.dof_count());
    pose.angles[JointModel::Full.dof_index("index-finger-phalanx-intermediate.flex").unwrap()] = 90f32.to_radians();
    assert_eq!(f.angles, pose.angles);
    let world = support::world_of(&rig, &pose, Limits::Anatomical);
    let mut skinning = world.clone();
    skinning_transforms(&world, HAND.mesh.inverse_bind(), &mut skinning);
    for (i, m) in [Method::Qb, Method::Dqb].into_iter().enumerate() {
        let mut out = Deformed::new(&HAND.mesh);
        Deformer::new(m, &HAND.mesh).deform(&HAND.mesh, &skinning, &mut out);
        assert_eq!(f.meshes[i][0], out.positions().as_flattened(), "{m} positions");
        assert_eq!(f.meshes[i][1], out.normals().as_flattened(), "{m} normals");
        assert!(f.meshes[i][2].is_empty());
    }
    let tip = rig.skeleton().find("index-finger-tip").unwrap();
    let t = world[tip].translation;
    assert_eq!(&f.joints[3 * tip..3 * tip + 3], &[t.x, t.y, t.z]);
}

#[test]
fn angles_are_clamped_to_the_limits_unless_limits_are_off() {
    let mut s = paused();
    let pip = JointModel::Full.dof_index("index-finger-phalanx-intermediate.flex").unwrap();
    s.apply(&command(r#"{"type":"angle","dof":"index-finger-phalanx-intermediate.flex","deg":200}"#)).unwrap();
    assert!((s.pose().angles[pip].to_degrees() - 110.0).abs() < 1e-4);
    s.apply(&command(r#"{"type":"limits","on":false}"#)).unwrap();
    s.apply(&command(r#"{"type":"angle","dof":"index-finger-phalanx-intermediate.flex","deg":150}"#)).unwrap();
    assert!((s.pose().angles[pip].to_degrees() - 150.0).abs() < 1e-4);
    assert_eq!(frame(&mut s).header.state & STATE_LIMITS, 0);
}

#[test]
fn bad_commands_are_refused_and_change_nothing() {
    let mut s = paused();
    let before = frame(&mut s);
    for (json, expect) in [
        (r#"{"type":"angle","dof":"index-finger.twist","deg":10}"#, "unknown degree of freedom"),
        (r#"{"type":"angle","dof":"index-finger-phalanx-intermediate.flex","deg":1e40}"#, "not a finite number"),
        (r#"{"type":"view","methods":[]}"#, "0 methods"),
        (r#"{"type":"view","methods":["dqb","dqb"]}"#, "given twice"),
        // Issue 9 bug 4: names are parsed case-insensitively, so repeats are found after parsing.
        (r#"{"type":"view","methods":["dqb","DQB"]}"#, "given twice"),
        (r#"{"type":"view","methods":["xb"]}"#, "xb"),
        (r#"{"type":"gesture","name":"wave"}"#, "unknown gesture"),
        (r#"{"type":"gesture","name":"fist","seconds":-1}"#, "seconds"),
        (r#"{"type":"joint_model","name":"huge"}"#, "huge"),
    ] {
        let e = Command::parse(json).and_then(|c| s.apply(&c).map_err(|e| e.to_string()));
        let e = e.unwrap_err();
        assert!(e.contains(expect), "{json}: {e:?} should mention {expect:?}");
    }
    // Issue 15: commands without fields refuse unknown ones too, as the others do.
    let unknown = [r#"{"type":"play","evil":1}"#, r#"{"type":"pause","x":null}"#, r#"{"type":"rest","deg":3}"#, r#"{"type":"heatmap","on":true,"x":1}"#];
    for json in ["", "{", "[]", r#"{"type":"fly"}"#, r#"{"type":"angle","dof":"x"}"#].into_iter().chain(unknown) {
        assert!(Command::parse(json).unwrap_err().starts_with("not a valid command"), "{json}");
    }
    for json in [r#"{"type":"play"}"#, r#"{"type":"pause"}"#, r#"{"type":"rest"}"#] {
        Command::parse(json).unwrap();
    }
    let mut after = frame(&mut s);
    after.header.sequence = before.header.sequence;
    after.header.engine_us = before.header.engine_us;
    assert_eq!(after, before);
}

#[test]
fn a_gesture_is_reached_smoothly() {
    let mut s = paused();
    s.apply(&command(r#"{"type":"gesture","name":"fist","seconds":0.5}"#)).unwrap();
    let target = gesture("fist").unwrap().pose(JointModel::Full);
    let pip = JointModel::Full.dof_index("index-finger-phalanx-intermediate.flex").unwrap();
    let mut last = 0.0;
    for _ in 0..5 {
        s.advance(0.1);
        let a = s.pose().angles[pip];
        assert!(a > last && a <= target.angles[pip] + 1e-6, "monotonic approach: {a} after {last}");
        last = a;
    }
    s.advance(0.1);
    assert_eq!(s.pose().angles, target.angles);
}

#[test]
fn the_timeline_plays_loops_and_seeks() {
    let mut s = Session::new(HAND.clone(), None, JointModel::Full).unwrap();
    let tour = Sequence::gestures(JointModel::Full);
    assert_eq!(tour.duration(), GESTURES.len() as f32 * 1.5);
    s.advance(2.0);
    let f = frame(&mut s);
    assert!(f.header.state & STATE_PLAYING != 0 && (f.header.time - 2.0).abs() < 1e-5);
    let mut expected = Pose::rest(JointModel::Full.dof_count());
    tour.sample(2.0, DualQuat::IDENTITY, &mut expected);
    assert_eq!(s.pose().angles, expected.angles);
    s.advance(tour.duration());
    assert!((frame(&mut s).header.time - 2.0).abs() < 1e-3, "loops");
    s.apply(&command(r#"{"type":"seek","time":4.0}"#)).unwrap();
    tour.sample(4.0, DualQuat::IDENTITY, &mut expected);
    assert_eq!(s.pose().angles, expected.angles);
    s.apply(&command(r#"{"type":"angle","dof":"index-finger-phalanx-distal.flex","deg":10}"#)).unwrap();
    assert_eq!(frame(&mut s).header.state & STATE_PLAYING, 0, "an edit stops the timeline");
    s.apply(&Command::Play {}).unwrap();
    assert!(frame(&mut s).header.state & STATE_PLAYING != 0);
}

#[test]
fn the_heat_map_is_zero_at_rest_and_grows_at_a_bent_joint() {
    let mut s = paused();
    s.apply(&command(r#"{"type":"heatmap","on":true}"#)).unwrap();
    s.apply(&command(r#"{"type":"view","methods":["lb","dqb"]}"#)).unwrap();
    let rest = frame(&mut s);
    assert!(rest.header.distortion);
    assert!(rest.meshes.iter().all(|m| m[2].iter().all(|&d| d < 1e-4)), "no distortion at rest");
    s.apply(&command(r#"{"type":"angle","dof":"index-finger-phalanx-intermediate.flex","deg":110}"#)).unwrap();
    let bent = frame(&mut s);
    for m in &bent.meshes {
        let max = m[2].iter().copied().fold(0.0, f32::max);
        assert!(max > 0.05, "a 110° PIP stretches the skin: {max}");
    }
}

#[test]
fn switching_the_joint_model_keeps_the_shared_angles() {
    let mut s = paused();
    s.apply(&command(r#"{"type":"angle","dof":"middle-finger-phalanx-proximal.flex","deg":45}"#)).unwrap();
    s.apply(&command(r#"{"type":"angle","dof":"thumb-metacarpal.flex","deg":20}"#)).unwrap();
    assert_eq!(s.apply(&command(r#"{"type":"joint_model","name":"paper"}"#)).unwrap(), Applied::Hello);
    let hello: serde_json::Value = serde_json::from_str(&s.hello(4096, None)).unwrap();
    assert_eq!(hello["dofs"].as_array().unwrap().len(), 18);
    assert_eq!(hello["joint_model"], "paper");
    let i = JointModel::Paper.dof_index("middle-finger-phalanx-proximal.flex").unwrap();
    assert!((s.pose().angles[i].to_degrees() - 45.0).abs() < 1e-4);
    assert_eq!(frame(&mut s).angles.len(), 18);
    assert_eq!(s.apply(&command(r#"{"type":"joint_model","name":"paper"}"#)).unwrap(), Applied::Frame);
}

#[test]
fn hello_describes_the_model_and_its_controls() {
    let s = Session::new(HAND.clone(), None, JointModel::Full).unwrap();
    let hello: serde_json::Value = serde_json::from_str(&s.hello(4096, None)).unwrap();
    assert_eq!(hello["type"], "hello");
    assert_eq!(hello["vertices"], 3000);
    assert_eq!(hello["joints"].as_array().unwrap().len(), 25);
    let dofs = hello["dofs"].as_array().unwrap();
    assert_eq!(dofs.len(), 23);
    let pip = dofs.iter().find(|d| d["name"] == "index-finger-phalanx-intermediate.flex").unwrap();
    assert_eq!((pip["min_deg"].as_f64(), pip["max_deg"].as_f64()), (Some(0.0), Some(110.0)));
    assert_eq!(hello["gestures"].as_array().unwrap().len(), GESTURES.len());
    assert_eq!(hello["methods"], serde_json::json!(["lb", "qb", "dqb", "cor"]));
    let topology = Topology::parse(&s.topologies()[0].encode()).unwrap();
    assert_eq!(topology.indices.len(), 3 * HAND.mesh.triangle_count());
    assert_eq!(topology.parents.iter().filter(|p| p.is_none()).count(), 1);
}

#[test]
fn sequences_hit_their_keys_and_ease_between_them() {
    let model = JointModel::Paper;
    let mut a = Pose::rest(model.dof_count());
    let mut b = a.clone();
    a.angles[0] = 0.0;
    b.angles[0] = 1.0;
    let key = |time, pose: &Pose| Keyframe { time, pose: pose.clone() };
    let seq = Sequence::new("t", model, vec![key(0.0, &a), key(2.0, &b), key(3.0, &b)]).unwrap();
    let mut out = Pose::rest(model.dof_count());
    let rest = DualQuat::IDENTITY;
    seq.sample(-1.0, rest, &mut out);
    assert_eq!(out.angles[0], 0.0);
    seq.sample(1.0, rest, &mut out);
    assert!((out.angles[0] - 0.5).abs() < 1e-6, "smoothstep is ½ at the middle");
    seq.sample(0.5, rest, &mut out);
    assert!(out.angles[0] < 0.25, "eases in: {}", out.angles[0]);
    seq.sample(2.5, rest, &mut out);
    assert_eq!(out.angles[0], 1.0);
    seq.sample(99.0, rest, &mut out);
    assert_eq!(out.angles[0], 1.0);
    let bad = |keys| Sequence::new("bad", model, keys).unwrap_err().to_string();
    assert!(bad(vec![]).contains("no keyframes"));
    assert!(bad(vec![key(1.0, &a), key(0.5, &b)]).contains("goes backwards"));
    assert!(bad(vec![key(f32::NAN, &a)]).contains("not finite"));
    assert!(bad(vec![key(0.0, &Pose::rest(3))]).contains("3 angles"));
    let tour = Sequence::gestures(JointModel::Full);
    let open = gesture("open_palm").unwrap().pose(JointModel::Full);
    assert_eq!(tour.keys().first().unwrap().pose, open);
    assert_eq!(tour.keys().last().unwrap().pose, open);
}

#[test]
fn vertex_distortion_is_the_mean_change_of_the_edges_at_each_vertex() {
    // One triangle, edge 0–1 stretched to twice its length.
    let rest = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    let posed = [[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    let d = VertexDistortion::new(&rest, &[0, 1, 2]);
    let mut out = [0.0; 3];
    d.compute(&rest, &mut out);
    assert!(out.iter().all(|&v| v.abs() < 1e-6), "{out:?}");
    d.compute(&posed, &mut out);
    let e12 = ((5f32).sqrt() / 2f32.sqrt() - 1.0).abs();
    assert!((out[0] - 0.5).abs() < 1e-6, "{out:?}");
    assert!((out[1] - (1.0 + e12) / 2.0).abs() < 1e-6, "{out:?}");
    assert!((out[2] - e12 / 2.0).abs() < 1e-6, "{out:?}");
}

/// A viewer in the paper model follows a live input posed in the full model: the DOFs both
/// have take the input's angles, by name, and its wrist; the timeline stops.
#[test]
fn following_an_input_of_another_joint_model_takes_the_shared_angles() {
    let mut s = Session::new(HAND.clone(), None, JointModel::Full).unwrap();
    s.apply(&command(r#"{"type":"joint_model","name":"paper"}"#)).unwrap();
    let mut input = Pose::rest(JointModel::Full.dof_count());
    for (k, a) in input.angles.iter_mut().enumerate() {
        *a = 0.01 * (k + 1) as f32;
    }
    input.wrist = Some(DualQuat::from_rotation_translation(glam::Quat::from_rotation_y(0.3), glam::Vec3::new(0.1, 1.0, 0.0)));
    s.follow(&input, JointModel::Full);
    for (i, d) in JointModel::Paper.dofs().enumerate() {
        let k = JointModel::Full.dof_index(&d.name()).unwrap();
        assert_eq!(s.pose().angles[i], input.angles[k], "{}", d.name());
    }
    assert_eq!(s.pose().wrist, input.wrist);
    assert_eq!(frame(&mut s).header.state & STATE_PLAYING, 0);
}

/// Gesture commands change the view: the next method alone (cycling through all four), all
/// four side by side, the heat map.
#[test]
fn gesture_commands_change_the_view() {
    use dqhand_stream::Action;
    let mut s = paused();
    let shown = |s: &Session| s.methods().as_slice().to_vec();
    assert_eq!(shown(&s), [Method::Dqb]);
    for expected in [Method::Cor, Method::Lb, Method::Qb, Method::Dqb] {
        s.act(Action::NextMethod);
        assert_eq!(shown(&s), [expected]);
    }
    s.act(Action::SplitView);
    assert_eq!(shown(&s), Method::ALL);
    assert_eq!(frame(&mut s).meshes.len(), 4);
    s.act(Action::NextMethod);
    assert_eq!(shown(&s), [Method::Qb], "after the first of the split view");
    assert!(!s.heatmap());
    s.act(Action::ToggleHeatmap);
    assert!(s.heatmap() && frame(&mut s).header.distortion);
    s.act(Action::ToggleHeatmap);
    assert!(!s.heatmap());
}
