//! The shape the physics simulates a hull proxy as (`collision::simulated_hull`) holds the
//! whole proxy and is little larger: on the built-in hand's proxies and on the WebXR generic
//! hand's (a mesh the project did not make), against the hull of its own vertices built again
//! here and every proxy vertex's distance from it.

mod support;

use dqhand::collision::{fit_proxies, simulated_hull, ProxyShape, MAX_SIMULATED_VERTICES, PROXY_MARGIN};
use dqhand::model::Model;
use glam::Vec3;
use parry3d::query::PointQuery;
use parry3d::shape::Triangle;

fn holds_the_proxy_and_is_little_larger(model: &Model) {
    let mut hulls = 0;
    let mut rng = dqhand::math::Rng::new(11);
    let directions: Vec<Vec3> = (0..500).map(|_| rng.unit()).collect();
    for proxy in fit_proxies(model, PROXY_MARGIN) {
        let ProxyShape::ConvexHull { points, .. } = &proxy.shape else { continue };
        hulls += 1;
        let simulated = simulated_hull(points).expect("a hull spans a volume");
        let round = simulated.as_round_convex_polyhedron().expect("a rounded hull");
        let radius = round.border_radius;
        let inner = round.inner_shape.points();
        // Every vertex of the proxy is in it: no farther from the inner hull than the rounding
        // (inside every face's plane, or near enough to some face).
        let (vertices, faces) = parry3d::transformation::try_convex_hull(inner).expect("a hull");
        let faces: Vec<Triangle> = faces.iter().map(|f| Triangle::new(vertices[f[0] as usize], vertices[f[1] as usize], vertices[f[2] as usize])).collect();
        let inside = |p: Vec3| faces.iter().all(|t| t.normal().is_some_and(|n| n.dot(p - t.a) <= 1e-7));
        let gap = |p: Vec3| if inside(p) { 0.0 } else { faces.iter().map(|t| t.distance_to_local_point(p, true)).fold(f32::MAX, f32::min) };
        let outside = points.iter().map(|&p| gap(p) - radius).fold(f32::MIN, f32::max);
        // How much larger it is: its reach past the proxy's along many directions.
        let reach = |q: &[Vec3], u: Vec3| q.iter().map(|p| p.dot(u)).fold(f32::MIN, f32::max);
        let larger = directions.iter().map(|&u| reach(inner, u) + radius - reach(points, u)).fold(0.0, f32::max);
        eprintln!("joint {}: {} -> {} vertices, rounded {:.3} mm, at most {:.3} mm larger", proxy.joint, points.len(), inner.len(), radius * 1e3, larger * 1e3);
        assert!(outside <= 1e-6, "joint {}: a vertex {outside} m outside", proxy.joint);
        assert!(inner.len() <= MAX_SIMULATED_VERTICES);
        assert!(larger <= 3e-4, "joint {}: {larger} m larger", proxy.joint);
    }
    assert!(hulls >= 5, "{hulls} hulls");
}

#[test]
fn the_simulated_hull_holds_the_built_in_hands_proxies_and_is_little_larger() {
    holds_the_proxy_and_is_little_larger(&dqhand::hand::build(&dqhand::hand::HandParams::default()).expect("the built-in hand"));
}

#[test]
fn the_simulated_hull_holds_the_webxr_generic_hands_proxies_and_is_little_larger() {
    holds_the_proxy_and_is_little_larger(&support::webxr_hand());
}
