//! The `dqhand` command: inspect, pose, benchmark and demo skinned hands.
//!
//! `main` only turns the result of a subcommand into an exit code: 0 on success, 1 with a
//! one-line error on stderr otherwise (clap exits with 2 on bad usage).

mod bench;
mod bench_stream;
mod both_hands_score;
mod calibrate;
mod demo;
mod feed;
mod gesture_bench;
mod grasp;
mod grasp_bench;
mod hand;
mod info;
mod learn_gesture;
mod listen;
mod live;
mod live_learning;
mod loadtest;
mod metrics;
mod outside_poses;
mod peers;
mod plain_soa_kernel;
mod recording;
mod relay;
mod replay;
mod roofline;
mod server;
mod skin;
mod synthesize;
mod train_gestures;

use clap::{Parser, Subcommand};

/// Dual quaternion virtual hand: LB, QB, DQB and CoR skinning of the built-in hand or any
/// skinned glTF 2.0 file.
#[derive(Parser)]
#[command(name = "dqhand", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Print meshes, vertex and triangle counts, the skeleton tree and influences per vertex.
    Info(info::Args),
    /// Build the anatomical hand for given measurements and write it as a rigged glTF.
    Hand(hand::Args),
    /// Pose a mesh with LB, QB, DQB or CoR and write it with normals (.ply, .obj or .glb).
    Skin(skin::Args),
    /// Time LB, QB, DQB and CoR interleaved in one run (the paper's Table 3 on this machine, and CoR beyond it).
    Bench(bench::Args),
    /// The viewer server under load and abuse, measured: 1, 10 and 64 viewers, a malformed
    /// flood, slowloris, a slow reader.
    Loadtest(loadtest::Args),
    /// Write one posed frame of the built-in hand (rest mesh, weights, skinning matrices) with
    /// dqhand's LB and DQB output and timing, for other implementations to compare (make bench-peers).
    ExportSkinning(peers::Args),
    /// The live viewer: a local server for the browser page that poses the hand and compares
    /// LB, QB, DQB and CoR (with --out: write the gesture library as meshes instead).
    Demo(demo::Args),
    /// Realism metrics of LB, QB, DQB and CoR: volume, collapse and bulge, candy wrapper,
    /// distortion and continuity over joint sweeps.
    Metrics(metrics::Args),
    /// Play a recording (glove CSV, joints or landmarks JSON lines) through the gesture loop
    /// as fast as it goes; gesture events as JSON lines on stdout.
    Replay(replay::Args),
    /// Live input without the viewer: records on a UDP port drive the gesture loop; gesture
    /// events as JSON lines on stdout, optionally recorded to a file.
    Listen(listen::Args),
    /// Derive a glove calibration from a recording of the calibration poses.
    Calibrate(calibrate::Args),
    /// Write a synthetic, labelled recording of the gesture library (from our own kinematics).
    Synthesize(synthesize::Args),
    /// Measure the gesture loop on varied hands it was not trained on (and, with --outside, on
    /// poses others recorded): recognition rate and latency, precision, confusions, spurious
    /// starts, retargeting error, time per record.
    GestureBench(gesture_bench::Args),
    /// Train the built-in gesture classifier on the tuning split of varied hands (joints and
    /// landmarks) and write gesture definitions with it.
    TrainGestures(train_gestures::Args),
    /// Learn a new gesture from a few seconds of recording (and of poses that must not trigger
    /// it): add it to gesture definitions and report how separable it is.
    LearnGesture(learn_gesture::Args),
    /// Play a recording through the manipulation loop (contacts, grasps, physics) in a scene
    /// as fast as it goes; one JSON line per frame, and the rendered hand as PLY if asked.
    Grasp(grasp::Args),
    /// Score the manipulation loop on scripted grasps of every object (success, skin penetration,
    /// slip, release latency, tunnelling, time per frame) against their stated targets.
    GraspBench(grasp_bench::Args),
}

fn main() {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Info(a) => info::run(&a),
        Command::Hand(a) => hand::run(&a),
        Command::Skin(a) => skin::run(&a),
        Command::Bench(a) => bench::run(&a),
        Command::Loadtest(a) => loadtest::run(&a),
        Command::ExportSkinning(a) => peers::run(&a),
        Command::Demo(a) => demo::run(&a),
        Command::Metrics(a) => metrics::run(&a),
        Command::Replay(a) => replay::run(&a),
        Command::Grasp(a) => grasp::run(&a),
        Command::GraspBench(a) => grasp_bench::run(&a),
        Command::Listen(a) => listen::run(&a),
        Command::Calibrate(a) => calibrate::run(&a),
        Command::Synthesize(a) => synthesize::run(&a),
        Command::GestureBench(a) => gesture_bench::run(&a),
        Command::TrainGestures(a) => train_gestures::run(&a),
        Command::LearnGesture(a) => learn_gesture::run(&a),
    };
    if let Err(e) = result {
        eprintln!("dqhand: error: {e:#}");
        std::process::exit(1);
    }
}

/// Prints the warnings of a load or pose step, one line each.
pub(crate) fn warn_all(warnings: &[impl std::fmt::Display]) {
    for w in warnings {
        eprintln!("dqhand: warning: {w}");
    }
}

/// Warns of each angle the anatomical limits clamped, and how to keep it.
pub(crate) fn warn_clamped(origin: &str, clamped: &[dqhand::kinematics::ClampedAngle]) {
    for c in clamped {
        eprintln!("dqhand: warning: {origin}: {c} (use --no-limits to allow it)");
    }
}
