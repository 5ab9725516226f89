//! The scene's rigid bodies in a rapier world.

use glam::{Affine3A, Quat, Vec3};
use rapier3d::prelude::{ActiveHooks, Collider, ColliderBuilder, ColliderHandle, ColliderSet, PairFilterContext, PhysicsHooks, RigidBodyBuilder, RigidBodyHandle, RigidBodyType, SolverFlags};
use rapier3d::pipeline::PhysicsWorld;
use parry3d::math::Pose;
use parry3d::bounding_volume::{Aabb, BoundingVolume};
use parry3d::query::ShapeCastOptions;
use parry3d::shape::SharedShape;

use crate::collision::{pose_of, simulated_hull, HandPart, HandProxies, ObjectColliders};
use crate::scene::Scene;

/// Gravity, m/s² along −Y.
pub const GRAVITY: f32 = 9.81;

/// The table top's friction and restitution: a varnished wooden top (objects keep their own,
/// and rapier combines the two by average).
pub const TABLE_FRICTION: f32 = 0.8;
/// See [`TABLE_FRICTION`].
pub const TABLE_RESTITUTION: f32 = 0.3;

/// The room's floor: the plane y = 0 (the scene files' table stands on it), so nothing that
/// leaves the table falls for ever; lower where a scene puts an object lower.
pub const FLOOR_Y: f32 = 0.0;
/// How far from the room's centre (the origin, across) an object may go before it is out of
/// reach: put back where the scene file has it, m; farther where a scene puts one farther.
pub const REACH_M: f32 = 5.0;

/// How near a joint of the hand's kinematic bodies must be to where it goes
/// to be left where it is, m and rad: far below anything the contact constraint resolves (it
/// stops the hand a fraction of a millimetre short). Rapier lists every body borrowed
/// mutably as changed, in a list it makes anew each step: a still hand whose pose wavers in
/// the last bits would otherwise cost that list's allocations every frame.
const PLACED_M: f32 = 1e-6;
/// See [`PLACED_M`].
const PLACED_RAD: f32 = 1e-6;

/// A hand's proxy this near an object let go passes through it until they are this far apart,
/// m ([`ScenePhysics::release`]).
const CLEAR_M: f32 = 0.002;

/// How far below an object let go its path is searched for proxies in the way, m: a hand's
/// length, past which no finger round it reaches.
const DROP_M: f32 = 0.2;

/// The pairs of an object let go and a hand's proxy in its way then ([`in_the_way`]), which
/// the solver leaves alone until they are clear (rapier asks this filter of every pair of an
/// object with its hook on).
struct LetGo {
    /// The object's collider, the proxy's collider, the proxy's body, and how far apart the
    /// two are clear, m.
    pairs: Vec<(ColliderHandle, ColliderHandle, RigidBodyHandle, f32)>,
}

impl PhysicsHooks for LetGo {
    /// A listed pair is left out; any other is solved as rapier solves a pair with no hook.
    fn filter_contact_pair(&self, c: &PairFilterContext) -> Option<SolverFlags> {
        let pair = |a, b| self.pairs.iter().any(|p| (p.0, p.1) == (a, b));
        (!pair(c.collider1, c.collider2) && !pair(c.collider2, c.collider1)).then(SolverFlags::default)
    }
}

/// The shape rapier simulates for a hand proxy or an object: a hull's [`simulated_hull`], any
/// other shape itself. A mesh object's solid is its hull, every vertex of it tried for each
/// support point (the teapot's 598; simulated, 256, made in 10 ms when the physics is built):
/// the teapot's physics step with fingers closing on it fell from 265 to 172 µs at p99 (2-core
/// AMD EPYC VM, `dqhand grasp-bench --objects teapot --speeds 0.5 --approaches above`), and its
/// worst frames from 1.42 to 1.08 ms.
fn simulated(shape: &SharedShape) -> SharedShape {
    shape.as_convex_polyhedron().and_then(|hull| simulated_hull(hull.points())).unwrap_or_else(|| shape.clone())
}

/// Whether hand proxy `proxy` is in the way of object `object` settling from the hand: within
/// [`CLEAR_M`] of it, or, with `drop` above 0, of it moved `drop` straight down. If so, how
/// far apart they are clear (and meet again), m: [`CLEAR_M`], or for a proxy below it the gap
/// now plus [`CLEAR_M`], which [`ScenePhysics::step`] narrows to their nearest since plus
/// [`CLEAR_M`]. The proxy is where the last step put it: its body's pose this frame, which the
/// next step moves it to, let more fingers through, and the teapot set down from the front,
/// headset-tracked, settled 1.46 mm into them (0.80 mm so).
fn in_the_way(colliders: &ColliderSet, object: ColliderHandle, proxy: ColliderHandle, drop: f32) -> Option<f32> {
    let gap = distance(colliders, object, proxy);
    if gap < CLEAR_M {
        return Some(CLEAR_M);
    }
    (drop > 0.0 && falls_onto(colliders, object, proxy, CLEAR_M, drop).is_some()).then_some(gap + CLEAR_M)
}

/// Whether an object whose centre of mass is at `centre` rests on a palm whose proxies in
/// its way ([`in_the_way`]) lie in box `palm`: under that centre (its top below it, its
/// footprint round it), so the object's weight bears on them. A palm under an object let go
/// holds it up; one beside or above it (the grasp from the side, from above) passes through
/// it as the fingers do.
fn rests_on(palm: &Aabb, centre: Vec3) -> bool {
    palm.maxs.y < centre.y && (palm.mins.x..=palm.maxs.x).contains(&centre.x) && (palm.mins.z..=palm.maxs.z).contains(&centre.z)
}

/// How far collider `object` moves straight down before it comes within `target` of collider
/// `other`, if it does within `drop` (m). Only from apart: parry answers a cast that starts
/// within the target distance with a contact query, a penetration query (which allocates)
/// where the shapes overlap.
fn falls_onto(colliders: &ColliderSet, object: ColliderHandle, other: ColliderHandle, target: f32, drop: f32) -> Option<f32> {
    let (a, b) = (&colliders[object], &colliders[other]);
    let options = ShapeCastOptions { max_time_of_impact: drop, target_distance: target, ..ShapeCastOptions::default() };
    let hit = parry3d::query::cast_shapes(a.position(), Vec3::NEG_Y, a.shape(), b.position(), Vec3::ZERO, b.shape(), options);
    hit.ok().flatten().map(|hit| hit.time_of_impact)
}

/// How far apart colliders `a` and `b` of `colliders` are (0 where they overlap; infinite
/// where parry cannot tell).
fn distance(colliders: &ColliderSet, a: ColliderHandle, b: ColliderHandle) -> f32 {
    let (a, b) = (&colliders[a], &colliders[b]);
    parry3d::query::distance(a.position(), a.shape(), b.position(), b.shape()).map_or(f32::INFINITY, |d| d.distance)
}

/// Whether `a` and `b` are within [`PLACED_M`] and [`PLACED_RAD`] of each other.
fn near(a: &Pose, b: &Pose) -> bool {
    a.translation.distance(b.translation) <= PLACED_M && 2.0 * (a.rotation.inverse() * b.rotation).xyz().length() <= PLACED_RAD
}

/// A hand's proxy in the simulation.
#[derive(Clone, Copy)]
struct ProxyBody {
    body: RigidBodyHandle,
    collider: ColliderHandle,
    /// The joint it moves with.
    joint: usize,
    /// Whether it is the palm's ([`HandPart::Palm`]): a palm may hold up an object let go.
    palm: bool,
}

/// The scene's free objects and table, simulated.
pub struct ScenePhysics {
    world: PhysicsWorld,
    bodies: Vec<RigidBodyHandle>,
    /// Each object's collider.
    colliders: Vec<ColliderHandle>,
    /// Objects let go and the proxies round them then, not yet clear.
    let_go: LetGo,
    /// Where the file puts each object.
    initial: Vec<Pose>,
    /// Per object, whether a hand holds it (it moves kinematically).
    held: Vec<bool>,
    /// Each rendered hand's proxies as kinematic bodies, with their joints: a free object
    /// meets the hands (a released ball rests on the fingers, a rolling one stops at them)
    /// instead of passing into them.
    hands: Vec<Vec<ProxyBody>>,
    /// The objects the last step put back, out of reach ([`REACH_M`], or under the floor).
    returned: Vec<usize>,
    /// The floor's height and the reach across, m (for this scene's objects).
    floor: f32,
    reach: f32,
}

impl ScenePhysics {
    /// The objects of `scene` at rest where the file puts them (their solids from
    /// `colliders`), on its table if it has one.
    #[must_use]
    pub fn new(scene: &Scene, colliders: &ObjectColliders) -> Self {
        let mut world = PhysicsWorld::new();
        world.gravity = Vec3::new(0.0, -GRAVITY, 0.0);
        world.integration_parameters.max_ccd_substeps = 4;
        let mut bodies = Vec::with_capacity(scene.objects.len());
        let mut handles = Vec::with_capacity(scene.objects.len());
        let mut initial = Vec::with_capacity(scene.objects.len());
        for (o, c) in scene.objects.iter().zip(colliders.objects()) {
            let pose = Pose::from_parts(o.position, o.rotation);
            let body = RigidBodyBuilder::dynamic().pose(pose).ccd_enabled(true).build();
            let collider = ColliderBuilder::new(simulated(&c.solid)).mass(o.mass).friction(o.friction).restitution(o.restitution).build();
            let (handle, collider) = world.insert(body, collider);
            bodies.push(handle);
            handles.push(collider);
            initial.push(pose);
        }
        if let Some(slab) = colliders.table_collider() {
            world.insert_collider(ColliderBuilder::new(slab.solid.clone()).position(slab.pose).friction(TABLE_FRICTION).restitution(TABLE_RESTITUTION).build(), None);
        }
        // Under every object and beyond the farthest, whatever the scene file says.
        let (floor, reach) = colliders.objects().iter().fold((FLOOR_Y, REACH_M), |(floor, reach), o| {
            let b = o.aabb();
            let across = Vec3::new(b.mins.x.abs().max(b.maxs.x.abs()), 0.0, b.mins.z.abs().max(b.maxs.z.abs())).length();
            (floor.min(b.mins.y - 0.01), reach.max(across + 1.0))
        });
        let slab = ColliderBuilder::cuboid(2.0 * reach, 0.5, 2.0 * reach).translation(Vec3::new(0.0, floor - 0.5, 0.0));
        world.insert_collider(slab.friction(TABLE_FRICTION).restitution(TABLE_RESTITUTION).build(), None);
        let returned = Vec::with_capacity(bodies.len());
        let let_go = LetGo { pairs: Vec::new() };
        Self { world, held: vec![false; bodies.len()], bodies, colliders: handles, let_go, initial, hands: Vec::new(), returned, floor, reach }
    }

    /// Adds a hand: `proxies` as kinematic bodies that [`Self::move_hand`] moves, a hull as its
    /// [`simulated_hull`] (which holds it with fewer vertices; the hull itself where that has
    /// none); returns its index there.
    pub fn add_hand(&mut self, proxies: &HandProxies) -> usize {
        let hand = proxies
            .colliders()
            .iter()
            .map(|p| {
                let body = RigidBodyBuilder::kinematic_position_based().build();
                let (body, collider) = self.world.insert(body, ColliderBuilder::new(simulated(&p.shape)).build());
                ProxyBody { body, collider, joint: p.joint, palm: p.part == HandPart::Palm }
            })
            .collect();
        self.hands.push(hand);
        // Room for every proxy of every hand in every object: no allocation when letting go.
        self.let_go.pairs.reserve(self.hands.iter().map(Vec::len).sum::<usize>() * self.bodies.len());
        self.hands.len() - 1
    }

    /// Puts hand `hand`'s joints at `world`, or takes it out of the world (`None`: the hand
    /// is not tracked, and an object it held off or pinched is free). Placed, not swept: the
    /// solver would give the bodies the velocity of the move, and a hand that stops at an
    /// object within the frame (the contact constraint stops it a fraction of a millimetre
    /// short) would strike it at full speed. So the hand holds free objects off and stops
    /// them, and does not bat them. A joint already where it goes ([`PLACED_M`]) is left
    /// alone.
    pub fn move_hand(&mut self, hand: usize, world: Option<&[Affine3A]>) {
        // Rapier marks every body borrowed mutably as changed: only those that change are.
        for &ProxyBody { body: h, joint, .. } in &self.hands[hand] {
            let placed = &self.world.bodies[h];
            let Some(world) = world else {
                if placed.is_enabled() {
                    self.world.bodies[h].set_enabled(false);
                }
                continue;
            };
            let pose = pose_of(&world[joint]);
            if placed.is_enabled() && near(placed.position(), &pose) && near(placed.next_position(), &pose) {
                continue;
            }
            let body = &mut self.world.bodies[h];
            body.set_enabled(true);
            body.set_position(pose, true);
            body.set_next_kinematic_position(pose);
        }
    }

    /// Objects with hooks but no pair let go left lose them.
    fn unhook(&mut self) {
        for &object in &self.colliders {
            let collider = &self.world.colliders[object];
            if !collider.active_hooks().is_empty() && !self.let_go.pairs.iter().any(|p| p.0 == object) {
                self.world.colliders[object].set_active_hooks(ActiveHooks::empty());
            }
        }
    }

    /// How far object collider `object` can fall straight down before it meets anything but a
    /// hand, m (at most [`DROP_M`]); 0 where it touches anything (it rests on it, or the
    /// proxies within [`CLEAR_M`] are all that is let through).
    fn drop_height(&self, object: ColliderHandle) -> f32 {
        let colliders = &self.world.colliders;
        let mut path = colliders[object].compute_aabb();
        path.mins.y -= DROP_M;
        let hand = |h: ColliderHandle| self.hands.iter().flatten().any(|p| p.collider == h);
        let below = |&(h, c): &(ColliderHandle, &Collider)| h != object && !hand(h) && c.compute_aabb().intersects(&path);
        // Cast only from apart (`falls_onto`): an object touching something falls 0.
        let down = |(h, _): (ColliderHandle, &Collider)| if distance(colliders, object, h) <= 0.0 { Some(0.0) } else { falls_onto(colliders, object, h, 0.0, DROP_M) };
        colliders.iter().filter(below).filter_map(down).fold(DROP_M, f32::min)
    }

    /// Object `i`'s pose: rotation and translation.
    #[must_use]
    pub fn pose(&self, i: usize) -> (Quat, Vec3) {
        let p = self.world.bodies[self.bodies[i]].position();
        (p.rotation, p.translation)
    }

    /// Object `i`'s linear and angular velocity.
    #[must_use]
    pub fn velocity(&self, i: usize) -> (Vec3, Vec3) {
        let b = &self.world.bodies[self.bodies[i]];
        (b.linvel(), b.angvel())
    }

    /// Object `i` is in a hand: the next [`Self::step`] moves it to `rotation`,
    /// `translation`, pushing what it meets on the way.
    pub fn hold(&mut self, i: usize, rotation: Quat, translation: Vec3) {
        if !self.held[i] {
            let object = self.colliders[i];
            self.let_go.pairs.retain(|p| p.0 != object);
            self.unhook();
            self.world.bodies[self.bodies[i]].set_body_type(RigidBodyType::KinematicPositionBased, true);
            self.held[i] = true;
        }
        self.world.bodies[self.bodies[i]].set_next_kinematic_position(Pose::from_parts(translation, rotation));
    }

    /// Object `i` leaves the hands with its origin moving at `linvel` and turning at `angvel`.
    /// The fingers are round it then, touching it or a fraction of a millimetre inside (the
    /// grasp held it kinematically): the solver would push them apart, and an object settling
    /// past them would be nudged away (a ball set down by a still hand rolled 21 mm, by a
    /// headset-tracked one 30 cm). So each proxy within [`CLEAR_M`] of it passes through it
    /// until they are [`CLEAR_M`] apart ([`Self::step`]), and so does each proxy of the hands
    /// letting go, `by` (their indices), below it in the path it may fall before anything else
    /// stops it ([`Self::drop_height`]): a ball let go 8 mm above the table by a
    /// headset-tracked hand landed on the little finger 4.5 mm below it and rolled 23 cm away.
    /// The other proxies still hold it off (another hand under it catches it), and so does a
    /// palm it rests on ([`rests_on`]): a ball let go on an upturned palm fell through the
    /// hand. The rendered hand stops at it whatever the physics does (the contact constraint).
    pub fn release(&mut self, i: usize, linvel: Vec3, angvel: Vec3, by: &[usize]) {
        let object = self.colliders[i];
        let drop = if by.is_empty() { 0.0 } else { self.drop_height(object) };
        for (h, hand) in self.hands.iter().enumerate() {
            let drop = if by.contains(&h) { drop } else { 0.0 };
            let colliders = &self.world.colliders;
            let first = self.let_go.pairs.len();
            for p in hand {
                if let Some(gap) = self.world.bodies[p.body].is_enabled().then(|| in_the_way(colliders, object, p.collider, drop)).flatten() {
                    self.let_go.pairs.push((object, p.collider, p.body, gap));
                }
            }
            // The palm's proxies among them hold it up if it rests on them.
            let palm = |proxy: ColliderHandle| hand.iter().any(|p| p.palm && p.collider == proxy);
            let boxes = self.let_go.pairs[first..].iter().filter(|q| palm(q.1)).map(|q| colliders[q.1].compute_aabb());
            if boxes.reduce(|a, b| a.merged(&b)).is_some_and(|b| rests_on(&b, self.world.bodies[self.bodies[i]].center_of_mass())) {
                let pairs = &mut self.let_go.pairs;
                let mut kept = first;
                for j in first..pairs.len() {
                    if !palm(pairs[j].1) {
                        pairs.swap(kept, j);
                        kept += 1;
                    }
                }
                pairs.truncate(kept);
            }
        }
        // The filter is asked only while the object has such pairs (rapier allocates more
        // per frame for a collider with hooks).
        if self.let_go.pairs.iter().any(|p| p.0 == object) {
            self.world.colliders[object].set_active_hooks(ActiveHooks::FILTER_CONTACT_PAIRS);
        }
        self.held[i] = false;
        let body = &mut self.world.bodies[self.bodies[i]];
        body.set_body_type(RigidBodyType::Dynamic, true);
        // The simulation moves the centre of mass; the hand gave the origin's velocity.
        let lever = body.center_of_mass() - body.position().translation;
        body.set_linvel(linvel + angvel.cross(lever), true);
        body.set_angvel(angvel, true);
    }

    /// Every object back where the file puts it, at rest, none held.
    pub fn reset(&mut self) {
        self.held.fill(false);
        self.let_go.pairs.clear();
        self.unhook();
        for i in 0..self.bodies.len() {
            self.put_back(i);
        }
    }

    /// Object `i` back where the file puts it, at rest.
    fn put_back(&mut self, i: usize) {
        let body = &mut self.world.bodies[self.bodies[i]];
        body.set_body_type(RigidBodyType::Dynamic, true);
        body.set_position(self.initial[i], true);
        body.set_linvel(Vec3::ZERO, true);
        body.set_angvel(Vec3::ZERO, true);
    }

    /// Advances the simulation by `dt` seconds; a free object that leaves the reach of the
    /// room ([`REACH_M`] across, or through the floor) is put back ([`Self::returned`]).
    pub fn step(&mut self, dt: f32) {
        self.world.integration_parameters.dt = dt;
        self.world.step_with_events(&self.let_go, &());
        if !self.let_go.pairs.is_empty() {
            let (colliders, bodies) = (&self.world.colliders, &self.world.bodies);
            // A pair ends once the two are CLEAR_M farther apart than their nearest since the
            // release: the object has passed the proxy, or come to rest beside it.
            self.let_go.pairs.retain_mut(|(object, proxy, body, gap)| {
                let d = distance(colliders, *object, *proxy);
                *gap = gap.min(d + CLEAR_M);
                bodies[*body].is_enabled() && d < *gap
            });
            self.unhook();
        }
        self.returned.clear();
        for i in 0..self.bodies.len() {
            let p = self.world.bodies[self.bodies[i]].position().translation;
            let out = Vec3::new(p.x, 0.0, p.z).length() > self.reach || p.y < self.floor - 0.5;
            if out && !self.held[i] {
                self.put_back(i);
                self.returned.push(i);
            }
        }
    }

    /// The objects the last [`Self::step`] put back because they had left the room's reach.
    #[must_use]
    pub fn returned(&self) -> &[usize] {
        &self.returned
    }
}
