//! Closed surfaces: whether a triangle mesh bounds a volume, and the volume it bounds.

use std::collections::HashMap;

use glam::DVec3;

/// Checks that a triangle mesh is a closed, consistently oriented 2-manifold: every edge is
/// used by exactly two triangles, once in each direction. Returns a description of the first
/// violation.
///
/// * `indices` — #F × 3 vertex indices.
///
/// # Errors
/// A lowercase sentence naming the offending edge.
pub fn check_closed(indices: &[u32]) -> Result<(), String> {
    let mut directed: HashMap<(u32, u32), u32> = HashMap::with_capacity(indices.len());
    for t in indices.chunks_exact(3) {
        for (a, b) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
            let n = directed.entry((a, b)).or_insert(0);
            *n += 1;
            if *n > 1 {
                return Err(format!("edge {a}-{b} is used twice in the same direction (inconsistent orientation or a non-manifold edge)"));
            }
        }
    }
    match directed.keys().find(|&&(a, b)| !directed.contains_key(&(b, a))) {
        Some((a, b)) => Err(format!("edge {a}-{b} borders only one triangle (the surface has a hole)")),
        None => Ok(()),
    }
}

/// The signed volume enclosed by a closed, outward-oriented triangle mesh (m³), by the
/// divergence theorem: `Σ a · (b × c) / 6` over its triangles. Meaningless for an open mesh;
/// check with [`check_closed`] first.
///
/// * `positions` — #V; `indices` — #F × 3.
#[must_use]
pub fn enclosed_volume(positions: &[[f32; 3]], indices: &[u32]) -> f64 {
    let p = |i: u32| DVec3::from(glam::Vec3::from(positions[i as usize]));
    indices.chunks_exact(3).map(|t| p(t[0]).dot(p(t[1]).cross(p(t[2])))).sum::<f64>() / 6.0
}
