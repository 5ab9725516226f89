//! Edge-length distortion: how much the skin stretches or shrinks against the rest pose.

use glam::Vec3;

/// The undirected edges of a triangle mesh, each once, as vertex pairs.
#[must_use]
pub fn edges(indices: &[u32]) -> Vec<[u32; 2]> {
    let mut e: Vec<[u32; 2]> = indices
        .chunks_exact(3)
        .flat_map(|t| [[t[0], t[1]], [t[1], t[2]], [t[2], t[0]]])
        .map(|[a, b]| [a.min(b), a.max(b)])
        .collect();
    e.sort_unstable();
    e.dedup();
    e
}

/// Mean and largest relative edge-length change `|ℓ − ℓ₀| / ℓ₀` over `edges`.
///
/// * `rest`, `posed` — #V positions; `edges` — vertex pairs.
#[must_use]
pub fn edge_distortion(rest: &[[f32; 3]], posed: &[[f32; 3]], edges: &[[u32; 2]]) -> (f32, f32) {
    let len = |p: &[[f32; 3]], [a, b]: [u32; 2]| Vec3::from(p[a as usize]).distance(Vec3::from(p[b as usize]));
    let (sum, max) = edges.iter().fold((0.0f64, 0.0f32), |(s, m), &e| {
        let r = (len(posed, e) - len(rest, e)).abs() / len(rest, e).max(1e-12);
        (s + f64::from(r), m.max(r))
    });
    ((sum / edges.len().max(1) as f64) as f32, max)
}
