//! Points and line segments.

use glam::Vec3;

/// Distance from `x` to the segment `a`–`b` (to `a` if the segment has no length).
#[must_use]
pub fn segment_distance(x: Vec3, a: Vec3, b: Vec3) -> f32 {
    x.distance(segment_closest(x, a, b))
}

/// The point of the segment `a`–`b` closest to `x` (`a` if the segment has no length).
#[must_use]
pub fn segment_closest(x: Vec3, a: Vec3, b: Vec3) -> Vec3 {
    let ab = b - a;
    let t = ((x - a).dot(ab) / ab.length_squared().max(1e-18)).clamp(0.0, 1.0);
    a + t * ab
}

/// The closest points of the segments `p0`–`p1` and `q0`–`q1` (Ericson, *Real-Time Collision
/// Detection*, 5.1.9), first on `p`, then on `q`.
#[must_use]
pub fn segment_segment_closest(p0: Vec3, p1: Vec3, q0: Vec3, q1: Vec3) -> (Vec3, Vec3) {
    const EPS: f32 = 1e-12;
    let d1 = p1 - p0;
    let d2 = q1 - q0;
    let r = p0 - q0;
    let a = d1.length_squared();
    let e = d2.length_squared();
    let f = d2.dot(r);
    let (s, t) = if a <= EPS && e <= EPS {
        (0.0, 0.0)
    } else if a <= EPS {
        (0.0, (f / e).clamp(0.0, 1.0))
    } else {
        let c = d1.dot(r);
        if e <= EPS {
            ((-c / a).clamp(0.0, 1.0), 0.0)
        } else {
            let b = d1.dot(d2);
            let denom = a * e - b * b;
            // Parallel segments (to f32's precision): any s will do, 0 is as good as another.
            let s = if denom > 1e-6 * a * e { ((b * f - c * e) / denom).clamp(0.0, 1.0) } else { 0.0 };
            let t = (b * s + f) / e;
            if t < 0.0 {
                ((-c / a).clamp(0.0, 1.0), 0.0)
            } else if t > 1.0 {
                (((b - c) / a).clamp(0.0, 1.0), 1.0)
            } else {
                (s, t)
            }
        }
    };
    (p0 + d1 * s, q0 + d2 * t)
}

/// Whether the triangle is too thin for its normal (the cross product of two edges) to be
/// more than f32's rounding: the sine of its angle at the first corner under 10⁻⁶ (a 1 cm
/// edge with the third corner 10 nm off it). A long thin triangle's normal can be tilted by
/// a tenth, its plane millimetres off its far corners.
#[must_use]
pub fn is_sliver([a, b, c]: [Vec3; 3]) -> bool {
    let (ab, ac) = (b - a, c - a);
    ab.cross(ac).length_squared() <= 1e-12 * ab.length_squared() * ac.length_squared()
}

/// The point of the triangle `a`, `b`, `c` closest to `x` (Ericson 5.1.5, by Voronoi regions;
/// a sliver, [`is_sliver`], by its edges).
#[must_use]
pub fn triangle_closest(x: Vec3, [a, b, c]: [Vec3; 3]) -> Vec3 {
    let ab = b - a;
    let ac = c - a;
    if is_sliver([a, b, c]) {
        return [segment_closest(x, a, b), segment_closest(x, b, c), segment_closest(x, c, a)]
            .into_iter()
            .min_by(|p, q| p.distance_squared(x).total_cmp(&q.distance_squared(x)))
            .unwrap_or(a);
    }
    let ap = x - a;
    let d1 = ab.dot(ap);
    let d2 = ac.dot(ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = x - b;
    let d3 = ab.dot(bp);
    let d4 = ac.dot(bp);
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return a + ab * (d1 / (d1 - d3));
    }
    let cp = x - c;
    let d5 = ab.dot(cp);
    let d6 = ac.dot(cp);
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return a + ac * (d2 / (d2 - d6));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0 {
        return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
    }
    let denom = 1.0 / (va + vb + vc);
    a + ab * (vb * denom) + ac * (vc * denom)
}

/// The closest points of the segment `p0`–`p1` and the triangle `tri`, first on the segment:
/// where the segment crosses the triangle, that point twice; otherwise the nearest of its
/// ends' feet on the triangle's plane that fall inside the triangle and its nearest points to
/// the triangle's edges (a segment that does not cross a triangle is nearest to it at one of
/// its ends or at an edge, and an end is nearest to the triangle's inside only at its foot).
/// A triangle too thin for its normal to mean anything in f32 ([`is_sliver`]) is its edges.
#[must_use]
pub fn segment_triangle_closest(p0: Vec3, p1: Vec3, tri: [Vec3; 3]) -> (Vec3, Vec3) {
    let [a, b, c] = tri;
    let n = (b - a).cross(c - a);
    let sliver = is_sliver(tri);
    // On the same side of each edge as the triangle (or on an edge).
    let inside = |x: Vec3| (b - a).cross(x - a).dot(n) >= 0.0 && (c - b).cross(x - b).dot(n) >= 0.0 && (a - c).cross(x - c).dot(n) >= 0.0;
    let (s0, s1) = ((p0 - a).dot(n), (p1 - a).dot(n));
    if !sliver && (s0 <= 0.0) != (s1 <= 0.0) {
        let x = p0 + (p1 - p0) * (s0 / (s0 - s1));
        if inside(x) {
            return (x, x);
        }
    }
    let mut best = segment_segment_closest(p0, p1, a, b);
    let mut consider = |pair: (Vec3, Vec3)| {
        if pair.0.distance_squared(pair.1) < best.0.distance_squared(best.1) {
            best = pair;
        }
    };
    consider(segment_segment_closest(p0, p1, b, c));
    consider(segment_segment_closest(p0, p1, c, a));
    if !sliver {
        for (p, s) in [(p0, s0), (p1, s1)] {
            let foot = p - n * (s / n.length_squared());
            if inside(foot) {
                consider((p, foot));
            }
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The least distance between points sampled densely on the segment and the triangle: an
    /// independent reference, at most the sampling's spacing above the true one.
    fn sampled(p0: Vec3, p1: Vec3, [a, b, c]: [Vec3; 3], n: usize) -> f32 {
        let mut best = f32::MAX;
        for i in 0..=n {
            let x = p0 + (p1 - p0) * (i as f32 / n as f32);
            for u in 0..=n {
                for w in 0..=(n - u) {
                    let y = a + (b - a) * (u as f32 / n as f32) + (c - a) * (w as f32 / n as f32);
                    best = best.min(x.distance(y));
                }
            }
        }
        best
    }

    #[test]
    fn segment_triangle_closest_points_match_dense_sampling() {
        let mut seed = 0x2545_f491_4f6c_dd1d_u64;
        let mut next = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 40) as f32 / (1u64 << 24) as f32 * 2.0 - 1.0
        };
        let mut crossing = 0;
        for _ in 0..300 {
            let mut v = || Vec3::new(next(), next(), next());
            let tri = [v(), v(), v()];
            let (p0, p1) = (v(), v());
            let (p, q) = segment_triangle_closest(p0, p1, tri);
            let exact = p.distance(q);
            let reference = sampled(p0, p1, tri, 60);
            // The sampled pairs are real pairs: never nearer than the exact; the spacing (a
            // fortieth of edges up to 2√3 long) bounds how much farther they may be.
            assert!(exact <= reference + 1e-5, "exact {exact} above sampled {reference}");
            assert!(reference - exact <= 0.12, "exact {exact}, sampled {reference}");
            // The points lie on their shapes.
            assert!(segment_distance(p, p0, p1) < 1e-5);
            assert!(triangle_closest(q, tri).distance(q) < 1e-5);
            crossing += usize::from(exact == 0.0);
        }
        // Both cases were met: segments through the triangle and clear of it.
        assert!(crossing > 5 && crossing < 295, "{crossing} crossings");
    }

    #[test]
    fn a_needle_is_its_edges() {
        // Triangles 1–2 cm long whose third corner is on (in f32) or 0.01–1 nm off the line of
        // the other two, in an object's frame (within 5 cm of its origin): their normals are
        // f32's rounding. The segment's distance to one is its distance to the edges (the
        // reference: both sampled densely), never shorter by more than the sampling.
        let at = Vec3::new(0.03, 0.05, -0.02);
        let mut slivers = 0;
        for k in 0..60 {
            let f = k as f32;
            let dir = Vec3::new((0.7 * f).cos(), (1.3 * f).sin(), (0.4 * f).cos()).normalize();
            let side = dir.any_orthonormal_vector();
            let length = 0.01 + 0.01 * (f * 0.37).fract();
            let (a, b) = (at, at + dir * length);
            let off = if k % 2 == 0 { 0.0 } else { 1e-11 * 100f32.powf((f * 0.71).fract()) };
            let c = a + (b - a) * (0.2 + 0.6 * (f * 0.53).fract()) + side * off;
            slivers += usize::from(is_sliver([a, b, c]));
            let up = side.cross(dir) * (0.0005 + 0.002 * (f * 0.29).fract());
            let (p0, p1) = (at + up - dir * 0.003 + side * 0.001 * (f * 0.17).sin(), at + up + dir * 0.02);
            let (p, q) = segment_triangle_closest(p0, p1, [a, b, c]);
            let n = 400;
            let sample = |u: Vec3, v: Vec3, i: usize| u + (v - u) * (i as f32 / n as f32);
            let mut reference = f32::MAX;
            for i in 0..=n {
                let x = sample(p0, p1, i);
                for (u, v) in [(a, b), (b, c), (c, a)] {
                    for j in 0..=n {
                        reference = reference.min(x.distance(sample(u, v, j)));
                    }
                }
            }
            // The samples are under 60 µm apart: the exact is under the sampled, by less than that.
            let exact = p.distance(q);
            assert!(exact <= reference + 1e-6 && reference - exact <= 1e-4, "case {k}: {exact} m against {reference} m sampled");
        }
        assert!(slivers >= 20, "{slivers} of 60 needles are slivers");
    }

    #[test]
    fn a_triangle_without_area_is_its_edges() {
        let (a, c) = (Vec3::ZERO, Vec3::new(1.0, 0.0, 0.0));
        for tri in [[a, a, c], [a, c, (a + c) / 2.0]] {
            let q = triangle_closest(Vec3::new(0.5, 1.0, 0.0), tri);
            assert!(q.distance(Vec3::new(0.5, 0.0, 0.0)) < 1e-6, "{q}");
            let (_, q) = segment_triangle_closest(Vec3::new(2.0, 1.0, 0.0), Vec3::new(2.0, -1.0, 0.0), tri);
            assert!(q.distance(c) < 1e-6, "{q}");
        }
    }
}
