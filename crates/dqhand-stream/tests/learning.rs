//! Learning a gesture while the live input runs: the `learn` command's checks, the hand's
//! features recorded over a stretch of live records, and a new gesture set taken in the middle
//! of the input (viewers told by a new hello; gestures named right afterwards, as a fresh
//! loop with the same set names them).

use std::sync::Arc;
use std::time::Duration;

use dqhand::gesture::{train, Example, GestureSet, TrainingParams};
use dqhand::interaction::gesture_examples::shape_features;
use dqhand::hand::{build, HandParams};
use dqhand::input::InputConfig;
use dqhand::interaction::synthetic::{generate, SyntheticParams};
use dqhand::interaction::GestureLoop;
use dqhand::kinematics::JointModel;
use dqhand_stream::{Applied, Command, LearnRequest, LiveInput, Session};

#[test]
fn learn_commands_are_checked() {
    let mut s = Session::new(Arc::new(build(&HandParams { vertices: 1000, ..HandParams::default() }).unwrap()), None, JointModel::Full).unwrap();
    let mut applied = |json: &str| Command::parse(json).and_then(|c| s.apply(&c).map_err(|e| e.to_string()));
    assert_eq!(applied(r#"{"type":"learn","name":"finger-gun_2"}"#).unwrap(), Applied::Learn(LearnRequest { name: "finger-gun_2".into(), seconds: 4.0, not: false }));
    assert_eq!(applied(r#"{"type":"learn","name":"gun","seconds":2.5,"not":true}"#).unwrap(), Applied::Learn(LearnRequest { name: "gun".into(), seconds: 2.5, not: true }));
    for (json, expect) in [
        (r#"{"type":"learn","name":""}"#, "\"\" is not a gesture name"),
        (r#"{"type":"learn","name":"two words"}"#, "\"two words\" is not a gesture name"),
        (r#"{"type":"learn","name":"../x"}"#, "is not a gesture name"),
        (&format!(r#"{{"type":"learn","name":"{}"}}"#, "a".repeat(33)), "is not a gesture name"),
        (r#"{"type":"learn","name":"gun","seconds":1}"#, "learn: 1 seconds (2 to 10)"),
        (r#"{"type":"learn","name":"gun","seconds":11}"#, "(2 to 10)"),
        (r#"{"type":"learn","name":"gun","why":1}"#, "not a valid command"),
    ] {
        let e = applied(json).unwrap_err();
        assert!(e.contains(expect), "{json}: {e:?} should contain {expect:?}");
    }
}

#[test]
fn a_capture_records_the_hand_features_and_a_new_set_is_taken_mid_input() {
    let model = Arc::new(build(&HandParams { vertices: 1000, ..HandParams::default() }).unwrap());
    // Records pushed as fast as the test runs: none is late, none is lost.
    let config = InputConfig { grace_s: 1e6, max_latency_s: 1e6, ..InputConfig::default() };
    let hands = |set| GestureLoop::new(model.clone(), JointModel::Full, None, config.clone(), Some(set)).unwrap();
    let input = LiveInput::new(hands(GestureSet::builtin()), "test", true).unwrap();
    let sequence = generate(&SyntheticParams { seed: 5, holds: 6, idle_s: 1.0, ..SyntheticParams::default() }).unwrap();
    let (first, second) = sequence.records.split_at(sequence.records.len() / 2);

    // A time that is not one is refused (NaN would never end).
    for bad in [f64::NAN, 0.0, -1.0, 61.0, f64::INFINITY] {
        assert!(input.capture(bad).unwrap_err().to_string().contains("seconds to record"), "{bad}");
    }
    // Ten records recorded; nothing handed over before the time is up, once after it.
    input.capture(0.3).unwrap();
    assert!(input.capture(1.0).unwrap_err().to_string().contains("already being recorded"));
    let mut recorded = hands(GestureSet::builtin());
    let mut expected = Vec::new();
    for r in &first[..10] {
        input.push(r, |_| {}).unwrap();
        recorded.push(r).unwrap();
        expected.push((r.time, recorded.features()));
    }
    assert!(input.captured().is_none(), "handed over before the time is up");
    std::thread::sleep(Duration::from_millis(350));
    let mut others = Vec::new();
    for r in &first[10..] {
        input.push(r, |_| {}).unwrap();
        recorded.push(r).unwrap();
        others.push(Example { features: recorded.features(), class: 0 });
    }
    let frames = input.captured().expect("the capture is over");
    assert_eq!(frames.len(), 10);
    for ((t, f), (te, fe)) in frames.iter().zip(&expected) {
        assert_eq!(t, te);
        assert_eq!(f, fe);
    }
    assert!(input.captured().is_none(), "handed over once");

    // A learned gesture first in the set: the viewers are told, and what follows is named
    // as a fresh loop with the new set names it.
    let mut set = GestureSet::builtin();
    let examples: Vec<Example> = frames.iter().map(|(_, f)| Example { features: *f, class: 1 }).chain(others).collect();
    let classifier = train(vec!["other".into(), "mine".into()], shape_features(), &examples, &TrainingParams { epochs: 1, hidden: 4, ..TrainingParams::default() }).unwrap();
    set.insert_learned("mine", classifier).unwrap();
    let mut session = Session::new(model.clone(), None, JointModel::Full).unwrap();
    let mut view = input.view();
    assert!(!input.update(&mut session, &mut view).hello);
    input.set_gestures(set.clone()).unwrap();
    assert!(input.update(&mut session, &mut view).hello, "a new hello lists the gestures");
    assert_eq!(input.describe().unwrap()["gestures"][0], "mine");
    assert_eq!(input.gesture_set().unwrap().gestures().len(), 13);

    let mut fresh = hands(set);
    let mut want = Vec::new();
    for r in second {
        want.extend(fresh.push(r).unwrap().map(|e| format!("{:?} {}", e.event, e.gesture)));
        input.push(r, |_| {}).unwrap();
    }
    let message: serde_json::Value = serde_json::from_str(&input.update(&mut session, &mut view).message.unwrap()).unwrap();
    let got: Vec<String> = message["events"].as_array().unwrap().iter().map(|e| format!("{} {}", if e["event"] == "start" { "Start" } else { "End" }, e["gesture"].as_str().unwrap())).collect();
    assert!(want.len() >= 4, "{want:?}");
    assert_eq!(got, want);
}
