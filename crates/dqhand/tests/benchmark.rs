//! The gesture loop's measures (`dqhand::interaction::benchmark`): events scored against
//! labels by hand-made cases, distributions, angle errors, and retargeting scored on a
//! noise-free synthetic sequence of our own hand.

use std::sync::Arc;

use dqhand::gesture::EventKind::{End, Start};
use dqhand::gesture::{Event, EventKind};
use dqhand::hand::{build, HandParams};
use dqhand::input::MappingTable;
use dqhand::interaction::benchmark::{AngleError, Distribution, LoggedEvent, RecognitionScore, RetargetScore, CLOSED_GAPS_M};
use dqhand::interaction::synthetic::{generate, Label, SyntheticFormat, SyntheticParams};
use dqhand::kinematics::Pose;
use dqhand::Error;

fn label(gesture: &str, reached: f64, until: f64) -> Label {
    Label { gesture: gesture.into(), reached, until }
}

fn event(t: f64, event: EventKind, gesture: &str) -> LoggedEvent {
    LoggedEvent { t, event, gesture: gesture.into() }
}

#[test]
fn a_hold_is_in_time_when_its_gesture_starts_within_150_ms_of_the_pose() {
    // Holds at 60 Hz: fist, point, pinch, each 1 s after a 0.4 s move.
    let labels = [label("fist", 0.9, 1.9), label("point", 2.3, 3.3), label("pinch", 3.7, 4.7)];
    let events = [
        event(0.85, Start, "fist"),           // during the move: in time, negative latency
        event(2.0, End, "fist"),              // the move to point
        event(2.0, Start, "victory"),         // another gesture passed through: no credit
        event(2.45, End, "victory"),          //
        event(2.45, Start, "point"),          // exactly at the deadline: in time
        event(3.85 + 1e-3, End, "point"),     //
        event(3.85 + 1e-3, Start, "pinch"),   // a frame after the deadline: late
    ];
    let score = RecognitionScore::new(&labels, (5.1, 10.0), &events);
    let outcomes: Vec<_> = score.holds.iter().map(|h| (h.gesture.as_str(), h.in_time(), h.shown_at_deadline.as_deref())).collect();
    assert_eq!(outcomes, [("fist", true, Some("fist")), ("point", true, Some("point")), ("pinch", false, Some("point"))]);
    assert!((score.holds[0].latency_s.unwrap() + 0.05).abs() < 1e-9);
    assert!((score.holds[1].latency_s.unwrap() - 0.15).abs() < 1e-9);
    assert!((score.holds[2].latency_s.unwrap() - 0.151).abs() < 1e-9, "a late start still has its latency");
    assert_eq!(score.in_time(), 2);
}

#[test]
fn a_start_outside_the_hold_is_not_its_recognition() {
    let labels = [label("fist", 0.9, 1.9), label("point", 2.3, 3.3), label("fist", 3.7, 4.7)];
    // The first fist never ends, so the second fist has no start of its own; point starts
    // only after its hold ended.
    let events = [event(1.0, Start, "fist"), event(3.4, End, "fist"), event(3.4, Start, "point")];
    let score = RecognitionScore::new(&labels, (5.1, 10.0), &events);
    assert_eq!(score.holds.iter().map(|h| h.latency_s.is_some()).collect::<Vec<_>>(), [true, false, false]);
    assert_eq!(score.holds[1].shown_at_deadline.as_deref(), Some("fist"));
    assert_eq!(score.holds[2].shown_at_deadline.as_deref(), Some("point"));
}

#[test]
fn a_start_that_flickers_off_or_is_replaced_by_the_deadline_is_not_in_time() {
    let labels = [label("fist", 0.9, 1.9), label("point", 2.3, 3.3)];
    let events = [
        event(0.8, Start, "fist"),   // during the move …
        event(0.85, End, "fist"),    // … gone before the pose is reached
        event(1.3, Start, "fist"),   // back 400 ms late
        event(2.35, End, "fist"),    //
        event(2.35, Start, "point"), // in time …
        event(2.4, End, "point"),    // … replaced 100 ms after the pose
        event(2.4, Start, "three"),  //
    ];
    let score = RecognitionScore::new(&labels, (5.0, 10.0), &events);
    let outcomes: Vec<_> = score.holds.iter().map(|h| (h.in_time(), h.shown_at_deadline.as_deref())).collect();
    assert_eq!(outcomes, [(false, None), (false, Some("three"))]);
    assert!((score.holds[0].latency_s.unwrap() - 0.4).abs() < 1e-9, "the late start is the latency");
    assert_eq!(score.in_time(), 0);
}

#[test]
fn only_the_gesture_shown_when_idle_begins_may_end_unpunished() {
    let labels = [label("fist", 0.9, 1.9)];
    // The fist ended before idle began: its start in idle is spurious (ends are no commands).
    let events = [event(1.0, Start, "fist"), event(2.0, End, "fist"), event(3.0, Start, "fist"), event(4.0, End, "fist")];
    let score = RecognitionScore::new(&labels, (2.5, 10.0), &events);
    assert_eq!((score.spurious, score.starts.clone()), (1, vec![("fist".to_owned(), true), ("fist".to_owned(), false)]));
}

#[test]
fn idle_events_are_spurious_except_the_end_of_the_last_hold() {
    let labels = [label("fist", 0.9, 1.9)];
    let idle = (2.3, 62.3);
    let quiet = [event(1.0, Start, "fist"), event(2.4, End, "fist")];
    let score = RecognitionScore::new(&labels, idle, &quiet);
    assert_eq!((score.spurious, score.idle_s), (0, 60.0));
    // A gesture seen in idle motion is two events; a second end of the last gesture is not
    // excused.
    let noisy = [event(1.0, Start, "fist"), event(2.4, End, "fist"), event(10.0, Start, "fist"), event(11.0, End, "fist"), event(62.4, Start, "rock")];
    assert_eq!(RecognitionScore::new(&labels, idle, &noisy).spurious, 2);
}

#[test]
fn logged_events_read_the_json_events_are_written_as() {
    let json = serde_json::to_string(&Event { t: 1.25, event: EventKind::End, gesture: "fist", index: 0 }).unwrap();
    let logged: LoggedEvent = serde_json::from_str(&json).unwrap();
    assert_eq!(logged, LoggedEvent::from(Event { t: 1.25, event: EventKind::End, gesture: "fist", index: 0 }));
    assert_eq!(logged, event(1.25, End, "fist"));
}

#[test]
fn distributions_take_the_sample_at_the_rounded_rank() {
    let mut samples: Vec<f64> = (1..=20).rev().map(f64::from).collect();
    let d = Distribution::of(&mut samples).unwrap();
    assert_eq!((d.count, d.median, d.p95, d.max), (20, 11.0, 19.0, 20.0));
    let ms = Distribution::of(&mut [0.002]).unwrap().scaled(1e3);
    assert_eq!((ms.count, ms.median, ms.p95, ms.max), (1, 2.0, 2.0, 2.0));
    assert_eq!(Distribution::of(&mut []), None);
}

#[test]
fn angle_errors_are_mean_and_largest_over_dofs_and_poses() {
    let deg = |a: &[f32]| Pose { wrist: None, angles: a.iter().map(|d| d.to_radians()).collect() };
    let mut e = AngleError::between(&deg(&[10.0, 20.0]), &deg(&[11.0, 17.0]));
    assert!((e.mean_deg() - 2.0).abs() < 1e-4 && (e.max_deg() - 3.0).abs() < 1e-4, "{e:?}");
    e.merge(&AngleError::between(&deg(&[0.0, 0.0]), &deg(&[0.0, -6.0])));
    assert!((e.mean_deg() - 2.5).abs() < 1e-4 && (e.max_deg() - 6.0).abs() < 1e-4 && e.count() == 4, "{e:?}");
    assert_eq!(AngleError::default().mean_deg(), 0.0);
}

#[test]
fn noise_free_joints_of_our_hand_retarget_to_the_true_angles_and_keep_contacts() {
    let ours = HandParams { vertices: 1000, ..HandParams::default() };
    let model = Arc::new(build(&ours).unwrap());
    let clean = SyntheticParams { hand: Some(ours), idle_s: 1.0, noise_m: 0.0, tremor_deg: 0.0, drop_rate: 0.0, ..SyntheticParams::default() };
    let s = generate(&clean).unwrap();
    assert!(s.labels.iter().any(|l| l.gesture == "pinch"), "the 13 holds cycle through every gesture");
    let score = RetargetScore::measure(model.clone(), std::slice::from_ref(&s)).unwrap();
    assert_eq!((score.records, score.refused), (s.records.len(), 0));
    assert!(score.angles.mean_deg() <= 0.1 && score.angles.max_deg() <= 1.0, "{score:?}");
    // pinch and ok, closed to 1, 3 and 5 mm: the virtual tips follow within a fraction of a
    // millimetre.
    assert!(score.contacts >= 2 * 30 * CLOSED_GAPS_M.len(), "{score:?}");
    assert!(score.max_contact_excess_m < 0.0005 && score.max_contact_gap_m < CLOSED_GAPS_M[2] + 0.0005, "{score:?}");

    let glove = SyntheticParams { holds: 1, idle_s: 0.0, format: SyntheticFormat::Glove(MappingTable::builtin("5dt-14").unwrap()), ..clean };
    let e = RetargetScore::measure(model, &[generate(&glove).unwrap()]).unwrap_err();
    assert!(matches!(e, Error::Sequence(_)) && e.to_string().starts_with("record at t = 0 s: no joints or landmarks"), "{e}");
}
