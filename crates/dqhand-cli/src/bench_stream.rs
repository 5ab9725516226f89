//! `dqhand bench --stream`: the viewer stream end to end. A server thread runs the real
//! WebSocket endpoint on a loopback port; a client in this process asks for the paper's three
//! methods side by side (LB, QB and DQB of every frame, as the figures in performance.md were
//! measured; the viewer's split view adds CoR), acknowledges each frame as the page does, and counts what
//! arrives. Reported: frames per second achieved against the target rate, the engine's own
//! time per frame (pose, three deformations, optional heat map) as median and 90th percentile,
//! and the bytes streamed.

use std::net::{Ipv4Addr, TcpListener};
use std::sync::Arc;
use std::time::{Duration, Instant};

use dqhand::kinematics::JointModel;
use dqhand::model::Model;
use dqhand_stream::FrameView;
use serde_json::json;
use tungstenite::Message;

use crate::server;

/// One configuration measured.
struct Run {
    target_fps: f64,
    heatmap: bool,
}

/// Frames before this are not counted (connection, caches, CPU frequency).
const WARM_UP: Duration = Duration::from_millis(300);

const RUNS: [Run; 3] = [
    Run { target_fps: 120.0, heatmap: false },
    Run { target_fps: 1000.0, heatmap: false },
    Run { target_fps: 1000.0, heatmap: true },
];

pub fn run(model: Model, seconds: f64, json_out: bool) -> anyhow::Result<()> {
    let model = Arc::new(model);
    let vertices = model.mesh.vertex_count();
    let mut rows = Vec::new();
    for r in &RUNS {
        let listener = TcpListener::bind((Ipv4Addr::LOCALHOST, 0))?;
        let address = listener.local_addr()?;
        let shared = server::Shared { model: model.clone(), second: None, joint_model: JointModel::Full, assets: None, fps: r.target_fps, feed: None, page: server::PageEngine::new(Err("no live input".into())) };
        std::thread::spawn(move || server::serve(listener, shared));
        let (mut ws, _) = tungstenite::connect(format!("ws://{address}/stream"))?;
        ws.send(Message::text(json!({ "type": "view", "methods": ["lb", "qb", "dqb"] }).to_string()))?;
        ws.send(Message::text(json!({ "type": "heatmap", "on": r.heatmap }).to_string()))?;
        let (mut frames, mut bytes, mut engine_us) = (0u64, 0u64, Vec::new());
        let (mut first, mut measuring) = (None, None);
        let elapsed = loop {
            let Message::Binary(b) = ws.read()? else { continue };
            let Ok(f) = FrameView::parse(&b) else { continue }; // the topology
            ws.send(Message::text(format!(r#"{{"type":"ack","seq":{}}}"#, f.header.sequence)))?;
            if f.header.mesh_count() != 3 || f.header.distortion != r.heatmap {
                continue; // frames from before the view changed
            }
            if first.get_or_insert_with(Instant::now).elapsed() < WARM_UP {
                continue;
            }
            let since = *measuring.get_or_insert_with(Instant::now);
            frames += 1;
            bytes += b.len() as u64;
            engine_us.push(f64::from(f.header.engine_us));
            let elapsed = since.elapsed().as_secs_f64();
            if elapsed >= seconds {
                break elapsed;
            }
        };
        let mut pick = |q: f64| dqhand::math::quantile(&mut engine_us, q).expect("frames arrived");
        let (median, p90) = (pick(0.5), pick(0.9));
        rows.push((r, frames as f64 / elapsed, median, p90, bytes as f64 / elapsed / (1024.0 * 1024.0)));
    }
    if json_out {
        let runs: Vec<_> = rows
            .iter()
            .map(|(r, fps, med, p90, mib)| json!({ "target_fps": r.target_fps, "heatmap": r.heatmap, "fps": fps, "engine_median_us": med, "engine_p90_us": p90, "mib_per_s": mib }))
            .collect();
        println!("{}", json!({ "vertices": vertices, "methods": ["lb", "qb", "dqb"], "seconds": seconds, "runs": runs }));
        return Ok(());
    }
    println!("viewer stream, the paper's three side by side (LB + QB + DQB per frame), {vertices} vertices, loopback WebSocket, {seconds} s per run");
    println!("{:<12} {:<8} {:>10} {:>16} {:>10} {:>8}", "target fps", "heat map", "fps", "engine median µs", "p90 µs", "MiB/s");
    for (r, fps, med, p90, mib) in &rows {
        let target = if r.target_fps >= 1000.0 { "as fast".to_string() } else { format!("{}", r.target_fps) };
        println!("{target:<12} {:<8} {fps:>10.1} {med:>16.0} {p90:>10.0} {mib:>8.0}", if r.heatmap { "on" } else { "off" });
    }
    Ok(())
}
