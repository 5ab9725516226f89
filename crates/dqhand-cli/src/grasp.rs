//! `dqhand grasp`: a recording through the manipulation loop as fast as it goes, one JSON
//! line per frame (a fixed rate on the records' clock), and with `--meshes` the rendered
//! hand (DQB, contact-constrained, world coordinates) every Nth frame as PLY.
//!
//! A trace line is [`frame_trace`]'s. With `--left-model` the loop has two hands (records drive
//! the hand of their side); the meshes are then `<frame>-left.ply` and `<frame>-right.ply`.

use std::io::Write;
use std::path::PathBuf;
use std::sync::Arc;

use anyhow::Context;
use dqhand::engine::ModelSource;
use dqhand::grasp::GraspParams;
use dqhand::gesture::GestureSet;
use dqhand::input::{GloveMapper, InputConfig, Record};
use dqhand::interaction::{frame_trace, ManipulationLoop};
use dqhand::kinematics::JointModel;
use dqhand::model::Model;
use dqhand::scene::Scene;
use dqhand::skin::{Method, MethodSet, SkinLayer};

use crate::recording::RecordingArgs;

/// Arguments of `dqhand grasp`.
#[derive(clap::Args)]
pub struct Args {
    /// The scene: a built-in one (`grasp`, `objects`) or a scene JSON file.
    #[arg(long)]
    scene: String,
    #[command(flatten)]
    recording: RecordingArgs,
    /// Write one JSON line per frame here.
    #[arg(long)]
    trace: PathBuf,
    /// Write the rendered hand every `--every` frames into this directory (`<frame>.ply`).
    #[arg(long)]
    meshes: Option<PathBuf>,
    /// Frames between meshes written.
    #[arg(long, default_value_t = 10, value_parser = clap::value_parser!(u64).range(1..))]
    every: u64,
    /// Frames per second of the loop, on the records' clock.
    #[arg(long, default_value_t = 60.0)]
    rate: f64,
    /// The hand: `builtin` or a skinned glTF with WebXR joint names.
    #[arg(long, default_value = "builtin")]
    model: ModelSource,
    /// A left hand beside `--model` (then a right one), for recordings of both hands:
    /// `builtin` (the built-in hand built as a left hand) or a skinned glTF of a left hand.
    #[arg(long)]
    left_model: Option<ModelSource>,
}

/// The loop of `model`'s hand in `scene`, or with a `left` model of two hands (`model` then the
/// right one), each driven through `mapper` from a glove.
///
/// # Errors
/// As [`ManipulationLoop::new`] and [`ManipulationLoop::two_handed`].
pub(crate) fn manipulation_loop(model: Arc<Model>, left: Option<Arc<Model>>, joint_model: JointModel, mapper: Option<GloveMapper>, config: InputConfig, gestures: Option<GestureSet>, scene: &Scene) -> dqhand::Result<ManipulationLoop> {
    match left {
        None => ManipulationLoop::new(model, joint_model, mapper, config, gestures, scene, GraspParams::default()),
        Some(left) => ManipulationLoop::two_handed([(left, mapper.clone()), (model, mapper)], joint_model, config, gestures, scene, GraspParams::default()),
    }
}

pub fn run(args: &Args) -> anyhow::Result<()> {
    anyhow::ensure!(args.rate.is_finite() && args.rate >= 1.0, "--rate {}: frames per second must be at least 1", args.rate);
    let scene = Scene::named(&args.scene)?;
    let model = Arc::new(args.model.load()?);
    let joint_model = JointModel::Full;
    let mapper = Some(args.recording.common.mapper(joint_model)?);
    let mut reader = args.recording.reader()?;
    let (config, gestures) = (args.recording.common.config()?, args.recording.recognition.set()?);
    let left = args.left_model.as_ref().map(|l| l.left().load().with_context(|| format!("--left-model {l}"))).transpose()?.map(Arc::new);
    let mut manip = manipulation_loop(model, left, joint_model, mapper, config, gestures, &scene)?;
    for w in manip.objects().warnings() {
        eprintln!("dqhand: warning: {}: {w}", args.scene);
    }
    let mut skins: Vec<SkinLayer> = manip.hands().iter().map(|h| SkinLayer::new(Arc::clone(&h.input().model().mesh), MethodSet::DQB)).collect();
    if let Some(dir) = &args.meshes {
        std::fs::create_dir_all(dir).with_context(|| dir.display().to_string())?;
    }
    let mut trace = std::io::BufWriter::new(std::fs::File::create(&args.trace).with_context(|| args.trace.display().to_string())?);
    let mut record = Record { time: 0.0, side: args.recording.common.hand, hand: None, tracker: None, arrival: None };
    let mut pending: Option<Record> = None;
    let (mut frame, mut refused) = (0u64, 0u64);
    let mut clock: Option<f64> = None;
    let period = 1.0 / args.rate;
    loop {
        // Every record up to this frame's time goes in before the frame.
        let next = match pending.take() {
            Some(r) => Some(r),
            None => match reader.next(&mut record).with_context(|| args.recording.input.display().to_string())? {
                None => None,
                Some(Err(rejection)) => {
                    refused += 1;
                    manip.reject(rejection);
                    continue;
                }
                Some(Ok(())) => Some(record),
            },
        };
        let now = *clock.get_or_insert_with(|| next.map_or(0.0, |r| r.time));
        match next {
            Some(r) if r.time <= now => {
                if manip.push(&r).is_err() {
                    refused += 1;
                }
                continue;
            }
            Some(r) => pending = Some(r),
            None => {}
        }
        manip.step(now);
        write_frame(&mut trace, now, &manip)?;
        if let Some(dir) = &args.meshes {
            if frame % args.every == 0 {
                for (hand, skin) in manip.hands().iter().zip(&mut skins) {
                    let name = if manip.hands().len() == 1 { format!("{frame}.ply") } else { format!("{frame}-{}.ply", hand.side().name()) };
                    skin.deform(hand.rendered().layer());
                    let mesh = skin.deformed(Method::Dqb).expect("DQB is the set");
                    dqhand::io::write_ply(&dir.join(name), mesh.positions(), mesh.normals(), skin.mesh().indices())?;
                }
            }
        }
        frame += 1;
        if pending.is_none() {
            break;
        }
        clock = Some(now + period);
    }
    trace.flush().with_context(|| args.trace.display().to_string())?;
    eprintln!("dqhand grasp: {frame} frames, {refused} records refused");
    Ok(())
}

fn write_frame(out: &mut impl Write, t: f64, manip: &ManipulationLoop) -> anyhow::Result<()> {
    serde_json::to_writer(&mut *out, &frame_trace(t, manip))?;
    out.write_all(b"\n")?;
    Ok(())
}
