//! Synthetic, labelled recordings of the gesture library, made from our own kinematics: the
//! sample recordings of the demo and the tests, and the sequences `dqhand gesture-bench`
//! scores. They are labelled synthetic wherever they are written.
//!
//! A sequence is a user's hand (random size, proportions and side unless fixed) moving
//! through the library's gestures (and thumbs down) in random order: each reached by an eased
//! move (smoothstep), held, with the wrist turned up to ±25° from a neutral orientation
//! (thumbs up and down keep the thumb pointing up or down), then a stretch of idle motion
//! (a relaxed, half-curled hand drifting slowly), where no gesture should be seen. Every frame
//! adds physiological tremor (9 Hz, per joint) and Gaussian joint noise; some records are
//! dropped. Records carry joints (with orientations), MediaPipe landmarks, or glove values
//! with a wrist tracker.

use glam::{Affine3A, Quat, Vec3};
use serde::{Deserialize, Serialize};

use crate::gesture::{gesture, GESTURES};
use crate::interaction::variation::{varied_pose, Split, VARIED_GESTURES};
use crate::hand::{HandParams, Side};
use crate::input::{mediapipe, Calibration, GloveSample, HandData, JointSet, MappingTable, MountingOffset, Record, RigidPose, TrackedJoint};
use crate::kinematics::{JointModel, JointPositions, Pose};
use crate::math::{DualQuat, Rng};
use crate::Result;

/// What the records carry.
#[derive(Clone, Debug)]
pub enum SyntheticFormat {
    /// The 25 WebXR joints with orientations.
    Joints,
    /// MediaPipe's 21 landmarks.
    Landmarks,
    /// Raw values of a glove (its default calibration) and a wrist tracker.
    Glove(MappingTable),
}

/// How a sequence is made.
#[derive(Clone, Debug)]
pub struct SyntheticParams {
    /// Seed of every random choice: the same seed gives the same sequence.
    pub seed: u64,
    /// The user's hand; `None` draws length 0.16–0.21 m, breadth 42–50 % of it, either side.
    pub hand: Option<HandParams>,
    /// Gestures held, in random order, cycling through the library and thumbs down.
    pub holds: usize,
    /// Seconds each gesture is held after it is reached.
    pub hold_s: f64,
    /// Seconds of the eased move to each gesture.
    pub move_s: f64,
    /// Seconds of idle motion at the end.
    pub idle_s: f64,
    /// Records per second.
    pub rate_hz: f64,
    /// Root-mean-square joint noise, metres (per joint, in 3D).
    pub noise_m: f32,
    /// Tremor amplitude per joint angle, degrees.
    pub tremor_deg: f32,
    /// Largest wrist turn from the neutral orientation, degrees.
    pub wrist_turn_deg: f32,
    /// Share of records dropped.
    pub drop_rate: f64,
    /// What the records carry.
    pub format: SyntheticFormat,
    /// Varied shapes, hands and tracking errors ([`crate::interaction::variation`]) from this
    /// split, instead of the library's shapes; `None` for the library's.
    pub variation: Option<Split>,
    /// The tracking errors of varied sequences; `None`: the format's ([`TrackingErrors::JOINTS`],
    /// [`TrackingErrors::LANDMARKS`], none for a glove).
    pub errors: Option<TrackingErrors>,
}

/// Tracking errors of varied sequences beyond the joint noise: what a real tracker adds.
#[derive(Clone, Copy, Debug)]
pub struct TrackingErrors {
    /// Extra root-mean-square noise along the camera axis (world Z), metres: monocular depth.
    pub depth_noise_m: f32,
    /// Largest depth offset of a whole finger, held for a hold (uniform ±), metres.
    pub depth_bias_m: f32,
    /// Largest offset of a fingertip across the camera axis (uniform ± in X and Y), held for
    /// a hold, metres; the finger's other joints are offset in proportion along it (the
    /// thumb's by half as much again): a monocular tracker's pose-dependent error.
    pub finger_bias_m: f32,
    /// Fingers dropping out (kept at the angles they had) per second.
    pub dropouts_per_s: f64,
    /// How long a dropout lasts, seconds (uniform between).
    pub dropout_s: (f64, f64),
    /// Share of records where one finger jumps.
    pub jump_rate: f64,
    /// How far it jumps, metres.
    pub jump_m: f32,
}

impl TrackingErrors {
    /// A headset's tracking of the 25 joints: stereo, so no depth error of its own.
    pub const JOINTS: Self = Self { depth_noise_m: 0.0, depth_bias_m: 0.0, finger_bias_m: 0.0, dropouts_per_s: 0.05, dropout_s: (0.1, 0.4), jump_rate: 0.01, jump_m: 0.004 };
    /// Monocular landmarks (MediaPipe from a webcam), the errors the built-in classifier is
    /// trained with: depth noise and per-finger depth offsets, lighter than MediaPipe's
    /// measured ones (trained on those, it recognises fewer holds of every source).
    pub const LANDMARKS: Self = Self { depth_noise_m: 0.006, depth_bias_m: 0.008, finger_bias_m: 0.0, dropouts_per_s: 0.1, dropout_s: (0.2, 0.5), jump_rate: 0.02, jump_m: 0.008 };
    /// MediaPipe's error as measured on the camera test's video of the WebXR generic hand
    /// (after the best similarity: RMS 14–17 mm across the camera axis, 12–14 mm along it):
    /// these give about 16 mm and 12 mm. `gesture-bench` scores the landmarks target on them.
    pub const MEDIAPIPE_MEASURED: Self = Self { depth_noise_m: 0.008, depth_bias_m: 0.016, finger_bias_m: 0.026, ..Self::LANDMARKS };
}

impl Default for SyntheticParams {
    fn default() -> Self {
        Self {
            seed: 1,
            hand: None,
            holds: 13,
            hold_s: 1.0,
            move_s: 0.4,
            idle_s: 10.0,
            rate_hz: 60.0,
            noise_m: 0.0015,
            tremor_deg: 0.5,
            wrist_turn_deg: 25.0,
            drop_rate: 0.02,
            format: SyntheticFormat::Joints,
            variation: None,
            errors: None,
        }
    }
}

impl SyntheticParams {
    /// A varied sequence of `split` ([`crate::interaction::variation`]): wrist turns up to 80°
    /// (what a webcam or a headset sees), the rest as the defaults.
    #[must_use]
    pub fn varied(split: Split, seed: u64, format: SyntheticFormat) -> Self {
        Self { seed, variation: Some(split), wrist_turn_deg: 80.0, format, ..Self::default() }
    }
}

/// One labelled hold: `gesture` is shown from `reached` to `until` (seconds); as JSON in
/// the labels file beside a synthesized recording.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Label {
    /// The gesture's name.
    pub gesture: String,
    /// When the pose is reached (the end of the move).
    pub reached: f64,
    /// When the move to the next pose begins.
    pub until: f64,
}

/// A generated sequence.
#[derive(Clone, Debug)]
pub struct Synthetic {
    /// The user's hand.
    pub hand: HandParams,
    /// The records, in time order, with the dropped ones left out.
    pub records: Vec<Record>,
    /// The true pose of every record (angles of the `full` model, the wrist).
    pub truth: Vec<Pose>,
    /// The holds.
    pub labels: Vec<Label>,
    /// The idle stretch, seconds from and to.
    pub idle: (f64, f64),
}

/// Generates a sequence.
///
/// # Errors
/// [`crate::Error::HandParameter`] for a hand that cannot be built.
pub fn generate(params: &SyntheticParams) -> Result<Synthetic> {
    let mut rng = Rng::new(params.variation.map_or(params.seed, |s| s.seed(params.seed)));
    let varied = params.variation.is_some();
    let hand = params.hand.unwrap_or_else(|| {
        let length = if varied { rng.uniform(0.15, 0.22) } else { rng.uniform(0.16, 0.21) } as f32;
        HandParams {
            length,
            breadth: length * if varied { rng.uniform(0.40, 0.50) } else { rng.uniform(0.42, 0.50) } as f32,
            side: if rng.next_f64() < 0.5 { Side::Left } else { Side::Right },
            vertices: *crate::hand::VERTEX_RANGE.start(),
        }
    });
    let mut posed = crate::hand::hand_kinematics(&hand, JointModel::Full)?;
    let rig = posed.rig().clone();
    let joints = JointPositions::new(posed.skeleton())?;
    let rest_wrist = rig.rest_wrist();
    // A user's own proportions: each bone ±15 % (varied sequences), applied to the joints.
    let bone_scale: [f32; 25] = core::array::from_fn(|_| if varied { rng.uniform(0.85, 1.15) as f32 } else { 1.0 });

    // The shapes: the library and thumbs down, in a shuffled cycle.
    let thumbs_up = gesture("thumbs_up")?.pose(JointModel::Full);
    posed.pose(&thumbs_up);
    let thumb = joints.read(posed.world());
    let thumb_direction = (thumb[4] - thumb[2]).normalize();
    let up_turn = Quat::from_rotation_arc(thumb_direction, Vec3::Y);
    let down_turn = Quat::from_rotation_arc(thumb_direction, -Vec3::Y);
    let mut names: Vec<&str> = if varied { VARIED_GESTURES.to_vec() } else { GESTURES.iter().map(|g| g.name).chain(["thumbs_down"]).collect() };
    let (rest_rotation, rest_translation) = rest_wrist.to_rotation_translation();
    let mut keys = Vec::new(); // (time, pose, label)
    let mut time = 0.0;
    let mut previous = relaxed(&mut rng);
    previous.wrist = Some(rest_wrist);
    keys.push((0.0, previous.clone(), None));
    time += 0.5;
    keys.push((time, previous, None));
    for k in 0..params.holds {
        if k % names.len() == 0 {
            let last = k.checked_sub(1).map(|p| names[p % names.len()]);
            for i in (1..names.len()).rev() {
                names.swap(i, (rng.next_f64() * (i + 1) as f64) as usize);
            }
            // The same gesture twice in a row would be one hold.
            if Some(names[0]) == last {
                names.swap(0, 1);
            }
        }
        let name = names[k % names.len()];
        let shape = if varied {
            let gap = |pose: &Pose| {
                posed.pose(pose);
                let p = proportioned(&joints.read(posed.world()), &bone_scale);
                p[4].distance(p[9])
            };
            varied_pose(name, &mut rng, gap)?.0
        } else if name == "thumbs_down" {
            thumbs_up.clone()
        } else {
            gesture(name)?.pose(JointModel::Full)
        };
        let turn = Quat::from_axis_angle(rng.unit(), (rng.uniform(-1.0, 1.0) * f64::from(params.wrist_turn_deg)).to_radians() as f32);
        // Thumbs up and down keep the thumb within 25° of vertical (turned about it, tilted).
        let thumb_turn = |rng: &mut Rng| turn_about_y(rng) * if varied { Quat::from_axis_angle(rng.unit(), rng.uniform(-15.0, 15.0).to_radians() as f32) } else { Quat::IDENTITY };
        let rotation = match name {
            "thumbs_up" => thumb_turn(&mut rng) * up_turn * rest_rotation,
            "thumbs_down" => thumb_turn(&mut rng) * down_turn * rest_rotation,
            _ => turn * rest_rotation,
        };
        let pose = Pose { wrist: Some(DualQuat::from_rotation_translation(rotation, rest_translation)), angles: shape.angles };
        time += params.move_s;
        keys.push((time, pose.clone(), Some((name, time, time + params.hold_s))));
        time += params.hold_s;
        keys.push((time, pose, None));
    }
    // Idle: relaxed shapes drifting slowly, from when the hand has reached the first one (the
    // move out of the last hold is a move, not idle motion).
    let mut idle_start = f64::INFINITY;
    while time < idle_start + params.idle_s {
        time += rng.uniform(1.0, 2.0);
        idle_start = idle_start.min(time);
        let mut pose = relaxed(&mut rng);
        let turn = Quat::from_axis_angle(rng.unit(), (rng.uniform(-1.0, 1.0) * f64::from(params.wrist_turn_deg)).to_radians() as f32);
        pose.wrist = Some(DualQuat::from_rotation_translation(turn * rest_rotation, rest_translation + rng.unit() * 0.05));
        keys.push((time, pose, None));
    }
    let labels = keys.iter().filter_map(|(_, _, l)| l.map(|(g, reached, until)| Label { gesture: g.to_owned(), reached, until })).collect();

    let dofs = JointModel::Full.dof_count();
    let phases: Vec<f32> = (0..dofs).map(|_| rng.uniform(0.0, core::f64::consts::TAU) as f32).collect();
    let sigma = params.noise_m / 3f32.sqrt();
    let glove = match &params.format {
        SyntheticFormat::Glove(table) => Some((table, Calibration::default_for(table))),
        _ => None,
    };
    let mount = MountingOffset::default();
    let errors = match (&params.format, varied) {
        (_, false) | (SyntheticFormat::Glove(_), true) => None,
        (SyntheticFormat::Joints, true) => Some(params.errors.unwrap_or(TrackingErrors::JOINTS)),
        (SyntheticFormat::Landmarks, true) => Some(params.errors.unwrap_or(TrackingErrors::LANDMARKS)),
    };
    // Each finger's DOFs (thumb first), which a dropout keeps where they were.
    let finger_dofs: [Vec<usize>; 5] = core::array::from_fn(|f| {
        let prefix = ["thumb", "index", "middle", "ring", "pinky"][f];
        JointModel::Full.dofs().enumerate().filter(|(_, d)| d.bone.starts_with(prefix)).map(|(i, _)| i).collect()
    });
    let mut dropout: Option<(usize, f64, Vec<f32>)> = None;
    let mut depth_bias = [0.0f32; 5];
    let mut finger_bias = [Vec3::ZERO; 5];
    let mut bias_key = usize::MAX;
    let (mut records, mut truth) = (Vec::new(), Vec::new());
    let mut pose = Pose::rest(dofs);
    let mut tracked = Pose::rest(dofs);
    let mut k = 0;
    let end = keys.last().map_or(0.0, |k| k.0);
    let mut frame = 0u64;
    loop {
        let t = frame as f64 / params.rate_hz;
        if t > end {
            break;
        }
        frame += 1;
        while k + 1 < keys.len() && keys[k + 1].0 <= t {
            k += 1;
        }
        let (t0, a, _) = &keys[k];
        let (t1, b, _) = keys.get(k + 1).unwrap_or(&keys[k]);
        let s = if t1 > t0 { ((t - t0) / (t1 - t0)).clamp(0.0, 1.0) as f32 } else { 1.0 };
        a.interpolate_into(b, s * s * (3.0 - 2.0 * s), rest_wrist, &mut pose);
        for (angle, phase) in pose.angles.iter_mut().zip(&phases) {
            *angle += params.tremor_deg.to_radians() * (core::f32::consts::TAU * 9.0 * t as f32 + phase).sin();
        }
        rig.clamp(&mut pose);
        if rng.next_f64() < params.drop_rate {
            continue;
        }
        tracked.clone_from(&pose);
        if let Some(e) = errors {
            if bias_key != k {
                bias_key = k;
                depth_bias = core::array::from_fn(|_| rng.uniform(-1.0, 1.0) as f32 * e.depth_bias_m);
                if e.finger_bias_m > 0.0 {
                    // (Drawn only when there is one: the other models' sequences stay as they were.)
                    finger_bias = core::array::from_fn(|f| {
                        let scale = e.finger_bias_m * if f == 0 { 1.5 } else { 1.0 };
                        Vec3::new(rng.uniform(-1.0, 1.0) as f32, rng.uniform(-1.0, 1.0) as f32, 0.0) * scale
                    });
                }
            }
            if dropout.as_ref().is_some_and(|d| t >= d.1) {
                dropout = None;
            }
            if dropout.is_none() && rng.next_f64() < e.dropouts_per_s / params.rate_hz {
                let f = rng.below(5);
                dropout = Some((f, t + rng.uniform(e.dropout_s.0, e.dropout_s.1), finger_dofs[f].iter().map(|&i| pose.angles[i]).collect()));
            }
            if let Some((f, _, kept)) = &dropout {
                for (&i, &a) in finger_dofs[*f].iter().zip(kept) {
                    tracked.angles[i] = a;
                }
            }
        }
        posed.pose(&tracked);
        let world = posed.world();
        let mut positions = proportioned(&joints.read(world), &bone_scale);
        for p in &mut positions {
            *p += rng.normal_vec3() * sigma;
        }
        if let Some(e) = errors {
            let jump = (rng.next_f64() < e.jump_rate).then(|| (rng.below(5), rng.unit() * e.jump_m));
            for (j, p) in positions.iter_mut().enumerate().skip(1) {
                let finger = if j < 5 { 0 } else { j / 5 };
                // Along the finger: the thumb's joints 1–4, the others' 5k+1..5k+4 (the
                // metacarpal 5k stays put with the palm).
                let along = if j < 5 { j as f32 / 4.0 } else { (j % 5) as f32 / 4.0 };
                *p += finger_bias[finger] * along;
                p.z += depth_bias[finger] + rng.normal() * e.depth_noise_m;
                if let Some((_, by)) = jump.filter(|(f, _)| *f == finger) {
                    *p += by;
                }
            }
        }
        let record_hand = match &params.format {
            SyntheticFormat::Joints => {
                HandData::Joints(joint_set(world, &joints, &positions))
            }
            SyntheticFormat::Landmarks => HandData::Landmarks(mediapipe::WEBXR_INDEX.map(|w| positions[w])),
            SyntheticFormat::Glove(_) => {
                let (table, calibration) = glove.as_ref().expect("a glove format has its table");
                HandData::Glove(glove_values(table, calibration, &pose, &mut rng))
            }
        };
        let tracker = glove.as_ref().map(|_| {
            let (r, p) = pose.wrist.unwrap_or(rest_wrist).to_rotation_translation();
            let wrist = Affine3A::from_rotation_translation(r, p);
            let offset = Affine3A::from_rotation_translation(Quat::from_array(mount.q), Vec3::from(mount.p));
            let (_, orientation, position) = (wrist * offset.inverse()).to_scale_rotation_translation();
            RigidPose { position, orientation: orientation.normalize() }
        });
        records.push(Record { time: t, side: hand.side, hand: Some(record_hand), tracker, arrival: None });
        truth.push(pose.clone());
    }
    Ok(Synthetic { hand, records, truth, labels, idle: (idle_start, end) })
}

/// Joint positions (WebXR order) of a hand whose bones are scaled by `scale` (each joint's
/// entry scales the bone ending at it), the wrist fixed: a user's own proportions.
fn proportioned(p: &[Vec3; 25], scale: &[f32; 25]) -> [Vec3; 25] {
    let mut out = *p;
    for j in 1..25 {
        let parent = if matches!(j, 1 | 5 | 10 | 15 | 20) { 0 } else { j - 1 };
        out[j] = out[parent] + (p[j] - p[parent]) * scale[j];
    }
    out
}

/// The tracked joints a hand tracker would report for joint transforms `world`: `positions`
/// (the joints' own, or with noise) and the joints' orientations.
pub(crate) fn joint_set(world: &[Affine3A], joints: &JointPositions, positions: &[Vec3; 25]) -> JointSet {
    let mut set = JointSet::new();
    for (i, (&j, p)) in joints.indices().iter().zip(positions).enumerate() {
        let (_, rotation, _) = world[j].to_scale_rotation_translation();
        set.set(i, TrackedJoint { position: *p, orientation: Some(rotation.normalize()), radius: 0.0 });
    }
    set
}

/// A relaxed hand: every finger half curled (neither extended nor curled), the thumb loose
/// and away from the fingertips.
fn relaxed(rng: &mut Rng) -> Pose {
    let mut pose = Pose::rest(JointModel::Full.dof_count());
    for (d, a) in JointModel::Full.dofs().zip(&mut pose.angles) {
        let deg = match (d.bone, d.motion) {
            (b, crate::kinematics::Motion::Flex) if b.starts_with("thumb") => rng.uniform(10.0, 25.0),
            (b, crate::kinematics::Motion::Flex) if b.ends_with("proximal") => rng.uniform(30.0, 45.0),
            (b, crate::kinematics::Motion::Flex) if b.ends_with("intermediate") => rng.uniform(40.0, 55.0),
            (_, crate::kinematics::Motion::Flex) => rng.uniform(15.0, 30.0),
            ("thumb-metacarpal", crate::kinematics::Motion::Abd) => rng.uniform(25.0, 35.0),
            (_, crate::kinematics::Motion::Abd) => rng.uniform(-3.0, 3.0),
        };
        *a = (deg as f32).to_radians();
    }
    pose
}

/// A turn of up to ±25° about the world vertical (keeps a thumb pointing up or down).
fn turn_about_y(rng: &mut Rng) -> Quat {
    Quat::from_rotation_y(rng.uniform(-25.0, 25.0).to_radians() as f32)
}

/// Raw glove values that the table maps back to `pose` (each sensor from the first DOF it
/// drives), with ±8 units of sensor noise.
fn glove_values(table: &MappingTable, calibration: &Calibration, pose: &Pose, rng: &mut Rng) -> GloveSample {
    let layout = table.layout();
    let mut values = [0.0f32; crate::input::MAX_GLOVE_SENSORS];
    for (i, sensor) in layout.sensors().iter().enumerate() {
        let c = calibration.sensors.get(&sensor.name);
        let flat = c.map_or(0.0, |c| c.flat);
        let full = c.and_then(|c| c.fist.or(c.spread)).unwrap_or(crate::input::RAW_MAX);
        let n = table
            .entries()
            .iter()
            .find(|e| e.sensor == sensor.name)
            .and_then(|e| JointModel::Full.dof_index(&e.dof).ok().map(|d| (pose.angles[d].to_degrees() - e.offset_deg) / e.gain_deg))
            .unwrap_or(0.0);
        values[i] = (flat + n * (full - flat) + rng.normal() * 8.0).clamp(0.0, crate::input::RAW_MAX);
    }
    GloveSample::new(&values[..layout.len()])
}
