//! `dqhand train-gestures`: trains the built-in gesture classifier on the tuning split of the
//! varied sequences (`dqhand::interaction::variation`), joints and landmarks with their
//! tracking errors, as the gesture loop sees them; writes the gesture definitions with it.
//! `crates/dqhand/data/gestures.json` is this command's output (`make gestures`); the held-out
//! split it never sees is what `dqhand gesture-bench` reports on.

use std::path::PathBuf;
use std::sync::Arc;

use dqhand::engine::ModelSource;
use dqhand::gesture::{train, Example, GestureSet, TrainingParams};
use dqhand::hand::HandParams;
use dqhand::input::InputConfig;
use dqhand::interaction::gesture_examples::{examples, shape_features, BUILTIN_CLASSES};
use dqhand::interaction::synthetic::{generate, SyntheticFormat, SyntheticParams};
use dqhand::interaction::variation::Split;
use dqhand::interaction::GestureLoop;
use dqhand::kinematics::JointModel;
use dqhand::model::Model;
use rayon::prelude::*;

/// Arguments of `dqhand train-gestures`.
#[derive(clap::Args)]
pub struct Args {
    /// Where to write the definitions (the built-in file's gestures with the new classifier).
    #[arg(long)]
    out: PathBuf,
    /// Tuning sequences per source (joints, landmarks).
    #[arg(long, default_value_t = 64)]
    sequences: u64,
    /// Every n-th record of a sequence is an example.
    #[arg(long, default_value_t = 2)]
    every: usize,
    /// Passes over the examples.
    #[arg(long, default_value_t = 40)]
    epochs: usize,
    /// Hidden units.
    #[arg(long, default_value_t = 32)]
    hidden: usize,
}

pub fn run(args: &Args) -> anyhow::Result<()> {
    anyhow::ensure!(args.sequences > 0, "--sequences must be at least 1");
    let model = Arc::new(ModelSource::Builtin(HandParams::default()).load()?);
    let examples = varied_examples(&model, &InputConfig::default(), Split::Tune, &BUILTIN_CLASSES, args.sequences, args.every)?;
    let mut counts = vec![0usize; BUILTIN_CLASSES.len()];
    examples.iter().for_each(|e| counts[e.class] += 1);
    eprintln!("train-gestures: {} examples from {} tuning sequences per source ({})", examples.len(), args.sequences, BUILTIN_CLASSES.iter().zip(&counts).map(|(c, n)| format!("{c} {n}")).collect::<Vec<_>>().join(", "));
    let started = std::time::Instant::now();
    let classes = BUILTIN_CLASSES.map(str::to_owned).to_vec();
    let classifier = train(classes, shape_features(), &examples, &TrainingParams { epochs: args.epochs, hidden: args.hidden, ..TrainingParams::default() })?;
    eprintln!("train-gestures: trained in {:.1} s", started.elapsed().as_secs_f64());
    let mut set = GestureSet::builtin();
    set.set_classifier(classifier)?;
    std::fs::write(&args.out, set.to_json() + "\n").map_err(|e| anyhow::anyhow!("{}: {e}", args.out.display()))?;
    Ok(())
}

/// The examples of `split`'s sequences 1..=`sequences`, joints and landmarks, on the cores:
/// the features the gesture loop computes on `model` with `config` (no recognition).
pub fn varied_examples(model: &Arc<Model>, config: &InputConfig, split: Split, classes: &[&str], sequences: u64, every: usize) -> anyhow::Result<Vec<Example>> {
    let jobs: Vec<(u64, bool)> = (1..=sequences).flat_map(|k| [(k, false), (k, true)]).collect();
    let parts: anyhow::Result<Vec<Vec<Example>>> = jobs
        .par_iter()
        .map(|&(seed, landmarks)| {
            let format = if landmarks { SyntheticFormat::Landmarks } else { SyntheticFormat::Joints };
            let sequence = generate(&SyntheticParams::varied(split, seed, format))?;
            let mut hands = GestureLoop::new(model.clone(), JointModel::Full, None, config.clone(), None)?;
            Ok(examples(&mut hands, &sequence, classes, every))
        })
        .collect();
    Ok(parts?.concat())
}
