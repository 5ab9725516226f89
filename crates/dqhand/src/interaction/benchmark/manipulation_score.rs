//! Measures of the manipulation loop on scripted grasps ([`crate::interaction::grasp_script`]):
//! whether the object was picked up, carried and set down, how deep the rendered skin went
//! into it, how far a carried object slipped in the hand, how many frames the release took,
//! whether the hand passed into or through anything, and how long a frame took.
//!
//! Penetration is measured on the rendered DQB skin against each object's true surface, not
//! against the proxies the contact constraint uses: a primitive's exact shape (parry's point
//! projection), a mesh's triangles by the generalised winding number (it is inside where the
//! number passes ½, which holds for an open mesh like the Utah teapot too) and its distance,
//! within [`MESH_DEPTH_RANGE_M`] of the surface.

use std::sync::Arc;
use std::time::Instant;

use glam::{Quat, Vec3};
use parry3d::bounding_volume::Aabb;
use parry3d::query::Ray;
use serde::Serialize;

use crate::collision::{Closure, ObjectCollider, ObjectColliders};
use crate::geometry::winding_number;
use crate::grasp::GraspEvent;
use crate::interaction::grasp_script::{Script, RATE_HZ};
use crate::interaction::ManipulationLoop;
use crate::kinematics::JointPositions;
use crate::skin::{Method, MethodSet, SkinLayer};

/// Farthest a set-down object may rest from where the script carried it, m.
pub const PLACE_TOLERANCE_M: f32 = 0.03;

/// Deepest the rendered skin may be in a held object on any frame of a successful run, m.
pub const HELD_DEPTH_M: f32 = 0.001;

/// How far inside a mesh object depth is measured, m: the winding number over every triangle
/// is too slow for every vertex of every frame, and skin deeper than this would have crossed
/// the surface within it on its way in (the palm-crossing check counts a hand gone further).
pub const MESH_DEPTH_RANGE_M: f32 = 0.01;

/// The least change of a rendered finger's closure in one frame that counts as a jump (rad).
pub const JUMP_RAD: f32 = 0.15;

/// A mesh's vertex positions and flat triangle indices, as the winding number reads them.
pub type FlatMesh = (Vec<[f32; 3]>, Vec<u32>);

/// What one scripted run measured.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RunScore {
    /// The object was grasped before the carry, held through it with the rendered skin no
    /// deeper in it than [`HELD_DEPTH_M`] on any frame, let go once the fingers opened, and
    /// came to rest within [`PLACE_TOLERANCE_M`] of where it was carried.
    pub success: bool,
    /// Where the object came to rest, from where it was carried to, m.
    pub place_error_m: f32,
    /// The deepest any rendered skin vertex went into any object, over the run, m.
    pub max_penetration_m: f32,
    /// The mean over frames with a contact of each frame's deepest vertex, m.
    pub mean_penetration_m: f32,
    /// The deepest any rendered skin vertex went into the object on a frame it was held, m.
    pub held_penetration_m: f32,
    /// How far the carried object moved in the tracked wrist's frame during the carry, m (the
    /// wrist of the hand holding it when the carry began).
    pub slip_m: f32,
    /// How far it turned in that frame, degrees.
    pub slip_deg: f32,
    /// How much farther the rendered wrist fell behind the true one along the carry than it
    /// was at the carry's start, at most, m: the hand and what it holds lagging the user's.
    pub carry_lag_m: f32,
    /// How far across (in the horizontal plane) the object moved from where the hand let it
    /// go, m: by the time it has fallen half way to the table when dropped (before landing,
    /// where a cube may tip over), or to where it comes to rest when set down. A still hand's
    /// opening fingers must not bat it away.
    pub release_drift_m: f32,
    /// Frames from the fingers beginning to open to the release, if released.
    pub release_frames: Option<u32>,
    /// The rendered palm's centre or a finger's last phalanx crossed the surface of an object
    /// it did not hold between two frames.
    pub tunnelled: bool,
    /// How many times a rendered finger jumped in one frame where the tracked finger did not:
    /// its closure (the sum of its closing angles) changed by more than [`JUMP_RAD`] and
    /// three times the tracked finger's change. A flicker between two poses counts each frame.
    pub finger_jumps: u32,
    /// Seconds each frame's [`ManipulationLoop::step`] took (collision, grasp, physics; every
    /// hand's).
    #[serde(skip)]
    pub step_s: Vec<f64>,
}

/// How deep `p` (world) is inside `object`'s true surface, m; 0 outside. `mesh` is the
/// object's triangles flattened for the winding number (a mesh object's only).
#[must_use]
pub fn depth(object: &ObjectCollider, mesh: Option<&FlatMesh>, p: Vec3) -> f32 {
    if !object.aabb().contains_local_point(p) {
        return 0.0;
    }
    let local = object.pose.inverse_transform_point(p);
    // Projected onto the boundary (not solid): the nearest surface point, and whether `p` is
    // inside, which a primitive knows exactly and a mesh's winding number decides.
    let projection = object.surface.project_local_point(local, false);
    let distance = projection.point.distance(local);
    let inside = match mesh {
        Some((positions, indices)) => distance <= MESH_DEPTH_RANGE_M && winding_number(positions, indices, local) >= 0.5,
        None => projection.is_inside,
    };
    if inside {
        distance
    } else {
        0.0
    }
}

/// WebXR indices of the points that must not cross a surface: the middle of each finger's
/// distal phalanx, between its distal joint and its tip (the tip itself lies on the skin, and
/// touches what the finger rests on); the palm's centre is added between the wrist (0) and the
/// middle finger's knuckle (11).
const TIPS: [(usize, usize); 5] = [(3, 4), (8, 9), (13, 14), (18, 19), (23, 24)];

/// Runs `script` through `manip` (fresh, on the script's scene; one hand or two, as the script
/// has records of one side or both) and scores it: `object` is the index of the scripted
/// object, `carried_to` where the script sets it down.
///
/// # Panics
/// If the loop's skeleton lacks the WebXR joints (the built-in hand has them).
pub fn score(manip: &mut ManipulationLoop, script: &Script, object: usize, carried_to: Vec3) -> RunScore {
    let meshes: Vec<Option<FlatMesh>> = manip
        .objects()
        .objects()
        .iter()
        .map(|o| o.mesh.as_ref().map(|m| (m.vertices.iter().map(|v| v.to_array()).collect(), m.triangles.iter().flatten().copied().collect())))
        .collect();
    let joints: Vec<JointPositions> = manip.hands().iter().map(|h| JointPositions::new(h.rendered().skeleton()).expect("a hand with WebXR joints")).collect();
    let mut rendered_skin: Vec<SkinLayer> = manip.hands().iter().map(|h| SkinLayer::new(Arc::clone(&h.input().model().mesh), MethodSet::DQB)).collect();
    let times = script.times;
    let mut score = RunScore {
        success: false,
        place_error_m: f32::INFINITY,
        max_penetration_m: 0.0,
        mean_penetration_m: 0.0,
        held_penetration_m: 0.0,
        slip_m: 0.0,
        slip_deg: 0.0,
        carry_lag_m: 0.0,
        release_drift_m: 0.0,
        release_frames: None,
        tunnelled: false,
        finger_jumps: 0,
        step_s: Vec::with_capacity(script.records.len()),
    };
    let (mut grasped_before_carry, mut held_through_carry) = (false, true);
    let mut released = false;
    let (mut penetration_sum, mut contact_frames) = (0.0f64, 0u32);
    // The hands holding the object and the object in their frame when the carry began.
    let mut in_wrist: Option<(Vec<Quat>, (Quat, Vec3))> = None;
    let mut carrier: Option<usize> = None;
    let mut carry_offset: Option<f32> = None;
    let mut let_go: Option<Vec3> = None;
    let mut fallen: Option<Vec3> = None;
    let mut rendered_points: Vec<Option<[Vec3; TIPS.len() + 1]>> = vec![None; manip.hands().len()];
    let mut closures: Vec<Option<[Closure; 5]>> = vec![None; manip.hands().len()];
    let mut skin: Vec<[f32; 3]> = Vec::new();
    let mut next = 0;
    while next < script.records.len() {
        // A frame: the records of its time (one per hand); a script's records are all good.
        let t = script.records[next].time;
        let frame = next..next + script.records[next..].iter().take_while(|r| r.time == t).count();
        next = frame.end;
        for record in &script.records[frame.clone()] {
            let _ = manip.push(record);
        }
        let started = Instant::now();
        let events = manip.step(t);
        score.step_s.push(started.elapsed().as_secs_f64());
        let holder = manip.hands().iter().position(|h| h.held() == Some(object));
        if t < times.carry_start && holder.is_some() {
            grasped_before_carry = true;
        }
        if t >= times.carry_start && t <= times.carry_end {
            held_through_carry &= holder.is_some();
            let hands = manip.hands();
            match carrier.or(holder).map(|k| &hands[k]).filter(|h| h.held() == Some(object)) {
                Some(hand) => {
                    carrier = carrier.or(holder);
                    // The object in the frame of the hands holding it: one hand's tracked wrist,
                    // or for two the mean of their turns since the carry began about their
                    // wrists' mean (a pair's fit moves with both hands, and slip is the object
                    // moving in the grip, not one hand's jitter against the other's; the two
                    // wrists face each other, so their own rotations have no useful mean).
                    let wrists: Vec<(Quat, Vec3)> = hands
                        .iter()
                        .filter(|h| h.held() == Some(object))
                        .map(|h| {
                            let (_, q, t) = h.constraint().tracked_world()[h.rendered().rig().wrist()].to_scale_rotation_translation();
                            (q, t)
                        })
                        .collect();
                    let centre = wrists.iter().map(|w| w.1).sum::<Vec3>() / wrists.len() as f32;
                    let (q, p) = manip.poses()[object];
                    // A hand joining or leaving the hold starts a new reference (no turn yet).
                    if in_wrist.as_ref().is_none_or(|(starts, _)| starts.len() != wrists.len()) {
                        in_wrist = Some((wrists.iter().map(|w| w.0).collect(), (q, p - centre)));
                    }
                    let (starts, first) = in_wrist.as_ref().expect("set above");
                    let turn = wrists.iter().zip(starts).fold(Quat::from_xyzw(0.0, 0.0, 0.0, 0.0), |sum, (w, s)| {
                        let d = w.0 * s.inverse();
                        sum + if sum.dot(d) < 0.0 { -d } else { d }
                    });
                    let turn = turn.normalize();
                    let here = (turn.inverse() * q, turn.inverse() * (p - centre));
                    score.slip_m = score.slip_m.max(here.1.distance(first.1));
                    score.slip_deg = score.slip_deg.max(here.0.angle_between(first.0).to_degrees());
                    let truth = frame.clone().find(|&r| hands[manip.hand_of(script.records[r].side)].side() == hand.side()).and_then(|r| script.truth[r].wrist);
                    if let (Some(rendered), Some(true_wrist)) = (hand.constraint().rendered().wrist, truth) {
                        let behind = (true_wrist.to_rotation_translation().1 - rendered.to_rotation_translation().1).dot(script.carry.normalize_or_zero());
                        let first = *carry_offset.get_or_insert(behind);
                        score.carry_lag_m = score.carry_lag_m.max(behind - first);
                    }
                }
                None => held_through_carry = false,
            }
        }
        // Let go by the last hand holding it.
        let let_go_now = events.iter().any(|(_, e)| matches!(e, GraspEvent::Release { object: o, .. } if o == object)) && holder.is_none();
        if let_go_now && t >= times.release && !released {
            released = true;
            let_go = Some(manip.poses()[object].1);
            score.release_frames = Some(((t - times.release) * RATE_HZ).round() as u32);
        }
        if let (Some(at), None) = (let_go, fallen) {
            let now = manip.poses()[object].1;
            if script.drop > 0.0 && at.y - now.y >= script.drop / 2.0 {
                fallen = Some(now);
            }
        }
        skin.clear();
        for (k, hand) in manip.hands().iter().enumerate() {
            // The rendered palm's centre (between the wrist and the middle finger's knuckle)
            // and the fingertips must not cross a surface between frames.
            let p = joints[k].read(hand.rendered().world());
            let mut now = [(p[0] + p[11]) / 2.0; TIPS.len() + 1];
            for (n, &(distal, tip)) in now[1..].iter_mut().zip(&TIPS) {
                *n = (p[distal] + p[tip]) / 2.0;
            }
            if let Some(last) = rendered_points[k].replace(now) {
                score.tunnelled |= last.iter().zip(&now).any(|(a, b)| crossed(manip.objects(), hand.held(), *a, *b));
            }
            let closure = *hand.constraint().closure();
            if let Some(last) = closures[k].replace(closure) {
                let jumped = |(a, b): (&Closure, &Closure)| {
                    let rendered = (b.rendered - a.rendered).abs();
                    rendered > JUMP_RAD && rendered > 3.0 * (b.tracked - a.tracked).abs()
                };
                score.finger_jumps += last.iter().zip(&closure).filter(|&p| jumped(p)).count() as u32;
            }
            rendered_skin[k].deform(hand.rendered().layer());
            skin.extend_from_slice(rendered_skin[k].deformed(Method::Dqb).expect("DQB is the set").positions());
        }
        let colliders = manip.objects().objects();
        let (mut deepest, mut in_held) = (0.0f32, 0.0f32);
        for v in &skin {
            let v = Vec3::from(*v);
            for (i, (o, m)) in colliders.iter().zip(&meshes).enumerate() {
                let d = depth(o, m.as_ref(), v);
                deepest = deepest.max(d);
                if i == object {
                    in_held = in_held.max(d);
                }
            }
        }
        score.max_penetration_m = score.max_penetration_m.max(deepest);
        if holder.is_some() {
            score.held_penetration_m = score.held_penetration_m.max(in_held);
        }
        if manip.hands().iter().any(|h| !h.contacts().is_empty()) {
            penetration_sum += f64::from(deepest);
            contact_frames += 1;
        }
    }
    score.mean_penetration_m = if contact_frames > 0 { (penetration_sum / f64::from(contact_frames)) as f32 } else { 0.0 };
    // A dropped object: where it was let go to fall (half way down, before it lands: a cube
    // may tip over on landing), across; a set-down one: where it rests.
    score.place_error_m = match fallen {
        Some(f) => Vec3::new(f.x - carried_to.x, 0.0, f.z - carried_to.z).length(),
        None => manip.poses()[object].1.distance(carried_to),
    };
    if let Some(at) = let_go {
        let rest = fallen.unwrap_or(manip.poses()[object].1);
        score.release_drift_m = Vec3::new(rest.x - at.x, 0.0, rest.z - at.z).length();
    }
    score.success = grasped_before_carry && held_through_carry && score.held_penetration_m <= HELD_DEPTH_M && released && manip.hands().iter().all(|h| h.held() != Some(object)) && score.place_error_m <= PLACE_TOLERANCE_M;
    score
}

/// Whether the segment `from`–`to` crosses the surface of an object (or the table) other
/// than `skip`; not a hand's proxies ([`ObjectColliders::near`] leaves them out between
/// solves). A mesh's inside is where parry's point query puts it.
fn crossed(objects: &ObjectColliders, skip: Option<usize>, from: Vec3, to: Vec3) -> bool {
    let length = from.distance(to);
    if length <= f32::EPSILON {
        return false;
    }
    let ray = Ray::new(from, (to - from) / length);
    // Into or out of it, or in and out again within the step (both ends outside, the ray
    // meets it): a point that stays inside has not crossed (it is a depth, measured apart).
    objects.near(&Aabb::from_points([from, to]), 0.0, skip).any(|(_, o)| {
        let inside = |p: Vec3| o.surface.contains_point(&o.pose, p);
        match (inside(from), inside(to)) {
            (false, false) => o.surface.cast_ray(&o.pose, &ray, length, true).is_some(),
            (a, b) => a != b,
        }
    })
}
