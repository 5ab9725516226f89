//! `dqhand grasp-bench` through the real command: a small run reports every measure, and the
//! scripted grasp of the ball meets the targets for success, penetration, slip and
//! tunnelling (correctness, not timing: the timings are only checked to be there).

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
    let what: Vec<(&str, &str)> = runs.iter().map(|x| (x["object"].as_str().unwrap(), x["kind"].as_str().unwrap())).collect();
    assert_eq!(what, [("ball", "grasp"), ("plate", "strike")]);
    assert_eq!((r["grasps"].as_u64(), r["successes"].as_u64()), (Some(1), Some(1)), "the ball is grasped, carried and set down");
    assert!(r["max_penetration_mm"].as_f64().unwrap() <= 1.0, "penetration {}", r["max_penetration_mm"]);
    assert!(r["max_slip_mm"].as_f64().unwrap() <= 3.0, "slip {}", r["max_slip_mm"]);
    assert_eq!(r["tunnelled"], 0, "a 10 m/s strike on the 8 mm plate does not pass into it");
    let ball = &runs[0];
    assert!(ball["release_frames"].as_u64().is_some(), "released: {ball}");
    assert!(ball["step_us"]["median"].as_f64().unwrap() > 0.0);
    assert!(r["teapot_step_us"].is_null(), "no teapot run, no teapot time");
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
