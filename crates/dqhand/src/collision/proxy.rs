//! Collision proxies: one simple convex shape per bone, slightly larger than its skin.
//!
//! Each vertex belongs to the bone with its heaviest weight. A phalanx (and the thumb's
//! metacarpal, which moves at the CMC joint) gets a capsule along its bone: the segment from
//! the joint to its child, its radius the largest distance of the bone's vertices from that
//! segment plus a margin, so the capsule encloses them. Every other bone (the wrist and the
//! finger metacarpals, which make the palm) gets the convex hull of its vertices, each pushed
//! out along its normal by the margin. Shapes are fitted in bind space (where the mesh's
//! vertices are, through the inverse bind matrices, not the skeleton's rest pose, which may
//! differ) and stored in the joint's own frame, so they move rigidly with it.

use glam::{Affine3A, Vec3};

use crate::math::segment_distance;
use crate::model::Model;

/// How far proxies stand off the skin (m): enough that contact is detected before the skin
/// would be reached, small against a finger (≈ 9 mm radius).
pub const PROXY_MARGIN: f32 = 0.001;

/// A convex shape in a joint's local frame.
#[derive(Clone, Debug, PartialEq)]
pub enum ProxyShape {
    /// All points within `radius` of the segment `start`–`end`.
    Capsule { start: Vec3, end: Vec3, radius: f32 },
    /// A convex polyhedron: its vertices and outward triangles.
    ConvexHull { points: Vec<Vec3>, triangles: Vec<[u32; 3]> },
}

/// The collision proxy of one joint.
#[derive(Clone, Debug, PartialEq)]
pub struct Proxy {
    /// Index of the joint in the model's skeleton.
    pub joint: usize,
    /// The shape, in the joint's local frame.
    pub shape: ProxyShape,
}

/// Fits a proxy to every joint that has vertices of its own, with margin `margin` (m).
#[must_use]
pub fn fit_proxies(model: &Model, margin: f32) -> Vec<Proxy> {
    let skeleton = &model.skeleton;
    let mesh = &model.mesh;
    let world = model.bind_world();
    let mut owned: Vec<Vec<usize>> = vec![Vec::new(); skeleton.len()];
    for v in 0..mesh.vertex_count() {
        if let Some((j, _)) = mesh.influences(v).next() {
            owned[j].push(v);
        }
    }
    let joints = skeleton.joints();
    owned
        .iter()
        .enumerate()
        .filter(|(_, vs)| !vs.is_empty())
        .map(|(j, vs)| {
            let to_local: Affine3A = world[j].inverse();
            let child = joints.iter().position(|c| c.parent == Some(j));
            let name = &joints[j].name;
            let capsule_bone = name.contains("phalanx") || name == "thumb-metacarpal";
            let shape = match child {
                Some(c) if capsule_bone => {
                    let end = to_local.transform_point3(world[c].translation.into());
                    let radius = vs
                        .iter()
                        .map(|&v| segment_distance(to_local.transform_point3(mesh.position(v)), Vec3::ZERO, end))
                        .fold(0.0, f32::max);
                    ProxyShape::Capsule { start: Vec3::ZERO, end, radius: radius + margin }
                }
                _ => {
                    let points: Vec<Vec3> = vs.iter().map(|&v| to_local.transform_point3(mesh.position(v) + mesh.normal(v) * margin)).collect();
                    match parry3d::transformation::try_convex_hull(&points) {
                        Ok((points, triangles)) => ProxyShape::ConvexHull { points, triangles },
                        // Fewer than four points, or all in a plane: a capsule around them.
                        Err(_) => {
                            let far = points.iter().copied().fold(Vec3::ZERO, |a, p| if p.length() > a.length() { p } else { a });
                            let radius = points.iter().map(|&p| segment_distance(p, Vec3::ZERO, far)).fold(0.0, f32::max);
                            ProxyShape::Capsule { start: Vec3::ZERO, end: far, radius: radius + margin }
                        }
                    }
                }
            };
            Proxy { joint: j, shape }
        })
        .collect()
}
