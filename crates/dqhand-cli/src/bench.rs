//! `dqhand bench`: the paper's Table 3 on this machine.
//!
//! The three methods are timed interleaved, frame by frame, in one run (the order rotating
//! each frame), so that machine noise hits them alike; the report is the median per frame
//! and the ratios of medians. Each frame the engine's kinematics stage poses the hand
//! untimed; what is timed is its skin stage (`Engine::skin`), per-bone conversion included.

use std::time::Instant;

use std::sync::Arc;

use dqhand::engine::{Engine, ModelSource};
use dqhand::gesture::Sequence;
use dqhand::kinematics::{JointModel, Pose, Transform};
use dqhand::model::Model;
use dqhand::skin::Method;
use glam::Quat;
use serde_json::json;

/// Arguments of `dqhand bench`.
#[derive(clap::Args)]
pub struct Args {
    /// A .glb or .gltf file, or `builtin` for the built-in hand.
    #[arg(long, default_value = "builtin")]
    mesh: ModelSource,
    /// Frames timed per method.
    #[arg(long, default_value_t = 2000)]
    frames: usize,
    /// Print one JSON object instead of a table.
    #[arg(long)]
    json: bool,
    /// Time the portable kernel even where the AVX2 + FMA one would run.
    #[arg(long)]
    portable: bool,
    /// Instead, measure the viewer stream end to end for this many seconds per run: split
    /// view over a loopback WebSocket, at 120 fps and as fast as it goes.
    #[arg(long, value_name = "SECONDS")]
    stream: Option<f64>,
}

pub fn run(args: &Args) -> anyhow::Result<()> {
    anyhow::ensure!(args.frames > 0, "--frames must be at least 1");
    let model = args.mesh.load()?;
    if !args.json {
        crate::warn_all(&model.warnings);
    }
    if let Some(seconds) = args.stream {
        anyhow::ensure!(seconds > 0.0 && seconds <= 600.0, "--stream takes 0 to 600 seconds");
        return crate::bench_stream::run(model, seconds, args.json);
    }
    let model = Arc::new(model);
    let mut animation = Animation::new(model.clone());
    if args.portable {
        animation.engine.use_portable_kernel();
    }
    let mut samples = vec![Vec::with_capacity(args.frames); 3];
    // Warm-up: caches, branch predictors, CPU frequency.
    for f in 0..100 {
        animation.pose(f);
        for m in Method::ALL {
            animation.engine.skin(m);
        }
    }
    for f in 0..args.frames {
        animation.pose(f);
        for k in 0..3 {
            let m = Method::ALL[(f + k) % 3];
            let t = Instant::now();
            let out = animation.engine.skin(m);
            samples[m.index()].push(t.elapsed().as_secs_f64() * 1e6);
            std::hint::black_box(out.positions());
        }
    }
    let mesh = &model.mesh;
    let animation = animation.name;
    let stats: Vec<(f64, f64, f64)> = samples.iter_mut().map(|s| (percentile(s, 0.5), percentile(s, 0.1), percentile(s, 0.9))).collect();
    let median = |m: Method| stats[m.index()].0;
    let simd = if dqhand::skin::simd_available() && !args.portable { "avx2+fma" } else { "portable" };
    let methods: serde_json::Map<String, serde_json::Value> = Method::ALL
        .iter()
        .map(|&m| {
            let (med, p10, p90) = stats[m.index()];
            (m.as_str().to_owned(), json!({ "us_per_frame": med, "fps": 1e6 / med, "p10_us": p10, "p90_us": p90 }))
        })
        .collect();
    let report = json!({
        "mesh": args.mesh.to_string(),
        "vertices": mesh.vertex_count(),
        "triangles": mesh.triangle_count(),
        "bones": mesh.bone_count(),
        "joints": mesh.inverse_bind().len(),
        "influences_per_vertex": mesh.influences_per_vertex(),
        "frames": args.frames,
        "animation": animation,
        "threads": 1,
        "kernel": simd,
        "normals": true,
        "methods": methods,
        "ratios": {
            "dqb_over_lb": median(Method::Dqb) / median(Method::Lb),
            "dqb_over_qb": median(Method::Dqb) / median(Method::Qb),
        },
    });
    if args.json {
        println!("{report}");
    } else {
        println!(
            "{}: {} vertices, {} bones, {} frames of {animation}, one thread, {simd} kernel, positions and normals",
            args.mesh,
            mesh.vertex_count(),
            mesh.bone_count(),
            args.frames
        );
        println!("{:<6} {:>12} {:>12} {:>12} {:>14}", "method", "median µs", "p10 µs", "p90 µs", "frames/s");
        for m in Method::ALL {
            let (med, p10, p90) = stats[m.index()];
            println!("{:<6} {med:>12.1} {p10:>12.1} {p90:>12.1} {:>14.0}", m.as_str().to_uppercase(), 1e6 / med);
        }
        println!("DQB/LB {:.3}   DQB/QB {:.3}   (paper: 1.056 and 1.024, rendering included)", median(Method::Dqb) / median(Method::Lb), median(Method::Dqb) / median(Method::Qb));
    }
    Ok(())
}

/// The poses to time, frame by frame: the bundled gesture sequence (the viewer's timeline)
/// sampled at 60 frames per second for a hand with WebXR joints, else every joint swinging
/// ±30° about its own X axis over 240 frames.
struct Animation {
    engine: Engine,
    name: &'static str,
    motion: Motion,
}

/// What moves the hand from frame to frame.
enum Motion {
    /// The gesture sequence and the pose sampled from it.
    Sequence(Sequence, Pose),
    /// Every joint's rest transform, and the swung transforms written each frame.
    Swings { rest: Vec<Transform>, locals: Vec<Transform> },
}

impl Animation {
    fn new(model: Arc<Model>) -> Self {
        match Engine::with_joint_model(model.clone(), JointModel::Full) {
            Ok(engine) => Self {
                engine,
                name: "the gesture sequence",
                motion: Motion::Sequence(Sequence::gestures(JointModel::Full), Pose::rest(JointModel::Full.dof_count())),
            },
            Err(_) => {
                let rest = model.skeleton.rest_locals();
                Self { engine: Engine::new(model), name: "joint swings", motion: Motion::Swings { locals: rest.clone(), rest } }
            }
        }
    }

    /// Poses frame `f` (the kinematics stage, untimed).
    fn pose(&mut self, f: usize) {
        match &mut self.motion {
            Motion::Sequence(sequence, pose) => {
                let rest_wrist = self.engine.rig().expect("a joint model").rest_wrist();
                let time = (f as f32 / 60.0) % sequence.duration();
                sequence.sample(time, rest_wrist, pose);
                self.engine.pose(pose);
            }
            Motion::Swings { rest, locals } => {
                let a = (f as f32 / 240.0 * std::f32::consts::TAU).sin() * 30f32.to_radians();
                for (l, r) in locals.iter_mut().zip(rest.iter()) {
                    l.rotation = r.rotation * Quat::from_rotation_x(a);
                }
                self.engine.pose_locals(locals);
            }
        }
    }
}

fn percentile(s: &mut [f64], q: f64) -> f64 {
    dqhand::math::quantile(s, q).expect("frames were timed")
}
