//! `dqhand learn-gesture`: a new gesture from a few seconds of recording. The recordings of
//! the gesture (`--input`) and of poses that must not trigger it (`--not`) go through the
//! gesture loop as `replay` plays them; their features, with those of every built-in gesture
//! and idle motion on varied generated hands (the tuning split), train a small classifier of
//! the new gesture against everything else, which is put first in the definitions written
//! (learned gestures are the specific ones). The report says how separable it is: measured on
//! the last 30 % of each recording, held back from training, and on the held-out split of
//! the generated gestures (which built-in gestures it would be taken for).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use dqhand::engine::ModelSource;
use dqhand::gesture::{train, Classifier, Example, GestureSet, HandFeatures, Recognizer, TrainingParams};
use dqhand::hand::HandParams;
use dqhand::input::{InputConfig, Record};
use dqhand::interaction::gesture_examples::{shape_features, BUILTIN_CLASSES};
use dqhand::interaction::variation::Split;
use dqhand::interaction::GestureLoop;
use dqhand::kinematics::JointModel;
use dqhand::model::Model;

use crate::recording::{Format, InputArgs, RecordingReader};
use crate::train_gestures::varied_examples;

/// Seconds cut from each end of a recording of the gesture: the hand moving into and out of it.
pub const EDGE_S: f64 = 0.3;
/// Share of each recording held back to measure the result.
const CHECK_SHARE: f64 = 0.3;
/// Above this share of its frames shown as a gesture of the set in use, a gesture learned
/// duplicates that one.
const ALREADY_SHOWN: f64 = 0.5;
/// Generated sequences per source (joints, landmarks) as the gesture's counter-examples.
const GENERATED_SEQUENCES: u64 = 12;

/// Arguments of `dqhand learn-gesture`.
#[derive(clap::Args)]
pub struct Args {
    /// The new gesture's name.
    #[arg(long)]
    name: String,
    /// Recordings of the gesture held (a few seconds each is enough; repeatable).
    #[arg(long, required = true)]
    input: Vec<PathBuf>,
    /// Recordings of poses that must not trigger it (repeatable).
    #[arg(long = "not")]
    not: Vec<PathBuf>,
    /// Their format (default: `.csv` is glove, anything else JSON lines).
    #[arg(long)]
    format: Option<Format>,
    #[command(flatten)]
    common: InputArgs,
    /// The definitions to add it to (default: the built-in ones).
    #[arg(long)]
    gestures: Option<PathBuf>,
    /// Where to write the definitions with the new gesture.
    #[arg(long)]
    out: PathBuf,
}

pub fn run(args: &Args) -> anyhow::Result<()> {
    anyhow::ensure!(!args.name.is_empty() && !args.name.contains(char::is_whitespace), "--name {:?}: give a name without spaces", args.name);
    let mut set = match &args.gestures {
        Some(path) => GestureSet::load(path)?,
        None => GestureSet::builtin(),
    };
    let model = Arc::new(ModelSource::Builtin(HandParams::default()).load()?);
    let (mut gesture, mut not) = (Frames::default(), Frames::default());
    for path in &args.input {
        gesture.add(recorded(path, args, &model)?, EDGE_S, &set).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
    }
    for path in &args.not {
        not.add(recorded(path, args, &model)?, 0.0, &set).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
    }
    let generated = Generated::new(&model, &args.common.config()?)?;
    let (classifier, report) = learn(&args.name, &gesture, &not, &generated)?;
    set.insert_learned(&args.name, classifier)?;
    std::fs::write(&args.out, set.to_json() + "\n").map_err(|e| anyhow::anyhow!("{}: {e}", args.out.display()))?;
    println!("learn-gesture: {:?} from {} recording(s); {report}", args.name, args.input.len());
    println!("{}; written first in {} (it wins where a built-in gesture also matches)", report.verdict(), args.out.display());
    Ok(())
}

/// Frames of the hand to learn from: the first 70 % of each recording to train on, the rest
/// held back to check; and what the gestures recognised now show over them.
#[derive(Default)]
pub struct Frames {
    fit: Vec<HandFeatures>,
    check: Vec<HandFeatures>,
    /// Frames each gesture of the set in use was shown on (a gesture learned again is
    /// already there; so is a shape a built-in gesture covers).
    shown: BTreeMap<String, usize>,
}

impl Frames {
    /// Frames kept, to train on and to check.
    pub fn count(&self) -> usize {
        self.fit.len() + self.check.len()
    }

    /// Adds one recording's frames (times and features): `edge_s` cut from both ends (the
    /// hand moving into and out of the gesture), then split by time; `set` recognises them
    /// as the live input would.
    ///
    /// # Errors
    /// Less than a second left after the cut.
    pub fn add(&mut self, frames: Vec<(f64, HandFeatures)>, edge_s: f64, set: &GestureSet) -> anyhow::Result<()> {
        let (Some(first), Some(last)) = (frames.first().map(|f| f.0), frames.last().map(|f| f.0)) else {
            anyhow::bail!("no record was accepted");
        };
        let (from, to) = (first + edge_s, last - edge_s);
        anyhow::ensure!(to - from >= 1.0, "{:.1} s of records; record at least {:.1} s", last - first, 1.0 + 2.0 * edge_s);
        let cut = from + (to - from) * (1.0 - CHECK_SHARE);
        let mut recognizer = Recognizer::new(set.clone());
        for &(t, f) in &frames {
            recognizer.update(t, &f);
            if let Some(g) = recognizer.current().filter(|_| t >= from && t <= to) {
                *self.shown.entry(g.to_owned()).or_default() += 1;
            }
        }
        for (t, f) in frames.into_iter().filter(|(t, _)| *t >= from && *t <= to) {
            if t < cut { &mut self.fit } else { &mut self.check }.push(f);
        }
        Ok(())
    }
}

/// The generated counter-examples: the built-in gestures and idle motion on varied hands,
/// the tuning split to train on and the held-out split to report overlaps. The same for
/// every gesture learned: a server makes them once.
pub struct Generated {
    tune: Vec<Example>,
    held_out: BTreeMap<&'static str, Vec<HandFeatures>>,
}

impl Generated {
    /// Generates them for `model` seen through `config`, on the cores.
    ///
    /// # Errors
    /// As [`varied_examples`].
    pub fn new(model: &Arc<Model>, config: &InputConfig) -> anyhow::Result<Self> {
        let generated = |split: Split| varied_examples(model, config, split, &BUILTIN_CLASSES, GENERATED_SEQUENCES, 3);
        let tune = generated(Split::Tune)?;
        let mut held_out: BTreeMap<&str, Vec<HandFeatures>> = BTreeMap::new();
        for e in generated(Split::HeldOut)? {
            held_out.entry(BUILTIN_CLASSES[e.class]).or_default().push(e.features);
        }
        Ok(Self { tune, held_out })
    }
}

/// What learning a gesture measured: how separable it is.
pub struct Report {
    /// Frames trained on: of the gesture, of `--not`, generated.
    trained: (usize, usize, usize),
    /// Share of the gesture's held-back frames taken for it, and their count.
    recall: (f64, usize),
    /// Share of the held-back `--not` frames taken for it, and their count.
    not_rate: (f64, usize),
    /// Share of each built-in gesture's held-out frames taken for it, most first.
    overlap: Vec<(f64, &'static str)>,
    /// The gesture the set in use shows most on its frames, and on what share of them.
    already: Option<(f64, String)>,
}

impl Report {
    /// Whether it stands apart: ≥ 90 % of its own frames, ≤ 5 % of any other's, and not a
    /// gesture the set in use already shows on most of its frames.
    pub fn separable(&self) -> bool {
        self.recall.0 >= 0.9
            && (self.not_rate.1 == 0 || self.not_rate.0 <= 0.05)
            && self.overlap.first().is_none_or(|(r, _)| *r <= 0.05)
            && self.already.as_ref().is_none_or(|(r, _)| *r <= ALREADY_SHOWN)
    }

    /// What to do about it, or that it stands apart.
    pub fn verdict(&self) -> String {
        match &self.already {
            Some((r, g)) if *r > ALREADY_SHOWN => format!("NOT well separable: the gestures recognised now show it as {g} ({:.0} % of its frames); learned first, it will be shown instead of {g}", r * 100.0),
            _ if self.separable() => "separable from the others".into(),
            _ => "NOT well separable: record it longer, hold it steadier, or record what it is confused with as what it is not".into(),
        }
    }

    /// The report as a viewer's `learning` message shows it.
    pub fn json(&self) -> serde_json::Value {
        serde_json::json!({
            "frames": self.trained.0,
            "not_frames": self.trained.1,
            "recall": self.recall.0,
            "checked": self.recall.1,
            "not_rate": (self.not_rate.1 > 0).then_some(self.not_rate.0),
            "overlap": self.overlap.iter().take(4).map(|(r, c)| serde_json::json!({ "gesture": c, "rate": r })).collect::<Vec<_>>(),
            "already": self.already.as_ref().map(|(r, g)| serde_json::json!({ "gesture": g, "rate": r })),
            "verdict": self.verdict(),
            "separable": self.separable(),
        })
    }
}

impl std::fmt::Display for Report {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let (gesture, not, generated) = self.trained;
        writeln!(f, "{gesture} frames of the gesture, {not} of --not, {generated} generated frames of the built-in gestures and idle motion (tuning split)")?;
        writeln!(f, "recognised on {:.1} % of the {} frames held back (the last {:.0} % of each recording)", self.recall.0 * 100.0, self.recall.1, CHECK_SHARE * 100.0)?;
        if self.not_rate.1 > 0 {
            writeln!(f, "taken for it on {:.1} % of the {} --not frames held back", self.not_rate.0 * 100.0, self.not_rate.1)?;
        }
        let shown: Vec<String> = self.overlap.iter().take(4).map(|(r, c)| format!("{c} {:.1} %", r * 100.0)).collect();
        writeln!(f, "taken for it on the built-in gestures' held-out frames (most first): {}", shown.join(", "))?;
        match &self.already {
            Some((r, g)) => write!(f, "the gestures recognised now show {g} on {:.1} % of its frames", r * 100.0),
            None => write!(f, "the gestures recognised now show none of theirs on its frames"),
        }
    }
}

/// Trains `name` against everything else (the `not` frames and the generated ones) and
/// measures it on the frames held back.
///
/// # Errors
/// As [`train`]: no frame of the gesture.
pub fn learn(name: &str, gesture: &Frames, not: &Frames, generated: &Generated) -> anyhow::Result<(Classifier, Report)> {
    let example = |class| move |f: &HandFeatures| Example { features: *f, class };
    let mut examples: Vec<Example> = gesture.fit.iter().map(example(1)).chain(not.fit.iter().map(example(0))).collect();
    examples.extend(generated.tune.iter().map(|e| Example { features: e.features, class: 0 }));
    let classifier = train(vec!["other".into(), name.to_owned()], shape_features(), &examples, &TrainingParams { hidden: 16, ..TrainingParams::default() })?;
    let (start, _) = classifier.thresholds();
    let mut scratch = classifier.scratch();
    let mut taken = |features: &[HandFeatures]| -> (f64, usize) {
        let n = features.iter().filter(|f| classifier.classify(f, &mut scratch)[1] > start).count();
        (if features.is_empty() { f64::NAN } else { n as f64 / features.len() as f64 }, features.len())
    };
    let (recall, not_rate) = (taken(&gesture.check), taken(&not.check));
    let mut overlap: Vec<(f64, &str)> = generated.held_out.iter().map(|(c, f)| (taken(f).0, *c)).collect();
    overlap.sort_by(|a, b| b.0.total_cmp(&a.0));
    let frames = (gesture.fit.len() + gesture.check.len()).max(1) as f64;
    // The gesture it replaces (learned again under its name) is not a duplicate of it.
    let already = gesture.shown.iter().filter(|(g, _)| *g != name).max_by_key(|(_, n)| **n).map(|(g, n)| (*n as f64 / frames, g.clone()));
    let report = Report { trained: (gesture.fit.len(), not.fit.len(), generated.tune.len()), recall, not_rate, overlap, already };
    Ok((classifier, report))
}

/// The features of every accepted record of `path`, with their times.
fn recorded(path: &Path, args: &Args, model: &Arc<Model>) -> anyhow::Result<Vec<(f64, HandFeatures)>> {
    let mut reader = RecordingReader::open(path, args.format, &args.common)?;
    let mapper = args.common.mapper(JointModel::Full)?;
    let mut hands = GestureLoop::new(model.clone(), JointModel::Full, Some(mapper), args.common.config()?, None)?;
    let mut record = Record { time: 0.0, side: args.common.hand, hand: None, tracker: None, arrival: None };
    let mut out = Vec::new();
    while let Some(read) = reader.next(&mut record).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))? {
        if read.is_ok() && hands.push(&record).is_ok() {
            out.push((record.time, hands.features()));
        }
    }
    Ok(out)
}
