//! Optimized centres of rotation (Le and Hodgins, "Real-time skeletal skinning with
//! optimized centers of rotation", ACM TOG 35(4), SIGGRAPH 2016): per vertex, the point of the
//! rest mesh its skin turns about.
//!
//! The centre of vertex `i` is the area-weighted mean of the triangles' centroids, each
//! weighted by how alike its weights are to the vertex's (their similarity, σ = 0.1):
//!
//! `s(wᵢ, wₜ) = Σ_{j≠k} wᵢⱼ wᵢₖ wₜⱼ wₜₖ exp(−(wᵢⱼ wₜₖ − wᵢₖ wₜⱼ)² / σ²)`,
//! `pᵢ* = Σₜ s(wᵢ, wₜ) aₜ cₜ / Σₜ s(wᵢ, wₜ) aₜ` (their integral over the surface, one point
//! per triangle: its centroid `cₜ`, area `aₜ` and mean weights `wₜ`).
//!
//! A term needs both joints `j`, `k` to weigh on the vertex and on the triangle, so the sums
//! run over the triangles of each pair of the vertex's joints only (a list per pair, built
//! once): the vertices of a pair's region times its triangles, where the definition sums over
//! every triangle for every vertex. A vertex with one joint moves rigidly whatever its centre
//! and takes its rest position; so does one whose pairs no triangle shares, which then moves
//! as LB moves it.
//! The paper subdivides the mesh first so that triangles are small against the weights'
//! changes; a mesh made for skinning (the built-in hand's 8,668 vertices) is used as it is.

use std::collections::HashMap;

#[cfg(feature = "rayon")]
use rayon::prelude::*;

use super::SkinnedMesh;

/// σ of the weights' similarity (Le and Hodgins'): how unlike two weightings of the
/// same pair of joints may be and still share a centre.
pub const SIMILARITY_SIGMA: f32 = 0.1;

/// The centre of rotation of every vertex of `mesh`, #V, in bind space (split across rayon's
/// threads where the `rayon` feature is on).
#[must_use]
pub fn centres_of_rotation(mesh: &SkinnedMesh) -> Vec<[f32; 3]> {
    let triangles = Triangles::of(mesh);
    let centre = |v: usize| triangles.centre(mesh, v);
    #[cfg(feature = "rayon")]
    return (0..mesh.vertex_count()).into_par_iter().map(centre).collect();
    #[cfg(not(feature = "rayon"))]
    (0..mesh.vertex_count()).map(centre).collect()
}

/// One triangle's share of a pair of joints: its area, centroid and mean weights of the two.
struct Share {
    area: f64,
    centroid: [f64; 3],
    w: (f32, f32),
}

/// Per pair of joints `(j, k)`, `j < k`, the triangles both weigh on.
struct Triangles {
    pairs: HashMap<(u16, u16), Vec<Share>>,
}

impl Triangles {
    fn of(mesh: &SkinnedMesh) -> Self {
        let mut pairs: HashMap<(u16, u16), Vec<Share>> = HashMap::new();
        let mut weights: Vec<(u16, f32)> = Vec::with_capacity(3 * mesh.influences_per_vertex());
        for t in mesh.indices().chunks_exact(3) {
            let [a, b, c] = [0, 1, 2].map(|i| mesh.position(t[i] as usize).as_dvec3());
            let area = 0.5 * (b - a).cross(c - a).length();
            if area == 0.0 {
                continue;
            }
            let centroid = ((a + b + c) / 3.0).to_array();
            weights.clear();
            for &v in t {
                for (j, w) in mesh.influences(v as usize) {
                    match weights.iter_mut().find(|e| usize::from(e.0) == j) {
                        Some(e) => e.1 += w / 3.0,
                        None => weights.push((j as u16, w / 3.0)),
                    }
                }
            }
            for (x, &(j, wj)) in weights.iter().enumerate() {
                for &(k, wk) in &weights[x + 1..] {
                    let (key, w) = ordered((j, wj), (k, wk));
                    pairs.entry(key).or_default().push(Share { area, centroid, w });
                }
            }
        }
        Self { pairs }
    }

    /// Vertex `v`'s centre, its rest position where no triangle is alike.
    fn centre(&self, mesh: &SkinnedMesh, v: usize) -> [f32; 3] {
        let inf: Vec<(usize, f32)> = mesh.influences(v).collect();
        let inv_sq = 1.0 / (SIMILARITY_SIGMA * SIMILARITY_SIGMA);
        let (mut sum, mut total) = ([0.0f64; 3], 0.0f64);
        for (x, &(j, wj)) in inf.iter().enumerate() {
            for &(k, wk) in &inf[x + 1..] {
                let (key, (vj, vk)) = ordered((j as u16, wj), (k as u16, wk));
                let Some(shares) = self.pairs.get(&key) else { continue };
                for s in shares {
                    let (tj, tk) = s.w;
                    let d = vj * tk - vk * tj;
                    // The similarity's terms (j, k) and (k, j) are equal: the factor 2 cancels.
                    let similarity = f64::from(vj * vk * tj * tk * (-d * d * inv_sq).exp());
                    let weight = similarity * s.area;
                    total += weight;
                    for c in 0..3 {
                        sum[c] += weight * s.centroid[c];
                    }
                }
            }
        }
        if total > 0.0 {
            sum.map(|c| (c / total) as f32)
        } else {
            mesh.position(v).to_array()
        }
    }
}

/// A pair of (joint, weight) as the key of [`Triangles::pairs`], the lower joint first, and
/// the weights in the same order.
fn ordered(a: (u16, f32), b: (u16, f32)) -> ((u16, u16), (f32, f32)) {
    if a.0 < b.0 { ((a.0, b.0), (a.1, b.1)) } else { ((b.0, a.0), (b.1, a.1)) }
}
