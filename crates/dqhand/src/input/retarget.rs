//! Retargeting: our hand's joint angles and wrist from the positions of a tracked hand of any
//! size and proportion, left or right.
//!
//! Only *directions* of the tracked bones are used, never their lengths, so a hand longer,
//! shorter or differently proportioned than ours gives the same angles for the same shape:
//! * the wrist's orientation turns our rest palm frame onto the tracked one (wrist → middle
//!   knuckle forward, little → index knuckle across; the same construction on both hands,
//!   so devices that disagree on the wrist joint's own axes cannot bias it); its position is
//!   the tracked wrist's;
//! * down each finger, in the order of forward kinematics, each joint's angles are solved in
//!   closed form so that our bone points where the tracked bone points, in the frame its
//!   already solved parent gives it, then clamped to the joint's range (so the children see
//!   the parent as it will be drawn). A 2-DOF joint (`rest · R(abd) · R(flex)`) is exact
//!   for any direction it can reach; a 1-DOF joint takes the bone's projection on its plane.
//!
//! A hand of the other side is mirrored (x → −x in the world) onto ours first: our right
//! hand shows a tracked left hand as its mirror image, with the same finger angles.
//!
//! **Contacts survive.** Different proportions move fingertips apart that touch on the user's
//! hand, so when the tracked thumb tip is within [`CONTACT_FULL`] of a fingertip, a small
//! damped-least-squares IK on the thumb (and, weighted less, that finger) brings the virtual
//! tips to the tracked gap less [`CONTACT_MARGIN`] (the IK stops within 0.1 mm, so the virtual
//! gap is never wider than the tracked one); between [`CONTACT_FULL`] and [`CONTACT_FADE`] the
//! correction fades out, so the hand never jumps.

use glam::{Affine3A, Mat3, Quat, Vec3};

use super::record::{JOINT_COUNT, LANDMARK_COUNT};
use super::{mediapipe, RejectKind, Rejection};
use crate::kinematics::Side;
use crate::kinematics::{webxr, HandRig, JointPositions, Motion, Pose, RigDof};
use crate::math::DualQuat;

/// Tracked thumb-to-fingertip gap below which the virtual tips are brought to the same gap.
pub const CONTACT_FULL: f32 = 0.01;
/// Gap above which no contact correction is made; it fades out linearly from [`CONTACT_FULL`].
pub const CONTACT_FADE: f32 = 0.02;
/// How much closer than the tracked gap the contact IK aims, metres: more than its stopping
/// tolerance, so a tracked gap is an upper bound of the virtual one.
pub const CONTACT_MARGIN: f32 = 0.0003;

/// WebXR indices of the wrist and the knuckles that span the palm frame.
const WRIST: usize = 0;
const INDEX_MCP: usize = 6;
const MIDDLE_MCP: usize = 11;
/// WebXR index of the thumb tip and of the index, middle, ring and pinky tips.
const THUMB_TIP: usize = 4;
const FINGER_TIPS: [usize; 4] = [9, 14, 19, 24];
/// WebXR indices of the four finger metacarpals, which landmarks lack.
const METACARPALS: [usize; 4] = [5, 10, 15, 20];
/// More DOFs than any joint model has (scratch size of the contact IK).
const MAX_DOFS: usize = 32;

/// One joint below the wrist, in forward-kinematics order.
#[derive(Clone, Debug)]
struct Step {
    joint: usize,
    parent: usize,
    /// WebXR indices of the joint and of the next joint along its finger (the bone's end).
    webxr: (usize, usize),
    /// WebXR index of the joint after that, when the bone is not the last of its finger.
    beyond: Option<usize>,
    /// The next joint's flexion axis in this joint's rest frame, when it is a hinge (flexion
    /// only, so the bending plane's normal is that axis).
    bend_axis: Option<Vec3>,
    /// Unit direction of the bone in the joint's rest frame.
    rest_dir: Vec3,
    /// The joint's DOFs (index into the pose, resolved DOF, motion), in the model's order.
    dofs: Vec<(usize, RigDof, Motion)>,
}

/// Solves poses of one [`HandRig`] from tracked positions; holds its scratch buffers, so
/// [`Self::solve`] allocates nothing.
#[derive(Clone, Debug)]
pub struct Retargeter {
    rig: HandRig,
    side: Side,
    steps: Vec<Step>,
    rest_world: Vec<Affine3A>,
    rest_palm: Mat3,
    /// Each finger metacarpal's base in the rest palm frame, relative to the wrist, divided
    /// by the rest palm length (wrist to middle knuckle): where landmarks put none.
    metacarpal_base: [Vec3; 4],
    world: Vec<Affine3A>,
    positions: [Vec3; JOINT_COUNT],
    /// Step ranges of the thumb and of each finger (for the contact IK).
    chains: [core::ops::Range<usize>; 5],
}

/// The side of a hand from its joints (WebXR order) and its wrist's +Y (the back of the hand):
/// index knuckle to middle knuckle, crossed with the palm's length, points to the back of a
/// left hand.
fn handedness(positions: &[Vec3; JOINT_COUNT], wrist_y: Vec3) -> Side {
    let h = (positions[INDEX_MCP] - positions[MIDDLE_MCP]).cross(positions[MIDDLE_MCP] - positions[WRIST]).dot(wrist_y);
    if h > 0.0 {
        Side::Left
    } else {
        Side::Right
    }
}

/// The side of a hand model rigged with the 25 WebXR joints, from its rest geometry (what a
/// retargeter for it finds), without building one: to check a file given as one side's hand.
///
/// # Errors
/// [`crate::Error::MissingJoint`] naming a WebXR joint the skeleton lacks.
pub fn rest_side(skeleton: &crate::kinematics::Skeleton) -> crate::Result<Side> {
    let index = *JointPositions::new(skeleton)?.indices();
    let rest_world = skeleton.rest_world();
    let positions: [Vec3; JOINT_COUNT] = core::array::from_fn(|i| Vec3::from(rest_world[index[i]].translation));
    Ok(handedness(&positions, rest_world[index[WRIST]].matrix3.y_axis.into()))
}

impl Retargeter {
    /// A retargeter for `rig`, whose skeleton must have all 25 WebXR joints (the built-in
    /// hand and WebXR-rigged glTF hands do).
    ///
    /// # Errors
    /// [`crate::Error::MissingJoint`] naming a WebXR joint the skeleton lacks.
    pub fn new(rig: &HandRig) -> crate::Result<Self> {
        let skeleton = rig.skeleton();
        let index = *JointPositions::new(skeleton)?.indices();
        let rest_world = skeleton.rest_world();
        let rest = |i: usize| Vec3::from(rest_world[index[i]].translation);
        let positions: [Vec3; JOINT_COUNT] = core::array::from_fn(rest);
        let rest_palm = palm_frame(&positions).expect("the rig's rest palm spans a frame");
        let palm_length = (positions[MIDDLE_MCP] - positions[WRIST]).length();
        let metacarpal_base = METACARPALS.map(|m| rest_palm.transpose() * (positions[m] - positions[WRIST]) / palm_length);
        let side = handedness(&positions, rest_world[index[WRIST]].matrix3.y_axis.into());

        let motions: Vec<Motion> = rig.model().dofs().map(|d| d.motion).collect();
        let mut steps = Vec::new();
        let mut chains: [core::ops::Range<usize>; 5] = Default::default();
        for (finger, chain) in chains.iter_mut().enumerate() {
            // The thumb's three bones (metacarpal, proximal, distal), each finger's four.
            let (first, bones) = if finger == 0 { (1, 3) } else { (5 * finger, 4) };
            chain.start = steps.len();
            for w in first..first + bones {
                let (joint, child) = (index[w], index[w + 1]);
                let rest_dir = (rest_world[joint].inverse().transform_point3(rest_world[child].translation.into())).normalize();
                let dofs = rig.dofs().iter().enumerate().filter(|(_, d)| d.joint == joint).map(|(i, d)| (i, *d, motions[i])).collect();
                let parent = skeleton.joints()[joint].parent.expect("a finger joint hangs from the wrist");
                let beyond = (w + 2 <= first + bones).then_some(w + 2);
                let mut child_dofs = rig.dofs().iter().zip(&motions).filter(|(d, _)| d.joint == child);
                let bend_axis = match (child_dofs.next(), child_dofs.next()) {
                    (Some((d, Motion::Flex)), None) => Some(skeleton.joints()[child].rest.rotation * d.axis),
                    _ => None,
                };
                steps.push(Step { joint, parent, webxr: (w, w + 1), beyond, bend_axis, rest_dir, dofs });
            }
            chain.end = steps.len();
        }
        Ok(Self {
            rig: rig.clone(),
            side,
            steps,
            world: rest_world.clone(),
            rest_world,
            rest_palm,
            metacarpal_base,
            positions,
            chains,
        })
    }

    /// The side of our hand (from its rest geometry).
    #[must_use]
    pub fn side(&self) -> Side {
        self.side
    }

    /// The rig it solves for.
    #[must_use]
    pub fn rig(&self) -> &HandRig {
        &self.rig
    }

    /// The 25 WebXR joint positions of MediaPipe `landmarks` (metres): the 21 landmarks in
    /// place, each finger metacarpal's base where our hand has it in the tracked palm's
    /// frame, scaled by the tracked palm's length.
    ///
    /// # Errors
    /// [`RejectKind::Unusable`] if the landmarks' palm spans no frame.
    pub fn landmark_joints(&self, landmarks: &[Vec3; LANDMARK_COUNT], out: &mut [Vec3; JOINT_COUNT]) -> Result<(), Rejection> {
        for (l, &w) in landmarks.iter().zip(&mediapipe::WEBXR_INDEX) {
            out[w] = *l;
        }
        let palm = palm_frame(out).ok_or_else(|| Rejection::new(RejectKind::Unusable, "landmarks: the knuckles and wrist span no palm"))?;
        let scale = (out[MIDDLE_MCP] - out[WRIST]).length();
        for (m, base) in METACARPALS.iter().zip(&self.metacarpal_base) {
            out[*m] = out[WRIST] + palm * *base * scale;
        }
        Ok(())
    }

    /// Solves `out` (angles of the rig's joint model, wrist) from tracked joint `positions`
    /// of a `side` hand in WebXR order. Allocates nothing.
    ///
    /// # Errors
    /// [`RejectKind::Unusable`] if the palm spans no frame or a bone has no length.
    ///
    /// # Panics
    /// If `out` has another angle count than the rig's joint model.
    pub fn solve(&mut self, positions: &[Vec3; JOINT_COUNT], side: Side, out: &mut Pose) -> Result<(), Rejection> {
        assert_eq!(out.angles.len(), self.rig.dofs().len(), "pose angle count");
        let mirror = if side == self.side { Vec3::ONE } else { Vec3::new(-1.0, 1.0, 1.0) };
        for (p, q) in self.positions.iter_mut().zip(positions) {
            *p = *q * mirror;
        }
        let p = self.positions;
        let palm = palm_frame(&p).ok_or_else(|| Rejection::new(RejectKind::Unusable, "joints: the knuckles and wrist span no palm"))?;
        let rest_wrist = self.rest_world[self.rig.wrist()];
        let rotation = Quat::from_mat3(&(palm * self.rest_palm.transpose() * Mat3::from(rest_wrist.matrix3))).normalize();
        let wrist = Affine3A::from_rotation_translation(rotation, p[WRIST]);
        self.world[self.rig.wrist()] = wrist;
        out.wrist = Some(DualQuat::from_rotation_translation(rotation, p[WRIST]));
        out.angles.fill(0.0);
        for s in 0..self.steps.len() {
            let step = &self.steps[s];
            let (w, child) = step.webxr;
            let along = p[child] - p[w];
            if along.length_squared() < 1e-12 {
                return Err(Rejection::new(RejectKind::Unusable, format!("joints: {} and {} coincide", webxr::JOINT_NAMES[w], webxr::JOINT_NAMES[child])));
            }
            let frame = self.world[step.parent] * self.rest_local(step.joint);
            let to_frame = frame.matrix3.inverse();
            let u = to_frame.mul_vec3(along.into()).normalize();
            // The finger's bending plane: its normal is the next joint's flexion axis.
            let plane = step.beyond.and_then(|b| {
                let next = (p[b] - p[child]).try_normalize()?;
                Some(to_frame.mul_vec3(along.normalize().cross(next).into()))
            });
            solve_joint(step, u, plane, &mut out.angles);
            self.world[step.joint] = self.world[step.parent] * self.local(step, &out.angles);
        }
        self.bring_contacts_together(out);
        Ok(())
    }

    /// The rest local transform of `joint` as an affine (its parent's frame → its rest frame).
    fn rest_local(&self, joint: usize) -> Affine3A {
        self.rig.skeleton().joints()[joint].rest.to_affine()
    }

    /// The posed local transform of a step's joint for `angles`.
    fn local(&self, step: &Step, angles: &[f32]) -> Affine3A {
        let mut t = self.rig.skeleton().joints()[step.joint].rest;
        for &(i, d, _) in &step.dofs {
            t.rotation = d.turn(t.rotation, angles[i]);
        }
        t.to_affine()
    }

    /// World position of the tip at the end of `chain` for `angles`, from the wrist's world
    /// transform in `self.world` (which is left untouched).
    fn tip(&self, chain: usize, angles: &[f32]) -> Vec3 {
        let steps = &self.steps[self.chains[chain].clone()];
        let mut world = self.world[steps[0].parent];
        for step in steps {
            world = world * self.local(step, angles);
        }
        let last = steps.last().expect("chains have joints");
        let (_, tip) = last.webxr;
        let tip_joint = self.rig.skeleton().find(webxr::JOINT_NAMES[tip]).expect("checked in new");
        world.transform_point3(self.rig.skeleton().joints()[tip_joint].rest.translation)
    }

    /// The contact IK: see the module docs.
    fn bring_contacts_together(&self, out: &mut Pose) {
        let p = &self.positions;
        let Some((finger, gap)) = FINGER_TIPS
            .iter()
            .enumerate()
            .map(|(f, &t)| (f + 1, p[THUMB_TIP] - p[t]))
            .min_by(|a, b| a.1.length().total_cmp(&b.1.length()))
        else {
            return;
        };
        let weight = ((CONTACT_FADE - gap.length()) / (CONTACT_FADE - CONTACT_FULL)).clamp(0.0, 1.0);
        if weight == 0.0 {
            return;
        }
        // DOFs that may move: the thumb's fully, the finger's at a third of the step.
        let mut movable = [(0usize, 0.0f32, 0.0f32, 0.0f32); 12];
        let mut n = 0;
        for (chain, share) in [(0, 1.0), (finger, 0.33)] {
            for step in &self.steps[self.chains[chain].clone()] {
                for &(i, d, _) in &step.dofs {
                    if n < movable.len() {
                        movable[n] = (i, share, d.min, d.max);
                        n += 1;
                    }
                }
            }
        }
        let movable = &movable[..n];
        let count = out.angles.len();
        let mut buffer = [0.0f32; MAX_DOFS];
        buffer[..count].copy_from_slice(&out.angles);
        let start = buffer;
        let angles = &mut buffer[..count];
        let aim = gap * ((gap.length() - CONTACT_MARGIN).max(0.0) / gap.length().max(f32::MIN_POSITIVE));
        let residual = |s: &Self, a: &[f32]| s.tip(0, a) - s.tip(finger, a) - aim;
        for _ in 0..16 {
            let e = residual(self, angles);
            if e.length() < 1e-4 {
                break;
            }
            // J W Jᵀ for the damped least-squares step.
            let mut columns = [Vec3::ZERO; 12];
            for (c, &(i, _, _, _)) in columns.iter_mut().zip(movable) {
                let keep = angles[i];
                angles[i] = keep + 1e-3;
                *c = (residual(self, angles) - e) / 1e-3;
                angles[i] = keep;
            }
            let mut jwj = Mat3::from_diagonal(Vec3::splat(1e-4));
            for (c, &(_, share, _, _)) in columns.iter().zip(movable) {
                jwj += Mat3::from_cols(*c * c.x, *c * c.y, *c * c.z) * share;
            }
            let y = jwj.inverse() * -e;
            for (c, &(i, share, min, max)) in columns.iter().zip(movable) {
                angles[i] = (angles[i] + share * c.dot(y)).clamp(min, max);
            }
        }
        for (o, (a, s)) in out.angles.iter_mut().zip(angles.iter().zip(&start)) {
            *o = s + weight * (a - s);
        }
    }
}

/// Solves one joint's angles so its bone, `rest_dir` in the rest frame, points along `u` (in
/// the same frame), clamped to the joint's ranges.
///
/// Abduction turns about an axis the bone nears as the joint flexes (a knuckle at 90°
/// points its finger along it), where the bone's direction no longer tells abduction apart.
/// The finger's bending plane still does: `plane` (first bone × next bone, in the same
/// frame) is the next joint's flexion axis, which abduction turns from the rest −X. The two
/// estimates are weighted by how well each is conditioned (sin² of the bone's angle to the
/// abduction axis; sin² of the next joint's bend).
fn solve_joint(step: &Step, u: Vec3, plane: Option<Vec3>, angles: &mut [f32]) {
    let d0 = step.rest_dir;
    match step.dofs.as_slice() {
        [] => {}
        [(i, d, _)] => angles[*i] = signed_angle(d.axis, d0, u).clamp(d.min, d.max),
        [(ia, a, Motion::Abd), (iflex, f, Motion::Flex)] => {
            // R_A(α) R_F(φ) d0 = u. R_A keeps the component along A, which fixes φ:
            // A·R_F(φ)d0 = p cos φ + q sin φ = A·u, with p = A·d0, q = A·(F × d0).
            let (axis_a, axis_f) = (a.axis, f.axis);
            let (p, q) = (axis_a.dot(d0), axis_a.dot(axis_f.cross(d0)));
            let rho = libm::hypotf(p, q);
            let candidates = if rho < 1e-6 {
                [0.0, 0.0]
            } else {
                let (phase, spread) = (libm::atan2f(q, p), libm::acosf((axis_a.dot(u) / rho).clamp(-1.0, 1.0)));
                [wrap(phase + spread), wrap(phase - spread)]
            };
            // Of the two flexions, the one that needs the least abduction.
            let (flex, abd) = candidates
                .map(|phi| (phi, signed_angle(axis_a, Quat::from_axis_angle(axis_f, phi) * d0, u)))
                .into_iter()
                .min_by(|x, y| (x.1.abs() + x.0.abs() * 1e-3).total_cmp(&(y.1.abs() + y.0.abs() * 1e-3)))
                .expect("two candidates");
            let w_bone = 1.0 - axis_a.dot(u) * axis_a.dot(u);
            let abd = match (plane, step.bend_axis) {
                (Some(n), Some(bend)) if n.length_squared() > 1e-6 => {
                    let from_plane = signed_angle(axis_a, Quat::from_axis_angle(axis_f, flex) * bend, n);
                    // A bend the other way (hyperextension) flips the normal: no estimate then.
                    if (from_plane - abd).abs() < core::f32::consts::FRAC_PI_2 {
                        let w_plane = n.length_squared();
                        (w_bone * abd + w_plane * from_plane) / (w_bone + w_plane)
                    } else {
                        abd
                    }
                }
                _ => abd,
            };
            angles[*iflex] = flex.clamp(f.min, f.max);
            angles[*ia] = abd.clamp(a.min, a.max);
        }
        other => unreachable!("a joint model turns a joint by at most abduction then flexion, not {other:?}"),
    }
}

/// The angle about `axis` that turns `from` toward `to`, both projected on the plane normal to
/// `axis`.
fn signed_angle(axis: Vec3, from: Vec3, to: Vec3) -> f32 {
    let (a, b) = (from - axis * axis.dot(from), to - axis * axis.dot(to));
    libm::atan2f(axis.dot(a.cross(b)), a.dot(b))
}

fn wrap(angle: f32) -> f32 {
    use core::f32::consts::{PI, TAU};
    (angle + PI).rem_euclid(TAU) - PI
}

/// The palm frame of WebXR joint positions: columns across (toward the index), normal,
/// forward (wrist to middle knuckle); `None` if the points span no frame. It rests on the
/// index and middle metacarpals, which do not move against the wrist (their carpometacarpal
/// joints are all but rigid), so cupping the palm (ring and little CMC) does not tilt it.
fn palm_frame(p: &[Vec3; JOINT_COUNT]) -> Option<Mat3> {
    let forward = (p[MIDDLE_MCP] - p[WRIST]).try_normalize()?;
    let normal = forward.cross(p[INDEX_MCP] - p[MIDDLE_MCP]).try_normalize()?;
    Some(Mat3::from_cols(normal.cross(forward), normal, forward))
}
