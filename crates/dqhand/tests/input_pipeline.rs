//! The input pipeline: records refused by kind, the hand held and marked lost on dropouts,
//! a smooth return, filtering, the glove and tracker path.

mod support;

use std::sync::OnceLock;

use dqhand::gesture::gesture;
use dqhand::hand::{HandParams, Side};
use dqhand::input::{Calibration, GloveMapper, GloveSample, HandData, InputConfig, InputPipeline, JointSet, MappingTable, Record, RejectKind, RigidPose, TrackedJoint, Tracking};
use dqhand::kinematics::{webxr, HandRig, JointModel, Limits, Pose};
use dqhand::model::Model;
use glam::{Quat, Vec3};

fn ours() -> &'static Model {
    static M: OnceLock<Model> = OnceLock::new();
    M.get_or_init(|| dqhand::hand::build(&HandParams { vertices: 1_000, ..HandParams::default() }).unwrap())
}

fn rig() -> HandRig {
    HandRig::new(&ours().skeleton, JointModel::Full).unwrap()
}

/// `record` as a live input takes it, at `arrival` (s) on its own clock.
fn arriving(record: Record, arrival: f64) -> Record {
    Record { arrival: Some(arrival), ..record }
}

fn joints_record(time: f64, pose: &Pose) -> Record {
    let rig = rig();
    let world = support::world_of(&rig, pose, Limits::Anatomical);
    let mut set = JointSet::new();
    for (i, name) in webxr::JOINT_NAMES.iter().enumerate() {
        let p: Vec3 = world[rig.skeleton().find(name).unwrap()].translation.into();
        set.set(i, TrackedJoint { position: p, orientation: None, radius: 0.0 });
    }
    Record { time, side: Side::Right, hand: Some(HandData::Joints(set)), tracker: None, arrival: None }
}

fn unfiltered() -> InputConfig {
    InputConfig { filter: false, ..InputConfig::default() }
}

fn max_diff_deg(a: &Pose, b: &Pose) -> f32 {
    a.angles.iter().zip(&b.angles).map(|(x, y)| (x - y).abs().to_degrees()).fold(0.0, f32::max)
}

#[test]
fn out_of_order_flood_and_late_records_are_refused_and_counted() {
    let mut p = InputPipeline::new(&rig(), None, unfiltered()).unwrap();
    let fist = gesture("fist").unwrap().pose(JointModel::Full);
    let point = gesture("point").unwrap().pose(JointModel::Full);
    assert_eq!(p.tracking(), Tracking::Waiting);
    p.push(&joints_record(1.0, &fist)).unwrap();
    assert_eq!(p.tracking(), Tracking::Tracking);
    for (record, kind) in [
        (joints_record(0.5, &point), RejectKind::OutOfOrder),
        (joints_record(1.0, &point), RejectKind::OutOfOrder),
        (joints_record(1.0002, &point), RejectKind::Flood),
    ] {
        assert_eq!(p.push(&record).unwrap_err().kind, kind);
        assert!(max_diff_deg(p.pose(), &fist) < 0.5, "a refused record leaves the pose alone");
    }
    // Live: the clock offset is the fastest delivery; 0.3 s slower than that is late.
    p.push(&arriving(joints_record(2.0, &fist), 102.01)).unwrap();
    p.push(&arriving(joints_record(2.1, &fist), 102.10)).unwrap();
    p.push(&arriving(joints_record(2.15, &fist), 102.33)).unwrap(); // 0.18 s slow: taken
    // (Within the grace time of the last arrival: later, the hand is lost and a late record
    // starts a new stream.)
    assert_eq!(p.push(&arriving(joints_record(2.2, &point), 102.55)).unwrap_err().kind, RejectKind::Late);
    p.push(&arriving(joints_record(2.5, &point), 102.56)).unwrap();
    let r = p.rejections();
    assert_eq!((r.count(RejectKind::OutOfOrder), r.count(RejectKind::Flood), r.count(RejectKind::Late), r.total()), (2, 1, 1, 4));
    assert_eq!(r.summary().count(), 3, "one line per kind");
    assert_eq!(p.accepted(), 5);
}

#[test]
fn a_dropout_holds_the_pose_marks_it_lost_and_recovers_smoothly() {
    let config = unfiltered();
    let (grace, recover) = (config.grace_s, f64::from(config.recover_s));
    let mut p = InputPipeline::new(&rig(), None, config).unwrap();
    let fist = gesture("fist").unwrap().pose(JointModel::Full);
    let open = gesture("open_palm").unwrap().pose(JointModel::Full);
    let mut t = 0.0;
    while t < 1.0 {
        p.push(&joints_record(t, &fist)).unwrap();
        t += 1.0 / 60.0;
    }
    let last = t - 1.0 / 60.0;
    p.advance(last + grace * 0.5);
    assert_eq!(p.tracking(), Tracking::Tracking, "within the grace time");
    p.advance(last + grace * 1.5);
    assert_eq!(p.tracking(), Tracking::Lost);
    assert!(max_diff_deg(p.pose(), &fist) < 0.5, "the hand holds its last good pose");
    // Records return with another shape: the hand blends over `recover_s`, no jump.
    let back = last + 1.0;
    let mut previous = p.pose().clone();
    let mut t = back;
    let mut largest_step = 0.0f32;
    while t < back + recover + 0.2 {
        p.push(&joints_record(t, &open)).unwrap();
        assert_eq!(p.tracking(), Tracking::Tracking);
        largest_step = largest_step.max(max_diff_deg(p.pose(), &previous));
        previous = p.pose().clone();
        t += 1.0 / 60.0;
    }
    let jump = max_diff_deg(&fist, &open);
    assert!(largest_step < jump / 5.0, "largest step {largest_step}° of a {jump}° change");
    assert!(max_diff_deg(p.pose(), &open) < 0.5, "after the blend the hand follows again");
}

#[test]
fn a_hand_lost_for_good_relaxes_its_fingers_where_it_was() {
    let config = unfiltered();
    let (grace, rest_after, recover) = (config.grace_s, config.rest_after_s, f64::from(config.recover_s));
    let mut p = InputPipeline::new(&rig(), None, config).unwrap();
    let mut fist = gesture("fist").unwrap().pose(JointModel::Full);
    fist.wrist = Some(dqhand::math::DualQuat::from_rotation_translation(Quat::from_rotation_y(0.7), Vec3::new(0.1, 1.2, -0.3)));
    // Live, arriving as captured.
    p.push(&arriving(joints_record(0.0, &fist), 0.0)).unwrap();
    p.push(&arriving(joints_record(0.1, &fist), 0.1)).unwrap();
    let wrist = p.pose().wrist;
    p.advance(0.1 + grace + rest_after - 0.01);
    assert_eq!(p.tracking(), Tracking::Lost);
    assert!(max_diff_deg(p.pose(), &fist) < 0.5, "a short dropout holds the pose");
    // A record of another stream (its clock restarted) that is refused changes nothing: the
    // relax is timed from the loss all the same.
    let mut unusable = joints_record(0.0, &fist);
    let Some(HandData::Joints(set)) = &mut unusable.hand else { unreachable!() };
    for i in 0..25 {
        set.set(i, TrackedJoint { position: Vec3::ZERO, orientation: None, radius: 0.0 });
    }
    assert_eq!(p.push(&arriving(unusable, 0.1 + grace + 0.1)).unwrap_err().kind, RejectKind::Unusable);
    p.advance(0.1 + grace + rest_after + recover / 2.0);
    let halfway = p.pose().angles.iter().zip(&fist.angles).filter(|(_, f)| f.abs() > 0.1).map(|(a, f)| a / f).collect::<Vec<_>>();
    assert!(halfway.iter().all(|r| (r - 0.5).abs() < 0.01), "half way through the ease, half the bend: {halfway:?}");
    p.advance(0.1 + grace + rest_after + recover + 0.01);
    assert!(max_diff_deg(p.pose(), &Pose::rest(fist.angles.len())) < 1e-3, "at rest");
    assert_eq!(p.pose().wrist, wrist, "the wrist stays where the hand was lost");
    // Records return: the hand blends from rest to them.
    p.push(&arriving(joints_record(3.0, &fist), 3.0)).unwrap();
    assert!(max_diff_deg(p.pose(), &Pose::rest(fist.angles.len())) < 1.0);
}

#[test]
fn unusable_geometry_is_refused() {
    let mut p = InputPipeline::new(&rig(), None, unfiltered()).unwrap();
    let mut r = joints_record(0.0, &Pose::rest(JointModel::Full.dof_count()));
    let Some(HandData::Joints(set)) = &mut r.hand else { unreachable!() };
    let wrist = set.get(0).unwrap().position;
    for i in 0..25 {
        set.set(i, TrackedJoint { position: wrist, orientation: None, radius: 0.0 });
    }
    assert_eq!(p.push(&r).unwrap_err().kind, RejectKind::Unusable);
    assert_eq!(p.tracking(), Tracking::Waiting);
}

/// The filter smooths jitter on a held pose and follows a change.
#[test]
fn the_filter_smooths_jitter() {
    let mut filtered = InputPipeline::new(&rig(), None, InputConfig::default()).unwrap();
    let mut raw = InputPipeline::new(&rig(), None, unfiltered()).unwrap();
    let pose = gesture("victory").unwrap().pose(JointModel::Full);
    let mut rng = 0x2545_f491_u32;
    let mut noise = || {
        rng ^= rng << 13;
        rng ^= rng >> 17;
        rng ^= rng << 5;
        (rng as f32 / u32::MAX as f32 - 0.5) * 0.003 // ±1.5 mm
    };
    let (mut raw_jitter, mut filtered_jitter) = (0.0f32, 0.0f32);
    let (mut last_raw, mut last_filtered) = (None::<Pose>, None::<Pose>);
    for k in 0..240 {
        let mut r = joints_record(f64::from(k) / 60.0, &pose);
        let Some(HandData::Joints(set)) = &mut r.hand else { unreachable!() };
        for i in 0..25 {
            let j = *set.get(i).unwrap();
            set.set(i, TrackedJoint { position: j.position + Vec3::new(noise(), noise(), noise()), ..j });
        }
        raw.push(&r).unwrap();
        filtered.push(&r).unwrap();
        if k > 60 {
            raw_jitter += max_diff_deg(raw.pose(), last_raw.as_ref().unwrap());
            filtered_jitter += max_diff_deg(filtered.pose(), last_filtered.as_ref().unwrap());
        }
        last_raw = Some(raw.pose().clone());
        last_filtered = Some(filtered.pose().clone());
    }
    assert!(filtered_jitter < raw_jitter / 3.0, "jitter raw {raw_jitter}, filtered {filtered_jitter}");
    assert!(max_diff_deg(filtered.pose(), &pose) < 6.0);
}

/// Glove values become angles through the mapper; the tracker, through the mounting offset,
/// becomes the wrist.
#[test]
fn glove_and_tracker_records_pose_the_hand() {
    let table = MappingTable::builtin("5dt-14").unwrap();
    let calibration = Calibration::default_for(&table);
    let mapper = GloveMapper::new(&table, &calibration, JointModel::Full).unwrap();
    let config = unfiltered();
    let mount = config.tracker_mount;
    let mut p = InputPipeline::new(&rig(), Some(mapper.clone()), config).unwrap();
    let fist_raw = GloveSample::new(&[4095.0; 14]);
    let tracker = RigidPose { position: Vec3::new(0.1, 1.0, -0.2), orientation: Quat::from_rotation_y(0.5) };
    p.push(&Record { time: 0.0, side: Side::Right, hand: Some(HandData::Glove(fist_raw)), tracker: Some(tracker), arrival: None }).unwrap();
    let mut expected = vec![0.0; JointModel::Full.dof_count()];
    mapper.map(&fist_raw, &mut expected).unwrap();
    assert_eq!(p.pose().angles, expected);
    assert_eq!(p.pose().wrist, Some(mount.wrist(tracker)));
    let index_pip = JointModel::Full.dof_index("index-finger-phalanx-intermediate.flex").unwrap();
    assert!(p.pose().angles[index_pip] > 1.0, "a fist curls the index");
    // A raw value outside 0–4095 is refused and the pose kept.
    let bad = GloveSample::new(&[5000.0; 14]);
    let e = p.push(&Record { time: 0.1, side: Side::Right, hand: Some(HandData::Glove(bad)), tracker: None, arrival: None }).unwrap_err();
    assert_eq!(e.kind, RejectKind::OutOfRange);
    assert_eq!(p.pose().angles, expected);
    // A glove record without a configured glove is refused.
    let mut bare = InputPipeline::new(&rig(), None, unfiltered()).unwrap();
    assert!(bare.push(&Record { time: 0.0, side: Side::Right, hand: Some(HandData::Glove(fist_raw)), tracker: None, arrival: None }).is_err());
    // A glove for another joint model is a configuration error.
    let paper = GloveMapper::new(&table, &calibration, JointModel::Paper).unwrap();
    assert!(InputPipeline::new(&rig(), Some(paper), unfiltered()).is_err());
}
/// A stream slower than the grace time (a camera inferring at 1.25 frames a second): with
/// the grace fixed, every record found the hand lost and blended back from the held pose, so
/// the hand never moved. The grace follows the stream's rate, and the hand follows it; when
/// the stream stops, it is lost after that longer grace, and a fast stream's grace is
/// `grace_s` again.
#[test]
fn a_slow_stream_keeps_tracking_and_drives_the_hand() {
    let config = unfiltered();
    let mut p = InputPipeline::new(&rig(), None, config.clone()).unwrap();
    let fist = gesture("fist").unwrap().pose(JointModel::Full);
    let open = gesture("open_palm").unwrap().pose(JointModel::Full);
    let interval = 0.8;
    let (mut now, mut lost_between) = (0.0, 0);
    for k in 0..12 {
        let t = f64::from(k) * interval;
        // The engine's frames advance the hand at 60 Hz between records.
        while now < t {
            p.advance(now);
            lost_between += usize::from(k >= 6 && p.tracking() == Tracking::Lost);
            now += 1.0 / 60.0;
        }
        p.push(&arriving(joints_record(t, if k < 8 { &fist } else { &open }), t)).unwrap();
    }
    assert_eq!(lost_between, 0, "tracking lost between the records of a steady slow stream");
    assert!((p.grace() - 2.5 * interval).abs() < 1e-9, "grace {}", p.grace());
    assert!(max_diff_deg(p.pose(), &open) < 0.5, "the slow stream drives the hand ({}° off)", max_diff_deg(p.pose(), &open));
    let last = 11.0 * interval;
    p.advance(last + p.grace() - 0.01);
    assert_eq!(p.tracking(), Tracking::Tracking);
    p.advance(last + p.grace() + 0.01);
    assert_eq!(p.tracking(), Tracking::Lost);
    // The sender restarts its clock: a new stream, `grace_s` until its rate is known again.
    p.push(&arriving(joints_record(0.0, &fist), 100.0)).unwrap();
    assert_eq!(p.grace(), config.grace_s, "a new stream's grace");
}

/// The grace time of a stream: `grace_s` until 4 intervals are known, then 2.5 times their
/// median (capped at 2 s), on the arrival clock live and the capture clock from a file; a fast
/// stream's dropout does not lengthen it.
#[test]
fn the_grace_time_follows_the_streams_rate() {
    let config = unfiltered();
    let fist = gesture("fist").unwrap().pose(JointModel::Full);
    // `interval` apart, live (arriving 50 ms after capture) or from a file; the grace after each.
    let graces = |interval: f64, live: bool, records: usize| {
        let mut p = InputPipeline::new(&rig(), None, config.clone()).unwrap();
        (0..records)
            .map(|k| {
                let t = k as f64 * interval;
                let record = joints_record(t, &fist);
                p.push(&if live { arriving(record, t + 0.05) } else { record }).unwrap();
                p.grace()
            })
            .collect::<Vec<_>>()
    };
    for live in [true, false] {
        let g = graces(0.4, live, 8);
        assert!(g[..4].iter().all(|&x| x == config.grace_s), "live {live}: before 4 intervals {g:?}");
        assert!(g[4..].iter().all(|&x| (x - 1.0).abs() < 1e-9), "live {live}: 2.5 × 0.4 s {g:?}");
        assert_eq!(graces(1.5, live, 6)[5], 2.0, "live {live}: the cap");
        assert_eq!(graces(1.0 / 60.0, live, 20)[19], config.grace_s, "live {live}: a fast stream");
    }
    // A fast stream with one 3 s gap in its records (the hand lost and found) keeps `grace_s`,
    // and is lost that long after its records stop.
    let mut p = InputPipeline::new(&rig(), None, config.clone()).unwrap();
    let times = (0..20).map(|k| f64::from(k) / 60.0).chain((0..20).map(|k| 3.5 + f64::from(k) / 60.0));
    for t in times {
        p.push(&arriving(joints_record(t, &fist), t)).unwrap();
    }
    assert_eq!(p.grace(), config.grace_s);
    let last = 3.5 + 19.0 / 60.0;
    p.advance(last + config.grace_s + 0.01);
    assert_eq!(p.tracking(), Tracking::Lost);
}

/// A live sender whose clock jumps ahead is refused; "lost" follows the arrival clock, so no
/// capture time holds the hand in "tracking"; once lost, a sender that restarted its clock at
/// zero (or another sender) is taken as a new stream.
#[test]
fn live_streams_jump_restart_and_go_lost_by_the_arrival_clock() {
    let config = unfiltered();
    let grace = config.grace_s;
    let mut p = InputPipeline::new(&rig(), None, config).unwrap();
    let fist = gesture("fist").unwrap().pose(JointModel::Full);
    let open = gesture("open_palm").unwrap().pose(JointModel::Full);
    // Arrival = capture + 100 s; one record 20 ms faster than the others is still taken.
    p.push(&arriving(joints_record(5.0, &fist), 105.0)).unwrap();
    p.push(&arriving(joints_record(5.1, &fist), 105.08)).unwrap();
    let jump = p.push(&arriving(joints_record(1e300, &open), 105.2)).unwrap_err();
    assert_eq!(jump.kind, RejectKind::OutOfRange, "{jump}");
    assert!(jump.to_string().contains("ahead of the stream's clock"), "{jump}");
    p.push(&arriving(joints_record(5.2, &fist), 105.2)).unwrap();
    // Records that stop: lost after the grace time on the arrival clock.
    p.advance(105.2 + grace * 0.5);
    assert_eq!(p.tracking(), Tracking::Tracking);
    p.advance(105.2 + grace * 1.5);
    assert_eq!(p.tracking(), Tracking::Lost);
    // The sender restarts at t = 0: a new stream, taken, and the hand follows it.
    p.push(&arriving(joints_record(0.0, &open), 300.0)).unwrap();
    assert_eq!(p.tracking(), Tracking::Tracking);
    for k in 1..40 {
        let t = f64::from(k) / 60.0;
        p.push(&arriving(joints_record(t, &open), 300.0 + t)).unwrap();
    }
    assert!(max_diff_deg(p.pose(), &open) < 0.5, "the new stream drives the hand");
    // While tracking, a second sender's clock is refused (out of order), not mixed in.
    assert_eq!(p.push(&arriving(joints_record(0.1, &fist), 300.7)).unwrap_err().kind, RejectKind::OutOfOrder);
}

/// A live stream stalls: records captured 1/30 s apart arrive in a burst after a 2 s stall,
/// so the live input marks the hand lost, lets it relax, and blends back. Written as a live
/// recording (each record with its arrival) and read back, the records replay to exactly the
/// poses shown live, whenever the live input advanced between them; without the arrival
/// times the capture clock sees no stall and the poses differ.
#[test]
fn a_live_recording_replays_to_the_poses_shown_live() {
    use dqhand::input::json_record::{parse_record, write_record};
    let config = InputConfig::default();
    let poses = ["fist", "open_palm", "point"].map(|g| gesture(g).unwrap().pose(JointModel::Full));
    let capture = |i: usize| i as f64 / 30.0;
    let arrival = |i: usize| capture(i) + 0.05 + if (40..60).contains(&i) { 2.0 - (i - 40) as f64 / 30.0 } else if i >= 60 { 1.4 } else { 0.0 };
    let mut live = InputPipeline::new(&rig(), None, config.clone()).unwrap();
    let (mut shown, mut file, mut tick, mut lost) = (Vec::new(), Vec::new(), 0.0, false);
    for i in 0..120 {
        let record = Record { arrival: Some(arrival(i)), ..joints_record(capture(i), &poses[i / 25 % 3]) };
        // The server's frames advance the hand at 120 Hz between records.
        while tick < arrival(i) {
            live.advance(tick);
            lost |= live.tracking() == Tracking::Lost;
            tick += 1.0 / 120.0;
        }
        if live.push(&record).is_ok() {
            shown.push(live.pose().clone());
            write_record(&mut file, &record, &[] as &[&str]).unwrap();
        }
    }
    assert!(lost, "the stall lost the hand");
    assert!(shown.len() >= 100, "{} records taken", shown.len());
    let replay = |with_arrival: bool| {
        let mut p = InputPipeline::new(&rig(), None, config.clone()).unwrap();
        let mut out = Vec::new();
        for line in std::str::from_utf8(&file).unwrap().lines() {
            let mut record = Record { time: 0.0, side: Side::Left, hand: None, tracker: None, arrival: None };
            parse_record(line, Side::Right, &[] as &[&str], &mut record).unwrap();
            assert!(record.arrival.is_some(), "{line}");
            p.push(&Record { arrival: record.arrival.filter(|_| with_arrival), ..record }).unwrap();
            out.push(p.pose().clone());
        }
        out
    };
    assert_eq!(replay(true), shown, "replayed with its arrival times");
    assert_ne!(replay(false), shown, "on the capture clock alone the stall is not seen");
}
