//! `dqhand grasp` through the real command: a scripted recording (from `dqhand synthesize
//! --scene`) grasps the ball and the teapot of the built-in scene; the trace has one line
//! per frame in the documented form and meshes every Nth frame; bad scenes are refused with
//! the file and the field named.

use std::path::{Path, PathBuf};
use std::process::Command;

use serde_json::Value;

fn temp_dir(test: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("dqhand-grasp-{}-{test}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn dqhand(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_dqhand")).args(args).output().unwrap()
}

#[test]
fn a_scripted_recording_grasps_carries_and_sets_down_both_objects() {
    let dir = temp_dir("scripted");
    let rec = dir.join("grasp.jsonl");
    let trace = dir.join("trace.jsonl");
    let meshes = dir.join("meshes");
    let out = dqhand(&["synthesize", "--scene", "grasp", "--side", "right", "--out", rec.to_str().unwrap()]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let out = dqhand(&["grasp", "--scene", "grasp", "--input", rec.to_str().unwrap(), "--trace", trace.to_str().unwrap(), "--meshes", meshes.to_str().unwrap(), "--every", "200"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let lines: Vec<Value> = std::fs::read_to_string(&trace).unwrap().lines().map(|l| serde_json::from_str(l).unwrap()).collect();
    let labels: Value = serde_json::from_str(&std::fs::read_to_string(rec.with_extension("labels.json")).unwrap()).unwrap();
    let end = labels["tasks"][1]["times"]["end"].as_f64().unwrap();
    assert!((lines.len() as f64 - (end * 60.0 + 1.0)).abs() <= 2.0, "one line per 1/60 s frame: {} lines for {end} s", lines.len());
    let mut held = Vec::new();
    for l in &lines {
        assert!(l["t"].is_f64());
        assert!(["ok", "lost"].contains(&l["tracking"].as_str().unwrap()));
        for c in l["contacts"].as_array().unwrap() {
            assert!(c["bone"].is_string() && ["ball", "teapot"].contains(&c["object"].as_str().unwrap()));
            let n: Vec<f64> = c["n"].as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect();
            assert!((n.iter().map(|x| x * x).sum::<f64>() - 1.0).abs() < 1e-3, "unit normals");
            assert_eq!(c["p"].as_array().unwrap().len(), 3);
        }
        assert_eq!(l["objects"]["teapot"]["q"].as_array().unwrap().len(), 4);
        if let Some(h) = l["held"].as_str() {
            if held.last() != Some(&h.to_owned()) {
                held.push(h.to_owned());
            }
        }
    }
    assert_eq!(held, ["ball", "teapot"], "each grasped once, in turn");
    assert!(lines.iter().any(|l| l["tracking"] == "lost"), "the gap between the two tasks is a tracking loss");
    let last = lines.last().unwrap();
    assert!(last["held"].is_null());
    let ball_z = last["objects"]["ball"]["p"][2].as_f64().unwrap();
    assert!((ball_z - (-0.35 + 0.2)).abs() < 0.03, "the ball carried 20 cm toward the user: z = {ball_z}");
    for frame in [0, 200, 400, 600] {
        let ply = meshes.join(format!("{frame}.ply"));
        assert!(std::fs::read(&ply).unwrap().starts_with(b"ply"), "{}", ply.display());
    }
    assert!(!meshes.join("100.ply").exists(), "only every 200th frame");
}

#[test]
fn bad_scenes_are_refused_naming_the_file_and_field() {
    let dir = temp_dir("bad-scene");
    let scene = dir.join("bad.json");
    std::fs::write(&scene, r#"{"objects": [{"name": "ball", "shape": "sphere", "radius": 0.04, "position": [0, 1, 0], "mass": -1}]}"#).unwrap();
    let trace = dir.join("trace.jsonl");
    let out = dqhand(&["grasp", "--scene", scene.to_str().unwrap(), "--input", "nonexistent.jsonl", "--trace", trace.to_str().unwrap()]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("bad.json") && err.contains("mass"), "{err}");
    assert!(!Path::new(&trace).exists(), "nothing written");
}

#[test]
fn a_recording_of_both_hands_drives_a_left_and_a_right_hand() {
    let dir = temp_dir("two-hands");
    let rec = dir.join("two.jsonl");
    let trace = dir.join("trace.jsonl");
    let meshes = dir.join("meshes");
    let out = dqhand(&["synthesize", "--scene", "two-hands", "--out", rec.to_str().unwrap()]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = std::fs::read_to_string(&rec).unwrap();
    assert!(text.contains("\"hand\":\"left\"") && text.contains("\"hand\":\"right\""), "records of both sides");
    let args = ["grasp", "--scene", "two-hands", "--left-model", "builtin", "--input", rec.to_str().unwrap(), "--trace", trace.to_str().unwrap(), "--meshes", meshes.to_str().unwrap(), "--every", "300"];
    let out = dqhand(&args);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let lines: Vec<Value> = std::fs::read_to_string(&trace).unwrap().lines().map(|l| serde_json::from_str(l).unwrap()).collect();
    // Who held what, in turn: the box by both hands, then the bar by the right, by both, by
    // the left alone.
    let mut held: Vec<(Value, Value)> = Vec::new();
    for l in &lines {
        assert!(l["tracking"]["left"].is_string() && l["tracking"]["right"].is_string(), "{l}");
        let now = (l["held"]["left"].clone(), l["held"]["right"].clone());
        if held.last() != Some(&now) {
            held.push(now);
        }
    }
    let names: Vec<(Option<&str>, Option<&str>)> = held.iter().map(|(l, r)| (l.as_str(), r.as_str())).collect();
    assert_eq!(
        names,
        [(None, None), (Some("box"), Some("box")), (None, None), (None, Some("baton")), (Some("baton"), Some("baton")), (Some("baton"), None), (None, None)],
        "the hold of each hand in turn"
    );
    let last = lines.last().unwrap();
    let bar = last["objects"]["baton"]["p"].as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect::<Vec<_>>();
    assert!((bar[2] - 0.24).abs() < 0.03 && (bar[1] - 0.78).abs() < 0.01, "the bar handed over and set down 24 cm on: {bar:?}");
    for side in ["left", "right"] {
        let ply = meshes.join(format!("300-{side}.ply"));
        assert!(std::fs::read(&ply).unwrap().starts_with(b"ply"), "{}", ply.display());
    }
}
