//! Drive the hand from a recording and print the gestures it recognises:
//! `cargo run -p dqhand --example gestures_from_a_recording -- RECORDING.jsonl`.
//!
//! A recording is one JSON record per line (WebXR or OpenXR joints, MediaPipe landmarks, a
//! glove's sensors; docs/formats.md), as `dqhand demo --record` or the page's Record button
//! write it, or `dqhand synthesize` makes it. Each record goes through the gesture loop: the
//! input pipeline (checks, retargeting onto the virtual hand, filters), one forward
//! kinematics pass, the finger features and the recogniser. A bad line is reported and
//! skipped; the rest plays on.

use std::fs::File;
use std::io::BufReader;
use std::sync::Arc;

use dqhand::gesture::{EventKind, GestureSet};
use dqhand::hand::{build, HandParams};
use dqhand::input::json_record::JsonRecordReader;
use dqhand::input::{InputConfig, Record};
use dqhand::interaction::GestureLoop;
use dqhand::kinematics::{JointModel, Side};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let Some(path) = std::env::args().nth(1) else {
        return Err("give a recording (JSON lines), e.g. one `dqhand synthesize --out FILE` made".into());
    };
    let hand = Arc::new(build(&HandParams::default())?);
    let mut gestures = GestureLoop::new(hand, JointModel::Full, None, InputConfig::default(), Some(GestureSet::builtin()))?;
    let file = File::open(&path).map_err(|e| format!("{path}: {e}"))?;
    let mut reader = JsonRecordReader::new(BufReader::new(file), Side::Right, Vec::new());
    let mut record = Record { time: 0.0, side: Side::Right, hand: None, tracker: None, arrival: None };
    let (mut taken, mut refused) = (0, 0);
    while let Some(read) = reader.next_record(&mut record).map_err(|e| format!("{path}: {e}"))? {
        if let Err(rejection) = read {
            eprintln!("{path}: {rejection}");
            refused += 1;
            continue;
        }
        match gestures.push(&record) {
            Ok(events) => {
                taken += 1;
                for e in events {
                    let what = if e.event == EventKind::Start { "start" } else { "end  " };
                    println!("{:8.3} s  {what}  {}", e.t, e.gesture);
                }
            }
            Err(_) => refused += 1,
        }
    }
    println!("{taken} records taken, {refused} refused");
    Ok(())
}
