//! The centres of rotation of CoR skinning against an independent reference: the definition
//! (Le and Hodgins 2016) summed plainly in `f64`, over every triangle and every ordered pair
//! of joints with dense weight vectors, where the engine sums per pair over the triangles
//! sharing it.

mod support;

use dqhand::glam::{Affine3A, DVec3, Vec3};
use dqhand::skin::{centres_of_rotation, MeshData, SkinnedMesh, SIMILARITY_SIGMA};

/// A tube along +X over three joints at x = 0, 0.1, 0.2 (m): `rings` rings of `sides`
/// vertices, radius 0.02, each vertex's weights falling off linearly from the joints (a
/// smooth skin around each joint), closed at neither end.
fn tube(rings: usize, sides: usize) -> MeshData {
    let mut data = MeshData { stride: 3, inverse_bind: vec![Affine3A::IDENTITY; 3], ..MeshData::default() };
    for r in 0..rings {
        let x = 0.2 * r as f32 / (rings - 1) as f32;
        let w: Vec<f32> = (0..3).map(|j| (1.0 - (x - 0.1 * j as f32).abs() / 0.1).max(0.0)).collect();
        for s in 0..sides {
            let a = std::f32::consts::TAU * s as f32 / sides as f32;
            data.positions.push([x, 0.02 * a.cos(), 0.02 * a.sin()]);
            data.joints.extend([0, 1, 2]);
            data.weights.extend(&w);
        }
    }
    for r in 0..rings - 1 {
        for s in 0..sides {
            let (a, b) = ((r * sides + s) as u32, (r * sides + (s + 1) % sides) as u32);
            let (c, d) = (a + sides as u32, b + sides as u32);
            data.indices.extend([a, c, b, b, c, d]);
        }
    }
    data
}

/// The centre of vertex `v` by the definition: `Σₜ s(wᵥ, wₜ) aₜ cₜ / Σₜ s(wᵥ, wₜ) aₜ` with
/// `s(a, b) = Σ_{j≠k} aⱼ aₖ bⱼ bₖ exp(−(aⱼ bₖ − aₖ bⱼ)² / σ²)`, `wₜ` the mean of the
/// triangle's vertices' weights; the rest position where the sum is 0.
fn reference(data: &MeshData, v: usize) -> DVec3 {
    let joints = data.inverse_bind.len();
    let dense = |u: usize| -> Vec<f64> {
        let mut w = vec![0.0; joints];
        let total: f64 = (0..data.stride).map(|s| f64::from(data.weights[u * data.stride + s])).sum();
        for s in 0..data.stride {
            w[data.joints[u * data.stride + s] as usize] += f64::from(data.weights[u * data.stride + s]) / total;
        }
        w
    };
    let sigma = f64::from(SIMILARITY_SIGMA);
    let similarity = |a: &[f64], b: &[f64]| -> f64 {
        let mut s = 0.0;
        for j in 0..joints {
            for k in 0..joints {
                if j != k {
                    let d = a[j] * b[k] - a[k] * b[j];
                    s += a[j] * a[k] * b[j] * b[k] * (-d * d / (sigma * sigma)).exp();
                }
            }
        }
        s
    };
    let wv = dense(v);
    let at = |u: u32| Vec3::from(data.positions[u as usize]).as_dvec3();
    let (mut sum, mut total) = (DVec3::ZERO, 0.0);
    for t in data.indices.chunks_exact(3) {
        let (a, b, c) = (at(t[0]), at(t[1]), at(t[2]));
        let area = 0.5 * (b - a).cross(c - a).length();
        let wt: Vec<f64> = (0..joints).map(|j| t.iter().map(|&u| dense(u as usize)[j]).sum::<f64>() / 3.0).collect();
        let weight = similarity(&wv, &wt) * area;
        sum += weight * (a + b + c) / 3.0;
        total += weight;
    }
    if total > 0.0 { sum / total } else { at(v as u32) }
}

#[test]
fn the_centres_are_the_definitions() {
    let data = tube(21, 12);
    let (mesh, _) = SkinnedMesh::new(data.clone()).expect("a valid tube");
    let centres = centres_of_rotation(&mesh);
    assert_eq!(centres.len(), data.positions.len());
    let mut two_joints = 0;
    for (v, c) in centres.iter().enumerate() {
        let want = reference(&data, v);
        let got = Vec3::from(*c).as_dvec3();
        assert!(got.distance(want) < 1e-6, "vertex {v}: centre {got} but the definition gives {want}");
        // The tube is symmetric about its axis and its weights depend on x alone, so a vertex
        // bending with two joints turns about a point on the axis, between the joints it
        // blends (its own rest position, 2 cm off the axis, where only one joint moves it).
        let x = f64::from(data.positions[v][0]);
        if x > 0.0 && x < 0.2 && (x - 0.1).abs() > 1e-6 {
            two_joints += 1;
            assert!(got.y.hypot(got.z) < 1e-5, "vertex {v}: centre {got} is off the axis");
            let (lo, hi) = if x < 0.1 { (0.0, 0.1) } else { (0.1, 0.2) };
            assert!(got.x > lo - 1e-6 && got.x < hi + 1e-6, "vertex {v} at x = {x}: centre {got} outside its joints' span");
        } else {
            assert!(got.distance(Vec3::from(data.positions[v]).as_dvec3()) < 1e-7, "vertex {v} on one joint: centre {got}, not its rest position");
        }
    }
    assert!(two_joints > 100, "{two_joints} vertices blend two joints");
}

#[test]
fn centres_given_with_a_mesh_are_kept_and_bad_ones_are_refused() {
    let (mesh, _) = SkinnedMesh::new(tube(3, 4)).expect("a valid tube");
    assert!(!mesh.has_centres_of_rotation(), "computed only when asked for");
    let n = mesh.vertex_count();
    let given: Vec<[f32; 3]> = (0..n).map(|v| [v as f32, 0.5, -1.0]).collect();
    let kept = mesh.clone().with_centres_of_rotation(&given).expect("one finite centre per vertex");
    assert!(kept.has_centres_of_rotation());
    assert_eq!(kept.centre_of_rotation(5).to_array(), given[5]);
    let short = mesh.clone().with_centres_of_rotation(&given[1..]).unwrap_err().to_string();
    assert!(short.contains(&format!("{} centres of rotation for {n} vertices", n - 1)), "{short}");
    let mut nan = given.clone();
    nan[7][1] = f32::NAN;
    let bad = mesh.with_centres_of_rotation(&nan).unwrap_err().to_string();
    assert!(bad.contains("vertex 7 has a non-finite centre of rotation"), "{bad}");
}

#[test]
fn on_the_webxr_generic_hand_the_centres_are_the_definitions() {
    let model = support::webxr_hand();
    let mesh = &model.mesh;
    // The same mesh as plain data for the reference: positions, triangles, weights.
    let n = mesh.vertex_count();
    let k = mesh.influences_per_vertex();
    let mut data = MeshData { positions: mesh.positions(), indices: mesh.indices().to_vec(), stride: k, inverse_bind: mesh.inverse_bind().to_vec(), ..MeshData::default() };
    for v in 0..n {
        let inf: Vec<(usize, f32)> = mesh.influences(v).collect();
        for s in 0..k {
            let (j, w) = inf.get(s).copied().unwrap_or((0, 0.0));
            data.joints.push(j as u32);
            data.weights.push(w);
        }
    }
    let centres = centres_of_rotation(mesh);
    let blended: Vec<usize> = (0..n).filter(|&v| mesh.influences(v).count() >= 2).collect();
    assert!(blended.len() > 100, "{} of {n} vertices blend joints", blended.len());
    // Ten vertices spread over those that blend joints (the dense sum is slow).
    for &v in blended.iter().step_by(blended.len() / 10) {
        let want = reference(&data, v);
        let got = Vec3::from(centres[v]).as_dvec3();
        assert!(got.distance(want) < 1e-6, "vertex {v}: centre {got} but the definition gives {want}");
    }
}
