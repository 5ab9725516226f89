//! `dqhand grasp-bench`: the manipulation loop against its stated targets on scripted
//! approach–grasp–lift–carry–release sequences (`dqhand::interaction::grasp_script`, made
//! from our own kinematics, so a run repeats): every object of the built-in `objects` scene,
//! alone on the table, approached from several directions at several speeds up to 10 m/s
//! (the marble by a pinch; the thin plate struck flat, for tunnelling only); and with two hands
//! (a left hand built as one) on the built-in `two-hands` scene: a 40 cm box carried between
//! two flat hands, and a bar handed from the right hand to the left. Each run is scored by
//! `dqhand::interaction::benchmark::score`, which the tests use too.

use std::sync::Arc;

use dqhand::collision::ObjectColliders;
use dqhand::engine::ModelSource;
use dqhand::grasp::GraspParams;
use dqhand::hand::{HandParams, Side};
use dqhand::input::InputConfig;
use dqhand::interaction::benchmark::{lag, score, Distribution, LagScore, RunScore};
use dqhand::interaction::grasp_script::{self, GraspTask, HeadsetTracking};
use dqhand::interaction::ManipulationLoop;
use dqhand::kinematics::JointModel;
use dqhand::model::Model;
use dqhand::scene::Scene;
use dqhand::skin::Crew;
use glam::Vec3;
use serde_json::{json, Value};

use crate::synthesize::TWO_HANDS_SCENE;

/// Share of scripted grasps to succeed.
const SUCCESS_TARGET: f64 = 0.98;
/// Deepest the rendered skin may go into an object, m.
const PENETRATION_TARGET_M: f32 = 0.001;
/// Farthest a carried object may slip in the hand over the carry, m.
const SLIP_TARGET_M: f32 = 0.003;
/// Longest median time of a frame's collision, grasp and physics against the teapot, µs.
const STEP_TARGET_US: f64 = 250.0;
/// Longest 99th-percentile frame of any run, per hand in it, µs: no hiccups.
const STEP_P99_TARGET_US: f64 = 1000.0;

/// Speeds a free hand is swept at for the lag, m/s.
const LAG_SPEEDS: [f32; 5] = [0.1, 0.25, 0.5, 1.0, 2.0];
/// Farthest the rendered wrist may trail the true one at 0.5 m/s, m.
const LAG_TARGET_M: f32 = 0.005;
/// Largest RMS tremble of the rendered wrist of a still hand, m.
const JITTER_TARGET_M: f32 = 0.0005;

/// Where each object is put, alone on the table, and how far it is carried (a 0.5 m carry
/// stays on the table).
const PLACE_XZ: [f32; 2] = [-0.25, -0.3];
const CARRY: Vec3 = Vec3::new(0.5, 0.0, 0.0);
const LIFT_M: f32 = 0.12;
/// How high above the table a dropped object is let go, m.
const DROP_M: f32 = 0.1;
/// The objects dropped, from above at 0.5 m/s.
const DROPPED: [&str; 4] = ["ball", "teapot", "cube", "mug"];
/// Farthest across a dropped or set-down object may come to rest from where it was let go, m.
const DRIFT_TARGET_M: f32 = 0.01;
/// How far off the object's middle the headset-tracked runs aim, m.
const AIM_OFF_M: f32 = 0.01;

/// A direction the (right) hand comes from: where the palm moves (and faces) and the fingers
/// point.
struct Approach {
    name: &'static str,
    palm: Vec3,
    fingers: Vec3,
}

/// From the side and the front the thumb is up, as a right hand takes a thing on a table: with
/// the thumb down it would be caught between the object and the table.
const APPROACHES: [Approach; 3] = [
    Approach { name: "above", palm: Vec3::NEG_Y, fingers: Vec3::NEG_Z },
    Approach { name: "side", palm: Vec3::NEG_X, fingers: Vec3::NEG_Z },
    Approach { name: "front", palm: Vec3::NEG_Z, fingers: Vec3::X },
];

/// How each object of the `objects` scene is taken.
#[derive(Clone, Copy, PartialEq)]
enum Kind {
    /// A whole-hand grasp from every approach.
    Grasp,
    /// A pinch of thumb and index from above.
    Pinch,
    /// Struck flat from above: tunnelling and penetration, not a grasp.
    Strike,
    /// Grasped from above, lifted, carried and let go by a still hand [`DROP_M`] above the
    /// table: where it lands.
    Drop,
    /// Carried between two flat hands pressed against it from either side.
    Between,
    /// Taken by the right hand, handed to the left, carried on and set down.
    HandOver,
}

impl Kind {
    fn name(self) -> &'static str {
        match self {
            Kind::Grasp => "grasp",
            Kind::Pinch => "pinch",
            Kind::Strike => "strike",
            Kind::Drop => "drop",
            Kind::Between => "between",
            Kind::HandOver => "handover",
        }
    }

    /// Hands the run drives.
    fn hands(self) -> usize {
        if matches!(self, Kind::Between | Kind::HandOver) { 2 } else { 1 }
    }
}

fn kind(object: &str) -> Kind {
    match object {
        "marble" => Kind::Pinch,
        "plate" => Kind::Strike,
        _ => Kind::Grasp,
    }
}

/// Arguments of `dqhand grasp-bench`.
#[derive(clap::Args)]
pub struct Args {
    /// Print one JSON object instead of tables.
    #[arg(long)]
    json: bool,
    /// Only these objects of the `objects` scene (comma-separated; default all).
    #[arg(long, value_delimiter = ',')]
    objects: Vec<String>,
    /// Approach speeds, m/s (comma-separated).
    #[arg(long, value_delimiter = ',', default_values_t = [0.5, 2.0, 10.0])]
    speeds: Vec<f32>,
    /// Only these approaches: above, side, front (comma-separated; default all).
    #[arg(long, value_delimiter = ',')]
    approaches: Vec<String>,
    /// Input configuration (filters, grace times) to measure instead of the default one.
    #[arg(long)]
    config: Option<std::path::PathBuf>,
    /// Threads each hand's fingers close on (the caller's and helpers; 1: the caller's alone).
    /// Default: the cores, at most five (one per finger).
    #[arg(long)]
    threads: Option<usize>,
}

/// One run: what was done and what it measured.
struct Run {
    object: String,
    kind: Kind,
    approach: &'static str,
    speed: f32,
    /// Tracked as a headset tracks, aiming off the middle.
    headset: bool,
    score: RunScore,
}

pub fn run(args: &Args) -> anyhow::Result<()> {
    for &s in &args.speeds {
        anyhow::ensure!(s.is_finite() && (0.05..=20.0).contains(&s), "--speeds {s}: an approach speed from 0.05 to 20 m/s");
    }
    for a in &args.approaches {
        anyhow::ensure!(APPROACHES.iter().any(|x| x.name == a), "--approaches {a}: not one of above, side, front");
    }
    let all = Scene::named("objects")?;
    for o in &args.objects {
        anyhow::ensure!(all.object(o).is_some(), "--objects {o}: the objects scene has no such object");
    }
    let model = Arc::new(ModelSource::Builtin(HandParams::default()).load()?);
    let config = args.config.as_deref().map(InputConfig::load).transpose()?.unwrap_or_default();
    let cores = std::thread::available_parallelism().map_or(1, std::num::NonZeroUsize::get);
    let threads = args.threads.unwrap_or(cores.min(5));
    anyhow::ensure!((1..=64).contains(&threads), "--threads {threads}: from 1 to 64");
    let crew = (threads > 1).then(|| Crew::new(threads, Crew::SPIN).map(Arc::new)).transpose()?;
    let bench = Bench { config, crew };
    let mut runs = Vec::new();
    for (index, object) in all.objects.iter().enumerate().filter(|(_, o)| args.objects.is_empty() || args.objects.contains(&o.name)) {
        let kind = kind(&object.name);
        let mut scene = Scene { table: all.table, objects: vec![object.clone()], actions: Vec::new() };
        scene.objects[0].position = Vec3::new(PLACE_XZ[0], object.position.y, PLACE_XZ[1]);
        let approaches = || APPROACHES.iter().filter(|a| (kind == Kind::Grasp || a.name == "above") && (args.approaches.is_empty() || args.approaches.iter().any(|n| n == a.name)));
        for approach in approaches() {
            for &speed in &args.speeds {
                let task = GraspTask { object: object.name.clone(), approach: approach.palm, fingers: approach.fingers, speed, lift: LIFT_M, carry: CARRY, pinch: kind == Kind::Pinch, drop: 0.0, aim: Vec3::ZERO };
                let score = measure(&model, &scene, &task, &bench, None)?;
                runs.push(Run { object: object.name.clone(), kind, approach: approach.name, speed, headset: false, score });
            }
        }
        // As a headset tracks a user who aims 1 cm off the middle (across the approach, a
        // seeded direction per run), at 0.5 m/s.
        for approach in approaches().filter(|_| kind != Kind::Strike) {
            // The same seed for the same object and approach, whatever else runs.
            let seed = 10 * index as u64 + APPROACHES.iter().position(|a| a.name == approach.name).unwrap_or(0) as u64;
            let aim = off_centre(approach.palm, seed) * AIM_OFF_M;
            let task = GraspTask { object: object.name.clone(), approach: approach.palm, fingers: approach.fingers, speed: 0.5, lift: LIFT_M, carry: CARRY, pinch: kind == Kind::Pinch, drop: 0.0, aim };
            let score = measure(&model, &scene, &task, &bench, Some(seed))?;
            runs.push(Run { object: object.name.clone(), kind, approach: approach.name, speed: 0.5, headset: true, score });
        }
        if DROPPED.contains(&object.name.as_str()) && (args.approaches.is_empty() || args.approaches.iter().any(|n| n == "above")) {
            let above = &APPROACHES[0];
            for headset in [false, true] {
                let task = GraspTask { object: object.name.clone(), approach: above.palm, fingers: above.fingers, speed: 0.5, lift: LIFT_M, carry: CARRY, pinch: false, drop: DROP_M, aim: Vec3::ZERO };
                let score = measure(&model, &scene, &task, &bench, headset.then_some(10 * index as u64 + 9))?;
                runs.push(Run { object: object.name.clone(), kind: Kind::Drop, approach: above.name, speed: 0.5, headset, score });
            }
        }
    }
    if args.objects.is_empty() && args.approaches.is_empty() {
        let left = Arc::new(ModelSource::Builtin(HandParams { side: Side::Left, ..HandParams::default() }).load()?);
        for kind in [Kind::Between, Kind::HandOver] {
            for headset in [false, true] {
                let (object, score) = measure_two([&left, &model], kind, &bench, headset.then_some(100 + kind.hands() as u64 * 10 + kind as u64))?;
                runs.push(Run { object, kind, approach: "both", speed: 0.5, headset, score });
            }
        }
    }
    let lags = LAG_SPEEDS.iter().enumerate().map(|(k, &speed)| measure_lag(&model, &all, speed, k as u64 + 1, &bench)).collect::<anyhow::Result<Vec<_>>>()?;
    let report = report(&runs, &lags, threads);
    if args.json {
        println!("{report}");
    } else {
        print_tables(&report);
    }
    Ok(())
}

/// A unit direction across `approach`, drawn from `seed`.
fn off_centre(approach: Vec3, seed: u64) -> Vec3 {
    let mut rng = dqhand::math::Rng::new(seed);
    let v = rng.unit();
    (v - approach * v.dot(approach)).normalize_or(approach.any_orthonormal_vector())
}

/// What every run is measured with.
struct Bench {
    config: InputConfig,
    /// The threads the fingers close on, beside the caller's.
    crew: Option<Arc<Crew>>,
}

impl Bench {
    /// `manip` measured as the bench measures.
    fn with_crew(&self, manip: ManipulationLoop) -> ManipulationLoop {
        match &self.crew {
            Some(crew) => manip.with_crew(Arc::clone(crew)),
            None => manip,
        }
    }
}

/// One run; with a seed, as a headset tracks it ([`HeadsetTracking::QUEST_LIKE`]).
fn measure(model: &Arc<Model>, scene: &Scene, task: &GraspTask, bench: &Bench, headset: Option<u64>) -> anyhow::Result<RunScore> {
    let objects = ObjectColliders::new(scene)?;
    let script = grasp_script::grasp(model.clone(), "objects", &objects, task, Side::Right)?;
    let script = match headset {
        Some(seed) => HeadsetTracking::QUEST_LIKE.track(&script, seed),
        None => script,
    };
    let mut manip = bench.with_crew(ManipulationLoop::new(model.clone(), JointModel::Full, None, bench.config.clone(), None, scene, GraspParams::default())?);
    // Where it comes to rest: carried there, and set down or dropped onto the table.
    Ok(score(&mut manip, &script, 0, scene.objects[0].position + task.carry))
}

/// A two-hand run of `kind` on the `two-hands` scene by `models` (left, right); with a seed,
/// as a headset tracks both hands. Returns the object's name and the score.
fn measure_two(models: [&Arc<Model>; 2], kind: Kind, bench: &Bench, headset: Option<u64>) -> anyhow::Result<(String, RunScore)> {
    let scene = Scene::named(TWO_HANDS_SCENE)?;
    let objects = ObjectColliders::new(&scene)?;
    let pair = [&**models[0], &**models[1]];
    let (object, script, carried) = match kind {
        Kind::Between => ("box", grasp_script::carry_between(pair, TWO_HANDS_SCENE, &objects, "box", LIFT_M, TWO_HAND_CARRY)?, TWO_HAND_CARRY),
        _ => ("baton", grasp_script::hand_over(pair, TWO_HANDS_SCENE, &objects, "baton", 0.08, LIFT_M, HAND_OVER_CARRY)?, 2.0 * HAND_OVER_CARRY),
    };
    let script = match headset {
        Some(seed) => HeadsetTracking::QUEST_LIKE.track(&script, seed),
        None => script,
    };
    let index = scene.objects.iter().position(|o| o.name == object).expect("the two-hands scene has both");
    let hands = models.map(|m| (Arc::clone(m), None));
    let mut manip = bench.with_crew(ManipulationLoop::two_handed(hands, JointModel::Full, bench.config.clone(), None, &scene, GraspParams::default())?);
    Ok((object.to_owned(), score(&mut manip, &script, index, scene.objects[index].position + carried)))
}

/// How far the box is carried between two hands, m.
const TWO_HAND_CARRY: Vec3 = Vec3::new(0.0, 0.0, 0.2);
/// How far each hand carries the bar in a hand-over (it stays on the table), m.
const HAND_OVER_CARRY: Vec3 = Vec3::new(0.0, 0.0, 0.12);

/// A free hand swept at `speed` 35 cm above the table, nothing near it.
fn measure_lag(model: &Arc<Model>, all: &Scene, speed: f32, seed: u64, bench: &Bench) -> anyhow::Result<LagScore> {
    let scene = Scene { table: all.table, objects: Vec::new(), actions: Vec::new() };
    let height = all.table.map_or(0.0, |t| t.height);
    let sweep = grasp_script::sweep(model, Vec3::new(-0.8, height + 0.35, 0.0), Vec3::X, speed, Side::Right, seed)?;
    let mut manip = bench.with_crew(ManipulationLoop::new(model.clone(), JointModel::Full, None, bench.config.clone(), None, &scene, GraspParams::default())?);
    Ok(lag(&mut manip, &sweep))
}

fn mm(m: f32) -> f64 {
    (f64::from(m) * 1000.0 * 100.0).round() / 100.0
}

fn us(d: Option<Distribution>) -> Value {
    d.map_or(Value::Null, |d| json!({"median": d.median * 1e6, "p95": d.p95 * 1e6, "p99": d.p99 * 1e6, "max": d.max * 1e6, "frames": d.count}))
}

fn report(runs: &[Run], lags: &[LagScore], threads: usize) -> Value {
    let grasps: Vec<&Run> = runs.iter().filter(|r| r.kind != Kind::Strike).collect();
    let drift = |kind: Kind| runs.iter().filter(|r| r.kind == kind && r.score.release_frames.is_some()).map(|r| r.score.release_drift_m).fold(0.0, f32::max);
    let successes = grasps.iter().filter(|r| r.score.success).count();
    let rate = if grasps.is_empty() { 0.0 } else { successes as f64 / grasps.len() as f64 };
    let max_penetration = runs.iter().map(|r| r.score.max_penetration_m).fold(0.0, f32::max);
    let mean_penetration = runs.iter().map(|r| r.score.mean_penetration_m).sum::<f32>() / runs.len().max(1) as f32;
    let slip = grasps.iter().map(|r| r.score.slip_m).fold(0.0, f32::max);
    let mut latency: Vec<f64> = grasps.iter().filter_map(|r| r.score.release_frames).map(f64::from).collect();
    let tunnelled = runs.iter().filter(|r| r.score.tunnelled).count();
    let mut all_steps: Vec<f64> = runs.iter().flat_map(|r| r.score.step_s.iter().copied()).collect();
    let mut teapot_steps: Vec<f64> = runs.iter().filter(|r| r.object == "teapot").flat_map(|r| r.score.step_s.iter().copied()).collect();
    let teapot = Distribution::of(&mut teapot_steps);
    // Each run's 99th-percentile frame, per hand it drives: the worst run's.
    let worst_p99 = runs.iter().filter_map(|r| Distribution::of(&mut r.score.step_s.clone()).map(|d| d.p99 / r.kind.hands() as f64)).fold(0.0, f64::max);
    let lines: Vec<Value> = runs
        .iter()
        .map(|r| {
            let steps = Distribution::of(&mut r.score.step_s.clone());
            json!({
                "object": r.object, "kind": r.kind.name(), "hands": r.kind.hands(),
                "approach": r.approach, "speed_m_s": r.speed, "headset": r.headset, "success": r.score.success, "place_error_mm": mm(r.score.place_error_m),
                "max_penetration_mm": mm(r.score.max_penetration_m), "mean_penetration_mm": mm(r.score.mean_penetration_m), "held_penetration_mm": mm(r.score.held_penetration_m),
                "slip_mm": mm(r.score.slip_m), "slip_deg": (f64::from(r.score.slip_deg) * 100.0).round() / 100.0, "carry_lag_mm": mm(r.score.carry_lag_m), "release_drift_mm": mm(r.score.release_drift_m), "release_frames": r.score.release_frames, "tunnelled": r.score.tunnelled, "finger_jumps": r.score.finger_jumps, "step_us": us(steps),
            })
        })
        .collect();
    json!({
        "synthetic": "scripted approach-grasp-lift-carry-release sequences from dqhand's own kinematics (dqhand::interaction::grasp_script); not captured from a person",
        "build": if cfg!(debug_assertions) { "debug" } else { "release" },
        "threads": threads,
        "grasps": grasps.len(), "successes": successes, "success_rate": rate,
        "headset_grasps": grasps.iter().filter(|r| r.headset).count(), "headset_successes": grasps.iter().filter(|r| r.headset && r.score.success).count(), "success_pass": !grasps.is_empty() && rate >= SUCCESS_TARGET,
        "max_penetration_mm": mm(max_penetration), "mean_penetration_mm": mm(mean_penetration), "penetration_pass": max_penetration <= PENETRATION_TARGET_M,
        "max_slip_mm": mm(slip), "slip_pass": !grasps.is_empty() && slip <= SLIP_TARGET_M,
        "max_carry_lag_mm": mm(grasps.iter().map(|r| r.score.carry_lag_m).fold(0.0, f32::max)),
        "max_drop_drift_mm": mm(drift(Kind::Drop)), "max_set_down_drift_mm": mm(drift(Kind::Grasp).max(drift(Kind::Pinch))),
        "drift_pass": drift(Kind::Drop) <= DRIFT_TARGET_M && runs.iter().any(|r| r.kind == Kind::Drop) && runs.iter().filter(|r| r.kind == Kind::Drop).all(|r| r.score.release_frames.is_some()),
        "release_frames": Distribution::of(&mut latency),
        "tunnelled": tunnelled, "tunnelling_pass": tunnelled == 0,
        "finger_jumps": runs.iter().map(|r| r.score.finger_jumps).sum::<u32>(), "runs_with_finger_jumps": runs.iter().filter(|r| r.score.finger_jumps > 0).count(),
        "step_us": us(Distribution::of(&mut all_steps)), "teapot_step_us": us(teapot), "teapot_step_pass": teapot.is_some_and(|d| d.median * 1e6 <= STEP_TARGET_US),
        "worst_step_p99_us_per_hand": worst_p99 * 1e6, "step_p99_pass": worst_p99 * 1e6 <= STEP_P99_TARGET_US,
        "two_hand_runs": runs.iter().filter(|r| r.kind.hands() == 2).count(), "two_hand_successes": runs.iter().filter(|r| r.kind.hands() == 2 && r.score.success).count(),
        "runs": lines,
        "lag": lags.iter().map(|l| json!({"speed_m_s": (f64::from(l.speed) * 1000.0).round() / 1000.0, "lag_mm": mm(l.lag_m), "lag_ms": (f64::from(l.lag_s) * 1e4).round() / 10.0, "jitter_mm": mm(l.jitter_m)})).collect::<Vec<_>>(),
        "lag_pass": lags.iter().filter(|l| l.speed == 0.5).all(|l| l.lag_m <= LAG_TARGET_M),
        "jitter_pass": lags.iter().all(|l| l.jitter_m <= JITTER_TARGET_M),
    })
}

fn pass(ok: &Value) -> &'static str {
    crate::gesture_bench::pass(ok.as_bool() == Some(true))
}

/// Prints the report as tables.
fn print_tables(r: &Value) {
    let f = |v: &Value| v.as_f64().unwrap_or(f64::NAN);
    println!("{}", r["synthetic"].as_str().unwrap_or_default());
    if r["build"] == "debug" {
        println!("debug build: the timings below are not meaningful; build with `cargo build --release -p dqhand-cli`");
    }
    println!("fingers closed on {} thread(s) a hand (--threads)", r["threads"]);
    println!();
    println!(
        "{:<8} {:<8} {:<6} {:>6} {:>8} {:>8} {:>10} {:>10} {:>8} {:>9} {:>8} {:>7} {:>9} {:>9} {:>10} {:>6} {:>10} {:>10}",
        "object", "kind", "from", "m/s", "tracking", "success", "place mm", "pen. mm", "mean mm", "held mm", "slip mm", "slip °", "drift mm", "release", "tunnelled", "jumps", "step µs", "p99 µs"
    );
    for run in r["runs"].as_array().into_iter().flatten() {
        println!(
            "{:<8} {:<8} {:<6} {:>6} {:>8} {:>8} {:>10.1} {:>10.2} {:>8.2} {:>9.2} {:>8.2} {:>7.2} {:>9.1} {:>9} {:>10} {:>6} {:>10.0} {:>10.0}",
            run["object"].as_str().unwrap_or_default(),
            run["kind"].as_str().unwrap_or_default(),
            run["approach"].as_str().unwrap_or_default(),
            f(&run["speed_m_s"]),
            if run["headset"] == true { "headset" } else { "exact" },
            if run["kind"] == "strike" { "-" } else if run["success"] == true { "yes" } else { "NO" },
            f(&run["place_error_mm"]),
            f(&run["max_penetration_mm"]),
            f(&run["mean_penetration_mm"]),
            f(&run["held_penetration_mm"]),
            f(&run["slip_mm"]),
            f(&run["slip_deg"]),
            f(&run["release_drift_mm"]),
            run["release_frames"].as_u64().map_or_else(|| "-".to_owned(), |x| x.to_string()),
            if run["tunnelled"] == true { "YES" } else { "no" },
            run["finger_jumps"].as_u64().unwrap_or_default(),
            f(&run["step_us"]["median"]),
            f(&run["step_us"]["p99"]),
        );
    }
    println!();
    println!("target                                   measured      verdict");
    println!(
        "grasp success ≥ 98 %                     {:>5.1} % ({}/{})  {}  (tracked like a headset, aiming 1 cm off: {}/{})",
        f(&r["success_rate"]) * 100.0,
        r["successes"],
        r["grasps"],
        pass(&r["success_pass"]),
        r["headset_successes"],
        r["headset_grasps"]
    );
    println!("rendered skin penetration ≤ 1 mm         {:>6.2} mm (mean {:.2})  {}", f(&r["max_penetration_mm"]), f(&r["mean_penetration_mm"]), pass(&r["penetration_pass"]));
    println!("slip over the 0.5 m carry ≤ 3 mm         {:>6.2} mm     {}", f(&r["max_slip_mm"]), pass(&r["slip_pass"]));
    println!("tunnelling, up to 10 m/s: none           {:>6} runs   {}", r["tunnelled"], pass(&r["tunnelling_pass"]));
    println!("rendered fingers jumping where the tracked ones did not (> 0.15 rad and 3× theirs in a frame): {} times in {} runs", r["finger_jumps"], r["runs_with_finger_jumps"]);
    println!("no hiccups: every run's p99 frame ≤ 1 ms a hand  {:>6.0} µs     {}", f(&r["worst_step_p99_us_per_hand"]), pass(&r["step_p99_pass"]));
    println!("(success also needs the rendered skin no deeper than 1 mm in the held object on every held frame; two hands: {}/{} runs)", r["two_hand_successes"], r["two_hand_runs"]);
    println!("(headset: 2 mm joint jitter, 1 % of records lost, 30 ms behind; every grasp from every approach at 0.5 m/s, and the drops)");
    println!(
        "collision + grasp + physics, teapot ≤ 250 µs (median)  {:.0} µs (p95 {:.0})  {}",
        f(&r["teapot_step_us"]["median"]),
        f(&r["teapot_step_us"]["p95"]),
        pass(&r["teapot_step_pass"])
    );
    let lag_at = |speed: f64| r["lag"].as_array().into_iter().flatten().find(|l| f(&l["speed_m_s"]) == speed).map_or(f64::NAN, |l| f(&l["lag_mm"]));
    let lags: Vec<String> = r["lag"].as_array().into_iter().flatten().map(|l| format!("{:.2} m/s {:.1} mm ({:.0} ms)", f(&l["speed_m_s"]), f(&l["lag_mm"]), f(&l["lag_ms"]))).collect();
    let jitter = r["lag"].as_array().into_iter().flatten().map(|l| f(&l["jitter_mm"])).fold(0.0, f64::max);
    println!("rendered wrist behind the true one at 0.5 m/s ≤ 5 mm  {:>5.1} mm     {}", lag_at(0.5), pass(&r["lag_pass"]));
    println!("held and carried (0.5 m/s on average, eased): the rendered wrist falls behind by at most {:.1} mm more than at the carry's start", f(&r["max_carry_lag_mm"]));
    println!("dropped by a still hand {} cm above the table, ≤ 1 cm across half way down  {:>5.1} mm     {}  (set down: {:.1} mm)", DROP_M * 100.0, f(&r["max_drop_drift_mm"]), pass(&r["drift_pass"]), f(&r["max_set_down_drift_mm"]));
    println!("still hand's jitter, RMS ≤ 0.5 mm        {:>6.2} mm     {}", jitter, pass(&r["jitter_pass"]));
    println!("lag of a free hand swept at constant speed (1.5 mm joint noise): {}", lags.join(", "));
    println!("release latency: median {} frames, max {} frames; all objects: {:.0} µs a frame (median)", r["release_frames"]["median"], r["release_frames"]["max"], f(&r["step_us"]["median"]));
}
