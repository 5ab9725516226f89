//! Gesture recognition on the real engine and built-in hands: every library gesture is
//! recognised as itself and nothing else, on both sides, at other sizes, under wrist
//! rotations and joint noise; hysteresis, minimum hold, pinch distances, the events' JSON
//! and the definition file's errors.

use std::sync::{Arc, OnceLock};

use dqhand::gesture::{Event, EventKind, Feature, Finger, GestureSet, HandFeatures, Recognizer, GESTURES};
use dqhand::hand::{build, HandParams, Side};
use dqhand::kinematics::{HandKinematics, JointModel, JointPositions, Pose};
use dqhand::math::DualQuat;
use dqhand::{Error, GestureProblem};
use glam::{Quat, Vec3};

/// A built hand, posed through its kinematics layer.
struct Hand {
    kinematics: HandKinematics,
    joints: JointPositions,
    side: Side,
}

impl Hand {
    fn new(length: f32, breadth: f32, side: Side) -> Self {
        let model = Arc::new(build(&HandParams { length, breadth, side, vertices: 2000 }).unwrap());
        let kinematics = model.hand_kinematics(JointModel::Full).unwrap();
        let joints = JointPositions::new(kinematics.skeleton()).unwrap();
        Self { kinematics, joints, side }
    }

    fn positions(&self, pose: &Pose) -> [Vec3; 25] {
        let mut kinematics = self.kinematics.clone();
        kinematics.pose(pose);
        self.joints.read(kinematics.world())
    }

    fn features(&self, pose: &Pose) -> HandFeatures {
        HandFeatures::from_positions(&self.positions(pose), self.side)
    }

    /// `pose` with the wrist turned by `turn` about the wrist joint.
    fn turned(&self, pose: &Pose, turn: Quat) -> Pose {
        let rest = self.kinematics.rig().rest_wrist();
        let (rotation, translation) = pose.wrist.unwrap_or(rest).to_rotation_translation();
        Pose { wrist: Some(DualQuat::from_rotation_translation(turn * rotation, translation)), angles: pose.angles.clone() }
    }

    /// Every gesture of the built-in set with a pose showing it: the library's, thumbs up
    /// turned so the thumb points up, and the same shape turned so it points down.
    fn cases(&self) -> Vec<(&'static str, Pose)> {
        let mut cases = Vec::new();
        for g in &GESTURES {
            let pose = g.pose(JointModel::Full);
            if g.name == "thumbs_up" {
                let thumb = self.features(&pose).thumb_direction;
                cases.push(("thumbs_up", self.turned(&pose, Quat::from_rotation_arc(thumb, Vec3::Y))));
                cases.push(("thumbs_down", self.turned(&pose, Quat::from_rotation_arc(thumb, -Vec3::Y))));
            } else {
                cases.push((g.name, pose));
            }
        }
        cases
    }
}

fn right() -> &'static Hand {
    static HAND: OnceLock<Hand> = OnceLock::new();
    HAND.get_or_init(|| Hand::new(0.19, 0.085, Side::Right))
}

fn set() -> &'static GestureSet {
    static SET: OnceLock<GestureSet> = OnceLock::new();
    SET.get_or_init(GestureSet::builtin)
}

/// Gestures written as conditions by hand (what a user's file may hold): the fist and pinch
/// the built-in set defined so before it was learned.
const CONDITIONS: &str = r#"{ "min_hold_s": 0.1,
  "hysteresis": { "curl": 0.1, "flexion": 10, "abduction": 5, "opposition": 0.02, "direction": 10 },
  "gestures": [
    { "name": "fist", "when": ["thumb.curl > 0.5", "index.curl > 0.6", "middle.curl > 0.6", "ring.curl > 0.6", "pinky.curl > 0.6"] },
    { "name": "pinch", "when": ["index.opposition < 0.12 release 0.16", "middle.curl > 0.35", "ring.curl > 0.35", "pinky.curl > 0.35"] } ] }"#;

fn conditions() -> GestureSet {
    GestureSet::from_json(CONDITIONS, "conditions").unwrap()
}

/// The gestures whose strict thresholds all pass.
fn strict_matches(f: &HandFeatures) -> Vec<&'static str> {
    let classifier = set().classifier().expect("the built-in set has a classifier");
    let mut scratch = classifier.scratch();
    let shared = classifier.classify(f, &mut scratch).to_vec();
    set().gestures().iter().filter(|g| g.matches(f, (&shared, classifier.thresholds()), &mut Default::default(), false)).map(|g| g.name()).collect()
}

/// Events as owned `(time, kind, gesture)`.
fn run(recognizer: &mut Recognizer, frames: impl IntoIterator<Item = (f64, HandFeatures)>) -> Vec<(f64, EventKind, String)> {
    let mut out = Vec::new();
    for (t, f) in frames {
        out.extend(recognizer.update(t, &f).map(|e| (e.t, e.event, e.gesture.to_owned())));
    }
    out
}

const FRAME_S: f64 = 1.0 / 90.0;

/// `seconds` of frames at 90 Hz from `start`, each from `features(frame index)`.
fn frames(start: f64, seconds: f64, mut features: impl FnMut(usize) -> HandFeatures) -> Vec<(f64, HandFeatures)> {
    (0..(seconds / FRAME_S).round() as usize).map(|i| (start + i as f64 * FRAME_S, features(i))).collect()
}

/// Asserts every case is recognised strictly as itself and nothing else.
fn assert_each_recognised_alone(hand: &Hand, what: &str) {
    let cases = hand.cases();
    assert_eq!(cases.len(), set().gestures().len(), "a pose per defined gesture");
    for (name, pose) in &cases {
        let f = hand.features(pose);
        assert_eq!(strict_matches(&f), [*name], "{what}: {name} matches; features {f:?}");
        let mut r = Recognizer::new(set().clone());
        let events = run(&mut r, frames(0.0, 0.5, |_| f));
        assert_eq!(events.len(), 1, "{what}: {name}: {events:?}");
        assert_eq!((events[0].1, events[0].2.as_str()), (EventKind::Start, *name), "{what}");
    }
}

#[test]
fn every_gesture_on_the_right_hand_is_recognised_as_itself_only() {
    assert_each_recognised_alone(right(), "right hand");
}

#[test]
fn every_gesture_on_a_left_hand_is_recognised_as_itself_only() {
    assert_each_recognised_alone(&Hand::new(0.19, 0.085, Side::Left), "left hand");
}

#[test]
fn every_gesture_on_small_and_large_hands_is_recognised_as_itself_only() {
    assert_each_recognised_alone(&Hand::new(0.16, 0.07, Side::Right), "hand 0.16 x 0.07");
    assert_each_recognised_alone(&Hand::new(0.21, 0.10, Side::Left), "left hand 0.21 x 0.10");
}

#[test]
fn gestures_survive_wrist_rotations_of_25_degrees() {
    let hand = right();
    let a = 25f32.to_radians();
    let mut turns = vec![];
    for axis in [Vec3::X, Vec3::Y, Vec3::Z, Vec3::new(1.0, 1.0, 0.0), Vec3::new(1.0, 0.0, 1.0), Vec3::new(0.0, 1.0, 1.0), Vec3::ONE] {
        turns.push(Quat::from_axis_angle(axis.normalize(), a));
        turns.push(Quat::from_axis_angle(axis.normalize(), -a));
    }
    for (name, pose) in hand.cases().iter().filter(|(n, _)| !n.starts_with("thumbs")) {
        for turn in &turns {
            let f = hand.features(&hand.turned(pose, *turn));
            assert_eq!(strict_matches(&f), [*name], "{name} turned by {turn:?}: {f:?}");
        }
    }
}

#[test]
fn thumbs_up_and_down_are_decided_by_the_wrist() {
    let hand = right();
    let shape = GESTURES.iter().find(|g| g.name == "thumbs_up").unwrap().pose(JointModel::Full);
    assert!(strict_matches(&hand.features(&shape)).is_empty(), "thumb sideways: neither up nor down");
    let cases = hand.cases();
    for name in ["thumbs_up", "thumbs_down"] {
        let pose = &cases.iter().find(|(n, _)| *n == name).unwrap().1;
        // Tilted 30° away from the vertical, still up or down.
        let tilted = hand.turned(pose, Quat::from_rotation_z(30f32.to_radians()));
        assert_eq!(strict_matches(&hand.features(&tilted)), [name]);
    }
}

/// splitmix64, and normal deviates by Box–Muller.
struct Rng(u64);

impl Rng {
    fn next_f64(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }

    fn normal(&mut self) -> f32 {
        let (u, v) = (1.0 - self.next_f64(), self.next_f64());
        ((-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()) as f32
    }

    fn vec3(&mut self, sigma: f32) -> Vec3 {
        Vec3::new(self.normal(), self.normal(), self.normal()) * sigma
    }
}

#[test]
fn gestures_held_under_joint_noise_start_once_and_never_flicker() {
    const SIGMA_M: f32 = 0.0015;
    let hand = right();
    let mut rng = Rng(7);
    let mut failed = vec![];
    let cases = hand.cases();
    for (name, pose) in &cases {
        let clean = hand.positions(pose);
        let mut r = Recognizer::new(set().clone());
        let events = run(&mut r, frames(0.0, 3.0, |_| HandFeatures::from_positions(&clean.map(|p| p + rng.vec3(SIGMA_M)), hand.side)));
        let start_only = events.len() == 1 && events[0].1 == EventKind::Start && events[0].2 == *name;
        if !start_only {
            failed.push(format!("{name}: {events:?}"));
        }
    }
    println!("{} of {} gestures held 3 s under 1.5 mm noise gave exactly one start", cases.len() - failed.len(), cases.len());
    assert!(failed.is_empty(), "{failed:#?}");
}

/// The fist's features with the index curl replaced.
fn fist_with_index_curl(curl: f32) -> HandFeatures {
    let fist = &right().cases()[1];
    assert_eq!(fist.0, "fist");
    let mut f = right().features(&fist.1);
    f.curl[Finger::Index as usize] = curl;
    f
}

#[test]
fn a_feature_trembling_around_a_threshold_causes_no_event_storm() {
    let trembling = frames(0.0, 2.0, |i| fist_with_index_curl(if i % 2 == 0 { 0.57 } else { 0.63 }));
    let mut r = Recognizer::new(conditions());
    let events = run(&mut r, frames(0.0, 0.3, |_| fist_with_index_curl(0.9)).into_iter().chain(trembling.iter().map(|&(t, f)| (t + 0.3, f))));
    assert_eq!(events, [(events[0].0, EventKind::Start, "fist".to_owned())]);
    // Without hysteresis and minimum hold the same input toggles every frame: the test can fail.
    let json = CONDITIONS
        .replace(r#""min_hold_s": 0.1"#, r#""min_hold_s": 0"#)
        .replace(r#""curl": 0.1"#, r#""curl": 0"#);
    let mut bare = Recognizer::new(GestureSet::from_json(&json, "bare").unwrap());
    assert!(run(&mut bare, trembling).len() > 100);
}

#[test]
fn a_pose_shorter_than_the_minimum_hold_causes_no_event() {
    let hand = right();
    let cases = hand.cases();
    let open = hand.features(&cases[0].1);
    let fist = hand.features(&cases[1].1);
    let min_hold = set().min_hold_s();
    assert_eq!(min_hold, 0.1);
    let mut r = Recognizer::new(set().clone());
    let mut segment = |f: HandFeatures, start: f64, seconds: f64| run(&mut r, frames(start, seconds, |_| f));
    assert_eq!(segment(open, 0.0, 0.5).len(), 1);
    assert_eq!(segment(fist, 0.5, 0.08), [], "a fist held 0.08 s");
    assert_eq!(segment(open, 0.58, 0.5), []);
    let fist_at = 1.08;
    let events = segment(fist, fist_at, 0.5);
    let kinds: Vec<_> = events.iter().map(|e| (e.1, e.2.as_str())).collect();
    assert_eq!(kinds, [(EventKind::End, "open_palm"), (EventKind::Start, "fist")]);
    let latency = events[0].0 - fist_at;
    assert!(latency >= min_hold && latency < min_hold + FRAME_S + 1e-9, "latency {latency} s");
}

#[test]
fn pinch_starts_and_ends_at_distinct_distances() {
    let hand = right();
    let pinch = hand.features(&hand.cases().iter().find(|(n, _)| *n == "pinch").unwrap().1);
    let condition = conditions().gestures().iter().find(|g| g.name() == "pinch").unwrap().conditions()[0];
    assert_eq!((condition.feature, condition.start, condition.hold), (Feature::Opposition(Finger::Index), 0.12, 0.16));
    let cm = |v: f32| v * pinch.hand_size * 100.0;
    assert!((1.8..2.4).contains(&cm(0.12)) && (2.5..3.1).contains(&cm(0.16)), "start {} cm, end {} cm", cm(0.12), cm(0.16));
    let at = |d: f32| {
        let mut f = pinch;
        f.opposition[0] = d;
        f.curl[2..].fill(0.5);
        f
    };
    let mut r = Recognizer::new(conditions());
    let mut t = 0.0;
    let mut phase = |d: f32| {
        let events = run(&mut r, frames(t, 0.5, |_| at(d)));
        t += 0.5;
        events.into_iter().map(|e| (e.1, e.2)).collect::<Vec<_>>()
    };
    assert_eq!(phase(0.13), [], "0.13 is not close enough to start");
    assert_eq!(phase(0.10), [(EventKind::Start, "pinch".to_owned())]);
    assert_eq!(phase(0.15), [], "0.15 is close enough to hold");
    assert_eq!(phase(0.17), [(EventKind::End, "pinch".to_owned())]);
}

#[test]
fn events_serialise_as_time_event_and_gesture() {
    let start = Event { t: 1.25, event: EventKind::Start, gesture: "fist", index: 0 };
    assert_eq!(serde_json::to_string(&start).unwrap(), r#"{"t":1.25,"event":"start","gesture":"fist"}"#);
    let mut r = Recognizer::new(set().clone());
    let fist = fist_with_index_curl(0.9);
    r.update(0.0, &fist).for_each(drop);
    let events: Vec<(String, usize)> = r.update(0.2, &fist).map(|e| (serde_json::to_string(&e).unwrap(), e.index)).collect();
    // The index is the gesture's identity in the set (not written: the name is for people).
    let index = set().gestures().iter().position(|g| g.name() == "fist").unwrap();
    assert_eq!(events, [(r#"{"t":0.2,"event":"start","gesture":"fist"}"#.to_owned(), index)]);
    assert_eq!(r.current_index(), Some(index));
}

fn definition_error(json: &str) -> (String, GestureProblem) {
    match GestureSet::from_json(json, "mine.json").unwrap_err() {
        e @ Error::GestureDefinition { .. } => {
            let message = e.to_string();
            let Error::GestureDefinition { problem, .. } = e else { unreachable!() };
            (message, problem)
        }
        other => panic!("{other}"),
    }
}

fn with_gestures(gestures: &str) -> String {
    format!(r#"{{"min_hold_s": 0.1, "hysteresis": {{"curl": 0.1, "flexion": 10, "abduction": 5, "opposition": 0.02, "direction": 10}}, "gestures": [{gestures}]}}"#)
}

#[test]
fn definition_file_errors_name_the_file_gesture_and_condition() {
    let cases: [(&str, &str); 6] = [
        (r#"{"name": "claw", "when": ["index.curly > 0.5"]}"#, r#"mine.json: gesture "claw", condition "index.curly > 0.5": unknown feature "index.curly"; valid: thumb.curl, "#),
        (r#"{"name": "claw", "when": ["index.curl >= 0.5"]}"#, r#"mine.json: gesture "claw", condition "index.curl >= 0.5": unknown operator ">=""#),
        (r#"{"name": "claw", "when": ["index.curl > half"]}"#, r#"mine.json: gesture "claw", condition "index.curl > half": threshold "half" is not a finite number"#),
        (r#"{"name": "claw", "when": ["index.curl>0.5"]}"#, r#"mine.json: gesture "claw", condition "index.curl>0.5": expected"#),
        (r#"{"name": "claw", "when": ["index.opposition < 0.1 release 0.05"]}"#, r#"mine.json: gesture "claw", condition "index.opposition < 0.1 release 0.05": release 0.05 must be above"#),
        (r#"{"name": "claw", "when": ["index.curl > 0.5"]}, {"name": "claw", "when": ["index.curl > 0.6"]}"#, r#"mine.json: gesture "claw" is defined twice"#),
    ];
    for (gestures, expected) in cases {
        let (message, _) = definition_error(&with_gestures(gestures));
        assert!(message.starts_with(expected), "{message}\nexpected to start with\n{expected}");
        assert!(!message.contains('\n'), "one line: {message}");
    }
    assert!(matches!(definition_error(&with_gestures(r#"{"name": "claw", "when": ["pinky.abduction > 5"]}"#)).1, GestureProblem::UnknownFeature { .. }));
    assert!(matches!(definition_error(&with_gestures(r#"{"name": "claw", "when": []}"#)).1, GestureProblem::NoCondition(_)));
    let (message, problem) = definition_error(&with_gestures(r#"{"name": "claw", "when": ["index.curl > 0.5"]},"#));
    assert!(matches!(problem, GestureProblem::Json(_)) && message.starts_with("mine.json: not valid gesture definitions: ") && message.contains("line 1"), "{message}");
    let (message, _) = definition_error(&with_gestures("").replacen("0.1,", "-0.1,", 1));
    assert_eq!(message, "mine.json: min_hold_s -0.1 is not a finite number ≥ 0");
    let (message, _) = definition_error(&with_gestures("").replace(r#""curl": 0.1"#, r#""curl": -0.1"#));
    assert_eq!(message, "mine.json: hysteresis.curl -0.1 is not a finite number ≥ 0");
    let (message, problem) = definition_error(&with_gestures("").replace(r#""direction": 10"#, r#""up": 10"#));
    assert!(matches!(problem, GestureProblem::Json(_)) && message.contains("unknown field `up`"), "{message}");
}

#[test]
fn a_gesture_added_to_a_file_is_recognised_without_code() {
    let dir = std::env::temp_dir().join(format!("dqhand-recognition-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("claw.json");
    // A fist with the index curled only halfway.
    std::fs::write(&path, with_gestures(r#"{"name": "claw", "when": ["index.curl > 0.35", "index.curl < 0.6", "middle.curl > 0.6"]}"#)).unwrap();
    let mut r = Recognizer::new(GestureSet::load(&path).unwrap());
    let events = run(&mut r, frames(0.0, 0.3, |_| fist_with_index_curl(0.45)));
    assert_eq!(events.iter().map(|e| e.2.as_str()).collect::<Vec<_>>(), ["claw"]);
    std::fs::write(&path, "{").unwrap();
    let e = GestureSet::load(&path).unwrap_err().to_string();
    assert!(e.starts_with(&format!("{}: not valid gesture definitions", path.display())), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
    let missing = GestureSet::load(&path).unwrap_err();
    assert!(matches!(missing, Error::Io { .. }), "{missing}");
}

#[test]
fn the_builtin_set_defines_every_library_gesture_and_thumbs_down() {
    let names: Vec<&str> = set().gestures().iter().map(|g| g.name()).collect();
    let mut expected: Vec<&str> = GESTURES.iter().map(|g| g.name).collect();
    expected.insert(expected.iter().position(|&n| n == "thumbs_up").unwrap() + 1, "thumbs_down");
    assert_eq!(names, expected);
}

/// Learned definitions: the built-in set written back reads back equal; a file with a
/// classifier and a gesture's own model (the settings fuzz target's seed) loads; a class the
/// classifier lacks is named.
#[test]
fn learned_definitions_write_back_equal_and_a_missing_class_is_named() {
    let set = GestureSet::builtin();
    assert_eq!(GestureSet::from_json(&set.to_json(), "written").unwrap(), set);
    let json = include_str!("../../../fuzz/seeds/settings/gestures-learned.json");
    let learned = GestureSet::from_json(json, "learned.json").unwrap();
    assert_eq!(learned.gestures()[0].model().unwrap().classes(), ["other", "gun"]);
    assert_eq!(learned.gestures()[1].class(), Some(1));
    let (message, problem) = definition_error(&json.replace(r#""class": "fist""#, r#""class": "fists""#));
    assert!(matches!(problem, GestureProblem::UnknownClass { .. }), "{message}");
    assert_eq!(message, "mine.json: gesture \"fist\": class \"fists\" is not one of the classifier's (none, fist, thumbs)");
    let (message, _) = definition_error(&json.replace(r#""start": 0.6, "hold": 0.35 } },"#, r#""start": 0.6, "hold": 0.7 } },"#));
    assert!(message.starts_with("mine.json: gesture \"gun\" model: start 0.6 and hold 0.7"), "{message}");
}
