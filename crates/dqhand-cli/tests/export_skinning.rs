//! `dqhand export-skinning` (the frame `make bench-peers` hands to libigl, NumPy and three.js):
//! blending the exported matrices by the exported weights, from LB's definition in plain f64
//! code, must give dqhand's exported LB positions, or every peer's deviation would be wrong.

use std::process::Command;

use serde_json::Value;

#[test]
fn the_exported_matrices_and_weights_reproduce_dqhand_lb() {
    let dir = std::env::temp_dir().join(format!("dqhand-cli-{}-export-skinning", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let out = Command::new(env!("CARGO_BIN_EXE_dqhand")).args(["export-skinning", "--frames", "3", "--out"]).arg(&dir).output().expect("run dqhand");
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));

    let rig: Value = serde_json::from_str(&std::fs::read_to_string(dir.join("rig.json")).unwrap()).unwrap();
    let bin = std::fs::read(dir.join("rig.bin")).unwrap();
    let n = rig["vertices"].as_u64().unwrap() as usize;
    let joints = rig["joints"].as_u64().unwrap() as usize;
    // An array as f64 (u32 indices convert exactly), after checking its declared shape.
    let array = |name: &str, rows: usize, columns: usize| -> Vec<f64> {
        let a = &rig["arrays"][name];
        assert_eq!(a["shape"], serde_json::json!([rows, columns]), "{name}");
        let offset = a["offset"].as_u64().unwrap() as usize;
        let words = bin[offset..offset + rows * columns * 4].chunks_exact(4).map(|b| <[u8; 4]>::try_from(b).unwrap());
        match a["dtype"].as_str().unwrap() {
            "float32" => words.map(|w| f64::from(f32::from_le_bytes(w))).collect(),
            "uint32" => words.map(|w| f64::from(u32::from_le_bytes(w))).collect(),
            other => panic!("{name}: dtype {other}"),
        }
    };
    let rest = array("rest_positions", n, 3);
    let (slots, weights) = (array("joints", n, 4), array("weights", n, 4));
    let skinning = array("skinning", joints, 16);
    let lb = array("lb_positions", n, 3);

    let mut moved = 0f64;
    for v in 0..n {
        let p = &rest[3 * v..3 * v + 3];
        let mut blended = [0f64; 3];
        for s in 4 * v..4 * v + 4 {
            // Column-major 4×4: element (row r, column c) at 4c + r.
            let m = &skinning[16 * slots[s] as usize..][..16];
            for (r, b) in blended.iter_mut().enumerate() {
                *b += weights[s] * (m[r] * p[0] + m[4 + r] * p[1] + m[8 + r] * p[2] + m[12 + r]);
            }
        }
        let weight_sum: f64 = weights[4 * v..4 * v + 4].iter().sum();
        assert!((weight_sum - 1.0).abs() < 1e-5, "vertex {v}: weights sum to {weight_sum}");
        let error = (0..3).map(|i| (blended[i] - lb[3 * v + i]).powi(2)).sum::<f64>().sqrt();
        assert!(error < 1e-4, "vertex {v}: Σ wᵢ Mᵢ v is {error} m from dqhand's LB");
        moved = moved.max((0..3).map(|i| (lb[3 * v + i] - p[i]).powi(2)).sum::<f64>().sqrt());
    }
    // Identity matrices would pass the check above: the default pose must bend the hand.
    assert!(moved > 0.02, "the pose moves no vertex more than {moved} m");

    let timing: Value = serde_json::from_str(&std::fs::read_to_string(dir.join("dqhand.json")).unwrap()).unwrap();
    for m in ["lb", "dqb"] {
        assert!(timing["methods"][m]["us_per_frame"].as_f64().unwrap() > 0.0, "{m} timed");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
