//! The scene's objects as persistent parry shapes: built once when a scene is loaded, moved
//! by pose each frame. A mesh has two: its true surface (a triangle mesh, which the hand
//! touches and penetration is measured against; it need not be closed, as the Utah teapot
//! is not) and a solid for the physics (its convex hull), because a triangle soup has no
//! volume to give a mass or to rest on a table with.
//!
//! The table is a fixed slab under the objects: the hand meets it (a finger does not close
//! through it) and the physics rests objects on it, but it is not an object to grasp.
//!
//! With two hands, each hand's proxies, where it was last rendered, are obstacles to the
//! other ([`ObjectColliders::add_hand`]): the rendered hands do not pass through each other.

use std::sync::Arc;

use glam::{Affine3A, Quat, Vec3};
use parry3d::bounding_volume::{Aabb, BoundingVolume};
use parry3d::math::Pose;
use parry3d::query::{self, NonlinearRigidMotion};
use parry3d::shape::{SharedShape, SupportMap, TriMeshFlags};

use super::hand_proxies::{pose_of, ProxyCollider};
use super::hull_support::HullSupport;
use super::support_pair::SupportPair;
use super::triangle_tree::TriangleTree;
use super::HandProxies;
use crate::Warning;
use crate::scene::{ObjectMesh, ObjectShape, Scene};
use crate::{Error, Result};

/// One object's shapes and where it is.
#[derive(Clone)]
pub struct ObjectCollider {
    /// The object's name in the scene.
    pub name: String,
    /// The true surface, in the object's frame.
    pub surface: SharedShape,
    /// The solid the physics simulates, in the object's frame.
    pub solid: SharedShape,
    /// The surface's triangles in the object's frame, for measuring penetration (a mesh's
    /// own; a primitive's are not needed: its surface is exact).
    pub mesh: Option<ObjectMesh>,
    /// The object's current world pose.
    pub pose: Pose,
    aabb: Aabb,
    /// A mesh's triangles in the tree the hand's proxies search (shared: colliders are cloned
    /// with the scene).
    triangles: Option<Arc<TriangleTree>>,
    /// The hull's support function by hill climbing, where the hull is a convex polyhedron.
    hull_support: Option<HullSupport>,
}

impl ObjectCollider {
    /// The world bounding box of the surface in the current pose.
    #[must_use]
    pub fn aabb(&self) -> &Aabb {
        &self.aabb
    }

    /// A mesh object's triangles, as [`super::ProxyMeshQuery`] searches them.
    #[must_use]
    pub fn triangles(&self) -> Option<&TriangleTree> {
        self.triangles.as_deref()
    }

    /// A convex shape that holds the surface and is much cheaper to query (a mesh's hull), where
    /// the surface is not convex itself: nothing outside it can touch the surface, so a query
    /// that stays outside it need not look at the triangles.
    #[must_use]
    pub fn hull(&self) -> Option<&SharedShape> {
        self.mesh.as_ref().map(|_| &self.solid)
    }

    /// The [`Self::hull`]'s support function, where it has one (a flat mesh's box is a compound).
    fn hull_support(&self) -> Option<&dyn SupportMap> {
        match &self.hull_support {
            Some(hull) => Some(hull),
            None => self.hull()?.as_support_map(),
        }
    }

    /// The distance from `proxy` at `pose` to the [`Self::hull`], if there is one: a lower
    /// bound of the distance to the surface.
    #[must_use]
    pub fn hull_distance(&self, pose: &Pose, proxy: &ProxyCollider) -> Option<f32> {
        let hull = self.hull()?;
        match self.hull_support() {
            Some(support) => Some(query::details::distance_support_map_support_map(&pose.inv_mul(&self.pose), proxy.support(), support)),
            None => query::distance(pose, &*proxy.shape, &self.pose, &**hull).ok().map(|x| x.distance),
        }
    }

    /// Whether `proxy`, moving by `motion` until time `end`, stays clear of the [`Self::hull`]
    /// (starting inside it is a hit): nothing that misses the hull can touch the surface.
    /// `false` where there is no hull.
    #[must_use]
    pub fn misses_hull(&self, motion: &NonlinearRigidMotion, proxy: &ProxyCollider, end: f32) -> bool {
        let Some(hull) = self.hull() else { return false };
        let still = NonlinearRigidMotion::constant_position(self.pose);
        match &self.hull_support {
            Some(support) => SupportPair { shapes: [&*proxy.shape, &**hull], supports: [proxy.support(), support] }.time_of_impact(motion, &still, end).is_none(),
            None => matches!(query::cast_shapes_nonlinear(motion, &*proxy.shape, &still, &**hull, 0.0, end, true), Ok(None)),
        }
    }

    /// The distance from `proxy` at `pose` to the surface, or a lower bound of it above
    /// `enough` (m): the distance to the [`Self::hull`], or a box's face-plane gap, when that
    /// is larger.
    #[must_use]
    pub fn distance_at_least(&self, pose: &Pose, proxy: &ProxyCollider, enough: f32) -> f32 {
        match self.hull_distance(pose, proxy).or_else(|| self.box_gap(pose, proxy)) {
            Some(d) if d > enough => d,
            _ => query::distance(pose, &*proxy.shape, &self.pose, &*self.surface).map_or(f32::INFINITY, |x| x.distance),
        }
    }

    /// Where the surface is a box (the table, a cube), a lower bound of its distance from
    /// `proxy` at `pose`: how far the proxy lies beyond the farthest of the box's six face
    /// planes (the box is on the inner side of each, the proxy past it). Exact above the
    /// middle of a face, as a finger over the table is, where parry's distance runs GJK.
    fn box_gap(&self, pose: &Pose, proxy: &ProxyCollider) -> Option<f32> {
        let half = self.surface.as_cuboid()?.half_extents;
        let local = self.pose.inv_mul(pose);
        let gap = (0..6)
            .map(|k| {
                let n = Vec3::AXES[k % 3] * if k < 3 { 1.0 } else { -1.0 };
                // The proxy's least extent along n: its support point along −n.
                let least = (local * proxy.support().local_support_point_toward(local.rotation.inverse() * -n)).dot(n);
                least - half[k % 3]
            })
            .fold(f32::MIN, f32::max);
        Some(gap)
    }
}

/// The table's top: a slab 5 cm thick reaching 30 cm past the objects' footprint, at least
/// 1.2 × 0.8 m.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TableTop {
    /// Height of the top (y), m.
    pub height: f32,
    /// Centre of the top (x, z), m.
    pub centre: [f32; 2],
    /// Half sizes of the top (x, z), m.
    pub half: [f32; 2],
}

/// Half the thickness of the table's slab, m.
const TABLE_HALF_THICKNESS: f32 = 0.025;
/// How far the table reaches past its objects, m.
const TABLE_MARGIN: f32 = 0.3;
/// The table's least half sizes (x, z), m.
const TABLE_MIN_HALF: [f32; 2] = [0.6, 0.4];

/// Every object of a scene, in file order, the table, and the hands' proxies.
#[derive(Clone)]
pub struct ObjectColliders {
    /// The objects, then the table's slab when there is one, then each hand's proxies.
    all: Vec<ObjectCollider>,
    count: usize,
    /// Per hand: where its proxies are in `all`, their joints and boxes in the joints'
    /// frames, and whether it is there.
    hands: Vec<(core::ops::Range<usize>, Vec<(usize, Aabb)>, bool)>,
    /// The hand being solved: its own proxies are no obstacle to it.
    solving: Option<usize>,
    table: Option<TableTop>,
    warnings: Vec<Warning>,
}

impl ObjectColliders {
    /// The shapes of `scene`'s objects, at the poses the file gives them.
    ///
    /// # Errors
    /// As [`ObjectMesh::load`] for a mesh object: a file that cannot be read, or no usable
    /// triangle.
    pub fn new(scene: &Scene) -> Result<Self> {
        let mut warnings = Vec::new();
        let mut objects = Vec::with_capacity(scene.objects.len());
        for o in &scene.objects {
            let (surface, solid, mesh) = match &o.shape {
                ObjectShape::Sphere { radius } => (SharedShape::ball(*radius), SharedShape::ball(*radius), None),
                ObjectShape::Box { size } => {
                    let s = SharedShape::cuboid(size.x / 2.0, size.y / 2.0, size.z / 2.0);
                    (s.clone(), s, None)
                }
                ObjectShape::Cylinder { radius, height } => {
                    let s = SharedShape::cylinder(height / 2.0, *radius);
                    (s.clone(), s, None)
                }
                ObjectShape::Mesh { source, scale } => {
                    let mut mesh = source.load()?;
                    for v in &mut mesh.vertices {
                        *v *= *scale;
                    }
                    warnings.extend(mesh.warnings.iter().map(|w| Warning::Object { object: o.name.clone(), warning: Box::new(w.clone()) }));
                    let (surface, solid) = mesh_shapes(&mesh).map_err(|problem| Error::ObjectMesh(format!("{source}: {}: {problem}", o.name)))?;
                    (surface, solid, Some(mesh))
                }
            };
            let pose = Pose::from_parts(o.position, o.rotation);
            let aabb = surface.compute_aabb(&pose);
            let hull_support = mesh.as_ref().and(solid.as_convex_polyhedron()).map(|h| HullSupport::new(h, 1.0));
            let triangles = mesh.as_ref().map(|m| Arc::new(TriangleTree::new(&m.vertices, &m.triangles)));
            objects.push(ObjectCollider { name: o.name.clone(), surface, solid, mesh, pose, aabb, triangles, hull_support });
        }
        let count = objects.len();
        let table = scene.table.map(|t| table_top(t.height, &objects));
        if let Some(t) = table {
            let surface = SharedShape::cuboid(t.half[0], TABLE_HALF_THICKNESS, t.half[1]);
            let pose = Pose::from_translation(Vec3::new(t.centre[0], t.height - TABLE_HALF_THICKNESS, t.centre[1]));
            let aabb = surface.compute_aabb(&pose);
            objects.push(ObjectCollider { name: "table".to_owned(), solid: surface.clone(), surface, mesh: None, pose, aabb, triangles: None, hull_support: None });
        }
        Ok(Self { all: objects, count, hands: Vec::new(), solving: None, table, warnings })
    }

    /// The objects, in scene order (not the table).
    #[must_use]
    pub fn objects(&self) -> &[ObjectCollider] {
        &self.all[..self.count]
    }

    /// The table's top, if the scene has a table.
    #[must_use]
    pub fn table(&self) -> Option<TableTop> {
        self.table
    }

    /// The table's slab as a collider (index [`Self::objects`]`.len()` in [`Self::near`]).
    #[must_use]
    pub fn table_collider(&self) -> Option<&ObjectCollider> {
        self.table.and(self.all.get(self.count))
    }

    /// How many colliders [`Self::near`] may name: the objects, the table, the hands' proxies.
    #[must_use]
    pub fn len(&self) -> usize {
        self.all.len()
    }

    /// Whether there is nothing at all (no object, no table, no hand).
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.all.is_empty()
    }

    /// What was accepted with a doubt (a flat mesh, dropped triangles), one line each.
    #[must_use]
    pub fn warnings(&self) -> &[Warning] {
        &self.warnings
    }

    /// Moves object `i` (allocates nothing).
    pub fn set_pose(&mut self, i: usize, rotation: Quat, translation: Vec3) {
        let o = &mut self.objects_mut()[i];
        o.pose = Pose::from_parts(translation, rotation);
        o.aabb = o.surface.compute_aabb(&o.pose);
    }

    /// Where object `i` may go when the hand puts it at `rotation`, `translation`: no lower
    /// than resting on the table where it is over the table. A held object moves kinematically,
    /// so the physics would let it pass into the table, and released there it would fall
    /// through.
    #[must_use]
    pub fn above_table(&self, i: usize, rotation: Quat, translation: Vec3) -> Vec3 {
        let Some(table) = self.table else { return translation };
        let pose = Pose::from_parts(translation, rotation);
        let solid = &self.objects()[i].solid;
        let over = (0..2).all(|k| (translation[2 * k] - table.centre[k]).abs() <= table.half[k]);
        let lowest = match solid.as_support_map() {
            Some(convex) => convex.support_point(&pose, Vec3::NEG_Y).y,
            None => solid.compute_aabb(&pose).mins.y,
        };
        if over && lowest < table.height {
            translation + Vec3::Y * (table.height - lowest)
        } else {
            translation
        }
    }

    /// Object `i`, or the table where `i` is the objects' count (an index [`Self::near`] gave).
    #[must_use]
    pub fn collider(&self, i: usize) -> &ObjectCollider {
        &self.all[i]
    }

    fn objects_mut(&mut self) -> &mut [ObjectCollider] {
        &mut self.all[..self.count]
    }

    /// The broad phase: the objects, the table (its index one past the objects') and the
    /// other hand's proxies ([`Self::solving`]), whose bounding box meets `aabb` (grown by
    /// `margin`), except `skip`.
    pub fn near(&self, aabb: &Aabb, margin: f32, skip: Option<usize>) -> impl Iterator<Item = (usize, &ObjectCollider)> {
        let aabb = aabb.loosened(margin);
        self.all.iter().enumerate().filter(move |(i, o)| Some(*i) != skip && o.aabb.intersects(&aabb) && self.obstacle(*i))
    }

    /// Adds a hand's `proxies` as obstacles to the other hands; returns the hand's index.
    /// It is not there until [`Self::move_hand`] puts it somewhere.
    pub fn add_hand(&mut self, proxies: &HandProxies) -> usize {
        let start = self.all.len();
        for p in proxies.colliders() {
            let pose = Pose::IDENTITY;
            let aabb = p.aabb(&pose);
            self.all.push(ObjectCollider { name: "hand".to_owned(), surface: p.shape.clone(), solid: p.shape.clone(), mesh: None, pose, aabb, triangles: None, hull_support: None });
        }
        self.hands.push((start..self.all.len(), proxies.colliders().iter().map(|p| (p.joint, p.aabb(&Pose::IDENTITY))).collect(), false));
        self.hands.len() - 1
    }

    /// Puts hand `hand`'s proxies on its joints' `world` transforms, or takes it away
    /// (`None`: not tracked). Allocates nothing.
    pub fn move_hand(&mut self, hand: usize, world: Option<&[Affine3A]>) {
        let (range, joints, there) = &mut self.hands[hand];
        *there = world.is_some();
        let Some(world) = world else { return };
        for (o, (j, local)) in self.all[range.clone()].iter_mut().zip(joints.iter()) {
            o.pose = pose_of(&world[*j]);
            // (A hull's box turned: parry's transforms each of its vertices.)
            o.aabb = local.transform_by(&o.pose);
        }
    }

    /// The share of object `i`'s motion from where it is to `to` (0 to 1) it may make before
    /// it comes within `stop` (m) of hand `hand`'s proxies, where that hand is placed
    /// and does not hold it: a held object moves kinematically with the hand holding it, and
    /// the other hand, stopped on it, cannot move out of its way (headset-tracked jitter
    /// carried a bar handed over 2.9 mm into the fingers closing on it). A proxy it overlaps
    /// already stops it only going deeper (parry's directional cast). A mesh is not stopped:
    /// parry's cast of a triangle mesh cost 4–60 ms frames ([`super::ProxyMeshQuery`]).
    #[must_use]
    pub fn free_share(&self, i: usize, hand: usize, to: &Pose, stop: f32) -> f32 {
        let (range, _, there) = &self.hands[hand];
        let o = &self.all[i];
        if !*there || range.is_empty() || o.mesh.is_some() {
            return 1.0;
        }
        let from = o.pose;
        let swept = o.surface.compute_swept_aabb(&from, to);
        // The short way round, as the object is then turned (slerp).
        let relative = to.rotation * from.rotation.inverse();
        let turn = if relative.w < 0.0 { -relative } else { relative }.to_scaled_axis();
        let linvel = to.translation - from.translation;
        let motion = NonlinearRigidMotion::new(from, Vec3::ZERO, linvel, turn);
        let radius = swept.half_extents().length();
        let swept = swept.loosened(radius * turn.length() / 2.0 + stop);
        let hit = self.all[range.clone()].iter().filter(|p| p.aabb.intersects(&swept)).fold(1.0, |share, p| {
            let still = NonlinearRigidMotion::constant_position(p.pose);
            match query::cast_shapes_nonlinear(&motion, &*o.surface, &still, &*p.surface, 0.0, share, false) {
                Ok(Some(hit)) => share.min(hit.time_of_impact),
                _ => share,
            }
        });
        // Stopped short of it, as the wrist is: not touching next frame.
        if hit < 1.0 { (hit - stop / (linvel.length() + turn.length() * radius)).max(0.0) } else { 1.0 }
    }

    /// The hand whose rendered pose is solved next: the other hands' proxies are obstacles
    /// to it, its own are not (`None`: no hand's are).
    pub fn solving(&mut self, hand: Option<usize>) {
        self.solving = hand;
    }

    /// Whether collider `i` stops the hand being solved.
    fn obstacle(&self, i: usize) -> bool {
        match self.hands.iter().position(|(r, _, _)| r.contains(&i)) {
            None => true,
            Some(h) => self.hands[h].2 && self.solving.is_some_and(|s| s != h),
        }
    }
}

/// The top of a table at `height` under `objects`: their footprint grown by [`TABLE_MARGIN`],
/// at least [`TABLE_MIN_HALF`]; centred on the origin when there is no object.
fn table_top(height: f32, objects: &[ObjectCollider]) -> TableTop {
    let (mut lo, mut hi) = ([0.0f32; 2], [0.0f32; 2]);
    if !objects.is_empty() {
        (lo, hi) = ([f32::INFINITY; 2], [f32::NEG_INFINITY; 2]);
        for o in objects {
            for (k, axis) in [0, 2].into_iter().enumerate() {
                lo[k] = lo[k].min(o.aabb.mins[axis]);
                hi[k] = hi[k].max(o.aabb.maxs[axis]);
            }
        }
    }
    let centre = [(lo[0] + hi[0]) / 2.0, (lo[1] + hi[1]) / 2.0];
    let half = [0, 1].map(|k| ((hi[k] - lo[k]) / 2.0 + TABLE_MARGIN).max(TABLE_MIN_HALF[k]));
    TableTop { height, centre, half }
}

/// A mesh's surface (triangles as they are: it may be open) and solid (its convex hull; a
/// flat mesh's box, 1 mm thick, since a plane has no hull).
fn mesh_shapes(mesh: &ObjectMesh) -> std::result::Result<(SharedShape, SharedShape), String> {
    let surface = SharedShape::trimesh_with_flags(mesh.vertices.clone(), mesh.triangles.clone(), TriMeshFlags::empty()).map_err(|e| e.to_string())?;
    let solid = SharedShape::convex_hull(&mesh.vertices).unwrap_or_else(|| {
        let aabb = Aabb::from_points(mesh.vertices.iter().copied());
        let half = (aabb.half_extents()).max(Vec3::splat(0.0005));
        SharedShape::compound(vec![(Pose::from_translation(aabb.center()), SharedShape::cuboid(half.x, half.y, half.z))])
    });
    Ok((surface, solid))
}

#[cfg(test)]
mod tests {
    use super::*;
    use parry3d::shape::Shape;

    /// A ball carried towards the other hand's index fingertip, along the finger, stops where it touches the hand
    /// (checked against the distances there), goes freely the other way, and passes where the
    /// hand is not placed.
    #[test]
    fn a_held_object_stops_at_the_other_hand() {
        let mut colliders = ObjectColliders::new(&Scene::named("objects").unwrap()).unwrap();
        let model = crate::hand::build(&crate::hand::HandParams::default()).expect("the built-in hand");
        let proxies = HandProxies::new(&super::super::fit_proxies(&model, super::super::PROXY_MARGIN), &model.skeleton);
        let hand = colliders.add_hand(&proxies);
        colliders.move_hand(hand, Some(&model.bind_world()));
        let tip = proxies.colliders().iter().position(|p| model.skeleton.joints()[p.joint].name == "index-finger-phalanx-distal").unwrap();
        let tip_pose = pose_of(&model.bind_world()[proxies.colliders()[tip].joint]);
        let ball = colliders.objects().iter().position(|o| o.name == "ball").unwrap();
        // 4 cm in radius, 2 cm beyond the fingertip along the finger, carried 4 cm back.
        let axis = proxies.colliders()[tip].shape.as_capsule().expect("a phalanx's capsule").segment;
        let (a, b) = (tip_pose * axis.a, tip_pose * axis.b);
        let along = (b - a).normalize();
        let start = b + along * 0.06;
        colliders.set_pose(ball, Quat::IDENTITY, start);
        let towards = Pose::from_translation(start - along * 0.04);
        let share = colliders.free_share(ball, hand, &towards, 0.0004);
        assert!(share > 0.0 && share < 1.0, "{share}");
        colliders.set_pose(ball, Quat::IDENTITY, start.lerp(towards.translation, share));
        let o = &colliders.objects()[ball];
        let p = &proxies.colliders()[tip];
        // Signed distances (negative where they overlap).
        let signed = |pose: &Pose, shape: &dyn Shape| query::contact(&o.pose, &*o.surface, pose, shape, 0.01).unwrap().map_or(0.01, |c| c.dist);
        let nearest = colliders.all[colliders.hands[hand].0.clone()].iter().map(|q| signed(&q.pose, &*q.surface)).fold(f32::INFINITY, f32::min);
        assert!(nearest > 0.0 && nearest < 1e-3, "stopped {nearest} m from the hand");
        assert!(signed(&tip_pose, &*p.shape) < 0.005, "not at the fingertip");
        // Away from the hand, or with the hand not placed, it goes all the way.
        colliders.set_pose(ball, Quat::IDENTITY, start);
        assert_eq!(colliders.free_share(ball, hand, &Pose::from_translation(start + along * 0.04), 0.0004), 1.0);
        colliders.move_hand(hand, None);
        assert_eq!(colliders.free_share(ball, hand, &towards, 0.0004), 1.0);
    }

    #[test]
    fn a_held_object_is_kept_on_the_table_top_only_over_the_table() {
        let scene = Scene::named("objects").unwrap();
        let colliders = ObjectColliders::new(&scene).unwrap();
        let table = colliders.table().unwrap();
        let ball = scene.objects.iter().position(|o| o.name == "ball").unwrap();
        let cube = scene.objects.iter().position(|o| o.name == "cube").unwrap();
        let over = Vec3::new(table.centre[0], table.height - 0.05, table.centre[1]);
        // A sphere of 4 cm rests with its centre 4 cm above the top, whatever its rotation.
        let raised = colliders.above_table(ball, Quat::from_rotation_x(1.0), over);
        assert!((raised.y - (table.height + 0.04)).abs() < 1e-5, "{raised}");
        // A 6 cm cube turned 45° about Z rests on an edge: √2 · 3 cm below its centre.
        let turned = colliders.above_table(cube, Quat::from_rotation_z(core::f32::consts::FRAC_PI_4), over);
        assert!((turned.y - (table.height + 0.03 * 2f32.sqrt())).abs() < 1e-4, "{turned}");
        // Above the top, or beside the table, it goes where the hand puts it.
        let high = over + Vec3::Y * 0.2;
        assert_eq!(colliders.above_table(ball, Quat::IDENTITY, high), high);
        let beside = Vec3::new(table.centre[0] + table.half[0] + 0.1, table.height - 0.05, table.centre[1]);
        assert_eq!(colliders.above_table(ball, Quat::IDENTITY, beside), beside);
    }

    /// A box's face-plane gap never exceeds parry's distance to the box (a lower bound, for
    /// every proxy of the hand, hull or capsule, at random poses round a turned cube), and
    /// matches it over the middle of a face.
    #[test]
    fn a_box_gap_is_a_lower_bound_exact_over_a_face() {
        let model = crate::hand::build(&crate::hand::HandParams::default()).expect("the built-in hand");
        let proxies = HandProxies::new(&super::super::fit_proxies(&model, super::super::PROXY_MARGIN), &model.skeleton);
        let surface = SharedShape::cuboid(0.3, 0.025, 0.2);
        let pose = Pose::from_parts(Vec3::new(0.1, 0.7, -0.2), Quat::from_rotation_y(0.4) * Quat::from_rotation_x(0.1));
        let aabb = surface.compute_aabb(&pose);
        let table = ObjectCollider { name: "box".to_owned(), solid: surface.clone(), surface, mesh: None, pose, aabb, triangles: None, hull_support: None };
        let mut rng = crate::math::Rng::new(7);
        let (mut over, mut checked) = (0, 0);
        for p in proxies.colliders() {
            for _ in 0..40 {
                let at = pose * (Vec3::new(rng.uniform(-0.45, 0.45) as f32, rng.uniform(-0.15, 0.15) as f32, rng.uniform(-0.3, 0.3) as f32));
                let proxy_pose = Pose::from_parts(at, Quat::from_scaled_axis(rng.normal_vec3()));
                let exact = query::distance(&proxy_pose, &*p.shape, &table.pose, &*table.surface).expect("convex shapes").distance;
                let gap = table.box_gap(&proxy_pose, p).expect("a box");
                assert!(gap <= exact + 1e-5, "joint {}: gap {gap} over the distance {exact}", p.joint);
                checked += 1;
            }
            // Above the middle of the top, clear of it: the gap is the distance.
            let proxy_pose = Pose::from_parts(pose * Vec3::new(0.0, 0.12, 0.0), Quat::from_scaled_axis(rng.normal_vec3()));
            let exact = query::distance(&proxy_pose, &*p.shape, &table.pose, &*table.surface).expect("convex shapes").distance;
            let gap = table.box_gap(&proxy_pose, p).expect("a box");
            if exact > 0.0 {
                assert!((gap - exact).abs() < 1e-4, "joint {}: gap {gap}, distance {exact}", p.joint);
                over += 1;
            }
        }
        assert!(checked > 500 && over >= 10, "{checked} poses, {over} over the top");
    }
}
