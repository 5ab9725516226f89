//! The built-in anatomical hand: a closed 2-manifold at every density, the skeleton inside it,
//! valid and local skin weights, the user's size, both sides, and clear errors.

use std::collections::HashSet;

use dqhand::hand::{build, HandParams, Side, DEFAULT_VERTICES};
use dqhand::kinematics::webxr;
use dqhand::geometry::{check_closed, edges, enclosed_volume, winding_number};
use dqhand::metrics::count_self_intersections;
use dqhand::model::Model;
use glam::{Vec3, Vec3Swizzles};

fn hand(params: HandParams) -> Model {
    build(&params).unwrap_or_else(|e| panic!("{params:?}: {e}"))
}

/// Checks what makes the mesh a sphere-like closed surface and returns its volume.
fn assert_closed_sphere(model: &Model, vertices: usize) -> f64 {
    let mesh = &model.mesh;
    assert_eq!(mesh.vertex_count(), vertices);
    // Every edge used by exactly two triangles, once in each direction.
    check_closed(mesh.indices()).unwrap();
    let (v, e, f) = (mesh.vertex_count() as i64, edges(mesh.indices()).len() as i64, mesh.triangle_count() as i64);
    assert_eq!(v - e + f, 2, "Euler characteristic of a sphere");
    let used: HashSet<u32> = mesh.indices().iter().copied().collect();
    assert_eq!(used.len(), vertices, "every vertex is on a triangle");
    let volume = enclosed_volume(&mesh.positions(), mesh.indices());
    assert!(volume > 0.0, "triangles face outward");
    volume
}

#[test]
fn default_hand_is_a_closed_manifold_with_the_papers_vertex_count() {
    let model = hand(HandParams::default());
    let volume = assert_closed_sphere(&model, DEFAULT_VERTICES);
    // An adult hand (to the wrist crease plus the short forearm stub) holds about 0.4 l.
    assert!((250e-6..600e-6).contains(&volume), "volume {volume} m³");
    assert_eq!(model.mesh.max_influences(), 4);
    assert_eq!(model.mesh.uvs().len(), DEFAULT_VERTICES);
}

#[test]
fn every_density_is_a_closed_manifold() {
    for vertices in [1_000, 3_000, 20_000] {
        let model = hand(HandParams { vertices, ..HandParams::default() });
        assert_closed_sphere(&model, vertices);
    }
}

#[test]
fn rest_pose_has_no_self_intersections() {
    let base = HandParams::default();
    for params in [base, HandParams { side: Side::Left, ..base }, HandParams { vertices: 3_000, ..base }, HandParams { length: 0.165, breadth: 0.072, ..base }] {
        let model = hand(params);
        assert_eq!(count_self_intersections(&model.mesh.positions(), model.mesh.indices()), 0, "{params:?}");
    }
}

#[test]
fn every_joint_centre_is_inside_the_skin() {
    for side in [Side::Right, Side::Left] {
        let model = hand(HandParams { side, ..HandParams::default() });
        let positions = model.mesh.positions();
        let world = model.skeleton.rest_world();
        for (j, name) in webxr::JOINT_NAMES.iter().enumerate() {
            let w = winding_number(&positions, model.mesh.indices(), world[j].translation.into());
            assert!((w - 1.0).abs() < 1e-3, "{side:?} {name}: winding number {w}");
        }
    }
}

#[test]
fn normals_point_out_of_the_surface() {
    let model = hand(HandParams::default());
    let positions = model.mesh.positions();
    // A point a millimetre along each normal is outside, a millimetre against it inside.
    for v in (0..model.mesh.vertex_count()).step_by(97) {
        let (p, n) = (model.mesh.position(v), model.mesh.normal(v));
        assert!((n.length() - 1.0).abs() < 1e-4);
        let outside = winding_number(&positions, model.mesh.indices(), p + n * 1e-3);
        let inside = winding_number(&positions, model.mesh.indices(), p - n * 1e-3);
        assert!(outside < 0.1 && inside > 0.9, "vertex {v}: {outside} / {inside}");
    }
}

fn joint(name: &str) -> usize {
    webxr::JOINT_NAMES.iter().position(|&n| n == name).unwrap()
}

#[test]
fn weights_are_local_to_the_finger() {
    let model = hand(HandParams::default());
    let world = model.skeleton.rest_world();
    for finger in webxr::FINGERS {
        let tip = joint(&format!("{finger}-tip"));
        let own: Vec<usize> = (joint(&format!("{finger}-metacarpal"))..tip).collect();
        let tip_at = Vec3::from(world[tip].translation);
        let mut near_tip = 0;
        for v in 0..model.mesh.vertex_count() {
            if model.mesh.position(v).distance(tip_at) < 0.015 {
                near_tip += 1;
                for (j, w) in model.mesh.influences(v) {
                    assert!(w == 0.0 || own.contains(&j), "{finger} tip vertex {v} moves with {}", webxr::JOINT_NAMES[j]);
                }
                assert!(model.mesh.influences(v).all(|(j, w)| w == 0.0 || j != 0), "wrist on a fingertip");
            }
        }
        assert!(near_tip > 20, "{finger}: {near_tip} vertices near the tip");
    }
}

#[test]
fn weights_change_smoothly_across_the_surface() {
    let model = hand(HandParams::default());
    let n = model.skeleton.len();
    let dense = |v: usize| {
        let mut w = vec![0.0f32; n];
        for (j, x) in model.mesh.influences(v) {
            w[j] += x;
        }
        w
    };
    let mut worst = 0.0f32;
    for [a, b] in edges(model.mesh.indices()) {
        let (wa, wb) = (dense(a as usize), dense(b as usize));
        let jump = wa.iter().zip(&wb).map(|(x, y)| (x - y).abs()).fold(0.0, f32::max);
        worst = worst.max(jump);
    }
    // Across one edge (about 2 mm) no weight changes by more than 0.65. The largest changes
    // are in the crotch of the webs, where the skin of two fingers meets (about 0.62).
    assert!(worst < 0.65, "largest weight change across an edge: {worst}");
}

fn extent(model: &Model) -> (Vec3, Vec3) {
    (0..model.mesh.vertex_count()).map(|v| model.mesh.position(v)).fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), p| (lo.min(p), hi.max(p)))
}

#[test]
fn the_hand_has_the_users_size() {
    for (length, breadth) in [(0.19, 0.085), (0.165, 0.072), (0.21, 0.095)] {
        let model = hand(HandParams { length, breadth, vertices: 3_000, ..HandParams::default() });
        let (lo, _) = extent(&model);
        // Wrist crease (z = 0) to the tip of the middle finger.
        assert!((-lo.z / length - 1.0).abs() < 0.04, "length {length}: {}", -lo.z);
        // Breadth across the metacarpal heads: the skin's width at the MCP level.
        let mcp_z = model.skeleton.rest_world()[joint("middle-finger-phalanx-proximal")].translation.z;
        let (mut min_x, mut max_x) = (f32::INFINITY, f32::NEG_INFINITY);
        for v in 0..model.mesh.vertex_count() {
            let p = model.mesh.position(v);
            let heaviest = model.mesh.influences(v).next().map_or(0, |(j, _)| j);
            if (p.z - mcp_z).abs() < 0.004 && !webxr::JOINT_NAMES[heaviest].starts_with("thumb") {
                min_x = min_x.min(p.x);
                max_x = max_x.max(p.x);
            }
        }
        assert!(((max_x - min_x) / breadth - 1.0).abs() < 0.1, "breadth {breadth}: {}", max_x - min_x);
    }
}

#[test]
fn left_hand_mirrors_the_right() {
    let right = hand(HandParams::default());
    let left = hand(HandParams { side: Side::Left, ..HandParams::default() });
    let ((rlo, rhi), (llo, lhi)) = (extent(&right), extent(&left));
    assert!((rlo.x + lhi.x).abs() < 1e-3 && (rhi.x + llo.x).abs() < 1e-3, "{rlo} {rhi} / {llo} {lhi}");
    assert!((rlo.yz() - llo.yz()).abs().max_element() < 1e-3);
    let [rw, lw] = [&right, &left].map(|m| m.skeleton.rest_world());
    for j in 0..rw.len() {
        let mirrored = Vec3::from(rw[j].translation) * Vec3::new(-1.0, 1.0, 1.0);
        assert!(mirrored.distance(lw[j].translation.into()) < 1e-6, "{}", webxr::JOINT_NAMES[j]);
    }
    let volume = |m: &Model| enclosed_volume(&m.mesh.positions(), m.mesh.indices());
    assert!((volume(&left) / volume(&right) - 1.0).abs() < 0.01);
}

#[test]
fn implausible_parameters_are_refused() {
    let base = HandParams::default();
    for (params, words) in [
        (HandParams { length: 0.0, ..base }, "length"),
        (HandParams { length: f32::NAN, ..base }, "length"),
        (HandParams { breadth: -0.08, ..base }, "breadth"),
        (HandParams { breadth: 0.2, ..base }, "breadth"),
        (HandParams { breadth: 0.03, ..base }, "breadth"),
        (HandParams { vertices: 0, ..base }, "vertices"),
        (HandParams { vertices: 10_000_000, ..base }, "vertices"),
    ] {
        let e = build(&params).unwrap_err().to_string();
        assert!(e.contains(words) && !e.contains('\n'), "{params:?}: {e}");
    }
}
