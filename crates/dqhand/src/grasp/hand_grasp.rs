//! The grasp state machine of one hand (see the module documentation for the rules).

use glam::{Affine3A, Quat, Vec3};

use crate::collision::{Closure, Contact, HandPart};
use crate::math::rigid_fit;

/// The thresholds of the grasp rules.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GraspParams {
    /// Least angle between the normals of two opposing contacts, degrees.
    pub opposition_deg: f32,
    /// How far past the rendered finger the tracked one must close to grasp, degrees.
    pub press_deg: f32,
    /// How far each grasping finger must open past its closure at the grasp to release,
    /// degrees.
    pub release_deg: f32,
    /// Seconds after a release before the object can be grasped again.
    pub cooldown_s: f64,
    /// Seconds a held object survives a tracking loss.
    pub loss_grace_s: f64,
    /// An object let go slower than this (its origin carried by the wrist's motion over the
    /// last 8 frames), m/s, is set down or dropped: it leaves without the hand's velocity.
    /// Tracking noise alone measures several cm/s (2 mm joint jitter, 30 ms late: up to
    /// 16 cm/s at a marble 10 cm from the wrist), which would roll a ball set down away or
    /// tip a dropped cube; a toss is faster.
    pub still_m_s: f32,
    /// A wrist turning slower than this, rad/s, gives the object no spin (and an object let
    /// go slower than [`Self::still_m_s`] none either).
    pub still_rad_s: f32,
    /// Two hands holding an object between them (neither alone) let go when their contacts
    /// are carried this much farther apart than at the grasp, m: the user pulls the hands
    /// apart. Squeezing brings them closer (the tracked palms go into the object).
    pub apart_m: f32,
    /// A hand whose tracked wrist is this much farther into an object than its rendered one
    /// (along the contact's normal), m, presses on it with every contact there: a flat hand
    /// pushed against a box, whose fingers do not close.
    pub push_m: f32,
}

impl Default for GraspParams {
    fn default() -> Self {
        Self { opposition_deg: 100.0, press_deg: 4.0, release_deg: 8.0, cooldown_s: 0.3, loss_grace_s: 0.5, still_m_s: 0.25, still_rad_s: 2.0, apart_m: 0.015, push_m: 0.005 }
    }
}

/// What a frame changed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum GraspEvent {
    /// The object was grasped.
    Grasp {
        /// Index of the object in the scene.
        object: usize,
    },
    /// The object was let go, with this velocity (m/s, and rad/s as an axis times a rate).
    Release {
        /// Index of the object in the scene.
        object: usize,
        /// Linear velocity of the object's origin.
        linvel: Vec3,
        /// Angular velocity.
        angvel: Vec3,
    },
}

/// One hand as [`Grasp::find_two_handed`] reads it: its grasp, contacts, finger closures, and
/// its tracked wrist less its rendered one (m).
pub type TwoHanded<'a> = (&'a Grasp, &'a [Contact], &'a [Closure; 5], Vec3);

/// At most this many contact points hold an object (the first ones found).
const MAX_ANCHORS: usize = 16;
/// At most this many points of one hand hold an object ([`Grasp::holding_points`]): its
/// contacts and the wrist frame's.
pub const MAX_HOLDING_POINTS: usize = MAX_ANCHORS + WRIST_POINTS.len();
/// The wrist frame's points added to the contacts: origin and 5 cm along each axis, so that
/// two contacts (a pinch) still fix the object's rotation.
const WRIST_POINTS: [Vec3; 4] = [Vec3::ZERO, Vec3::new(0.05, 0.0, 0.0), Vec3::new(0.0, 0.05, 0.0), Vec3::new(0.0, 0.0, 0.05)];
/// Frames of held poses kept for the release velocity.
const HISTORY: usize = 8;

#[derive(Clone, Debug)]
struct Held {
    object: usize,
    wrist: usize,
    /// (joint, point in the rendered joint's frame): contacts and the wrist frame's points.
    anchors: [(usize, Vec3); MAX_ANCHORS + 4],
    count: usize,
    /// The anchors at the grasp ([`Held::place`]).
    reference: [Vec3; MAX_ANCHORS + 4],
    current: [Vec3; MAX_ANCHORS + 4],
    /// The object's pose at the grasp (or when the other hand last let go of it).
    start: (Quat, Vec3),
    /// Whether this hand's own grasp holds the object (thumb or palm against a finger), not
    /// only its share of a two-hand hold.
    alone: bool,
    /// The grasping fingers (thumb first) and the most their rendered closures (summed) have
    /// wrapped the object since the grasp: the tracked ones must open past it to release.
    fingers: [bool; 5],
    closure: f32,
    lost_since: Option<f64>,
    /// The object's pose this frame.
    target: (Quat, Vec3),
    /// The tracked wrist's last poses, newest last: (time, rotation, translation).
    history: [(f64, Quat, Vec3); HISTORY],
    filled: usize,
}

/// The grasp state of one hand over a scene's objects.
#[derive(Clone, Debug)]
pub struct Grasp {
    params: GraspParams,
    held: Option<Held>,
    /// Per object, the time before which it cannot be grasped.
    cooldown_until: Vec<f64>,
}

impl Grasp {
    /// A hand holding nothing, in a scene of `objects` objects.
    #[must_use]
    pub fn new(params: GraspParams, objects: usize) -> Self {
        Self { params, held: None, cooldown_until: vec![f64::NEG_INFINITY; objects] }
    }

    /// The object held, if any.
    #[must_use]
    pub fn held(&self) -> Option<usize> {
        self.held.as_ref().map(|h| h.object)
    }

    /// Where the held object goes this frame: its rotation and translation.
    #[must_use]
    pub fn target(&self) -> Option<(Quat, Vec3)> {
        self.held.as_ref().map(|h| h.target)
    }

    /// Lets go of everything at once, with no velocity and no cooldown (a scene reset).
    pub fn clear(&mut self) {
        self.held = None;
        self.cooldown_until.fill(f64::NEG_INFINITY);
    }

    /// The first half of a frame at `now` (s), before the rendered hand is solved: the held
    /// object follows the hand ([`Self::target`]; `tracked_world` this frame's tracked joints,
    /// `rendered_world` the last rendered ones), or is let go because the fingers opened
    /// (`closure`: tracked, and rendered as last solved) or tracking has been lost
    /// (`tracking` false) for longer than the grace time. Allocates nothing.
    pub fn follow(&mut self, now: f64, tracking: bool, closure: &[Closure; 5], tracked_world: &[Affine3A], rendered_world: &[Affine3A]) -> Option<GraspEvent> {
        let held = self.held.as_mut()?;
        if !tracking {
            let since = *held.lost_since.get_or_insert(now);
            return (now - since > self.params.loss_grace_s).then(|| self.release(now, false));
        }
        held.lost_since = None;
        held.closure = held.closure.max(grasping(closure, held.fingers, |c| c.rendered));
        let count = held.fingers.iter().filter(|g| **g).count() as f32;
        if held.alone && grasping(closure, held.fingers, |c| c.tracked) < held.closure - self.params.release_deg.to_radians() * count {
            return Some(self.release(now, true));
        }
        let n = held.count;
        place(&held.anchors[..n], held.wrist, tracked_world, rendered_world, &mut held.current);
        let (r, t) = rigid_fit(&held.reference[..n], &held.current[..n]);
        held.target = ((r * held.start.0).normalize(), r * held.start.1 + t);
        held.remember(now, &tracked_world[held.wrist]);
        None
    }

    /// The second half of a frame, with the rendered hand solved: grasps an object when
    /// nothing is held and the rules hold for the rendered pose's `contacts` and the fingers'
    /// `closure`. `rendered_world` and `tracked_world` are both poses' joint transforms,
    /// `wrist` the wrist joint, `objects` each object's pose. Allocates nothing.
    #[allow(clippy::too_many_arguments)]
    pub fn detect(
        &mut self,
        now: f64,
        tracking: bool,
        contacts: &[Contact],
        closure: &[Closure; 5],
        rendered_world: &[Affine3A],
        tracked_world: &[Affine3A],
        wrist: usize,
        objects: &[(Quat, Vec3)],
    ) -> Option<GraspEvent> {
        if self.held.is_some() || !tracking {
            return None;
        }
        let object = self.find_grasp(now, contacts, closure)?;
        Some(self.take(now, object, objects[object], true, contacts, closure, rendered_world, tracked_world, wrist))
    }

    /// The object two free hands hold between them, if any: a pressing contact of each on it
    /// ([`Self::detect`]'s rule for one contact: a palm, or a finger squeezed past its
    /// rendered copy; or any contact of a hand pushed [`GraspParams::push_m`] into the
    /// object), their normals opposed. Neither hand need hold it alone: two flat hands
    /// pressing a large box from either side carry it. Each hand is given as its grasp,
    /// contacts, finger closures and push (its tracked wrist less its rendered one, m).
    #[must_use]
    pub fn find_two_handed(now: f64, a: TwoHanded<'_>, b: TwoHanded<'_>) -> Option<usize> {
        if a.0.held.is_some() || b.0.held.is_some() {
            return None;
        }
        let opposed = libm::cosf(a.0.params.opposition_deg.to_radians());
        let ready = |g: &Grasp, o: usize| now >= g.cooldown_until[o];
        let presses = |(g, _, closure, push): TwoHanded<'_>, c: &Contact| g.pressing(c, closure) || push.dot(-c.normal) >= g.params.push_m;
        a.1.iter().filter(|c| presses(a, c) && ready(a.0, c.object) && ready(b.0, c.object)).find_map(|ca| {
            b.1.iter().any(|cb| cb.object == ca.object && presses(b, cb) && ca.normal.dot(cb.normal) <= opposed).then_some(ca.object)
        })
    }

    /// Takes hold of `object`, at `pose` now, by `contacts` (see [`Self::detect`]); `alone`:
    /// this hand's grasp holds it by itself, else only with the other hand's. Allocates
    /// nothing.
    #[allow(clippy::too_many_arguments)]
    pub fn take(
        &mut self,
        now: f64,
        object: usize,
        pose: (Quat, Vec3),
        alone: bool,
        contacts: &[Contact],
        closure: &[Closure; 5],
        rendered_world: &[Affine3A],
        tracked_world: &[Affine3A],
        wrist: usize,
    ) -> GraspEvent {
        let mut held = Held {
            object,
            wrist,
            anchors: [(0, Vec3::ZERO); MAX_ANCHORS + 4],
            count: 0,
            reference: [Vec3::ZERO; MAX_ANCHORS + 4],
            current: [Vec3::ZERO; MAX_ANCHORS + 4],
            start: pose,
            alone,
            fingers: [false; 5],
            closure: 0.0,
            lost_since: None,
            target: pose,
            history: [(now, Quat::IDENTITY, Vec3::ZERO); HISTORY],
            filled: 0,
        };
        for c in contacts.iter().filter(|c| c.object == object).take(MAX_ANCHORS) {
            held.anchors[held.count] = (c.joint, rendered_world[c.joint].inverse().transform_point3(c.point));
            held.count += 1;
            if let HandPart::Finger(f) = c.part {
                held.fingers[f] = true;
            }
        }
        for p in WRIST_POINTS {
            held.anchors[held.count] = (wrist, p);
            held.count += 1;
        }
        place(&held.anchors[..held.count], wrist, tracked_world, rendered_world, &mut held.reference);
        held.current = held.reference;
        held.closure = grasping(closure, held.fingers, |c| c.rendered);
        held.remember(now, &tracked_world[wrist]);
        self.held = Some(held);
        GraspEvent::Grasp { object }
    }

    /// Whether this hand's grasp holds its object by itself ([`Self::take`]).
    #[must_use]
    pub fn alone(&self) -> bool {
        self.held.as_ref().is_some_and(|h| h.alone)
    }

    /// The held object's holding points: each in the object's frame, and where the hand
    /// carries it this frame (after [`Self::follow`]). Both hands' together give a two-hand
    /// hold's best rigid fit.
    pub fn holding_points(&self) -> impl Iterator<Item = (Vec3, Vec3)> + '_ {
        self.held.iter().flat_map(|h| {
            let (q, t) = h.start;
            let to_object = q.inverse();
            h.reference[..h.count].iter().zip(&h.current[..h.count]).map(move |(r, c)| (to_object * (*r - t), *c))
        })
    }

    /// Where this hand's contacts on the held object are carried this frame (their mean), if
    /// it holds one: how far apart two hands holding it between them are.
    #[must_use]
    pub fn contact_centre(&self) -> Option<Vec3> {
        let h = self.held.as_ref()?;
        let n = h.count - WRIST_POINTS.len();
        (n > 0).then(|| h.current[..n].iter().copied().sum::<Vec3>() / n as f32)
    }

    /// The held object goes to `pose` this frame: both hands' fit, not this hand's alone.
    pub fn set_target(&mut self, pose: (Quat, Vec3)) {
        if let Some(h) = &mut self.held {
            h.target = pose;
        }
    }

    /// The held object, at `pose`, is now held from where the hand holds it this frame (the
    /// other hand let go of it): it stays put instead of jumping to this hand's own fit since
    /// its grasp.
    pub fn rebase(&mut self, pose: (Quat, Vec3)) {
        if let Some(h) = &mut self.held {
            h.start = pose;
            h.target = pose;
            h.reference = h.current;
        }
    }

    /// Lets go of the held object now (the other hand let go of a two-hand hold, or the two
    /// hands drew apart), with the hand's velocity.
    pub fn let_go(&mut self, now: f64) -> Option<GraspEvent> {
        self.held.is_some().then(|| self.release(now, true))
    }

    /// Whether `c` presses on its object: a palm always does, a finger when it is tracked
    /// closed past its rendered copy by [`GraspParams::press_deg`].
    fn pressing(&self, c: &Contact, closure: &[Closure; 5]) -> bool {
        match c.part {
            HandPart::Palm => true,
            HandPart::Finger(f) => closure[f].tracked - closure[f].rendered >= self.params.press_deg.to_radians(),
        }
    }

    /// The object the contacts grasp, if any: a pressing thumb or palm contact and a pressing
    /// finger contact on it, with opposing normals.
    fn find_grasp(&self, now: f64, contacts: &[Contact], closure: &[Closure; 5]) -> Option<usize> {
        let opposed = libm::cosf(self.params.opposition_deg.to_radians());
        let thumb_side = |c: &&Contact| matches!(c.part, HandPart::Palm | HandPart::Finger(0)) && self.pressing(c, closure);
        let finger = |c: &&Contact| matches!(c.part, HandPart::Finger(1..)) && self.pressing(c, closure);
        contacts.iter().filter(thumb_side).find_map(|a| {
            let ok = now >= self.cooldown_until[a.object]
                && contacts.iter().filter(finger).any(|b| b.object == a.object && a.normal.dot(b.normal) <= opposed);
            ok.then_some(a.object)
        })
    }

    fn release(&mut self, now: f64, moving: bool) -> GraspEvent {
        let held = self.held.take().expect("releasing a held object");
        self.cooldown_until[held.object] = now + self.params.cooldown_s;
        // The object leaves with the hand's motion, not the fingers' (they are opening):
        // the velocity of its origin as a point fixed to the wrist over the last frames.
        let (t0, q0, p0) = held.history[HISTORY - held.filled];
        let (t1, q1, p1) = held.history[HISTORY - 1];
        let dt = (t1 - t0) as f32;
        let (linvel, angvel) = if moving && dt > 0.0 {
            let q1 = if q0.dot(q1) < 0.0 { -q1 } else { q1 };
            let angvel = (q1 * q0.inverse()).to_scaled_axis() / dt;
            let angvel = if angvel.length() < self.params.still_rad_s { Vec3::ZERO } else { angvel };
            // The object's origin as a point fixed to the wrist; slower than a toss, it is set
            // down or dropped, not thrown.
            let linvel = (p1 - p0) / dt + angvel.cross(held.target.1 - p1);
            if linvel.length() < self.params.still_m_s { (Vec3::ZERO, Vec3::ZERO) } else { (linvel, angvel) }
        } else {
            (Vec3::ZERO, Vec3::ZERO)
        };
        GraspEvent::Release { object: held.object, linvel, angvel }
    }
}

/// The grasping `fingers`' closures summed, `side` (tracked or rendered) of each.
fn grasping(closure: &[Closure; 5], fingers: [bool; 5], side: fn(&Closure) -> f32) -> f32 {
    closure.iter().zip(fingers).filter(|(_, g)| *g).map(|(c, _)| side(c)).sum()
}

/// Where `anchors` are now (into `out`): on the rendered bones, carried by the tracked
/// `wrist`. Not on the tracked bones: the tracked fingers close on into the object after the
/// grasp, which would drag it across the palm; the rendered ones stop on its surface and move
/// only where the user's fingers move outside it.
fn place(anchors: &[(usize, Vec3)], wrist: usize, tracked_world: &[Affine3A], rendered_world: &[Affine3A], out: &mut [Vec3]) {
    let carry = tracked_world[wrist] * rendered_world[wrist].inverse();
    for (o, &(j, local)) in out.iter_mut().zip(anchors) {
        *o = (carry * rendered_world[j]).transform_point3(local);
    }
}

impl Held {
    /// Keeps the tracked wrist's pose `wrist` at `now` for the release velocity.
    fn remember(&mut self, now: f64, wrist: &Affine3A) {
        let (_, q, p) = wrist.to_scale_rotation_translation();
        self.history.rotate_left(1);
        self.history[HISTORY - 1] = (now, q.normalize(), p);
        self.filled = (self.filled + 1).min(HISTORY);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const WRIST: usize = 0;

    fn contact(part: HandPart, joint: usize, normal: Vec3) -> Contact {
        Contact { joint, part, object: 0, point: -normal * 0.04, normal, distance: 0.0 }
    }

    /// The thumb on one side of a ball at the origin, the index on the other.
    fn pinch() -> [Contact; 2] {
        [contact(HandPart::Finger(0), 1, Vec3::X), contact(HandPart::Finger(1), 2, -Vec3::X)]
    }

    /// Thumb and index each `tracked_deg` closed, stopped at 30°.
    fn closure(tracked_deg: f32) -> [Closure; 5] {
        let c = Closure { tracked: tracked_deg.to_radians(), rendered: 30f32.to_radians() };
        [c, c, Closure::default(), Closure::default(), Closure::default()]
    }

    fn world(shift: Vec3) -> Vec<Affine3A> {
        vec![Affine3A::from_translation(shift); 3]
    }

    const BALL: [(Quat, Vec3); 1] = [(Quat::IDENTITY, Vec3::ZERO)];

    fn grasped(g: &mut Grasp, t: f64) -> Option<GraspEvent> {
        g.detect(t, true, &pinch(), &closure(40.0), &world(Vec3::ZERO), &world(Vec3::ZERO), WRIST, &BALL)
    }

    #[test]
    fn opposing_pressing_contacts_grasp() {
        let mut g = Grasp::new(GraspParams::default(), 1);
        assert_eq!(grasped(&mut g, 0.0), Some(GraspEvent::Grasp { object: 0 }));
        assert_eq!(g.held(), Some(0));
    }

    #[test]
    fn no_grasp_without_opposition_pressure_or_tracking() {
        let mut g = Grasp::new(GraspParams::default(), 1);
        let same_side = [contact(HandPart::Finger(0), 1, Vec3::X), contact(HandPart::Finger(1), 2, Vec3::X)];
        assert_eq!(g.detect(0.0, true, &same_side, &closure(40.0), &world(Vec3::ZERO), &world(Vec3::ZERO), WRIST, &BALL), None);
        // Touching but not squeezing: tracked 2° past the surface, under the 4° needed.
        assert_eq!(g.detect(0.0, true, &pinch(), &closure(32.0), &world(Vec3::ZERO), &world(Vec3::ZERO), WRIST, &BALL), None);
        assert_eq!(g.detect(0.0, false, &pinch(), &closure(40.0), &world(Vec3::ZERO), &world(Vec3::ZERO), WRIST, &BALL), None);
        let two_fingers = [contact(HandPart::Finger(2), 1, Vec3::X), contact(HandPart::Finger(1), 2, -Vec3::X)];
        assert_eq!(g.detect(0.0, true, &two_fingers, &closure(40.0), &world(Vec3::ZERO), &world(Vec3::ZERO), WRIST, &BALL), None, "needs the thumb or the palm");
    }

    #[test]
    fn held_object_moves_rigidly_with_the_hand() {
        let mut g = Grasp::new(GraspParams::default(), 1);
        grasped(&mut g, 0.0);
        let shift = Vec3::new(0.1, 0.2, -0.3);
        assert_eq!(g.follow(1.0 / 60.0, true, &closure(40.0), &world(shift), &world(Vec3::ZERO)), None);
        let (q, t) = g.target().unwrap();
        assert!((t - shift).length() < 1e-5 && q.angle_between(Quat::IDENTITY) < 1e-4, "{t} {q}");
    }

    #[test]
    fn tracked_fingers_closing_into_the_object_do_not_drag_it() {
        let mut g = Grasp::new(GraspParams::default(), 1);
        grasped(&mut g, 0.0);
        // The tracked thumb and index 1 cm further in, the wrist and the rendered hand still.
        let mut tracked = world(Vec3::ZERO);
        tracked[1] = Affine3A::from_translation(Vec3::new(-0.01, 0.0, 0.0));
        tracked[2] = Affine3A::from_translation(Vec3::new(0.01, 0.0, 0.0));
        assert_eq!(g.follow(1.0 / 60.0, true, &closure(50.0), &tracked, &world(Vec3::ZERO)), None);
        let (q, t) = g.target().unwrap();
        assert!(t.length() < 1e-6 && q.angle_between(Quat::IDENTITY) < 1e-5, "{t} {q}");
    }

    #[test]
    fn release_has_hysteresis_velocity_and_cooldown() {
        let mut g = Grasp::new(GraspParams::default(), 1);
        grasped(&mut g, 0.0);
        // Opening to 25° each: 5° under the 30° closure at the grasp, within the 8° margin.
        let mut t = 0.0;
        for k in 1..=3 {
            t = f64::from(k) / 60.0;
            assert_eq!(g.follow(t, true, &closure(25.0), &world(Vec3::new(0.01 * k as f32, 0.0, 0.0)), &world(Vec3::ZERO)), None);
        }
        t += 1.0 / 60.0;
        let Some(GraspEvent::Release { object: 0, linvel, .. }) = g.follow(t, true, &closure(21.0), &world(Vec3::new(0.04, 0.0, 0.0)), &world(Vec3::ZERO)) else { panic!("opened past the margin") };
        assert!((linvel - Vec3::new(0.6, 0.0, 0.0)).length() < 1e-3, "the hand moved 1 cm per frame: {linvel}");
        assert_eq!(grasped(&mut g, t + 0.1), None, "cooling down");
        assert!(grasped(&mut g, t + 0.31).is_some(), "cooled down");
    }

    #[test]
    fn a_grasp_made_with_open_fingers_is_released_past_their_tightest_wrap() {
        // Thumb and index resting on the object open (stopped at 0°, tracked 5°): grasped.
        let open = |tracked: f32, rendered: f32| {
            let c = Closure { tracked: tracked.to_radians(), rendered: rendered.to_radians() };
            [c, c, Closure::default(), Closure::default(), Closure::default()]
        };
        let mut g = Grasp::new(GraspParams::default(), 1);
        assert!(g.detect(0.0, true, &pinch(), &open(5.0, 0.0), &world(Vec3::ZERO), &world(Vec3::ZERO), WRIST, &BALL).is_some());
        // They close on, wrapping the object to 30° each, and open again: fully open is no
        // more than 8° past the closure at the grasp, but it is 30° past the tightest wrap.
        assert_eq!(g.follow(0.1, true, &open(40.0, 30.0), &world(Vec3::ZERO), &world(Vec3::ZERO)), None);
        assert_eq!(g.follow(0.2, true, &open(25.0, 25.0), &world(Vec3::ZERO), &world(Vec3::ZERO)), None, "within the margin of the wrap");
        assert!(matches!(g.follow(0.3, true, &open(0.0, 0.0), &world(Vec3::ZERO), &world(Vec3::ZERO)), Some(GraspEvent::Release { .. })));
    }

    #[test]
    fn a_short_tracking_loss_keeps_the_object() {
        let mut g = Grasp::new(GraspParams::default(), 1);
        grasped(&mut g, 0.0);
        assert_eq!(g.follow(0.1, false, &closure(0.0), &world(Vec3::ONE), &world(Vec3::ZERO)), None);
        assert_eq!(g.follow(0.55, false, &closure(0.0), &world(Vec3::ONE), &world(Vec3::ZERO)), None, "0.45 s lost: within the grace time");
        assert_eq!(g.target().unwrap().1, Vec3::ZERO, "stays where it was while lost");
        assert_eq!(g.follow(0.6, true, &closure(40.0), &world(Vec3::ZERO), &world(Vec3::ZERO)), None, "tracking back");
        assert_eq!(g.follow(0.7, false, &closure(40.0), &world(Vec3::ZERO), &world(Vec3::ZERO)), None);
        assert!(matches!(g.follow(1.21, false, &closure(40.0), &world(Vec3::ZERO), &world(Vec3::ZERO)), Some(GraspEvent::Release { linvel: Vec3::ZERO, .. })), "0.51 s lost: dropped");
    }

    #[test]
    fn two_hands_pressing_opposite_sides_hold_an_object_between_them() {
        let (a, b) = (Grasp::new(GraspParams::default(), 1), Grasp::new(GraspParams::default(), 1));
        // Flat fingers (not squeezing) of each hand on either side of the object.
        let left = [contact(HandPart::Finger(1), 2, -Vec3::X)];
        let right = [contact(HandPart::Finger(1), 2, Vec3::X)];
        let flat = closure(30.0);
        let pushed = |side: Vec3| -side * 0.01;
        // Neither hand pushed into it: no hold; both pushed 1 cm in: held.
        assert_eq!(Grasp::find_two_handed(0.0, (&a, &left, &flat, Vec3::ZERO), (&b, &right, &flat, Vec3::ZERO)), None);
        assert_eq!(Grasp::find_two_handed(0.0, (&a, &left, &flat, pushed(-Vec3::X)), (&b, &right, &flat, pushed(Vec3::X))), Some(0));
        // Pushed, but along the surface (5 mm deep is needed), or both on one side: none.
        assert_eq!(Grasp::find_two_handed(0.0, (&a, &left, &flat, Vec3::Y * 0.01), (&b, &right, &flat, pushed(Vec3::X))), None);
        assert_eq!(Grasp::find_two_handed(0.0, (&a, &left, &flat, pushed(-Vec3::X)), (&b, &left, &flat, pushed(-Vec3::X))), None);
        // Palms always press.
        let palms = ([contact(HandPart::Palm, 0, -Vec3::X)], [contact(HandPart::Palm, 0, Vec3::X)]);
        assert_eq!(Grasp::find_two_handed(0.0, (&a, &palms.0, &flat, Vec3::ZERO), (&b, &palms.1, &flat, Vec3::ZERO)), Some(0));
    }

    #[test]
    fn a_hand_holding_with_the_other_is_not_released_by_its_fingers_and_is_rebased_where_it_holds() {
        let mut g = Grasp::new(GraspParams::default(), 1);
        g.take(0.0, 0, BALL[0], false, &pinch(), &closure(40.0), &world(Vec3::ZERO), &world(Vec3::ZERO), WRIST);
        assert!(!g.alone());
        // Its fingers open wide: a hand holding its share does not let go for that.
        assert_eq!(g.follow(0.1, true, &closure(0.0), &world(Vec3::X * 0.01), &world(Vec3::ZERO)), None);
        // Its points in the object's frame, and where the hand carries them.
        let points: Vec<(Vec3, Vec3)> = g.holding_points().collect();
        assert_eq!(points.len(), 2 + WRIST_POINTS.len());
        assert!(points.iter().all(|(o, w)| (*w - *o - Vec3::X * 0.01).length() < 1e-6), "{points:?}");
        // The other hand lets go with the object 2 cm up: it stays there, not where this
        // hand alone would have put it.
        let up = (Quat::IDENTITY, Vec3::Y * 0.02);
        g.rebase(up);
        assert_eq!(g.target(), Some(up));
        assert_eq!(g.follow(0.2, true, &closure(0.0), &world(Vec3::X * 0.01), &world(Vec3::ZERO)), None);
        let (q, t) = g.target().unwrap();
        assert!((t - up.1).length() < 1e-6 && q.angle_between(Quat::IDENTITY) < 1e-5, "{t}");
        assert!(matches!(g.let_go(0.3), Some(GraspEvent::Release { object: 0, .. })));
    }
}
