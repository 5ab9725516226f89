//! Smooth vertex normals of a triangle mesh, for meshes that come without them.

use glam::Vec3;

/// Area-weighted vertex normals of a triangle mesh, #V (unit; +Y where undefined).
#[must_use]
pub fn vertex_normals(positions: &[[f32; 3]], indices: &[u32]) -> Vec<[f32; 3]> {
    let mut acc = vec![Vec3::ZERO; positions.len()];
    for t in indices.chunks_exact(3) {
        let [a, b, c] = [t[0], t[1], t[2]].map(|i| Vec3::from(positions[i as usize]));
        let n = (b - a).cross(c - a);
        for &i in t {
            acc[i as usize] += n;
        }
    }
    acc.into_iter().map(|n| n.normalize_or(Vec3::Y).to_array()).collect()
}
