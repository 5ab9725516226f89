//! The procedural placeholder hand: tubes on the anatomical skeleton (see the module docs).

use glam::{Affine3A, Quat, Vec3};

use crate::kinematics::{webxr, Joint, Skeleton, Transform};
use crate::model::Model;
use crate::skin::{MeshData, SkinnedMesh};
use crate::{Error, Result};

/// Which hand.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Side {
    /// Left hand: the thumb on +X when the palm faces down and the fingers point along −Z.
    Left,
    /// Right hand: the thumb on −X.
    #[default]
    Right,
}

/// The two measurements a user gives, and the side.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HandParams {
    /// Wrist crease to middle fingertip (m); adult default 0.19.
    pub length: f32,
    /// Across the metacarpal heads (m); adult default 0.085.
    pub breadth: f32,
    /// Left or right.
    pub side: Side,
}

impl Default for HandParams {
    fn default() -> Self {
        Self { length: 0.19, breadth: 0.085, side: Side::Right }
    }
}

/// Segment lengths as fractions of hand length (Buchholz et al. 1992): metacarpal, proximal,
/// (intermediate,) distal. The thumb has no intermediate phalanx.
const SEGMENTS: [&[f32]; 5] = [
    &[0.251, 0.196, 0.158],
    &[0.374, 0.265, 0.143, 0.097],
    &[0.373, 0.277, 0.170, 0.108],
    &[0.336, 0.259, 0.165, 0.107],
    &[0.295, 0.206, 0.117, 0.093],
];
/// MCP position across the hand, fraction of breadth toward the radial side.
const MCP_ACROSS: [f32; 4] = [0.33, 0.10, -0.12, -0.32];
/// Finger thickness relative to the index.
const FINGER_SCALE: [f32; 5] = [1.2, 1.0, 1.02, 0.94, 0.8];
/// Vertices around each tube: fingers and thumb, palm.
const AROUND: [usize; 2] = [24, 32];
/// Rings along each tube: thumb, four fingers, palm. With two cap vertices per tube this
/// gives 4 × (24·60+2) + (24·50+2) + (32·53+2) = 8,668 vertices, the paper's Table 2.
const RINGS: [usize; 6] = [50, 60, 60, 60, 60, 53];

/// Builds the built-in hand.
///
/// # Errors
/// [`Error::Invalid`] if a measurement is not positive and finite, or the breadth is not
/// smaller than the length (no hand has such proportions).
pub fn build(params: &HandParams) -> Result<Model> {
    let HandParams { length: l, breadth: b, side } = *params;
    if !(l.is_finite() && l > 0.0) {
        return Err(Error::Invalid(format!("hand length {l} m is not a positive length")));
    }
    if !(b.is_finite() && b > 0.0) {
        return Err(Error::Invalid(format!("hand breadth {b} m is not a positive length")));
    }
    if b >= 0.75 * l {
        return Err(Error::Invalid(format!("hand breadth {b} m is not smaller than 0.75 × length {l} m; no hand has such proportions")));
    }
    let radial = Vec3::X * if side == Side::Right { -1.0 } else { 1.0 };
    let frames = joint_frames(l, b, radial);
    let skeleton = skeleton_from_world(&frames)?;
    let mut mesh = TubeMesh::default();
    let joint = |n: &str| webxr::JOINT_NAMES.iter().position(|&j| j == n).unwrap_or(0) as u32;
    for (f, finger) in webxr::FINGERS.iter().enumerate() {
        let first = joint(&format!("{finger}-metacarpal"));
        let bones = SEGMENTS[f].len();
        let chain: Vec<usize> = (0..=bones).map(|i| first as usize + i).collect();
        let radius = 0.105 * b * FINGER_SCALE[f];
        let start = if f == 0 { 0.0 } else { -0.35 * SEGMENTS[f][0] * l };
        mesh.finger(&frames, &chain, f == 0, radius, start, RINGS[f]);
    }
    mesh.palm(&frames, l, b, radial);
    let inverse_bind = frames.iter().map(|m| m.inverse()).collect();
    let data = MeshData {
        positions: mesh.positions,
        normals: Vec::new(),
        uvs: mesh.uvs,
        stride: 4,
        joints: mesh.joints,
        weights: mesh.weights,
        indices: mesh.indices,
        parts: Vec::new(),
        inverse_bind,
    };
    let (mesh, warnings) = SkinnedMesh::new(data)?;
    let side_name = if side == Side::Right { "right" } else { "left" };
    Ok(Model {
        description: format!(
            "built-in {side_name} hand, length {l} m, breadth {b} m: procedural placeholder (tubes on the anatomical skeleton), not the anatomical mesh"
        ),
        skeleton,
        mesh,
        warnings,
    })
}

/// World frames of the 25 WebXR joints: −Z along each bone, +Y dorsal; the wrist at the
/// origin with the identity rotation, palm down, fingers along −Z.
fn joint_frames(l: f32, b: f32, radial: Vec3) -> Vec<Affine3A> {
    let mut frames = vec![Affine3A::IDENTITY; 25];
    let along = |dir: Vec3, up: Vec3| {
        let z = -dir.normalize();
        let x = up.cross(z).normalize();
        Quat::from_mat3(&glam::Mat3::from_cols(x, z.cross(x), z))
    };
    for (f, seg) in SEGMENTS.iter().enumerate() {
        let first = if f == 0 { 1 } else { 5 * f };
        let (base, dirs): (Vec3, [Vec3; 2]) = if f == 0 {
            let dir = (radial * 0.55 - Vec3::Y * 0.2 - Vec3::Z * 0.8).normalize();
            (radial * 0.22 * b - Vec3::Y * 0.012 - Vec3::Z * 0.07 * l, [dir, dir])
        } else {
            let mcp_x = radial * MCP_ACROSS[f - 1] * b;
            let cmc = mcp_x * 0.4 - Vec3::Z * 0.08 * l;
            let dx = (mcp_x * 0.6).length();
            let mc = seg[0] * l;
            let mcp = mcp_x - Vec3::Z * (0.08 * l + (mc * mc - dx * dx).sqrt());
            (cmc, [(mcp - cmc).normalize(), Vec3::NEG_Z])
        };
        let up = if f == 0 { (radial * 0.7 + Vec3::Y * 0.7).normalize() } else { Vec3::Y };
        let mut p = base;
        for (i, &s) in seg.iter().chain(std::iter::once(&0.0)).enumerate() {
            let dir = dirs[usize::from(i > 0)];
            frames[first + i] = Affine3A::from_rotation_translation(along(dir, up), p);
            p += dir * s * l;
        }
    }
    frames
}

fn skeleton_from_world(world: &[Affine3A]) -> Result<Skeleton> {
    let joints = webxr::JOINT_NAMES
        .iter()
        .enumerate()
        .map(|(i, &name)| {
            let parent = webxr::anatomical_parent(name).and_then(|p| webxr::JOINT_NAMES.iter().position(|&n| n == p));
            let local = parent.map_or(world[i], |p| world[p].inverse() * world[i]);
            Joint { name: name.to_owned(), parent, rest: Transform::from_affine(&local) }
        })
        .collect();
    Skeleton::new(joints)
}

fn smoothstep(x: f32) -> f32 {
    let x = x.clamp(0.0, 1.0);
    x * x * (3.0 - 2.0 * x)
}

/// Mesh under construction: closed tubes with a centre vertex capping each end.
#[derive(Default)]
struct TubeMesh {
    positions: Vec<[f32; 3]>,
    uvs: Vec<[f32; 2]>,
    joints: Vec<u32>,
    weights: Vec<f32>,
    indices: Vec<u32>,
}

/// One ring of a tube: centre, frame axes, radii and up to four (joint, weight) influences.
struct Ring {
    centre: Vec3,
    x: Vec3,
    y: Vec3,
    radii: [f32; 2],
    influences: [(u32, f32); 4],
}

impl TubeMesh {
    fn push(&mut self, p: Vec3, uv: [f32; 2], influences: &[(u32, f32); 4]) {
        self.positions.push(p.to_array());
        self.uvs.push(uv);
        for &(j, w) in influences {
            self.joints.push(j);
            self.weights.push(w);
        }
    }

    /// Appends a closed tube through `rings` with `around` vertices per ring; triangles face
    /// outward.
    fn tube(&mut self, rings: &[Ring], around: usize, end_caps: [(Vec3, [(u32, f32); 4]); 2]) {
        let first = self.positions.len() as u32;
        let n = rings.len();
        for (i, r) in rings.iter().enumerate() {
            for k in 0..around {
                let phi = core::f32::consts::TAU * k as f32 / around as f32;
                let p = r.centre + r.x * (r.radii[0] * phi.cos()) + r.y * (r.radii[1] * phi.sin());
                self.push(p, [k as f32 / around as f32, i as f32 / (n - 1) as f32], &r.influences);
            }
        }
        let caps = [first + (n * around) as u32, first + (n * around) as u32 + 1];
        for (c, infl) in &end_caps {
            self.push(*c, [0.5, 0.5], infl);
        }
        let at = |i: usize, k: usize| first + (i * around + k % around) as u32;
        let start = self.indices.len();
        for i in 0..n - 1 {
            for k in 0..around {
                self.indices.extend([at(i, k), at(i, k + 1), at(i + 1, k), at(i + 1, k), at(i, k + 1), at(i + 1, k + 1)]);
            }
        }
        for k in 0..around {
            self.indices.extend([caps[0], at(0, k + 1), at(0, k)]);
            self.indices.extend([caps[1], at(n - 1, k), at(n - 1, k + 1)]);
        }
        // Orient the closed part outward: flip it if its signed volume is negative.
        let tri = &mut self.indices[start..];
        let volume: f32 = tri
            .chunks_exact(3)
            .map(|t| {
                let [a, b, c] = [t[0], t[1], t[2]].map(|i| Vec3::from(self.positions[i as usize]));
                a.dot(b.cross(c))
            })
            .sum();
        if volume < 0.0 {
            tri.chunks_exact_mut(3).for_each(|t| t.swap(1, 2));
        }
    }

    /// A finger (or the thumb) along the joints of `chain` (metacarpal … tip), from arc length
    /// `start` (negative: inside the palm) to a rounded tip. Weights blend smoothly across each
    /// joint over ± 0.8 radius.
    fn finger(&mut self, frames: &[Affine3A], chain: &[usize], thumb: bool, radius: f32, start: f32, rings: usize) {
        let pos = |j: usize| Vec3::from(frames[chain[j]].translation);
        // Arc length of each joint along the chain, measured from the MCP (thumb: from the CMC).
        let origin = if thumb { 0 } else { 1 };
        let mut arc = vec![0.0f32; chain.len()];
        for j in 1..chain.len() {
            arc[j] = arc[j - 1] + pos(j).distance(pos(j - 1));
        }
        let offset = arc[origin];
        arc.iter_mut().for_each(|a| *a -= offset);
        let end = arc[chain.len() - 1];
        let tip_r = radius * 0.75;
        let wrist_blend = |s: f32| if thumb { 1.0 - smoothstep((s - 0.1 * arc[1]) / (0.3 * arc[1])) } else { 0.0 };
        let ring_at = |s: f32| {
            let seg = (1..chain.len()).find(|&j| s < arc[j]).map_or(chain.len() - 2, |j| j - 1);
            let frame = frames[chain[seg]];
            let centre = pos(seg) + (pos(seg + 1) - pos(seg)).normalize() * (s - arc[seg]);
            let taper = 1.0 - 0.25 * ((s - arc[0]) / (end - arc[0])).clamp(0.0, 1.0);
            let mut r = radius * taper;
            if s > end - tip_r {
                let u = (s - (end - tip_r)) / tip_r;
                r = r.min(tip_r) * (1.0 - u * u).max(0.0).sqrt();
            }
            // Influences: the bone the point lies on and its neighbour across the nearest joint.
            let mut infl = [(chain[seg] as u32, 1.0), (chain[seg] as u32, 0.0), (0, 0.0), (0, 0.0)];
            for j in 1..chain.len() - 1 {
                let h = 0.8 * radius;
                if (s - arc[j]).abs() < h {
                    let t = smoothstep((s - arc[j] + h) / (2.0 * h));
                    infl[0] = (chain[j - 1] as u32, 1.0 - t);
                    infl[1] = (chain[j] as u32, t);
                }
            }
            let w = wrist_blend(s);
            if w > 0.0 {
                infl[0].1 *= 1.0 - w;
                infl[1].1 *= 1.0 - w;
                infl[2] = (0, w);
            }
            Ring {
                centre,
                x: frame.matrix3.x_axis.into(),
                y: frame.matrix3.y_axis.into(),
                radii: [r, r * 0.9],
                influences: infl,
            }
        };
        let rings: Vec<Ring> = (0..rings).map(|i| ring_at(start + (end - start) * i as f32 / rings as f32)).collect();
        let caps = [(rings[0].centre, rings[0].influences), (pos(chain.len() - 1), rings[rings.len() - 1].influences)];
        self.tube(&rings, AROUND[0], caps);
    }

    /// The palm: an elliptic tube from behind the wrist to the knuckles, weighted to the
    /// wrist near the wrist and to the two nearest metacarpals across the hand.
    fn palm(&mut self, frames: &[Affine3A], l: f32, b: f32, radial: Vec3) {
        let mcp = |f: usize| Vec3::from(frames[5 * f + 1].translation);
        let mc_x: Vec<f32> = (1..5).map(|f| mcp(f).dot(radial)).collect();
        let z0 = 0.03 * l;
        let z1 = (1..5).map(|f| mcp(f).z).sum::<f32>() / 4.0 + 0.01 * l;
        let n = RINGS[5];
        let rings: Vec<Ring> = (0..n)
            .map(|i| {
                let u = i as f32 / (n - 1) as f32;
                let z = z0 + (z1 - z0) * u;
                let centre = radial * (0.5 * (mc_x[0] + mc_x[3]) * u) + Vec3::Z * z - Vec3::Y * 0.01 * b;
                let wrist = 1.0 - smoothstep((u - 0.15) / 0.4);
                Ring {
                    centre,
                    x: radial,
                    y: Vec3::Y,
                    radii: [(0.32 + 0.2 * u) * b, (0.15 - 0.03 * u) * b],
                    influences: [(0, wrist), (0, 0.0), (0, 0.0), (0, 0.0)],
                }
            })
            .collect();
        let first = self.positions.len();
        self.tube(&rings, AROUND[1], [(rings[0].centre, rings[0].influences), (rings[n - 1].centre, rings[n - 1].influences)]);
        // Spread the non-wrist weight over the two metacarpals nearest across the hand.
        for v in first..self.positions.len() {
            let x = Vec3::from(self.positions[v]).dot(radial);
            let wrist = self.weights[v * 4];
            let f = (0..3).find(|&f| x >= mc_x[f + 1]).unwrap_or(2);
            let t = ((x - mc_x[f + 1]) / (mc_x[f] - mc_x[f + 1])).clamp(0.0, 1.0);
            let rest = 1.0 - wrist;
            let mc = |f: usize| (5 * (f + 1)) as u32;
            let infl = [(0, wrist), (mc(f), rest * t), (mc(f + 1), rest * (1.0 - t)), (0, 0.0)];
            for (s, (j, w)) in infl.into_iter().enumerate() {
                self.joints[v * 4 + s] = j;
                self.weights[v * 4 + s] = w;
            }
        }
    }
}
