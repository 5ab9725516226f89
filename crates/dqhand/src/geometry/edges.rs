//! The edges of a triangle mesh.

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
