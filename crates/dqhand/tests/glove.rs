//! Dataglove input: mapping tables, calibration, the mapper and the glove CSV. Expected
//! angles are computed by hand from the table definitions (angle = offset + gain · reading,
//! reading = (raw − flat) / (high − flat), couplings in order).

mod support;

use std::io::Cursor;

use dqhand::hand::Side;
use dqhand::input::{
    Calibration, GloveCsvReader, GloveCsvWriter, GloveMapper, GloveSample, HandData, MappingTable, Record, RejectKind,
    RigidPose, SensorCalibration, SensorKind,
};
use dqhand::kinematics::JointModel;
use dqhand::Error;
use glam::{Quat, Vec3};
use proptest::prelude::*;

fn table(name: &str) -> MappingTable {
    MappingTable::builtin(name).unwrap()
}

/// Maps `raw` (layout order) and returns the angles in degrees.
fn map_deg(table: &MappingTable, calibration: &Calibration, model: JointModel, raw: &[f32]) -> Vec<f32> {
    let mapper = GloveMapper::new(table, calibration, model).unwrap();
    let mut angles = vec![f32::NAN; model.dof_count()];
    mapper.map(&GloveSample::new(raw), &mut angles).unwrap();
    angles.iter().map(|a| a.to_degrees()).collect()
}

fn angle(angles_deg: &[f32], model: JointModel, dof: &str) -> f32 {
    angles_deg[model.dof_index(dof).unwrap()]
}

fn empty_record() -> Record {
    Record { time: -1.0, side: Side::Right, hand: None, tracker: None, arrival: None }
}

// ---- tables ----

#[test]
fn shipped_tables_load_and_resolve_on_both_models() {
    let expected = [("5dt-14", 14), ("5dt-5", 5), ("cyberglove-18", 18)];
    assert_eq!(MappingTable::BUILTIN, expected.map(|(n, _)| n));
    for (name, sensors) in expected {
        let t = table(name);
        assert_eq!(t.name(), name);
        assert_eq!(t.layout().len(), sensors);
        assert!(!t.notes().is_empty());
        for model in JointModel::ALL {
            let raw = vec![0.0; sensors];
            // Default calibration, flat hand: every mapped angle is its offset, 0 here.
            let angles = map_deg(&t, &Calibration::default_for(&t), model, &raw);
            assert_eq!(angles.len(), model.dof_count());
            assert!(angles.iter().all(|a| *a == 0.0), "{name} on {model}: {angles:?}");
        }
    }
}

#[test]
fn five_dt_14_sensors_are_in_sdk_order_with_kinds() {
    let t = table("5dt-14");
    let names: Vec<&str> = t.layout().sensors().iter().map(|s| s.name.as_str()).collect();
    assert_eq!(
        names,
        [
            "thumb_near", "thumb_far", "thumb_index", "index_near", "index_far", "index_middle", "middle_near", "middle_far",
            "middle_ring", "ring_near", "ring_far", "ring_little", "little_near", "little_far"
        ]
    );
    let abduction: Vec<&str> =
        t.layout().sensors().iter().filter(|s| s.kind == SensorKind::Abduction).map(|s| s.name.as_str()).collect();
    assert_eq!(abduction, ["thumb_index", "index_middle", "middle_ring", "ring_little"]);
}

#[test]
fn cyberglove_wrist_sensors_are_listed_but_unmapped() {
    let t = table("cyberglove-18");
    assert_eq!(t.layout().index_of("wrist_pitch"), Some(16));
    assert_eq!(t.layout().index_of("wrist_yaw"), Some(17));
    assert!(t.entries().iter().all(|e| !e.sensor.starts_with("wrist")));
    assert!(t.notes().contains("wrist_pitch and wrist_yaw are listed but unmapped"));
    // Full fist on every sensor, wrist included: the wrist moves nothing, palm arch flexes
    // ring and little CMC to 10° and 20°.
    let angles = map_deg(&t, &Calibration::default_for(&t), JointModel::Full, &[4095.0; 18]);
    let m = JointModel::Full;
    assert_close!(angle(&angles, m, "ring-finger-metacarpal.flex"), 10.0, 1e-3);
    assert_close!(angle(&angles, m, "pinky-finger-metacarpal.flex"), 20.0, 1e-3);
    assert_close!(angle(&angles, m, "thumb-metacarpal.flex"), 45.0, 1e-3);
    assert_close!(angle(&angles, m, "pinky-finger-phalanx-distal.flex"), 100.0 * 2.0 / 3.0, 1e-3);
}

#[test]
fn unknown_builtin_lists_the_shipped_tables() {
    let e = MappingTable::builtin("dataglove-9000").unwrap_err();
    assert!(matches!(e, Error::UnknownName { .. }));
    assert!(e.to_string().contains("5dt-14, 5dt-5, cyberglove-18"), "{e}");
}

// ---- mapping ----

/// 5DT-14 calibrated sensor by sensor: readings and angles worked out by hand.
#[test]
fn calibrated_5dt_14_sample_maps_to_hand_computed_angles() {
    let t = table("5dt-14");
    let mut cal = Calibration::default_for(&t);
    let flex = |flat, fist| SensorCalibration { flat, fist: Some(fist), spread: None };
    let abd = |flat, spread| SensorCalibration { flat, fist: None, spread: Some(spread) };
    cal.sensors.insert("index_near".into(), flex(1000.0, 3000.0));
    cal.sensors.insert("index_far".into(), flex(500.0, 2500.0));
    cal.sensors.insert("thumb_index".into(), abd(1000.0, 3000.0));
    cal.sensors.insert("ring_little".into(), abd(2000.0, 1000.0)); // wired downward
    cal.sensors.insert("thumb_far".into(), flex(3000.0, 1000.0)); // wired downward
    let mut raw = [0.0; 14];
    raw[1] = 3500.0; // thumb_far: (3500 − 3000) / (1000 − 3000) = −0.25 → −20° (past flat)
    raw[2] = 1500.0; // thumb_index: 0.25 → thumb CMC abd 12.5°
    raw[3] = 2000.0; // index_near: 0.5 → index MCP 45°
    raw[4] = 2000.0; // index_far: 0.75 → index PIP 75°, DIP ⅔ · 75 = 50°
    raw[11] = 1500.0; // ring_little: 0.5 → little MCP abd 15°
    raw[13] = 4095.0; // little_far: 1 → little PIP 100°, DIP 66.67°

    let full = JointModel::Full;
    let a = map_deg(&t, &cal, full, &raw);
    let expected = [
        ("thumb-phalanx-distal.flex", -20.0),
        ("thumb-metacarpal.abd", 12.5),
        ("index-finger-phalanx-proximal.flex", 45.0),
        ("index-finger-phalanx-intermediate.flex", 75.0),
        ("index-finger-phalanx-distal.flex", 50.0),
        ("pinky-finger-phalanx-proximal.abd", 15.0),
        ("pinky-finger-phalanx-intermediate.flex", 100.0),
        ("pinky-finger-phalanx-distal.flex", 200.0 / 3.0),
    ];
    for (dof, deg) in expected {
        assert_close!(angle(&a, full, dof), deg, 1e-3);
    }
    let set: Vec<usize> = expected.iter().map(|(d, _)| full.dof_index(d).unwrap()).collect();
    for (i, v) in a.iter().enumerate().filter(|(i, _)| !set.contains(i)) {
        assert_eq!(*v, 0.0, "{} should stay 0", full.dofs().nth(i).unwrap().name());
    }

    // The paper model has no thumb CMC: that entry is skipped, the rest is the same.
    let paper = JointModel::Paper;
    let p = map_deg(&t, &cal, paper, &raw);
    for (dof, deg) in expected.iter().filter(|(d, _)| !d.starts_with("thumb-metacarpal")) {
        assert_close!(angle(&p, paper, dof), *deg, 1e-3);
    }
    assert_eq!(p.iter().filter(|v| **v != 0.0).count(), expected.len() - 1);
}

/// 5DT-5: PIP follows MCP and DIP follows PIP, a chain of couplings.
#[test]
fn five_dt_5_chains_couplings() {
    let t = table("5dt-5");
    let m = JointModel::Paper;
    // Default calibration 0 → flat, 4095 → fist; index at 0.6, thumb at 0.5.
    let a = map_deg(&t, &Calibration::default_for(&t), m, &[2047.5, 2457.0, 0.0, 0.0, 4095.0]);
    assert_close!(angle(&a, m, "index-finger-phalanx-proximal.flex"), 54.0, 1e-3);
    assert_close!(angle(&a, m, "index-finger-phalanx-intermediate.flex"), 60.0, 1e-3); // 54 · 10/9
    assert_close!(angle(&a, m, "index-finger-phalanx-distal.flex"), 40.0, 1e-3); // 60 · 2/3
    assert_close!(angle(&a, m, "thumb-phalanx-proximal.flex"), 27.5, 1e-3);
    assert_close!(angle(&a, m, "thumb-phalanx-distal.flex"), 33.0, 1e-3); // 27.5 · 1.2
    assert_close!(angle(&a, m, "pinky-finger-phalanx-distal.flex"), 200.0 / 3.0, 1e-3);
    assert_eq!(angle(&a, m, "middle-finger-phalanx-distal.flex"), 0.0);
    assert_eq!(angle(&a, m, "index-finger-phalanx-proximal.abd"), 0.0);
}

#[test]
fn mapper_rejects_bad_raw_values_naming_the_sensor() {
    let t = table("5dt-5");
    let mapper = GloveMapper::new(&t, &Calibration::default_for(&t), JointModel::Paper).unwrap();
    let mut angles = vec![7.0; 18];
    let cases = [
        ([0.0, 0.0, 4096.0, 0.0, 0.0], RejectKind::OutOfRange, "middle_near"),
        ([0.0, -1.0, 0.0, 0.0, 0.0], RejectKind::OutOfRange, "index_near"),
        ([f32::NAN, 0.0, 0.0, 0.0, 0.0], RejectKind::NonFinite, "thumb_near"),
        ([0.0, 0.0, 0.0, 0.0, f32::INFINITY], RejectKind::NonFinite, "little_near"),
    ];
    for (raw, kind, sensor) in cases {
        let r = mapper.map(&GloveSample::new(&raw), &mut angles).unwrap_err();
        assert_eq!(r.kind, kind, "{r}");
        assert!(r.message.contains(sensor), "{r}");
        assert!(angles.iter().all(|a| *a == 7.0), "angles touched on rejection");
    }
    let r = mapper.map(&GloveSample::new(&[0.0; 4]), &mut angles).unwrap_err();
    assert_eq!(r.kind, RejectKind::Malformed);
}

// ---- user tables ----

const CUSTOM: &str = r#"{
  "glove": "custom",
  "notes": "two sensors on the index finger",
  "sensors": [ {"name": "bend", "kind": "flexion"}, {"name": "splay", "kind": "abduction"} ],
  "entries": [
    {"sensor": "bend", "dof": "index-finger-phalanx-proximal.flex", "gain_deg": 80, "offset_deg": -10},
    {"sensor": "splay", "dof": "index-finger-phalanx-proximal.abd", "gain_deg": 20, "offset_deg": -5}
  ],
  "couplings": [
    {"dof": "index-finger-phalanx-intermediate.flex", "from": "index-finger-phalanx-proximal.flex", "ratio": 1.0},
    {"dof": "index-finger-phalanx-distal.flex", "from": "index-finger-phalanx-intermediate.flex", "ratio": 0.5}
  ]
}"#;

#[test]
fn user_table_maps_with_offsets_and_chained_couplings() {
    let t = MappingTable::from_json(CUSTOM).unwrap();
    let cal = Calibration::from_json(
        r#"{"glove": "custom", "sensors": {"bend": {"flat": 100, "fist": 900}, "splay": {"flat": 50, "spread": 250}}}"#,
    )
    .unwrap();
    let m = JointModel::Paper;
    // bend 300 → 0.25 → −10 + 20 = 10°; PIP = 10°, DIP = 5°. splay 250 → 1 → −5 + 20 = 15°.
    let a = map_deg(&t, &cal, m, &[300.0, 250.0]);
    assert_close!(angle(&a, m, "index-finger-phalanx-proximal.flex"), 10.0, 1e-4);
    assert_close!(angle(&a, m, "index-finger-phalanx-intermediate.flex"), 10.0, 1e-4);
    assert_close!(angle(&a, m, "index-finger-phalanx-distal.flex"), 5.0, 1e-4);
    assert_close!(angle(&a, m, "index-finger-phalanx-proximal.abd"), 15.0, 1e-4);
    assert_eq!(a.iter().filter(|v| **v != 0.0).count(), 4);
}

/// `CUSTOM` with `from` replaced by `to` (once).
fn edited(from: &str, to: &str) -> String {
    assert!(CUSTOM.contains(from), "{from}");
    CUSTOM.replacen(from, to, 1)
}

fn table_problem(text: &str) -> (String, Error) {
    match MappingTable::from_json(text).unwrap_err() {
        e @ Error::GloveTable { .. } => {
            let message = e.to_string();
            let Error::GloveTable { table, problem } = e else { unreachable!() };
            assert!(message.starts_with(&format!("glove table {table:?}: ")), "{message}");
            (table, *problem)
        }
        other => panic!("expected a glove table error, got {other:?}"),
    }
}

#[test]
fn unknown_dof_names_the_table_and_lists_valid_dofs() {
    let (table, problem) = table_problem(&edited("index-finger-phalanx-proximal.abd", "index-finger-phalanx-proximal.twist"));
    assert_eq!(table, "custom");
    let Error::UnknownName { name, valid, .. } = &problem else { panic!("{problem:?}") };
    assert_eq!(name, "index-finger-phalanx-proximal.twist");
    assert!(valid.contains("thumb-metacarpal.abd") && valid.contains("index-finger-phalanx-proximal.abd"), "{valid}");
}

#[test]
fn bad_user_tables_give_specific_errors() {
    let (_, p) = table_problem(&edited(r#""sensor": "splay""#, r#""sensor": "spread""#));
    assert!(matches!(&p, Error::UnknownName { kind: "sensor", name, valid } if name == "spread" && valid == "bend, splay"), "{p:?}");

    let (_, p) = table_problem(&edited(r#"{"name": "splay""#, r#"{"name": "bend""#));
    assert!(matches!(&p, Error::Glove(m) if m.contains("\"bend\" is listed twice")), "{p:?}");

    // 1e39 is beyond f32: infinite.
    let (_, p) = table_problem(&edited(r#""gain_deg": 80"#, r#""gain_deg": 1e39"#));
    assert!(matches!(&p, Error::Glove(m) if m.contains("not finite")), "{p:?}");

    let (_, p) = table_problem(&edited(r#""ratio": 0.5"#, r#""ratio": -1e39"#));
    assert!(matches!(&p, Error::Glove(m) if m.contains("not finite")), "{p:?}");

    // A coupling reading what only a later coupling sets.
    let swapped = CUSTOM.replacen("\"from\": \"index-finger-phalanx-proximal.flex\"", "\"from\": \"index-finger-phalanx-distal.flex\"", 1);
    let (_, p) = table_problem(&swapped);
    assert!(matches!(&p, Error::Glove(m) if m.contains("no entry or earlier coupling sets it")), "{p:?}");

    // A DOF set by an entry and a coupling.
    let (_, p) = table_problem(&edited("\"dof\": \"index-finger-phalanx-intermediate.flex\"", "\"dof\": \"index-finger-phalanx-proximal.abd\""));
    assert!(matches!(&p, Error::Glove(m) if m.contains("index-finger-phalanx-proximal.abd is set by")), "{p:?}");

    // A sensor name that cannot be a CSV column.
    let (_, p) = table_problem(&CUSTOM.replace("\"bend\"", "\"t\""));
    assert!(matches!(&p, Error::Glove(m) if m.contains("\"t\" is not usable")), "{p:?}");

    // Unknown field: not a table at all.
    let e = MappingTable::from_json(&edited("\"notes\"", "\"note\"")).unwrap_err();
    assert!(matches!(&e, Error::Glove(m) if m.starts_with("not a valid glove table") && m.contains("note")), "{e:?}");
}

// ---- calibration ----

#[test]
fn calibration_json_round_trips_and_reads_the_documented_format() {
    let t = table("5dt-14");
    let mut cal = Calibration::default_for(&t);
    cal.sensors.insert("thumb_near".into(), SensorCalibration { flat: 812.25, fist: Some(3100.1), spread: None });
    cal.sensors.insert("thumb_index".into(), SensorCalibration { flat: 1500.0, fist: None, spread: Some(2999.7) });
    assert_eq!(Calibration::from_json(&cal.to_json()).unwrap(), cal);

    let path = std::env::temp_dir().join(format!("dqhand-glove-calibration-{}.json", std::process::id()));
    cal.save(&path).unwrap();
    let loaded = Calibration::load(&path);
    std::fs::remove_file(&path).unwrap();
    assert_eq!(loaded.unwrap(), cal);

    let doc = Calibration::from_json(r#"{"glove": "5dt-14", "sensors": {"thumb_near": {"flat": 812, "fist": 3100}, "thumb_index": {"flat": 1500, "spread": 3000}}}"#).unwrap();
    assert_eq!(doc.glove, "5dt-14");
    assert_eq!(doc.sensors["thumb_near"], SensorCalibration { flat: 812.0, fist: Some(3100.0), spread: None });
    assert_eq!(doc.sensors["thumb_index"], SensorCalibration { flat: 1500.0, fist: None, spread: Some(3000.0) });
}

#[test]
fn calibrations_that_do_not_fit_the_table_are_refused() {
    let t = table("5dt-5");
    let calibration_error = |cal: &Calibration| match GloveMapper::new(&t, cal, JointModel::Paper).unwrap_err() {
        Error::Calibration(m) => m,
        other => panic!("{other:?}"),
    };
    let mut other_glove = Calibration::default_for(&t);
    other_glove.glove = "5dt-14".into();
    assert!(calibration_error(&other_glove).contains("\"5dt-14\""));

    let mut missing = Calibration::default_for(&t);
    missing.sensors.remove("ring_near");
    assert!(calibration_error(&missing).starts_with("sensor ring_near: not in the calibration"));

    let mut wrong_kind = Calibration::default_for(&t);
    wrong_kind.sensors.insert("index_near".into(), SensorCalibration { flat: 0.0, fist: None, spread: Some(4000.0) });
    assert!(calibration_error(&wrong_kind).starts_with("sensor index_near (flexion): no fist value"));

    let mut degenerate = Calibration::default_for(&t);
    degenerate.sensors.insert("index_near".into(), SensorCalibration { flat: 2000.0, fist: Some(2000.0), spread: None });
    assert!(calibration_error(&degenerate).starts_with("sensor index_near: flat 2000 and fist 2000"));

    let mut unknown = Calibration::default_for(&t);
    unknown.sensors.insert("index_far".into(), SensorCalibration { flat: 0.0, fist: Some(10.0), spread: None });
    assert!(calibration_error(&unknown).starts_with("calibration sensor \"index_far\""));
}

/// Deterministic noise in [−amplitude, amplitude] (a small LCG, so the test needs no seed crate).
struct Noise(u64);

impl Noise {
    fn next(&mut self, amplitude: f32) -> f32 {
        self.0 = self.0.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
        ((self.0 >> 40) as f32 / (1u64 << 24) as f32 * 2.0 - 1.0) * amplitude
    }
}

#[test]
fn derive_recovers_the_held_extremes() {
    let t = table("5dt-14");
    let kinds: Vec<SensorKind> = t.layout().sensors().iter().map(|s| s.kind).collect();
    // The true raw values of each sensor at each pose.
    let flat: Vec<f32> = (0..14).map(|i| 500.0 + 37.0 * i as f32).collect();
    let fist: Vec<f32> = (0..14).map(|i| 3000.0 + 29.0 * i as f32).collect();
    let spread: Vec<f32> = (0..14).map(|i| 2800.0 - 13.0 * i as f32).collect();
    let pose = |name: &str| -> Vec<f32> {
        (0..14)
            .map(|i| match (name, kinds[i]) {
                ("flat", _) | ("spread", SensorKind::Flexion) => flat[i],
                ("fist", SensorKind::Flexion) => fist[i],
                ("fist", SensorKind::Abduction) => flat[i] + 150.0, // fingers pressed in a fist
                ("spread", SensorKind::Abduction) => spread[i],
                _ => unreachable!(),
            })
            .collect()
    };
    let mut noise = Noise(7);
    let mut samples = Vec::new();
    let mut previous = pose("flat");
    // Holds in a shuffled order and of unequal lengths, with 12-frame transitions between.
    for (name, frames) in [("spread", 80), ("fist", 40), ("flat", 60), ("fist", 25), ("spread", 30)] {
        let target = pose(name);
        for k in 1..=12 {
            let s = k as f32 / 13.0;
            let v: Vec<f32> = previous.iter().zip(&target).map(|(a, b)| a + (b - a) * s + noise.next(15.0)).collect();
            samples.push(GloveSample::new(&v));
        }
        for _ in 0..frames {
            let v: Vec<f32> = target.iter().map(|x| x + noise.next(15.0)).collect();
            samples.push(GloveSample::new(&v));
        }
        previous = target;
    }
    // Dropouts are ignored.
    samples.insert(100, GloveSample::new(&[f32::NAN; 14]));
    samples.insert(5, GloveSample::new(&[5000.0; 14]));

    let cal = Calibration::derive(&t, &samples).unwrap();
    assert_eq!(cal.glove, "5dt-14");
    for (i, sensor) in t.layout().sensors().iter().enumerate() {
        let c = cal.sensors[&sensor.name];
        assert_close!(c.flat, flat[i], 8.0);
        match sensor.kind {
            SensorKind::Flexion => {
                assert_close!(c.fist.unwrap(), fist[i], 8.0);
                assert_eq!(c.spread, None);
            }
            SensorKind::Abduction => {
                assert_close!(c.spread.unwrap(), spread[i], 8.0);
                assert_eq!(c.fist, None);
            }
        }
    }
    // And it maps: the true fist gives 90° at index MCP, give or take the noise.
    let a = map_deg(&t, &cal, JointModel::Paper, &pose("fist"));
    assert_close!(angle(&a, JointModel::Paper, "index-finger-phalanx-proximal.flex"), 90.0, 1.0);
}

#[test]
fn derive_refuses_a_recording_whose_sensors_never_move() {
    let t = table("5dt-5");
    let mut noise = Noise(3);
    let mut samples: Vec<GloveSample> =
        (0..300).map(|_| GloveSample::new(&[2000.0 + noise.next(5.0), 100.0, 4000.0, 1200.0, 1800.0])).collect();
    let e = Calibration::derive(&t, &samples).unwrap_err();
    let Error::Calibration(m) = &e else { panic!("{e:?}") };
    assert!(m.contains("sensors thumb_near, index_near, middle_near, ring_near, little_near moved less than 200"), "{m}");
    assert!(!m.contains('\n'));

    // Only the thumb still: only it is named.
    for (k, s) in samples.iter_mut().enumerate() {
        let bent = if k % 100 < 50 { 0.0 } else { 2500.0 };
        *s = GloveSample::new(&[2000.0, 100.0 + bent, 400.0 + bent, 300.0 + bent, 200.0 + bent]);
    }
    let e = Calibration::derive(&t, &samples).unwrap_err();
    assert!(e.to_string().contains("sensors thumb_near moved less"), "{e}");

    let e = Calibration::derive(&t, &[GloveSample::new(&[0.0; 4])]).unwrap_err();
    assert!(e.to_string().starts_with("calibration sample 0: 4 values; glove 5dt-5 has 5 sensors"), "{e}");
}

// ---- CSV ----

fn reader(text: &str, table: &MappingTable) -> dqhand::Result<GloveCsvReader<Cursor<Vec<u8>>>> {
    GloveCsvReader::new(Cursor::new(text.as_bytes().to_vec()), table, Side::Left)
}

/// Every row's outcome: the record or the rejection.
fn read_all(text: &str, table: &MappingTable) -> Vec<Result<Record, (RejectKind, String)>> {
    let mut r = reader(text, table).unwrap();
    let mut out = empty_record();
    let mut all = Vec::new();
    while let Some(row) = r.next_record(&mut out) {
        all.push(row.map(|()| out).map_err(|e| (e.kind, e.message)));
    }
    all
}

fn glove(record: &Record) -> &[f32] {
    match &record.hand {
        Some(HandData::Glove(s)) => s.values(),
        other => panic!("{other:?}"),
    }
}

#[test]
fn csv_without_tracker_or_hand_columns() {
    let t = table("5dt-5");
    // Columns in another order than the layout; a blank line; CRLF line ends; no final newline.
    let text = "t,index_near,thumb_near,middle_near,ring_near,little_near\r\n0.5, 10,20,30,40,50\r\n\r\n1.25,4095,0,1.5,2,3";
    let rows = read_all(text, &t);
    assert_eq!(rows.len(), 2);
    let a = rows[0].as_ref().unwrap();
    assert_eq!((a.time, a.side, a.tracker), (0.5, Side::Left, None));
    assert_eq!(glove(a), [20.0, 10.0, 30.0, 40.0, 50.0]);
    let b = rows[1].as_ref().unwrap();
    assert_eq!(b.time, 1.25);
    assert_eq!(glove(b), [0.0, 4095.0, 1.5, 2.0, 3.0]);
}

#[test]
fn csv_with_tracker_and_hand_columns() {
    let t = table("5dt-5");
    let text = "hand,t,thumb_near,index_near,middle_near,ring_near,little_near,qw,qx,qy,qz,px,py,pz\n\
                right,0,1,2,3,4,5,1,0,0,0,0.1,0.2,0.3\n\
                left,0.1,1,2,3,4,5,0,0,0.6,0.8,1,2,3\n\
                right,0.2,1,2,3,4,5,1.002,0,0,0,0,0,0\n";
    let rows = read_all(text, &t);
    let r: Vec<&Record> = rows.iter().map(|r| r.as_ref().unwrap()).collect();
    assert_eq!(r[0].side, Side::Right);
    assert_eq!(r[0].tracker, Some(RigidPose { position: Vec3::new(0.1, 0.2, 0.3), orientation: Quat::IDENTITY }));
    assert_eq!(r[1].side, Side::Left);
    let p = r[1].tracker.unwrap();
    assert_eq!(p.position, Vec3::new(1.0, 2.0, 3.0));
    assert_close!(p.orientation.to_array().into_iter().zip([0.0, 0.6, 0.8, 0.0]).map(|(a, b)| (a - b).abs()).sum::<f32>(), 0.0, 1e-6);
    // Slightly off unit: normalised.
    assert_close!(r[2].tracker.unwrap().orientation.w, 1.0, 1e-6);
    assert_close!(r[2].tracker.unwrap().orientation.length(), 1.0, 1e-6);
}

#[test]
fn csv_bad_rows_are_rejected_by_kind_and_line_and_reading_goes_on() {
    let t = table("5dt-5");
    let text = "t,thumb_near,index_near,middle_near,ring_near,little_near,px,py,pz,qx,qy,qz,qw\n\
                0.0,1,2,3,4,5,0,0,0,0,0,0,1\n\
                0.1,1,2,3,4,0,0,0,0,0,0,1\n\
                0.2,1,2,NaN,4,5,0,0,0,0,0,0,1\n\
                0.3,1,2,4096,4,5,0,0,0,0,0,0,1\n\
                0.4,-1,2,3,4,5,0,0,0,0,0,0,1\n\
                0.5,1,2,3,4,5,0,0,0,0,0,0,2\n\
                abc,1,2,3,4,5,0,0,0,0,0,0,1\n\
                0.6,1,,3,4,5,0,0,0,0,0,0,1\n\
                0.7,1,2,3,4,5,0,0,inf,0,0,0,1\n\
                0.8,1,2,3,4,5,0,0,0,0,0,0,1,9\n\
                0.9,9,8,7,6,5,0,0,0,0,0,0,1\n\
                1.0,1,2,3";
    let rows = read_all(text, &t);
    let expect: [(usize, Option<(RejectKind, &str)>); 12] = [
        (2, None),
        (3, Some((RejectKind::ColumnCount, "12 columns; the header has 13"))),
        (4, Some((RejectKind::NonFinite, "middle_near"))),
        (5, Some((RejectKind::OutOfRange, "middle_near = 4096"))),
        (6, Some((RejectKind::OutOfRange, "thumb_near = -1"))),
        (7, Some((RejectKind::OutOfRange, "length 2"))),
        (8, Some((RejectKind::Malformed, "t \"abc\" is not a number"))),
        (9, Some((RejectKind::Malformed, "index_near is empty"))),
        (10, Some((RejectKind::NonFinite, "pz = inf"))),
        (11, Some((RejectKind::ColumnCount, "14 columns"))),
        (12, None),
        (13, Some((RejectKind::Malformed, "truncated"))),
    ];
    assert_eq!(rows.len(), expect.len(), "{rows:?}");
    for (row, (line, want)) in rows.iter().zip(expect) {
        match (row, want) {
            (Ok(_), None) => {}
            (Err((kind, message)), Some((want_kind, needle))) => {
                assert_eq!(*kind, want_kind, "{message}");
                assert!(message.starts_with(&format!("line {line}: ")), "{message}");
                assert!(message.contains(needle), "{message} lacks {needle}");
            }
            other => panic!("line {line}: {other:?}"),
        }
    }
    let last_good = rows[10].as_ref().unwrap();
    assert_eq!((last_good.time, glove(last_good)), (0.9, &[9.0, 8.0, 7.0, 6.0, 5.0][..]));
}

#[test]
fn csv_rejection_leaves_the_record_as_it_was() {
    let t = table("5dt-5");
    let mut r = reader("t,thumb_near,index_near,middle_near,ring_near,little_near\n1,1,2,3,4,5\n2,1,2,3,4,x\n", &t).unwrap();
    let mut out = empty_record();
    r.next_record(&mut out).unwrap().unwrap();
    let good = out;
    assert_eq!(r.next_record(&mut out).unwrap().unwrap_err().kind, RejectKind::Malformed);
    assert_eq!(out, good);
    assert!(r.next_record(&mut out).is_none());
}

fn header_error(text: &str) -> String {
    match reader(text, &table("5dt-5")) {
        Err(Error::Glove(m)) => m,
        Err(other) => panic!("{other:?}"),
        Ok(_) => panic!("header accepted: {text}"),
    }
}

#[test]
fn csv_header_errors_name_the_columns() {
    let m = header_error("t,thumb_near,middle_near,ring_near\n");
    assert!(m.contains("no column for sensors index_near, little_near of glove 5dt-5"), "{m}");
    let m = header_error("t,thumb_near,index_near,middle_near,ring_near,little_near,pinky_near,wrist\n");
    assert!(m.contains("unknown columns \"pinky_near\", \"wrist\""), "{m}");
    let m = header_error("t,thumb_near,index_near,middle_near,ring_near,little_near,px,py,pz\n");
    assert!(m.contains("tracker columns qx, qy, qz, qw missing"), "{m}");
    let m = header_error("thumb_near,index_near,middle_near,ring_near,little_near\n");
    assert!(m.contains("no time column t"), "{m}");
    let m = header_error("t,t,thumb_near,index_near,middle_near,ring_near,little_near\n");
    assert!(m.contains("\"t\" appears twice"), "{m}");
    assert!(header_error("").contains("header: missing"));
}

fn records(tracker: bool, hand: bool) -> Vec<Record> {
    let mut noise = Noise(11);
    (0..50)
        .map(|k| Record {
            time: k as f64 * 0.0137 + 1e-9,
            side: if hand && k % 3 == 0 { Side::Left } else { Side::Right },
            hand: Some(HandData::Glove(GloveSample::new(&[0.0, 4095.0, 2047.5 + noise.next(2000.0), 1.0 / 3.0, 123.456]))),
            tracker: tracker.then(|| RigidPose {
                position: Vec3::new(noise.next(1.0), noise.next(1.0), noise.next(1.0)),
                orientation: Quat::from_axis_angle(Vec3::new(noise.next(1.0), 1.0, noise.next(1.0)).normalize(), noise.next(3.0)),
            }),
            arrival: None,
        })
        .collect()
}

#[test]
fn csv_writer_round_trips_through_the_reader() {
    let t = table("5dt-5");
    for (tracker, hand) in [(false, false), (true, false), (false, true), (true, true)] {
        let mut bytes = Vec::new();
        let mut w = GloveCsvWriter::new(&mut bytes, &t, tracker, hand).unwrap();
        let written = records(tracker, hand);
        for r in &written {
            w.write(r).unwrap();
        }
        let text = String::from_utf8(bytes).unwrap();
        let mut r = GloveCsvReader::new(Cursor::new(text.as_bytes()), &t, Side::Right).unwrap();
        let mut out = empty_record();
        let mut read = Vec::new();
        while let Some(row) = r.next_record(&mut out) {
            row.unwrap();
            read.push(out);
        }
        assert_eq!(read, written, "tracker {tracker}, hand {hand}:\n{text}");
    }
}

#[test]
fn csv_writer_refuses_records_its_columns_cannot_hold() {
    let t = table("5dt-5");
    let mut bytes = Vec::new();
    let mut w = GloveCsvWriter::new(&mut bytes, &t, true, false).unwrap();
    let good = records(true, false)[0];
    let bad = [
        Record { tracker: None, ..good },
        Record { hand: None, ..good },
        Record { hand: Some(HandData::Glove(GloveSample::new(&[0.0; 4]))), ..good },
        Record { hand: Some(HandData::Glove(GloveSample::new(&[0.0, 0.0, 4096.0, 0.0, 0.0]))), ..good },
        Record { time: f64::NAN, ..good },
        Record { tracker: Some(RigidPose { position: Vec3::ZERO, orientation: Quat::from_xyzw(0.0, 0.0, 0.0, 2.0) }), ..good },
    ];
    for r in &bad {
        assert_eq!(w.write(r).unwrap_err().kind(), std::io::ErrorKind::InvalidInput, "{r:?}");
    }
    w.write(&good).unwrap();
    // Only the header and the good row were written.
    assert_eq!(String::from_utf8(bytes).unwrap().lines().count(), 2);
}

proptest! {
    #[test]
    fn csv_byte_soup_never_panics(soup in proptest::collection::vec(any::<u8>(), 0..600), with_header in any::<bool>()) {
        let t = table("5dt-5");
        let mut input = if with_header { b"t,thumb_near,index_near,middle_near,ring_near,little_near,px,py,pz,qx,qy,qz,qw,hand\n".to_vec() } else { Vec::new() };
        input.extend_from_slice(&soup);
        if let Ok(mut r) = GloveCsvReader::new(Cursor::new(input), &t, Side::Right) {
            let mut out = empty_record();
            let mut rows = 0;
            while let Some(row) = r.next_record(&mut out) {
                if let Err(e) = row {
                    prop_assert!(e.message.starts_with("line "));
                }
                rows += 1;
                prop_assert!(rows <= 601);
            }
        }
    }

    #[test]
    fn csv_soup_of_plausible_fields_never_panics(fields in proptest::collection::vec(prop_oneof![
        Just("1".to_string()), Just("".to_string()), Just("nan".to_string()), Just("-0".to_string()), Just("4095".to_string()),
        Just("left".to_string()), Just("1e40".to_string()), Just("\n".to_string()), Just("\r".to_string()), "[0-9.,e+-]{0,6}"
    ], 0..80)) {
        let t = table("5dt-5");
        let text = format!("t,thumb_near,index_near,middle_near,ring_near,little_near,px,py,pz,qx,qy,qz,qw,hand\n{}", fields.join(","));
        let mut r = GloveCsvReader::new(Cursor::new(text.into_bytes()), &t, Side::Right).unwrap();
        let mut out = empty_record();
        while let Some(row) = r.next_record(&mut out) {
            if row.is_ok() {
                prop_assert!(out.time >= 0.0 && glove(&out).iter().all(|v| (0.0..=4095.0).contains(v)));
            }
        }
    }
}
