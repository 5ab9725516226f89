//! Self-contact: how deep the posed skin passes into itself between the hand's parts (each
//! finger, and the palm), and how much space it encloses twice there.
//!
//! A closed, outward-oriented surface that passes through itself encloses some space twice: its
//! winding number there, the signed count of its crossings by a ray to infinity (+1 leaving,
//! −1 entering), is 2. A vertex is inside another part where a point just under it (along its
//! normal) has winding number 2 and is inside the other parts' triangles by their generalised
//! winding number (Jacobson et al. 2013: at least ½; they are open where a part meets the next,
//! and a skin folded into its own part is not a contact between parts); its depth is its
//! distance to the nearest of those triangles. The shared volume is the space of winding
//! number 2 in the box around those vertices (grown by their depth and longest edge): exact
//! along lines parallel to x (the intervals between sorted crossings where two layers enclose
//! them), [`SPACING`] apart across (an overlap holding no vertex, smaller than a triangle, is not
//! seen; a skin folded into its own part in that box is counted). Counting intersecting
//! triangle pairs (`count_self_intersections`) says that the skin crosses itself, not how far.

use glam::Vec3;
use parry3d::bounding_volume::{Aabb, BoundingVolume};
use parry3d::partitioning::{Bvh, BvhBuildStrategy};

use crate::geometry::{edges, vertex_normals, winding_number};
use crate::math::triangle_closest;

/// How far apart the lines measuring the shared volume are (m).
pub const SPACING: f32 = 0.0005;
/// How far under a vertex its winding number is read (m): far less than any skin is thick.
const UNDER: f32 = 1e-5;
/// Three ray directions, none along an axis or a simple diagonal: a ray through an edge or a
/// vertex counts a crossing twice or not at all, so each point's winding number is the median
/// of three.
const RAYS: [Vec3; 3] = [Vec3::new(0.3137, 0.8613, 0.3995), Vec3::new(-0.3712, 0.8355, 0.4051), Vec3::new(0.6988, -0.2671, -0.6636)];

/// The self-contact of one posed skin.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SelfContact {
    /// The deepest vertex inside another part, m (0 where none is).
    pub depth_m: f32,
    /// The space the skin encloses twice, m³.
    pub volume_m3: f64,
    /// How many vertices are inside another part.
    pub vertices: usize,
}

/// The posed triangles in a tree, for winding numbers and nearest triangles.
struct Surface<'a> {
    positions: &'a [[f32; 3]],
    triangles: Vec<[u32; 3]>,
    bvh: Bvh,
}

impl<'a> Surface<'a> {
    fn new(positions: &'a [[f32; 3]], indices: &[u32]) -> Self {
        let triangles: Vec<[u32; 3]> = indices.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect();
        let boxes: Vec<Aabb> = triangles.iter().map(|t| Aabb::from_points(t.map(|i| Vec3::from(positions[i as usize])))).collect();
        Self { positions, bvh: Bvh::from_leaves(BvhBuildStrategy::Binned, &boxes), triangles }
    }

    fn corners(&self, t: u32) -> [Vec3; 3] {
        self.triangles[t as usize].map(|i| Vec3::from(self.positions[i as usize]))
    }

    /// The winding number at `x`: the signed crossings along the first of [`RAYS`], and where
    /// that says 2 or more, the median of all three.
    fn winding(&self, x: Vec3) -> i32 {
        let mut hits = Vec::new();
        let mut along = |d: Vec3| {
            hits.clear();
            self.crossings(x, d, &mut hits);
            hits.iter().map(|h| -h.1).sum::<i32>()
        };
        let a = along(RAYS[0]);
        if a < 2 {
            return a;
        }
        let (b, c) = (along(RAYS[1]), along(RAYS[2]));
        a.min(b).max(a.max(b).min(c))
    }

    /// The crossings of the ray from `x` along `d` into `hits`: how far along, and +1 where it
    /// enters the surface, −1 where it leaves (by the triangle's winding; Möller and Trumbore's
    /// ray–triangle test, the tree's boxes by slabs).
    fn crossings(&self, x: Vec3, d: Vec3, hits: &mut Vec<(f32, i32)>) {
        let inv = d.recip();
        let meets = |b: &Aabb| {
            let (t0, t1) = ((b.mins - x) * inv, (b.maxs - x) * inv);
            t0.min(t1).max_element().max(0.0) <= t0.max(t1).min_element()
        };
        for t in self.bvh.leaves(|node| meets(&node.aabb())) {
            let [a, b, c] = self.corners(t);
            let (e1, e2) = (b - a, c - a);
            let p = d.cross(e2);
            let det = e1.dot(p);
            if det == 0.0 {
                continue;
            }
            let s = x - a;
            let u = s.dot(p) / det;
            let q = s.cross(e1);
            let v = d.dot(q) / det;
            let t = e2.dot(q) / det;
            if u >= 0.0 && v >= 0.0 && u + v <= 1.0 && t > 0.0 {
                // Against the outward normal e1 × e2 it enters.
                hits.push((t, if det > 0.0 { 1 } else { -1 }));
            }
        }
    }

    /// The space of winding number 2 or more inside `bounds` (m³), line by line along x.
    fn shared_volume(&self, bounds: &Aabb, whole: &Aabb) -> f64 {
        let mut hits = Vec::new();
        let mut volume = 0.0f64;
        let extent = bounds.maxs - bounds.mins;
        let (ny, nz) = ((extent.y / SPACING).ceil() as usize, (extent.z / SPACING).ceil() as usize);
        for j in 0..ny {
            for k in 0..nz {
                // (Off the grid of whole spacings, so as to miss the mesh's vertices.)
                let (y, z) = (bounds.mins.y + (j as f32 + 0.4142) * SPACING, bounds.mins.z + (k as f32 + 0.7321) * SPACING);
                let start = Vec3::new(whole.mins.x - 0.01, y, z);
                hits.clear();
                self.crossings(start, Vec3::X, &mut hits);
                hits.sort_unstable_by(|a, b| a.0.total_cmp(&b.0));
                let mut w = 0;
                for pair in hits.windows(2) {
                    w += pair[0].1;
                    if w >= 2 {
                        let (a, b) = ((start.x + pair[0].0).max(bounds.mins.x), (start.x + pair[1].0).min(bounds.maxs.x));
                        volume += f64::from((b - a).max(0.0));
                    }
                }
            }
        }
        volume * f64::from(SPACING) * f64::from(SPACING)
    }

    /// The distance from `x` to the nearest triangle with no vertex of part `own`.
    fn distance_to_others(&self, x: Vec3, parts: &[u8], own: u8) -> f32 {
        let found = self.bvh.find_best(
            f32::MAX,
            |node, _| {
                let b = node.aabb();
                (b.mins - x).max(x - b.maxs).max(Vec3::ZERO).length()
            },
            |t, _| {
                let tri = self.triangles[t as usize];
                (!tri.iter().any(|&v| parts[v as usize] == own)).then(|| triangle_closest(x, self.corners(t)).distance(x))
            },
        );
        found.map_or(f32::INFINITY, |(_, d)| d)
    }
}

/// The self-contact of the closed, outward-oriented skin `positions`/`indices` whose vertex
/// `v` belongs to part `parts[v]`.
///
/// # Panics
/// If `parts` does not have one entry per vertex.
#[must_use]
pub fn self_contact(positions: &[[f32; 3]], indices: &[u32], parts: &[u8]) -> SelfContact {
    assert_eq!(parts.len(), positions.len(), "one part per vertex");
    let surface = Surface::new(positions, indices);
    let normals = vertex_normals(positions, indices);
    let mut contact = SelfContact::default();
    // Per vertex, its longest edge: the surface inside another part lies within it of the
    // vertices inside.
    let mut edge = vec![0.0f32; positions.len()];
    for [a, b] in edges(indices).into_iter().map(|e| e.map(|v| v as usize)) {
        let l = Vec3::from(positions[a]).distance(Vec3::from(positions[b]));
        edge[a] = edge[a].max(l);
        edge[b] = edge[b].max(l);
    }
    // Per part, the triangles with none of its vertices (made when first needed).
    let mut others: Vec<Option<Vec<u32>>> = Vec::new();
    let mut inside = Vec::new();
    for (v, (p, n)) in positions.iter().zip(&normals).enumerate() {
        let p = Vec3::from(*p);
        if surface.winding(p - Vec3::from(*n) * UNDER) >= 2 {
            let own = usize::from(parts[v]);
            if others.len() <= own {
                others.resize(own + 1, None);
            }
            let others = others[own].get_or_insert_with(|| surface.triangles.iter().filter(|t| !t.iter().any(|&i| parts[i as usize] == parts[v])).flatten().copied().collect());
            if winding_number(positions, others, p) < 0.5 {
                continue;
            }
            let depth = surface.distance_to_others(p, parts, parts[v]);
            if depth.is_finite() {
                contact.depth_m = contact.depth_m.max(depth);
                contact.vertices += 1;
                inside.push((p, depth + edge[v]));
            }
        }
    }
    if let Some(bounds) = inside.iter().map(|&(p, reach)| Aabb::new(p - reach, p + reach)).reduce(|a, b| a.merged(&b)) {
        let whole = Aabb::from_points(positions.iter().map(|p| Vec3::from(*p)));
        contact.volume_m3 = surface.shared_volume(&bounds, &whole);
    }
    contact
}
