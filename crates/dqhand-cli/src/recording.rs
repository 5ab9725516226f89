//! Recordings on disk, and the options every input command shares: which glove, which
//! calibration, which configuration and gesture definitions.

use std::fs::File;
use std::io::{BufReader, BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::Arc;

use anyhow::Context;
use dqhand::gesture::GestureSet;
use dqhand::hand::Side;
use dqhand::input::json_record::{write_record, JsonRecordReader};
use dqhand::input::{Calibration, GloveCsvReader, GloveCsvWriter, GloveMapper, InputConfig, MappingTable, Record, Rejection};
use dqhand::kinematics::JointModel;

/// The file formats of recordings.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Format {
    /// Glove CSV: `t`, the glove's sensor columns, optional tracker and hand columns.
    Glove,
    /// JSON lines with `joints` (WebXR or OpenXR names) or `landmarks`.
    Joints,
    /// JSON lines with MediaPipe `landmarks` (read like `joints`).
    Landmarks,
}

/// Input options shared by `replay`, `listen`, `calibrate` and `demo`.
#[derive(clap::Args, Clone, Debug)]
pub struct InputArgs {
    /// The glove's mapping table: `5dt-14`, `5dt-5`, `cyberglove-18` or a JSON file.
    #[arg(long, default_value = "5dt-14")]
    pub glove: String,
    /// The glove's calibration (JSON, from `dqhand calibrate`); default: raw 0 flat, 4095 fist.
    #[arg(long)]
    pub calib: Option<PathBuf>,
    /// Input configuration (filters, dropouts, tracker mount, gesture commands), JSON.
    #[arg(long)]
    pub config: Option<PathBuf>,
    /// The side of records that do not say.
    #[arg(long, default_value = "right", value_parser = parse_side)]
    pub hand: Side,
}

pub fn parse_side(s: &str) -> Result<Side, String> {
    match s {
        "left" => Ok(Side::Left),
        "right" => Ok(Side::Right),
        _ => Err(format!("{s:?} is neither left nor right")),
    }
}

/// A glove's mapping table: a built-in name (`5dt-14`, …) or a JSON file.
pub fn glove_table(name: &str) -> anyhow::Result<MappingTable> {
    Ok(if MappingTable::BUILTIN.contains(&name) { MappingTable::builtin(name)? } else { MappingTable::load(Path::new(name))? })
}

impl InputArgs {
    pub fn table(&self) -> anyhow::Result<MappingTable> {
        glove_table(&self.glove)
    }

    pub fn mapper(&self, joint_model: JointModel) -> anyhow::Result<GloveMapper> {
        let table = self.table()?;
        let calibration = match &self.calib {
            Some(path) => Calibration::load(path)?,
            None => Calibration::default_for(&table),
        };
        Ok(GloveMapper::new(&table, &calibration, joint_model)?)
    }

    /// The input configuration; its `actions` must be the viewer's.
    pub fn config(&self) -> anyhow::Result<InputConfig> {
        Ok(match &self.config {
            Some(path) => {
                let config = InputConfig::load(path)?;
                dqhand_stream::ViewerAction::resolve(&config.actions).with_context(|| path.display().to_string())?;
                config
            }
            None => InputConfig::default(),
        })
    }
}

/// Whether and what to recognise, for the commands where recognition is optional.
#[derive(clap::Args, Clone, Debug)]
pub struct GestureArgs {
    /// Recognise gestures and print their events.
    #[arg(long)]
    pub gestures: bool,
    /// Gesture definitions to use instead of the built-in ones (implies --gestures).
    #[arg(long)]
    pub gestures_file: Option<PathBuf>,
}

impl GestureArgs {
    /// The definitions to recognise, `None` with recognition off.
    pub fn set(&self) -> anyhow::Result<Option<GestureSet>> {
        gesture_set(self.gestures_file.as_deref(), self.gestures)
    }
}

/// The gesture definitions of `file`, else the built-in ones when recognition is `on`, else
/// none.
pub fn gesture_set(file: Option<&Path>, on: bool) -> anyhow::Result<Option<GestureSet>> {
    Ok(match (file, on) {
        (Some(path), _) => Some(GestureSet::load(path)?),
        (None, true) => Some(GestureSet::builtin()),
        (None, false) => None,
    })
}

/// A recording being read, record by record.
pub enum RecordingReader {
    Json(JsonRecordReader<BufReader<File>>),
    Glove(GloveCsvReader<BufReader<File>>),
    /// Records made in memory (the scripted grasps `demo --scene` plays), and the next one.
    Records(Arc<[Record]>, usize),
}

/// A recording to play and what to do with it: the options `replay` and `grasp` share.
#[derive(clap::Args)]
pub struct RecordingArgs {
    /// The recording (glove CSV, or joints/landmarks JSON lines).
    #[arg(long)]
    pub input: PathBuf,
    /// Its format (default: `.csv` is glove, anything else JSON lines).
    #[arg(long)]
    pub format: Option<Format>,
    #[command(flatten)]
    pub common: InputArgs,
    #[command(flatten)]
    pub recognition: GestureArgs,
}

impl RecordingArgs {
    /// The recording, opened.
    pub fn reader(&self) -> anyhow::Result<RecordingReader> {
        RecordingReader::open(&self.input, self.format, &self.common)
    }
}

impl RecordingReader {
    /// Opens `path` as `format`, or by its extension (`.csv` glove, else JSON lines).
    pub fn open(path: &Path, format: Option<Format>, args: &InputArgs) -> anyhow::Result<Self> {
        let file = File::open(path).with_context(|| path.display().to_string())?;
        let reader = BufReader::new(file);
        let format = format.unwrap_or(if path.extension().is_some_and(|e| e.eq_ignore_ascii_case("csv")) { Format::Glove } else { Format::Joints });
        Ok(match format {
            Format::Glove => Self::Glove(GloveCsvReader::new(reader, &args.table()?, args.hand).map_err(|e| e.in_file(path))?),
            Format::Joints | Format::Landmarks => {
                let sensors = args.table()?.layout().sensors().iter().map(|s| s.name.clone()).collect();
                Self::Json(JsonRecordReader::new(reader, args.hand, sensors))
            }
        })
    }

    /// The next record: `None` at the end, else the record or its rejection.
    pub fn next(&mut self, out: &mut Record) -> std::io::Result<Option<Result<(), Rejection>>> {
        match self {
            Self::Json(r) => r.next_record(out),
            Self::Glove(r) => Ok(r.next_record(out)),
            Self::Records(records, next) => Ok(records.get(*next).map(|r| {
                *out = *r;
                *next += 1;
                Ok(())
            })),
        }
    }
}

/// Writes `records` to `path`: a glove CSV with tracker and hand columns for the glove of
/// `table`, else JSON lines.
pub fn write_recording(path: &Path, records: &[Record], table: Option<&MappingTable>) -> anyhow::Result<()> {
    let write = || -> std::io::Result<()> {
        let mut out = BufWriter::new(File::create(path)?);
        match table {
            Some(table) => {
                let mut w = GloveCsvWriter::new(out, table, true, true)?;
                for r in records {
                    w.write(r)?;
                }
                Ok(())
            }
            None => {
                for r in records {
                    write_record(&mut out, r, &[] as &[&str])?;
                }
                out.flush()
            }
        }
    };
    write().with_context(|| path.display().to_string())
}
