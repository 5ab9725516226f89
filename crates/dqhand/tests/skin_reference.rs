//! LB, QB, DQB and CoR against an independent reference: plain `f64` code written from the
//! definitions (design.md, paper section 4.4, Kavan et al. 2008, Le and Hodgins 2016),
//! sharing nothing with the kernel — not its parameter layout, not its sign alignment, not
//! its normalisation. CoR's centres are random here, given with the mesh: its precomputation
//! has its own reference (tests/centres_of_rotation.rs).
//!
//! Regression for issue 9 bug 1: QB's sign alignment used to flip the translation with the
//! rotation, so a vertex whose influences lay in opposite quaternion hemispheres got
//! `Σ wᵢ sᵢ tᵢ` instead of `Σ wᵢ tᵢ`. Rotations up to 180° put neighbouring bones in opposite
//! hemispheres often, and the reference flips the sign of its own bone quaternions at
//! random, so the result must not depend on the sign either side picks.

mod support;

use dqhand::skin::{Deformed, Deformer, Kernel, MeshData, Method, SkinnedMesh, Strategy as LookupStrategy};
use glam::{Affine3A, DMat3, DQuat, DVec3, Quat, Vec3};
use proptest::prelude::*;

/// One random skinned vertex set and a pose: per joint a skinning transform and a sign flip.
#[derive(Debug, Clone)]
struct Case {
    positions: Vec<[f32; 3]>,
    normals: Vec<[f32; 3]>,
    /// Per vertex, (joint, weight) influences; weights not normalised.
    influences: Vec<Vec<(u32, f32)>>,
    /// Per vertex, its centre of rotation (CoR).
    centres: Vec<[f32; 3]>,
    skinning: Vec<Affine3A>,
    flips: Vec<bool>,
}

/// Joints of most cases. The AVX-512 kernel looks parameters and pair signs up from two
/// registers per table up to 32 joints, and gathers past that: one test fills both
/// registers ([`TABLE_JOINTS`]), one uses [`MANY_JOINTS`].
const JOINTS: usize = 6;
const TABLE_JOINTS: usize = 32;
const MANY_JOINTS: usize = 40;

fn case(max_influences: usize) -> impl Strategy<Value = Case> {
    case_of(JOINTS, max_influences)
}

fn case_of(joints: usize, max_influences: usize) -> impl Strategy<Value = Case> {
    let vertex = (
        (-1.0f32..1.0, -1.0f32..1.0, -1.0f32..1.0),
        (-1.0f32..1.0, -1.0f32..1.0, -1.0f32..1.0).prop_filter("normal", |n| n.0.abs() + n.1.abs() + n.2.abs() > 0.2),
        proptest::collection::vec((0..joints as u32, 0.05f32..1.0), 1..=max_influences).prop_map(|mut inf| {
            inf.sort_by_key(|i| i.0);
            inf.dedup_by_key(|i| i.0);
            inf
        }),
        (-1.0f32..1.0, -1.0f32..1.0, -1.0f32..1.0),
    );
    let bone = (
        (-1.0f64..1.0, -1.0f64..1.0, -1.0f64..1.0).prop_filter("axis", |a| a.0.abs() + a.1.abs() + a.2.abs() > 0.2),
        0.0f64..std::f64::consts::PI,
        (-2.0f32..2.0, -2.0f32..2.0, -2.0f32..2.0),
        any::<bool>(),
    );
    (proptest::collection::vec(vertex, 1..72), proptest::collection::vec(bone, joints)).prop_map(|(vs, bones)| {
        let mut c = Case { positions: vec![], normals: vec![], influences: vec![], centres: vec![], skinning: vec![], flips: vec![] };
        for (p, n, inf, centre) in vs {
            c.centres.push([centre.0, centre.1, centre.2]);
            c.positions.push([p.0, p.1, p.2]);
            let n = Vec3::new(n.0, n.1, n.2).normalize();
            c.normals.push(n.to_array());
            c.influences.push(inf);
        }
        for (axis, angle, t, flip) in bones {
            let q = DQuat::from_axis_angle(DVec3::new(axis.0, axis.1, axis.2).normalize(), angle);
            c.skinning.push(Affine3A::from_rotation_translation(q.as_quat(), Vec3::new(t.0, t.1, t.2)));
            c.flips.push(flip);
        }
        c
    })
}

fn mesh(c: &Case, stride: usize) -> SkinnedMesh {
    let mut data = MeshData {
        positions: c.positions.clone(),
        normals: c.normals.clone(),
        stride,
        inverse_bind: vec![Affine3A::IDENTITY; c.skinning.len()],
        ..MeshData::default()
    };
    for inf in &c.influences {
        for s in 0..stride {
            let (j, w) = inf.get(s).copied().unwrap_or((0, 0.0));
            data.joints.push(j);
            data.weights.push(w);
        }
    }
    SkinnedMesh::new(data).expect("valid mesh").0.with_centres_of_rotation(&c.centres).expect("one centre per vertex")
}

/// A bone's rotation and translation in `f64`, read off the matrix by Shepperd's method
/// (written here, not glam's or the kernel's conversion), its sign flipped on request.
fn bone(m: &Affine3A, flip: bool) -> (DQuat, DVec3) {
    let r = DMat3::from_cols(m.matrix3.x_axis.as_dvec3(), m.matrix3.y_axis.as_dvec3(), m.matrix3.z_axis.as_dvec3());
    let e = |row: usize, col: usize| r.col(col)[row];
    let trace = e(0, 0) + e(1, 1) + e(2, 2);
    let (x, y, z, w) = if trace > 0.0 {
        let s = 2.0 * (1.0 + trace).sqrt();
        ((e(2, 1) - e(1, 2)) / s, (e(0, 2) - e(2, 0)) / s, (e(1, 0) - e(0, 1)) / s, s / 4.0)
    } else if e(0, 0) > e(1, 1) && e(0, 0) > e(2, 2) {
        let s = 2.0 * (1.0 + e(0, 0) - e(1, 1) - e(2, 2)).sqrt();
        (s / 4.0, (e(0, 1) + e(1, 0)) / s, (e(0, 2) + e(2, 0)) / s, (e(2, 1) - e(1, 2)) / s)
    } else if e(1, 1) > e(2, 2) {
        let s = 2.0 * (1.0 + e(1, 1) - e(0, 0) - e(2, 2)).sqrt();
        ((e(0, 1) + e(1, 0)) / s, s / 4.0, (e(1, 2) + e(2, 1)) / s, (e(0, 2) - e(2, 0)) / s)
    } else {
        let s = 2.0 * (1.0 + e(2, 2) - e(0, 0) - e(1, 1)).sqrt();
        ((e(0, 2) + e(2, 0)) / s, (e(1, 2) + e(2, 1)) / s, s / 4.0, (e(1, 0) - e(0, 1)) / s)
    };
    let q = DQuat::from_xyzw(x, y, z, w);
    (if flip { -q } else { q }, m.translation.as_dvec3())
}

/// Hamilton product, written out.
fn mul(a: [f64; 4], b: [f64; 4]) -> [f64; 4] {
    let [ax, ay, az, aw] = a;
    let [bx, by, bz, bw] = b;
    [
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
        aw * bw - ax * bx - ay * by - az * bz,
    ]
}

fn conj(q: [f64; 4]) -> [f64; 4] {
    [-q[0], -q[1], -q[2], q[3]]
}

/// `q v q*` for a unit `q`.
fn rotate(q: [f64; 4], v: DVec3) -> DVec3 {
    let r = mul(mul(q, [v.x, v.y, v.z, 0.0]), conj(q));
    DVec3::new(r[0], r[1], r[2])
}

/// The reference position and normal of vertex `v` under `method`, and the condition number
/// of the normal's transform (LB's blended matrix, near singular where LB collapses: a
/// float computation of its inverse loses that many times more; 1 for the rotations of QB
/// and DQB). `None` where QB's or DQB's hemisphere sign is undecided: an influence's rotation
/// is 180° from the heaviest one's, their quaternions' dot product within rounding of 0,
/// and either sign is as right (the blends differ completely).
fn reference(c: &Case, v: usize, method: Method) -> Option<(DVec3, DVec3, f64)> {
    reference_of(c, v, method, None)
}

/// As [`reference`], or with `turned` each joint's rotation as the quaternion of the way it
/// turned, blended as given: no hemisphere is chosen, the skin follows the turn.
fn reference_of(c: &Case, v: usize, method: Method, turned: Option<&[DQuat]>) -> Option<(DVec3, DVec3, f64)> {
    let total: f64 = c.influences[v].iter().map(|i| f64::from(i.1)).sum();
    let inf: Vec<(usize, f64)> = c.influences[v].iter().map(|&(j, w)| (j as usize, f64::from(w) / total)).collect();
    let p = Vec3::from(c.positions[v]).as_dvec3();
    let n = Vec3::from(c.normals[v]).as_dvec3();
    match method {
        Method::Lb => {
            // v' = Σ wᵢ Mᵢ v; n' = normalise((Σ wᵢ Rᵢ)⁻ᵀ n).
            let mut r = DMat3::ZERO;
            let mut t = DVec3::ZERO;
            for &(j, w) in &inf {
                let m = &c.skinning[j];
                r += DMat3::from_cols(m.matrix3.x_axis.as_dvec3(), m.matrix3.y_axis.as_dvec3(), m.matrix3.z_axis.as_dvec3()) * w;
                t += m.translation.as_dvec3() * w;
            }
            let frobenius = |m: DMat3| (m.x_axis.length_squared() + m.y_axis.length_squared() + m.z_axis.length_squared()).sqrt();
            Some((r * p + t, (r.inverse().transpose() * n).normalize(), frobenius(r) * frobenius(r.inverse())))
        }
        Method::Qb | Method::Dqb | Method::Cor => {
            let bones: Vec<(usize, f64, [f64; 4], DVec3)> = inf
                .iter()
                .map(|&(j, w)| {
                    let (q, t) = bone(&c.skinning[j], c.flips[j]);
                    let q = turned.map_or(q, |turned| turned[j]);
                    (j, w, [q.x, q.y, q.z, q.w], t)
                })
                .collect();
            let heaviest = bones.iter().fold(&bones[0], |a, b| if b.1 > a.1 { b } else { a }).2;
            let dot = |q: [f64; 4]| q.iter().zip(&heaviest).map(|(a, b)| a * b).sum::<f64>();
            if turned.is_none() && bones.iter().any(|b| dot(b.2).abs() < 1e-5) {
                return None;
            }
            let sign = |q: [f64; 4]| if turned.is_none() && dot(q) < 0.0 { -1.0 } else { 1.0 };
            if method != Method::Dqb {
                // q = normalise(Σ wᵢ sᵢ qᵢ). QB: t = Σ wᵢ tᵢ, v' = q v q* + t. CoR, about
                // the centre c: v' = q (v − c) q* + Σ wᵢ (qᵢ c qᵢ* + tᵢ).
                let mut q = [0.0; 4];
                let mut t = DVec3::ZERO;
                let mut moved_centre = DVec3::ZERO;
                let centre = Vec3::from(c.centres[v]).as_dvec3();
                for &(_, w, qi, ti) in &bones {
                    let s = sign(qi);
                    (0..4).for_each(|k| q[k] += w * s * qi[k]);
                    t += ti * w;
                    moved_centre += (rotate(qi, centre) + ti) * w;
                }
                let len = q.iter().map(|x| x * x).sum::<f64>().sqrt();
                let q = q.map(|x| x / len);
                let position = if method == Method::Qb { rotate(q, p) + t } else { rotate(q, p - centre) + moved_centre };
                Some((position, rotate(q, n), 1.0))
            } else {
                // b̂ = Σ wᵢ sᵢ q̂ᵢ with q̂ = q + ε ½ t q; b̂ / ‖b₀‖;
                // v' = b₀ v b₀* + 2 vec(b_ε b₀*) (paper eq. 3–6).
                let (mut real, mut dual) = ([0.0; 4], [0.0; 4]);
                for &(_, w, qi, ti) in &bones {
                    let s = sign(qi);
                    let d = mul([ti.x, ti.y, ti.z, 0.0], qi).map(|x| 0.5 * x);
                    (0..4).for_each(|k| {
                        real[k] += w * s * qi[k];
                        dual[k] += w * s * d[k];
                    });
                }
                let len = real.iter().map(|x| x * x).sum::<f64>().sqrt();
                let (real, dual) = (real.map(|x| x / len), dual.map(|x| x / len));
                let t = mul(dual, conj(real)).map(|x| 2.0 * x);
                Some((rotate(real, p) + DVec3::new(t[0], t[1], t[2]), rotate(real, n), 1.0))
            }
        }
    }
}

/// Every method on every kernel this CPU runs, and on the AVX-512 kernel every lookup
/// strategy, positions and normals, then positions only (which kernels ran is said, and
/// required with `DQHAND_REQUIRE_KERNELS`: `support::kernels`).
fn check(c: &Case, stride: usize) -> Result<(), TestCaseError> {
    let mesh = mesh(c, stride);
    let kernels = support::kernels::kernels();
    for (kernel, strategy) in paths(&kernels) {
        for method in Method::ALL {
            let mut deformer = deformer(method, &mesh, kernel, strategy);
            let kernel = format!("{kernel:?}{}", strategy.map_or(String::new(), |s| format!(" ({})", s.name())));
            let (mut out, mut only) = (Deformed::new(&mesh), Deformed::positions_only(&mesh));
            deformer.deform(&mesh, &c.skinning, &mut out);
            deformer.deform(&mesh, &c.skinning, &mut only);
            prop_assert!(only.normals().is_empty(), "{method} on {kernel}: normals when only positions are asked for; {kernels}");
            for v in 0..c.positions.len() {
                let Some((p, n, condition)) = reference(c, v, method) else { continue };
                let (gp, gn) = (Vec3::from(out.positions()[v]).as_dvec3(), Vec3::from(out.normals()[v]).as_dvec3());
                prop_assert!(gp.distance(p) < 2e-4, "{method} on {kernel}, vertex {v}: position {gp} but the reference gives {p}; {kernels}");
                // Rounding of f32 (~1e-7) grows with the condition number (3 for a rotation).
                let normal_tolerance = 2e-4_f64.max(1e-6 * condition);
                prop_assert!(gn.distance(n) < normal_tolerance, "{method} on {kernel}, vertex {v}: normal {gn} but the reference gives {n} (condition {condition:.0}); {kernels}");
                let op = Vec3::from(only.positions()[v]).as_dvec3();
                prop_assert!(op.distance(p) < 2e-4, "{method} on {kernel}, positions only, vertex {v}: {op} but the reference gives {p}; {kernels}");
            }
        }
    }
    Ok(())
}

/// Every kernel this CPU runs, and on the AVX-512 kernel each lookup strategy.
fn paths(kernels: &support::kernels::Kernels) -> Vec<(Kernel, Option<LookupStrategy>)> {
    kernels.run.iter().flat_map(|&k| if k == Kernel::Avx512 { LookupStrategy::ALL.map(Some).to_vec() } else { vec![None] }.into_iter().map(move |s| (k, s))).collect()
}

fn deformer(method: Method, mesh: &SkinnedMesh, kernel: Kernel, strategy: Option<LookupStrategy>) -> Deformer {
    let deformer = Deformer::new(method, mesh).with_kernel(kernel);
    match strategy {
        Some(s) => deformer.with_strategy(s),
        None => deformer,
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    #[test]
    fn the_kernels_match_the_reference_with_up_to_four_influences(c in case(4)) {
        check(&c, 4)?;
    }

    #[test]
    fn the_kernels_match_the_reference_with_up_to_eight_influences(c in case(8)) {
        check(&c, 8)?;
    }

    #[test]
    fn the_kernels_match_the_reference_with_a_full_register_table(c in case_of(TABLE_JOINTS, 4)) {
        check(&c, 4)?;
    }

    #[test]
    fn the_kernels_match_the_reference_with_more_joints_than_a_register_table(c in case_of(MANY_JOINTS, 4)) {
        check(&c, 4)?;
    }
}

#[test]
fn qb_translation_is_not_flipped_with_the_rotation() {
    // Two bones turned 170° and −89° about Y and translated by +X and +Z. Converted from
    // their matrices (largest component kept positive) their quaternions are
    // (0, 0.996, 0, 0.087) and (0, −0.70, 0, 0.71): opposite hemispheres. QB must still
    // translate the vertex at the origin by the plain mean, (0.5, 0, 0.5).
    let c = Case {
        positions: vec![[0.0; 3]],
        normals: vec![[0.0, 1.0, 0.0]],
        influences: vec![vec![(0, 0.5), (1, 0.5)]],
        centres: vec![[0.0; 3]],
        skinning: vec![
            Affine3A::from_rotation_translation(Quat::from_rotation_y(170f32.to_radians()), Vec3::X),
            Affine3A::from_rotation_translation(Quat::from_rotation_y(-89f32.to_radians()), Vec3::Z),
        ],
        flips: vec![false, false],
    };
    let mesh = mesh(&c, 2);
    let mut out = Deformed::new(&mesh);
    Deformer::new(Method::Qb, &mesh).deform(&mesh, &c.skinning, &mut out);
    assert_close!(out.positions()[0], [0.5, 0.0, 0.5], 1e-5);
    let (p, _, _) = reference(&c, 0, Method::Qb).expect("signs decided");
    assert_close!(out.positions()[0], p.as_vec3().to_array(), 1e-5);
}


/// A forearm-like cylinder: joint 0 placed by a fixed rigid motion, joint 1 twisted by
/// `degrees` about the cylinder's axis (X) on top of it, and the vertices' weights passing
/// from one to the other along X. Returns the case and the quaternions of the way each joint
/// turned (joint 1's continuous in the twist, never re-signed).
fn twisted(degrees: f64) -> (Case, Vec<DQuat>) {
    let placed = DQuat::from_axis_angle(DVec3::new(1.0, 2.0, 3.0).normalize(), 0.7);
    let turned = [placed, placed * DQuat::from_axis_angle(DVec3::X, degrees.to_radians())];
    let offset = Vec3::new(0.1, -0.2, 0.3);
    // Joint 1 twists about the axis itself, so both translations are the placement's.
    let skinning = turned.map(|q| Affine3A::from_rotation_translation(q.as_quat(), offset)).to_vec();
    let mut c = Case { positions: vec![], normals: vec![], influences: vec![], centres: vec![], skinning, flips: vec![false; 2] };
    for i in 0..24 {
        let (x, around) = (0.2 + 0.6 * (i / 6) as f32 / 3.0, std::f32::consts::TAU * (i % 6) as f32 / 6.0);
        let n = Vec3::new(0.0, around.cos(), around.sin());
        c.positions.push((Vec3::new(x, 0.0, 0.0) + 0.1 * n).to_array());
        c.normals.push(n.to_array());
        c.influences.push(vec![(0, 1.0 - x), (1, x)]);
        c.centres.push([x, 0.0, 0.0]);
    }
    (c, turned.to_vec())
}

#[test]
fn a_twist_past_180_degrees_is_followed_the_way_it_turned_up_to_270() {
    // Twisted frame by frame in 10° steps, every method on every kernel blends joint 1 the
    // way it turned while the twist is under 270° and the shortest way past it. A jump
    // (355° to 185°) takes the shortest way, −175°; the next step, to −185°, is followed on
    // that way; after a forgotten frame, −195° is the shortest way's 165°. From there a jump of
    // 75° to 240° takes the shortest way, −120°, and steps of 40° and 55° are followed to −215°.
    let kernels = support::kernels::kernels();
    let mesh = mesh(&twisted(0.0).0, 4);
    // (twist, blended the way it turned, the previous frame forgotten)
    let mut frames: Vec<(f64, bool, bool)> = (0..36).map(|step| 5.0 + 10.0 * f64::from(step)).map(|d| (d, d < 270.0, false)).collect();
    frames.extend([(185.0, false, false), (-185.0, true, false), (-195.0, false, true), (240.0, false, false), (-160.0, true, false), (-215.0, true, false)]);
    for (kernel, strategy) in paths(&kernels) {
        for method in Method::ALL {
            let mut deformer = deformer(method, &mesh, kernel, strategy);
            let mut out = Deformed::new(&mesh);
            for (frame, &(degrees, followed, forgotten)) in frames.iter().enumerate() {
                let (c, turned) = twisted(degrees);
                if forgotten {
                    deformer.forget_previous_frame();
                }
                deformer.deform(&mesh, &c.skinning, &mut out);
                for v in 0..c.positions.len() {
                    let (p, n, _) = reference_of(&c, v, method, followed.then_some(&turned[..])).expect("signs decided");
                    let (gp, gn) = (Vec3::from(out.positions()[v]).as_dvec3(), Vec3::from(out.normals()[v]).as_dvec3());
                    assert!(
                        gp.distance(p) < 2e-4 && gn.distance(n) < 2e-4,
                        "{method} on {kernel:?} {strategy:?}, frame {frame} (twist {degrees}°, followed {followed}), vertex {v}: {gp} {gn} but the reference gives {p} {n}; {kernels}"
                    );
                }
            }
        }
    }
}
