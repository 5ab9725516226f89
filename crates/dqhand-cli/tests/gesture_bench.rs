//! `dqhand gesture-bench` through the real command: a small fixed-seed run reports every
//! measure, and its accuracy figures meet the targets (correctness, not timing: the
//! timings are only checked to be there).

use std::process::Command;

use serde_json::Value;

fn bench(args: &[&str]) -> Value {
    let out = Command::new(env!("CARGO_BIN_EXE_dqhand")).arg("gesture-bench").args(args).output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    serde_json::from_slice(&out.stdout).unwrap()
}

fn number(v: &Value, what: &str) -> f64 {
    v.as_f64().unwrap_or_else(|| panic!("{what} is not a number: {v}"))
}

#[test]
fn a_small_run_reports_every_measure_and_meets_the_accuracy_targets() {
    let outside = concat!(env!("CARGO_MANIFEST_DIR"), "/../../third_party/node_modules");
    let r = bench(&["--json", "--seed", "3", "--sequences", "2", "--outside", outside]);
    assert!(r["synthetic"].as_str().unwrap().contains("not captured from a person"));
    assert_eq!(r["split"], "held-out");
    assert_eq!((r["seed"].as_u64(), r["sequences_per_source"].as_u64()), (Some(3), Some(2)));
    assert!(["debug", "release"].contains(&r["build"].as_str().unwrap()));
    let sources = r["sources"].as_array().unwrap();
    let names: Vec<&str> = sources.iter().map(|s| s["source"].as_str().unwrap()).collect();
    assert_eq!(names, ["joints", "landmarks", "landmarks, light", "glove 5dt-14", "glove cyberglove-18", "outside poses"]);
    for s in &sources[..5] {
        let name = s["source"].as_str().unwrap();
        assert_eq!(s["holds"], 26, "{name}: 2 sequences of 13 holds");
        for key in ["rate", "minutes", "spurious_per_minute", "records_per_s"] {
            number(&s[key], &format!("{name} {key}"));
        }
        for key in ["median", "p95", "max"] {
            number(&s["latency_ms"][key], &format!("{name} latency {key}"));
            assert!(number(&s["push_us"][key], &format!("{name} push {key}")) > 0.0);
        }
        assert_eq!(s["gestures"].as_object().unwrap().len(), 12, "{name}: every built-in gesture");
        // Confusions: each hold is counted once in its gesture's row.
        let row_sum: u64 = s["gestures"].as_object().unwrap().values().flat_map(|g| g["shown_at_deadline"].as_object().unwrap().values()).map(|v| v.as_u64().unwrap()).sum();
        assert_eq!(row_sum, 26, "{name}");
        assert_eq!(s["glove_dofs_not_driven"].as_array().unwrap().is_empty(), !name.starts_with("glove"));
    }
    // Hand tracking on held-out hands, and other people's poses: the targets, and quiet.
    for s in [&sources[0], &sources[5]] {
        let name = s["source"].as_str().unwrap();
        assert!(number(&s["rate"], name) >= number(&s["target"], name) && s["rate_pass"] == true, "{name}: {s}");
        assert!(number(&s["spurious_per_minute"], name) <= 1.0 && s["spurious_pass"] == true, "{name}: {s}");
    }
    // Landmarks with MediaPipe's measured errors do NOT meet the 95 % target (docs/gestures.md
    // says so: about 85–88 %); the bench must say so, and the figure must not fall further.
    // With the lighter errors the classifier is trained on, they would (no target: reported).
    let measured = &sources[1];
    assert_eq!(number(&measured["target"], "landmarks target"), 0.95);
    assert_eq!(measured["rate_pass"], number(&measured["rate"], "landmarks") >= 0.95, "{measured}");
    assert!(number(&measured["rate"], "landmarks") >= 0.8, "{measured}");
    assert!(number(&sources[2]["rate"], "landmarks, light") >= 0.95, "{}", sources[2]);
    assert!(sources[5]["holds"].as_u64().unwrap() >= 48, "every outside pose, three times per hand");
    // Both hands of handy-work's captures at once, each hand recognised by itself and the
    // gesture of both hands (both palms open, held together) from the two.
    let both = &r["both_hands"];
    assert_eq!((both["holds"].as_u64(), both["hands"].as_u64()), (Some(45), Some(90)), "7 captures, 7 mixed pairs, 1 held together, 3 rounds: {both}");
    assert!(number(&both["hands_rate"], "both hands") >= 0.97 && both["hands_pass"] == true, "{both}");
    assert!(both["two_hand"].as_u64().unwrap() >= 30 && number(&both["two_hand_rate"], "two-hand") >= 0.9, "{both}");
    // Our own hand's noise-free joints come back within the 1° (much better, in fact).
    let own = &r["retarget"]["own_hand"];
    assert!(number(&own["scores"]["mean_deg"], "mean") <= 1.0 && own["mean_pass"] == true, "{own}");
    for who in [&own["scores"], &r["retarget"]["users_hands"]] {
        assert!(who["records"].as_u64().unwrap() > 1000 && who["refused"] == 0, "{who}");
        assert!(who["contacts"].as_u64().unwrap() > 0, "near pinches are closed into contacts: {who}");
        // The virtual gap is never wider than the tracked one, so within the 5 mm target.
        assert!(number(&who["max_contact_excess_mm"], "excess") <= 0.0 && who["contact_pass"] == true, "{who}");
        assert!(number(&who["max_contact_gap_mm"], "gap") <= 5.0, "{who}");
    }
    let speed = &r["speed"];
    assert!(number(&speed["push_us"]["median"], "push") > 0.0 && number(&speed["records_per_s"], "records/s") > 0.0);
    assert_eq!(speed["records"], sources.iter().map(|s| s["records"].as_u64().unwrap()).sum::<u64>());
}

#[test]
fn the_table_names_the_targets_and_says_a_debug_build_is_not_timed() {
    let out = Command::new(env!("CARGO_BIN_EXE_dqhand")).args(["gesture-bench", "--sequences", "1"]).output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = String::from_utf8_lossy(&out.stdout);
    for needle in ["recognition:", "joints ≥ 97 %", "landmarks ≥ 95 %", "spurious/min", "retargeting", "target mean ≤ 1°", "thumb–index contacts", "GestureLoop::push", "records/s"] {
        assert!(text.contains(needle), "{needle:?} not in\n{text}");
    }
    assert_eq!(text.contains("debug build: the timings below are not meaningful"), cfg!(debug_assertions), "{text}");
    let bad = Command::new(env!("CARGO_BIN_EXE_dqhand")).args(["gesture-bench", "--sequences", "0"]).output().unwrap();
    assert_eq!(bad.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&bad.stderr).contains("--sequences must be at least 1"));
}
