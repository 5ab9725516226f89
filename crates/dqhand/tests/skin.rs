//! The skinned mesh and the LB, QB and DQB deformers (paper 4.4).

mod support;

use dqhand::gesture::gesture;
use dqhand::hand::{build, HandParams};
use dqhand::geometry::vertex_normals;
use dqhand::kinematics::{JointModel, Limits, PoseTarget};
use dqhand::math::DualQuat;
use std::sync::Arc;
use std::time::Duration;

use dqhand::skin::{Crew, Deformed, Deformer, Kernel, MeshData, Method, MethodSet, SkinLayer, SkinnedMesh, Strategy, MIN_VERTICES_PER_THREAD};
use glam::{Affine3A, Quat, Vec3, Vec3A};
use proptest::prelude::*;
use support::{rotation, vec3};

fn deform(method: Method, mesh: &SkinnedMesh, skinning: &[Affine3A]) -> Deformed {
    let mut out = Deformed::new(mesh);
    Deformer::new(method, mesh).deform(mesh, skinning, &mut out);
    out
}

/// A cylinder of radius `r` along +Y from y = 0 to y = 2, bound to joint 0 below y = 1 and
/// joint 1 above, blended linearly over y ∈ [0.5, 1.5]; 32 vertices per ring, 41 rings.
fn cylinder(r: f32) -> SkinnedMesh {
    let (around, rings) = (32, 41);
    let mut d = MeshData { stride: 2, inverse_bind: vec![Affine3A::IDENTITY; 2], ..MeshData::default() };
    for i in 0..rings {
        let y = 2.0 * i as f32 / (rings - 1) as f32;
        let w = ((y - 0.5) / 1.0).clamp(0.0, 1.0);
        for k in 0..around {
            let a = std::f32::consts::TAU * k as f32 / around as f32;
            d.positions.push([r * a.cos(), y, r * a.sin()]);
            d.joints.extend([0, 1]);
            d.weights.extend([1.0 - w, w]);
        }
    }
    for i in 0..rings - 1 {
        for k in 0..around {
            let at = |i: usize, k: usize| (i * around + k % around) as u32;
            d.indices.extend([at(i, k), at(i + 1, k), at(i, k + 1), at(i, k + 1), at(i + 1, k), at(i + 1, k + 1)]);
        }
    }
    SkinnedMesh::new(d).unwrap().0
}

/// Smallest distance of the middle ring (y = 1) from the cylinder axis after deformation.
fn middle_radius(out: &Deformed, axis_at: impl Fn(f32) -> Vec3) -> f32 {
    (20 * 32..21 * 32).map(|v| Vec3::from(out.positions()[v]).distance(axis_at(1.0))).fold(f32::MAX, f32::min)
}

#[test]
fn dqb_keeps_a_twisted_cylinder_round_where_lb_collapses() {
    let mesh = cylinder(1.0);
    let twist = [Affine3A::IDENTITY, Affine3A::from_rotation_y(std::f32::consts::PI * 0.999)];
    let axis = |y: f32| Vec3::new(0.0, y, 0.0);
    let lb = middle_radius(&deform(Method::Lb, &mesh, &twist), axis);
    let qb = middle_radius(&deform(Method::Qb, &mesh, &twist), axis);
    let dqb = middle_radius(&deform(Method::Dqb, &mesh, &twist), axis);
    assert!(lb < 0.05, "LB candy wrapper: radius {lb}");
    assert_close!(dqb, 1.0, 1e-3);
    assert_close!(qb, 1.0, 1e-3);
}

#[test]
fn dqb_does_not_collapse_a_bent_joint_where_lb_does() {
    let mesh = cylinder(1.0);
    // Bend the upper half 120° about the X axis through the joint centre (0, 1, 0).
    let pivot = Vec3::Y;
    let bend = Affine3A::from_translation(pivot) * Affine3A::from_rotation_x(2.1) * Affine3A::from_translation(-pivot);
    let skinning = [Affine3A::IDENTITY, bend];
    let inner = |out: &Deformed| middle_radius(out, |_| pivot);
    let (lb, dqb) = (inner(&deform(Method::Lb, &mesh, &skinning)), inner(&deform(Method::Dqb, &mesh, &skinning)));
    assert!(lb < 0.55, "LB collapses toward the joint: {lb}");
    assert!(dqb > 0.8, "DQB keeps the joint's volume: {dqb}");
}

proptest! {
    #[test]
    fn a_single_bone_vertex_moves_rigidly_under_all_three(r in rotation(), t in vec3(1.0), p in vec3(0.5)) {
        let mesh = SkinnedMesh::new(MeshData {
            positions: vec![p.to_array(); 3],
            normals: vec![[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], Vec3::new(1.0, 1.0, 1.0).normalize().to_array()],
            stride: 1,
            joints: vec![1; 3],
            weights: vec![1.0; 3],
            inverse_bind: vec![Affine3A::IDENTITY; 2],
            ..MeshData::default()
        }).unwrap().0;
        let m = Affine3A::from_rotation_translation(r, t);
        for method in Method::ALL {
            let out = deform(method, &mesh, &[Affine3A::IDENTITY, m]);
            for v in 0..3 {
                assert_close!(out.positions()[v], m.transform_point3(p).to_array(), 1e-5);
                assert_close!(out.normals()[v], m.transform_vector3(mesh.normal(v)).to_array(), 1e-5);
            }
        }
    }
}

#[test]
fn antipodal_rotations_in_one_blend_are_aligned() {
    // Two bones turned 170° and −170° about Y: as quaternions they lie in opposite
    // hemispheres though the rotations are only 20° apart, so the aligned blend turns the
    // vertex by 180°; an unaligned one would cancel the rotations out.
    let mesh = SkinnedMesh::new(MeshData {
        positions: vec![[1.0, 0.0, 0.0]],
        normals: vec![[1.0, 0.0, 0.0]],
        stride: 2,
        joints: vec![0, 1],
        weights: vec![0.5, 0.5],
        inverse_bind: vec![Affine3A::IDENTITY; 2],
        ..MeshData::default()
    })
    .unwrap()
    .0;
    let (a, b) = (Quat::from_rotation_y(170f32.to_radians()), Quat::from_rotation_y(-170f32.to_radians()));
    assert!(a.dot(b) < 0.0);
    let skinning = [Affine3A::from_quat(a), Affine3A::from_quat(b)];
    // The same blend written with `b` replaced by its aligned antipode `−b`.
    let aligned = (DualQuat::from_rotation(a) * 0.5 + DualQuat::from_rotation(-b) * 0.5).normalize();
    let expected = aligned.transform_point3(Vec3::X);
    assert_close!(expected, Vec3::NEG_X, 1e-5);
    for method in [Method::Qb, Method::Dqb] {
        let out = deform(method, &mesh, &skinning);
        assert_close!(out.positions()[0], expected.to_array(), 1e-5);
        assert_close!(out.normals()[0], expected.to_array(), 1e-5);
    }
}

#[test]
fn lb_normals_use_the_inverse_transpose() {
    // A non-rigid (scaled) bone: the normal of the plane x + y = 0 must stay perpendicular to
    // the deformed plane, which the blended matrix itself would not give.
    let mesh = SkinnedMesh::new(MeshData {
        positions: vec![[0.0; 3]],
        normals: vec![Vec3::new(1.0, 1.0, 0.0).normalize().to_array()],
        stride: 1,
        joints: vec![0],
        weights: vec![1.0],
        inverse_bind: vec![Affine3A::IDENTITY],
        ..MeshData::default()
    })
    .unwrap()
    .0;
    let m = Affine3A::from_scale(Vec3::new(2.0, 1.0, 1.0));
    let out = deform(Method::Lb, &mesh, &[m]);
    let tangent = m.transform_vector3(Vec3::new(1.0, -1.0, 0.0));
    assert_close!(Vec3::from(out.normals()[0]).dot(tangent), 0.0, 1e-6);
    assert_close!(Vec3::from(out.normals()[0]).length(), 1.0, 1e-6);
}

fn posed_hand(name: &str) -> (dqhand::model::Model, Vec<Affine3A>) {
    let model = build(&HandParams::default()).unwrap();
    let target = PoseTarget::Angles { model: JointModel::Full, pose: gesture(name).unwrap().pose(JointModel::Full) };
    let (skinning, _) = support::pose_skinning(&model, &target, Limits::Anatomical).unwrap();
    (model, skinning)
}

/// Angles in degrees between the deformed normals and the normals of the deformed surface
/// (area-weighted face normals), for the vertices `keep` selects; asserts unit length.
fn normal_errors(mesh: &SkinnedMesh, out: &Deformed, keep: impl Fn(usize) -> bool) -> Vec<f32> {
    let surface = vertex_normals(out.positions(), mesh.indices());
    let mut angles: Vec<f32> = (0..mesh.vertex_count())
        .filter(|&v| keep(v))
        .map(|v| {
            let n = Vec3::from(out.normals()[v]);
            assert_close!(n.length(), 1.0, 1e-4);
            n.angle_between(Vec3::from(surface[v])).to_degrees()
        })
        .collect();
    angles.sort_by(f32::total_cmp);
    angles
}

#[test]
fn normals_are_unit_and_turn_with_the_bone_where_one_bone_moves_the_skin() {
    // A vertex with a single influence moves rigidly with its bone, so every method must turn
    // its rest normal by exactly that bone's rotation.
    for g in ["fist", "ok", "victory"] {
        let (model, skinning) = posed_hand(g);
        let mesh = &model.mesh;
        let single: Vec<(usize, usize)> = (0..mesh.vertex_count())
            .filter_map(|v| {
                let infl: Vec<_> = mesh.influences(v).filter(|i| i.1 > 0.0).collect();
                (infl.len() == 1).then(|| (v, infl[0].0))
            })
            .collect();
        assert!(single.len() > mesh.vertex_count() / 10, "{} single-influence vertices", single.len());
        for method in Method::ALL {
            let out = deform(method, mesh, &skinning);
            let worst = single
                .iter()
                .map(|&(v, j)| {
                    let n = Vec3::from(out.normals()[v]);
                    assert_close!(n.length(), 1.0, 1e-4);
                    n.angle_between((skinning[j].matrix3 * Vec3A::from(mesh.normal(v))).into()).to_degrees()
                })
                .fold(0.0, f32::max);
            assert!(worst < 0.5, "{g} {method}: worst normal error {worst}° on single-bone vertices");
        }
    }
}

#[test]
fn dqb_and_lb_normals_follow_a_smoothly_bent_surface() {
    // A 60° bend of a slender tube (radius ¼ of the blend length). Eq. (6) and LB's inverse
    // transpose both ignore the gradient of the weights, so inside the blend they deviate
    // from the true surface normal by an amount that grows with bend angle × radius / blend
    // length (measured: median 0.1–0.2°, 90th percentile 14–16° here); away from the blend
    // they are exact. The open tube's end rings are left out.
    let mesh = cylinder(0.25);
    let pivot = Vec3::Y;
    let bend = Affine3A::from_translation(pivot) * Affine3A::from_rotation_x(60f32.to_radians()) * Affine3A::from_translation(-pivot);
    for method in [Method::Lb, Method::Dqb] {
        let out = deform(method, &mesh, &[Affine3A::IDENTITY, bend]);
        let angles = normal_errors(&mesh, &out, |v| (32..40 * 32).contains(&v));
        let (median, p90) = (angles[angles.len() / 2], angles[angles.len() * 9 / 10]);
        assert!(median < 1.0 && p90 < 20.0, "{method}: normal error median {median}°, 90th percentile {p90}°");
    }
}

/// On the built-in hand (the reference tests use small random meshes): every kernel this CPU
/// runs agrees with the portable one (which ran is said, and required with
/// `DQHAND_REQUIRE_KERNELS`: `support::kernels`); a deformation split across a crew's threads
/// (helpers parked or spinning), and a batch of poses, give exactly what one thread gives.
#[test]
fn kernels_threads_and_batches_agree_on_the_hand() {
    let (model, pinch) = posed_hand("pinch");
    let (_, fist) = posed_hand("fist");
    let mesh = &model.mesh;
    let pool = rayon::ThreadPoolBuilder::new().num_threads(3).build().unwrap();
    // Helpers that park at once (woken per frame) and helpers that spin between frames.
    let crews = [Duration::ZERO, Crew::SPIN].map(|spin| Arc::new(Crew::new(3, spin).unwrap()));
    assert!(mesh.vertex_count() >= 3 * MIN_VERTICES_PER_THREAD, "the hand is split three ways");
    let kernels = support::kernels::kernels();
    for method in Method::ALL {
        let mut portable = Deformed::new(mesh);
        Deformer::new(method, mesh).with_kernel(Kernel::Portable).deform(mesh, &pinch, &mut portable);
        for &kernel in &kernels.run {
            let single = deform_with(Deformer::new(method, mesh).with_kernel(kernel), mesh, &pinch);
            for (a, b) in single.positions().iter().zip(portable.positions()).chain(single.normals().iter().zip(portable.normals())) {
                assert_close!(*a, *b, 1e-5, "{method} on {kernel:?} against portable; {kernels}");
            }
            // Every lookup strategy of the AVX-512 kernel, forced, against the portable kernel.
            for strategy in if kernel == Kernel::Avx512 { &Strategy::ALL[..] } else { &[] } {
                let forced = deform_with(Deformer::new(method, mesh).with_kernel(kernel).with_strategy(*strategy), mesh, &pinch);
                for (a, b) in forced.positions().iter().zip(portable.positions()).chain(forced.normals().iter().zip(portable.normals())) {
                    assert_close!(*a, *b, 1e-5, "{method} on {kernel:?} ({}) against portable; {kernels}", strategy.name());
                }
            }
            let fisted = deform_with(Deformer::new(method, mesh).with_kernel(kernel), mesh, &fist);
            for crew in &crews {
                let mut split = Deformer::new(method, mesh).with_kernel(kernel).with_crew(Arc::clone(crew));
                let mut out = Deformed::new(mesh);
                // Two poses in turn: a piece left undone would keep the other pose.
                for i in 0..20 {
                    let (pose, expected) = if i % 2 == 0 { (&pinch, &single) } else { (&fist, &fisted) };
                    split.deform(mesh, pose, &mut out);
                    assert_eq!(&out, expected, "{method} on {kernel:?}: three threads, {crew:?}, frame {i}; {kernels}");
                }
                let mut only = Deformed::positions_only(mesh);
                split.deform(mesh, &pinch, &mut only);
                assert_eq!(only.positions(), single.positions(), "{method} on {kernel:?}: positions only, three threads; {kernels}");
            }
            let poses: Vec<Affine3A> = [&pinch, &fist, &pinch].into_iter().flatten().copied().collect();
            let mut batch = vec![Deformed::new(mesh); 3];
            Deformer::new(method, mesh).with_kernel(kernel).deform_batch(&pool, mesh, &poses, &mut batch);
            assert_eq!(batch, vec![single.clone(), fisted, single.clone()], "{method} on {kernel:?}: a batch; {kernels}");
        }
    }
}

/// The AVX-512 kernel's lookup strategies give the same bits, not only the same values to
/// rounding: the run-time choice is a matter of speed and must not change what is drawn, even
/// where a pair's sign alignment sits on a knife's edge (each phalanx turned a half-turn from
/// its parent, about axes in 24 directions: their rotations' dot product is 0 up to rounding;
/// the gather strategy's sign once summed it fused, and differed from the others here).
#[test]
fn every_lookup_strategy_gives_the_same_bits() {
    let (model, pinch) = posed_hand("pinch");
    let mesh = &model.mesh;
    let joints = model.skeleton.joints();
    // Half-turns about axes in many directions (which of a product's roundings the sum meets
    // first depends on the components' order and signs).
    let half_turned: Vec<Vec<Affine3A>> = (0..24)
        .map(|k| {
            let (theta, phi) = (k as f32 * 0.61, k as f32 * 1.37);
            let axis = glam::Vec3::new(theta.sin() * phi.cos(), theta.cos(), theta.sin() * phi.sin()).normalize();
            let mut pose = pinch.clone();
            for (j, joint) in joints.iter().enumerate().filter(|(_, j)| j.name.contains("phalanx")) {
                let parent = joint.parent.expect("a phalanx has a parent");
                pose[j] = pinch[parent] * Affine3A::from_axis_angle(axis, std::f32::consts::PI);
            }
            pose
        })
        .collect();
    let kernels = support::kernels::kernels();
    if !kernels.run.contains(&Kernel::Avx512) {
        // (`DQHAND_REQUIRE_KERNELS` makes the kernels' test fail where AVX-512 is required.)
        eprintln!("no AVX-512 kernel on this CPU: the strategies are not compared; {kernels}");
        return;
    }
    for method in Method::ALL {
        for pose in core::iter::once(&pinch).chain(&half_turned) {
            let outs: Vec<Deformed> = Strategy::ALL.iter().map(|&s| deform_with(Deformer::new(method, mesh).with_kernel(Kernel::Avx512).with_strategy(s), mesh, pose)).collect();
            for (s, out) in Strategy::ALL.iter().zip(&outs).skip(1) {
                let same = out.positions().iter().chain(out.normals()).zip(outs[0].positions().iter().chain(outs[0].normals())).all(|(a, b)| a.map(f32::to_bits) == b.map(f32::to_bits));
                assert!(same, "{method}: {} and {} differ", s.name(), Strategy::ALL[0].name());
            }
        }
    }
}

fn deform_with(mut deformer: Deformer, mesh: &SkinnedMesh, skinning: &[Affine3A]) -> Deformed {
    let mut out = Deformed::new(mesh);
    deformer.deform(mesh, skinning, &mut out);
    out
}

#[test]
fn the_rest_pose_reproduces_the_mesh() {
    let model = build(&HandParams::default()).unwrap();
    let skinning = support::pose_skinning(&model, &PoseTarget::LocalRotations(vec![]), Limits::Anatomical).unwrap().0;
    for method in Method::ALL {
        let out = deform(method, &model.mesh, &skinning);
        for v in (0..model.mesh.vertex_count()).step_by(7) {
            assert_close!(out.positions()[v], model.mesh.position(v).to_array(), 1e-5);
            assert_close!(out.normals()[v], model.mesh.normal(v).to_array(), 1e-4);
        }
    }
}

fn one_vertex(position: [f32; 3], joints: Vec<u32>, weights: Vec<f32>, inverse_bind: Vec<Affine3A>) -> MeshData {
    MeshData { positions: vec![position], stride: joints.len(), joints, weights, inverse_bind, ..MeshData::default() }
}

#[test]
fn malformed_meshes_are_rejected_with_the_culprit_named() {
    let ok_ib = vec![Affine3A::IDENTITY; 2];
    let err = |d: MeshData| SkinnedMesh::new(d).unwrap_err().to_string();
    assert!(err(one_vertex([f32::NAN, 0.0, 0.0], vec![0], vec![1.0], ok_ib.clone())).contains("vertex 0 has a non-finite position"));
    assert!(err(one_vertex([0.0; 3], vec![5], vec![1.0], ok_ib.clone())).contains("bound to joint 5"));
    assert!(err(one_vertex([0.0; 3], vec![0, 1], vec![0.0, 0.0], ok_ib.clone())).contains("vertex 0 has no positive weight"));
    assert!(err(one_vertex([0.0; 3], vec![0], vec![-1.0], ok_ib.clone())).contains("invalid weight"));
    assert!(err(one_vertex([0.0; 3], vec![0], vec![1.0], vec![Affine3A::ZERO])).contains("not invertible"));
    assert!(err(one_vertex([0.0; 3], vec![0; 9], vec![0.1; 9], ok_ib.clone())).contains("9 influences"));
    let mut uv = one_vertex([0.0; 3], vec![0], vec![1.0], ok_ib.clone());
    uv.uvs = vec![[0.5, f32::NAN]];
    assert!(err(uv).contains("vertex 0 has a non-finite texture coordinate"));
    let mut normal = one_vertex([0.0; 3], vec![0], vec![1.0], ok_ib.clone());
    normal.normals = vec![[0.0, f32::INFINITY, 0.0]];
    assert!(err(normal).contains("vertex 0 has a non-finite normal"));
    let mut tri = one_vertex([0.0; 3], vec![0], vec![1.0], ok_ib.clone());
    tri.indices = vec![0, 0, 3];
    assert!(err(tri).contains("triangle 0 uses vertex 3"));
    let (mesh, warnings) = SkinnedMesh::new(one_vertex([0.0; 3], vec![0, 1], vec![0.2, 0.2], ok_ib)).unwrap();
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    assert_eq!(mesh.influences(0).collect::<Vec<_>>(), vec![(0, 0.5), (1, 0.5)]);
}

#[test]
fn eight_influences_are_kept() {
    let ib = vec![Affine3A::IDENTITY; 8];
    let (mesh, _) = SkinnedMesh::new(one_vertex([1.0, 0.0, 0.0], (0..8).collect(), vec![0.125; 8], ib)).unwrap();
    assert_eq!(mesh.max_influences(), 8);
    assert_eq!(mesh.influences_per_vertex(), 8);
    let skinning: Vec<Affine3A> = (0..8).map(|i| Affine3A::from_translation(Vec3::Y * i as f32)).collect();
    for method in Method::ALL {
        assert_close!(deform(method, &mesh, &skinning).positions()[0], [1.0, 3.5, 0.0], 1e-5);
    }
}

#[test]
fn huge_weights_are_normalised_without_overflow() {
    let ib = vec![Affine3A::IDENTITY; 2];
    let (mesh, warnings) = SkinnedMesh::new(one_vertex([1.0, 0.0, 0.0], vec![0, 1], vec![3e38, 3e38], ib)).unwrap();
    assert_eq!(warnings.len(), 1);
    assert_eq!(mesh.influences(0).collect::<Vec<_>>(), vec![(0, 0.5), (1, 0.5)]);
}

#[test]
fn zero_length_normals_are_replaced_by_face_normals() {
    let mut d = one_vertex([0.0; 3], vec![0], vec![1.0], vec![Affine3A::IDENTITY]);
    d.positions = vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    (d.joints, d.weights, d.indices) = (vec![0; 3], vec![1.0; 3], vec![0, 1, 2]);
    d.normals = vec![[0.0; 3], [0.0, 0.0, 1.0], [0.0, 0.0, 1.0]];
    let (mesh, warnings) = SkinnedMesh::new(d).unwrap();
    assert_eq!(warnings[0], dqhand::Warning::NormalsReplaced { normals: 1 }, "{warnings:?}");
    assert_eq!(mesh.normal(0), Vec3::Z);
}

/// Grouping vertices by influence count moves whole vertices (position, normal, texture
/// coordinate, influences) within their part and renumbers the triangles to match.
#[test]
fn sorting_by_influence_count_keeps_every_vertex_and_triangle() {
    let n = 40;
    let counts = |v: usize| 1 + (v * 7 + v / 3) % 4;
    let mut data = MeshData {
        positions: (0..n).map(|v| [v as f32, (v * v) as f32, 1.0]).collect(),
        normals: (0..n).map(|v| Vec3::new(1.0, v as f32, 0.5).normalize().to_array()).collect(),
        uvs: (0..n).map(|v| [v as f32 / 40.0, 0.5]).collect(),
        stride: 4,
        indices: (0..n as u32 - 2).flat_map(|i| [i, i + 1, i + 2]).collect(),
        parts: vec![
            dqhand::skin::Part { name: "a".into(), vertices: 0..15, indices: 0..30 },
            dqhand::skin::Part { name: "b".into(), vertices: 15..n, indices: 30..(n - 2) * 3 },
        ],
        inverse_bind: vec![Affine3A::IDENTITY; 5],
        ..MeshData::default()
    };
    for v in 0..n {
        for s in 0..4 {
            data.joints.push(((v + s) % 5) as u32);
            data.weights.push(if s < counts(v) { 1.0 + s as f32 } else { 0.0 });
        }
    }
    let before = data.clone();
    data.sort_by_influence_count();
    let vertex = |d: &MeshData, v: usize| (d.positions[v], d.normals[v], d.uvs[v], d.joints[v * 4..][..4].to_vec(), d.weights[v * 4..][..4].to_vec());
    for part in &data.parts {
        let mut old: Vec<_> = part.vertices.clone().map(|v| format!("{:?}", vertex(&before, v))).collect();
        let mut new: Vec<_> = part.vertices.clone().map(|v| format!("{:?}", vertex(&data, v))).collect();
        old.sort();
        new.sort();
        assert_eq!(old, new, "part {}: the same vertices", part.name);
        let count = |v: usize| data.weights[v * 4..][..4].iter().filter(|&&w| w > 0.0).count();
        assert!(part.vertices.clone().zip(part.vertices.clone().skip(1)).all(|(a, b)| count(a) <= count(b)), "part {}: grouped", part.name);
    }
    let corners = |d: &MeshData| d.indices.chunks(3).map(|t| t.iter().map(|&i| d.positions[i as usize]).collect::<Vec<_>>()).collect::<Vec<_>>();
    assert_eq!(corners(&data), corners(&before), "every triangle joins the same points");
    assert!(SkinnedMesh::new(data).is_ok());
}

#[test]
fn the_built_in_hand_is_grouped_by_influence_count() {
    let model = build(&HandParams::default()).unwrap();
    let mesh = &model.mesh;
    let counts: Vec<usize> = (0..mesh.vertex_count()).map(|v| mesh.influences(v).count()).collect();
    assert!(counts.windows(2).all(|w| w[0] <= w[1]));
}

#[test]
fn a_skin_layer_follows_a_twist_until_told_to_forget_and_a_method_joining_follows_it_too() {
    // The cylinder twisted 0–190° in 10° steps through a skin layer, then the 190° frame
    // again after forgetting: followed, it is the way it turned (the opposite side of the
    // shortest way's 170°), forgotten it is what a new layer shows of 190°.
    let mesh = Arc::new(cylinder(1.0));
    let twist = |degrees: f32| [Affine3A::IDENTITY, Affine3A::from_rotation_y(degrees.to_radians())];
    let mut followed = SkinLayer::new(Arc::clone(&mesh), MethodSet::new(&[Method::Dqb]).unwrap());
    for step in 0..=19 {
        followed.deform(&twist(10.0 * step as f32)[..]);
    }
    let mut fresh = SkinLayer::new(Arc::clone(&mesh), MethodSet::new(&[Method::Dqb]).unwrap());
    fresh.deform(&twist(190.0)[..]);
    let at = |layer: &SkinLayer| layer.deformed(Method::Dqb).unwrap().positions().to_vec();
    let gap = |a: &[[f32; 3]], b: &[[f32; 3]]| a.iter().zip(b).map(|(p, q)| Vec3::from(*p).distance(Vec3::from(*q))).fold(0.0, f32::max);
    assert!(gap(&at(&followed), &at(&fresh)) > 0.5, "followed 190° should differ from the shortest way");
    followed.forget_previous_frame();
    followed.deform(&twist(190.0)[..]);
    assert_eq!(at(&followed), at(&fresh));

    // A method joining the set follows the frames the set deformed: QB shown beside DQB from
    // 190° on is the QB that followed the whole twist itself, not the shortest way's.
    let layer = |methods: &[Method]| SkinLayer::new(Arc::clone(&mesh), MethodSet::new(methods).unwrap());
    let (mut joined, mut alone, mut fresh_qb) = (layer(&[Method::Dqb]), layer(&[Method::Qb]), layer(&[Method::Qb]));
    for step in 0..=18 {
        joined.deform(&twist(10.0 * step as f32)[..]);
        alone.deform(&twist(10.0 * step as f32)[..]);
    }
    joined.set_methods(MethodSet::new(&[Method::Dqb, Method::Qb]).unwrap());
    joined.deform(&twist(190.0)[..]);
    alone.deform(&twist(190.0)[..]);
    fresh_qb.deform(&twist(190.0)[..]);
    let qb = |layer: &SkinLayer| layer.deformed(Method::Qb).unwrap().positions().to_vec();
    assert_eq!(qb(&joined), qb(&alone));
    assert!(gap(&qb(&joined), &qb(&fresh_qb)) > 0.5, "QB joining at 190° should follow the twist");
}

#[test]
fn on_the_webxr_generic_hand_a_twist_past_180_degrees_flips_alone_and_is_followed() {
    // A mesh the project did not make: its index intermediate phalanx, and the bones below it,
    // twisted 5–195° about the phalanx's axis in 10° steps, every other bone at bind.
    let model = support::webxr_hand();
    let (mesh, bind, skeleton) = (&model.mesh, model.bind_world(), &model.skeleton);
    let joint = skeleton.index_of("index-finger-phalanx-intermediate").unwrap();
    let child = skeleton.index_of("index-finger-phalanx-distal").unwrap();
    let (at, axis) = (Vec3::from(bind[joint].translation), Vec3::from(bind[child].translation - bind[joint].translation).normalize());
    let below = |mut i: usize| loop {
        if i == joint {
            return true;
        }
        match skeleton.joints()[i].parent {
            Some(p) => i = p,
            None => return false,
        }
    };
    let twist = |degrees: f32| {
        let m = Affine3A::from_translation(at) * Affine3A::from_axis_angle(axis, degrees.to_radians()) * Affine3A::from_translation(-at);
        (0..skeleton.len()).map(|i| if below(i) { m } else { Affine3A::IDENTITY }).collect::<Vec<_>>()
    };
    let largest_move = |a: &[[f32; 3]], b: &[[f32; 3]]| a.iter().zip(b).map(|(p, q)| Vec3::from(*p).distance(Vec3::from(*q))).fold(0.0, f32::max);
    // 175° to 185°: the step where the nearer hemisphere switches.
    let flip = 18;
    for method in [Method::Qb, Method::Dqb, Method::Cor] {
        let (mut followed, mut alone) = (Deformer::new(method, mesh), Deformer::new(method, mesh));
        let (mut steps_followed, mut steps_alone) = (Vec::new(), Vec::new());
        let (mut last_followed, mut last_alone): (Option<Vec<[f32; 3]>>, Option<Vec<[f32; 3]>>) = (None, None);
        for step in 0..20 {
            let skinning = twist(5.0 + 10.0 * step as f32);
            let (mut f, mut a) = (Deformed::positions_only(mesh), Deformed::positions_only(mesh));
            followed.deform(mesh, &skinning, &mut f);
            alone.forget_previous_frame();
            alone.deform(mesh, &skinning, &mut a);
            if let (Some(lf), Some(la)) = (&last_followed, &last_alone) {
                steps_followed.push(largest_move(lf, f.positions()));
                steps_alone.push(largest_move(la, a.positions()));
            }
            (last_followed, last_alone) = (Some(f.positions().to_vec()), Some(a.positions().to_vec()));
        }
        // steps[i] is the step into frame i + 1.
        let elsewhere = |steps: &[f32]| steps.iter().enumerate().filter(|(i, _)| i + 1 != flip).map(|(_, s)| *s).fold(0.0, f32::max);
        let (at_flip_alone, at_flip_followed) = (steps_alone[flip - 1], steps_followed[flip - 1]);
        assert!(at_flip_alone > 3.0 * elsewhere(&steps_alone), "{method} alone: {at_flip_alone} m at 175→185°, at most {} elsewhere", elsewhere(&steps_alone));
        assert!(at_flip_followed < 1.5 * elsewhere(&steps_followed), "{method} followed: {at_flip_followed} m at 175→185°, at most {} elsewhere", elsewhere(&steps_followed));
    }
}
