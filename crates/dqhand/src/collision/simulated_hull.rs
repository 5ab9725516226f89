//! The shape the physics simulates a hull proxy or a mesh object as: a few of its vertices' hull,
//! rounded by how far the rest lie outside it, so it holds the whole proxy (or object).
//!
//! A hull proxy is the hull of every skin vertex its joint carries (957 vertices on the built-in
//! hand's wrist). rapier transforms every one of them for the collider's box twice a step, and
//! its contacts try every one for each support point: a fifth of the manipulation loop's time
//! on the teapot, measured by `perf`. A few hundred vertices at most keep the shape to a
//! quarter of a millimetre; the rounding (parry's round convex polyhedron, which rapier's
//! contacts handle as they do a polyhedron, faces and all) makes it no smaller anywhere, so an
//! object pushed by the simulated hand is never pushed into the hand the contact constraint
//! sees.

use glam::Vec3;
use parry3d::query::PointQuery;
use parry3d::shape::{SharedShape, Triangle};

/// Directions whose extreme vertices start the simulated hull.
const DIRECTIONS: usize = 32;

/// Vertices are added to the simulated hull until none is farther than this outside its
/// faces' planes (m).
const OUTSIDE_M: f32 = 2.5e-4;

/// How many vertices are added to the simulated hull at a time: one at a time keeps fewest
/// (each the farthest out), but builds a hull for each (0.3 s for the wrist's).
const BATCH: usize = 16;

/// The most vertices the simulated hull keeps.
pub const MAX_SIMULATED_VERTICES: usize = 256;

/// The simulated shape of the hull of `points` (a proxy's vertices, m): the hull of the
/// vertices extreme along [`DIRECTIONS`] directions, grown by each face's farthest vertex
/// outside it ([`BATCH`] at a time, the farthest first) until none is [`OUTSIDE_M`] outside
/// (or it has [`MAX_SIMULATED_VERTICES`]), rounded by the largest distance of any of `points` from it.
/// `None` where `points` span no volume or are not all finite.
#[must_use]
pub fn simulated_hull(points: &[Vec3]) -> Option<SharedShape> {
    if !points.iter().all(|p| p.is_finite()) {
        return None;
    }
    let mut kept: Vec<Vec3> = fibonacci_sphere(DIRECTIONS)
        .filter_map(|u| points.iter().copied().max_by(|a, b| a.dot(u).total_cmp(&b.dot(u))))
        .collect();
    kept.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)).then(a.z.total_cmp(&b.z)));
    kept.dedup();
    loop {
        let (vertices, faces) = parry3d::transformation::try_convex_hull(&kept).ok()?;
        // Each face (they turn outward) and its unit normal; a degenerate one has none, and its
        // neighbours hold it.
        let planes: Vec<(Triangle, Vec3)> = faces.iter().filter_map(|&[a, b, c]| {
            let t = Triangle::new(vertices[a as usize], vertices[b as usize], vertices[c as usize]);
            t.normal().map(|n| (t, n))
        }).collect();
        // Per face, the point farthest above its plane, if more than [`OUTSIDE_M`]: quickhull's
        // next points, the [`BATCH`] farthest at once.
        let mut farthest: Vec<(f32, Vec3)> = vec![(OUTSIDE_M, Vec3::ZERO); planes.len()];
        for &p in points {
            let (face, by) = planes.iter().map(|(t, n)| n.dot(p - t.a)).enumerate().max_by(|a, b| a.1.total_cmp(&b.1))?;
            if by > farthest[face].0 {
                farthest[face] = (by, p);
            }
        }
        let mut due: Vec<(f32, Vec3)> = farthest.into_iter().filter(|&(by, _)| by > OUTSIDE_M).collect();
        if !due.is_empty() && kept.len() < MAX_SIMULATED_VERTICES {
            due.sort_by(|a, b| b.0.total_cmp(&a.0));
            let room = (MAX_SIMULATED_VERTICES - kept.len()).min(BATCH);
            kept.extend(due.iter().take(room).map(|&(_, p)| p));
            continue;
        }
        // Each point's distance: an outside point's nearest point of the hull is on a face
        // whose plane it is above. (The shape is the hull of these vertices: parry's
        // polyhedron of it merges nearly coplanar faces, and its support points, which GJK
        // asks, are its vertices'.)
        let distance = |p: Vec3| planes.iter().filter(|(t, n)| n.dot(p - t.a) > 0.0).map(|(t, _)| t.distance_to_local_point(p, true)).reduce(f32::min).unwrap_or(0.0);
        let outside = points.iter().map(|&p| distance(p)).fold(0.0, f32::max);
        return SharedShape::round_convex_mesh(vertices, &faces, outside);
    }
}

/// `n` directions spread evenly over the unit sphere (the golden-angle spiral).
fn fibonacci_sphere(n: usize) -> impl Iterator<Item = Vec3> {
    let turn = core::f32::consts::PI * (3.0 - 5.0f32.sqrt());
    (0..n).map(move |i| {
        let y = 1.0 - 2.0 * (i as f32 + 0.5) / n as f32;
        let r = (1.0 - y * y).max(0.0).sqrt();
        let a = turn * i as f32;
        Vec3::new(r * a.cos(), y, r * a.sin())
    })
}
