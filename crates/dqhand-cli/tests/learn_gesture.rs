//! `dqhand learn-gesture` through the real command: a gesture no built-in definition has (the
//! finger gun: index out, thumb up, the others curled), recorded for a few seconds as a hand
//! tracker's landmarks, is learned; replaying a new recording of it starts it, and a fist
//! (recorded as what must not trigger it) does not.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use dqhand::gesture::gesture;
use dqhand::hand::{build, HandParams};
use dqhand::input::mediapipe::WEBXR_INDEX;
use dqhand::kinematics::{JointModel, JointPositions, Pose};
use dqhand::math::Rng;

fn dqhand(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_dqhand")).args(args).output().unwrap()
}

/// A `seconds`-long landmarks recording of `pose` held by a right hand of `length` metres,
/// with 2 mm of landmark noise (seeded).
fn record(path: &Path, pose: &Pose, length: f32, seconds: f64, seed: u64) {
    let hand = build(&HandParams { length, breadth: length * 0.45, vertices: 1000, ..HandParams::default() }).unwrap();
    let mut kinematics = hand.hand_kinematics(JointModel::Full).unwrap();
    kinematics.pose(pose);
    let joints = JointPositions::new(kinematics.skeleton()).unwrap().read(kinematics.world());
    let mut rng = Rng::new(seed);
    let lines: Vec<String> = (0..(seconds * 30.0) as usize)
        .map(|k| {
            let landmarks: Vec<[f32; 3]> = WEBXR_INDEX.iter().map(|&w| (joints[w] + rng.normal_vec3() * 0.002).to_array()).collect();
            serde_json::json!({"t": k as f64 / 30.0, "hand": "right", "landmarks": landmarks}).to_string()
        })
        .collect();
    std::fs::write(path, lines.join("\n") + "\n").unwrap();
}

fn gun() -> Pose {
    let mut pose = gesture("point").unwrap().pose(JointModel::Full);
    for (dof, deg) in [("thumb-metacarpal.abd", 45.0f32), ("thumb-metacarpal.flex", -20.0), ("thumb-phalanx-proximal.flex", 0.0), ("thumb-phalanx-distal.flex", 0.0)] {
        pose.angles[JointModel::Full.dof_index(dof).unwrap()] = deg.to_radians();
    }
    pose
}

fn temp_dir() -> PathBuf {
    let dir = std::env::temp_dir().join(format!("dqhand-learn-gesture-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn started(out: &Output) -> Vec<String> {
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    String::from_utf8_lossy(&out.stdout)
        .lines()
        .map(|l| serde_json::from_str::<serde_json::Value>(l).unwrap())
        .filter(|e| e["event"] == "start")
        .map(|e| e["gesture"].as_str().unwrap().to_owned())
        .collect()
}

#[test]
fn a_recorded_gesture_is_learned_and_recognised_in_a_new_recording_and_a_fist_is_not_it() {
    let dir = temp_dir();
    let (gun_rec, fist_rec) = (dir.join("gun.jsonl"), dir.join("fist.jsonl"));
    record(&gun_rec, &gun(), 0.18, 4.0, 1);
    record(&fist_rec, &gesture("fist").unwrap().pose(JointModel::Full), 0.18, 3.0, 2);
    let out_file = dir.join("gestures.json");
    let out = dqhand(&["learn-gesture", "--name", "gun", "--input", gun_rec.to_str().unwrap(), "--not", fist_rec.to_str().unwrap(), "--out", out_file.to_str().unwrap()]);
    let report = String::from_utf8_lossy(&out.stdout).to_string();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    for needle in ["learn-gesture: \"gun\"", "frames held back", "built-in gestures' held-out frames"] {
        assert!(report.contains(needle), "{needle}: {report}");
    }
    let file: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&out_file).unwrap()).unwrap();
    assert_eq!(file["gestures"][0]["name"], "gun", "a learned gesture comes first");
    assert_eq!(file["gestures"].as_array().unwrap().len(), 13, "the 12 built-in ones follow");

    // A new recording by a smaller hand: the gun starts; the fist starts, never the gun.
    let (new_gun, new_fist) = (dir.join("gun2.jsonl"), dir.join("fist2.jsonl"));
    record(&new_gun, &gun(), 0.16, 2.0, 3);
    record(&new_fist, &gesture("fist").unwrap().pose(JointModel::Full), 0.16, 2.0, 4);
    let replay = |input: &Path| dqhand(&["replay", "--gestures-file", out_file.to_str().unwrap(), "--input", input.to_str().unwrap()]);
    assert_eq!(started(&replay(&new_gun)), ["gun"]);
    assert_eq!(started(&replay(&new_fist)), ["fist"]);

    // A recording too short to learn from is refused, naming it.
    let brief = dir.join("brief.jsonl");
    record(&brief, &gun(), 0.18, 1.0, 5);
    let short = dqhand(&["learn-gesture", "--name", "gun", "--input", brief.to_str().unwrap(), "--out", out_file.to_str().unwrap()]);
    assert_eq!(short.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&short.stderr).contains("brief.jsonl: 1.0 s of records; record at least 1.6 s"), "{}", String::from_utf8_lossy(&short.stderr));
    std::fs::remove_dir_all(&dir).unwrap();
}
