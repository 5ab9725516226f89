//! Points and line segments.

use glam::Vec3;

/// Distance from `x` to the segment `a`–`b` (to `a` if the segment has no length).
#[must_use]
pub fn segment_distance(x: Vec3, a: Vec3, b: Vec3) -> f32 {
    let ab = b - a;
    let t = ((x - a).dot(ab) / ab.length_squared().max(1e-18)).clamp(0.0, 1.0);
    x.distance(a + t * ab)
}
