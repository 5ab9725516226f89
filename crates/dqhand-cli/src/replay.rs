//! `dqhand replay`: a recording through the gesture loop as fast as it goes: gesture events
//! as JSON lines on stdout, the retargeted poses to a file if asked, a summary of refused
//! records (and with `--stats`, speed and the user's hand size) on stderr.

use std::io::Write;
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;

use anyhow::Context;
use dqhand::engine::ModelSource;
use dqhand::input::{Record, Tracking};
use dqhand::interaction::benchmark::Distribution;
use dqhand::interaction::GestureLoop;
use dqhand::io::PoseFile;
use dqhand::kinematics::JointModel;
use dqhand::math::quantile;

use crate::recording::RecordingArgs;

/// Arguments of `dqhand replay`.
#[derive(clap::Args)]
pub struct Args {
    #[command(flatten)]
    recording: RecordingArgs,
    /// Write the retargeted pose of every record here (JSON lines: `t`, `tracking` and a
    /// pose file's `model`, `wrist`, `angles_deg`).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Also report records per second, time per record and the user's hand size.
    #[arg(long)]
    stats: bool,
    /// Joint model of the retargeted poses.
    #[arg(long, default_value = "full")]
    joint_model: JointModel,
    /// The hand posed: `builtin` or a skinned glTF with WebXR joint names.
    #[arg(long, default_value = "builtin")]
    model: ModelSource,
}

pub fn run(args: &Args) -> anyhow::Result<()> {
    let model = Arc::new(args.model.load()?);
    let gestures = args.recording.recognition.set()?;
    let mapper = Some(args.recording.common.mapper(args.joint_model)?);
    let mut reader = args.recording.reader()?;
    let mut gesture_loop = GestureLoop::new(model, args.joint_model, mapper, args.recording.common.config()?, gestures)?;
    let mut out = match &args.out {
        Some(path) => Some(std::io::BufWriter::new(std::fs::File::create(path).with_context(|| path.display().to_string())?)),
        None => None,
    };
    let stdout = std::io::stdout();
    let mut events_out = std::io::BufWriter::new(stdout.lock());
    let mut record = Record { time: 0.0, side: args.recording.common.hand, hand: None, tracker: None, arrival: None };
    let (mut records, mut times_us, mut sizes) = (0u64, Vec::new(), Vec::new());
    let start = Instant::now();
    loop {
        let t0 = Instant::now();
        let Some(read) = reader.next(&mut record).with_context(|| args.recording.input.display().to_string())? else { break };
        records += 1;
        if let Err(rejection) = read {
            gesture_loop.reject(rejection);
            continue;
        }
        match gesture_loop.push(&record) {
            Ok(events) => {
                for event in events {
                    serde_json::to_writer(&mut events_out, &event)?;
                    events_out.write_all(b"\n")?;
                }
            }
            Err(_) => continue,
        }
        if args.stats {
            times_us.push(t0.elapsed().as_secs_f64() * 1e6);
            if record.hand.as_ref().is_some_and(|h| !matches!(h, dqhand::input::HandData::Glove(_))) {
                sizes.extend(dqhand::hand::measure(gesture_loop.pipeline().tracked_positions()));
            }
        }
        if let Some(out) = &mut out {
            let pipeline = gesture_loop.pipeline();
            let mut line = serde_json::to_value(PoseFile::from_pose(args.joint_model, pipeline.pose()))?;
            line["t"] = serde_json::json!(record.time);
            line["tracking"] = serde_json::json!(pipeline.tracking().as_str());
            serde_json::to_writer(&mut *out, &line)?;
            out.write_all(b"\n")?;
        }
    }
    events_out.flush()?;
    if let Some(out) = &mut out {
        out.flush()?;
    }
    let elapsed = start.elapsed().as_secs_f64();
    let pipeline = gesture_loop.pipeline();
    for line in pipeline.rejections().summary() {
        eprintln!("dqhand: {}: {line}", args.recording.input.display());
    }
    eprintln!("{}: {records} records, {} taken, {} rejected{}", args.recording.input.display(), pipeline.accepted(), pipeline.rejections().total(), if pipeline.tracking() == Tracking::Lost { ", tracking lost at the end" } else { "" });
    if args.stats {
        let median = Distribution::of(&mut times_us).map_or(0.0, |d| d.median);
        eprintln!("{:.0} records per second, {median:.1} µs per taken record (median: read, filter, retarget, FK, features, recogniser)", records as f64 / elapsed);
        let mut lengths: Vec<f32> = sizes.iter().map(|s| s.0).collect();
        let mut breadths: Vec<f32> = sizes.iter().map(|s| s.1).collect();
        if let (Some(l), Some(b)) = (quantile(&mut lengths, 0.5), quantile(&mut breadths, 0.5)) {
            eprintln!("user's hand: length {l:.3} m, breadth {b:.3} m (build it: dqhand hand --length {l:.3} --breadth {b:.3})");
        }
    }
    Ok(())
}
