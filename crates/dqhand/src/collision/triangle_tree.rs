//! A mesh object's triangles in a bounding volume hierarchy of its own, built once per object,
//! for [`super::ProxyMeshQuery`]: each node keeps its box and its bounding sphere, and each
//! triangle what a proxy's cheap bound of the distance to it needs (its plane's unit normal,
//! its centroid and how far its corners reach from it), so a search measures nothing twice.
//!
//! parry's tree over a [`parry3d::shape::TriMesh`] holds boxes only: a search of it computed
//! each node's half diagonal and each triangle's normal and reach anew, through two
//! indirections per triangle, for each of the ~100 nodes and dozens of triangles that a
//! finger resting on the teapot meets (the closing finger's searches were two thirds of the
//! teapot's heavy frames, issue 28). Here the triangles are stored in the order of the leaves,
//! up to [`LEAF`] to a leaf, and the search keeps each stacked node's bound, so that a node
//! passed over since is not opened.
//!
//! Built top down (split at the median centroid along the longest axis of the centroids'
//! box), so its depth is at most log₂ of the triangle count less one or two: [`MAX_DEPTH`] is
//! far above any mesh a scene may load.

use glam::Vec3;
use parry3d::bounding_volume::{Aabb, BoundingVolume};
use parry3d::shape::Triangle;

use crate::math::is_sliver;

/// Triangles per leaf at most.
const LEAF: usize = 4;
/// The deepest a tree can be (more than `LEAF` · 2³⁰ triangles, more than a `u32` counts, make
/// the nodes at this depth leaves): a search's stack holds one more entry.
const MAX_DEPTH: usize = 32;

/// One triangle and what a cheap bound of the distance to it needs.
#[derive(Clone, Copy, Debug)]
pub struct TreeTriangle {
    /// The triangle, in the mesh's frame.
    pub triangle: Triangle,
    /// The unit normal of its plane by its winding (zero for a sliver, [`is_sliver`], whose
    /// normal is rounding).
    pub normal: Vec3,
    /// Its centroid.
    pub centroid: Vec3,
    /// How far its farthest corner is from the centroid (m).
    pub spread: f32,
}

impl TreeTriangle {
    fn new(triangle: Triangle) -> Self {
        let centroid = (triangle.a + triangle.b + triangle.c) / 3.0;
        let spread = centroid.distance_squared(triangle.a).max(centroid.distance_squared(triangle.b)).max(centroid.distance_squared(triangle.c)).sqrt();
        let corners = [triangle.a, triangle.b, triangle.c];
        let normal = if is_sliver(corners) { Vec3::ZERO } else { (triangle.b - triangle.a).cross(triangle.c - triangle.a).normalize_or_zero() };
        Self { triangle, normal, centroid, spread }
    }
}

/// A node of the tree: its box, its bounding sphere, and its children or triangles.
#[derive(Clone, Copy, Debug)]
pub struct TreeNode {
    /// The box holding its triangles.
    pub aabb: Aabb,
    /// The box's centre: with [`Self::radius`], a sphere holding its triangles.
    pub centre: Vec3,
    /// The box's half diagonal (m).
    pub radius: f32,
    /// A leaf's first triangle; an inner node's second child (its first is the next node).
    first: u32,
    /// A leaf's triangle count; 0 for an inner node.
    count: u32,
}

impl TreeNode {
    fn leaf(&self) -> Option<std::ops::Range<usize>> {
        (self.count > 0).then(|| self.first as usize..(self.first + self.count) as usize)
    }
}

/// A mesh's triangles and their tree.
#[derive(Clone, Debug)]
pub struct TriangleTree {
    nodes: Vec<TreeNode>,
    triangles: Vec<TreeTriangle>,
}

impl TriangleTree {
    /// The tree of the triangles `indices` of `vertices` (out-of-range indices are the caller's
    /// bug: a loaded mesh has been checked).
    ///
    /// # Panics
    /// If an index is not a vertex's.
    #[must_use]
    pub fn new(vertices: &[Vec3], indices: &[[u32; 3]]) -> Self {
        let mut triangles: Vec<TreeTriangle> = indices.iter().map(|t| TreeTriangle::new(Triangle::new(vertices[t[0] as usize], vertices[t[1] as usize], vertices[t[2] as usize]))).collect();
        let mut nodes = Vec::with_capacity(2 * triangles.len() / LEAF + 1);
        if !triangles.is_empty() {
            build(&mut nodes, &mut triangles, 0, 0);
        }
        Self { nodes, triangles }
    }

    /// The triangles, in the tree's order.
    #[must_use]
    pub fn triangles(&self) -> &[TreeTriangle] {
        &self.triangles
    }

    /// Calls `each` with the index (in [`Self::triangles`]) of every triangle whose box meets
    /// `aabb`, under nodes that `keep` keeps.
    pub fn overlapping(&self, aabb: &Aabb, keep: impl Fn(&TreeNode) -> bool, mut each: impl FnMut(u32)) {
        let mut stack = [0u32; MAX_DEPTH + 1];
        let mut depth = usize::from(!self.nodes.is_empty());
        while depth > 0 {
            depth -= 1;
            let i = stack[depth] as usize;
            let node = &self.nodes[i];
            if !node.aabb.intersects(aabb) || !keep(node) {
                continue;
            }
            match node.leaf() {
                Some(range) => {
                    for t in range.filter(|&t| self.triangles[t].triangle.local_aabb().intersects(aabb)) {
                        each(t as u32);
                    }
                }
                None => {
                    stack[depth] = node.first;
                    stack[depth + 1] = i as u32 + 1;
                    depth += 2;
                }
            }
        }
    }

    /// The least cost `leaf_cost` gives any triangle below `limit`, and its value, searching
    /// nearest first: `node_cost` bounds the cost of anything under a node from below, and a
    /// node whose bound is not below `worth(best)` (the best found so far; `worth` may not
    /// decrease) is passed over; `leaf_cost`, given the best so far, may give `None` for a
    /// triangle it judges not worth measuring. Both may tighten their bounds as the search
    /// goes (a node stacked earlier keeps its looser bound, which is still a bound).
    pub fn find_best<T>(&self, limit: f32, node_cost: impl Fn(&TreeNode) -> f32, mut leaf_cost: impl FnMut(&TreeTriangle, f32) -> Option<(f32, T)>, worth: impl Fn(f32) -> f32) -> Option<(f32, T)> {
        let mut stack = [(0u32, 0.0f32); MAX_DEPTH + 1];
        let mut depth = 0;
        let mut best: Option<(f32, T)> = None;
        let mut best_cost = limit;
        if let Some(root) = self.nodes.first() {
            stack[0] = (0, node_cost(root));
            depth = 1;
        }
        while depth > 0 {
            depth -= 1;
            let (i, bound) = stack[depth];
            if bound >= worth(best_cost) {
                continue;
            }
            let node = &self.nodes[i as usize];
            if let Some(range) = node.leaf() {
                for t in &self.triangles[range] {
                    if let Some((cost, value)) = leaf_cost(t, best_cost) {
                        if cost < best_cost {
                            (best_cost, best) = (cost, Some((cost, value)));
                        }
                    }
                }
                continue;
            }
            let (mut near, mut far) = ((i + 1, node_cost(&self.nodes[i as usize + 1])), (node.first, node_cost(&self.nodes[node.first as usize])));
            if far.1 < near.1 {
                std::mem::swap(&mut near, &mut far);
            }
            // The farther first on the stack, so the nearer is opened next.
            for child in [far, near] {
                if child.1 < worth(best_cost) {
                    stack[depth] = child;
                    depth += 1;
                }
            }
        }
        best
    }
}

/// Appends the subtree of `triangles` (reordered in place; `offset` is the first one's index
/// in the whole mesh) to `nodes`, at depth `depth`.
fn build(nodes: &mut Vec<TreeNode>, triangles: &mut [TreeTriangle], offset: usize, depth: usize) {
    let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
    let (mut clo, mut chi) = (lo, hi);
    for t in triangles.iter() {
        let tri = &t.triangle;
        lo = lo.min(tri.a).min(tri.b).min(tri.c);
        hi = hi.max(tri.a).max(tri.b).max(tri.c);
        clo = clo.min(t.centroid);
        chi = chi.max(t.centroid);
    }
    let aabb = Aabb::new(lo, hi);
    let (centre, radius) = (aabb.center(), aabb.half_extents().length());
    let index = nodes.len();
    nodes.push(TreeNode { aabb, centre, radius, first: offset as u32, count: triangles.len() as u32 });
    if triangles.len() <= LEAF || depth == MAX_DEPTH - 1 {
        return;
    }
    let extent = chi - clo;
    let axis = if extent.x >= extent.y && extent.x >= extent.z { 0 } else if extent.y >= extent.z { 1 } else { 2 };
    let half = triangles.len() / 2;
    triangles.select_nth_unstable_by(half, |a, b| a.centroid[axis].total_cmp(&b.centroid[axis]));
    let (left, right) = triangles.split_at_mut(half);
    build(nodes, left, offset, depth + 1);
    let second = nodes.len() as u32;
    build(nodes, right, offset + half, depth + 1);
    nodes[index].first = second;
    nodes[index].count = 0;
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A bumpy grid of triangles, irregular enough that no split is even.
    fn grid(n: usize) -> (Vec<Vec3>, Vec<[u32; 3]>) {
        let mut vertices = Vec::new();
        for i in 0..=n {
            for j in 0..=n {
                let (x, z) = (i as f32 / n as f32, j as f32 / n as f32);
                vertices.push(Vec3::new(x + 0.3 * z * z, (7.0 * x).sin() * (5.0 * z).cos() * 0.2, z));
            }
        }
        let at = |i: usize, j: usize| (i * (n + 1) + j) as u32;
        let mut triangles = Vec::new();
        for i in 0..n {
            for j in 0..n {
                triangles.push([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
                triangles.push([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
            }
        }
        (vertices, triangles)
    }

    #[test]
    fn every_triangle_is_in_one_leaf_inside_its_boxes() {
        let (vertices, indices) = grid(23);
        let tree = TriangleTree::new(&vertices, &indices);
        assert_eq!(tree.triangles().len(), indices.len());
        // Every triangle once, in one leaf, and within each box on the way down to it.
        let mut seen = vec![0; indices.len()];
        fn walk(tree: &TriangleTree, i: usize, seen: &mut [u32], depth: usize) -> usize {
            let node = &tree.nodes[i];
            let inside = |t: &TreeTriangle| [t.triangle.a, t.triangle.b, t.triangle.c].iter().all(|&p| p.cmpge(node.aabb.mins).all() && p.cmple(node.aabb.maxs).all());
            match node.leaf() {
                Some(range) => {
                    assert!(!range.is_empty() && range.len() <= LEAF);
                    for t in range {
                        assert!(inside(&tree.triangles[t]));
                        seen[t] += 1;
                    }
                    depth
                }
                None => walk(tree, i + 1, seen, depth + 1).max(walk(tree, node.first as usize, seen, depth + 1)),
            }
        }
        let depth = walk(&tree, 0, &mut seen, 0);
        assert!(seen.iter().all(|&n| n == 1));
        // Balanced: the median split halves each node.
        assert!(depth <= (indices.len() as f32 / LEAF as f32).log2().ceil() as usize + 1, "depth {depth}");
    }

    #[test]
    fn the_overlapping_triangles_are_those_whose_boxes_meet_the_box() {
        // The reference: every triangle whose own box meets the query box, tried one by one.
        let (vertices, indices) = grid(17);
        let tree = TriangleTree::new(&vertices, &indices);
        let mut met = 0;
        for k in 0..40 {
            let c = Vec3::new((k as f32 * 0.37).fract(), (k as f32 * 0.11).sin() * 0.2, (k as f32 * 0.73).fract());
            let query = Aabb::from_half_extents(c, Vec3::splat(0.02 + 0.01 * (k % 5) as f32));
            let mut found = Vec::new();
            tree.overlapping(&query, |_| true, |t| found.push(t));
            let reference: Vec<u32> = (0..tree.triangles().len() as u32)
                .filter(|&t| tree.triangles()[t as usize].triangle.local_aabb().intersects(&query))
                .collect();
            found.sort_unstable();
            assert_eq!(found, reference, "query {k}");
            met += usize::from(!found.is_empty());
        }
        assert!(met > 10 && met < 40, "{met} of 40 boxes met the grid");
    }

    #[test]
    fn the_best_is_the_least_over_every_triangle() {
        // Nearest triangle centroid to a point, by the tree with sphere bounds, against every
        // triangle.
        let (vertices, indices) = grid(19);
        let tree = TriangleTree::new(&vertices, &indices);
        for k in 0..50 {
            let x = Vec3::new((k as f32 * 0.61).fract() * 1.4 - 0.2, (k as f32 * 0.3).cos() * 0.4, (k as f32 * 0.29).fract() * 1.2 - 0.1);
            let found = tree.find_best(f32::INFINITY, |n| x.distance(n.centre) - n.radius, |t, _| Some((x.distance(t.centroid), t.centroid)), |b| b);
            let reference = tree.triangles().iter().map(|t| x.distance(t.centroid)).fold(f32::INFINITY, f32::min);
            let (cost, at) = found.expect("something is nearest");
            assert_eq!(cost, reference);
            assert_eq!(x.distance(at), reference);
            // Under a limit below it, nothing.
            assert!(tree.find_best(reference, |n| x.distance(n.centre) - n.radius, |t, _| Some((x.distance(t.centroid), ())), |b| b).is_none());
        }
    }
}
