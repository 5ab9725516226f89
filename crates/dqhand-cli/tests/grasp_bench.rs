//! `dqhand grasp-bench` through the real command: a small run reports every measure, and the
//! scripted grasp of the ball meets the targets for success, penetration, slip,
//! tunnelling, the drop's drift and the free hand's lag and jitter (correctness, not timing:
//! the timings are only checked to be there).

use std::process::Command;

use serde_json::Value;

fn bench(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_dqhand")).arg("grasp-bench").args(args).output().unwrap()
}

#[test]
fn a_small_run_reports_every_measure_and_meets_the_targets() {
    let out = bench(&["--json", "--objects", "ball,plate", "--speeds", "10", "--approaches", "above"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let r: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!(r["synthetic"].as_str().unwrap().contains("not captured from a person"));
    let runs = r["runs"].as_array().unwrap();
    let what: Vec<(&str, &str, bool)> = runs.iter().map(|x| (x["object"].as_str().unwrap(), x["kind"].as_str().unwrap(), x["headset"].as_bool().unwrap())).collect();
    assert_eq!(what, [("ball", "grasp", false), ("ball", "grasp", true), ("ball", "drop", false), ("ball", "drop", true), ("plate", "strike", false)]);
    let ball = &runs[0];
    assert_eq!(ball["success"], true, "the ball is grasped at 10 m/s, carried and set down: {ball}");
    assert!(ball["release_frames"].as_u64().is_some(), "released: {ball}");
    assert!(ball["step_us"]["median"].as_f64().unwrap() > 0.0);
    assert_eq!(r["headset_grasps"], 2, "the grasp and the drop as a headset tracks: {r}");
    assert!(r["max_penetration_mm"].as_f64().unwrap() <= 1.0, "penetration {}", r["max_penetration_mm"]);
    assert!(r["max_slip_mm"].as_f64().unwrap() <= 3.0, "slip {}", r["max_slip_mm"]);
    assert_eq!(r["tunnelled"], 0, "a 10 m/s strike on the 8 mm plate does not pass into it");
    // Dropped by a still hand, exact and tracked like a headset: straight down.
    assert!(r["max_drop_drift_mm"].as_f64().unwrap() <= 10.0 && r["drift_pass"] == true, "{r}");
    // The free hand's lag and jitter at every speed, within the targets at 0.5 m/s.
    let lag = r["lag"].as_array().unwrap();
    assert_eq!(lag.iter().map(|l| l["speed_m_s"].as_f64().unwrap()).collect::<Vec<_>>(), [0.1, 0.25, 0.5, 1.0, 2.0]);
    assert!(r["lag_pass"] == true && r["jitter_pass"] == true, "{lag:?}");
    for l in lag {
        assert!(l["lag_mm"].as_f64().unwrap() > 0.0 && l["jitter_mm"].as_f64().unwrap() > 0.0, "{l}");
    }
    assert!(r["teapot_step_us"].is_null(), "no teapot run, no teapot time");
}

/// The runs of one object from one approach at 0.5 m/s.
fn runs_at_half_a_metre(object: &str, approach: &str) -> Vec<Value> {
    let out = bench(&["--json", "--objects", object, "--speeds", "0.5", "--approaches", approach]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let r: Value = serde_json::from_slice(&out.stdout).unwrap();
    r["runs"].as_array().unwrap().clone()
}

/// The exact and the headset-tracked run of one object from one approach at 0.5 m/s.
fn both_runs(object: &str, approach: &str) -> Vec<Value> {
    let runs = runs_at_half_a_metre(object, approach);
    assert_eq!(runs.iter().map(|x| x["headset"].as_bool().unwrap()).collect::<Vec<_>>(), [false, true]);
    runs
}

/// Issue 28: the teapot set down from the front, tracked as a headset tracks it, turns into
/// the ring and little fingers round it as it settles on the table (the fingers let it
/// through, so as not to bat it away); a finger that no start leaves clear takes the one the
/// mesh overlaps least, not the one as last rendered, which left the skin 1.02 mm in it.
#[test]
fn the_teapot_set_down_from_the_front_stays_out_of_the_fingers_round_it() {
    for run in both_runs("teapot", "front") {
        assert_eq!(run["success"], true, "{run}");
        assert!(run["max_penetration_mm"].as_f64().unwrap() <= 1.0, "the skin in the teapot: {run}");
    }
}

/// Headset-tracked, the ball is set down 8 mm above the table with a finger 4.5 mm below its
/// side: that finger must let it fall past, not turn it into a roll (it rolled 23 cm away
/// while only the proxies within 2 mm of it were let through).
#[test]
fn the_ball_set_down_from_the_side_falls_past_the_finger_below_it() {
    for run in both_runs("ball", "side") {
        assert_eq!(run["success"], true, "{run}");
        assert!(run["release_drift_mm"].as_f64().unwrap() <= 10.0, "the ball rolled away: {run}");
    }
}

/// The ball held from above: a finger that reached the user's angles clear of it closes on
/// from there, not from open into the ball again the next frame (its little finger, curled
/// under it, flickered between the two every other frame for 0.8 s: 77 jumps of 0.6–1.5 rad).
#[test]
fn the_fingers_round_the_ball_held_from_above_do_not_flicker() {
    let runs = runs_at_half_a_metre("ball", "above");
    assert_eq!(runs.len(), 4, "the grasp and the drop, exact and headset-tracked");
    for run in runs {
        assert_eq!(run["success"], true, "{run}");
        assert_eq!(run["finger_jumps"], 0, "{run}");
    }
}

#[test]
fn bad_arguments_are_refused_naming_them() {
    for (args, says) in [(&["--objects", "anvil"][..], "--objects anvil"), (&["--speeds", "0"][..], "--speeds 0"), (&["--approaches", "below"][..], "--approaches below")] {
        let out = bench(args);
        assert!(!out.status.success());
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(says), "{args:?}: {err}");
    }
}
