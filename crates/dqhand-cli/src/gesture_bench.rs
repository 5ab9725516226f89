//! `dqhand gesture-bench`: the gesture loop against its stated targets, on labelled
//! synthetic sequences (`dqhand::interaction::synthetic`, seeded, so a run repeats):
//! recognition within 150 ms of each pose being reached and the latency, spurious events per
//! minute of idle motion, the retargeting error against the true angles, and the speed of the
//! per-record path. Each sequence is written as a recording and replayed as `dqhand replay
//! --gestures` replays one (same reader, same loop), so records per second are replay's. The
//! measures are `dqhand::interaction::benchmark`'s, which the tests use too.

use std::collections::BTreeMap;
use std::path::Path;
use std::sync::Arc;
use std::time::Instant;

use dqhand::engine::ModelSource;
use dqhand::gesture::GestureSet;
use dqhand::hand::{HandParams, Side};
use dqhand::input::{MappingTable, Record, CONTACT_FADE};
use dqhand::interaction::benchmark::{Distribution, LoggedEvent, RecognitionScore, RetargetScore, CLOSED_GAPS_M, CONTACT_GAP_M, RECOGNITION_DEADLINE_S};
use dqhand::interaction::synthetic::{generate, Synthetic, SyntheticParams};
use dqhand::interaction::GestureLoop;
use dqhand::kinematics::JointModel;
use dqhand::model::Model;
use serde_json::{json, Value};

use crate::recording::{write_recording, Format, InputArgs, RecordingReader};
use crate::synthesize::synthetic_format;

/// Share of labelled holds to recognise within [`RECOGNITION_DEADLINE_S`].
const RECOGNITION_TARGET: f64 = 0.98;
/// Most events per minute of idle motion.
const SPURIOUS_TARGET_PER_MIN: f64 = 1.0;
/// Largest mean joint angle error on noise-free joints of our own hand, degrees.
const ANGLE_TARGET_DEG: f64 = 1.0;
/// Largest median time of the per-record path (`GestureLoop::push`), µs.
const PUSH_TARGET_US: f64 = 50.0;
/// Fewest records per second replayed.
const REPLAY_TARGET_PER_S: f64 = 20_000.0;
/// Seconds of idle motion per sequence: the generator's 10 s give too few minutes of it for
/// a rate per minute.
const IDLE_S: f64 = 30.0;

/// A source measured: its name, recording format and glove table.
struct Source {
    name: &'static str,
    format: Format,
    glove: Option<&'static str>,
}

const SOURCES: [Source; 4] = [
    Source { name: "joints", format: Format::Joints, glove: None },
    Source { name: "landmarks", format: Format::Landmarks, glove: None },
    Source { name: "glove 5dt-14", format: Format::Glove, glove: Some("5dt-14") },
    Source { name: "glove cyberglove-18", format: Format::Glove, glove: Some("cyberglove-18") },
];

/// Arguments of `dqhand gesture-bench`.
#[derive(clap::Args)]
pub struct Args {
    /// Print one JSON object instead of tables.
    #[arg(long)]
    json: bool,
    /// Seed of the first sequence; sequence k of every source has seed + k (the same user,
    /// gestures and wrist turns across sources).
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Sequences per source, each a random user's hand (size, side) and gesture order.
    #[arg(long, default_value_t = 8)]
    sequences: usize,
}

pub fn run(args: &Args) -> anyhow::Result<()> {
    anyhow::ensure!(args.sequences > 0, "--sequences must be at least 1");
    let model = Arc::new(ModelSource::Builtin(HandParams::default()).load()?);
    let dir = std::env::temp_dir().join(format!("dqhand-gesture-bench-{}", std::process::id()));
    std::fs::create_dir_all(&dir)?;
    let sources: anyhow::Result<Vec<SourceRun>> = SOURCES.iter().map(|s| SourceRun::measure(s, args, &model, &dir)).collect();
    let _ = std::fs::remove_dir_all(&dir);
    let sources = sources?;
    let retarget = RetargetRun::measure(args, &model)?;
    let report = report(args, &sources, &retarget);
    if args.json {
        println!("{report}");
    } else {
        print_tables(&report);
    }
    Ok(())
}

/// The sequences of one source, replayed and scored.
struct SourceRun {
    source: &'static Source,
    /// Sensor-driven DOFs of the `full` model the glove moves neither directly nor by
    /// coupling (empty for hand tracking).
    undriven: Vec<String>,
    scores: Vec<RecognitionScore>,
    push_us: Vec<f64>,
    records: usize,
    loop_s: f64,
}

impl SourceRun {
    fn measure(source: &'static Source, args: &Args, model: &Arc<Model>, dir: &Path) -> anyhow::Result<Self> {
        let input = InputArgs { glove: source.glove.unwrap_or("5dt-14").into(), calib: None, config: None, hand: Side::Right };
        let table = source.glove.map(MappingTable::builtin).transpose()?;
        let undriven = table.as_ref().map_or_else(Vec::new, |t| {
            let driven = |dof: &str| t.entries().iter().any(|e| e.dof == dof) || t.couplings().iter().any(|c| c.dof == dof);
            JointModel::Full.dofs().map(|d| d.name()).filter(|d| !driven(d)).collect()
        });
        let mut run = Self { source, undriven, scores: Vec::new(), push_us: Vec::new(), records: 0, loop_s: 0.0 };
        for k in 0..args.sequences {
            let params = SyntheticParams {
                seed: args.seed.wrapping_add(k as u64),
                idle_s: IDLE_S,
                format: synthetic_format(source.format, table.as_ref()),
                ..SyntheticParams::default()
            };
            let s = generate(&params)?;
            let path = dir.join(format!("{k}.{}", if table.is_some() { "csv" } else { "jsonl" }));
            write_recording(&path, &s.records, table.as_ref())?;
            run.push_us.reserve(s.records.len());
            let events = run.replay(&path, &input, model)?;
            run.scores.push(RecognitionScore::new(&s.labels, s.idle, &events));
        }
        Ok(run)
    }

    /// Replays the recording at `path` through a fresh gesture loop as `dqhand replay
    /// --gestures` does, timing each push and the whole loop; returns the events.
    fn replay(&mut self, path: &Path, input: &InputArgs, model: &Arc<Model>) -> anyhow::Result<Vec<LoggedEvent>> {
        let mut reader = RecordingReader::open(path, Some(self.source.format), input)?;
        let mapper = input.mapper(JointModel::Full)?;
        let mut gesture_loop = GestureLoop::new(model.clone(), JointModel::Full, Some(mapper), input.config()?, Some(GestureSet::builtin()))?;
        let mut record = Record { time: 0.0, side: input.hand, hand: None, tracker: None, arrival: None };
        let mut events = Vec::new();
        let start = Instant::now();
        while let Some(read) = reader.next(&mut record)? {
            self.records += 1;
            if let Err(rejection) = read {
                gesture_loop.reject(rejection);
                continue;
            }
            let t0 = Instant::now();
            let pushed = gesture_loop.push(&record);
            self.push_us.push(t0.elapsed().as_secs_f64() * 1e6);
            if let Ok(new) = pushed {
                events.extend(new.map(LoggedEvent::from));
            }
        }
        self.loop_s += start.elapsed().as_secs_f64();
        Ok(events)
    }
}

/// Retargeting of noise-free joints: our own hand (the angle target) and the users' hands of
/// the recognition sequences (the contact target).
struct RetargetRun {
    own: RetargetScore,
    users: RetargetScore,
}

impl RetargetRun {
    fn measure(args: &Args, model: &Arc<Model>) -> anyhow::Result<Self> {
        let sequences = |hand: Option<HandParams>| -> dqhand::Result<Vec<Synthetic>> {
            (0..args.sequences)
                .map(|k| {
                    let seed = args.seed.wrapping_add(k as u64);
                    generate(&SyntheticParams { seed, hand, noise_m: 0.0, tremor_deg: 0.0, drop_rate: 0.0, ..SyntheticParams::default() })
                })
                .collect()
        };
        Ok(Self {
            own: RetargetScore::measure(model.clone(), &sequences(Some(HandParams::default()))?)?,
            users: RetargetScore::measure(model.clone(), &sequences(None)?)?,
        })
    }
}

/// Per-gesture tallies of one source.
#[derive(Default)]
struct GestureTally {
    holds: usize,
    in_time: usize,
    latencies_s: Vec<f64>,
    /// What was current at the deadline of holds not recognised in time.
    shown_instead: BTreeMap<String, usize>,
}

fn distribution_ms(latencies_s: &mut [f64]) -> Value {
    Distribution::of(latencies_s).map_or(Value::Null, |d| json!(d.scaled(1e3)))
}

fn rate(part: usize, whole: usize) -> f64 {
    if whole == 0 {
        0.0
    } else {
        part as f64 / whole as f64
    }
}

/// Everything measured, as the JSON object `--json` prints and the tables are read from.
fn report(args: &Args, sources: &[SourceRun], retarget: &RetargetRun) -> Value {
    let names: Vec<String> = GestureSet::builtin().gestures().iter().map(|g| g.name().to_owned()).collect();
    let defaults = SyntheticParams::default();
    let mut all_push = Vec::new();
    let (mut all_records, mut all_loop_s) = (0, 0.0);
    let mut rows = Vec::new();
    for run in sources {
        let mut tallies: BTreeMap<&str, GestureTally> = names.iter().map(|n| (n.as_str(), GestureTally::default())).collect();
        let mut latencies = Vec::new();
        for hold in run.scores.iter().flat_map(|s| &s.holds) {
            let tally = tallies.entry(hold.gesture.as_str()).or_default();
            tally.holds += 1;
            if hold.in_time() {
                tally.in_time += 1;
            } else {
                *tally.shown_instead.entry(hold.shown_at_deadline.clone().unwrap_or_else(|| "none".into())).or_default() += 1;
            }
            tally.latencies_s.extend(hold.latency_s);
            latencies.extend(hold.latency_s);
        }
        let holds: usize = run.scores.iter().map(|s| s.holds.len()).sum();
        let in_time: usize = run.scores.iter().map(RecognitionScore::in_time).sum();
        let spurious: usize = run.scores.iter().map(|s| s.spurious).sum();
        let idle_min = run.scores.iter().map(|s| s.idle_s).sum::<f64>() / 60.0;
        let gestures: serde_json::Map<String, Value> = names
            .iter()
            .map(|n| {
                let t = tallies.get_mut(n.as_str()).expect("a tally per gesture");
                let value = json!({
                    "holds": t.holds,
                    "in_time": t.in_time,
                    "rate": rate(t.in_time, t.holds),
                    "latency_ms": distribution_ms(&mut t.latencies_s),
                    "shown_instead": t.shown_instead,
                });
                (n.clone(), value)
            })
            .collect();
        let mut push = run.push_us.clone();
        all_push.extend_from_slice(&run.push_us);
        all_records += run.records;
        all_loop_s += run.loop_s;
        let push = Distribution::of(&mut push);
        let recognition_rate = rate(in_time, holds);
        let spurious_per_min = spurious as f64 / idle_min;
        rows.push(json!({
            "source": run.source.name,
            "glove_dofs_not_driven": run.undriven,
            "holds": holds,
            "in_time": in_time,
            "rate": recognition_rate,
            "rate_pass": recognition_rate >= RECOGNITION_TARGET,
            "latency_ms": distribution_ms(&mut latencies),
            "gestures": gestures,
            "idle_minutes": idle_min,
            "spurious_events": spurious,
            "spurious_per_minute": spurious_per_min,
            "spurious_pass": spurious_per_min <= SPURIOUS_TARGET_PER_MIN,
            "push_us": push,
            "push_pass": push.is_some_and(|d| d.median <= PUSH_TARGET_US),
            "records": run.records,
            "records_per_s": run.records as f64 / run.loop_s,
            "records_per_s_pass": run.records as f64 / run.loop_s >= REPLAY_TARGET_PER_S,
        }));
    }
    let push = Distribution::of(&mut all_push);
    let records_per_s = all_records as f64 / all_loop_s;
    // Every source must meet the speed targets: a fast glove must not hide slow joints.
    let every = |field: &str| !rows.is_empty() && rows.iter().all(|r| r[field] == true);
    let (push_pass, records_per_s_pass) = (every("push_pass"), every("records_per_s_pass"));
    let retarget_json = |s: &RetargetScore| {
        json!({
            "records": s.records,
            "refused": s.refused,
            "mean_deg": s.angles.mean_deg(),
            "max_deg": s.angles.max_deg(),
            "contacts": s.contacts,
            "max_contact_gap_mm": s.max_contact_gap_m * 1e3,
            "max_contact_excess_mm": s.max_contact_excess_m * 1e3,
            "contact_pass": s.contacts > 0 && s.max_contact_gap_m <= CONTACT_GAP_M,
        })
    };
    let own = &retarget.own;
    let own_hand = HandParams::default();
    json!({
        "synthetic": "sequences generated from dqhand's own kinematics (dqhand::interaction::synthetic); not captured from a person",
        "build": if cfg!(debug_assertions) { "debug" } else { "release" },
        "seed": args.seed,
        "sequences_per_source": args.sequences,
        "generator": {
            "hands": "random: length 0.16-0.21 m, breadth 42-50 % of it, either side",
            "holds": defaults.holds,
            "hold_s": defaults.hold_s,
            "move_s": defaults.move_s,
            "idle_s": IDLE_S,
            "rate_hz": defaults.rate_hz,
            "noise_m": defaults.noise_m,
            "tremor_deg": defaults.tremor_deg,
            "wrist_turn_deg": defaults.wrist_turn_deg,
            "drop_rate": defaults.drop_rate,
        },
        "targets": {
            "recognition_rate": RECOGNITION_TARGET,
            "deadline_ms": RECOGNITION_DEADLINE_S * 1e3,
            "spurious_per_minute": SPURIOUS_TARGET_PER_MIN,
            "retarget_mean_deg": ANGLE_TARGET_DEG,
            "contact_gap_mm": CONTACT_GAP_M * 1e3,
            "push_median_us": PUSH_TARGET_US,
            "records_per_s": REPLAY_TARGET_PER_S,
        },
        "sources": rows,
        "retarget": {
            "near_pinch_mm": CONTACT_FADE * 1e3,
            "closed_gaps_mm": CLOSED_GAPS_M.map(|g| g * 1e3),
            "own_hand": {
                "hand": { "length": own_hand.length, "breadth": own_hand.breadth, "side": own_hand.side.name() },
                "mean_pass": own.records > 0 && own.refused == 0 && own.angles.mean_deg() <= ANGLE_TARGET_DEG,
                "scores": retarget_json(own),
            },
            "users_hands": retarget_json(&retarget.users),
        },
        "speed": {
            "push_us": push,
            "push_pass": push_pass,
            "records": all_records,
            "records_per_s": records_per_s,
            "records_per_s_pass": records_per_s_pass,
        },
    })
}

/// A target's verdict, as every bench prints it.
pub(crate) fn pass(ok: bool) -> &'static str {
    if ok {
        "pass"
    } else {
        "FAIL"
    }
}

/// Prints the report as tables.
fn print_tables(r: &Value) {
    let f = |v: &Value| v.as_f64().unwrap_or(f64::NAN);
    let u = |v: &Value| v.as_u64().unwrap_or(0);
    let g = &r["generator"];
    let t = &r["targets"];
    println!(
        "dqhand gesture-bench: {} synthetic sequences per source (seeds {} to {}; from our own kinematics, not captured from a person)",
        u(&r["sequences_per_source"]),
        u(&r["seed"]),
        u(&r["seed"]) + u(&r["sequences_per_source"]) - 1
    );
    println!(
        "each: a user's hand ({}), {} holds of {} s after {} s eased moves, wrist turns up to {}°, {} s of idle motion, {} Hz, {:.1} mm joint noise, {}° tremor, {} % of records dropped",
        g["hands"].as_str().unwrap_or(""),
        u(&g["holds"]),
        f(&g["hold_s"]),
        f(&g["move_s"]),
        f(&g["wrist_turn_deg"]),
        f(&g["idle_s"]),
        f(&g["rate_hz"]),
        f(&g["noise_m"]) * 1e3,
        f(&g["tremor_deg"]),
        f(&g["drop_rate"]) * 100.0
    );
    if r["build"] == "debug" {
        println!("debug build: the timings below are not meaningful; build with `cargo build --release -p dqhand-cli`");
    }
    println!();
    println!(
        "recognition: the gesture's start within {} ms of the pose being reached (target ≥ {:.0} %); latency ms of every start during its hold (negative: during the move)",
        f(&t["deadline_ms"]),
        f(&t["recognition_rate"]) * 100.0
    );
    println!(
        "{:<20} {:>6} {:>8} {:>8} {:>7} {:>6} {:>6} {:>9} {:>13} {:>9} {:>10}",
        "source", "holds", "in time", "rate", "median", "p95", "max", "idle min", "spurious/min", "µs/push", "records/s"
    );
    // (+ 0.0 prints −0.0 as 0.)
    let ms = |d: &Value, k: &str| d[k].as_f64().map_or("-".to_owned(), |v| format!("{:.0}", v.round() + 0.0));
    for s in r["sources"].as_array().into_iter().flatten() {
        let l = &s["latency_ms"];
        println!(
            "{:<20} {:>6} {:>8} {:>6.1} % {:>7} {:>6} {:>6} {:>9.1} {:>8.2} {:<4} {:>9.1} {:>10.0}",
            s["source"].as_str().unwrap_or(""),
            u(&s["holds"]),
            u(&s["in_time"]),
            f(&s["rate"]) * 100.0,
            ms(l, "median"),
            ms(l, "p95"),
            ms(l, "max"),
            f(&s["idle_minutes"]),
            f(&s["spurious_per_minute"]),
            pass(s["spurious_pass"] == true),
            f(&s["push_us"]["median"]),
            f(&s["records_per_s"])
        );
    }
    println!();
    println!("per gesture: in time / holds, median latency ms");
    let sources: Vec<&Value> = r["sources"].as_array().into_iter().flatten().collect();
    print!("{:<14}", "gesture");
    for s in &sources {
        print!(" {:>20}", s["source"].as_str().unwrap_or(""));
    }
    println!();
    let names: Vec<String> = sources.first().and_then(|s| s["gestures"].as_object()).map(|o| o.keys().cloned().collect()).unwrap_or_default();
    for name in &names {
        print!("{name:<14}");
        for s in &sources {
            let c = &s["gestures"][name];
            print!(" {:>20}", format!("{}/{} {}", c["in_time"], c["holds"], ms(&c["latency_ms"], "median")));
        }
        println!();
    }
    for s in &sources {
        let below: Vec<String> = s["gestures"]
            .as_object()
            .into_iter()
            .flatten()
            .filter(|(_, c)| f(&c["rate"]) < f(&t["recognition_rate"]))
            .map(|(n, c)| {
                let instead: Vec<String> = c["shown_instead"].as_object().into_iter().flatten().map(|(k, v)| format!("{k} {v}")).collect();
                format!("{n} {}/{} (shown instead: {})", c["in_time"], c["holds"], instead.join(", "))
            })
            .collect();
        if below.is_empty() {
            continue;
        }
        println!("{}: below target: {}", s["source"].as_str().unwrap_or(""), below.join("; "));
        if let Some(undriven) = s["glove_dofs_not_driven"].as_array().filter(|u| !u.is_empty()) {
            let names: Vec<&str> = undriven.iter().filter_map(Value::as_str).collect();
            println!("  the glove drives no {} (they stay at 0°)", names.join(", "));
        }
    }
    println!();
    let own = &r["retarget"]["own_hand"];
    let users = &r["retarget"]["users_hands"];
    let o = &own["scores"];
    println!("retargeting of noise-free joints (no filter), angles against the truth");
    println!(
        "our own hand ({:.3} m × {:.3} m, {}): {} records, mean {:.3}°, max {:.2}° (target mean ≤ {}°): {}",
        f(&own["hand"]["length"]),
        f(&own["hand"]["breadth"]),
        own["hand"]["side"].as_str().unwrap_or(""),
        u(&o["records"]),
        f(&o["mean_deg"]),
        f(&o["max_deg"]),
        f(&t["retarget_mean_deg"]),
        pass(own["mean_pass"] == true)
    );
    println!(
        "the users' hands (other sizes and proportions; angles for information): {} records, mean {:.2}°, max {:.1}°",
        u(&users["records"]),
        f(&users["mean_deg"]),
        f(&users["max_deg"])
    );
    println!(
        "thumb–index contacts: records with the tracked tips ≤ {} mm apart, and near pinches (tips < {} mm: pinch, ok) closed to {} mm; virtual gap target ≤ {} mm",
        f(&t["contact_gap_mm"]),
        f(&r["retarget"]["near_pinch_mm"]),
        r["retarget"]["closed_gaps_mm"].as_array().into_iter().flatten().map(|g| format!("{}", f(g))).collect::<Vec<_>>().join(", "),
        f(&t["contact_gap_mm"])
    );
    for (who, s) in [("our own hand", o), ("the users' hands", users)] {
        println!(
            "  {who}: {} contacts, virtual gap at most {:.2} mm, at most {:.2} mm wider than the tracked one: {}",
            u(&s["contacts"]),
            f(&s["max_contact_gap_mm"]),
            f(&s["max_contact_excess_mm"]),
            if u(&s["contacts"]) == 0 { "not exercised" } else { pass(s["contact_pass"] == true) }
        );
    }
    println!();
    let sp = &r["speed"];
    println!(
        "speed ({} build, one thread, {} records, all sources): GestureLoop::push median {:.1} µs, p95 {:.1} µs (target ≤ {} µs for every source): {}; replay {:.0} records/s (target ≥ {} for every source): {}",
        r["build"].as_str().unwrap_or(""),
        u(&sp["records"]),
        f(&sp["push_us"]["median"]),
        f(&sp["push_us"]["p95"]),
        f(&t["push_median_us"]),
        pass(sp["push_pass"] == true),
        f(&sp["records_per_s"]),
        f(&t["records_per_s"]),
        pass(sp["records_per_s_pass"] == true)
    );
    let rates: Vec<String> = sources
        .iter()
        .map(|s| format!("{} {}", s["source"].as_str().unwrap_or(""), pass(s["rate_pass"] == true)))
        .collect();
    println!("recognition target: {}", rates.join(", "));
}
