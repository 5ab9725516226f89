//! A convex hull's support function by hill climbing over its edges.
//!
//! parry's convex polyhedron finds a support point by trying every vertex: the wrist's proxy
//! has 957, and GJK asks for a support point some ten times a query, so a third of a
//! manipulation frame's time went there while the hand rested on a mesh. On a convex
//! polyhedron a vertex no neighbour beats is the farthest of all along a direction (the
//! simplex method's argument), so the search walks from the nearest of a few precomputed
//! extremes to a better neighbour until none is better: the same point, about 20 dot products
//! on the wrist's hull (10–15 on the metacarpals') instead of 957.

use glam::Vec3;
use parry3d::shape::{ConvexPolyhedron, SupportMap};

/// A direction's component counts as zero below this share of its largest (tan 22.5°): a
/// direction picks the nearest of the 26 of a cube's faces, edges and corners.
const LEVEL: f32 = 0.414;

/// A convex polyhedron's vertices and their neighbours along its edges.
#[derive(Clone, Debug)]
pub struct HullSupport {
    points: Vec<Vec3>,
    /// Vertex `v`'s neighbours: `neighbours[first[v]..first[v + 1]]`.
    first: Vec<u32>,
    neighbours: Vec<u32>,
    /// The farthest vertex along each direction of components -1, 0 or 1 (in base 3, +1).
    starts: [u32; 27],
}

impl HullSupport {
    /// The support of `hull`, its points scaled by `scale`.
    #[must_use]
    pub fn new(hull: &ConvexPolyhedron, scale: f32) -> Self {
        let points: Vec<Vec3> = hull.points().iter().map(|p| *p * scale).collect();
        let mut pairs: Vec<(u32, u32)> = hull.edges().iter().flat_map(|e| [(e.vertices[0], e.vertices[1]), (e.vertices[1], e.vertices[0])]).collect();
        pairs.sort_unstable();
        pairs.dedup();
        let mut first = vec![0u32; points.len() + 1];
        for &(a, _) in &pairs {
            first[a as usize + 1] += 1;
        }
        for v in 0..points.len() {
            first[v + 1] += first[v];
        }
        let neighbours = pairs.iter().map(|&(_, b)| b).collect();
        let starts = core::array::from_fn(|k| {
            let d = Vec3::new((k / 9) as f32 - 1.0, (k / 3 % 3) as f32 - 1.0, (k % 3) as f32 - 1.0);
            (0..points.len()).max_by(|&a, &b| points[a].dot(d).total_cmp(&points[b].dot(d))).unwrap_or(0) as u32
        });
        Self { points, first, neighbours, starts }
    }
}

impl SupportMap for HullSupport {
    fn local_support_point(&self, dir: Vec3) -> Vec3 {
        let level = dir.abs().max_element() * LEVEL;
        let digit = |c: f32| usize::from(c > -level) + usize::from(c > level);
        let mut v = self.starts[digit(dir.x) * 9 + digit(dir.y) * 3 + digit(dir.z)] as usize;
        let mut best = self.points[v].dot(dir);
        loop {
            let from = v;
            for &n in &self.neighbours[self.first[from] as usize..self.first[from + 1] as usize] {
                let d = self.points[n as usize].dot(dir);
                if d > best {
                    (v, best) = (n as usize, d);
                }
            }
            if v == from {
                return self.points[v];
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Rng;

    /// Every direction's walk ends at a point as far along it as the farthest of all the
    /// vertices (tried one by one): on a rounded, flattened hull of 1,500 vertices like the
    /// wrist's, on a cube, whose faces tie, and on the Utah teapot's hull.
    #[test]
    fn the_walk_finds_the_farthest_vertex() {
        let mut rng = Rng::new(11);
        let blob: Vec<Vec3> = (0..3000).map(|_| rng.unit() * Vec3::new(0.045, 0.04, 0.015)).collect();
        let cube: Vec<Vec3> = (0..8).map(|k| Vec3::new((k & 1) as f32, ((k >> 1) & 1) as f32, (k >> 2) as f32) - 0.5).collect();
        // The Utah teapot's vertices (Newell's patches, as the scene's teapot is made).
        let scene = crate::scene::Scene::named("objects").expect("built in");
        let colliders = super::super::ObjectColliders::new(&scene).expect("its shapes");
        let teapot = colliders.objects().iter().find(|o| o.name == "teapot").and_then(|o| o.mesh.as_ref()).expect("the teapot");
        for points in [blob, cube, teapot.vertices.clone()] {
            let (points, triangles) = parry3d::transformation::try_convex_hull(&points).expect("a hull");
            let hull = ConvexPolyhedron::from_convex_mesh(points.clone(), &triangles).expect("a polyhedron");
            let support = HullSupport::new(&hull, 2.0);
            for _ in 0..5000 {
                let dir = rng.unit() * (0.1 + rng.uniform(0.0, 3.0) as f32);
                let walked = support.local_support_point(dir).dot(dir);
                let farthest = points.iter().map(|p| (*p * 2.0).dot(dir)).fold(f32::NEG_INFINITY, f32::max);
                assert!(walked >= farthest - 1e-6 * farthest.abs().max(1.0), "{dir}: {walked} walked, {farthest} farthest");
            }
        }
    }
}
