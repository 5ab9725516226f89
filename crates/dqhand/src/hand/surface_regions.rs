//! Which triangles of the built-in hand are nail, palm and back: the nails from the shape's
//! nail plates, the rest by which way each triangle faces in the bind pose (palm down, −Y).
//!
//! The triangles are then ordered by region, so that each region's triangles are one range
//! of the index array: one glTF primitive each over the same vertices, and one draw group
//! each in the viewer, with no vertex duplicated at a region's edge (the vertex count stays
//! the one asked for).

use std::ops::Range;

use glam::Vec3;

use super::shape::HandShape;
use crate::appearance::SurfaceRegion;

/// Reorders the triangles of `indices` (over `positions`) by region, keeping their order
/// within each, and returns each region's range of `indices`, in [`SurfaceRegion::ALL`] order.
pub(crate) fn sort_by_region(shape: &HandShape, positions: &[[f32; 3]], indices: &mut Vec<u32>) -> Vec<(SurfaceRegion, Range<usize>)> {
    let region = |t: &[u32]| {
        let [a, b, c] = [0, 1, 2].map(|k| Vec3::from(positions[t[k] as usize]));
        if shape.over_nail((a + b + c) / 3.0) {
            SurfaceRegion::Nail
        } else if (b - a).cross(c - a).y < 0.0 {
            SurfaceRegion::Palm
        } else {
            SurfaceRegion::Back
        }
    };
    let mut triangles: Vec<(SurfaceRegion, [u32; 3])> = indices.chunks_exact(3).map(|t| (region(t), [t[0], t[1], t[2]])).collect();
    triangles.sort_by_key(|t| t.0);
    *indices = triangles.iter().flat_map(|t| t.1).collect();
    SurfaceRegion::ALL
        .iter()
        .map(|&r| {
            let start = 3 * triangles.partition_point(|t| t.0 < r);
            let end = 3 * triangles.partition_point(|t| t.0 <= r);
            (r, start..end)
        })
        .collect()
}
