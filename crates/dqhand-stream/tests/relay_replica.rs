//! A page's engine following `dqhand demo`'s relay is a replica of the demo's live input: given
//! the arrival times the demo stamped on its records, it names the gesture events the demo's
//! input named (as `dqhand replay` of the demo's recording does), however the relay bunched
//! the records on their way; an input judging them on its own clock does not.

use std::sync::Arc;

use dqhand::gesture::GestureSet;
use dqhand::hand::{build, HandParams};
use dqhand::input::{InputConfig, Record};
use dqhand::interaction::synthetic::{generate, SyntheticParams};
use dqhand::interaction::GestureLoop;
use dqhand::kinematics::JointModel;
use dqhand_stream::{LiveInput, Session};
use serde_json::Value;

/// The gesture events an input names for `records`, pushed all at once (as a burst from the
/// relay), read from its `input` messages: `(t, event, gesture)`.
fn events_of(input: &LiveInput, session: &mut Session, records: &[Record]) -> Vec<(String, String, String)> {
    let mut view = input.view();
    let mut events = Vec::new();
    for r in records {
        let _ = input.push(r, |_| {}); // refusals are counted
        if let Some(message) = input.update(session, &mut view).message {
            let m: Value = serde_json::from_str(&message).unwrap();
            events.extend(m["events"].as_array().unwrap().iter().map(|e| (format!("{:.6}", e["t"].as_f64().unwrap()), e["event"].to_string(), e["gesture"].to_string())));
        }
    }
    events
}

#[test]
fn a_replica_following_the_arrivals_names_the_events_the_original_named() {
    let model = Arc::new(build(&HandParams { vertices: 1000, ..HandParams::default() }).unwrap());
    let config = InputConfig { grace_s: 0.3, max_latency_s: 0.2, ..InputConfig::default() };
    let hands = || GestureLoop::new(model.clone(), JointModel::Full, None, config.clone(), Some(GestureSet::builtin())).unwrap();
    let sequence = generate(&SyntheticParams { seed: 7, holds: 6, idle_s: 1.0, ..SyntheticParams::default() }).unwrap();
    // As the demo stamped them on its clock: on time, but for a sender stalled 1.5 s a third of
    // the way in, whose records then came in a burst.
    let (stall_from, stall_to) = (sequence.records[sequence.records.len() / 3].time, sequence.records[sequence.records.len() / 3].time + 1.5);
    let records: Vec<Record> = sequence.records.iter().map(|r| Record { arrival: Some(1000.0 + if (stall_from..stall_to).contains(&r.time) { stall_to } else { r.time }), ..*r }).collect();

    // The replay of the demo's recording: each record taken at its stamp.
    let mut replay = hands();
    let mut expected = Vec::new();
    for r in &records {
        if let Ok(events) = replay.push(r) {
            expected.extend(events.map(|e| (format!("{:.6}", e.t), serde_json::to_string(&e.event).unwrap(), serde_json::to_string(e.gesture).unwrap())));
        }
    }
    assert!(expected.len() >= 8, "the sequence names gestures: {expected:?}");
    assert!(expected.iter().any(|(_, kind, _)| kind == "\"end\""), "{expected:?}");

    let mut session = Session::new(Arc::clone(&model), None, JointModel::Full).unwrap();
    let replica = LiveInput::new(hands(), "relay", true).unwrap().following_arrivals();
    assert_eq!(events_of(&replica, &mut session, &records), expected, "the replica names what the original named");
    let own_clock = LiveInput::new(hands(), "relay", true).unwrap();
    assert_ne!(events_of(&own_clock, &mut session, &records), expected, "an input on its own clock takes the burst as it came");
}
