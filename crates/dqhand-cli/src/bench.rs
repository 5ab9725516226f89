//! `dqhand bench`: the paper's Table 3 on this machine.
//!
//! The three methods are timed interleaved, frame by frame, in one run (the order rotating
//! each frame), so that machine noise hits them alike; the report is the median per frame
//! and the ratios of medians. The pose sequence (forward kinematics) is computed before
//! timing: what is timed is `Deformer::deform`, per-bone conversion included.

use std::time::Instant;

use dqhand::kinematics::{HandRig, JointModel, Limits};
use dqhand::model::{Model, PoseBuffers};
use dqhand::skin::{Deformed, Deformer, Method};
use glam::{Affine3A, Quat};
use serde_json::json;

/// Arguments of `dqhand bench`.
#[derive(clap::Args)]
pub struct Args {
    /// A .glb or .gltf file, or `builtin` for the built-in hand.
    #[arg(long, default_value = "builtin")]
    mesh: String,
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
    let model = dqhand::io::load_model(&args.mesh)?;
    if !args.json {
        crate::warn_all(&model.warnings);
    }
    if let Some(seconds) = args.stream {
        anyhow::ensure!(seconds > 0.0 && seconds <= 600.0, "--stream takes 0 to 600 seconds");
        return crate::bench_stream::run(model, seconds, args.json);
    }
    let (animation, poses) = animation(&model)?;
    let mesh = &model.mesh;
    let mut deformers: Vec<Deformer> = Method::ALL
        .iter()
        .map(|&m| Deformer::new(m, mesh))
        .map(|d| if args.portable { d.portable() } else { d })
        .collect();
    let mut out = Deformed::new(mesh);
    let mut samples = vec![Vec::with_capacity(args.frames); 3];
    // Warm-up: caches, branch predictors, CPU frequency.
    for f in 0..poses.len().min(100) {
        for d in &mut deformers {
            d.deform(mesh, &poses[f], &mut out);
        }
    }
    for f in 0..args.frames {
        let skinning = &poses[f % poses.len()];
        for k in 0..3 {
            let m = (f + k) % 3;
            let t = Instant::now();
            deformers[m].deform(mesh, skinning, &mut out);
            samples[m].push(t.elapsed().as_secs_f64() * 1e6);
            std::hint::black_box(out.positions());
        }
    }
    let stats: Vec<(f64, f64, f64)> = samples.iter_mut().map(|s| (percentile(s, 0.5), percentile(s, 0.1), percentile(s, 0.9))).collect();
    let median = |m: Method| stats[m as usize].0;
    let simd = if dqhand::skin::simd_available() && !args.portable { "avx2+fma" } else { "portable" };
    let methods: serde_json::Map<String, serde_json::Value> = Method::ALL
        .iter()
        .map(|&m| {
            let (med, p10, p90) = stats[m as usize];
            (m.as_str().to_owned(), json!({ "us_per_frame": med, "fps": 1e6 / med, "p10_us": p10, "p90_us": p90 }))
        })
        .collect();
    let report = json!({
        "mesh": args.mesh,
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
            let (med, p10, p90) = stats[m as usize];
            println!("{:<6} {med:>12.1} {p10:>12.1} {p90:>12.1} {:>14.0}", m.as_str().to_uppercase(), 1e6 / med);
        }
        println!("DQB/LB {:.3}   DQB/QB {:.3}   (paper: 1.056 and 1.024, rendering included)", median(Method::Dqb) / median(Method::Lb), median(Method::Dqb) / median(Method::Qb));
    }
    Ok(())
}

/// The poses to time: the gesture tour for a hand with WebXR joints, else every joint
/// swinging ±30° about its own X axis.
fn animation(model: &Model) -> anyhow::Result<(&'static str, Vec<Vec<Affine3A>>)> {
    let ib = model.mesh.inverse_bind();
    if let Ok(rig) = HandRig::new(&model.skeleton, JointModel::Full) {
        let mut buffers = PoseBuffers::new(rig.skeleton());
        let frames = dqhand::gesture::tour(JointModel::Full, 20)
            .iter()
            .map(|pose| {
                rig.locals(pose, Limits::Anatomical, &mut buffers.locals);
                buffers.evaluate(rig.skeleton(), ib).to_vec()
            })
            .collect();
        return Ok(("the gesture tour", frames));
    }
    let mut buffers = PoseBuffers::new(&model.skeleton);
    let rest = model.skeleton.rest_locals();
    let frames = (0..240)
        .map(|f| {
            let a = (f as f32 / 240.0 * std::f32::consts::TAU).sin() * 30f32.to_radians();
            for (l, r) in buffers.locals.iter_mut().zip(&rest) {
                l.rotation = r.rotation * Quat::from_rotation_x(a);
            }
            buffers.evaluate(&model.skeleton, ib).to_vec()
        })
        .collect();
    Ok(("joint swings", frames))
}

fn percentile(s: &mut [f64], q: f64) -> f64 {
    s.sort_by(f64::total_cmp);
    s[((s.len() - 1) as f64 * q).round() as usize]
}
