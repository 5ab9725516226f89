//! `dqhand bench`: the paper's Table 3 on this machine.
//!
//! The three methods are timed interleaved, frame by frame, in one run (the order rotating
//! each frame), so that machine noise hits them alike; the report is the median per frame
//! and the ratios of medians. Each frame the engine's kinematics stage poses the hand
//! untimed; what is timed is one variant's `Deformer::deform` on the engine's skinning
//! transforms, per-bone conversion included.
//!
//! On an AVX-512 CPU the kernel's lookup strategies are timed side by side, with the one
//! `Deformer::new` chose, against a straightforward AVX-512 DQB kernel
//! ([`PlainSoaKernel`]) and the frame's roofline ([`roofline`](crate::roofline)).

use std::time::Instant;

use std::sync::Arc;

use dqhand::engine::ModelSource;
use dqhand::gesture::Sequence;
use dqhand::kinematics::{HandKinematics, JointModel, KinematicsLayer, Pose, Transform};
use dqhand::model::Model;
use dqhand::skin::{Crew, Deformed, Deformer, Kernel, Method, SelfContactPass, SkinnedMesh, Strategy};
use glam::{Affine3A, Quat};
use serde_json::json;

use crate::plain_soa_kernel::PlainSoaKernel;
use crate::roofline::{Machine, Work};

/// Arguments of `dqhand bench`.
#[derive(clap::Args)]
pub struct Args {
    /// A .glb or .gltf file, or `builtin` for the built-in hand.
    #[arg(long, default_value = "builtin")]
    mesh: ModelSource,
    /// Frames timed per variant.
    #[arg(long, default_value_t = 2000)]
    frames: usize,
    /// Print one JSON object instead of tables.
    #[arg(long)]
    json: bool,
    /// Thread counts to time DQB with, besides one (default: every count up to this
    /// machine's cores).
    #[arg(long, value_delimiter = ',')]
    threads: Vec<usize>,
    /// Instead, measure the viewer stream end to end for this many seconds per run: split
    /// view over a loopback WebSocket, at 120 fps and as fast as it goes.
    #[arg(long, value_name = "SECONDS")]
    stream: Option<f64>,
}

/// One timed configuration: a method on a kernel (with a lookup strategy: `None` for the
/// one `Deformer::new` chose), on some threads, with or without normals; or the plain kernel.
struct Variant {
    method: Method,
    kernel: &'static str,
    strategy: Option<Strategy>,
    threads: usize,
    normals: bool,
    runner: Runner,
    samples: Vec<f64>,
}

/// What a variant runs.
enum Runner {
    Engine(Deformer, Deformed),
    /// The straightforward kernel and its positions and normals (#V each).
    Plain(Box<PlainSoaKernel>, Vec<[f32; 3]>, Vec<[f32; 3]>),
}

/// Frames per block of the back-to-back thread timing.
const BACK_TO_BACK: usize = 50;

/// The plain kernel's name in the report.
const PLAIN: &str = "avx512-plain";

impl Variant {
    /// Deforms one frame and returns the µs it took.
    fn time(&mut self, mesh: &SkinnedMesh, skinning: &[Affine3A]) -> f64 {
        let t = Instant::now();
        match &mut self.runner {
            Runner::Engine(deformer, out) => deformer.deform(mesh, skinning, out),
            Runner::Plain(kernel, positions, normals) => kernel.deform(skinning, positions, normals),
        }
        t.elapsed().as_secs_f64() * 1e6
    }

    fn positions(&self) -> &[[f32; 3]] {
        match &self.runner {
            Runner::Engine(_, out) => out.positions(),
            Runner::Plain(_, positions, _) => positions,
        }
    }
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
    let cores = std::thread::available_parallelism().map_or(1, usize::from);
    let threads: Vec<usize> = if args.threads.is_empty() { (2..=cores).collect() } else { args.threads.iter().copied().filter(|&t| t > 1).collect() };
    anyhow::ensure!(threads.iter().all(|&t| t <= 256), "--threads: at most 256");
    let forced = std::env::var(Strategy::ENV).ok();
    if let Some(name) = &forced {
        let names: Vec<&str> = Strategy::ALL.iter().map(|s| s.name()).collect();
        anyhow::ensure!(Strategy::named(name).is_some(), "{}={name:?} is not a strategy ({})", Strategy::ENV, names.join(", "));
    }
    let model = Arc::new(model);
    let mesh = &model.mesh;
    let best = Kernel::best();
    // CoR's precomputation, timed alone (the first CoR deformer below computes the mesh's
    // own, once).
    let centres_ms = {
        let start = std::time::Instant::now();
        std::hint::black_box(dqhand::skin::centres_of_rotation(mesh));
        start.elapsed().as_secs_f64() * 1e3
    };
    // The run-time choice, made before the timed variants' deformers are built (the first
    // deformer of each method measures; the rest reuse the choice).
    let chosen = Method::ALL.map(|m| Deformer::new(m, mesh).strategy());
    let strategies: Vec<Strategy> = if best == Kernel::Avx512 { Strategy::ALL.into_iter().filter(|s| s.serves(mesh.inverse_bind().len())).collect() } else { Vec::new() };
    let kernels: Vec<Kernel> = Kernel::ALL.into_iter().filter(|k| k.available()).collect();
    let mut variants = Vec::new();
    // One crew per thread count, shared by its variants, as an application would keep one.
    let crews: Vec<(usize, Arc<Crew>)> = threads.iter().map(|&t| Ok((t, Arc::new(Crew::new(t, Crew::SPIN)?)))).collect::<anyhow::Result<_>>()?;
    let mut add = |method, kernel: Kernel, strategy: Option<Strategy>, threads: usize, normals| {
        let mut deformer = Deformer::new(method, mesh).with_kernel(kernel);
        if let Some(s) = strategy {
            deformer = deformer.with_strategy(s);
        }
        if let Some((_, crew)) = crews.iter().find(|(t, _)| *t == threads) {
            deformer = deformer.with_crew(Arc::clone(crew));
        }
        let out = if normals { Deformed::new(mesh) } else { Deformed::positions_only(mesh) };
        variants.push(Variant { method, kernel: kernel.name(), strategy, threads, normals, runner: Runner::Engine(deformer, out), samples: Vec::with_capacity(args.frames) });
    };
    for &kernel in &kernels {
        for normals in [true, false] {
            for m in Method::ALL {
                add(m, kernel, None, 1, normals);
            }
        }
    }
    for &s in &strategies {
        for normals in [true, false] {
            for m in Method::ALL {
                add(m, Kernel::Avx512, Some(s), 1, normals);
            }
        }
    }
    for &t in &threads {
        for normals in [true, false] {
            add(Method::Dqb, best, None, t, normals);
        }
    }
    if let Some(plain) = PlainSoaKernel::new(mesh) {
        let n = mesh.vertex_count();
        let runner = Runner::Plain(Box::new(plain), vec![[0.0; 3]; n], vec![[0.0; 3]; n]);
        variants.push(Variant { method: Method::Dqb, kernel: PLAIN, strategy: None, threads: 1, normals: true, runner, samples: Vec::with_capacity(args.frames) });
    }
    let machine = Machine::measure();
    let mut animation = Animation::new(model.clone());
    // Warm-up: caches, branch predictors, CPU frequency, the crews' threads.
    for f in 0..100 {
        animation.pose(f);
        for v in &mut variants {
            v.time(mesh, animation.skinning());
        }
    }
    // Interleaved frame by frame, the order rotating: machine noise hits every variant alike.
    let n = variants.len();
    for f in 0..args.frames {
        animation.pose(f);
        for k in 0..n {
            let v = &mut variants[(f + k) % n];
            let us = v.time(mesh, animation.skinning());
            v.samples.push(us);
            std::hint::black_box(v.positions());
        }
    }
    // The thread variants again, each frame right after the last (a tight loop, where a
    // crew's helpers stay awake), in blocks that alternate between the variants; the
    // interleaved loop above came to each one ~n variants apart, after its helpers parked.
    let streamed: Vec<usize> = (0..n).filter(|&i| matches!(variants[i].runner, Runner::Engine(..)) && variants[i].method == Method::Dqb && variants[i].kernel == best.name() && variants[i].strategy.is_none()).collect();
    let mut back_to_back: Vec<Vec<f64>> = vec![Vec::with_capacity(args.frames); streamed.len()];
    for block in 0..args.frames.div_ceil(BACK_TO_BACK) {
        for (samples, &i) in back_to_back.iter_mut().zip(&streamed) {
            for f in block * BACK_TO_BACK..((block + 1) * BACK_TO_BACK).min(args.frames) {
                animation.pose(f);
                samples.push(variants[i].time(mesh, animation.skinning()));
            }
        }
    }
    let back_to_back: Vec<serde_json::Value> = streamed
        .iter()
        .zip(&mut back_to_back)
        .map(|(&i, samples)| json!({ "threads": variants[i].threads, "normals": variants[i].normals, "us_per_frame": percentile(samples, 0.5), "p90_us": percentile(samples, 0.9) }))
        .collect();
    // The contact pass after DQB (untimed), frame by frame over the same animation.
    let contact_pass = {
        let mut pass = SelfContactPass::new(mesh, &model.skeleton);
        let (mut deformer, mut out) = (Deformer::new(Method::Dqb, mesh), Deformed::new(mesh));
        let (mut samples, mut pushes) = (Vec::with_capacity(args.frames), Vec::with_capacity(args.frames));
        for f in 0..args.frames {
            animation.pose(f);
            deformer.deform(mesh, animation.skinning(), &mut out);
            let t = Instant::now();
            let report = pass.apply(animation.skinning(), &mut out);
            samples.push(t.elapsed().as_secs_f64() * 1e6);
            pushes.push(report.pushed as f64);
        }
        json!({ "us_per_frame": percentile(&mut samples, 0.5), "p90_us": percentile(&mut samples, 0.9), "max_us": percentile(&mut samples, 1.0), "pushes_median": percentile(&mut pushes, 0.5), "pushes_max": percentile(&mut pushes, 1.0) })
    };
    let rows: Vec<serde_json::Value> = variants
        .iter_mut()
        .map(|v| {
            let (med, p10, p90) = (percentile(&mut v.samples, 0.5), percentile(&mut v.samples, 0.1), percentile(&mut v.samples, 0.9));
            json!({ "method": v.method.as_str(), "kernel": v.kernel, "strategy": v.strategy.map(Strategy::name), "threads": v.threads, "normals": v.normals, "us_per_frame": med, "p10_us": p10, "p90_us": p90, "fps": 1e6 / med })
        })
        .collect();
    let find = |method: Method, kernel: &str, strategy: Option<Strategy>, threads: usize, normals: bool| {
        rows.iter().find(|r| r["method"] == method.as_str() && r["kernel"] == kernel && r["strategy"] == json!(strategy.map(Strategy::name)) && r["threads"] == threads && r["normals"] == normals)
    };
    let row = |method: Method, kernel: Kernel, threads: usize, normals: bool| find(method, kernel.name(), None, threads, normals).expect("a timed variant");
    let stat = |r: &serde_json::Value, key: &str| r[key].as_f64().expect("a number");
    let us = |method, kernel, threads, normals| stat(row(method, kernel, threads, normals), "us_per_frame");
    let by_strategy = |method, s, normals| stat(find(method, Kernel::Avx512.name(), Some(s), 1, normals).expect("a timed strategy"), "us_per_frame");
    let plain = find(Method::Dqb, PLAIN, None, 1, true).map(|r| stat(r, "us_per_frame"));
    let roofline: Vec<serde_json::Value> = Method::ALL
        .into_iter()
        .flat_map(|m| [true, false].map(|normals| (m, normals)))
        .map(|(m, normals)| {
            let work = Work::of(mesh, m, normals);
            let (bound, measured) = (work.bound_us(&machine), us(m, best, 1, normals));
            json!({ "method": m.as_str(), "normals": normals, "bytes_read": work.read, "bytes_written": work.written, "flops": work.flops, "bound_us": bound, "us_per_frame": measured, "over_bound": measured / bound })
        })
        .collect();
    let table3 = |m: Method| us(m, best, 1, true);
    let animation = animation.name;
    let report = json!({
        "mesh": args.mesh.to_string(),
        "vertices": mesh.vertex_count(),
        "triangles": mesh.triangle_count(),
        "bones": mesh.bone_count(),
        "joints": mesh.inverse_bind().len(),
        "influences_per_vertex": mesh.influences_per_vertex(),
        "frames": args.frames,
        "animation": animation,
        "cores": cores,
        "kernel": best.name(),
        "kernels": kernels.iter().map(|k| k.name()).collect::<Vec<_>>(),
        "cor_centres_ms": centres_ms,
        "methods": Method::ALL.iter().map(|&m| (m.as_str().to_owned(), json!({ "us_per_frame": table3(m), "fps": 1e6 / table3(m) }))).collect::<serde_json::Map<_, _>>(),
        "ratios": { "dqb_over_lb": table3(Method::Dqb) / table3(Method::Lb), "dqb_over_qb": table3(Method::Dqb) / table3(Method::Qb) },
        "strategies": strategies.iter().map(|s| s.name()).collect::<Vec<_>>(),
        "chosen_strategy": Method::ALL.iter().zip(&chosen).map(|(m, s)| (m.as_str().to_owned(), json!(s.map(Strategy::name)))).collect::<serde_json::Map<_, _>>(),
        "strategy_forced": forced,
        "plain_soa_dqb_us": plain,
        "machine": { "l2_read_bytes_per_s": machine.l2_read_bytes_per_s, "l2_write_bytes_per_s": machine.l2_write_bytes_per_s, "peak_flops": machine.peak_flops, "vector_bits": machine.vector_bits },
        "roofline": roofline,
        "variants": rows,
        "threads_back_to_back": back_to_back,
        "contact_pass": contact_pass,
        "crew_wake": crews.iter().map(|(t, c)| {
            let costs = c.wake_costs();
            json!({ "threads": t, "join_us": costs.map(|(j, _)| j.as_secs_f64() * 1e6), "wake_call_us": costs.map(|(_, w)| w.as_secs_f64() * 1e6) })
        }).collect::<Vec<_>>(),
    });
    if args.json {
        println!("{report}");
        return Ok(());
    }
    println!(
        "{}: {} vertices, {} bones, {} frames of {animation} per variant, {} variants interleaved, medians (µs per frame)",
        args.mesh,
        mesh.vertex_count(),
        mesh.bone_count(),
        args.frames,
        n
    );
    println!("\nthe paper's Table 3: one thread, {} kernel, positions and normals", best.name());
    println!("{:<6} {:>10} {:>10} {:>10} {:>12}", "method", "median", "p10", "p90", "frames/s");
    for m in Method::ALL {
        let r = row(m, best, 1, true);
        let (med, p10, p90) = (stat(r, "us_per_frame"), stat(r, "p10_us"), stat(r, "p90_us"));
        println!("{:<6} {med:>10.1} {p10:>10.1} {p90:>10.1} {:>12.0}", m.as_str().to_uppercase(), 1e6 / med);
    }
    println!("DQB/LB {:.3}   DQB/QB {:.3}   (paper: 1.056 and 1.024, rendering included)", table3(Method::Dqb) / table3(Method::Lb), table3(Method::Dqb) / table3(Method::Qb));
    println!("CoR/DQB {:.3}   (target ≤ 1.2); CoR's centres of rotation computed in {centres_ms:.0} ms on {cores} threads", table3(Method::Cor) / table3(Method::Dqb));
    println!(
        "contact pass after DQB (skin out of skin, one thread): {:.1} µs median, p90 {:.1}, max {:.1} (target ≤ 50); {:.0} vertices pushed per frame, median ({:.0} at most)",
        stat(&contact_pass, "us_per_frame"),
        stat(&contact_pass, "p90_us"),
        stat(&contact_pass, "max_us"),
        stat(&contact_pass, "pushes_median"),
        stat(&contact_pass, "pushes_max")
    );
    let heads = Method::ALL.map(|m| format!("{:>8}", m.as_str().to_uppercase())).join(" ");
    println!("\nkernels: one thread; positions and normals | positions only");
    println!("{:<9} {heads} | {heads}", "kernel");
    for &k in &kernels {
        let cell = |normals| Method::ALL.map(|m| format!("{:>8.1}", us(m, k, 1, normals))).join(" ");
        println!("{:<9} {} | {}", k.name(), cell(true), cell(false));
    }
    if !strategies.is_empty() {
        println!("\nAVX-512 lookup strategies: one thread; positions and normals | positions only");
        println!("{:<9} {heads} | {heads}", "strategy");
        for &s in &strategies {
            let cell = |normals| Method::ALL.map(|m| format!("{:>8.1}", by_strategy(m, s, normals))).join(" ");
            println!("{:<9} {} | {}", s.name(), cell(true), cell(false));
        }
        let how = forced.as_ref().map_or_else(|| "measured when each deformer was built".to_owned(), |name| format!("forced by {}={name}", Strategy::ENV));
        println!("run-time choice ({how}): {}", Method::ALL.iter().zip(&chosen).map(|(m, s)| format!("{} {}", m.as_str().to_uppercase(), s.map_or("none", Strategy::name))).collect::<Vec<_>>().join(", "));
    }
    if let Some(plain) = plain {
        let dqb = table3(Method::Dqb);
        println!("\nstraightforward SoA AVX-512 DQB kernel (gathers, no tuning), positions and normals: {plain:.1} µs; the engine's {dqb:.1} µs is {:.2}× it", dqb / plain);
    }
    println!(
        "\nroofline, one core, measured here: L2 read {:.0} GB/s, write {:.0} GB/s, peak {:.0} Gflop/s ({}-bit fused multiply-adds); {} kernel",
        machine.l2_read_bytes_per_s / 1e9,
        machine.l2_write_bytes_per_s / 1e9,
        machine.peak_flops / 1e9,
        machine.vector_bits,
        best.name()
    );
    println!("{:<6} {:<16} {:>9} {:>12} {:>9} {:>9} {:>8}", "method", "outputs", "KB/frame", "kflop/frame", "bound µs", "median", "× bound");
    for r in &roofline {
        let outputs = if r["normals"] == true { "positions+normals" } else { "positions" };
        println!(
            "{:<6} {outputs:<16} {:>9.0} {:>12.0} {:>9.2} {:>9.1} {:>8.2}",
            r["method"].as_str().unwrap_or_default().to_uppercase(),
            (stat(r, "bytes_read") + stat(r, "bytes_written")) / 1e3,
            stat(r, "flops") / 1e3,
            stat(r, "bound_us"),
            stat(r, "us_per_frame"),
            stat(r, "over_bound")
        );
    }
    let over_bound = stat(&roofline[Method::Dqb.index() * 2], "over_bound");
    let met = |ok: bool| if ok { "met" } else { "not met" };
    print!("\ntargets (issue 33): DQB with normals {over_bound:.2}× the roofline (≤ 2: {})", met(over_bound <= 2.0));
    if let Some(plain) = plain {
        let r = table3(Method::Dqb) / plain;
        print!(", {r:.2}× the straightforward kernel (≤ 0.75: {})", met(r <= 0.75));
    }
    println!(", LB/DQB {:.2} (≤ 1: {})", table3(Method::Lb) / table3(Method::Dqb), met(table3(Method::Lb) <= table3(Method::Dqb)));
    println!("\nthreads: DQB, {} kernel ({cores} cores here); interleaved as above (a crew's helpers park between frames), and back to back", best.name());
    println!("{:<8} {:>18} {:>8} {:>18} {:>8} | {:>18} {:>8} {:>18} {:>8}", "threads", "positions+normals", "speed-up", "positions only", "speed-up", "positions+normals", "speed-up", "positions only", "speed-up");
    let streamed_us = |t: usize, normals: bool| stat(back_to_back.iter().find(|r| r["threads"] == t && r["normals"] == normals).expect("a streamed variant"), "us_per_frame");
    for t in std::iter::once(1).chain(threads.iter().copied()) {
        let (a, b) = (us(Method::Dqb, best, t, true), us(Method::Dqb, best, t, false));
        let (c, d) = (streamed_us(t, true), streamed_us(t, false));
        print!("{t:<8} {a:>18.1} {:>8.2} {b:>18.1} {:>8.2}", us(Method::Dqb, best, 1, true) / a, us(Method::Dqb, best, 1, false) / b);
        println!(" | {c:>18.1} {:>8.2} {d:>18.1} {:>8.2}", streamed_us(1, true) / c, streamed_us(1, false) / d);
    }
    for (t, crew) in &crews {
        match crew.wake_costs() {
            Some((join, wake)) => println!("{t} threads: waking a parked helper took the caller {:.1} µs, and the helper ran {:.1} µs after it (medians): shorter jobs run without waking it", wake.as_secs_f64() * 1e6, join.as_secs_f64() * 1e6),
            None => println!("{t} threads: no parked helper was woken often enough to measure"),
        }
    }
    Ok(())
}

/// The poses to time, frame by frame: the bundled gesture sequence (the viewer's timeline)
/// sampled at 60 frames per second for a hand with WebXR joints, else every joint swinging
/// ±30° about its own X axis over 240 frames.
struct Animation {
    name: &'static str,
    motion: Motion,
}

/// What moves the hand from frame to frame.
enum Motion {
    /// The gesture sequence, the pose sampled from it, and the hand posing it.
    Sequence(Sequence, Pose, Box<HandKinematics>),
    /// Every joint's rest transform, the swung transforms written each frame, and the
    /// skeleton they pose.
    Swings { rest: Vec<Transform>, locals: Vec<Transform>, layer: Box<KinematicsLayer> },
}

impl Animation {
    fn new(model: Arc<Model>) -> Self {
        match model.hand_kinematics(JointModel::Full) {
            Ok(hand) => Self {
                name: "the gesture sequence",
                motion: Motion::Sequence(Sequence::gestures(JointModel::Full), Pose::rest(JointModel::Full.dof_count()), Box::new(hand)),
            },
            Err(_) => {
                let rest = model.skeleton.rest_locals();
                Self { name: "joint swings", motion: Motion::Swings { locals: rest.clone(), rest, layer: Box::new(model.kinematics()) } }
            }
        }
    }

    /// Poses frame `f` (the kinematics stage, untimed).
    fn pose(&mut self, f: usize) {
        match &mut self.motion {
            Motion::Sequence(sequence, pose, hand) => {
                let time = (f as f32 / 60.0) % sequence.duration();
                sequence.sample(time, hand.rig().rest_wrist(), pose);
                hand.pose(pose);
            }
            Motion::Swings { rest, locals, layer } => {
                let a = (f as f32 / 240.0 * std::f32::consts::TAU).sin() * 30f32.to_radians();
                for (l, r) in locals.iter_mut().zip(rest.iter()) {
                    l.rotation = r.rotation * Quat::from_rotation_x(a);
                }
                layer.pose_locals(locals);
            }
        }
    }

    /// The skinning transforms of the frame posed last.
    fn skinning(&self) -> &[glam::Affine3A] {
        match &self.motion {
            Motion::Sequence(_, _, hand) => hand.skinning(),
            Motion::Swings { layer, .. } => layer.skinning(),
        }
    }
}

fn percentile(s: &mut [f64], q: f64) -> f64 {
    dqhand::math::quantile(s, q).expect("frames were timed")
}
