//! Edge-length distortion: how much the skin stretches or shrinks against the rest pose.

use glam::Vec3;

use crate::geometry::edges;

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

/// Per-vertex distortion for the viewer's heat map: at each vertex, the mean relative
/// length change `|ℓ − ℓ₀| / ℓ₀` of the edges that meet there.
///
/// The edges and their rest lengths are found once; [`Self::compute`] then allocates nothing,
/// so it can run every frame beside the deformers.
#[derive(Clone, Debug)]
pub struct VertexDistortion {
    edges: Vec<[u32; 2]>,
    rest_inverse: Vec<f32>,
    /// 1 / (edges at each vertex).
    degree_inverse: Vec<f32>,
}

impl VertexDistortion {
    /// Prepares the edges of `indices` with their lengths on `rest` (#V positions).
    #[must_use]
    pub fn new(rest: &[[f32; 3]], indices: &[u32]) -> Self {
        let edges = edges(indices);
        let mut degree = vec![0u32; rest.len()];
        let rest_inverse = edges
            .iter()
            .map(|&[a, b]| {
                degree[a as usize] += 1;
                degree[b as usize] += 1;
                1.0 / Vec3::from(rest[a as usize]).distance(Vec3::from(rest[b as usize])).max(1e-12)
            })
            .collect();
        let degree_inverse = degree.iter().map(|&d| if d == 0 { 0.0 } else { 1.0 / d as f32 }).collect();
        Self { edges, rest_inverse, degree_inverse }
    }

    /// Writes each vertex's mean edge-length change of `posed` against rest into `out`.
    ///
    /// # Panics
    /// If `posed` or `out` do not have one entry per vertex.
    pub fn compute(&self, posed: &[[f32; 3]], out: &mut [f32]) {
        assert!(posed.len() == self.degree_inverse.len() && out.len() == posed.len(), "one entry per vertex");
        out.fill(0.0);
        for (&[a, b], &r) in self.edges.iter().zip(&self.rest_inverse) {
            let change = (Vec3::from(posed[a as usize]).distance(Vec3::from(posed[b as usize])) * r - 1.0).abs();
            out[a as usize] += change;
            out[b as usize] += change;
        }
        for (o, &d) in out.iter_mut().zip(&self.degree_inverse) {
            *o *= d;
        }
    }
}
