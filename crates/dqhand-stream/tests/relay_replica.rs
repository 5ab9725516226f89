//! A page's engine following `dqhand demo`'s relay is a replica of the demo's live input: given
//! the arrival times the demo stamped on its records, it names the gesture events the demo's
//! input named (as `dqhand replay` of the demo's recording does), although a busy page took
//! some of them late and in a burst; an input judging them on its own clock does not. (Real
//! time: the records are delivered at their times, about as long as the recording lasts.)

use std::sync::Arc;
use std::time::{Duration, Instant};

use dqhand::gesture::GestureSet;
use dqhand::hand::{build, HandParams};
use dqhand::input::{InputConfig, Record};
use dqhand::interaction::synthetic::{generate, SyntheticParams};
use dqhand::interaction::GestureLoop;
use dqhand::kinematics::JointModel;
use dqhand_stream::{LiveInput, Session};
use serde_json::Value;

/// The gesture events an input names for `records`, each delivered at its `deliver` time
/// (s from the start, on the test's clock), read from its `input` messages: `(t, event, gesture)`.
fn events_of(input: &LiveInput, session: &mut Session, records: &[Record], deliver: &[f64]) -> Vec<(String, String, String)> {
    let mut view = input.view();
    let mut events = Vec::new();
    let start = Instant::now();
    for (r, &at) in records.iter().zip(deliver) {
        std::thread::sleep(Duration::from_secs_f64(at).saturating_sub(start.elapsed()));
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
    let config = InputConfig { grace_s: 0.3, max_latency_s: 0.1, ..InputConfig::default() };
    let hands = || GestureLoop::new(model.clone(), JointModel::Full, None, config.clone(), Some(GestureSet::builtin())).unwrap();
    let sequence = generate(&SyntheticParams { seed: 7, holds: 3, idle_s: 0.5, ..SyntheticParams::default() }).unwrap();
    let records = &sequence.records;
    let (first, span) = (records[0].time, records.last().unwrap().time - records[0].time);
    // As the demo stamped them on its clock: on time, but for a sender stalled 0.8 s a third of
    // the way in, whose records then came in a burst.
    let stall = (first + span / 3.0, first + span / 3.0 + 0.8);
    let stamped: Vec<Record> = records.iter().map(|r| Record { arrival: Some(1000.0 + if (stall.0..stall.1).contains(&r.time) { stall.1 } else { r.time }), ..*r }).collect();
    // As the relay delivered them to the page: as stamped, but for the page busy 0.25 s two
    // thirds of the way in (a camera frame), whose records it then took in a burst. (A page
    // busy for longer than the grace time judges the hand lost between records, as the demo
    // would have had its records stopped that long.)
    let busy = (first + 2.0 * span / 3.0, first + 2.0 * span / 3.0 + 0.25);
    let deliver: Vec<f64> = stamped.iter().map(|r| r.arrival.unwrap() - 1000.0 - first).map(|t| if (busy.0 - first..busy.1 - first).contains(&t) { busy.1 - first } else { t }).collect();

    // The replay of the demo's recording: each record taken at its stamp.
    let mut replay = hands();
    let mut expected = Vec::new();
    for r in &stamped {
        if let Ok(events) = replay.push(r) {
            expected.extend(events.map(|e| (format!("{:.6}", e.t), serde_json::to_string(&e.event).unwrap(), serde_json::to_string(e.gesture).unwrap())));
        }
    }
    assert!(expected.len() >= 5, "the sequence names gestures: {expected:?}");

    let mut session = Session::new(Arc::clone(&model), None, JointModel::Full).unwrap();
    let replica = LiveInput::new(hands(), "relay", true).unwrap().following_arrivals();
    assert_eq!(events_of(&replica, &mut session, &stamped, &deliver), expected, "the replica names what the original named");
    let own_clock = LiveInput::new(hands(), "relay", true).unwrap();
    assert_ne!(events_of(&own_clock, &mut session, &stamped, &deliver), expected, "an input on its own clock takes the page's burst as it came");
}
