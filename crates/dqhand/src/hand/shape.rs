//! The hand's shape as an implicit surface: a signed distance field built from anatomical
//! parts around the skeleton, smoothly blended.
//!
//! Each part belongs to one bone: two round cones per phalanx (wider at the joints than at the
//! waist), an ellipsoid pad on its palmar side, a dorsal bump over each knuckle, a nail plate
//! on each distal phalanx; flattened round cones along the metacarpals that together make the
//! palm, which narrows toward the wrist; the thenar and hypothenar eminences; a forearm stub
//! closed behind the wrist. Parts blend within their group (the palm, each finger) with a
//! polynomial smooth minimum; each finger then blends into the palm with a wider radius, which
//! forms the webs, while the fingers blend with each other only over a small radius, so that
//! the gaps between them stay open.
//!
//! Besides the distance to the whole hand, the field gives the distance to each bone's own
//! parts, which [`super::weights`] turns into skin weights.

use glam::{Affine3A, Vec3, Vec3A};

use super::anthropometry::Anatomy;
use crate::kinematics::webxr;

/// The palm's group; fingers are groups 1 (thumb) to 5 (little).
const PALM: usize = 0;
const GROUPS: usize = 6;
/// Share of a nail plate's outline (its ellipse's squared radius) that is nail; the rest is
/// under the skin's fold at the rim.
pub(crate) const NAIL_OUTLINE: f32 = 0.8;

/// One solid, in the local frame of its part.
#[derive(Clone, Copy, Debug)]
enum Solid {
    /// A cone with spherical ends of radii `ra` at the origin and `rb` at `(0, 0, −len)`.
    RoundCone { len: f32, ra: f32, rb: f32 },
    /// An ellipsoid centred at the origin with the given semi-axes.
    Ellipsoid { radii: Vec3 },
}

/// A solid placed in the hand: `to_local` maps world points into its frame, whose Y axis is
/// then divided by `squash` (< 1 flattens the part in its dorsal–palmar depth).
#[derive(Clone, Copy, Debug)]
struct Part {
    to_local: Affine3A,
    /// World centre and radius of a sphere around the part.
    bounding: (Vec3, f32),
    squash: f32,
    solid: Solid,
    /// Joint (bone) the part moves with.
    bone: usize,
    group: usize,
    /// Radius over which the part blends into its group.
    blend: f32,
}

impl Solid {
    /// Radius of a sphere around the solid, centred on its frame's origin.
    fn extent(&self) -> f32 {
        match *self {
            Solid::RoundCone { len, ra, rb } => len + ra.max(rb),
            Solid::Ellipsoid { radii } => radii.max_element(),
        }
    }
}

impl Part {
    fn distance(&self, p: Vec3A) -> f32 {
        let mut q = self.to_local.transform_point3a(p);
        q.y /= self.squash;
        let d = match self.solid {
            Solid::RoundCone { len, ra, rb } => round_cone(q, len, ra, rb),
            Solid::Ellipsoid { radii } => ellipsoid(q, radii.into()),
        };
        // The squash shrinks distances along Y at most by `squash`: keep a lower bound.
        d * self.squash
    }
}

/// Signed distance to a round cone along −Z (Quílez's exact formula, specialised to an axis).
fn round_cone(q: Vec3A, len: f32, ra: f32, rb: f32) -> f32 {
    let x = q.truncate().length();
    let y = -q.z;
    // The cone's side is tangent to both spheres; `c` and `s` are its slope's cosine and sine.
    let s = (ra - rb) / len;
    let c = (1.0 - s * s).max(0.0).sqrt();
    let k = -x * s + y * c;
    if k < 0.0 {
        return (x * x + y * y).sqrt() - ra;
    }
    if k > c * len {
        return (x * x + (y - len) * (y - len)).sqrt() - rb;
    }
    x * c + y * s - ra
}

/// Signed distance to an ellipsoid, approximately (exact on the axes, a close bound elsewhere).
fn ellipsoid(q: Vec3A, radii: Vec3A) -> f32 {
    let k0 = (q / radii).length();
    let k1 = (q / (radii * radii)).length();
    if k1 == 0.0 {
        -radii.min_element()
    } else {
        k0 * (k0 - 1.0) / k1
    }
}

/// Polynomial smooth minimum: equal to `min(a, b)` where they differ by more than `k`, rounded
/// in between (a fillet of radius about `k`).
fn smooth_min(a: f32, b: f32, k: f32) -> f32 {
    let h = (k - (a - b).abs()).max(0.0) / k;
    a.min(b) - h * h * k * 0.25
}

/// The hand's signed distance field (negative inside, metres).
#[derive(Clone, Debug)]
pub(crate) struct HandShape {
    parts: Vec<Part>,
    /// The nail plates among the parts.
    nails: Vec<usize>,
    /// Blend radius of each finger into the palm.
    web: f32,
    /// Blend radius between fingers: small, to round the crease where their bases overlap
    /// without closing the gaps between them.
    between: f32,
    /// Axis-aligned bounds of the whole hand, with a margin.
    pub bounds: [Vec3; 2],
    /// Grid spacing that resolves the narrowest gap and thinnest part: surface nets on a
    /// coarser grid may join two sheets in one cell and leave a non-manifold edge.
    pub finest_feature: f32,
}

impl HandShape {
    /// Models the hand around `anatomy`'s skeleton.
    pub fn new(anatomy: &Anatomy) -> Self {
        let b = anatomy.breadth;
        let mut parts = Vec::new();
        let mut nails = Vec::new();
        let frame = |j: usize| anatomy.frames[j];
        let joint = |name: &str| webxr::JOINT_NAMES.iter().position(|&n| n == name).unwrap_or(0);
        // A round cone from point `a` to `c` in the frame of joint `j` (for its up vector).
        let cone = |j: usize, a: Vec3, c: Vec3, ra: f32, rb: f32, squash: f32, group: usize, blend: f32| {
            let f = frame(j);
            let dir = (c - a).normalize();
            // Keep the bone's dorsal axis, turned to be perpendicular to the cone's axis.
            let up = Vec3::from(f.matrix3.y_axis);
            let z = -dir;
            let x = up.cross(z).normalize_or(Vec3::from(f.matrix3.x_axis));
            let to_world = Affine3A::from_mat3_translation(glam::Mat3::from_cols(x, z.cross(x), z), a);
            Part {
                to_local: to_world.inverse(),
                // Tighter than `Solid::extent`: centred on the axis' midpoint.
                bounding: (a.lerp(c, 0.5), 0.5 * a.distance(c) + ra.max(rb)),
                squash,
                solid: Solid::RoundCone { len: a.distance(c), ra, rb },
                bone: j,
                group,
                blend,
            }
        };
        // A solid at `offset` in joint `j`'s frame.
        let placed = |j: usize, offset: Vec3, solid: Solid, squash: f32, group: usize, blend: f32| Part {
            to_local: (frame(j) * Affine3A::from_translation(offset)).inverse(),
            bounding: (frame(j).transform_point3(offset), solid.extent()),
            squash,
            solid,
            bone: j,
            group,
            blend,
        };

        // Palm: the wrist and forearm stub, the metacarpals, the knuckles, the eminences.
        let wrist = joint("wrist");
        let wrist_r = 0.3 * b;
        parts.push(cone(wrist, Vec3::new(0.0, -0.03 * b, 0.25 * b), Vec3::new(0.0, -0.03 * b, -0.45 * b), wrist_r, wrist_r * 1.05, 0.62, PALM, 0.2 * b));
        for f in 1..5 {
            let cmc = joint(&format!("{}-metacarpal", webxr::FINGERS[f]));
            let mcp = cmc + 1;
            let down = -Vec3::from(frame(cmc).matrix3.y_axis) * 0.03 * b;
            let (a, c) = (anatomy.position(cmc) + down, anatomy.position(mcp) + down);
            let (ra, rc) = (anatomy.radius[cmc], 0.65 * anatomy.radius[cmc]);
            parts.push(cone(cmc, a, c.lerp(a, 0.02), ra, rc.max(anatomy.radius[mcp] * 1.1), 0.78, PALM, 0.12 * b));
            // The metacarpal head's dorsal bump.
            let r = 0.7 * anatomy.radius[mcp];
            parts.push(placed(cmc, Vec3::new(0.0, 0.02 * b, -(anatomy.position(mcp) - anatomy.position(cmc)).length() + 0.2 * r), Solid::Ellipsoid { radii: Vec3::new(r, 0.9 * r, 1.1 * r) }, 1.0, PALM, 0.06 * b));
        }
        let thumb_mc = joint("thumb-metacarpal");
        let mc_len = anatomy.position(thumb_mc + 1).distance(anatomy.position(thumb_mc));
        parts.push(cone(thumb_mc, anatomy.position(thumb_mc), anatomy.position(thumb_mc + 1), anatomy.radius[thumb_mc] * 0.8, anatomy.radius[thumb_mc + 1] * 1.05, 0.85, PALM, 0.1 * b));
        // Thenar eminence: the muscle bulk on the palmar side of the thumb's metacarpal.
        let ulnar = -anatomy.radial;
        let thenar_offset = frame(thumb_mc).inverse().transform_vector3(ulnar * 0.08 * b) + Vec3::new(0.0, -0.05 * b, -0.42 * mc_len);
        parts.push(placed(thumb_mc, thenar_offset, Solid::Ellipsoid { radii: Vec3::new(0.17 * b, 0.13 * b, 0.62 * mc_len) }, 1.0, PALM, 0.12 * b));
        // Hypothenar eminence along the little finger's metacarpal, on the ulnar palmar edge.
        let little_mc = joint("pinky-finger-metacarpal");
        let little_len = anatomy.position(little_mc + 1).distance(anatomy.position(little_mc));
        let hyp_offset = frame(little_mc).inverse().transform_vector3(ulnar * 0.03 * b) + Vec3::new(0.0, -0.07 * b, -0.42 * little_len);
        parts.push(placed(little_mc, hyp_offset, Solid::Ellipsoid { radii: Vec3::new(0.13 * b, 0.11 * b, 0.5 * little_len) }, 1.0, PALM, 0.12 * b));

        // Fingers: phalanges with a waist, pads, knuckle bumps, nails.
        for (f, finger) in webxr::FINGERS.iter().enumerate() {
            let group = f + 1;
            let first = joint(&format!("{finger}-metacarpal")) + 1;
            let tip = joint(&format!("{finger}-tip"));
            for j in first..tip {
                let (a, c) = (anatomy.position(j), anatomy.position(j + 1));
                let len = a.distance(c);
                let (ra, rc) = (anatomy.radius[j], anatomy.radius[j + 1]);
                let blend = 0.25 * rc;
                let squash = 0.86;
                let distal = j + 1 == tip;
                let waist = 0.96 * (ra + rc) * 0.5;
                if distal {
                    // The fingertip: rounded so that the skin ends just beyond the tip joint.
                    let end = c + (c - a).normalize() * (0.15 * rc - rc);
                    parts.push(cone(j, a, a.lerp(end, 0.4), ra, waist, squash, group, blend));
                    parts.push(cone(j, a.lerp(end, 0.4), end, waist, rc, squash, group, blend));
                    // The nail plate: a thin lens just proud of the distal two thirds of the back.
                    let nail = Solid::Ellipsoid { radii: Vec3::new(0.6 * rc, 0.1 * rc, 0.33 * len) };
                    nails.push(parts.len());
                    parts.push(placed(j, Vec3::new(0.0, 0.84 * waist * squash, -0.6 * len), nail, 1.0, group, 0.12 * rc));
                } else {
                    let mid = a.lerp(c, 0.5);
                    parts.push(cone(j, a, mid, ra, waist, squash, group, blend));
                    parts.push(cone(j, mid, c, waist, rc, squash, group, blend));
                    // A knuckle bump over the next joint.
                    let r = 0.5 * rc;
                    parts.push(placed(j, Vec3::new(0.0, 0.36 * rc, -len + 0.1 * rc), Solid::Ellipsoid { radii: Vec3::splat(r) }, 1.0, group, 0.5 * rc));
                }
                // The pad on the palmar side.
                let pad_r = if distal { 0.8 * rc } else { 0.72 * waist };
                let pad = Solid::Ellipsoid { radii: Vec3::new(pad_r, 0.6 * pad_r, 0.4 * len) };
                let at = if distal { 0.55 } else { 0.5 };
                parts.push(placed(j, Vec3::new(0.0, -0.35 * waist, -at * len), pad, 1.0, group, 0.4 * waist));
            }
        }
        // Bounds of the parts, with room for the blends and a margin for the grid.
        let pad = Vec3::splat(0.1 * b);
        let bounds = parts.iter().fold([Vec3::INFINITY, Vec3::NEG_INFINITY], |[lo, hi], p| {
            let (c, r) = p.bounding;
            [lo.min(c - r - pad), hi.max(c + r + pad)]
        });
        Self { parts, nails, web: 0.09 * b, between: 0.045 * b, bounds, finest_feature: 0.011 * b }
    }

    /// Signed distance from `p` to the skin (negative inside).
    pub fn distance(&self, p: Vec3) -> f32 {
        let p = Vec3A::from(p);
        let mut group = [f32::INFINITY; GROUPS];
        for part in &self.parts {
            let g = &mut group[part.group];
            // A part farther than the group's value plus its blend radius cannot change it:
            // skip it on the distance to its bounding sphere, scaled down as its squash (and,
            // with a margin, the ellipsoid bound) may shorten the distance it reports.
            let (centre, radius) = part.bounding;
            if 0.9 * part.squash * (Vec3::from(p).distance(centre) - radius) > *g + part.blend {
                continue;
            }
            let d = part.distance(p);
            *g = if g.is_finite() { smooth_min(*g, d, part.blend) } else { d };
        }
        let fingers = group[2..].iter().fold(group[1], |a, &b| smooth_min(a, b, self.between));
        smooth_min(group[PALM], fingers, self.web)
    }

    /// Gradient of [`Self::distance`] by central differences (not unit: the field is only
    /// approximately a distance).
    pub fn gradient(&self, p: Vec3, eps: f32) -> Vec3 {
        let d = |o: Vec3| self.distance(p + o) - self.distance(p - o);
        Vec3::new(d(Vec3::X * eps), d(Vec3::Y * eps), d(Vec3::Z * eps)) / (2.0 * eps)
    }

    /// Each nail plate: the map from world into its frame (−Z toward the fingertip, +Y out of
    /// the nail) and its ellipsoid's semi-axes, of which [`Self::over_nail`] takes the share
    /// [`NAIL_OUTLINE`] of the outline.
    pub fn nail_plates(&self) -> impl Iterator<Item = (Affine3A, Vec3)> + '_ {
        self.nails.iter().filter_map(|&i| match self.parts[i].solid {
            Solid::Ellipsoid { radii } => Some((self.parts[i].to_local, radii)),
            Solid::RoundCone { .. } => None,
        })
    }

    /// Whether `p`, a point of the skin, lies on a nail: over a nail plate's outline (seen
    /// along its finger's dorsal axis, short of its rim, where the skin folds over it) and on
    /// the plate's dorsal half.
    pub fn over_nail(&self, p: Vec3) -> bool {
        self.nails.iter().any(|&i| {
            let part = &self.parts[i];
            let Solid::Ellipsoid { radii } = part.solid else { return false };
            let q = part.to_local.transform_point3(p);
            q.y > 0.0 && (q.x / radii.x).powi(2) + (q.z / radii.z).powi(2) <= NAIL_OUTLINE
        })
    }

    /// Distance from `p` to each bone's own parts (`f32::INFINITY` for bones with none),
    /// written into `out` (one entry per joint).
    pub fn bone_distances(&self, p: Vec3, out: &mut [f32]) {
        out.fill(f32::INFINITY);
        let p = Vec3A::from(p);
        for part in &self.parts {
            out[part.bone] = out[part.bone].min(part.distance(p));
        }
    }
}
