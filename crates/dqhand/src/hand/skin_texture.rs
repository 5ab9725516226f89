//! The built-in hand's skin maps, drawn from its anatomy on its UVs (issue 32): the flexion
//! creases of the fingers and the thumb, the palm's three main lines (distal and proximal
//! transverse, thenar) and the wrist creases on the palm's maps; the knuckles' wrinkles on the
//! back's; fine pores and a slow variation of tone on both, redder over the knuckles and the
//! finger pads. The nails are painted on the back's maps where the skin over each nail plate
//! projects (found by tracing the shape's distance field down onto the back, so the thumbnail,
//! which faces sideways, is painted where its own skin reads the map): the nail bed, the
//! lunula, the free edge and the cuticle round the rim.
//!
//! Each feature is a groove of a height field (a Gaussian profile across a polyline) that
//! also darkens the albedo; the normal map is the height field's slope. Where the creases lie
//! follows the surface anatomy of the palm (Bugbee and Botte 1993, "Surface anatomy of the
//! hand", Clin. Orthop. 296:122; Kapandji, *The Physiology of the Joints*, vol. 1): the
//! interphalangeal creases at their joints (the proximal one doubled), the finger's base
//! crease a third of the way along the proximal phalanx, the distal palmar crease from the
//! ulnar edge at the level of the little finger's MCP to between the index and middle fingers,
//! the proximal one from the radial edge above the index MCP obliquely across, the thenar one
//! round the thenar eminence to the wrist. Every distance is a fraction of the hand's length
//! or breadth, or of the finger's breadth at its joint, so the maps scale with the hand.
//!
//! The UVs are [`PalmPlane`]'s projection, the same for the back and the palm: the two maps
//! are drawn on the same plane coordinates, each with its side's features.

use glam::{Vec2, Vec3};
use rayon::prelude::*;

use super::anthropometry::Anatomy;
use super::shape::{HandShape, NAIL_OUTLINE};
use crate::appearance::{SkinImage, SkinMaps};
use crate::kinematics::webxr;

/// Texels across the hand (u).
pub const WIDTH: u32 = 640;
/// Texels along it (v): on the default hand, 0.24 mm a texel both ways.
pub const HEIGHT: u32 = 1024;

/// The skin's tone, linear RGB (sRGB `#e0a98f`, the viewer's flat colour before the maps).
const TONE: Vec3 = Vec3::new(0.745, 0.397, 0.275);
/// A crease's colour relative to the skin around it.
const CREASE: Vec3 = Vec3::new(0.72, 0.62, 0.6);
/// The nail bed, the lunula and the free edge, linear RGB.
const NAIL_BED: Vec3 = Vec3::new(0.80, 0.46, 0.42);
const LUNULA: Vec3 = Vec3::new(0.86, 0.68, 0.64);
const FREE_EDGE: Vec3 = Vec3::new(0.92, 0.86, 0.78);
/// How far past a nail's outline (in units of it) its cuticle is painted.
const CUTICLE: f32 = 1.12;

/// The UV projection: the hand's box seen along the palm's normal, u across the hand (radial
/// side at u = 1 on both sides' hands, so a left hand's UVs are a right one's), v from the
/// end of the forearm stub behind the wrist to beyond the fingertips: no part of the skin,
/// the thumb stretched out radially included, reads a clamped edge of the maps.
#[derive(Clone, Copy, Debug)]
pub(crate) struct PalmPlane {
    /// The radial direction's x (−1 for a right hand, +1 for a left one).
    radial: f32,
    /// The box's x at u = 0 (its ulnar side), and its width across.
    ulnar: f32,
    across: f32,
    /// The box's z at v = 0 (behind the wrist), and its length.
    behind: f32,
    along: f32,
    /// A millimetre of the default hand (0.19 m long), scaled to this one: the features' unit.
    mm: f32,
}

impl PalmPlane {
    pub fn new(anatomy: &Anatomy, shape: &HandShape, length: f32) -> Self {
        // The shape's box has a margin of 0.1 breadths for its grid; half of it is kept.
        let [lo, hi] = shape.bounds;
        let inset = 0.05 * anatomy.breadth;
        let radial = anatomy.radial.x.signum();
        let ulnar = if radial < 0.0 { hi.x - inset } else { lo.x + inset };
        Self { radial, ulnar, across: hi.x - lo.x - 2.0 * inset, behind: hi.z - inset, along: hi.z - lo.z - 2.0 * inset, mm: 1e-3 * length / 0.19 }
    }

    /// The texture coordinates of bind-space `p`.
    pub fn uv(&self, p: Vec3) -> [f32; 2] {
        [self.radial * (p.x - self.ulnar) / self.across, (self.behind - p.z) / self.along]
    }

    /// The plane point (x, z) of texture coordinates (u, v).
    fn point(&self, u: f32, v: f32) -> Vec2 {
        Vec2::new(self.ulnar + self.radial * u * self.across, self.behind - v * self.along)
    }
}

/// A groove along a polyline of the plane (x, z).
struct Groove {
    points: Vec<Vec2>,
    /// Half width of the Gaussian profile (m).
    width: f32,
    /// Depth at the middle (m).
    depth: f32,
    /// The box holding what it reaches: lower and upper corners.
    reach: (Vec2, Vec2),
}

impl Groove {
    fn new(points: Vec<Vec2>, width: f32, depth: f32) -> Self {
        let (lo, hi) = points.iter().fold((Vec2::INFINITY, Vec2::NEG_INFINITY), |(lo, hi), &p| (lo.min(p), hi.max(p)));
        Self { points, width, depth, reach: (lo - 3.0 * width, hi + 3.0 * width) }
    }

    /// A quadratic Bézier from `a` through control `c` to `b`, in eight pieces.
    fn curve(a: Vec2, c: Vec2, b: Vec2, width: f32, depth: f32) -> Self {
        let points = (0..=8).map(|k| k as f32 / 8.0).map(|t| a * (1.0 - t) * (1.0 - t) + c * 2.0 * t * (1.0 - t) + b * t * t).collect();
        Self::new(points, width, depth)
    }

    /// Its profile at `p`: 0 far away, 1 on the line.
    fn profile(&self, p: Vec2) -> f32 {
        let d = self.points.windows(2).map(|s| segment_distance(p, s[0], s[1])).fold(f32::INFINITY, f32::min);
        (-(d / self.width).powi(2)).exp()
    }
}

fn segment_distance(p: Vec2, a: Vec2, b: Vec2) -> f32 {
    let ab = b - a;
    let t = ((p - a).dot(ab) / ab.length_squared().max(f32::MIN_POSITIVE)).clamp(0.0, 1.0);
    p.distance(a + ab * t)
}

/// A round patch of colour: `tint` multiplies the skin's, fully at the centre, fading out by
/// `radius`.
struct Blush {
    centre: Vec2,
    radius: f32,
    tint: Vec3,
}

/// The features of one side.
struct Side {
    grooves: Vec<Groove>,
    blushes: Vec<Blush>,
}

/// Draws the back's and the palm's maps, on `plane`, of a hand `length` long, `shape` modelled
/// around `anatomy`.
pub(crate) fn draw(anatomy: &Anatomy, shape: &HandShape, length: f32, plane: PalmPlane) -> [SkinMaps; 2] {
    let (back, palm) = features(anatomy, length, plane.mm);
    let nails = nail_coordinates(shape, plane);
    [paint(&back, plane, &nails, 1), paint(&palm, plane, &[], 2)]
}

/// For each texel of the back's maps over a nail: where the skin it maps to lies in that
/// nail's plate, across and along (+1 the proximal end) in units of the nail's outline, out
/// to its cuticle; `None` elsewhere. The skin is found by sphere tracing the shape's distance
/// field down (−Y) from above the hand, within each nail's box in the plane.
fn nail_coordinates(shape: &HandShape, plane: PalmPlane) -> Vec<Option<Vec2>> {
    let (w, h) = (WIDTH as usize, HEIGHT as usize);
    let mut out = vec![None; w * h];
    let (top, bottom) = (shape.bounds[1].y, shape.bounds[0].y);
    let outline = NAIL_OUTLINE.sqrt();
    for (to_local, radii) in shape.nail_plates() {
        let to_world = to_local.inverse();
        let flat = |v: Vec3| Vec2::new(v.x, v.z).abs();
        let centre = Vec3::from(to_world.translation);
        let half = (flat(to_world.transform_vector3(Vec3::X * radii.x)) + flat(to_world.transform_vector3(Vec3::Z * radii.z))) * CUTICLE;
        let [u0, v0] = plane.uv(centre - Vec3::new(half.x, 0.0, half.y));
        let [u1, v1] = plane.uv(centre + Vec3::new(half.x, 0.0, half.y));
        let cols = ((u0.min(u1) * w as f32) as usize).min(w)..((u0.max(u1) * w as f32).ceil() as usize).min(w);
        let rows = ((v0.min(v1) * h as f32) as usize).min(h)..((v0.max(v1) * h as f32).ceil() as usize).min(h);
        for row in rows {
            for col in cols.clone() {
                let p = plane.point((col as f32 + 0.5) / w as f32, (row as f32 + 0.5) / h as f32);
                // (The field is a lower bound of the distance: no step passes the skin.)
                let mut y = top;
                let skin = loop {
                    let d = shape.distance(Vec3::new(p.x, y, p.y));
                    if d < 0.01 * plane.mm {
                        break Some(Vec3::new(p.x, y, p.y));
                    }
                    y -= d.max(0.02 * plane.mm);
                    if y < bottom {
                        break None;
                    }
                };
                let Some(q) = skin.map(|s| to_local.transform_point3(s)) else { continue };
                let at = Vec2::new(q.x / radii.x, q.z / radii.z) / outline;
                if q.y > 0.0 && at.length() <= CUTICLE {
                    out[row * w + col] = Some(at);
                }
            }
        }
    }
    out
}

/// The features of the back and of the palm of a hand `l` long, in units of `mm`.
fn features(anatomy: &Anatomy, l: f32, mm: f32) -> (Side, Side) {
    let b = anatomy.breadth;
    let joint = |name: &str| webxr::JOINT_NAMES.iter().position(|&n| n == name).unwrap_or(0);
    let at = |j: usize| {
        let p = anatomy.position(j);
        Vec2::new(p.x, p.z)
    };
    let radial = Vec2::new(anatomy.radial.x, 0.0);
    // Toward the wrist (+Z).
    let proximal = Vec2::Y;
    let mut back = Side { grooves: Vec::new(), blushes: Vec::new() };
    let mut palm = Side { grooves: Vec::new(), blushes: Vec::new() };
    for (f, finger) in webxr::FINGERS.iter().enumerate() {
        let first = joint(&format!("{finger}-metacarpal")) + 1;
        let tip = joint(&format!("{finger}-tip"));
        for j in first..tip {
            let (c, next) = (at(j), at(j + 1));
            let prev = at(j - 1);
            let axis = (next - prev).normalize_or(-proximal);
            let across = axis.perp();
            let r = anatomy.radius[j];
            let line = |centre: Vec2, half: f32, bow: f32| Groove::curve(centre - across * half, centre + axis * bow, centre + across * half, 0.35 * mm, 0.3 * mm);
            let base = j == first;
            if !base || f == 0 {
                // An interphalangeal crease (the thumb's MCP too): doubled at the PIP.
                let pip = f > 0 && j == first + 1;
                for k in if pip { [-1.0f32, 1.0].as_slice() } else { [0.0f32].as_slice() } {
                    palm.grooves.push(line(c + axis * (k * 0.8 * mm), 0.8 * r, 0.12 * r));
                }
                // The knuckle's wrinkles on the back, longer over the PIP.
                let count = if pip { 5 } else { 3 };
                for k in 0..count {
                    let offset = (k as f32 - (count - 1) as f32 / 2.0) * 0.9 * mm;
                    let half = (if pip { 0.6 } else { 0.45 }) * r * (1.0 - 0.12 * (offset / mm).abs());
                    let mut g = line(c + axis * offset, half, -0.25 * r);
                    (g.width, g.depth) = (0.28 * mm, 0.09 * mm);
                    back.grooves.push(g);
                }
                back.blushes.push(Blush { centre: c, radius: 1.1 * r, tint: Vec3::new(1.0, 0.9, 0.88) });
            } else {
                // The finger's base crease, a third along the proximal phalanx; doubled on the
                // middle and ring fingers.
                let at_base = c.lerp(next, 0.33);
                for k in if f == 2 || f == 3 { [-1.0f32, 1.0].as_slice() } else { [0.0f32].as_slice() } {
                    palm.grooves.push(line(at_base + axis * (k * 1.0 * mm), 0.85 * r, 0.1 * r));
                }
                // The metacarpal head: a faint pair of wrinkles, and redder skin.
                for k in [-0.5f32, 0.5] {
                    let mut g = line(c + axis * (k * 1.2 * mm), 0.5 * r, -0.2 * r);
                    (g.width, g.depth) = (0.3 * mm, 0.05 * mm);
                    back.grooves.push(g);
                }
                back.blushes.push(Blush { centre: c, radius: 1.4 * r, tint: Vec3::new(1.0, 0.92, 0.9) });
            }
            if j + 1 == tip {
                // The finger pad, pinker.
                palm.blushes.push(Blush { centre: c.lerp(next, 0.55), radius: 1.2 * r, tint: Vec3::new(1.0, 0.88, 0.86) });
            }
        }
    }
    // The palm's lines (plane coordinates from the knuckles and the wrist at the origin).
    let mcp = |f: usize| at(joint(&format!("{}-phalanx-proximal", webxr::FINGERS[f])));
    let r_mcp = |f: usize| anatomy.radius[joint(&format!("{}-phalanx-proximal", webxr::FINGERS[f]))];
    let (index, middle, ring, little) = (mcp(1), mcp(2), mcp(3), mcp(4));
    let ulnar = -radial;
    let deep = |g: Groove| Groove::new(g.points, 0.45 * mm, 0.4 * mm);
    let distal = Groove::curve(little + ulnar * 1.1 * r_mcp(4) + proximal * 0.035 * l, ring + proximal * 0.05 * l, index.lerp(middle, 0.5) + proximal * 0.02 * l, 0.0, 0.0);
    let start = index + radial * 1.1 * r_mcp(1) + proximal * 0.085 * l;
    let proximal_line = Groove::curve(start, middle + proximal * 0.12 * l, ring + ulnar * 0.4 * r_mcp(3) + proximal * 0.17 * l, 0.0, 0.0);
    let thumb_mc = at(joint("thumb-metacarpal")).lerp(at(joint("thumb-phalanx-proximal")), 0.5);
    let thenar = Groove::curve(start, thumb_mc + ulnar * 0.45 * b + proximal * 0.02 * l, radial * 0.06 * b + proximal * -0.03 * l, 0.0, 0.0);
    palm.grooves.extend([distal, proximal_line, thenar].map(deep));
    for z in [-0.006, -0.02] {
        let (a, c) = (radial * 0.3 * b + proximal * z * l, ulnar * 0.3 * b + proximal * z * l);
        palm.grooves.push(Groove::curve(a, a.lerp(c, 0.5) - proximal * 0.01 * l, c, 0.4 * mm, 0.18 * mm));
    }
    // The thenar and hypothenar eminences, a little redder.
    palm.blushes.push(Blush { centre: thumb_mc + ulnar * 0.12 * b, radius: 0.2 * b, tint: Vec3::new(1.0, 0.93, 0.92) });
    palm.blushes.push(Blush { centre: little + ulnar * 0.05 * b + proximal * 0.2 * l, radius: 0.16 * b, tint: Vec3::new(1.0, 0.94, 0.93) });
    (back, palm)
}

/// A hash of integer lattice coordinates to [0, 1).
fn lattice(x: i32, y: i32, seed: u32) -> f32 {
    let mut h = (x as u32).wrapping_mul(0x8da6_b343) ^ (y as u32).wrapping_mul(0xd816_3841) ^ seed.wrapping_mul(0xcb1a_b31f);
    h ^= h >> 13;
    h = h.wrapping_mul(0x5bd1_e995);
    h ^= h >> 15;
    (h >> 8) as f32 / (1u32 << 24) as f32
}

/// Smooth value noise at `p` (in lattice cells), in [0, 1).
fn value_noise(p: Vec2, seed: u32) -> f32 {
    let (i, f) = (p.floor(), p - p.floor());
    let s = f * f * (Vec2::splat(3.0) - 2.0 * f);
    let (x, y) = (i.x as i32, i.y as i32);
    let (a, b, c, d) = (lattice(x, y, seed), lattice(x + 1, y, seed), lattice(x, y + 1, seed), lattice(x + 1, y + 1, seed));
    (a + (b - a) * s.x) + ((c + (d - c) * s.x) - (a + (b - a) * s.x)) * s.y
}

/// Linear to sRGB, one channel, as a byte.
fn srgb(c: f32) -> u8 {
    let c = c.clamp(0.0, 1.0);
    let s = if c <= 0.003_130_8 { 12.92 * c } else { 1.055 * c.powf(1.0 / 2.4) - 0.055 };
    (s * 255.0 + 0.5) as u8
}

/// Paints one side's maps: the height field and the albedo texel by texel (rows in parallel),
/// then the normals from the height's slope.
fn paint(side: &Side, plane: PalmPlane, nails: &[Option<Vec2>], seed: u32) -> SkinMaps {
    let (w, h) = (WIDTH as usize, HEIGHT as usize);
    let texel = Vec2::new(plane.across / w as f32, plane.along / h as f32);
    let mm = plane.mm;
    let mut height = vec![0.0f32; w * h];
    let mut albedo = vec![0u8; 3 * w * h];
    height.par_chunks_mut(w).zip(albedo.par_chunks_mut(3 * w)).enumerate().for_each(|(row, (heights, colours))| {
        let v = (row as f32 + 0.5) / h as f32;
        let z = plane.point(0.5, v).y;
        let grooves: Vec<&Groove> = side.grooves.iter().filter(|g| (g.reach.0.y..=g.reach.1.y).contains(&z)).collect();
        for col in 0..w {
            let p = plane.point((col as f32 + 0.5) / w as f32, v);
            // Pores and fine wrinkles: two octaves of noise a few tenths of a millimetre wide.
            let fine = value_noise(p / (0.35 * mm), seed) + 0.5 * value_noise(p / (0.9 * mm), seed + 7);
            let mut depth = 0.012 * mm * fine;
            let mut crease = 0.0f32;
            for g in grooves.iter().filter(|g| p.x >= g.reach.0.x && p.x <= g.reach.1.x) {
                let k = g.profile(p);
                depth += g.depth * k;
                crease = crease.max(k * (g.depth / (0.3 * mm)).min(1.0));
            }
            // The tone: a slow variation, blushes, creases darker.
            let slow = 0.94 + 0.08 * value_noise(p / (7.0 * mm), seed + 13) + 0.03 * (fine - 0.75);
            let mut colour = TONE * slow;
            for blush in &side.blushes {
                let t = (1.0 - p.distance(blush.centre) / blush.radius).clamp(0.0, 1.0);
                colour *= Vec3::ONE.lerp(blush.tint, t * t * (3.0 - 2.0 * t));
            }
            colour *= Vec3::ONE.lerp(CREASE, crease);
            if let Some(q) = nails.get(row * w + col).copied().flatten() {
                // The lunula at the proximal end, the free edge at the distal one, a darker
                // cuticle in a shallow groove round the rim.
                let rim = q.length();
                let mut nail = NAIL_BED * (0.97 + 0.06 * value_noise(p / (0.6 * mm), seed + 21));
                nail = nail.lerp(LUNULA, smoothstep(0.45, 0.7, q.y) * (1.0 - smoothstep(0.75, 0.95, rim)));
                nail = nail.lerp(FREE_EDGE, smoothstep(-0.72, -0.88, q.y));
                let cuticle = smoothstep(0.9, 1.0, rim);
                colour = nail.lerp(colour * Vec3::new(0.86, 0.8, 0.8), cuticle);
                depth = 0.1 * mm * (1.0 - ((rim - 1.0) / (CUTICLE - 1.0)).abs().min(1.0));
            }
            heights[col] = -depth;
            colours[3 * col..3 * col + 3].copy_from_slice(&[srgb(colour.x), srgb(colour.y), srgb(colour.z)]);
        }
    });
    // Tangent-space normals: +X along u, +Y up the image (against v), +Z out of the skin.
    let mut normal = vec![0u8; 3 * w * h];
    normal.par_chunks_mut(3 * w).enumerate().for_each(|(row, out)| {
        for col in 0..w {
            let at = |c: usize, r: usize| height[r.min(h - 1) * w + c.min(w - 1)];
            let du = (at(col + 1, row) - at(col.saturating_sub(1), row)) / (2.0 * texel.x);
            let dv = (at(col, row + 1) - at(col, row.saturating_sub(1))) / (2.0 * texel.y);
            let n = Vec3::new(-du, dv, 1.0).normalize();
            let byte = |x: f32| (127.5 + 127.5 * x).round().clamp(0.0, 255.0) as u8;
            out[3 * col..3 * col + 3].copy_from_slice(&[byte(n.x), byte(n.y), byte(n.z)]);
        }
    });
    SkinMaps { albedo: SkinImage { width: WIDTH, height: HEIGHT, rgb: albedo }, normal: SkinImage { width: WIDTH, height: HEIGHT, rgb: normal } }
}

fn smoothstep(a: f32, b: f32, x: f32) -> f32 {
    let t = ((x - a) / (b - a)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each nail plate is on the maps, and painted over hundreds of texels.
    #[test]
    fn every_nail_is_painted() {
        let anatomy = Anatomy::new(0.19, 0.085, Vec3::NEG_X);
        let shape = HandShape::new(&anatomy);
        let plane = PalmPlane::new(&anatomy, &shape, 0.19);
        let nails = nail_coordinates(&shape, plane);
        for (to_local, radii) in shape.nail_plates() {
            let c = Vec3::from(to_local.inverse().translation);
            let [u, v] = plane.uv(c);
            let (col, row) = ((u * WIDTH as f32) as usize, (v * HEIGHT as f32) as usize);
            assert!((0.0..1.0).contains(&u) && (0.0..1.0).contains(&v), "a nail at {c} is off the maps: {u} {v}");
            let (rows, cols) = (row.saturating_sub(40)..(row + 40).min(HEIGHT as usize), col.saturating_sub(40)..(col + 40).min(WIDTH as usize));
            let painted = rows.flat_map(|r| cols.clone().map(move |c| (r, c))).filter(|&(r, c)| nails[r * WIDTH as usize + c].is_some()).count();
            // A nail some 10 mm by 12 mm, about 40 by 50 texels; the thumb's foreshortened.
            assert!(painted > 500, "a nail at {c} of {radii} has {painted} texels");
        }
    }
}
