//! Inside or outside a closed surface, robustly: the generalised winding number.

use glam::DVec3;

/// Generalised winding number of `point` with respect to a closed, outward-oriented mesh: the
/// signed solid angle its triangles subtend, over 4π (Van Oosterom and Strackee's formula for
/// a triangle's solid angle). 1 inside, 0 outside; robust near the surface too.
///
/// * `positions` — #V; `indices` — #F × 3.
#[must_use]
pub fn winding_number(positions: &[[f32; 3]], indices: &[u32], point: glam::Vec3) -> f64 {
    let o = DVec3::from(point);
    let p = |i: u32| DVec3::from(glam::Vec3::from(positions[i as usize])) - o;
    let total: f64 = indices
        .chunks_exact(3)
        .map(|t| {
            let [a, b, c] = [p(t[0]), p(t[1]), p(t[2])];
            let (la, lb, lc) = (a.length(), b.length(), c.length());
            let numerator = a.dot(b.cross(c));
            let denominator = la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
            2.0 * numerator.atan2(denominator)
        })
        .sum();
    total / (4.0 * std::f64::consts::PI)
}
