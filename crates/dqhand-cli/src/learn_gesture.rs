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
use dqhand::gesture::{train, Example, GestureSet, HandFeatures, TrainingParams};
use dqhand::hand::HandParams;
use dqhand::input::Record;
use dqhand::interaction::gesture_examples::{shape_features, BUILTIN_CLASSES};
use dqhand::interaction::variation::Split;
use dqhand::interaction::GestureLoop;
use dqhand::kinematics::JointModel;
use dqhand::model::Model;

use crate::recording::{Format, InputArgs, RecordingReader};
use crate::train_gestures::varied_examples;

/// Seconds cut from each end of a recording of the gesture: the hand moving into and out of it.
const EDGE_S: f64 = 0.3;
/// Share of each recording held back to measure the result.
const CHECK_SHARE: f64 = 0.3;
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
    let (mut train_set, mut check_gesture, mut check_not) = (Vec::new(), Vec::new(), Vec::new());
    for path in &args.input {
        let (fit, check) = split(recorded(path, args, &model)?, EDGE_S, path)?;
        train_set.extend(fit.into_iter().map(|features| Example { features, class: 1 }));
        check_gesture.extend(check);
    }
    for path in &args.not {
        let (fit, check) = split(recorded(path, args, &model)?, 0.0, path)?;
        train_set.extend(fit.into_iter().map(|features| Example { features, class: 0 }));
        check_not.extend(check);
    }
    let config = args.common.config()?;
    let generated = |split: Split| varied_examples(&model, &config, split, &BUILTIN_CLASSES, GENERATED_SEQUENCES, 3);
    let tune = generated(Split::Tune)?;
    let gesture_examples = train_set.iter().filter(|e| e.class == 1).count();
    train_set.extend(tune.iter().map(|e| Example { features: e.features, class: 0 }));
    let classifier = train(vec!["other".into(), args.name.clone()], shape_features(), &train_set, &TrainingParams { hidden: 16, ..TrainingParams::default() })?;

    // Separability: how often the held-back frames are taken for the new gesture.
    let (start, _) = classifier.thresholds();
    let mut scratch = classifier.scratch();
    let mut taken = |features: &[HandFeatures]| -> f64 {
        let n = features.iter().filter(|f| classifier.classify(f, &mut scratch)[1] > start).count();
        if features.is_empty() { f64::NAN } else { n as f64 / features.len() as f64 }
    };
    let recall = taken(&check_gesture);
    let not_rate = taken(&check_not);
    let held_out = generated(Split::HeldOut)?;
    let mut by_class: BTreeMap<&str, Vec<HandFeatures>> = BTreeMap::new();
    for e in &held_out {
        by_class.entry(BUILTIN_CLASSES[e.class]).or_default().push(e.features);
    }
    let mut overlap: Vec<(f64, &str)> = by_class.iter().map(|(c, f)| (taken(f), *c)).collect();
    overlap.sort_by(|a, b| b.0.total_cmp(&a.0));
    set.insert_learned(&args.name, classifier)?;
    std::fs::write(&args.out, set.to_json() + "\n").map_err(|e| anyhow::anyhow!("{}: {e}", args.out.display()))?;

    println!(
        "learn-gesture: {:?} from {} frames of {} recording(s), {} of --not, {} generated frames of the built-in gestures and idle motion (tuning split)",
        args.name,
        gesture_examples,
        args.input.len(),
        train_set.len() - gesture_examples - tune.len(),
        tune.len()
    );
    println!("recognised on {:.1} % of the {} frames held back (the last {:.0} % of each recording)", recall * 100.0, check_gesture.len(), CHECK_SHARE * 100.0);
    if !check_not.is_empty() {
        println!("taken for it on {:.1} % of the {} --not frames held back", not_rate * 100.0, check_not.len());
    }
    let shown: Vec<String> = overlap.iter().take(4).map(|(r, c)| format!("{c} {:.1} %", r * 100.0)).collect();
    println!("taken for it on the built-in gestures' held-out frames (most first): {}", shown.join(", "));
    let separable = recall >= 0.9 && (not_rate.is_nan() || not_rate <= 0.05) && overlap.first().is_none_or(|(r, _)| *r <= 0.05);
    println!(
        "{}; written first in {} (it wins where a built-in gesture also matches)",
        if separable { "separable from the others" } else { "NOT well separable: record it longer, hold it steadier, or add what it is confused with to --not" },
        args.out.display()
    );
    Ok(())
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

/// Cuts `edge_s` from both ends, then splits by time: the first 70 % to train on, the rest
/// to check.
fn split(frames: Vec<(f64, HandFeatures)>, edge_s: f64, path: &Path) -> anyhow::Result<(Vec<HandFeatures>, Vec<HandFeatures>)> {
    let (Some(first), Some(last)) = (frames.first().map(|f| f.0), frames.last().map(|f| f.0)) else {
        anyhow::bail!("{}: no record was accepted", path.display());
    };
    let (from, to) = (first + edge_s, last - edge_s);
    anyhow::ensure!(to - from >= 1.0, "{}: {:.1} s of records; record at least {:.1} s", path.display(), last - first, 1.0 + 2.0 * edge_s);
    let cut = from + (to - from) * (1.0 - CHECK_SHARE);
    let inside = frames.into_iter().filter(|(t, _)| *t >= from && *t <= to);
    let (fit, check): (Vec<_>, Vec<_>) = inside.partition(|(t, _)| *t < cut);
    Ok((fit.into_iter().map(|f| f.1).collect(), check.into_iter().map(|f| f.1).collect()))
}
