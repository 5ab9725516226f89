//! The rendered hand, constrained by contacts: the tracked hand may go inside an object, the
//! hand the user sees does not.
//!
//! Two stages per frame, both continuous (a time of impact along the motion, never a test at
//! the end of it only, so nothing fast or thin is passed through):
//! 1. **Wrist.** The hand's proxies, its fingers as last rendered, move rigidly from the last
//!    rendered wrist to the tracked one (a screw: rotation about the wrist, translation of
//!    it); parry's nonlinear shape cast (against a mesh, [`ProxyMeshQuery`]'s advancement)
//!    gives the first time of impact with any object or the table, and the wrist stops just
//!    before it (a gap of [`STOP_DISTANCE`], so that the
//!    next frame's cast starts clear of the surface: a cast that starts touching may let the
//!    hand sink), the palm (or a finger) on the surface. After [`SNAP_AFTER_S`] held back,
//!    the wrist jumps to a tracked pose whose hand is free again (the user has gone round the
//!    object, or tracking came back elsewhere). While an object is held the rendered hand
//!    keeps its grip: it moves with the object, where it was on it at the grasp, so the
//!    tracked hand closing further (it goes into the object) does not pull the rendered one in.
//! 2. **Fingers.** Each finger closes along its flexion, from open to the tracked angles, by
//!    conservative advancement: the distance of its proxies to the objects over an upper bound
//!    of how fast any of their points moves per unit of the closure gives a step that cannot
//!    pass through anything. A proxy is measured again only once that bound may have fallen to
//!    the stop distance; against a mesh its distance is [`ProxyMeshQuery`]'s (exact for a
//!    capsule; parry's in metres is centimetres long there). At the first contact the joints proximal to the touching phalanx
//!    stop and the distal ones close on, so the finger wraps the object. Where the open
//!    finger would itself be in an object (a thumb lying on the ball under the palm) the
//!    closure starts from the finger as last rendered, which the wrist stage kept clear; a
//!    finger touching the held object starts there too, and keeps its grip. The ring and
//!    little fingers' chains begin at their CMC joints, which arch the palm as they close.
//!
//! The contacts of the rendered pose are every proxy within [`CONTACT_DISTANCE`] of an object:
//! against a mesh, the nearest point [`ProxyMeshQuery`] finds.
//!
//! The tracked pose is left as it is: the grasp logic reads it.

use std::sync::{Arc, Mutex, PoisonError};

use glam::{Affine3A, Vec3};
use parry3d::bounding_volume::{Aabb, BoundingVolume};
use parry3d::query::{self, NonlinearRigidMotion};

use super::proxy_mesh_query::{ProxyMeshQuery, TOLERANCE};
use super::hand_proxies::pose_of;
use super::{HandPart, HandProxies, ObjectCollider, ObjectColliders, FINGERS};
use crate::kinematics::{forward_kinematics, forward_kinematics_of, HandKinematics, Motion, Pose, Transform};
use crate::math::DualQuat;
use crate::skin::Crew;

/// Proxies closer than this to an object touch it (m).
pub const CONTACT_DISTANCE: f32 = 0.002;

/// A finger or the wrist stops this close to a surface (m): the proxies' margin keeps the
/// skin off.
pub const STOP_DISTANCE: f32 = 0.0004;

/// Wrist motions that together move no proxy point farther than this (m) since the last cast
/// are not cast: nothing is passed through in a micrometre, and a still hand would ask every
/// query of the last frame again (a hand closing on an object holds its wrist still).
const STILL_M: f32 = 1e-6;

/// Steps of conservative advancement per finger stage: enough to converge from any start; a
/// finger that has not converged stays where it safely is.
const MAX_ADVANCES: usize = 40;

/// How much farther than it can move a proxy must be from a mesh object's hull for its cast to
/// be skipped (m): parry's GJK distance in metres to small faces can be centimetres long (see
/// `proxy_mesh_query`'s `UNIT`); no cast is skipped on such an answer.
const MESH_DISTANCE_SLACK: f32 = 0.01;

/// How far a finger's proxy looks for a mesh object's nearest triangle (m): a proxy farther
/// than this advances as if it were this far (one more step, where a search of the whole
/// mesh would cost more than it saves).
const MESH_LOOKOUT: f32 = 0.03;

/// How much less a finger's start must overlap a mesh than the finger as last rendered for
/// the finger to jump to it when no start is clear (m): less would let it flicker between
/// starts with the tracking's jitter.
const SWITCH_OVERLAP: f32 = 0.0001;

/// Seconds the rendered wrist may be held back before it jumps to a free tracked pose.
pub const SNAP_AFTER_S: f64 = 0.5;

/// A proxy touching an object in the rendered pose.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Contact {
    /// The joint whose proxy touches.
    pub joint: usize,
    /// Its part of the hand.
    pub part: HandPart,
    /// Index of the object in the scene.
    pub object: usize,
    /// The nearest point of the object's surface (world).
    pub point: Vec3,
    /// The object's surface normal there, pointing at the hand (world, unit).
    pub normal: Vec3,
    /// Gap between proxy and surface (m; 0 or less when they overlap).
    pub distance: f32,
}

/// How closed a finger is: the sum of its flexion angles (radians), tracked and rendered.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Closure {
    /// The user's.
    pub tracked: f32,
    /// The rendered finger's, stopped by contact.
    pub rendered: f32,
}

/// One finger's closing chain, resolved once.
#[derive(Clone, Debug, Default)]
struct FingerChain {
    /// The DOFs that close it (flexion; the thumb's CMC abduction too), proximal first:
    /// (index in the pose, joint it turns).
    dofs: Vec<(usize, usize)>,
    /// The rest of its DOFs (abduction, twist), indices in the pose: a gripping finger keeps
    /// them too.
    others: Vec<usize>,
    /// The joints its closure moves (its first DOF's joint and all below it), parents first,
    /// and every DOF turning them (ascending indices in the pose): what each step of its
    /// advancement poses again.
    joints: Vec<usize>,
    turns: Vec<usize>,
    /// Its proxies: (index in [`HandProxies::colliders`], the last DOF (position in `dofs`)
    /// that moves it, and per DOF an upper bound of the distance of its core's points (a
    /// capsule's segment: its distance falls no faster than they move) from that DOF's
    /// joint, 0 where the DOF does not move it).
    proxies: Vec<(usize, usize, Vec<f32>)>,
    /// The largest distance of any of its proxies' points from its first DOF's joint.
    reach: f32,
    /// Per proxy, during the closure: a lower bound of its distance to the objects and the
    /// closure parameter it was measured at (it falls no faster than the proxy moves).
    bounds: Vec<(f32, f32)>,
}

/// A bound that must be measured.
const UNMEASURED: (f32, f32) = (f32::NEG_INFINITY, 0.0);

/// One finger's closure (stage 2) with buffers of its own, so that the five may close at
/// once ([`ContactConstraint::set_crew`]), each on its own copy of the pose, and give back
/// their DOFs.
#[derive(Clone)]
struct FingerCloser {
    chain: FingerChain,
    /// The pose it tries: the frame's rendered pose so far, its own DOFs as it closes.
    trial: Pose,
    /// The local and world transforms of the poses that conservative advancement tries.
    trial_locals: Vec<Transform>,
    trial_world: Vec<Affine3A>,
    /// The objects within its reach in its last closure (none where it kept its grip
    /// without closing).
    near: Vec<usize>,
    /// Its own queries' buffers and remembered directions.
    query: ProxyMeshQuery,
    /// How many of its leading closing joints its last closure stopped on contacts with the
    /// held object.
    held_prefix: usize,
    /// Whether its last closure reached the tracked angles untouched.
    free: bool,
}

/// What every finger's closure reads: the frame's hand so far, the last one, and the scene.
struct ClosureScene<'a> {
    kinematics: &'a HandKinematics,
    proxies: &'a HandProxies,
    /// The tracked angles, the rendered wrist.
    rendered: &'a Pose,
    previous: &'a Pose,
    tracked: &'a Pose,
    /// The last frame's contacts.
    contacts: &'a [Contact],
    objects: &'a ObjectColliders,
    held: Option<usize>,
    /// Whether the hand is still on the held object (see [`ContactConstraint::solve`]).
    still: bool,
}

/// Solves the rendered pose from the tracked one each frame; every buffer is allocated once.
#[derive(Clone)]
pub struct ContactConstraint {
    proxies: HandProxies,
    fingers: [FingerCloser; 5],
    /// The rendered hand, posed once per solve.
    kinematics: HandKinematics,
    tracked_world: Vec<Affine3A>,
    tracked: Pose,
    rendered: Pose,
    /// The last frame's rendered pose: where a finger closes from when its open pose is not
    /// clear.
    previous: Pose,
    wrist: Option<DualQuat>,
    /// The object held and the rendered wrist in its frame at the grasp.
    grip: Option<(usize, DualQuat)>,
    held_back_since: Option<f64>,
    /// The object that carried the rendered hand (its grip) in the last solve, and its pose
    /// there: the contacts with it were found at that pose.
    carried: Option<(usize, parry3d::math::Pose)>,
    /// How far the wrist may have moved (m, any proxy point) since its last cast: motions too
    /// small to cast add up to [`STILL_M`] at most.
    uncast: f32,
    /// Per joint: the finger whose closure moves it (none for the wrist and the metacarpals that
    /// only the wrist moves; the ring and little metacarpals turn with their fingers).
    moved_by: Vec<Option<usize>>,
    contacts: Vec<Contact>,
    /// The last frame's contacts (a second buffer, swapped with `contacts`).
    last_contacts: Vec<Contact>,
    closure: [Closure; 5],
    mesh_query: ProxyMeshQuery,
    /// The proxy (index in [`HandProxies::colliders`]) that last stopped the wrist: cast first.
    first_stop: usize,
    /// Threads the fingers close on ([`Self::set_crew`]); none: the caller's alone.
    crew: Option<Arc<Crew>>,
}

impl ContactConstraint {
    /// A constraint for `proxies` on the skeleton of `kinematics`, which poses the rendered
    /// hand (with its limits).
    #[must_use]
    pub fn new(proxies: HandProxies, kinematics: HandKinematics) -> Self {
        let rig = kinematics.rig();
        let skeleton = rig.skeleton();
        let joints = skeleton.joints();
        let rest = skeleton.rest_world();
        let at = |j: usize| Vec3::from(rest[j].translation);
        let is_ancestor = |a: usize, mut j: usize| loop {
            if j == a {
                return true;
            }
            match joints[j].parent {
                Some(p) => j = p,
                None => return false,
            }
        };
        // Length of the chain from `a` down to `j`: no bend of the joints between can put
        // `j` farther from `a` (triangle inequality).
        let chain_length = |a: usize, mut j: usize| {
            let mut length = 0.0;
            while j != a {
                let p = joints[j].parent.expect("a descendant");
                length += at(j).distance(at(p));
                j = p;
            }
            length
        };
        let fingers = core::array::from_fn(|f| {
            // Flexion (the ring and little fingers' from their CMC joints, which arch the palm),
            // and the thumb's opposition (CMC abduction), which also closes it.
            let closes = |d: &crate::kinematics::Dof| d.motion == Motion::Flex || d.bone == "thumb-metacarpal";
            let (mut dofs, mut others) = (Vec::new(), Vec::new());
            for (i, (d, r)) in rig.model().dofs().zip(rig.dofs()).enumerate() {
                if !joints[r.joint].name.starts_with(FINGERS[f]) {
                    continue;
                }
                if closes(d) {
                    dofs.push((i, r.joint));
                } else {
                    others.push(i);
                }
            }
            let depth = |mut j: usize| {
                let mut d = 0;
                while let Some(p) = joints[j].parent {
                    (j, d) = (p, d + 1);
                }
                d
            };
            dofs.sort_by_key(|&(_, j)| depth(j));
            assert!(dofs.len() <= 4, "at most four closing DOFs per finger");
            let mut reach: f32 = 0.0;
            // Every proxy the chain moves: its phalanges', and a metacarpal's that turns.
            let proxies = proxies
                .colliders()
                .iter()
                .enumerate()
                .filter_map(|(i, p)| {
                    let levers: Vec<f32> = dofs.iter().map(|&(_, j)| if is_ancestor(j, p.joint) { chain_length(j, p.joint) + p.lever } else { 0.0 }).collect();
                    let last = levers.iter().rposition(|&l| l > 0.0)?;
                    reach = reach.max(levers[0] + p.extent - p.lever);
                    Some((i, last, levers))
                })
                .collect::<Vec<_>>();
            let bounds = vec![UNMEASURED; proxies.len()];
            let root = dofs.first().map(|&(_, j)| j);
            let moved = |j: usize| root.is_some_and(|r| is_ancestor(r, j));
            let subtree = skeleton.order().iter().copied().filter(|&j| moved(j)).collect();
            let turns = rig.dofs().iter().enumerate().filter(|(_, r)| moved(r.joint)).map(|(i, _)| i).collect();
            // What a step of the closure turns is all below its first joint (see forward_trial_of).
            debug_assert!(dofs.iter().all(|&(_, j)| moved(j)), "a finger's closing joints under its first");
            FingerChain { dofs, others, joints: subtree, turns, proxies, reach, bounds }
        });
        let n = skeleton.len();
        let moved_by: Vec<Option<usize>> = (0..n).map(|j| fingers.iter().position(|c: &FingerChain| c.joints.contains(&j))).collect();
        debug_assert!(
            fingers.iter().enumerate().all(|(f, c)| c.joints.iter().all(|&j| moved_by[j] == Some(f)) && c.turns.iter().all(|&i| fingers.iter().enumerate().all(|(g, d)| g == f || !d.turns.contains(&i)))),
            "the fingers' chains share no joint and no DOF (they close in parallel)"
        );
        let query = ProxyMeshQuery::new(&proxies);
        let fingers = fingers.map(|chain| FingerCloser {
            chain,
            trial: Pose::rest(rig.dofs().len()),
            trial_locals: skeleton.rest_locals(),
            trial_world: vec![Affine3A::IDENTITY; n],
            near: Vec::new(),
            query: query.clone(),
            held_prefix: 0,
            free: false,
        });
        Self {
            mesh_query: query,
            first_stop: 0,
            crew: None,
            contacts: Vec::with_capacity(proxies.colliders().len() * 4),
            last_contacts: Vec::with_capacity(proxies.colliders().len() * 4),
            carried: None,
            uncast: 0.0,
            moved_by,
            proxies,
            fingers,
            tracked_world: vec![Affine3A::IDENTITY; n],
            tracked: Pose::rest(rig.dofs().len()),
            rendered: Pose::rest(rig.dofs().len()),
            previous: Pose::rest(rig.dofs().len()),
            wrist: None,
            grip: None,
            held_back_since: None,
            closure: [Closure::default(); 5],
            kinematics,
        }
    }

    /// Closes the fingers (stage 2) across `crew`'s threads (none: on the caller's alone)
    /// where two or more have objects within reach. Their chains share no joint and no DOF,
    /// so each closes on its own copy of the pose and the rendered pose is the one closed
    /// finger after finger. Around the teapot the five closures take 0.5–0.9 ms in turn, most
    /// of such a frame (docs/performance.md). Allocates nothing per frame, as the crew does not.
    pub fn set_crew(&mut self, crew: Option<Arc<Crew>>) {
        self.crew = crew;
    }

    /// Forgets the last rendered hand (its wrist, grip, contacts and joints kept on contacts): the next
    /// [`Self::solve`] starts from the tracked one (after a reset, or when tracking comes back,
    /// the wrist perhaps far from where it was).
    pub fn restart(&mut self) {
        self.wrist = None;
        self.held_back_since = None;
        self.grip = None;
        self.carried = None;
        self.contacts.clear();
        for finger in &mut self.fingers {
            (finger.held_prefix, finger.free) = (0, false);
        }
        self.uncast = 0.0;
    }

    /// Object `object` has been grasped: from the next [`Self::solve`] while it is held, the
    /// rendered wrist keeps where it is now in the object's frame (`pose`, the object's pose at
    /// the grasp).
    pub fn grip(&mut self, object: usize, pose: &parry3d::math::Pose) {
        if let Some(wrist) = self.wrist {
            let object_pose = DualQuat::from_rotation_translation(pose.rotation, pose.translation);
            self.grip = Some((object, object_pose.conjugate() * wrist));
        }
    }

    /// Takes the frame's `tracked` pose and its joints' world transforms, as the tracked
    /// hand's kinematics layer posed them (they are not computed again): the finger closures
    /// ([`Self::closure`], tracked) and [`Self::tracked_world`], which the grasp logic reads
    /// before the rendered pose is solved. Allocates nothing.
    ///
    /// # Panics
    /// If `tracked_world` does not have one transform per joint.
    pub fn track(&mut self, tracked: &Pose, tracked_world: &[Affine3A]) {
        self.tracked.clone_from(tracked);
        self.tracked_world.copy_from_slice(tracked_world);
        for (f, finger) in self.fingers.iter().enumerate() {
            self.closure[f].tracked = finger.chain.dofs.iter().map(|&(i, _)| tracked.angles[i]).sum();
        }
    }

    /// Solves the rendered pose for the tracked pose of [`Self::track`] at time `now` (s)
    /// against `objects`; `held`, the object in the hand, moves with the hand, so it does not
    /// stop the wrist, and the fingers that touched it keep their grip (the module
    /// documentation, stage 2). Allocates nothing once the fingers' `near` have grown to the scene.
    pub fn solve(&mut self, objects: &ObjectColliders, held: Option<usize>, now: f64) {
        // A finger far from everything closes in microseconds: a split pays only where two or
        // more had objects within reach in their last closure. The crew is woken now, to join
        // the closure from its start.
        let split = self.fingers.iter().filter(|finger| !finger.near.is_empty()).count() >= 2;
        if let Some(crew) = self.crew.as_ref().filter(|_| split) {
            crew.wake_ahead();
        }
        for finger in &mut self.fingers {
            if finger.near.capacity() < objects.len() {
                finger.near.reserve(objects.len());
            }
        }
        let target = self.tracked.wrist.unwrap_or_else(|| self.kinematics.rig().rest_wrist());
        let (wrist, carrier) = match self.grip {
            Some((object, offset)) if Some(object) == held => {
                self.held_back_since = None;
                let pose = &objects.objects()[object].pose;
                (DualQuat::from_rotation_translation(pose.rotation, pose.translation) * offset, Some(object))
            }
            _ => {
                self.grip = None;
                (self.solve_wrist(target, objects, held, now), None)
            }
        };
        // Carried by the same object last frame and this one, the hand has not moved on it:
        // what the fingers keep of their pose need not be asked of it again.
        let still_on = self.carried.filter(|&(o, _)| Some(o) == carrier);
        if self.wrist.is_none() {
            // Restarted: there is no last rendered hand but the tracked one (the one before
            // the restart, or the rest pose, may be anywhere, in the table).
            self.rendered.clone_from(&self.tracked);
        }
        self.wrist = Some(wrist);
        self.previous.clone_from(&self.rendered);
        self.rendered.clone_from(&self.tracked);
        self.rendered.wrist = Some(wrist);
        let scene = ClosureScene {
            kinematics: &self.kinematics,
            proxies: &self.proxies,
            rendered: &self.rendered,
            previous: &self.previous,
            tracked: &self.tracked,
            contacts: &self.contacts,
            objects,
            held,
            still: still_on.is_some(),
        };
        let closure = self.closure;
        match self.crew.as_ref().filter(|_| split) {
            Some(crew) => {
                // One lock per finger, each taken by the one piece that closes it: uncontended.
                let fingers = self.fingers.each_mut().map(Mutex::new);
                crew.run(fingers.len(), &|f| fingers[f].lock().unwrap_or_else(PoisonError::into_inner).close(f, closure[f], &scene));
            }
            None => {
                for (f, finger) in self.fingers.iter_mut().enumerate() {
                    finger.close(f, closure[f], &scene);
                }
            }
        }
        // Per finger: its rendered angles are the last frame's.
        let mut kept = [false; 5];
        for (finger, kept) in self.fingers.iter().zip(&mut kept) {
            let chain = &finger.chain;
            for i in chain.dofs.iter().map(|&(i, _)| i).chain(chain.others.iter().copied()) {
                self.rendered.angles[i] = finger.trial.angles[i];
            }
            let same = |i: usize| self.rendered.angles[i].to_bits() == self.previous.angles[i].to_bits();
            *kept = chain.dofs.iter().all(|&(i, _)| same(i)) && chain.others.iter().all(|&i| same(i));
        }
        self.kinematics.pose(&self.rendered);
        self.find_contacts(objects, still_on, kept);
        self.carried = carrier.map(|o| (o, objects.collider(o).pose));
        for (f, finger) in self.fingers.iter().enumerate() {
            self.closure[f].rendered = finger.chain.dofs.iter().map(|&(i, _)| self.rendered.angles[i]).sum();
        }
    }

    /// Stage 1: the first time of impact of the palm on its way to `target`.
    fn solve_wrist(&mut self, target: DualQuat, objects: &ObjectColliders, held: Option<usize>, now: f64) -> DualQuat {
        let Some(start) = self.wrist else { return target };
        let (r0, t0) = start.to_rotation_translation();
        let (r1, t1) = target.to_rotation_translation();
        let r1 = if r0.dot(r1) < 0.0 { -r1 } else { r1 };
        let angvel = (r1 * r0.inverse()).to_scaled_axis();
        let linvel = t1 - t0;
        let start_affine = Affine3A::from_rotation_translation(r0, t0);
        // The whole hand moves rigidly, its fingers as last rendered: a finger or the thenar
        // must not be carried into an object by the wrist either.
        let world = self.kinematics.world();
        let to_wrist = world[self.kinematics.rig().wrist()].inverse();
        let reach = self.proxies.colliders().iter().map(|p| (to_wrist * world[p.joint]).translation.length() + p.extent).fold(0.0, f32::max);
        // The fastest any proxy point moves, m per unit of the motion: how far the hand moves,
        // and what turns the stop gap into a time.
        let speed = linvel.length() + angvel.length() * reach;
        if self.uncast + speed < STILL_M {
            self.uncast += speed;
            self.held_back_since = None;
            return target;
        }
        self.uncast = 0.0;
        let mut toi: f32 = 1.0;
        // The proxy that stopped the wrist last frame first: a hand held back on an object is
        // stopped at once, and no other proxy can stop it sooner.
        let colliders = self.proxies.colliders();
        let first = self.first_stop.min(colliders.len().saturating_sub(1));
        for i in core::iter::once(first).filter(|&i| i < colliders.len()).chain((0..colliders.len()).filter(|&i| i != first)) {
            if toi <= 0.0 {
                break;
            }
            let p = &colliders[i];
            let offset = to_wrist * world[p.joint];
            let from = pose_of(&(start_affine * offset));
            let to = pose_of(&(Affine3A::from_rotation_translation(r1, t1) * offset));
            let radius = offset.translation.length() + p.extent;
            // The arc a turning point sweeps bulges out of the two end boxes by at most
            // radius · angle / 2.
            let bulge = radius * angvel.length().min(core::f32::consts::PI) / 2.0;
            let swept = p.swept_aabb(&from, &to).loosened(bulge);
            let motion = NonlinearRigidMotion::new(from, offset.inverse().transform_point3(Vec3::ZERO), linvel, angvel);
            // How far any of its points can move before `toi`: a surface farther than that
            // from where it starts cannot be reached (one distance query, where the cast
            // would test every triangle the swept box meets).
            let reach = (linvel.length() + angvel.length() * radius) * toi;
            for (_, o) in objects.near(&swept, 0.0, held) {
                let mesh = o.triangles();
                // A mesh's own advancement starts with its distance: the hull's is enough here.
                let (gap, slack) = match mesh {
                    Some(_) => (o.hull_distance(&from, p).unwrap_or(0.0), MESH_DISTANCE_SLACK),
                    None => (o.distance_at_least(&from, p, reach), 0.0),
                };
                // (A query parry cannot answer reads as infinitely far: then cast.)
                if gap > reach + slack && gap.is_finite() {
                    continue;
                }
                // (One in the hull from the start, as a finger round the teapot's handle, meets
                // it at once: no cast needed to know.)
                if gap > 0.0 && o.misses_hull(&motion, p, toi) {
                    continue;
                }
                let still = NonlinearRigidMotion::constant_position(o.pose);
                let hit = match mesh {
                    Some(mesh) => self.mesh_query.time_of_impact(i, &motion, radius, &swept, mesh, &o.pose, toi),
                    // A proxy touching a primitive stops the wrist unless it moves off the
                    // surface: parry's directional cast read a thumb 0.2 mm off a bar as
                    // overlapping it, judged the overlap a leaving one, and let the hand 5 mm
                    // into the bar (the headset-tracked hand-over).
                    None if gap <= 2.0 * STOP_DISTANCE && !moves_off(&motion, &*p.shape, o, toi) => Some(0.0),
                    None => query::cast_shapes_nonlinear(&motion, &*p.shape, &still, &*o.surface, 0.0, toi, false).ok().flatten().map(|hit| hit.time_of_impact),
                };
                if let Some(hit) = hit.filter(|&hit| hit < toi) {
                    (toi, self.first_stop) = (hit, i);
                }
            }
        }
        if toi >= 1.0 {
            self.held_back_since = None;
            return target;
        }
        let since = *self.held_back_since.get_or_insert(now);
        if now - since > SNAP_AFTER_S && self.hand_free(target, objects, held) {
            self.held_back_since = None;
            return target;
        }
        let toi = (toi - STOP_DISTANCE / speed).max(0.0);
        DualQuat::from_rotation_translation(r0.slerp(r1, toi).normalize(), t0.lerp(t1, toi))
    }

    /// Whether the tracked hand is clear of every object with its wrist at `wrist`.
    fn hand_free(&self, wrist: DualQuat, objects: &ObjectColliders, held: Option<usize>) -> bool {
        let (r, t) = wrist.to_rotation_translation();
        let at = Affine3A::from_rotation_translation(r, t) * self.tracked_world[self.kinematics.rig().wrist()].inverse();
        self.proxies.colliders().iter().all(|p| {
            let pose = pose_of(&(at * self.tracked_world[p.joint]));
            let aabb = p.aabb(&pose);
            objects.near(&aabb, 0.0, held).all(|(_, o)| !query::intersection_test(&pose, &*p.shape, &o.pose, &*o.surface).is_ok_and(|x| x.intersecting))
        })
    }

    /// The contacts of the rendered pose. Where the hand was `still_on` an object (carried by
    /// it last frame and this one, at the pose given), the contacts with it of every joint the
    /// fingers `kept` still (per finger) are last frame's, moved with the object: rigidly
    /// attached, they are the same.
    fn find_contacts(&mut self, objects: &ObjectColliders, still_on: Option<(usize, parry3d::math::Pose)>, kept: [bool; 5]) {
        std::mem::swap(&mut self.contacts, &mut self.last_contacts);
        self.contacts.clear();
        let moved_by = &self.moved_by;
        let unmoved = |j: usize| still_on.is_some() && moved_by[j].is_none_or(|f| kept[f]);
        if let Some((object, then)) = still_on {
            let now = objects.collider(object).pose;
            let turn = now.rotation * then.rotation.inverse();
            for c in self.last_contacts.iter().filter(|c| c.object == object && unmoved(c.joint)) {
                let point = turn * (c.point - then.translation) + now.translation;
                self.contacts.push(Contact { point, normal: turn * c.normal, ..*c });
            }
        }
        for (k, p) in self.proxies.colliders().iter().enumerate() {
            let pose = pose_of(&self.kinematics.world()[p.joint]);
            let aabb = p.aabb(&pose);
            let skip = still_on.map(|(o, _)| o).filter(|_| unmoved(p.joint));
            for (i, o) in objects.near(&aabb, CONTACT_DISTANCE, skip).filter(|(i, _)| *i < objects.objects().len()) {
                if let Some(mesh) = o.triangles() {
                    if let Some(n) = self.mesh_query.nearest(k, &pose, mesh, &o.pose, CONTACT_DISTANCE) {
                        self.contacts.push(Contact { joint: p.joint, part: p.part, object: i, point: n.point, normal: n.normal, distance: n.distance });
                    }
                    continue;
                }
                if o.distance_at_least(&pose, p, CONTACT_DISTANCE) > CONTACT_DISTANCE {
                    continue;
                }
                if let Ok(Some(c)) = query::contact(&pose, &*p.shape, &o.pose, &*o.surface, CONTACT_DISTANCE) {
                    let normal = (-c.normal1).normalize_or_zero();
                    self.contacts.push(Contact { joint: p.joint, part: p.part, object: i, point: c.point2, normal, distance: c.dist });
                }
            }
        }
    }

    /// The rendered pose of the last [`Self::solve`].
    #[must_use]
    pub fn rendered(&self) -> &Pose {
        &self.rendered
    }

    /// The world transform of each joint in the rendered pose.
    #[must_use]
    pub fn world(&self) -> &[Affine3A] {
        self.kinematics.world()
    }

    /// The rendered hand's kinematics layer (posed once per [`Self::solve`]): what the skin
    /// layer deforms for the hand the user sees.
    #[must_use]
    pub fn kinematics(&self) -> &HandKinematics {
        &self.kinematics
    }

    /// The world transform of each joint in the tracked pose.
    #[must_use]
    pub fn tracked_world(&self) -> &[Affine3A] {
        &self.tracked_world
    }

    /// The proxies touching objects in the rendered pose.
    #[must_use]
    pub fn contacts(&self) -> &[Contact] {
        &self.contacts
    }

    /// How closed each finger is, tracked and rendered, thumb first.
    #[must_use]
    pub fn closure(&self) -> &[Closure; 5] {
        &self.closure
    }
}

impl FingerCloser {
    /// Forward kinematics of a pose conservative advancement tries (its trial angles), into
    /// the trial transforms: a step of the search, not the rendered hand.
    fn forward_trial(&mut self, kinematics: &HandKinematics) {
        let rig = kinematics.rig();
        rig.locals(&self.trial, kinematics.limits(), &mut self.trial_locals);
        forward_kinematics(rig.skeleton(), &self.trial_locals, &mut self.trial_world);
    }

    /// [`Self::forward_trial`] of only `chain`'s joints, the rest as the last trial left them:
    /// a step of its closure, which turns nothing else.
    fn forward_trial_of(&mut self, chain: &FingerChain, kinematics: &HandKinematics) {
        let rig = kinematics.rig();
        rig.locals_of(&self.trial, kinematics.limits(), &chain.joints, &chain.turns, &mut self.trial_locals);
        forward_kinematics_of(rig.skeleton(), &chain.joints, &self.trial_locals, &mut self.trial_world);
    }

    /// Stage 2 for finger `f`: conservative advancement of its closure.
    ///
    /// A finger that touched the `held` object last frame keeps its grip until the tracked
    /// finger opens past it: the closure starts from the finger as last rendered, the joints up
    /// to a phalanx touching there stay, and the distal ones close on (it wraps the object
    /// further). Closing it from open again would ask the object the same questions every
    /// frame, and a slightly different path may end on a different contact (the tracked
    /// finger has gone into the object), turning the object in the hand. Its abduction stays
    /// too: it would slide the touching phalanx sideways, unchecked.
    ///
    /// While the hand is `still` on the held object (see [`Self::solve`]), the leading joints of
    /// a gripping finger that stopped on contacts with it last frame stop there again at once:
    /// they are kept without a query, and only the joints past them close (none, when every
    /// joint had stopped on it).
    fn close(&mut self, f: usize, closure: Closure, scene: &ClosureScene) {
        let ClosureScene { kinematics, proxies, previous, tracked, objects, held, still, .. } = *scene;
        self.trial.clone_from(scene.rendered);
        let mut chain = std::mem::take(&mut self.chain);
        if chain.dofs.is_empty() {
            self.chain = chain;
            return;
        }
        let opening = closure.tracked < closure.rendered;
        let gripping = held.is_some_and(|h| !opening && scene.contacts.iter().any(|c| c.object == h && c.part == HandPart::Finger(f)));
        let kept = if gripping && still { self.held_prefix.min(chain.dofs.len()) } else { 0 };
        if kept == chain.dofs.len() {
            for i in chain.dofs.iter().map(|&(i, _)| i).chain(chain.others.iter().copied()) {
                self.trial.angles[i] = previous.angles[i];
            }
            self.free = false;
            self.near.clear();
            self.chain = chain;
            return;
        }
        // The closure runs from `start` to the tracked angles (`self.trial` holds those).
        let mut target = [0.0f32; 4];
        let mut start = [0.0f32; 4];
        for (k, &(i, _)) in chain.dofs.iter().enumerate() {
            target[k] = self.trial.angles[i];
            self.trial.angles[i] = 0.0;
        }
        if gripping {
            for &i in &chain.others {
                self.trial.angles[i] = previous.angles[i];
            }
        }
        self.forward_trial(kinematics);
        let root = Vec3::from(self.trial_world[chain.dofs[0].1].translation);
        let reach = Aabb::from_half_extents(root, Vec3::splat(chain.reach));
        self.near.clear();
        self.near.extend(objects.near(&reach, CONTACT_DISTANCE, None).map(|(i, _)| i));
        let mut active = kept;
        // The leading joints stopped on the held object so far.
        let mut prefix = kept;
        let mut s: f32 = 0.0;
        if !self.near.is_empty() {
            let set = |angles: &mut [f32], active: usize, s: f32, start: &[f32; 4], target: &[f32; 4]| {
                for (k, &(i, _)) in chain.dofs.iter().enumerate().skip(active) {
                    angles[i] = start[k] + (target[k] - start[k]) * s;
                }
            };
            // Where the closure starts: open, else as last rendered, else the tracked angles
            // (clear after a snap of the wrist); the first whose proxies are clear. When
            // none is (an object has moved into the finger), the finger stays as last
            // rendered, the least change, and the physics pushes the object off it; but an
            // object let go passes through the fingers round it (`ScenePhysics::release`),
            // so where only meshes are that near, whose signed distances tell how deep, the
            // finger takes the start they overlap clearly the least ([`SWITCH_OVERLAP`]).
            // A finger of a hand holding something that reached the tracked angles untouched
            // last frame tries as last rendered first: from open it would meet the object on
            // its way to angles clear of it, and flicker between the two every other frame
            // (the little finger curled under a ball held from above). Not while nothing is
            // held: closing from where they were drawn let the 4 cm ball through the fingers
            // on the approach. The starts are kinds 0 (open), 1 (last rendered) and 2
            // (tracked), tried in `order`; `checking` is the place in `order` of the one being
            // tried until one is clear, and `tried` holds per kind its nearest distance and
            // whether nothing but a mesh was within the stop distance (a primitive's or the
            // table's reads 0 at any depth). A gripping finger starts as last rendered,
            // touching.
            let free = self.free && held.is_some();
            let order = if free { [1, 0, 2] } else { [0, 1, 2] };
            let mut checking = Some(0);
            let mut tried = [(0.0f32, false); 3];
            starting_angles(order[0], &chain.dofs, previous, tracked, &mut start);
            if gripping {
                for (k, &(i, _)) in chain.dofs.iter().enumerate() {
                    start[k] = previous.angles[i];
                    if k < kept {
                        self.trial.angles[i] = start[k];
                    }
                }
                checking = None;
            }
            chain.bounds.fill(UNMEASURED);
            for _ in 0..MAX_ADVANCES {
                set(&mut self.trial.angles, active, s, &start, &target);
                self.forward_trial_of(&chain, kinematics);
                // The nearest proxy measured (its distance, last DOF and the object), and the
                // largest step no point of any can overrun. A proxy is measured only where its
                // bound may have come down to the stop distance: the others cannot stop the
                // finger here, and their bounds still limit the step.
                let mut nearest = (f32::INFINITY, 0, usize::MAX);
                let mut meshes_only = true;
                let mut step = f32::INFINITY;
                for ((p, last, levers), (bound, at)) in chain.proxies.iter().zip(chain.bounds.iter_mut()) {
                    if *last < active {
                        continue;
                    }
                    let speed: f32 = (active..=*last).map(|k| (target[k] - start[k]).abs() * levers[k]).sum();
                    let mut remaining = *bound - speed * (s - *at);
                    if remaining <= STOP_DISTANCE {
                        let proxy = &proxies.colliders()[*p];
                        let pose = pose_of(&self.trial_world[proxy.joint]);
                        let (mut d, mut to) = (f32::INFINITY, usize::MAX);
                        for &o in &self.near {
                            let c = objects.collider(o);
                            // (Against a mesh, exact only where it stops the finger: above, a
                            // lower bound steps nearly as far, and saves measuring the triangles within
                            // millimetres of a palm's hull, which the search could not tell
                            // apart, at every step.)
                            let (here, signed) = match c.triangles() {
                                Some(mesh) => (self.query.distance_at_least(*p, &pose, mesh, &c.pose, STOP_DISTANCE, MESH_LOOKOUT), true),
                                None => (c.distance_at_least(&pose, proxy, STOP_DISTANCE), false),
                            };
                            meshes_only &= signed || here > STOP_DISTANCE;
                            if here < d {
                                (d, to) = (here, o);
                            }
                        }
                        (*bound, *at, remaining) = (d, s, d);
                        if d < nearest.0 {
                            nearest = (d, *last, to);
                        }
                    }
                    if speed > 0.0 {
                        step = step.min(remaining / speed);
                    }
                }
                if let Some(at) = checking.take() {
                    if nearest.0 <= STOP_DISTANCE {
                        tried[order[at]] = (nearest.0, meshes_only);
                        // The next start to try; after the last, as last rendered unless
                        // another overlaps only meshes, clearly less (the least; ties: open).
                        let next = match at {
                            0 | 1 => order[at + 1],
                            _ if !tried[1].1 => 1,
                            _ => [2, 0].into_iter().filter(|&b| tried[b].1 && tried[b].0 > tried[1].0 + SWITCH_OVERLAP).max_by(|&a, &b| tried[a].0.total_cmp(&tried[b].0)).unwrap_or(1),
                        };
                        starting_angles(next, &chain.dofs, previous, tracked, &mut start);
                        if at == 2 {
                            break;
                        }
                        checking = Some(at + 1);
                        chain.bounds.fill(UNMEASURED);
                        continue;
                    }
                }
                if nearest.0 <= STOP_DISTANCE {
                    // Contact: the joints up to the touching phalanx stop here; the rest close on.
                    for k in active..chain.dofs.len() {
                        start[k] = self.trial.angles[chain.dofs[k].0];
                    }
                    if prefix == active && held == Some(nearest.2) {
                        prefix = nearest.1 + 1;
                    }
                    active = nearest.1 + 1;
                    s = 0.0;
                    chain.bounds.fill(UNMEASURED);
                    if active >= chain.dofs.len() {
                        break;
                    }
                    continue;
                }
                if s + step >= 1.0 {
                    s = 1.0;
                    break;
                }
                s += step;
            }
            set(&mut self.trial.angles, active, s, &start, &target);
        } else {
            for (k, &(i, _)) in chain.dofs.iter().enumerate() {
                self.trial.angles[i] = target[k];
            }
            prefix = 0;
        }
        self.held_prefix = prefix;
        self.free = self.near.is_empty() || (active == 0 && s >= 1.0);
        self.chain = chain;
    }
}

/// A finger's closing angles (`dofs`' pose indices) at start `kind` of its closure: 0 open,
/// 1 as last rendered (`previous`), 2 the tracked angles.
fn starting_angles(kind: usize, dofs: &[(usize, usize)], previous: &Pose, tracked: &Pose, start: &mut [f32; 4]) {
    for (k, &(i, _)) in dofs.iter().enumerate() {
        start[k] = match kind {
            0 => 0.0,
            1 => previous.angles[i],
            _ => tracked.angles[i],
        };
    }
}

/// Whether a proxy touching primitive `o` at the start of `motion` moves off it: its touching
/// point does not close on the surface there (as [`ProxyMeshQuery::time_of_impact`] judges a
/// touching triangle), and halfway to `end` and at `end` it is no deeper in than it started: a
/// turn can lift the touching point and sink another end of the proxy (a left thumb's
/// metacarpal, touching a bar, rolled 5.4 mm into it where parry's directional cast saw no hit).
fn moves_off(motion: &NonlinearRigidMotion, shape: &dyn parry3d::shape::Shape, o: &ObjectCollider, end: f32) -> bool {
    let pivot = motion.start * motion.local_center;
    // parry's contact has no answer for some shapes touching exactly: then it does not.
    let Ok(Some(c)) = query::contact(&motion.start, shape, &o.pose, &*o.surface, CONTACT_DISTANCE) else { return false };
    let deeper = |t: f32| query::contact(&motion.position_at_time(t), shape, &o.pose, &*o.surface, CONTACT_DISTANCE).is_ok_and(|e| e.is_some_and(|e| e.dist < c.dist.min(0.0) - TOLERANCE));
    (motion.linvel + motion.angvel.cross(c.point1 - pivot)).dot(c.normal1) <= 0.0 && !deeper(end / 2.0) && !deeper(end)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::collision::{fit_proxies, PROXY_MARGIN};
    use crate::kinematics::JointModel;

    /// A step of a finger's closure poses its joints as the whole hand's forward kinematics
    /// does, to the bit, and leaves the rest as they were.
    #[test]
    fn a_closing_finger_is_posed_alone_as_the_whole_hand_poses_it() {
        let model = crate::hand::build(&crate::hand::HandParams { vertices: 2000, ..crate::hand::HandParams::default() }).expect("the built-in hand");
        let kinematics = HandKinematics::new(&model.skeleton, model.mesh.inverse_bind(), JointModel::Full).expect("a rig");
        let mut c = ContactConstraint::new(HandProxies::new(&fit_proxies(&model, PROXY_MARGIN), &model.skeleton), kinematics);
        let mut rng = crate::math::Rng::new(3);
        for f in 0..5 {
            let (finger, kinematics) = (&mut c.fingers[f], &c.kinematics);
            let chain = std::mem::take(&mut finger.chain);
            assert!(!chain.dofs.is_empty() && chain.proxies.iter().all(|(p, ..)| chain.joints.contains(&c.proxies.colliders()[*p].joint)), "finger {f}");
            for a in &mut finger.trial.angles {
                *a = rng.uniform(-0.3, 1.2) as f32;
            }
            finger.forward_trial(kinematics);
            for &(i, _) in &chain.dofs {
                finger.trial.angles[i] = rng.uniform(0.0, 1.5) as f32;
            }
            let before = finger.trial_world.clone();
            finger.forward_trial_of(&chain, kinematics);
            let alone = finger.trial_world.clone();
            finger.forward_trial(kinematics);
            assert_eq!(alone, finger.trial_world, "finger {f}: posed alone, not as the whole hand");
            assert!(chain.joints.iter().all(|&j| alone[j] != before[j]), "finger {f}: a joint of the closure did not move");
            finger.chain = chain;
        }
    }
}
