//! A hand's proxies queried against a triangle mesh: the nearest triangle (the finger stage's
//! distances and the contacts of [`super::ContactConstraint`] against a mesh object), and the
//! first time of impact of a proxy moving rigidly with the wrist (its wrist stage).
//!
//! The nearest triangle is a best-first search of the mesh's tree, each node bounded by the gap
//! between its box and the proxy's or the proxy's distance to the node's centre, each triangle
//! first by a cheap bound, then measured exactly (a capsule) or in centimetres (a hull,
//! [`UNIT`]): parry's own distance to a mesh runs GJK in metres, too long by up to 17 mm
//! against millimetre triangles. Where only a lower bound is asked above some distance, what
//! is nearly as near as the best found is passed over ([`SHORT_ABOVE`]). Each bound also
//! takes the plane square to the direction from the proxy to the nearest point found, in this
//! search or this proxy's last (`Placed::face`): nothing beyond it is nearer than its distance
//! from the proxy's reach along that direction, and no overlap is deeper than how far it
//! reaches past it. A palm lying on the teapot's millimetre triangles has dozens within a
//! millimetre inside its hull's box, which the box bound could not tell from the nearest and
//! GJK or EPA measured one by one (2–9 µs each); that plane tells most of them at a glance.
//!
//! The time of impact is conservative advancement (Mirtich 1996) over the triangles the proxy's
//! sweep can reach, each with its own lower bound of the distance: measured exactly at some
//! time, it falls no faster than the proxy closes on the plane through the nearest point
//! (square to the gap), which holds the triangle on its far side: the motion's speed along that
//! normal n plus what its turning ω adds (radius · |n × ω|); where they overlap, it deepens no
//! faster either, since they would have to part by no more than the depth along that normal.
//! The search jumps to the earliest time a bound can reach [`TOLERANCE`] (or a triangle left,
//! below, its floor) and measures only the triangles due then, so a proxy sliding along a
//! surface or moving away from it takes a few steps, where a bound from the proxy's whole speed
//! would creep. The triangles wait in a heap by when each is due, so a step costs its own
//! measurements, not a pass over the thousands in a palm's sweep (frames of 1–2 ms on the
//! teapot); a triangle due is first bounded again cheaply where the proxy now is, with the
//! plane of the nearest measured there, and measured only if that bound is due too. Only the
//! triangles within the proxy's reach over the motion are gathered, and none where the whole
//! mesh is farther than that (one search).
//!
//! It replaces parry's nonlinear composite cast for meshes, which advances each triangle under
//! the proxy on its own, with a stepping search for each one the proxy starts touching: 4–60 ms
//! frames on the teapot while the hand was held back on it. Here a triangle the proxy starts
//! touching (within [`TOLERANCE`]) stops it at once unless the motion takes the touching point
//! away from it; then it may not stop the proxy until the proxy is clear of it by [`REARM`]
//! (parry's "directional" cast: a finger resting on the lid may lift off it), but it still does
//! if the proxy goes deeper into it than it started (a roll that lifts one end of a finger lying
//! on it and sinks the other): it is measured again only when its bound can reach that floor, so
//! one that started in an overlap, rose clear and comes back in the same motion stops at that
//! depth, not at [`TOLERANCE`] (it never goes deeper than it started).

use glam::Vec3;
use parry3d::bounding_volume::Aabb;
use parry3d::math::Pose;
use parry3d::query::NonlinearRigidMotion;
use parry3d::query::epa::EPA;
use parry3d::query::gjk::{self, CsoPoint, GJKResult, VoronoiSimplex};
use parry3d::query::Contact;
use parry3d::shape::{Shape, SupportMap, Triangle};
use std::cell::Cell;
use std::collections::BinaryHeap;
use std::sync::Arc;

use super::hull_support::HullSupport;
use super::triangle_tree::{TreeNode, TreeTriangle, TriangleTree};
use super::HandProxies;
use crate::math::{segment_distance, segment_triangle_closest};

/// How far short of its distance to a mesh a proxy's lower bound may fall, as a share of what
/// the distance exceeds the exactness asked for by ([`ProxyMeshQuery::distance_at_least`]).
const SHORT_ABOVE: f32 = 0.1;
/// A distance this small is contact (m): where the advancement stops.
pub const TOLERANCE: f32 = 2e-5;
/// How far a proxy must get from a triangle it started touching and left before the triangle
/// can stop it again (m).
const REARM: f32 = 1e-4;
/// How far a capsule's axis must be from a triangle for the direction between them to be
/// trusted as the normal the advancement's bound falls along (m): their closest points are
/// rounded by about 1e-8 m, which turns it by 1e-4 rad here.
const PARTING: f32 = 1e-4;
/// Steps of the advancement that measure a triangle before it stops where it got (short of
/// any hit: conservative).
const MAX_STEPS: usize = 128;
/// How many times [`MAX_STEPS`] it may take in all, counting those that only bound triangles
/// again: a palm's sweep may have hundreds far off, each due at its own time and put off by
/// its bound there.
const BOUNDING_STEPS: usize = 16;
/// A triangle whose bound is within half a tolerance of the tolerance (of its floor, for one left)
/// is due (the bound reaches it at the step's time, up to rounding): bounded again where the
/// proxy is, and measured if that bound is due too.
const DUE: f32 = 1.5;

/// One triangle the sweep meets.
#[derive(Clone, Copy, Debug)]
struct Candidate {
    triangle: u32,
    /// A lower bound of the proxy's distance to it at time `at` (exact where measured).
    bound: f32,
    at: f32,
    /// How fast the bound falls after `at` (m per unit of time).
    rate: f32,
    /// Touched at the start by a motion leaving it: the distance it was touched at (m).
    left: Option<f32>,
}

impl Candidate {
    /// The distance at which it stops the proxy: the tolerance, or for one left, the depth it
    /// started at less the tolerance (it may not go deeper than it started).
    fn stops_at(&self) -> f32 {
        self.left.map_or(TOLERANCE, |start| start.min(0.0) - TOLERANCE)
    }

    /// Arms a triangle left again once its bound clears it by [`REARM`] (a bound under its
    /// distance, measured or not): then it stops the proxy at the tolerance.
    fn rearm(&mut self) {
        if self.left.is_some() && self.bound > REARM {
            self.left = None;
        }
    }

    /// The earliest time its bound can be down to `level` (earlier than `at` where it is
    /// already; infinite where it does not fall and is not).
    fn reaches(&self, level: f32) -> f32 {
        match self.bound <= level {
            _ if self.rate > 0.0 => self.at + (self.bound - level) / self.rate,
            true => f32::NEG_INFINITY,
            false => f32::INFINITY,
        }
    }

    /// The earliest time it can stop the proxy.
    fn stops_by(&self) -> f32 {
        self.reaches(self.stops_at())
    }

    /// From when it is measured again: its bound within [`DUE`] tolerances of its stop (the
    /// bound reaches the stop then, up to rounding); never where it does not fall that far.
    fn measured_from(&self) -> Option<f32> {
        Some(self.reaches(self.stops_at() + (DUE - 1.0) * TOLERANCE)).filter(|at| *at < f32::INFINITY)
    }
}

/// The point of a mesh nearest a proxy (world frame).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MeshNearest {
    /// The proxy's signed distance to it (m; negative where they overlap).
    pub distance: f32,
    /// The mesh's unit normal there, towards the proxy.
    pub normal: Vec3,
    /// The point on the mesh.
    pub point: Vec3,
}

/// The gap between two boxes (0 where they overlap): a lower bound of the distance between
/// anything inside them.
fn box_gap(a: &Aabb, b: &Aabb) -> f32 {
    (a.mins - b.maxs).max(b.mins - a.maxs).max(Vec3::ZERO).length()
}

/// A hand's proxies as the queries see them, and its buffers, kept between frames
/// (nothing is allocated per frame once they have grown).
#[derive(Clone)]
pub struct ProxyMeshQuery {
    /// Per proxy of the hand, in [`HandProxies::colliders`]' order.
    shapes: Vec<QueryShape>,
    /// Per proxy, the direction (its own frame) from it to the nearest point its searches last
    /// measured: a plane square to it bounds most triangles near that point at once.
    faced: Vec<Vec3>,
    epa: Scratch,
    advancement: Advancement,
}

/// The advancement's buffers, kept between queries.
#[derive(Clone, Default)]
struct Advancement {
    /// The triangles the sweep can reach.
    candidates: Vec<Candidate>,
    /// Each candidate not being measured, by the time it is due to be measured again.
    due: BinaryHeap<Due>,
    /// The candidates due at the step's time.
    batch: Vec<u32>,
}

/// A candidate (its index) due to be measured again at time `at`: ordered earliest first.
#[derive(Clone, Copy, Debug)]
struct Due {
    at: f32,
    candidate: u32,
}

impl PartialEq for Due {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other).is_eq()
    }
}

impl Eq for Due {}

impl PartialOrd for Due {
    fn partial_cmp(&self, other: &Self) -> Option<core::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for Due {
    /// Reversed: std's heap pops its largest, the advancement wants the earliest.
    fn cmp(&self, other: &Self) -> core::cmp::Ordering {
        other.at.total_cmp(&self.at).then(other.candidate.cmp(&self.candidate))
    }
}

/// parry's GJK, in f32 with tolerances fixed in absolute units, reports distances from a
/// convex shape to millimetre triangles in metres up to 17 mm too long (measured against exact
/// distances on the teapot: the test `parry_distance_to_small_triangles_needs_a_larger_unit`);
/// in centimetres it is within 0.05 mm. A hull proxy is queried there.
const UNIT: f32 = 100.0;
/// What parry's distance in [`UNIT`]s may still be too long by (m): taken off it, so that the
/// advancement never steps into a triangle.
const GJK_ERROR: f32 = 1e-4;

/// A proxy as the advancement queries it.
#[derive(Clone)]
enum QueryShape {
    /// A capsule's axis and radius (m, the joint's frame): distances are exact.
    Capsule { a: Vec3, b: Vec3, radius: f32 },
    /// Any other convex shape, scaled to [`UNIT`]s for parry's GJK, and its box in the joint's
    /// frame (m) for a cheap bound.
    Scaled(Convex, Aabb),
}

/// A convex shape's support function, in [`UNIT`]s.
#[derive(Clone)]
enum Convex {
    /// A hull's, by hill climbing ([`HullSupport`]).
    Hull(HullSupport),
    /// Any other's, parry's own.
    Other(Arc<dyn Shape>),
}

/// EPA's buffers, kept between queries (a new EPA allocates as it grows): a copy starts empty.
#[derive(Default)]
struct Scratch(EPA);

impl Clone for Scratch {
    fn clone(&self) -> Self {
        Self::default()
    }
}

impl Convex {
    /// The support function GJK asks.
    fn support(&self) -> &dyn SupportMap {
        match self {
            Self::Hull(hull) => hull,
            Self::Other(shape) => shape.as_support_map().expect("checked when made"),
        }
    }

    /// How far the shape reaches along the unit direction `n` (m, its own frame).
    fn reach(&self, n: Vec3) -> f32 {
        self.support().local_support_point_toward(n).dot(n) / UNIT
    }

    /// The closest points of the shape and `tri` (placed by `pos12` in the shape's frame), or
    /// their deepest overlap: parry's `query::contact` between two support maps, with `epa`'s
    /// buffers. `None` where EPA finds no answer (the shapes touch exactly).
    fn contact(&self, pos12: &Pose, tri: &Triangle, epa: &mut EPA) -> Option<Contact> {
        let support = self.support();
        let mut simplex = VoronoiSimplex::new();
        simplex.reset(CsoPoint::from_shapes(pos12, support, tri, pos12.translation.normalize_or(Vec3::X)));
        let closest = match gjk::closest_points(pos12, support, tri, f32::MAX, true, &mut simplex) {
            GJKResult::Intersection => epa.closest_points(pos12, support, tri, &simplex),
            GJKResult::ClosestPoints(p1, p2, n) => Some((p1, p2, n)),
            _ => None,
        };
        closest.map(|(point1, point2, normal1)| Contact::new(point1, pos12.inverse_transform_point(point2), normal1, pos12.rotation.inverse() * -normal1, (point2 - point1).dot(normal1)))
    }
}

/// The unit normal of `tri`'s plane (by its winding).
fn face_normal(tri: &Triangle) -> Vec3 {
    (tri.b - tri.a).cross(tri.c - tri.a).normalize_or_zero()
}

/// The unit normal of `tri`'s plane on the side of `x`.
fn face_normal_towards(tri: &Triangle, x: Vec3) -> Vec3 {
    let n = face_normal(tri);
    if (x - tri.a).dot(n) >= 0.0 { n } else { -n }
}

impl QueryShape {
    /// How `shape` is queried.
    ///
    /// # Panics
    /// For a shape that is not convex or that parry cannot scale: a hand's proxies are
    /// capsules and hulls ([`super::ProxyShape`]).
    fn of(shape: &dyn Shape) -> Self {
        if let Some(c) = shape.as_capsule() {
            return Self::Capsule { a: c.segment.a, b: c.segment.b, radius: c.radius };
        }
        let convex = match shape.as_convex_polyhedron() {
            Some(hull) => Convex::Hull(HullSupport::new(hull, UNIT)),
            None => Convex::Other(Arc::from(shape.scale_dyn(Vec3::splat(UNIT), 16).filter(|s| s.as_support_map().is_some()).expect("a convex proxy"))),
        };
        Self::Scaled(convex, shape.compute_local_aabb())
    }

    /// The box holding the proxy at `pose` (the mesh's frame).
    fn aabb(&self, pose: &Pose) -> Aabb {
        match self {
            Self::Capsule { a, b, radius } => {
                let (p, q) = (*pose * *a, *pose * *b);
                Aabb::new(p.min(q) - *radius, p.max(q) + *radius)
            }
            Self::Scaled(_, aabb) => aabb.transform_by(pose),
        }
    }

    /// The least signed distance it can have to anything: a node of the tree whose box meets
    /// the proxy's may hold a triangle this deep in it.
    fn deepest(&self) -> f32 {
        match self {
            Self::Capsule { radius, .. } => -radius,
            Self::Scaled(_, aabb) => -aabb.half_extents().length(),
        }
    }

    /// The proxy at `pose` (the mesh's frame), ready for the bounds of many nodes and
    /// triangles.
    fn at(&self, pose: Pose) -> Placed<'_> {
        let axis = match self {
            Self::Capsule { a, b, .. } => (pose * *a, pose * *b),
            Self::Scaled(..) => (pose.translation, pose.translation),
        };
        Placed { shape: self, pose, to_local: pose.inverse(), aabb: self.aabb(&pose), axis, reach: Cell::new((Vec3::ZERO, 0.0)) }
    }

    /// Whether a signed distance `distance` from [`Self::to_triangle`] came with a normal along
    /// which the shapes part by it (a capsule's axis crossing the triangle has none, and one
    /// nearly crossing it a normal rounding may turn: [`PARTING`]).
    fn parts_along_normal(&self, distance: f32) -> bool {
        match self {
            Self::Capsule { radius, .. } => distance > PARTING - radius,
            Self::Scaled(..) => true,
        }
    }

    /// The signed distance to `tri` (negative inside), the triangle's normal there towards the
    /// proxy, and the proxy's point nearest the triangle, all in the mesh's frame, at `pose`
    /// (a hull's overlaps through `epa`'s buffers).
    fn to_triangle(&self, pose: &Pose, tri: &Triangle, epa: &mut EPA) -> (f32, Vec3, Vec3) {
        match self {
            Self::Capsule { a, b, radius } => {
                let (p0, p1) = (*pose * *a, *pose * *b);
                let (p, q) = segment_triangle_closest(p0, p1, [tri.a, tri.b, tri.c]);
                let gap = p - q;
                let length = gap.length();
                let normal = if length > 1e-9 {
                    gap / length
                } else {
                    // The axis crosses the triangle: out on the side of the axis's farther end.
                    let n = face_normal(tri);
                    let far = if (p0 - q).dot(n).abs() > (p1 - q).dot(n).abs() { p0 } else { p1 };
                    face_normal_towards(tri, far)
                };
                (length - radius, normal, p - normal * *radius)
            }
            Self::Scaled(convex, _) => {
                let pose = Pose::from_parts(pose.translation * UNIT, pose.rotation);
                let tri = Triangle::new(tri.a * UNIT, tri.b * UNIT, tri.c * UNIT);
                let contact = convex.contact(&pose.inverse(), &tri, epa).map(|mut c| {
                    c.transform_by_mut(&pose, &Pose::identity());
                    c
                });
                match contact {
                    // parry gives no normal where the shapes touch exactly.
                    Some(c) if c.normal1 != Vec3::ZERO => (c.dist / UNIT - GJK_ERROR, -c.normal1, c.point1 / UNIT),
                    Some(c) => (c.dist / UNIT - GJK_ERROR, face_normal_towards(&tri, pose.translation), c.point1 / UNIT),
                    // No answer: touching, and not leaving (it stops the proxy, never lets it in).
                    None => (0.0, Vec3::ZERO, pose.translation / UNIT),
                }
            }
        }
    }
}

/// A proxy at a pose (the mesh's frame), with what each bound needs made once.
struct Placed<'a> {
    shape: &'a QueryShape,
    pose: Pose,
    /// The pose's inverse.
    to_local: Pose,
    /// The box holding it.
    aabb: Aabb,
    /// A capsule's axis (the mesh's frame).
    axis: (Vec3, Vec3),
    /// A unit direction (the mesh's frame) and how far the proxy reaches along it: no point
    /// beyond that plane is nearer than its distance to it.
    reach: Cell<(Vec3, f32)>,
}

impl Placed<'_> {
    /// Takes `u` (unit, the mesh's frame, from the proxy towards the mesh) as the direction
    /// of [`Self::along`].
    fn face(&self, u: Vec3) {
        // (Turned between frames and back, a remembered direction drifts off unit length.)
        let u = u.normalize_or_zero();
        if u == Vec3::ZERO {
            return;
        }
        let reach = match self.shape {
            QueryShape::Capsule { radius, .. } => self.axis.0.dot(u).max(self.axis.1.dot(u)) + radius,
            QueryShape::Scaled(convex, _) => convex.reach(self.to_local.rotation * u) + u.dot(self.pose.translation),
        };
        self.reach.set((u, reach));
    }

    /// A lower bound of the signed distance to anything whose least extent along the faced
    /// direction is `least`: how far past the proxy's reach it is (no overlap can be deeper
    /// either: the shapes would have to part by that much along it).
    fn along(&self, least: impl FnOnce(Vec3) -> f32) -> f32 {
        let (u, reach) = self.reach.get();
        if u == Vec3::ZERO {
            return f32::NEG_INFINITY;
        }
        let short = if matches!(self.shape, QueryShape::Scaled(..)) { GJK_ERROR } else { 1e-6 };
        least(u) - reach - short
    }

    /// A lower bound of the distance to anything in the tree's node `node`: the gap between
    /// the boxes, or where larger (a slanted finger's box holds much that the finger is far
    /// from) the proxy's distance to the node's centre less the node's half diagonal.
    fn node_gap(&self, node: &TreeNode) -> f32 {
        let boxes = box_gap(&node.aabb, &self.aabb);
        let centre_gap = match self.shape {
            QueryShape::Capsule { radius, .. } => segment_distance(node.centre, self.axis.0, self.axis.1) - radius,
            QueryShape::Scaled(_, local) => {
                let c = self.to_local * node.centre;
                (local.mins - c).max(c - local.maxs).max(Vec3::ZERO).length()
            }
        } - node.radius;
        let along = self.along(|u| u.dot(node.centre) - node.aabb.half_extents().dot(u.abs()));
        if boxes > 0.0 || centre_gap > 0.0 { boxes.max(centre_gap).max(along) } else { self.shape.deepest().max(along) }
    }

    /// A lower bound of the distance to `tri`, far cheaper than the distance: for a capsule,
    /// the larger of its axis's distance to the triangle's bounding sphere and to the
    /// triangle's plane; for a hull, the larger of the gap between its box and the triangle's
    /// box in the joint's frame and the gap along the triangle's normal.
    fn bound(&self, tri: &TreeTriangle) -> f32 {
        let t = &tri.triangle;
        let faced = self.along(|u| u.dot(t.a).min(u.dot(t.b)).min(u.dot(t.c)));
        match self.shape {
            QueryShape::Capsule { radius, .. } => {
                let (p, q) = self.axis;
                // A small triangle is no nearer than its centroid less its vertices' reach (a
                // finger lying on a mesh has hundreds of triangles within its length), a large
                // one no nearer than its plane when the axis is on one side of it.
                let (n, a) = (tri.normal, tri.triangle.a);
                let (dp, dq) = ((p - a).dot(n), (q - a).dot(n));
                let plane = if dp * dq > 0.0 { dp.abs().min(dq.abs()) } else { 0.0 };
                ((segment_distance(tri.centroid, p, q) - tri.spread).max(plane) - radius).max(faced)
            }
            QueryShape::Scaled(_, aabb) => {
                let [a, b, c] = [self.to_local * t.a, self.to_local * t.b, self.to_local * t.c];
                let (lo, hi) = (a.min(b).min(c), a.max(b).max(c));
                let boxes = (aabb.mins - hi).max(lo - aabb.maxs).max(Vec3::ZERO).length();
                let n = self.to_local.rotation * tri.normal;
                let reach = (aabb.half_extents() * n.abs()).element_sum();
                let along = (a - aabb.center()).dot(n).abs() - reach;
                // Where both gaps close the hull may overlap the triangle: as deep as it can,
                // or as the faced plane allows.
                let gap = boxes.max(along);
                if gap > 0.0 { gap.max(faced) } else { self.shape.deepest().max(faced) }
            }
        }
    }
}

impl ProxyMeshQuery {
    /// The advancement for `proxies`.
    #[must_use]
    pub fn new(proxies: &HandProxies) -> Self {
        let shapes: Vec<QueryShape> = proxies.colliders().iter().map(|p| QueryShape::of(&*p.shape)).collect();
        Self { faced: vec![Vec3::ZERO; shapes.len()], shapes, epa: Scratch::default(), advancement: Advancement::default() }
    }

    /// The point of `mesh` (at `mesh_pose`) nearest proxy `proxy` (at `pose`), if it is nearer
    /// than `limit` (m).
    #[must_use]
    pub fn nearest(&mut self, proxy: usize, pose: &Pose, mesh: &TriangleTree, mesh_pose: &Pose, limit: f32) -> Option<MeshNearest> {
        let query = &self.shapes[proxy];
        let local = mesh_pose.inv_mul(pose);
        let near = Self::search(query, &mut self.faced[proxy], &mut self.epa.0, &local, mesh, limit, f32::INFINITY, 0.0)?;
        Some(MeshNearest { distance: near.distance, normal: mesh_pose.rotation * near.normal, point: *mesh_pose * near.point })
    }

    /// A lower bound of the distance from proxy `proxy` (at `pose`) to `mesh` (at
    /// `mesh_pose`), exact where it is under `exact_below`, and at most `limit` (m): what
    /// conservative advancement needs, where a triangle whose cheap bound is enough is never
    /// measured (a finger a centimetre off a mesh has dozens of triangles about as near).
    /// Above `exact_below` the search also passes over what is within [`SHORT_ABOVE`] of the
    /// excess of being the nearest: a finger lying a centimetre along a curved mesh has
    /// hundreds of triangles within a millimetre of its distance, which it need not tell apart.
    #[allow(clippy::too_many_arguments)]
    #[must_use]
    pub fn distance_at_least(&mut self, proxy: usize, pose: &Pose, mesh: &TriangleTree, mesh_pose: &Pose, exact_below: f32, limit: f32) -> f32 {
        let query = &self.shapes[proxy];
        // Nothing found within the limit: what was passed over may be a little nearer.
        let passed_over = limit - SHORT_ABOVE * (limit - exact_below).max(0.0);
        Self::search(query, &mut self.faced[proxy], &mut self.epa.0, &mesh_pose.inv_mul(pose), mesh, limit, exact_below, SHORT_ABOVE).map_or(passed_over, |n| n.distance)
    }

    /// The best-first search of the mesh's tree for the triangle nearest `query` at `pose` (the
    /// mesh's frame) within `limit` (the deepest, where it overlaps several); a triangle whose
    /// cheap bound is above `exact_below` counts as that far (with no normal or point). With
    /// `short` above 0, the distance found may be short of the true one by that share of its
    /// excess over `exact_below`: what is no nearer than that is not looked at. `faced` is the
    /// proxy's remembered direction (its frame), which the search takes and leaves updated;
    /// `epa`, the buffers of the hull queries.
    fn search(query: &QueryShape, faced: &mut Vec3, epa: &mut EPA, pose: &Pose, mesh: &TriangleTree, limit: f32, exact_below: f32, short: f32) -> Option<MeshNearest> {
        let placed = query.at(*pose);
        if *faced != Vec3::ZERO {
            placed.face(pose.rotation * *faced);
        }
        // What can still count, with `best` found: rising with `best`, so that it holds for
        // everything passed over on the way to the final `best`.
        let worth = |best: f32| best - short * (best - exact_below).max(0.0);
        let nearest = mesh.find_best(
            limit,
            |node| placed.node_gap(node),
            |tri, best| {
                // The cheap bound first: most triangles near the proxy are not the nearest.
                let bound = placed.bound(tri);
                if bound >= worth(best) {
                    return None;
                }
                if bound > exact_below {
                    return Some((bound, (Vec3::ZERO, Vec3::ZERO)));
                }
                let (distance, normal, point) = query.to_triangle(pose, &tri.triangle, epa);
                if distance < best && normal != Vec3::ZERO {
                    placed.face(-normal);
                }
                Some((distance, (normal, point - normal * distance)))
            },
            worth,
        );
        *faced = placed.to_local.rotation * placed.reach.get().0;
        nearest.map(|(distance, (normal, point))| MeshNearest { distance: worth(distance), normal, point })
    }

    /// The first time in `[0, end)` at which proxy `proxy`, moving by `motion`, comes within
    /// [`TOLERANCE`] of `mesh` (still at `mesh_pose`), if any. No point of the proxy is farther
    /// than `radius` from the motion's centre; `swept` (world) holds the proxy over the whole
    /// motion.
    #[allow(clippy::too_many_arguments)]
    pub fn time_of_impact(&mut self, proxy: usize, motion: &NonlinearRigidMotion, radius: f32, swept: &Aabb, mesh: &TriangleTree, mesh_pose: &Pose, end: f32) -> Option<f32> {
        let cast = &self.shapes[proxy];
        // How fast a point of the proxy may move, m per unit of time: all told, and by turning.
        let turning = motion.angvel.length() * radius;
        let speed = motion.linvel.length() + turning;
        if speed <= 0.0 {
            return None;
        }
        let local_pose = |t: f32| mesh_pose.inv_mul(&motion.position_at_time(t));
        let start = local_pose(0.0);
        let pivot = motion.start * motion.local_center;
        // How fast the proxy's point `x` (world) moves along `n`: into a surface of normal `n`
        // where negative.
        let along = |x: Vec3, n: Vec3| (motion.linvel + motion.angvel.cross(x - pivot)).dot(n);
        // Touching at the start and moving into it (as below): stopped at once, before the
        // sweep's triangles are gathered (hundreds, while the hand is held back on the teapot).
        // The search takes a copy of the proxy's faced direction: later searches are as before.
        let mut faced = self.faced[proxy];
        if let Some(n) = Self::search(cast, &mut faced, &mut self.epa.0, &start, mesh, TOLERANCE, TOLERANCE, 0.0) {
            let (normal, at) = (mesh_pose.rotation * n.normal, *mesh_pose * (n.point + n.normal * n.distance));
            // (Into it clearly: the point is rebuilt from the mesh's, a little off, so a motion
            // along the surface is left to the full test.)
            if n.distance <= TOLERANCE && (normal == Vec3::ZERO || along(at, normal) < -1e-6 * speed) {
                return Some(0.0);
            }
        }
        // How fast the proxy closes on a plane of unit normal `n` (the mesh's frame, towards
        // the proxy): its motion's speed against `n`, plus what turning adds (a point at most
        // `radius` from the centre turning by ω moves along `n` by at most radius |n × ω|).
        let closing = |n: Vec3| {
            let n = mesh_pose.rotation * n;
            (radius * n.cross(motion.angvel).length() - motion.linvel.dot(n)).clamp(0.0, speed)
        };
        // No point of the proxy gets farther than this from where it starts (and a tolerance
        // and a half).
        let reach = speed * end + DUE * TOLERANCE;
        // The whole mesh farther than that from the start by the triangles' cheap bounds (one
        // search that measures none, exact below −1 m, where the sweep's box may hold
        // thousands): nothing is hit.
        Self::search(cast, &mut faced, &mut self.epa.0, &start, mesh, reach, -1.0, 0.0)?;
        // The triangles the sweep may reach: in its box, and no farther from the proxy at the
        // start than that (by the bounds of the tree's nodes and their own, with the plane the
        // search faced).
        let placed = cast.at(start);
        placed.face(start.rotation * faced);
        let Advancement { candidates, due, batch } = &mut self.advancement;
        candidates.clear();
        mesh.overlapping(&swept.transform_by(&mesh_pose.inverse()), |node| placed.node_gap(node) <= reach, |triangle| {
            let bound = placed.bound(&mesh.triangles()[triangle as usize]);
            if bound <= reach {
                candidates.push(Candidate { triangle, bound, at: 0.0, rate: speed, left: None });
            }
        });
        // Nearest first (the earliest due): a contact at the start is then found after few
        // exact distances.
        due.clear();
        due.extend(candidates.iter().enumerate().filter_map(|(k, c)| c.measured_from().map(|at| Due { at, candidate: k as u32 })));
        let mut t = 0.0;
        batch.clear();
        while let Some(d) = due.peek().filter(|d| d.at <= 0.0) {
            batch.push(d.candidate);
            due.pop();
        }
        // Steps that measured a triangle (a step that only bounded some again costs little).
        let mut measuring = 0;
        for _ in 0..MAX_STEPS * BOUNDING_STEPS {
            let pose = if t == 0.0 { start } else { local_pose(t) };
            let placed = cast.at(pose);
            let (mut nearest, mut measured) = (f32::INFINITY, false);
            for &k in batch.iter() {
                let c = &mut candidates[k as usize];
                let tri = &mesh.triangles()[c.triangle as usize];
                if t > 0.0 {
                    // Its cheap bound here first, with the plane of the nearest measured in
                    // this step: what that puts off is not measured (hundreds of triangles whose
                    // bounds from the start ran out, most of them far, or behind that plane).
                    let mut cheap = Candidate { bound: placed.bound(tri), at: t, rate: speed, ..*c };
                    cheap.rearm();
                    if let Some(at) = cheap.measured_from().filter(|&at| at > t) {
                        *c = cheap;
                        due.push(Due { at, candidate: k });
                        continue;
                    }
                }
                let (distance, normal, point) = cast.to_triangle(&pose, &tri.triangle, &mut self.epa.0);
                measured = true;
                if distance < nearest && normal != Vec3::ZERO {
                    nearest = distance;
                    placed.face(-normal);
                }
                (c.bound, c.at) = (distance, t);
                let (n, x) = (mesh_pose.rotation * normal, *mesh_pose * point);
                if t == 0.0 && distance <= TOLERANCE && n != Vec3::ZERO {
                    // Its touching point moves off it: a proxy may leave what it rests on.
                    c.left = (along(x, n) >= 0.0).then_some(distance);
                }
                // The plane through its nearest point, square to `n`, holds the triangle on
                // its far side; the proxy closes on that plane no faster than this. Where
                // they overlap, by no more than they would have to part along `n`, which
                // grows no faster (where a capsule's axis crosses the triangle, or the query
                // gave no normal, there is no such direction: the whole speed).
                c.rate = if n != Vec3::ZERO && cast.parts_along_normal(distance) { closing(normal) } else { speed };
                // A triangle left may not stop the proxy unless it goes deeper than it started
                // (a turn can lift the touching point and sink another end of the proxy): its
                // floor is what matters then, not the tolerance, until it is clear by REARM.
                c.rearm();
                if distance <= c.stops_at() {
                    return Some(t);
                }
                if let Some(at) = c.measured_from() {
                    due.push(Due { at, candidate: k });
                }
            }
            // The next step: the earliest time a bound can come down to its stop, and every
            // triangle due by then (taken off in the order they fall due: none later can be
            // earlier).
            let mut next = f32::INFINITY;
            batch.clear();
            while let Some(d) = due.peek().filter(|d| d.at <= next) {
                let k = d.candidate;
                due.pop();
                next = next.min(candidates[k as usize].stops_by());
                batch.push(k);
            }
            if next >= end {
                return None;
            }
            t = next;
            measuring += usize::from(measured);
            if measuring == MAX_STEPS {
                break;
            }
        }
        Some(t)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use parry3d::bounding_volume::BoundingVolume;
    use parry3d::shape::SharedShape;
    use crate::math::triangle_closest;

    /// A flat square of two triangles, 20 cm across, in the plane y = 0.
    fn floor() -> TriangleTree {
        let v = [Vec3::new(-0.1, 0.0, -0.1), Vec3::new(0.1, 0.0, -0.1), Vec3::new(0.1, 0.0, 0.1), Vec3::new(-0.1, 0.0, 0.1)];
        TriangleTree::new(&v, &[[0, 2, 1], [0, 3, 2]])
    }

    fn cast(shape: &SharedShape, from: Vec3, linvel: Vec3, angvel: Vec3) -> Option<f32> {
        let mut cast = query_of(std::slice::from_ref(shape));
        let start = Pose::from_translation(from);
        let motion = NonlinearRigidMotion::new(start, Vec3::ZERO, linvel, angvel);
        let extent = shape.compute_local_bounding_sphere().radius;
        let to = motion.position_at_time(1.0);
        let swept = shape.compute_swept_aabb(&start, &to).loosened(extent * angvel.length());
        cast.time_of_impact(0, &motion, extent, &swept, &floor(), &Pose::identity(), 1.0)
    }

    #[test]
    fn a_falling_capsule_stops_where_its_lowest_point_meets_the_floor() {
        // Lying along x, 1 cm radius, its axis 5 cm up, falling 10 cm: contact at 4 cm of 10.
        let capsule = SharedShape::capsule(Vec3::new(-0.02, 0.0, 0.0), Vec3::new(0.02, 0.0, 0.0), 0.01);
        let t = cast(&capsule, Vec3::new(0.0, 0.05, 0.0), Vec3::new(0.0, -0.1, 0.0), Vec3::ZERO).expect("it hits");
        assert!((t - 0.4).abs() < 1e-3, "{t}");
        // Falling 3 cm only, it does not reach the floor.
        assert!(cast(&capsule, Vec3::new(0.0, 0.05, 0.0), Vec3::new(0.0, -0.03, 0.0), Vec3::ZERO).is_none());
    }

    #[test]
    fn a_turning_capsule_stops_when_its_end_swings_down_to_the_floor() {
        // Upright (4 cm axis, 1 cm radius), its lowest point 2 mm above the floor, turned by 90°
        // about its centre: its lowest point only rises. Lowered by 2.5 cm as it turns, it hits
        // when the lowest point, 1 cm + 2 cm·|cos θ| under the centre, reaches the floor.
        let capsule = SharedShape::capsule(Vec3::new(0.0, -0.02, 0.0), Vec3::new(0.0, 0.02, 0.0), 0.01);
        let from = Vec3::new(0.0, 0.032, 0.0);
        assert!(cast(&capsule, from, Vec3::ZERO, Vec3::new(0.0, 0.0, core::f32::consts::FRAC_PI_2)).is_none());
        let t = cast(&capsule, from, Vec3::new(0.0, -0.025, 0.0), Vec3::new(0.0, 0.0, core::f32::consts::FRAC_PI_2)).expect("it hits");
        let (height, angle) = (0.032 - 0.025 * t, core::f32::consts::FRAC_PI_2 * t);
        let lowest = height - 0.01 - 0.02 * angle.cos().abs();
        assert!(lowest.abs() < 1e-4 && lowest > -1e-5, "t {t}, lowest point at {lowest}");
    }

    #[test]
    fn a_proxy_touching_the_floor_is_stopped_going_down_and_free_going_up() {
        let capsule = SharedShape::capsule(Vec3::new(-0.02, 0.0, 0.0), Vec3::new(0.02, 0.0, 0.0), 0.01);
        let touching = Vec3::new(0.0, 0.01, 0.0);
        assert_eq!(cast(&capsule, touching, Vec3::new(0.0, -0.05, 0.0), Vec3::ZERO), Some(0.0));
        assert!(cast(&capsule, touching, Vec3::new(0.0, 0.05, 0.0), Vec3::ZERO).is_none());
        // A convex hull proxy (parry's contact) the same way: a 2 cm cube resting on the floor.
        let cube = SharedShape::cuboid(0.01, 0.01, 0.01);
        assert_eq!(cast(&cube, touching, Vec3::new(0.0, -0.05, 0.0), Vec3::ZERO), Some(0.0));
        assert!(cast(&cube, touching, Vec3::new(0.02, 0.05, 0.0), Vec3::ZERO).is_none());
        // It stops short by at most what parry's distance may be off by, never past the floor.
        let t = cast(&cube, Vec3::new(0.0, 0.03, 0.0), Vec3::new(0.0, -0.04, 0.0), Vec3::ZERO).expect("it hits");
        assert!(t <= 0.5 && (0.5 - t) * 0.04 <= GJK_ERROR + 2.0 * TOLERANCE, "{t}");
    }

    #[test]
    fn a_capsule_lying_on_the_floor_and_rolled_end_over_end_stops_as_its_far_end_sinks() {
        // Lying along z on the floor, turned about x through its centre: one end rises (the
        // touching point found first may be there), the other sinks. It must stop at once.
        let capsule = SharedShape::capsule(Vec3::new(0.0, 0.0, -0.02), Vec3::new(0.0, 0.0, 0.02), 0.01);
        for turn in [1.0, -1.0] {
            let t = cast(&capsule, Vec3::new(0.05, 0.01, 0.0), Vec3::ZERO, Vec3::new(turn, 0.0, 0.0));
            // At most a few steps in: the sinking end goes no deeper than the tolerance.
            let t = t.expect("it stops");
            assert!(0.02 * (t).sin() <= 2.0 * TOLERANCE, "turned {t} rad before stopping");
        }
    }

    #[test]
    fn a_hull_sunk_into_the_floor_slides_and_lifts_freely_and_stops_as_it_tips_deeper() {
        // A 2 cm cube 1 mm into the floor (an object pressed into a palm, the other way round).
        let cube = SharedShape::cuboid(0.01, 0.01, 0.01);
        let sunk = Vec3::new(0.0, 0.009, 0.0);
        // Along the floor it goes no deeper, and lifted it comes out: neither stops it.
        assert!(cast(&cube, sunk, Vec3::new(0.05, 0.0, 0.0), Vec3::ZERO).is_none());
        assert!(cast(&cube, sunk, Vec3::new(0.01, 0.03, 0.0), Vec3::ZERO).is_none());
        // Pushed down, it stops at once.
        assert_eq!(cast(&cube, sunk, Vec3::new(0.0, -0.02, 0.0), Vec3::ZERO), Some(0.0));
        // Tipped about z, one bottom edge rises and the other sinks at once: it stops before
        // that edge is deeper than the cube started by more than the advancement's slack
        // (measured again only as its bound reaches the depth it started at).
        for turn in [0.5, -0.5] {
            let t = cast(&cube, sunk, Vec3::ZERO, Vec3::new(0.0, 0.0, turn)).expect("it stops");
            let angle = turn * t;
            let lowest = 0.009 - 0.01 * (angle.cos() + angle.sin().abs());
            assert!(lowest >= -0.001 - GJK_ERROR - 2.0 * DUE * TOLERANCE, "turned {angle} rad, lowest point at {lowest}");
        }
    }

    /// The Utah teapot's triangles (data from outside the project), at the size the built-in
    /// scenes give it (scale 0.6: about 25 cm across, triangles of millimetres).
    fn teapot_triangles() -> Vec<Triangle> {
        let mesh = crate::scene::ObjectMesh::builtin("objects/teapot.obj").expect("the built-in teapot");
        let v = |i: u32| mesh.vertices[i as usize] * 0.6;
        mesh.triangles.iter().map(|t| Triangle::new(v(t[0]), v(t[1]), v(t[2]))).collect()
    }

    /// The tree of `triangles`, each with corners of its own.
    fn tree_of(triangles: &[Triangle]) -> TriangleTree {
        let corners: Vec<Vec3> = triangles.iter().flat_map(|t| [t.a, t.b, t.c]).collect();
        TriangleTree::new(&corners, &(0..triangles.len() as u32).map(|i| [3 * i, 3 * i + 1, 3 * i + 2]).collect::<Vec<_>>())
    }

    /// The hull (points, triangles) of the box of half extents `half` about the origin.
    fn box_hull(half: Vec3) -> (Vec<Vec3>, Vec<[u32; 3]>) {
        let corners: Vec<Vec3> = (0..8).map(|i| Vec3::new(if i & 1 == 0 { -half.x } else { half.x }, if i & 2 == 0 { -half.y } else { half.y }, if i & 4 == 0 { -half.z } else { half.z })).collect();
        parry3d::transformation::try_convex_hull(&corners).expect("a box's hull")
    }

    /// The queries of `shapes`, in order, with nothing remembered.
    fn query_of(shapes: &[SharedShape]) -> ProxyMeshQuery {
        ProxyMeshQuery { shapes: shapes.iter().map(|s| QueryShape::of(&**s)).collect(), faced: vec![Vec3::ZERO; shapes.len()], epa: Scratch::default(), advancement: Advancement::default() }
    }

    #[test]
    fn the_nearest_triangle_is_the_nearest_of_all() {
        // A finger-sized capsule and a palm-sized box around the teapot, up to 3 cm off: the
        // tree search must find what trying every triangle finds (the reference: the closest
        // points of the segment and each triangle, by brute force, no tree and no bound), and
        // the advancement's bound must never be above it and be it below `exact_below`.
        let triangles = teapot_triangles();
        let mesh = tree_of(&triangles);
        let (a, b, radius) = (Vec3::new(0.0, -0.02, 0.0), Vec3::new(0.0, 0.02, 0.0), 0.008);
        let shapes = [SharedShape::capsule(a, b, radius), SharedShape::cuboid(0.04, 0.01, 0.03)];
        let mut query = query_of(&shapes);
        let mesh_pose = Pose::from_parts(Vec3::new(0.3, 0.8, -0.2), glam::Quat::from_rotation_y(0.7));
        let (box_points, box_triangles) = box_hull(Vec3::new(0.04, 0.01, 0.03));
        let box_reach = Vec3::new(0.04, 0.01, 0.03).length();
        let (mut checked, mut touching, mut boxes, mut overlaps) = (0, 0, 0, 0);
        for (k, tri) in triangles.iter().enumerate().step_by(23) {
            let centre = (tri.a + tri.b + tri.c) / 3.0;
            let off = -0.004 + 0.034 * (k % 17) as f32 / 16.0;
            let local = Pose::from_parts(centre + face_normal(tri) * (off + radius), glam::Quat::from_rotation_x(k as f32 * 0.37) * glam::Quat::from_rotation_z(k as f32 * 0.11));
            let pose = mesh_pose * local;
            // The capsule, exactly: the reference tries every triangle with the closest points
            // of segment and triangle (themselves tested against dense sampling in `math`).
            let (p0, p1) = (local * a, local * b);
            let brute = triangles.iter().map(|t| {
                let (p, q) = segment_triangle_closest(p0, p1, [t.a, t.b, t.c]);
                p.distance(q) - radius
            });
            let reference = brute.fold(f32::INFINITY, f32::min);
            let found = query.nearest(0, &pose, &mesh, &mesh_pose, 0.05);
            match found {
                Some(n) => {
                    assert!((n.distance - reference).abs() < 1e-6, "nearest {} where every triangle gives {reference}", n.distance);
                    // Its point is on the mesh, that far from the capsule, along its normal.
                    let on_axis = crate::math::segment_closest(mesh_pose.inverse() * n.point, p0, p1);
                    assert!((on_axis.distance(mesh_pose.inverse() * n.point) - radius - n.distance).abs() < 1e-5);
                    assert!((n.normal.length() - 1.0).abs() < 1e-5);
                    touching += usize::from(n.distance <= 0.002);
                }
                None => assert!(reference >= 0.05, "nothing found within 5 cm where a triangle is {reference} m off"),
            }
            let bound = query.distance_at_least(0, &pose, &mesh, &mesh_pose, 0.002, 0.03);
            assert!(bound <= reference + 1e-6 && bound <= 0.03, "bound {bound} above the distance {reference}");
            if reference < 0.002 {
                assert!((bound - reference).abs() < 1e-6, "bound {bound} not exact at {reference}");
            }
            // The box, through parry in centimetres less its error: never farther than the
            // exact distance (polyhedron and triangle, from the definition), at most 0.2 mm
            // nearer.
            let mut by_centre: Vec<(f32, &Triangle)> = triangles.iter().map(|t| (triangle_closest(local.translation, [t.a, t.b, t.c]).distance(local.translation) - box_reach, t)).collect();
            by_centre.sort_by(|x, y| x.0.total_cmp(&y.0));
            // Every triangle that may be nearest (or deepest): the exact distance, and the
            // query's own per-triangle value, the least of which the tree search must find.
            let (mut exact_box, mut each_box) = (f32::INFINITY, f32::INFINITY);
            for (no_nearer, t) in by_centre {
                if no_nearer > exact_box.max(each_box) + 0.002 {
                    break;
                }
                exact_box = exact_box.min(polyhedron_triangle(&box_points, &box_triangles, &local, t));
                each_box = each_box.min(query.shapes[1].to_triangle(&local, t, &mut EPA::new()).0);
            }
            let found = query.nearest(1, &pose, &mesh, &mesh_pose, 0.05);
            assert!(exact_box >= 0.05 || found.is_some(), "no box contact where a triangle is {exact_box} m off");
            if let Some(n) = found {
                // The search finds the least of the triangles' values (the deepest overlap too), up
                // to what a triangle's box bound may exceed its value by (parry's distance in
                // units less its error is below the true distance, which the bound is under).
                assert!(n.distance >= each_box - 1e-6 && n.distance <= each_box + 2.0 * GJK_ERROR, "box: the search found {} where the least is {each_box}", n.distance);
                // (The reference says 0 for any overlap, the query how deep.)
                let deeper = if exact_box > 0.0 { exact_box - 2.0 * GJK_ERROR } else { f32::NEG_INFINITY };
                assert!(n.distance <= exact_box + 1e-6 && n.distance >= deeper, "box: {} where exactly {exact_box}", n.distance);
                boxes += usize::from(exact_box > 0.0);
                overlaps += usize::from(exact_box == 0.0);
            }
            checked += 1;
        }
        assert!(checked > 20 && touching > 3 && boxes > 10 && overlaps > 0, "{checked} poses, {touching} within 2 mm, {boxes} boxes clear, {overlaps} overlapping");
    }

    /// A capsule (a finger's) and a hull (a palm-sized box) swept past, into and away from the
    /// Utah teapot (data from outside the project), turning as they go (some about a wrist
    /// 10 cm off, as the wrist stage turns its proxies): the advancement must
    /// stop no later than the first contact and at it (within the tolerance, the hull's
    /// within parry's error), and find none only where there is none. The reference samples
    /// each motion at 200 times and measures exactly every triangle whose box the motion may
    /// reach and whose bounding sphere is near enough to matter (the closest points of segment
    /// and triangle; the polyhedron's from its faces and edges): no tree, no bound and no
    /// advancement.
    #[test]
    fn a_sweep_past_the_teapot_stops_at_its_first_contact() {
        const SAMPLES: usize = 200;
        let triangles = teapot_triangles();
        let mesh = tree_of(&triangles);
        let (a, b, radius) = (Vec3::new(0.0, -0.02, 0.0), Vec3::new(0.0, 0.02, 0.0), 0.008);
        let half = Vec3::new(0.04, 0.01, 0.03);
        let (box_points, box_triangles) = box_hull(half);
        let shapes = [SharedShape::capsule(a, b, radius), SharedShape::convex_mesh(box_points.clone(), &box_triangles).expect("a hull")];
        let mut query = query_of(&shapes);
        let (mut hits, mut misses) = ([0; 2], [0; 2]);
        for (case, (k, tri)) in triangles.iter().enumerate().step_by(151).enumerate() {
            let proxy = case / 3 % 2;
            let extent = shapes[proxy].compute_local_bounding_sphere().radius;
            let centre = (tri.a + tri.b + tri.c) / 3.0;
            let n = face_normal(tri);
            let side = n.any_orthonormal_vector();
            // 5–20 mm off its surface, moved 3 cm: into it, past it, or off it, and turned.
            let off = 0.005 + 0.015 * (k % 7) as f32 / 6.0;
            let linvel = [-n * 0.03, side * 0.03 - n * 0.006, n * 0.03 + side * 0.01][case % 3];
            let angvel = Vec3::new(0.3, -0.2, 0.5) * ((k % 5) as f32 - 2.0) * 0.4;
            // (The box lies along the surface, its thin side towards it.)
            let turn = [glam::Quat::from_rotation_x(k as f32 * 0.37), glam::Quat::from_rotation_arc(Vec3::Y, n) * glam::Quat::from_rotation_y(k as f32 * 0.37)][proxy];
            let start = Pose::from_parts(centre + n * (off + [extent, half.y][proxy]), turn);
            // Every fourth turns about a wrist 10 cm off (its own frame), slower, as the wrist
            // stage's proxies do.
            let (pivot, angvel) = if case % 4 == 3 { (Vec3::new(0.0, 0.0, -0.1), angvel * 0.2) } else { (Vec3::ZERO, angvel) };
            let reach = pivot.length() + extent;
            let motion = NonlinearRigidMotion::new(start, pivot, linvel, angvel);
            let swept = shapes[proxy].compute_swept_aabb(&start, &motion.position_at_time(1.0)).loosened(reach * angvel.length());
            let found = query.time_of_impact(proxy, &motion, reach, &swept, &mesh, &Pose::identity(), 1.0);
            // The reference: every triangle the motion's box may reach, measured exactly where
            // its bounding sphere is within `below` of the proxy's (the least, or `below`).
            let near: Vec<(&Triangle, Vec3, f32)> = triangles
                .iter()
                .filter(|t| t.local_aabb().intersects(&swept))
                .map(|t| {
                    let centroid = (t.a + t.b + t.c) / 3.0;
                    (t, centroid, [t.a, t.b, t.c].iter().map(|v| v.distance(centroid)).fold(0.0, f32::max))
                })
                .collect();
            let distance = |t: f32, below: f32| {
                let pose = motion.position_at_time(t);
                near.iter()
                    .filter(|(_, centroid, spread)| match proxy {
                        0 => crate::math::segment_distance(*centroid, pose * a, pose * b) - spread - radius < below,
                        _ => centroid.distance(pose.translation) - spread - half.length() < below,
                    })
                    .map(|(tri, _, _)| match proxy {
                        0 => {
                            let (p, q) = segment_triangle_closest(pose * a, pose * b, [tri.a, tri.b, tri.c]);
                            p.distance(q) - radius
                        }
                        _ => polyhedron_triangle(&box_points, &box_triangles, &pose, tri),
                    })
                    .fold(below, f32::min)
            };
            // (A start in the teapot's other parts, or its winding turned in, is no sweep.)
            if distance(0.0, 0.002) < 0.002 {
                continue;
            }
            let first = (0..=SAMPLES).map(|i| i as f32 / SAMPLES as f32).find(|&t| distance(t, 2.0 * TOLERANCE) <= TOLERANCE);
            // (The box's distances are parry's in units, which may be short by its error.)
            let slack = if proxy == 0 { 1e-6 } else { 2.0 * GJK_ERROR };
            match found {
                Some(t) => {
                    let there = distance(t, f32::INFINITY);
                    assert!(there >= TOLERANCE - 2e-6 && there <= 2.0 * TOLERANCE + slack, "proxy {proxy} by triangle {k}: stopped at {t}, {there} m from the teapot");
                    assert!(first.is_none_or(|f| t <= f + 1e-6), "proxy {proxy} by triangle {k}: stopped at {t}, past the contact at {first:?}");
                    hits[proxy] += 1;
                }
                None => {
                    let least = (0..=SAMPLES).map(|i| distance(i as f32 / SAMPLES as f32, TOLERANCE)).fold(f32::INFINITY, f32::min);
                    assert!(least > 0.0, "proxy {proxy} by triangle {k}: no stop, but {least} m from the teapot on the way");
                    misses[proxy] += 1;
                }
            }
        }
        assert!(hits.iter().all(|&h| h >= 3) && misses.iter().all(|&m| m >= 2), "hits {hits:?}, misses {misses:?}");
    }

    /// Why hull proxies are queried in [`UNIT`]s: against the Utah teapot's millimetre
    /// triangles, parry's distance from a capsule in metres is centimetres off somewhere, and in
    /// centimetres within [`GJK_ERROR`] everywhere (the exact distance is the reference). If parry
    /// fixes this, the first assertion fails and the scaling can go.
    #[test]
    fn parry_distance_to_small_triangles_needs_a_larger_unit() {
        let capsule = SharedShape::capsule(Vec3::new(0.0, -0.015, 0.0), Vec3::new(0.0, 0.015, 0.0), 0.008);
        let scaled = QueryShape::Scaled(Convex::Other(Arc::from(capsule.scale_dyn(Vec3::splat(UNIT), 16).expect("a capsule scales"))), capsule.compute_local_aabb());
        let exact = QueryShape::of(&*capsule);
        let (mut in_metres, mut in_units) = (0.0f32, 0.0f32);
        for (k, tri) in teapot_triangles().into_iter().enumerate().step_by(7) {
            let centre = (tri.a + tri.b + tri.c) / 3.0;
            let normal = face_normal(&tri);
            // Beside the triangle, 1–2 cm off along its normal, tilted by the triangle's index.
            let pose = Pose::from_parts(centre + normal * (0.01 + 0.01 * (k % 10) as f32 / 10.0), glam::Quat::from_rotation_x(k as f32 * 0.37));
            let (reference, _, _) = exact.to_triangle(&pose, &tri, &mut EPA::new());
            if reference <= 0.0 {
                continue;
            }
            let metres = parry3d::query::distance(&pose, &*capsule, &Pose::identity(), &tri).expect("a distance").distance;
            in_metres = in_metres.max((metres - reference).abs());
            in_units = in_units.max((scaled.to_triangle(&pose, &tri, &mut EPA::new()).0 + GJK_ERROR - reference).abs());
        }
        assert!(in_metres > 0.005, "parry in metres is off by {in_metres} m at most");
        assert!(in_units < GJK_ERROR, "parry in centimetres is off by {in_units} m");
    }

    /// The exact distance from the convex polyhedron `points`/`triangles` (placed at `pose`) to
    /// `tri`, 0 where they meet: the nearest of its edges to the triangle and of the triangle's
    /// edges to its faces (two convex polyhedra are nearest at such a pair), or 0 when a corner
    /// of the triangle is inside it. Written from the definition; shares nothing with GJK.
    fn polyhedron_triangle(points: &[Vec3], triangles: &[[u32; 3]], pose: &Pose, tri: &Triangle) -> f32 {
        let p: Vec<Vec3> = points.iter().map(|&x| *pose * x).collect();
        let corners = [tri.a, tri.b, tri.c];
        let inside = |x: Vec3| triangles.iter().all(|t| (p[t[1] as usize] - p[t[0] as usize]).cross(p[t[2] as usize] - p[t[0] as usize]).dot(x - p[t[0] as usize]) <= 0.0);
        if corners.iter().any(|&x| inside(x)) {
            return 0.0;
        }
        let mut best = f32::INFINITY;
        for t in triangles {
            let face = [p[t[0] as usize], p[t[1] as usize], p[t[2] as usize]];
            for k in 0..3 {
                let (a, b) = segment_triangle_closest(face[k], face[(k + 1) % 3], corners);
                best = best.min(a.distance(b));
                let (a, b) = segment_triangle_closest(corners[k], corners[(k + 1) % 3], face);
                best = best.min(a.distance(b));
            }
        }
        best
    }

    /// The hand's own hull proxies (the index metacarpal's and the wrist's), queried in
    /// [`UNIT`]s, against the exact distance beside the teapot's triangles from 0.2 mm to 1 cm
    /// away: never longer than the truth (the advancement's safety), and at most [`GJK_ERROR`]
    /// shorter.
    #[test]
    fn a_hull_proxy_in_units_is_never_farther_than_the_exact_distance() {
        let model = crate::hand::build(&crate::hand::HandParams::default()).expect("the built-in hand");
        let teapot = teapot_triangles();
        let mut checked = 0;
        for proxy in crate::collision::fit_proxies(&model, crate::collision::PROXY_MARGIN) {
            let name = &model.skeleton.joints()[proxy.joint].name;
            let crate::collision::ProxyShape::ConvexHull { points, triangles } = &proxy.shape else { continue };
            if name != "index-finger-metacarpal" && name != "wrist" {
                continue;
            }
            let shape = SharedShape::convex_mesh(points.clone(), triangles).expect("a hull");
            let cast = QueryShape::of(&*shape);
            let (lowest, _) = points.iter().fold((f32::INFINITY, Vec3::ZERO), |(y, p), &q| if q.y < y { (q.y, q) } else { (y, p) });
            for (k, tri) in teapot.iter().enumerate().step_by(97) {
                let normal = face_normal(tri);
                let centre = (tri.a + tri.b + tri.c) / 3.0;
                // The hull's lowest point (its own y) turned to face the triangle, then lifted.
                let turn = glam::Quat::from_rotation_arc(Vec3::NEG_Y, -normal);
                let gap = 0.0002 + 0.0098 * (k % 13) as f32 / 12.0;
                let pose = Pose::from_parts(centre + normal * gap - turn * Vec3::new(0.0, lowest, 0.0), turn);
                let exact = polyhedron_triangle(points, triangles, &pose, tri);
                let (queried, _, _) = cast.to_triangle(&pose, tri, &mut EPA::new());
                assert!(queried <= exact + 1e-6, "{name}, triangle {k}: {queried} m queried, {exact} m exact");
                assert!(exact - queried <= 2.0 * GJK_ERROR, "{name}, triangle {k}: {queried} m queried, {exact} m exact");
                checked += 1;
            }
        }
        assert!(checked > 40, "{checked} placements");
    }
}
