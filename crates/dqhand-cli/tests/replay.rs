//! The gesture loop through the real command: synthesize a labelled recording, replay it
//! (or stream it to `listen`), and check the printed events against the labels; bad records
//! counted, not fatal.

use std::io::{BufRead, BufReader, Read};
use std::net::UdpSocket;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::Duration;

use dqhand::interaction::benchmark::{LoggedEvent, RecognitionScore};
use dqhand::interaction::synthetic::Label;

fn temp_dir(test: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("dqhand-replay-{}-{test}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn dqhand<S: AsRef<std::ffi::OsStr>>(args: &[S]) -> Output {
    let out = Command::new(env!("CARGO_BIN_EXE_dqhand")).args(args).output().unwrap();
    assert!(out.status.success(), "dqhand {:?}: {}", args.iter().map(|a| a.as_ref().to_owned()).collect::<Vec<_>>(), String::from_utf8_lossy(&out.stderr));
    out
}

fn synthesize(dir: &Path, format: &str, extension: &str, extra: &[&str]) -> (PathBuf, serde_json::Value) {
    let path = dir.join(format!("rec.{extension}"));
    let mut args = vec!["synthesize", "--format", format, "--holds", "13", "--idle", "20", "--out", path.to_str().unwrap()];
    args.extend_from_slice(extra);
    dqhand(&args);
    let labels: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(path.with_extension("labels.json")).unwrap()).unwrap();
    assert!(labels["synthetic"].as_str().unwrap().contains("not captured"));
    (path, labels)
}

fn events(out: &Output) -> Vec<LoggedEvent> {
    events_in(&String::from_utf8_lossy(&out.stdout))
}

fn events_in(stdout: &str) -> Vec<LoggedEvent> {
    stdout.lines().map(|l| serde_json::from_str(l).unwrap()).collect()
}

/// The events scored against the labels (as `dqhand gesture-bench` scores them).
fn score(events: &[LoggedEvent], labels: &serde_json::Value) -> RecognitionScore {
    let holds: Vec<Label> = serde_json::from_value(labels["holds"].clone()).unwrap();
    let idle = (labels["idle"][0].as_f64().unwrap(), labels["idle"][1].as_f64().unwrap());
    RecognitionScore::new(&holds, idle, events)
}

/// Every labelled hold starts within 150 ms of the pose being reached; idle motion causes no
/// event.
fn check_recognition(out: &Output, labels: &serde_json::Value) {
    check_events(&events(out), labels);
}

fn check_events(events: &[LoggedEvent], labels: &serde_json::Value) {
    let score = score(events, labels);
    assert_eq!(score.holds.len(), labels["holds"].as_array().unwrap().len());
    for hold in &score.holds {
        assert!(hold.in_time(), "{} reached at {} s not recognised within 150 ms: {hold:?}\n{events:?}", hold.gesture, hold.reached);
    }
    assert_eq!(score.spurious, 0, "idle motion caused events: {events:?}");
}

#[test]
fn joints_and_landmarks_recordings_print_the_labelled_gestures() {
    let dir = temp_dir("joints");
    for (format, hand) in [("joints", "right"), ("landmarks", "left")] {
        let (path, labels) = synthesize(&dir, format, "jsonl", &["--seed", "5", "--length", "0.17", "--breadth", "0.08", "--side", hand]);
        let poses = dir.join("poses.jsonl");
        let out = dqhand(&["replay", "--input", path.to_str().unwrap(), "--gestures", "--stats", "--out", poses.to_str().unwrap()]);
        check_recognition(&out, &labels);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(stderr.contains("0 rejected"), "{stderr}");
        assert!(stderr.contains("length 0.17"), "the user's hand is measured: {stderr}");
        let first: serde_json::Value = serde_json::from_str(std::fs::read_to_string(&poses).unwrap().lines().next().unwrap()).unwrap();
        assert_eq!(first["model"], "full");
        assert!(first["t"].is_number() && first["wrist"].is_object() && first["tracking"] == "tracking");
    }
}

/// A glove recording drives the hand: the finger gestures a 14-sensor glove can tell apart.
#[test]
fn a_glove_recording_prints_its_finger_gestures() {
    let dir = temp_dir("glove");
    let (path, labels) = synthesize(&dir, "glove", "csv", &["--seed", "4", "--side", "right"]);
    let out = dqhand(&["replay", "--input", path.to_str().unwrap(), "--gestures"]);
    let events = events(&out);
    let score = score(&events, &labels);
    // The 5DT has no thumb CMC flexion or thumb-tip sensing: only the finger-defined gestures.
    for hold in score.holds.iter().filter(|h| ["fist", "point", "victory", "three", "four"].contains(&h.gesture.as_str())) {
        assert!(hold.latency_s.is_some_and(|l| l < 0.5), "{} at {}: {hold:?}\n{events:?}", hold.gesture, hold.reached);
    }
}

/// `calibrate` finds the flat, fist and spread readings of a calibration recording, and the
/// calibration it writes is what a replay then uses.
#[test]
fn calibrate_writes_the_extremes_of_the_calibration_poses() {
    let dir = temp_dir("calibrate");
    let sensors = ["thumb_near", "thumb_far", "thumb_index", "index_near", "index_far", "index_middle", "middle_near", "middle_far", "middle_ring", "ring_near", "ring_far", "ring_little", "little_near", "little_far"];
    let abduction = |s: &str| ["thumb_index", "index_middle", "middle_ring", "ring_little"].contains(&s);
    let mut csv = format!("t,{}\n", sensors.join(","));
    for (k, (flex, abd)) in [(600.0, 700.0), (3400.0, 700.0), (600.0, 2900.0)].iter().enumerate() {
        for i in 0..20 {
            let t = (k * 20 + i) as f64 * 0.02;
            let values: Vec<String> = sensors.iter().map(|s| format!("{}", if abduction(s) { abd } else { flex } + (i % 3) as f64)).collect();
            csv += &format!("{t},{}\n", values.join(","));
        }
    }
    let path = dir.join("calibration.csv");
    std::fs::write(&path, csv).unwrap();
    let calib = dir.join("calib.json");
    dqhand(&["calibrate", "--input", path.to_str().unwrap(), "--out", calib.to_str().unwrap()]);
    let c: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&calib).unwrap()).unwrap();
    let index = &c["sensors"]["index_near"];
    assert!((index["flat"].as_f64().unwrap() - 601.0).abs() <= 2.0 && (index["fist"].as_f64().unwrap() - 3401.0).abs() <= 2.0, "{c}");
    let spread = &c["sensors"]["index_middle"];
    assert!((spread["flat"].as_f64().unwrap() - 701.0).abs() <= 2.0 && (spread["spread"].as_f64().unwrap() - 2901.0).abs() <= 2.0, "{c}");
    dqhand(&["replay", "--input", path.to_str().unwrap(), "--calib", calib.to_str().unwrap()]);
}

/// Bad records are counted per kind on stderr; the good ones still drive the hand.
#[test]
fn bad_records_are_summarised_and_skipped() {
    let dir = temp_dir("bad");
    let (path, _) = synthesize(&dir, "joints", "jsonl", &["--seed", "6", "--side", "right"]);
    let text = std::fs::read_to_string(&path).unwrap();
    let mut lines: Vec<String> = text.lines().map(str::to_owned).collect();
    lines.insert(10, "{\"t\": 0.1, \"joints\": {\"wrist\"".into());
    lines.insert(20, lines[5].clone()); // time going backwards
    lines.insert(30, lines[31].replace("\"wrist\"", "\"wrist-bone\""));
    let bad = dir.join("bad.jsonl");
    std::fs::write(&bad, lines.join("\n")).unwrap();
    let out = dqhand(&["replay", "--input", bad.to_str().unwrap(), "--gestures"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    for needle in ["1 record rejected (malformed), first: line 11", "1 record rejected (unknown name), first: line 31", "1 record rejected (out of order)", "3 rejected"] {
        assert!(stderr.contains(needle), "{needle:?} not in {stderr}");
    }
    assert!(!events(&out).is_empty());
    // A file that is not there is one clear error.
    let out = Command::new(env!("CARGO_BIN_EXE_dqhand")).args(["replay", "--input", "/no/such.jsonl"]).output().unwrap();
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("/no/such.jsonl"));
}

/// `listen` takes a recording streamed over UDP, one record per datagram, with bad datagrams
/// among them: it prints the labelled gestures as they happen, summarises the refusals per
/// kind, and records exactly the records it took, in a file `replay` reads back to the same
/// events.
#[test]
fn listen_takes_udp_records_prints_events_and_records_what_it_took() {
    let dir = temp_dir("listen");
    let (path, labels) = synthesize(&dir, "joints", "jsonl", &["--seed", "7", "--side", "left"]);
    let recorded = dir.join("live.jsonl");
    let mut child = Command::new(env!("CARGO_BIN_EXE_dqhand"))
        .args(["listen", "--udp", "0", "--gestures", "--hand", "left", "--seconds", "15", "--record", recorded.to_str().unwrap()])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut stderr = BufReader::new(child.stderr.take().unwrap());
    let mut banner = String::new();
    stderr.read_line(&mut banner).unwrap();
    let address = banner.strip_prefix("listening on udp ").and_then(|a| a.split(',').next()).unwrap_or_else(|| panic!("{banner}")).trim().to_owned();
    assert!(banner.contains("this machine only"), "{banner}");
    let lines: Vec<String> = std::fs::read_to_string(&path).unwrap().lines().map(str::to_owned).collect();
    let socket = UdpSocket::bind("127.0.0.1:0").unwrap();
    for (i, line) in lines.iter().enumerate() {
        match i {
            10 => drop(socket.send_to(b"{\"t\": 0.1, \"joints\": {\"wrist\"", &address)),
            20 => drop(socket.send_to(lines[5].as_bytes(), &address)), // time going backwards
            30 => drop(socket.send_to(lines[31].replace("\"wrist\"", "\"wrist-bone\"").as_bytes(), &address)),
            40 => drop(socket.send_to(&vec![b'x'; 20_000], &address)),
            _ => {}
        }
        socket.send_to(line.as_bytes(), &address).unwrap();
        std::thread::sleep(Duration::from_millis(1));
    }
    let mut stdout = String::new();
    child.stdout.take().unwrap().read_to_string(&mut stdout).unwrap();
    let mut rest = String::new();
    stderr.read_to_string(&mut rest).unwrap();
    assert!(child.wait().unwrap().success(), "{rest}");
    let live = events_in(&stdout);
    check_events(&live, &labels);
    for needle in ["1 record rejected (malformed)", "1 record rejected (unknown name)", "1 record rejected (out of order)", "1 record rejected (too large)", "tracking: tracking", "tracking: lost"] {
        assert!(rest.contains(needle), "{needle:?} not in {rest}");
    }
    // Loopback UDP may drop a datagram on a loaded machine: count what was taken.
    let taken: usize = rest.lines().find_map(|l| l.strip_suffix(" records taken, 4 rejected")).and_then(|l| l.rsplit(' ').next()?.parse().ok()).unwrap_or_else(|| panic!("no total in {rest}"));
    assert!(taken * 20 >= lines.len() * 19, "{taken} of {} records taken", lines.len());
    let recording = std::fs::read_to_string(&recorded).unwrap();
    assert_eq!(recording.lines().count(), taken, "every record taken is recorded, nothing else");
    let replayed = dqhand(&["replay", "--input", recorded.to_str().unwrap(), "--gestures", "--hand", "left"]);
    assert_eq!(events(&replayed), live, "the recording replays to the events seen live");
}
