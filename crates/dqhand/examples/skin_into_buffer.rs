//! Skin into your own buffer, with the core alone (no glTF, no built-in hand, no physics):
//! `cargo run -p dqhand --no-default-features --example skin_into_buffer`.
//!
//! A two-bone cylinder (a forearm and a hand, say) is built in code, the second bone twisted
//! by 150°, and deformed by linear blending and by dual quaternion blending straight into
//! vertex arrays the caller owns (as a renderer's mapped vertex buffer would be). Half way
//! along, where both bones weigh the same, LB collapses the cylinder (the candy wrapper, the
//! paper's Figure 5); DQB keeps its radius.

use std::sync::Arc;

use dqhand::glam::{Affine3A, Quat, Vec3};
use dqhand::kinematics::{Joint, KinematicsLayer, Skeleton, Transform};
use dqhand::skin::{Method, MethodSet, MeshData, SkinLayer, SkinnedMesh, VertexBuffers};

const RINGS: usize = 21;
const AROUND: usize = 24;
const LENGTH: f32 = 0.2; // m
const RADIUS: f32 = 0.02; // m

fn main() -> Result<(), dqhand::Error> {
    // Two joints along +Y: the root at the origin, the second at the middle.
    let skeleton = Skeleton::new(vec![
        Joint { name: "root".into(), parent: None, rest: Transform::IDENTITY },
        Joint { name: "twist".into(), parent: Some(0), rest: Transform::from_rotation_translation(Quat::IDENTITY, Vec3::Y * LENGTH / 2.0) },
    ])?;
    let inverse_bind: Vec<Affine3A> = skeleton.rest_world().iter().map(Affine3A::inverse).collect();
    let mesh = Arc::new(cylinder(inverse_bind.clone())?);

    // The kinematics layer: the second joint twisted about the cylinder's axis.
    let mut kinematics = KinematicsLayer::new(skeleton.clone(), &inverse_bind);
    let mut locals = skeleton.rest_locals();
    locals[1].rotation = Quat::from_rotation_y(150f32.to_radians());
    kinematics.pose_locals(&locals);

    // The skin layer, writing into the caller's arrays (#V × 3 floats each).
    let n = mesh.vertex_count();
    let mut skin = SkinLayer::new(Arc::clone(&mesh), MethodSet::new(&[Method::Lb, Method::Dqb])?);
    let (mut positions, mut normals) = (vec![0.0f32; n * 3], vec![0.0f32; n * 3]);
    println!("a {LENGTH} m cylinder of radius {RADIUS} m, {n} vertices, its far half twisted by 150°:");
    for method in [Method::Lb, Method::Dqb] {
        skin.deform_into(method, &kinematics, VertexBuffers::Separate { positions: &mut positions, normals: Some(&mut normals) });
        // The middle ring: both bones weigh 0.5 there.
        let middle = RINGS / 2 * AROUND;
        let radius = (middle..middle + AROUND).map(|v| Vec3::new(positions[3 * v], 0.0, positions[3 * v + 2]).length()).sum::<f32>() / AROUND as f32;
        println!("  {method:>3}: mean radius of the middle ring {:.4} m ({:.0} % of the rest radius)", radius, 100.0 * radius / RADIUS);
    }
    Ok(())
}

/// A capped-less tube along +Y, each ring weighted from the root (bottom) to the twist joint
/// (top), linearly.
fn cylinder(inverse_bind: Vec<Affine3A>) -> Result<SkinnedMesh, dqhand::Error> {
    let mut data = MeshData { stride: 2, inverse_bind, ..MeshData::default() };
    for r in 0..RINGS {
        let s = r as f32 / (RINGS - 1) as f32;
        for a in 0..AROUND {
            let angle = a as f32 / AROUND as f32 * std::f32::consts::TAU;
            let (sin, cos) = angle.sin_cos();
            data.positions.push([RADIUS * cos, LENGTH * s, RADIUS * sin]);
            data.normals.push([cos, 0.0, sin]);
            data.joints.extend([0, 1]);
            data.weights.extend([1.0 - s, s]);
        }
    }
    for r in 0..RINGS - 1 {
        for a in 0..AROUND {
            let (v, next) = ((r * AROUND + a) as u32, (r * AROUND + (a + 1) % AROUND) as u32);
            let up = AROUND as u32;
            data.indices.extend([v, v + up, next, next, v + up, next + up]);
        }
    }
    let (mesh, _warnings) = SkinnedMesh::new(data)?;
    Ok(mesh)
}
