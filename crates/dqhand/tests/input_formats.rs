//! Records from JSON (joints, OpenXR joints, landmarks, glove, tracker), the One Euro filters
//! against a plain transcription of Casiez et al.'s pseudo-code, and the mounting offset.

mod support;

use dqhand::hand::Side;
use dqhand::input::json_record::{parse_record, write_record, JsonRecordReader, MAX_RECORD_BYTES};
use dqhand::input::{openxr, HandData, MountingOffset, OneEuro, OneEuroParams, OneEuroRotation, OneEuroVec3, Record, RejectKind, RigidPose};
use dqhand::kinematics::webxr;
use dqhand::math::DualQuat;
use glam::{Quat, Vec3};
use proptest::prelude::*;

const NO_GLOVE: [&str; 0] = [];

fn empty() -> Record {
    Record { time: 0.0, side: Side::Right, hand: None, tracker: None, arrival: None }
}

fn joints_json(names: &[&str], skip: Option<usize>) -> String {
    let entries: Vec<String> = names
        .iter()
        .enumerate()
        .filter(|(i, _)| Some(*i) != skip)
        .map(|(i, n)| format!("\"{n}\": {{\"p\": [{}, 1.0, -0.5], \"q\": [0, 0, 0, 1], \"r\": 0.01}}", i as f32 * 0.01))
        .collect();
    format!("{{\"t\": 1.5, \"hand\": \"left\", \"joints\": {{{}}}}}", entries.join(", "))
}

#[test]
fn webxr_joints_by_name() {
    let mut r = empty();
    parse_record(&joints_json(&webxr::JOINT_NAMES, None), Side::Right, &NO_GLOVE, &mut r).unwrap();
    assert_eq!((r.time, r.side), (1.5, Side::Left));
    let Some(HandData::Joints(set)) = r.hand else { panic!("{:?}", r.hand) };
    assert!(set.is_complete());
    let thumb_tip = set.get(4).unwrap();
    assert_eq!(thumb_tip.position, Vec3::new(0.04, 1.0, -0.5));
    assert_eq!(thumb_tip.orientation, Some(Quat::IDENTITY));
    assert_eq!(thumb_tip.radius, 0.01);
}

#[test]
fn openxr_joints_by_name_and_in_order_skip_the_palm() {
    let mut r = empty();
    parse_record(&joints_json(&openxr::JOINT_NAMES, None), Side::Right, &NO_GLOVE, &mut r).unwrap();
    let Some(HandData::Joints(set)) = r.hand else { panic!() };
    // OpenXR joint k (k ≥ 1) is WebXR joint k − 1; its position was written as k · 0.01.
    assert_eq!(set.get(0).unwrap().position.x, 0.01);
    assert_eq!(set.get(24).unwrap().position.x, 0.25);

    let array: Vec<String> = (0..26).map(|k| format!("{{\"p\": [{}, 0, 0]}}", k as f32)).collect();
    parse_record(&format!("{{\"t\": 0, \"joints\": [{}]}}", array.join(",")), Side::Right, &NO_GLOVE, &mut r).unwrap();
    let Some(HandData::Joints(set)) = r.hand else { panic!() };
    assert_eq!(set.get(0).unwrap().position.x, 1.0, "OpenXR order: the palm (0) is dropped");
    assert_eq!(set.get(0).unwrap().orientation, None);
    assert_eq!(r.side, Side::Right, "the reader's side when the record names none");

    let array: Vec<String> = (0..25).map(|k| format!("{{\"p\": [{}, 0, 0]}}", k as f32)).collect();
    parse_record(&format!("{{\"t\": 0, \"joints\": [{}]}}", array.join(",")), Side::Right, &NO_GLOVE, &mut r).unwrap();
    let Some(HandData::Joints(set)) = r.hand else { panic!() };
    assert_eq!(set.get(0).unwrap().position.x, 0.0, "WebXR order");
}

#[test]
fn landmarks_glove_and_tracker() {
    let mut r = empty();
    let points: Vec<String> = (0..21).map(|i| format!("[{}, 0.5, 0]", i as f32 * 0.001)).collect();
    parse_record(&format!("{{\"t\": 2, \"landmarks\": [{}]}}", points.join(",")), Side::Left, &NO_GLOVE, &mut r).unwrap();
    let Some(HandData::Landmarks(l)) = r.hand else { panic!() };
    assert!((l[20] - Vec3::new(0.02, 0.5, 0.0)).length() < 1e-7);
    assert_eq!(r.side, Side::Left);

    let sensors = ["a", "b", "c"];
    parse_record(r#"{"t": 3, "glove": {"c": 3, "a": 1, "b": 2}, "tracker": {"p": [1, 2, 3], "q": [0, 0, 0, 1]}}"#, Side::Right, &sensors, &mut r).unwrap();
    let Some(HandData::Glove(g)) = r.hand else { panic!() };
    assert_eq!(g.values(), &[1.0, 2.0, 3.0], "by name, in the glove's order");
    assert_eq!(r.tracker.unwrap().position, Vec3::new(1.0, 2.0, 3.0));
    parse_record(r#"{"t": 3, "glove": [7, 8, 9]}"#, Side::Right, &sensors, &mut r).unwrap();
    let Some(HandData::Glove(g)) = r.hand else { panic!() };
    assert_eq!(g.values(), &[7.0, 8.0, 9.0]);
    parse_record(r#"{"t": 4, "tracker": {"p": [0, 1, 0], "q": [0, 0.7071068, 0, 0.7071068]}}"#, Side::Right, &sensors, &mut r).unwrap();
    assert!(r.hand.is_none() && r.tracker.is_some(), "a tracker-only record");
    assert_eq!(r.arrival, None);
    parse_record(r#"{"t": 4, "tracker": {"p": [0, 1, 0], "q": [0, 0, 0, 1]}, "arrival": 12.5}"#, Side::Right, &sensors, &mut r).unwrap();
    assert_eq!(r.arrival, Some(12.5), "a live recording's arrival time");
}

/// Each bad record is refused with its kind and a message naming the problem.
#[test]
fn bad_records_are_refused_by_kind() {
    let sensors = ["a", "b"];
    let cases: &[(&str, RejectKind, &str)] = &[
        (r#"{"t": 1, "joints": {"wrist": {"p": [0, 0"#, RejectKind::Malformed, "truncated"),
        ("not json", RejectKind::Malformed, "malformed"),
        (r#"{"t": 1, "landmarks": [[0,0,0]], "extra": 1}"#, RejectKind::Malformed, "malformed"),
        (r#"{"t": -1, "tracker": {"p": [0,0,0], "q": [0,0,0,1]}}"#, RejectKind::OutOfRange, "negative"),
        (r#"{"t": 1, "arrival": -0.5, "tracker": {"p": [0,0,0], "q": [0,0,0,1]}}"#, RejectKind::OutOfRange, "arrival: -0.5 is negative"),
        (r#"{"t": 1, "arrival": "now", "tracker": {"p": [0,0,0], "q": [0,0,0,1]}}"#, RejectKind::Malformed, "malformed"),
        (r#"{"t": 1, "hand": "both", "tracker": {"p": [0,0,0], "q": [0,0,0,1]}}"#, RejectKind::UnknownName, "both"),
        (r#"{"t": 1, "joints": {"wrist": {"p": [0,0,0]}, "thumb-nail": {"p": [0,0,0]}}}"#, RejectKind::UnknownName, "thumb-nail"),
        (r#"{"t": 1, "joints": {"wrist": {"p": [0,0,0]}}}"#, RejectKind::Malformed, "thumb-metacarpal is missing"),
        (r#"{"t": 1, "joints": [{"p": [0,0,0]}]}"#, RejectKind::ColumnCount, "1 entries"),
        (r#"{"t": 1, "tracker": {"p": [0,0,1e39], "q": [0,0,0,1]}}"#, RejectKind::NonFinite, "tracker"),
        (r#"{"t": 1, "tracker": {"p": [0,0,200], "q": [0,0,0,1]}}"#, RejectKind::OutOfRange, "100 m"),
        (r#"{"t": 1, "tracker": {"p": [0,0,0], "q": [0,0,0,2]}}"#, RejectKind::OutOfRange, "unit quaternion"),
        (r#"{"t": 1, "glove": {"a": 1, "z": 2}}"#, RejectKind::UnknownName, "\"z\""),
        (r#"{"t": 1, "glove": {"a": 1}}"#, RejectKind::Malformed, "\"b\" is missing"),
        (r#"{"t": 1, "glove": [1, 2, 3]}"#, RejectKind::ColumnCount, "3 values"),
        (r#"{"t": 1}"#, RejectKind::Malformed, "needs joints"),
        (r#"{"t": 1, "glove": [1, 2], "landmarks": []}"#, RejectKind::Malformed, "malformed"),
    ];
    for (line, kind, needle) in cases {
        let mut r = empty();
        let e = parse_record(line, Side::Right, &sensors, &mut r).unwrap_err();
        assert_eq!(e.kind, *kind, "{line}: {e}");
        assert!(e.message.contains(needle), "{line}: {e:?} lacks {needle:?}");
        assert_eq!(r, empty(), "{line}: a refused record leaves the output alone");
    }
    let e = parse_record(r#"{"t": 1, "glove": [1, 2]}"#, Side::Right, &NO_GLOVE, &mut empty()).unwrap_err();
    assert!(e.message.contains("no glove"), "{e}");
}

/// A reader goes on after bad lines; each rejection names its line; over-long lines are
/// skipped without being held.
#[test]
fn the_reader_goes_on_after_bad_lines() {
    let good = r#"{"t": 1, "tracker": {"p": [0,0,0], "q": [0,0,0,1]}}"#;
    let long = format!("{{\"t\": 2, \"pad\": \"{}\"}}", "x".repeat(MAX_RECORD_BYTES * 3));
    let text = format!("{good}\n\nnot json\n{long}\n\u{0}\u{ff}\n{good}\n{{\"t\": 3, \"tracker\"");
    let mut bytes = text.into_bytes();
    let bad_utf8 = bytes.iter().position(|&b| b == 0).unwrap();
    bytes[bad_utf8 + 1] = 0xff;
    let mut reader = JsonRecordReader::new(std::io::Cursor::new(bytes), Side::Right, Vec::new());
    let mut r = empty();
    let mut results = Vec::new();
    while let Some(result) = reader.next_record(&mut r).unwrap() {
        results.push(result.map_err(|e| (e.kind, e.message)));
    }
    assert!(results[0].is_ok());
    assert_eq!(results[1].as_ref().unwrap_err().0, RejectKind::Malformed);
    assert!(results[1].as_ref().unwrap_err().1.starts_with("line 3: "), "{:?}", results[1]);
    assert_eq!(results[2].as_ref().unwrap_err().0, RejectKind::TooLarge);
    assert!(results[2].as_ref().unwrap_err().1.starts_with("line 4: "));
    assert_eq!(results[3].as_ref().unwrap_err().0, RejectKind::Malformed);
    assert!(results[3].as_ref().unwrap_err().1.contains("UTF-8"));
    assert!(results[4].is_ok(), "{:?}", results[4]);
    assert!(results[5].as_ref().unwrap_err().1.contains("truncated"));
    assert_eq!(results.len(), 6);
}

#[test]
fn written_records_read_back() {
    let sensors = ["a", "b"];
    let mut r = empty();
    let mut lines = Vec::new();
    for line in [
        joints_json(&webxr::JOINT_NAMES, None),
        r#"{"t": 3, "hand": "right", "glove": [1.5, 4095], "tracker": {"p": [1, 2, 3], "q": [0, 0, 0, 1]}, "arrival": 3.0416666666666665}"#.to_owned(),
    ] {
        parse_record(&line, Side::Right, &sensors, &mut r).unwrap();
        let mut out = Vec::new();
        write_record(&mut out, &r, &sensors).unwrap();
        let mut back = empty();
        parse_record(std::str::from_utf8(&out).unwrap().trim_end(), Side::Right, &sensors, &mut back).unwrap();
        assert_eq!(back, r);
        lines.push(out);
    }
    assert!(lines.iter().all(|l| l.ends_with(b"\n") && l.iter().filter(|&&b| b == b'\n').count() == 1));
}

/// Found by the `json_record` fuzz target on the first line of the sample joints recording:
/// parsing normalised every orientation again, and normalising this already unit quaternion
/// moved its last bits, so a written record did not read back equal.
#[test]
fn fuzz_json_record_a_written_unit_quaternion_reads_back_bit_for_bit() {
    let q = [-0.286_056_5_f32, 0.336_425_07, 0.553_402_8, 0.706_211_86];
    assert!((Quat::from_array(q).length() - 1.0).abs() < 1e-6);
    assert_ne!(Quat::from_array(q).normalize().to_array(), q, "the case needs a quaternion that normalising moves");
    let line = format!(r#"{{"t": 0, "tracker": {{"p": [0, 0, 0], "q": [{}, {}, {}, {}]}}}}"#, q[0], q[1], q[2], q[3]);
    let mut r = empty();
    parse_record(&line, Side::Right, &NO_GLOVE, &mut r).unwrap();
    assert_eq!(r.tracker.unwrap().orientation.to_array(), q);
}

/// The One Euro filter on a 3-vector, written from the paper's equations with the derivative
/// low-passed per component and its length setting the one cutoff (f64 throughout).
struct ReferenceVec3 {
    freq_min: f64,
    beta: f64,
    d_cutoff: f64,
    x_prev: Option<[f64; 3]>,
    dx_prev: [f64; 3],
}

impl ReferenceVec3 {
    fn filter(&mut self, x: [f64; 3], dt: f64) -> [f64; 3] {
        let Some(prev) = self.x_prev else {
            self.x_prev = Some(x);
            return x;
        };
        let a_d = Reference::alpha(self.d_cutoff, dt);
        let edx: [f64; 3] = std::array::from_fn(|k| a_d * (x[k] - prev[k]) / dt + (1.0 - a_d) * self.dx_prev[k]);
        self.dx_prev = edx;
        let speed = edx.iter().map(|v| v * v).sum::<f64>().sqrt();
        let a = Reference::alpha(self.freq_min + self.beta * speed, dt);
        let out = std::array::from_fn(|k| a * x[k] + (1.0 - a) * prev[k]);
        self.x_prev = Some(out);
        out
    }
}

#[test]
fn a_still_noisy_position_trembles_less_than_the_noise_and_settles_where_it_is() {
    // The velocity is low-passed as a vector: a still point's noise averages out of it, so
    // the cutoff stays near its minimum (low-passing each step's speed, never negative,
    // would raise it with the noise).
    let mut f = OneEuroVec3::new(OneEuroParams::POSITION);
    let mut rng = dqhand::math::Rng::new(7);
    let sigma = 0.0015 / 3f32.sqrt();
    let at = Vec3::new(0.1, 1.0, -0.3);
    // Offsets from the true point, in f64: the mean of squares would cancel in f32.
    let (mut sum, mut square, mut n) = (glam::DVec3::ZERO, 0.0f64, 0.0f64);
    for k in 0..600 {
        let x = at + rng.normal_vec3() * sigma;
        let y = (f.filter(x, 1.0 / 60.0) - at).as_dvec3();
        if k >= 60 {
            sum += y;
            square += y.length_squared();
            n += 1.0;
        }
    }
    let mean = sum / n;
    let tremble = (square / n - mean.length_squared()).max(0.0).sqrt();
    assert!(mean.length() < 0.0005, "{mean:?}");
    assert!(tremble < 0.0005, "tremble {tremble} m against 1.5 mm of noise");
}

proptest! {
    /// Any record that parses is written as a line that parses back to the same record, with
    /// orientations unit or off unit length by up to 5 % (the parser takes 10 %).
    #[test]
    fn parsed_orientations_read_back_equal(v in support::vec3(1.0), w in -1.0f32..1.0, scale in 0.95f32..1.05) {
        let q = Quat::from_xyzw(v.x, v.y, v.z, w);
        prop_assume!(q.length() > 0.1);
        let q = q.normalize() * scale;
        let line = format!(r#"{{"t": 1, "tracker": {{"p": [0, 1, 0], "q": [{}, {}, {}, {}]}}}}"#, q.x, q.y, q.z, q.w);
        let mut r = empty();
        parse_record(&line, Side::Right, &NO_GLOVE, &mut r).unwrap();
        let mut out = Vec::new();
        write_record(&mut out, &r, &NO_GLOVE).unwrap();
        let mut back = empty();
        parse_record(std::str::from_utf8(&out).unwrap().trim_end(), Side::Right, &NO_GLOVE, &mut back).unwrap();
        prop_assert_eq!(back, r);
    }
}

proptest! {
    /// Byte soup never panics the parser or the reader.
    #[test]
    fn arbitrary_text_never_panics(text in "\\PC{0,400}", bytes in proptest::collection::vec(any::<u8>(), 0..400)) {
        let mut r = empty();
        let _ = parse_record(&text, Side::Right, &["a"], &mut r);
        let mut reader = JsonRecordReader::new(std::io::Cursor::new(bytes), Side::Right, vec!["a".into()]);
        while let Some(_) = reader.next_record(&mut r).unwrap() {}
    }
}

/// Casiez et al.'s pseudo-code, transcribed plainly (the reference).
struct Reference {
    freq_min: f64,
    beta: f64,
    d_cutoff: f64,
    x_prev: Option<f64>,
    dx_prev: f64,
}

impl Reference {
    fn alpha(cutoff: f64, dt: f64) -> f64 {
        let tau = 1.0 / (2.0 * std::f64::consts::PI * cutoff);
        1.0 / (1.0 + tau / dt)
    }
    fn filter(&mut self, x: f64, dt: f64) -> f64 {
        let Some(prev) = self.x_prev else {
            self.x_prev = Some(x);
            return x;
        };
        let dx = (x - prev) / dt;
        let a_d = Self::alpha(self.d_cutoff, dt);
        let edx = a_d * dx + (1.0 - a_d) * self.dx_prev;
        self.dx_prev = edx;
        let cutoff = self.freq_min + self.beta * edx.abs();
        let a = Self::alpha(cutoff, dt);
        let out = a * x + (1.0 - a) * prev;
        self.x_prev = Some(out);
        out
    }
}

proptest! {
    #[test]
    fn one_euro_matches_the_reference(
        samples in proptest::collection::vec((-2.0f32..2.0, 0.002f32..0.05), 1..200),
        min_cutoff in 0.1f32..5.0, beta in 0.0f32..5.0, d_cutoff in 0.5f32..3.0,
    ) {
        let params = OneEuroParams { min_cutoff, beta, d_cutoff };
        let mut f = OneEuro::new(params);
        let mut v = OneEuroVec3::new(params);
        let mut reference = Reference { freq_min: min_cutoff.into(), beta: beta.into(), d_cutoff: d_cutoff.into(), x_prev: None, dx_prev: 0.0 };
        let mut reference_speed = Reference { freq_min: min_cutoff.into(), beta: beta.into(), d_cutoff: d_cutoff.into(), x_prev: None, dx_prev: 0.0 };
        let direction = Vec3::new(0.6, 0.0, -0.8);
        let mut d = 3.0f32;
        for &(x, dt) in &samples {
            let expected = reference.filter(x.into(), dt.into()) as f32;
            prop_assert!((f.filter(x, dt) - expected).abs() < 1e-3 * (1.0 + expected.abs()));
            // Moving away along a fixed direction, the position filter is the scalar filter on
            // the distance (its speed, the velocity's length, is the scalar's |dx/dt| there).
            d += x.abs() * 0.1;
            let expected = reference_speed.filter(d.into(), dt.into()) as f32;
            let got = v.filter(direction * d, dt);
            prop_assert!((got - direction * expected).length() < 1e-3 * (1.0 + expected));
        }
    }

    /// On any path, the position filter is the reference's, velocity per component.
    #[test]
    fn position_filter_matches_the_reference_on_any_path(
        steps in proptest::collection::vec((support::vec3(0.05), 0.002f32..0.05), 1..150),
        min_cutoff in 0.1f32..5.0, beta in 0.0f32..50.0, d_cutoff in 0.5f32..3.0,
    ) {
        let mut v = OneEuroVec3::new(OneEuroParams { min_cutoff, beta, d_cutoff });
        let mut reference = ReferenceVec3 { freq_min: min_cutoff.into(), beta: beta.into(), d_cutoff: d_cutoff.into(), x_prev: None, dx_prev: [0.0; 3] };
        let mut x = Vec3::new(0.0, 1.0, 0.0);
        for &(step, dt) in &steps {
            x += step;
            let want = reference.filter(x.as_dvec3().to_array(), dt.into());
            let got = v.filter(x, dt);
            prop_assert!((got.as_dvec3() - glam::DVec3::from(want)).length() < 1e-4, "got {got:?}, want {want:?}");
        }
    }

    /// About a fixed axis, the rotation filter is the scalar filter on the angle, and it
    /// stays on the unit sphere.
    #[test]
    fn rotation_filter_is_the_scalar_filter_about_a_fixed_axis(
        angles in proptest::collection::vec((0.0f32..0.02, 0.005f32..0.05), 1..120),
        axis in support::vec3(1.0),
    ) {
        prop_assume!(axis.length() > 0.1);
        let axis = axis.normalize();
        let params = OneEuroParams::ROTATION;
        let mut q = OneEuroRotation::new(params);
        let mut reference = Reference { freq_min: params.min_cutoff.into(), beta: params.beta.into(), d_cutoff: params.d_cutoff.into(), x_prev: None, dx_prev: 0.0 };
        let mut sum = 0.0f32;
        for &(step, dt) in &angles {
            sum += step; // turning one way, below π: the short arc is the scalar's path
            let expected = reference.filter(sum.into(), dt.into()) as f32;
            let got = q.filter(Quat::from_axis_angle(axis, sum), dt);
            prop_assert!((got.length() - 1.0).abs() < 1e-4);
            let want = Quat::from_axis_angle(axis, expected);
            prop_assert!(got.angle_between(want) < 2e-3, "got {got:?}, want angle {expected}");
        }
    }
}

#[test]
fn the_mounting_offset_puts_the_wrist_where_it_was_calibrated() {
    let sensor = RigidPose { position: Vec3::new(0.1, 1.2, -0.3), orientation: Quat::from_rotation_x(0.4) * Quat::from_rotation_y(-1.0) };
    let wrist = DualQuat::from_rotation_translation(Quat::from_rotation_z(0.3), Vec3::new(0.1, 1.17, -0.31));
    let offset = MountingOffset::calibrate(sensor, wrist);
    assert!(offset.is_valid());
    let (r0, t0) = wrist.to_rotation_translation();
    let (r1, t1) = offset.wrist(sensor).to_rotation_translation();
    assert!(r0.angle_between(r1) < 1e-4 && (t0 - t1).length() < 1e-5);
    // Moving the sensor moves the wrist rigidly with it.
    let moved = RigidPose { position: sensor.position + Vec3::X, orientation: sensor.orientation };
    assert!((offset.wrist(moved).translation() - (t0 + Vec3::X)).length() < 1e-5);
    // The default: the joint 2 cm below a sensor lying flat on the back of the wrist.
    let flat = RigidPose { position: Vec3::new(0.0, 1.0, 0.0), orientation: Quat::IDENTITY };
    assert!((MountingOffset::default().wrist(flat).translation() - Vec3::new(0.0, 0.98, 0.0)).length() < 1e-6);
}
