//! Proportions of an adult hand from its length and breadth: the skeleton and the finger
//! breadths the shape is modelled around.
//!
//! Sources (all values are fractions, so one hand length and breadth scale them):
//! * segment lengths (metacarpal, phalanges) as fractions of hand length: Buchholz, Armstrong
//!   and Goldstein 1992, "Anthropometric data for describing the kinematics of the human
//!   hand", Ergonomics 35:261, Table 3 (joint centre to joint centre; distal: to the tip);
//! * finger breadths at the MCP, PIP and DIP joints and the thumb's at the MCP and IP joints as
//!   fractions of hand breadth: the means of Greiner 1991, "Hand anthropometry of U.S. Army
//!   personnel" (Natick TR-92/011), divided by that survey's mean hand breadth and rounded;
//! * joint centres at mid-depth of the finger; the metacarpal heads spread across 65 % of the
//!   hand breadth, their bases (CMC) converge to 40 % of that; the relaxed spread of the
//!   fingers (index 9° radial … little 15° ulnar) leaves a gap between them at rest, the pose
//!   a hand is modelled and rigged in; the thumb's dorsal axis points mostly radially (a relaxed
//!   thumbnail faces sideways), so that its flexion carries it across the palm.

use glam::{Affine3A, Mat3, Quat, Vec3};

use crate::kinematics::{webxr, Joint, Skeleton, Transform};
use crate::Result;

/// Segment lengths as fractions of hand length (Buchholz et al. 1992): metacarpal, proximal,
/// (intermediate,) distal. The thumb has no intermediate phalanx.
const SEGMENTS: [&[f32]; 5] = [
    &[0.251, 0.196, 0.158],
    &[0.374, 0.265, 0.143, 0.097],
    &[0.373, 0.277, 0.170, 0.108],
    &[0.336, 0.259, 0.165, 0.107],
    &[0.295, 0.206, 0.117, 0.093],
];
/// Full breadth of each finger at its joints, fraction of hand breadth: thumb CMC, MCP, IP,
/// tip; fingers CMC (the palm's metacarpal), MCP, PIP, DIP, tip (Greiner 1991, rounded).
const BREADTH: [&[f32]; 5] = [
    &[0.36, 0.27, 0.255, 0.22],
    &[0.36, 0.26, 0.236, 0.202, 0.18],
    &[0.36, 0.265, 0.236, 0.208, 0.185],
    &[0.34, 0.25, 0.225, 0.197, 0.175],
    &[0.30, 0.22, 0.202, 0.180, 0.16],
];
/// MCP position across the hand, fraction of breadth toward the radial side.
const MCP_ACROSS: [f32; 4] = [0.33, 0.10, -0.12, -0.32];
/// Relaxed spread of the fingers at rest, degrees toward the radial side.
const SPREAD_DEG: [f32; 4] = [9.0, 1.0, -7.0, -15.0];

/// Hand length and breadth from the 25 WebXR joint positions of a hand (any pose, any
/// place): the inverse of the proportions `Anatomy::new` builds with, so measuring a hand it built gives
/// back its length and breadth.
///
/// * length: the middle finger's proximal + intermediate + distal bones, which do not change
///   with the pose, over their fraction of hand length (Buchholz et al.);
/// * breadth: the index-to-little knuckle distance across the palm (its component normal to
///   the wrist→middle-knuckle axis) over the share of breadth the knuckles span.
///
/// `None` if the joints are degenerate.
pub fn measure(joints: &[Vec3; 25]) -> Option<(f32, f32)> {
    let middle = &SEGMENTS[2][1..];
    let bones: f32 = (11..14).map(|i| (joints[i + 1] - joints[i]).length()).sum();
    let length = bones / middle.iter().sum::<f32>();
    let forward = (joints[11] - joints[0]).try_normalize()?;
    let across = joints[6] - joints[21];
    let breadth = (across - forward * across.dot(forward)).length() / (MCP_ACROSS[0] - MCP_ACROSS[3]);
    (length.is_finite() && length > 0.0 && breadth.is_finite() && breadth > 0.0).then_some((length, breadth))
}

/// The hand's skeleton in world space and the half-breadth of the finger at each joint.
#[derive(Clone, Debug)]
pub(crate) struct Anatomy {
    /// World frame of each WebXR joint (−Z along the bone, +Y dorsal), in
    /// [`webxr::JOINT_NAMES`] order.
    pub frames: Vec<Affine3A>,
    /// Half the finger's breadth at each joint (m); the wrist's is half the wrist breadth.
    pub radius: Vec<f32>,
    /// Unit vector toward the thumb side.
    pub radial: Vec3,
    /// Hand breadth (m).
    pub breadth: f32,
}

impl Anatomy {
    /// Joint frames for a hand `length` long and `breadth` wide; `radial` is −X for a right
    /// hand, +X for a left one. The wrist is at the origin with the identity rotation, the
    /// palm down and the fingers along −Z.
    pub fn new(length: f32, breadth: f32, radial: Vec3) -> Self {
        let (l, b) = (length, breadth);
        let mut frames = vec![Affine3A::IDENTITY; webxr::JOINT_NAMES.len()];
        let mut radius = vec![0.33 * b; webxr::JOINT_NAMES.len()];
        let along = |dir: Vec3, up: Vec3| {
            let z = -dir.normalize();
            let x = up.cross(z).normalize();
            Quat::from_mat3(&Mat3::from_cols(x, z.cross(x), z))
        };
        for (f, seg) in SEGMENTS.iter().enumerate() {
            let first = if f == 0 { 1 } else { 5 * f };
            let (base, dirs, up) = if f == 0 {
                let dir = (radial * 0.55 - Vec3::Y * 0.2 - Vec3::Z * 0.8).normalize();
                let up = (radial * 0.85 + Vec3::Y * 0.5).normalize();
                (radial * 0.2 * b - Vec3::Y * 0.14 * b - Vec3::Z * 0.06 * l, [dir, dir], up)
            } else {
                let mcp_x = radial * MCP_ACROSS[f - 1] * b;
                let cmc = mcp_x * 0.4 - Vec3::Z * 0.08 * l;
                let dx = (mcp_x * 0.6).length();
                let mc = seg[0] * l;
                let mcp = mcp_x - Vec3::Z * (0.08 * l + (mc * mc - dx * dx).sqrt());
                let spread = SPREAD_DEG[f - 1].to_radians();
                let phalanges = radial * spread.sin() - Vec3::Z * spread.cos();
                (cmc, [(mcp - cmc).normalize(), phalanges], Vec3::Y)
            };
            let mut p = base;
            for (i, &s) in seg.iter().chain(std::iter::once(&0.0)).enumerate() {
                let dir = dirs[usize::from(i > 0)];
                frames[first + i] = Affine3A::from_rotation_translation(along(dir, up), p);
                radius[first + i] = 0.5 * BREADTH[f][i] * b;
                p += dir * s * l;
            }
        }
        Self { frames, radius, radial, breadth: b }
    }

    /// World position of joint `j`.
    pub fn position(&self, j: usize) -> Vec3 {
        self.frames[j].translation.into()
    }

    /// The skeleton: WebXR joint names on the anatomical hierarchy, rest transforms from the
    /// world frames.
    pub fn skeleton(&self) -> Result<Skeleton> {
        let world = &self.frames;
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
}
