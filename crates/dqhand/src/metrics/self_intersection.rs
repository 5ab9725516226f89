//! Self-intersection: pairs of triangles of the deformed skin that pass through each other.
//!
//! Broad phase: parry's bounding volume hierarchy over the triangles' boxes, traversed
//! against itself. Narrow phase: parry's exact intersection test of the two triangles.
//! Triangles that share a vertex are neighbours on the surface and are not counted.

use parry3d::bounding_volume::Aabb;
use parry3d::math::{Pose, Vector};
use parry3d::partitioning::{Bvh, BvhBuildStrategy};
use parry3d::query::intersection_test;
use parry3d::shape::Triangle;

/// Number of pairs of triangles that intersect, neighbours sharing a vertex excluded.
///
/// * `positions` — #V; `indices` — #F × 3.
#[must_use]
pub fn count_self_intersections(positions: &[[f32; 3]], indices: &[u32]) -> usize {
    let triangles: Vec<[u32; 3]> = indices.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect();
    let shape = |t: &[u32; 3]| {
        let [a, b, c] = t.map(|i| Vector::from(positions[i as usize]));
        Triangle::new(a, b, c)
    };
    let boxes: Vec<Aabb> = triangles.iter().map(|t| shape(t).local_aabb()).collect();
    let bvh = Bvh::from_leaves(BvhBuildStrategy::Binned, &boxes);
    let neighbours = |a: &[u32; 3], b: &[u32; 3]| a.iter().any(|v| b.contains(v));
    bvh.leaf_pairs(&bvh, |n1, n2| n1.intersects(n2))
        .filter(|&(i, j)| i < j)
        .filter(|&(i, j)| {
            let (a, b) = (&triangles[i as usize], &triangles[j as usize]);
            !neighbours(a, b)
                && intersection_test(&Pose::IDENTITY, &shape(a), &Pose::IDENTITY, &shape(b)).is_ok_and(|r| r.intersecting)
        })
        .count()
}
