//! Scripted manipulation recordings, made from our own kinematics: approach an object, grasp
//! it, lift, carry, put it down, let go and retract (the paper's Figure 9 sequences, and the
//! set `dqhand grasp-bench` scores); and strikes, a flat hand driven through an object at a
//! given speed, for tunnelling. They are labelled synthetic wherever they are written.
//!
//! The user's hand is the loop's own model, tracked without noise: what is measured is the
//! manipulation loop, not the retargeting. The tracked hand goes into the object (the palm
//! presses 1 cm into it, the fingers close as if it were not there), as a real user's does.

use std::sync::Arc;

use glam::{Affine3A, Mat3, Quat, Vec3};
use parry3d::query::Ray;

use super::synthetic::joint_set;
use crate::collision::{fit_proxies, ObjectCollider, ObjectColliders, Proxy, ProxyShape, TableTop, FINGERS};
use crate::gesture::gesture;
use crate::kinematics::Side;
use crate::input::{HandData, Record, TrackedJoint};
use crate::kinematics::{HandKinematics, JointModel, JointPositions, Motion, Pose};
use crate::math::DualQuat;
use crate::model::Model;
use crate::{Error, Result, SceneProblem};

/// How far the tracked palm presses into the object, m.
const PRESS_M: f32 = 0.01;
/// Where the hand starts and ends, back from the grasp along the approach, m.
const STANDOFF_M: f32 = 0.2;
/// How far above the table's top a scripted hand keeps its skin, m: its proxies (the skin and
/// a 1 mm margin) then leave the contact constraint's stop gap, so the rendered hand can be
/// where the tracked one is. (Its joints 1 cm up, as before, put the skin of a proximal
/// phalanx, 12.5 mm round its joint, in the table, and a rendered finger blocked open there
/// dragged a released ball along.)
const SKIN_CLEARANCE_M: f32 = 0.002;
/// Turns about the approach a hand taking a thing from a table may be given, degrees, fewest
/// first ([`grasp`]).
const TILTS_DEG: [f32; 7] = [0.0, 10.0, -10.0, 20.0, -20.0, 30.0, -30.0];
/// Carrying speed, m/s.
const CARRY_SPEED: f32 = 0.5;

/// One scripted grasp.
#[derive(Clone, Debug, PartialEq)]
pub struct GraspTask {
    /// The object's name in the scene.
    pub object: String,
    /// The direction the palm moves and faces on the approach (world, unit).
    pub approach: Vec3,
    /// The direction the fingers point (world; made perpendicular to `approach`).
    pub fingers: Vec3,
    /// Approach speed, m/s.
    pub speed: f32,
    /// How high the object is lifted, m.
    pub lift: f32,
    /// The carry, m (world displacement after the lift).
    pub carry: Vec3,
    /// A pinch (thumb and index tips) instead of a whole-hand grasp.
    pub pinch: bool,
    /// How high above where it was picked up the hand lets it go, m: 0 sets it down; above,
    /// a still hand opens and it falls.
    pub drop: f32,
    /// Where the hand aims, off the object's middle (world, m; its part along the approach
    /// is ignored): a user's grasp is rarely centred.
    pub aim: Vec3,
}

/// When each stage of a scripted grasp happens, s.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct GraspTimes {
    /// The palm reaches the object.
    pub reached: f64,
    /// The fingers are closed.
    pub closed: f64,
    /// The carry begins (after the lift).
    pub carry_start: f64,
    /// The carry ends.
    pub carry_end: f64,
    /// The object is set down; the fingers begin to open.
    pub release: f64,
    /// The end of the recording.
    pub end: f64,
}

/// A scripted recording.
#[derive(Clone, Debug)]
pub struct Script {
    /// The records, one per frame.
    pub records: Vec<Record>,
    /// The tracked pose of each record (the `full` joint model).
    pub truth: Vec<Pose>,
    /// The stages.
    pub times: GraspTimes,
    /// Where the carry takes the hand (and the object), m.
    pub carry: Vec3,
    /// How high above the table it is let go, m ([`GraspTask::drop`]).
    pub drop: f32,
}

impl Script {
    /// The same script `offset` seconds later: its records and its times.
    pub fn shift(&mut self, offset: f64) {
        for r in &mut self.records {
            r.time += offset;
        }
        let t = &mut self.times;
        for x in [&mut t.reached, &mut t.closed, &mut t.carry_start, &mut t.carry_end, &mut t.release, &mut t.end] {
            *x += offset;
        }
    }
}

/// Records per second.
pub const RATE_HZ: f64 = 60.0;

/// The hand in the frame of its wrist: where its palm's centre is, which way the palm faces
/// and the fingers point.
struct HandFrame {
    palm: Vec3,
    palmar: Vec3,
    fingers: Vec3,
    /// Between the thumb's tip and the opposing finger's half-way through a grasp's closure
    /// (the middle's), or at the end of a pinch's (the index's, where the tips meet): where
    /// the object goes, across the approach, so that thumb and fingers close on opposite
    /// sides of it.
    grip: Vec3,
}

/// The WebXR joints of `hand` in `pose`, in its wrist's frame.
fn in_wrist(hand: &mut HandKinematics, joints: &JointPositions, pose: &Pose) -> [Vec3; 25] {
    hand.pose(pose);
    let world = hand.world();
    let wrist = hand.rig().wrist();
    let to_wrist = world[wrist].inverse();
    joints.read(world).map(|p| to_wrist.transform_point3(p))
}

fn hand_frame(hand: &mut HandKinematics, joints: &JointPositions, closing: &Closing) -> HandFrame {
    let dofs = hand.rig().dofs().len();
    let p = in_wrist(hand, joints, &Pose::rest(dofs));
    // WebXR order: 0 wrist, 11 middle proximal; palmar is the wrist's −Y.
    let fingers = p[11].normalize();
    let palmar = (-Vec3::Y - fingers * fingers.dot(-Vec3::Y)).normalize();
    // The palm's surface: its thickness is about a third of a metacarpal's length.
    let palm = p[11] * 0.55 + palmar * (p[11].length() * 0.3);
    let pinch = closing.pinch;
    let half = in_wrist(hand, joints, &closing.pose(if pinch { 1.0 / PINCH_OVERSHOOT } else { 0.5 }));
    // WebXR order: 4 thumb tip, 9 index tip, 14 middle tip.
    let grip = (half[4] + half[if pinch { 9 } else { 14 }]) / 2.0;
    HandFrame { palm, palmar, fingers, grip }
}

/// How far past the library's `pinch` the scripted pinch closes: the tracked tips press on
/// past a small object's surface, as a user's do.
const PINCH_OVERSHOOT: f32 = 1.25;

/// How a DOF's closure follows the grasp's.
#[derive(Clone, Copy)]
enum Lead {
    /// With it (the pinch, the thumb).
    Even,
    /// Ahead of it: the knuckles, which lead a power grasp, so the proximal phalanges wrap
    /// the object first.
    Knuckle,
    /// Behind it: the distal joints of a power grasp.
    Distal,
}

/// A grasp's closing motion over the `full` model's DOFs: each one's open and shut angles
/// (degrees) and how it follows the closure. A pinch closes toward the gesture library's
/// `pinch` (the thumb's pad on the index's), [`PINCH_OVERSHOOT`] times over. The open hand of
/// a power grasp has its thumb beside the index (CMC extended 15°, not abducted): in front of
/// the palm it meets a mug or a teapot first and holds the palm 4 cm off.
struct Closing {
    pinch: bool,
    /// Per DOF: open and shut angles, how it follows, its finger (in [`FINGERS`] order) and,
    /// for a finger's abduction, its angle when held against the middle finger.
    dofs: Vec<(f32, f32, Lead, usize, Option<f32>)>,
    /// Per finger, held against the middle finger (not splayed) all through.
    together: [bool; 5],
}

impl Closing {
    fn new(pinch: bool) -> Self {
        let pinched = gesture("pinch").expect("the library has a pinch").pose(JointModel::Full);
        let dofs = JointModel::Full
            .dofs()
            .zip(&pinched.angles)
            .map(|(d, p)| {
                let thumb = d.bone.starts_with("thumb");
                let (open, shut) = match (d.bone, d.motion) {
                    ("thumb-metacarpal", Motion::Abd) => (if pinch { 15.0 } else { 0.0 }, if pinch { p.to_degrees() * PINCH_OVERSHOOT } else { 50.0 }),
                    _ if pinch => (if thumb || d.bone.starts_with("index") || d.motion == Motion::Abd { 0.0 } else { 20.0 }, p.to_degrees() * PINCH_OVERSHOOT),
                    ("thumb-metacarpal", Motion::Flex) => (-15.0, 30.0),
                    (_, Motion::Flex) if thumb => (0.0, 45.0),
                    (b, Motion::Flex) if b.ends_with("proximal") => (0.0, 80.0),
                    (b, Motion::Flex) if b.ends_with("intermediate") => (0.0, 95.0),
                    (_, Motion::Flex) => (0.0, 60.0),
                    (_, Motion::Abd) => (0.0, 0.0),
                };
                let lead = if pinch || thumb {
                    Lead::Even
                } else if d.bone.ends_with("proximal") {
                    Lead::Knuckle
                } else {
                    Lead::Distal
                };
                let finger = FINGERS.iter().position(|f| d.bone.starts_with(f)).expect("every DOF is a finger's");
                let together = (d.motion == Motion::Abd && !thumb).then_some(if d.bone.starts_with("middle") { 0.0 } else { d.min_deg });
                (open, shut, lead, finger, together)
            })
            .collect();
        Self { pinch, dofs, together: [false; 5] }
    }

    /// The hand closed by `closed` (0 open, 1 shut).
    fn pose(&self, closed: f32) -> Pose {
        let mut pose = Pose::rest(self.dofs.len());
        for (a, &(open, shut, lead, finger, together)) in pose.angles.iter_mut().zip(&self.dofs) {
            if let Some(together) = together.filter(|_| self.together[finger]) {
                *a = together.to_radians();
                continue;
            }
            let s = match lead {
                Lead::Even => closed,
                Lead::Knuckle => (closed / 0.6).min(1.0),
                Lead::Distal => ((closed - 0.3) / 0.7).max(0.0),
            };
            *a = (open + (shut - open) * s).to_radians();
        }
        pose
    }
}

fn smooth(s: f64) -> f32 {
    let s = s.clamp(0.0, 1.0);
    (s * s * (3.0 - 2.0 * s)) as f32
}

/// A keyframe: time, palm position, closure.
type Key = (f64, Vec3, f32);

/// One hand's part of a script: its kinematics, how it is turned and closes, and its
/// keyframes.
struct HandPath {
    hand: HandKinematics,
    joints: JointPositions,
    closing: Closing,
    frame: HandFrame,
    rotation: Quat,
    side: Side,
    keys: Vec<Key>,
    /// Shapes holding the skin of each bone: what keeps the hand off the table.
    skin: Vec<Proxy>,
}

impl HandPath {
    /// `model`'s hand with its palm facing `approach` and its fingers along `fingers` (made
    /// perpendicular), closing as a pinch or a grasp.
    fn new(model: &Model, side: Side, approach: Vec3, fingers: Vec3, pinch: bool) -> Result<Self> {
        let d = approach.normalize();
        let f = (fingers - d * fingers.dot(d)).normalize();
        let mut hand = model.hand_kinematics(JointModel::Full)?;
        let joints = JointPositions::new(hand.skeleton())?;
        let closing = Closing::new(pinch);
        let frame = hand_frame(&mut hand, &joints, &closing);
        let rotation = {
            let hand = Mat3::from_cols(frame.palmar, frame.fingers, frame.palmar.cross(frame.fingers));
            let world = Mat3::from_cols(d, f, d.cross(f));
            Quat::from_mat3(&(world * hand.transpose())).normalize()
        };
        Ok(Self { hand, joints, closing, frame, rotation, side, keys: Vec::new(), skin: fit_proxies(model, 0.0) })
    }

    /// Where the palm goes to take `object`, aiming `aim` off its middle. A grasp (`grip`):
    /// the palm presses into the surface point seen along the approach `d` through the middle
    /// of the object's bounding box, shifted across the approach so that the hand's grip
    /// point is over the middle; a flat hand, the palm's centre is. Where that line misses the
    /// object (the grip point of a power grasp is 4–5 cm out along the fingers, past a 4 cm
    /// ball's edge), the palm presses into the surface seen through the middle: the fingers lie
    /// on it there, and the palm is not pushed to the object's middle plane. A pinch: the tips
    /// meet in the middle.
    fn reach(&self, object: &ObjectCollider, d: Vec3, aim: Vec3, grip: bool) -> Vec3 {
        let offset = if grip { self.rotation * (self.frame.grip - self.frame.palm) } else { Vec3::ZERO };
        let offset = offset - (aim - d * aim.dot(d));
        if self.closing.pinch {
            return object.aabb().center() - offset;
        }
        let centre = object.aabb().center() - (offset - d * offset.dot(d));
        let cast = |from: Vec3| object.surface.cast_ray(&object.pose, &Ray::new(from - d, d), 2.0, true);
        let toi = cast(centre).or_else(|| cast(object.aabb().center())).unwrap_or(1.0);
        centre - d + d * (toi + PRESS_M)
    }

    /// `palm` raised until the open hand there, and closed, has its skin [`SKIN_CLEARANCE_M`]
    /// above the table's top; a finger whose skin would be in the table open is held against
    /// the middle finger first, not splayed ([`Closing::together`]: the splayed little finger
    /// of an open hand taking a ball from the side, thumb up, reaches 3 cm below its knuckle,
    /// which raises the whole hand until the ball is out of the thumb's reach). Returns the
    /// palm.
    fn above_table(&mut self, palm: Vec3, table: Option<TableTop>) -> Vec3 {
        let Some(table) = table else { return palm };
        let floor = table.height + SKIN_CLEARANCE_M;
        self.closing.together = [false; 5];
        for finger in 1..FINGERS.len() {
            self.closing.together[finger] = self.lowest(palm, 0.0, Some(finger)) < floor;
        }
        let lowest = self.lowest(palm, 0.0, None).min(self.lowest(palm, 1.0, None));
        palm + Vec3::Y * (floor - lowest).max(0.0)
    }

    /// The lowest point of the skin of the hand with its palm at `palm` closed by `closed`:
    /// of `finger`'s bones (in [`FINGERS`] order), or of all.
    fn lowest(&mut self, palm: Vec3, closed: f32, finger: Option<usize>) -> f32 {
        let mut pose = self.closing.pose(closed);
        pose.wrist = Some(self.wrist_at(palm));
        self.hand.pose(&pose);
        let joints = self.hand.skeleton().joints();
        let world = self.hand.world();
        let lowest = |p: &Proxy| {
            let w = world[p.joint];
            match &p.shape {
                ProxyShape::Capsule { start, end, radius } => w.transform_point3(*start).y.min(w.transform_point3(*end).y) - radius,
                ProxyShape::ConvexHull { points, .. } => points.iter().map(|q| w.transform_point3(*q).y).fold(f32::INFINITY, f32::min),
            }
        };
        self.skin.iter().filter(|p| finger.is_none_or(|f| joints[p.joint].name.starts_with(FINGERS[f]))).map(lowest).fold(f32::INFINITY, f32::min)
    }

    /// Where the palm goes to take `object` (aiming `aim` off its middle) with the hand clear
    /// of `table` ([`Self::reach`], [`Self::above_table`]), turned about the approach `d` by
    /// the first of [`TILTS_DEG`] that needs the least raise: a user taking a ball off a
    /// table from the side tips the fingers up rather than lift the hand over it and take it
    /// by its upper half (the table would hold the palm 3 cm above the ball's middle, out of
    /// the thumb's reach). From above, a turn about the approach changes no height, and the
    /// hand is not turned.
    fn place(&mut self, object: &ObjectCollider, d: Vec3, aim: Vec3, table: Option<TableTop>) -> Vec3 {
        let base = self.rotation;
        let mut best = (f32::INFINITY, 0.0);
        for tilt in TILTS_DEG {
            self.rotation = Quat::from_axis_angle(d, tilt.to_radians()) * base;
            let at = self.reach(object, d, aim, true);
            let raise = self.above_table(at, table).y - at.y;
            // Less by a millimetre: not for rounding.
            if raise < best.0 - 0.001 {
                best = (raise, tilt);
            }
        }
        self.rotation = Quat::from_axis_angle(d, best.1.to_radians()) * base;
        let at = self.reach(object, d, aim, true);
        self.above_table(at, table)
    }

    /// The wrist that puts the palm at `palm`.
    fn wrist_at(&self, palm: Vec3) -> DualQuat {
        DualQuat::from_rotation_translation(self.rotation, palm - self.rotation * self.frame.palm)
    }

    /// A keyframe `dt` after the last (at 0 for the first): palm at `p`, closed by `c`.
    /// Returns its time.
    fn key(&mut self, dt: f64, p: Vec3, c: f32) -> f64 {
        let t = self.keys.last().map_or(0.0, |k| k.0) + dt;
        self.keys.push((t, p, c));
        t
    }

    /// The record and the tracked pose at `t`: between the keys, eased, except the key
    /// numbered `linear` which is reached at constant speed.
    fn at(&mut self, t: f64, linear: Option<usize>) -> (Record, Pose) {
        let keys = &self.keys;
        let k = keys.iter().rposition(|k| k.0 <= t).unwrap_or(0).min(keys.len() - 2);
        let ((t0, p0, c0), (t1, p1, c1)) = (keys[k], keys[k + 1]);
        let s = if t1 > t0 { (t - t0) / (t1 - t0) } else { 1.0 };
        let s = if Some(k + 1) == linear { s.clamp(0.0, 1.0) as f32 } else { smooth(s) };
        let palm = p0.lerp(p1, s);
        let mut pose = self.closing.pose(c0 + (c1 - c0) * s);
        pose.wrist = Some(self.wrist_at(palm));
        self.hand.pose(&pose);
        let world: &[Affine3A] = self.hand.world();
        let positions = self.joints.read(world);
        (Record { time: t, side: self.side, hand: Some(HandData::Joints(joint_set(world, &self.joints, &positions))), tracker: None, arrival: None }, pose)
    }
}

/// The object called `name` among `objects` (of the scene `file`).
fn find<'a>(objects: &'a ObjectColliders, file: &str, name: &str) -> Result<&'a ObjectCollider> {
    objects.objects().iter().find(|o| o.name == name).ok_or_else(|| Error::Scene { file: file.to_owned(), problem: SceneProblem::NoObject(name.to_owned()) })
}

/// The records of `paths` (one record per path and frame, in path order) from 0 to `end`,
/// with `times` and the rest of the script.
fn play(paths: &mut [HandPath], times: GraspTimes, carry: Vec3, drop: f32, linear: Option<usize>) -> Script {
    let frames = (times.end * RATE_HZ).floor() as usize + 1;
    let mut script = Script { records: Vec::with_capacity(frames * paths.len()), truth: Vec::with_capacity(frames * paths.len()), times, carry, drop };
    for i in 0..frames {
        let t = i as f64 / RATE_HZ;
        for path in paths.iter_mut() {
            let (record, pose) = path.at(t, linear);
            script.records.push(record);
            script.truth.push(pose);
        }
    }
    script
}

/// Records of `model` (a `side` hand) doing `task` in the scene `file`, whose objects are
/// `objects`.
///
/// # Errors
/// [`SceneProblem::NoObject`] if the scene has no object of the task's; as
/// [`Model::hand_kinematics`].
pub fn grasp(model: Arc<Model>, file: &str, objects: &ObjectColliders, task: &GraspTask, side: Side) -> Result<Script> {
    let object = find(objects, file, &task.object)?;
    let d = task.approach.normalize();
    let mut path = HandPath::new(&model, side, d, task.fingers, task.pinch)?;
    let grasp_at = path.place(object, d, task.aim, objects.table());
    let start = grasp_at - d * STANDOFF_M;
    let lifted = grasp_at + Vec3::Y * task.lift;
    let carried = lifted + task.carry;
    let set_down = carried - Vec3::Y * (task.lift - task.drop);
    path.key(0.0, start, 0.0);
    path.key(0.3, start, 0.0);
    let reached = path.key(f64::from(STANDOFF_M / task.speed), grasp_at, 0.0);
    path.key(0.15, grasp_at, 0.0);
    let closed = path.key(0.5, grasp_at, 1.0);
    path.key(0.2, grasp_at, 1.0);
    let carry_start = path.key(0.5, lifted, 1.0);
    let carry_end = path.key(f64::from(task.carry.length() / CARRY_SPEED), carried, 1.0);
    path.key(0.2, carried, 1.0);
    path.key(0.5, set_down, 1.0);
    let release = path.key(0.1, set_down, 1.0);
    path.key(0.4, set_down, 0.0);
    path.key(0.5, set_down - d * STANDOFF_M, 0.0);
    let end = path.key(1.0, set_down - d * STANDOFF_M, 0.0);
    let times = GraspTimes { reached, closed, carry_start, carry_end, release, end };
    // The approach is at constant speed (its speed is the point); the rest eased.
    Ok(play(&mut [path], times, task.carry, task.drop, Some(2)))
}

/// The directions two facing hands' palms move in: the left hand's (+X), the right's (−X).
const FACING: [Vec3; 2] = [Vec3::X, Vec3::NEG_X];

/// `models` (a left and a right hand) flat, facing each other along X, fingers forward (−Z).
fn facing(models: [&Model; 2]) -> Result<Vec<HandPath>> {
    [Side::Left, Side::Right].into_iter().zip(FACING).zip(models).map(|((side, d), model)| HandPath::new(model, side, d, Vec3::NEG_Z, false)).collect()
}

/// Records of two hands (`models`: a left and a right one) carrying `object` between their
/// flat palms: each comes at it from its own side along X at 0.5 m/s, presses its palm
/// [`PRESS_M`] into it, and they lift it by `lift`, carry it by `carry`, set it down and
/// draw apart. A frame's records are the left hand's, then the right's.
///
/// # Errors
/// As [`grasp`].
pub fn carry_between(models: [&Model; 2], file: &str, objects: &ObjectColliders, object: &str, lift: f32, carry: Vec3) -> Result<Script> {
    let object = find(objects, file, object)?;
    let mut paths = facing(models)?;
    let mut times = GraspTimes { reached: 0.0, closed: 0.0, carry_start: 0.0, carry_end: 0.0, release: 0.0, end: 0.0 };
    for (path, d) in paths.iter_mut().zip(FACING) {
        let at = path.reach(object, d, Vec3::ZERO, false);
        let start = at - d * STANDOFF_M;
        let (lifted, carried) = (at + Vec3::Y * lift, at + Vec3::Y * lift + carry);
        path.key(0.0, start, 0.0);
        path.key(0.3, start, 0.0);
        times.reached = path.key(f64::from(STANDOFF_M / 0.5), at, 0.0);
        times.closed = path.key(0.3, at, 0.0);
        times.carry_start = path.key(0.5, lifted, 0.0);
        times.carry_end = path.key(f64::from(carry.length() / CARRY_SPEED), carried, 0.0);
        path.key(0.2, carried, 0.0);
        times.release = path.key(0.5, carried - Vec3::Y * lift, 0.0);
        path.key(0.5, carried - Vec3::Y * lift - d * STANDOFF_M, 0.0);
        times.end = path.key(1.0, carried - Vec3::Y * lift - d * STANDOFF_M, 0.0);
    }
    Ok(play(&mut paths, times, carry, 0.0, Some(2)))
}

/// Records of two flat hands (`models`: a left and a right one) brought together palm to
/// palm at `centre` and pressed on `press` past it (m; a user's hands meet, the tracked ones
/// overlap), held there for half a second and drawn apart: what keeps the rendered hands out
/// of each other. A frame's records are the left hand's, then the right's.
///
/// # Errors
/// As [`grasp`].
pub fn clap(models: [&Model; 2], centre: Vec3, press: f32) -> Result<Script> {
    let mut paths = facing(models)?;
    let mut times = GraspTimes { reached: 0.0, closed: 0.0, carry_start: 0.0, carry_end: 0.0, release: 0.0, end: 0.0 };
    for (path, d) in paths.iter_mut().zip(FACING) {
        let start = centre - d * STANDOFF_M;
        path.key(0.0, start, 0.0);
        path.key(0.3, start, 0.0);
        times.reached = path.key(f64::from(STANDOFF_M / 0.5), centre, 0.0);
        times.closed = path.key(f64::from(press / 0.1), centre + d * press, 0.0);
        times.release = path.key(0.5, centre + d * press, 0.0);
        times.end = path.key(0.6, start, 0.0);
        (times.carry_start, times.carry_end) = (times.release, times.release);
    }
    Ok(play(&mut paths, times, Vec3::ZERO, 0.0, None))
}

/// Records of a hand-over: the right hand (`models[1]`) grasps `object` from above near its
/// +X end (`reach` off its middle), lifts it and carries it by `carry`; the left hand grasps
/// it there near its −X end, the right one opens and draws back, and the left one carries
/// it on by `carry` and sets it down. A frame's records are the left hand's, then the
/// right's; the script's carry is the left hand's.
///
/// # Errors
/// As [`grasp`].
pub fn hand_over(models: [&Model; 2], file: &str, objects: &ObjectColliders, object: &str, reach: f32, lift: f32, carry: Vec3) -> Result<Script> {
    let object = find(objects, file, object)?;
    let d = Vec3::NEG_Y;
    let [mut left, mut right] = [(Side::Left, -reach), (Side::Right, reach)].map(|(side, x)| (side, Vec3::X * x));
    let mut paths = [&mut left, &mut right]
        .into_iter()
        .zip(models)
        .map(|((side, aim), model)| {
            let path = HandPath::new(model, *side, d, Vec3::NEG_Z, false)?;
            *aim = path.reach(object, d, *aim, true);
            Ok(path)
        })
        .collect::<Result<Vec<_>>>()?;
    let (left_at, right_at) = (left.1 + Vec3::Y * lift + carry, right.1);
    // The right hand takes it and brings it to the meeting point.
    let r = &mut paths[1];
    r.key(0.0, right_at - d * STANDOFF_M, 0.0);
    r.key(0.3, right_at - d * STANDOFF_M, 0.0);
    r.key(f64::from(STANDOFF_M / 0.5), right_at, 0.0);
    r.key(0.15, right_at, 0.0);
    r.key(0.5, right_at, 1.0);
    r.key(0.2, right_at, 1.0);
    r.key(0.5, right_at + Vec3::Y * lift, 1.0);
    let met = r.key(f64::from(carry.length() / CARRY_SPEED), right_at + Vec3::Y * lift + carry, 1.0);
    // The left hand comes from above while the right holds it still, and grasps.
    let l = &mut paths[0];
    l.key(0.0, left_at - d * STANDOFF_M, 0.0);
    l.key(met, left_at - d * STANDOFF_M, 0.0);
    let reached = l.key(f64::from(STANDOFF_M / 0.5), left_at, 0.0);
    l.key(0.15, left_at, 0.0);
    let closed = l.key(0.5, left_at, 1.0);
    l.key(0.2, left_at, 1.0);
    // The right hand opens and draws back; the left carries it on and sets it down.
    let r = &mut paths[1];
    r.key(closed + 0.2 - met, right_at + Vec3::Y * lift + carry, 1.0);
    r.key(0.4, right_at + Vec3::Y * lift + carry, 0.0);
    r.key(0.5, right_at + Vec3::Y * lift + carry - d * STANDOFF_M, 0.0);
    let l = &mut paths[0];
    let carry_start = l.key(0.9, left_at, 1.0);
    let carry_end = l.key(f64::from(carry.length() / CARRY_SPEED), left_at + carry, 1.0);
    l.key(0.2, left_at + carry, 1.0);
    l.key(0.5, left_at + carry - Vec3::Y * lift, 1.0);
    let release = l.key(0.1, left_at + carry - Vec3::Y * lift, 1.0);
    l.key(0.4, left_at + carry - Vec3::Y * lift, 0.0);
    l.key(0.5, left_at + carry - Vec3::Y * lift - d * STANDOFF_M, 0.0);
    let end = l.key(1.0, left_at + carry - Vec3::Y * lift - d * STANDOFF_M, 0.0);
    let waited = end - paths[1].keys.last().map_or(0.0, |k| k.0);
    paths[1].key(waited, right_at + Vec3::Y * lift + carry - d * STANDOFF_M, 0.0);
    let times = GraspTimes { reached, closed, carry_start, carry_end, release, end };
    Ok(play(&mut paths, times, carry, 0.0, None))
}

impl GraspTask {
    /// The default grasp of `object`: from above at 0.5 m/s, fingers pointing away from the
    /// user (−Z), lifted 12 cm, carried 20 cm toward the user (+Z) and set down.
    #[must_use]
    pub fn from_above(object: &str) -> Self {
        Self { object: object.to_owned(), approach: -Vec3::Y, fingers: -Vec3::Z, speed: 0.5, lift: 0.12, carry: Vec3::new(0.0, 0.0, 0.2), pinch: false, drop: 0.0, aim: Vec3::ZERO }
    }
}

/// Seconds without records between two tasks of [`sequence`]: tracking is lost, so the hand
/// reappears at the next start instead of sweeping through the scene.
pub const TASK_GAP_S: f64 = 0.5;

/// The tasks one after another on one clock, each starting [`TASK_GAP_S`] after the last
/// ends; returns the scripts with their times shifted.
///
/// # Errors
/// As [`grasp`].
pub fn sequence(model: &Arc<Model>, file: &str, objects: &ObjectColliders, tasks: &[GraspTask], side: Side) -> Result<Vec<Script>> {
    let mut offset = 0.0;
    let mut scripts = Vec::with_capacity(tasks.len());
    for task in tasks {
        let mut s = grasp(model.clone(), file, objects, task, side)?;
        s.shift(offset);
        offset = s.times.end + TASK_GAP_S;
        scripts.push(s);
    }
    Ok(scripts)
}

/// A free hand moved at a constant speed, for the loop's lag, and held still before, for its
/// jitter: what [`crate::interaction::benchmark::lag`] measures.
#[derive(Clone, Debug, PartialEq)]
pub struct Sweep {
    /// The records, one per frame, joints with [`SWEEP_NOISE_M`] of noise.
    pub records: Vec<Record>,
    /// The true pose of each record (the `full` joint model).
    pub truth: Vec<Pose>,
    /// The stretch the hand is still (after the filters settled), s.
    pub rest: (f64, f64),
    /// The stretch it moves at `speed` (after a ramp and a settling time), s.
    pub steady: (f64, f64),
    /// Its speed there, m/s, along `direction`.
    pub speed: f32,
    pub direction: Vec3,
}

/// Joint noise of a sweep's records, m RMS: the gesture benchmark's.
pub const SWEEP_NOISE_M: f32 = 0.0015;

/// Records of `model`'s open hand at `start`, still for 2 s, then sped up along `direction`
/// to `speed` (m/s) over 0.2 s and carried on for 1.3 s; the steady stretch is its last
/// second. Seeded noise: the same seed makes the same records.
///
/// # Errors
/// As [`Model::hand_kinematics`].
pub fn sweep(model: &Arc<Model>, start: Vec3, direction: Vec3, speed: f32, side: Side, seed: u64) -> Result<Sweep> {
    const REST_S: f64 = 2.0;
    const RAMP_S: f64 = 0.2;
    const MOVE_S: f64 = 1.3;
    let direction = direction.normalize();
    let mut hand = model.hand_kinematics(JointModel::Full)?;
    let joints = JointPositions::new(hand.skeleton())?;
    let mut rng = crate::math::Rng::new(seed);
    let sigma = SWEEP_NOISE_M / 3f32.sqrt();
    let frames = ((REST_S + RAMP_S + MOVE_S) * RATE_HZ).floor() as usize + 1;
    let mut out = Sweep { records: Vec::with_capacity(frames), truth: Vec::with_capacity(frames), rest: (0.5, REST_S), steady: (REST_S + MOVE_S + RAMP_S - 1.0, REST_S + RAMP_S + MOVE_S), speed, direction };
    for i in 0..frames {
        let t = i as f64 / RATE_HZ;
        // Constant acceleration over the ramp, then constant speed.
        let moving = (t - REST_S).max(0.0);
        let travelled = if moving < RAMP_S { moving * moving / (2.0 * RAMP_S) } else { RAMP_S / 2.0 + (moving - RAMP_S) };
        let mut pose = Pose::rest(JointModel::Full.dof_count());
        pose.wrist = Some(DualQuat::from_rotation_translation(Quat::IDENTITY, start + direction * (speed * travelled as f32)));
        hand.pose(&pose);
        let world: &[Affine3A] = hand.world();
        let positions = joints.read(world).map(|p| p + rng.normal_vec3() * sigma);
        out.records.push(Record { time: t, side, hand: Some(HandData::Joints(joint_set(world, &joints, &positions))), tracker: None, arrival: None });
        out.truth.push(pose);
    }
    Ok(out)
}

/// How a headset tracks a hand, beyond the script's truth: the issue's "headset-like
/// tracking" for the grasp benchmark.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HeadsetTracking {
    /// RMS noise of every joint position, m.
    pub jitter_m: f32,
    /// Share of records lost.
    pub drop_rate: f64,
    /// How old each record's hand is when it arrives, s (rounded to whole records).
    pub latency_s: f64,
}

impl HeadsetTracking {
    /// 2 mm of joint jitter, 1 % of records lost, 30 ms behind.
    pub const QUEST_LIKE: Self = Self { jitter_m: 0.002, drop_rate: 0.01, latency_s: 0.03 };

    /// `script` as this tracking reports it (seeded): each record carries its hand of
    /// `latency_s` earlier with noisy joints, and some are lost (each hand's independently). The truth and the times stay
    /// the script's: the hand the user has now.
    #[must_use]
    pub fn track(&self, script: &Script, seed: u64) -> Script {
        let mut rng = crate::math::Rng::new(seed);
        let sigma = self.jitter_m / 3f32.sqrt();
        // A frame's records are one per hand: a hand's record `behind` frames earlier is as
        // many frames' records back.
        let per_frame = script.records.iter().take_while(|r| script.records.first().is_some_and(|f| f.time == r.time)).count().max(1);
        let behind = (self.latency_s * RATE_HZ).round() as usize * per_frame;
        let mut out = Script { records: Vec::with_capacity(script.records.len()), truth: Vec::with_capacity(script.truth.len()), times: script.times, carry: script.carry, drop: script.drop };
        for (k, (record, truth)) in script.records.iter().zip(&script.truth).enumerate() {
            if rng.next_f64() < self.drop_rate {
                continue;
            }
            // (The first frames, with nothing that old, carry their own hand.)
            let mut hand = script.records[if k >= behind { k - behind } else { k }].hand;
            if let Some(HandData::Joints(joints)) = &mut hand {
                for i in 0..25 {
                    if let Some(&j) = joints.get(i) {
                        joints.set(i, TrackedJoint { position: j.position + rng.normal_vec3() * sigma, ..j });
                    }
                }
            }
            out.records.push(Record { hand, ..*record });
            out.truth.push(truth.clone());
        }
        out
    }
}
