//! `dqhand calibrate`: a glove calibration from a recording of the calibration poses (a flat
//! open hand, a fist and, for the abduction sensors, a spread hand, held in any order).

use std::path::PathBuf;

use dqhand::input::{Calibration, HandData, Record};

use crate::recording::{Format, InputArgs, RecordingReader};

/// Arguments of `dqhand calibrate`.
#[derive(clap::Args)]
pub struct Args {
    /// The glove recording (CSV, or JSON lines with `glove` values).
    #[arg(long)]
    input: PathBuf,
    /// The calibration to write (JSON).
    #[arg(long)]
    out: PathBuf,
    /// Its format (default by extension).
    #[arg(long)]
    format: Option<Format>,
    #[command(flatten)]
    common: InputArgs,
}

pub fn run(args: &Args) -> anyhow::Result<()> {
    let table = args.common.table()?;
    let mut reader = RecordingReader::open(&args.input, args.format, &args.common)?;
    let mut record = Record { time: 0.0, side: args.common.hand, hand: None, tracker: None, arrival: None };
    let (mut samples, mut rejected) = (Vec::new(), dqhand::input::Rejections::default());
    while let Some(read) = reader.next(&mut record)? {
        match (read, &record.hand) {
            (Ok(()), Some(HandData::Glove(sample))) => samples.push(*sample),
            (Ok(()), _) => {}
            (Err(r), _) => rejected.add(r),
        }
    }
    for line in rejected.summary() {
        eprintln!("dqhand: {}: {line}", args.input.display());
    }
    let calibration = Calibration::derive(&table, &samples).map_err(|e| e.in_file(&args.input))?;
    calibration.save(&args.out)?;
    println!("{}: calibration of {} sensors from {} samples of {}", args.out.display(), table.layout().len(), samples.len(), args.input.display());
    Ok(())
}
