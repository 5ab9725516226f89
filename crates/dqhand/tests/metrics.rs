//! Realism metrics: closed-surface checks, volume, distortion, and the paper's claim on the
//! built-in hand (DQB keeps volume and radius where LB collapses).

use dqhand::hand::{build, HandParams};
use dqhand::geometry::{check_closed, edges, enclosed_volume, winding_number};
use dqhand::metrics::{edge_distortion, measure};

/// A unit cube, outward-facing triangles.
fn cube() -> (Vec<[f32; 3]>, Vec<u32>) {
    let p = (0..8).map(|i| [(i & 1) as f32, ((i >> 1) & 1) as f32, ((i >> 2) & 1) as f32]).collect();
    let quads = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
    let i = quads.iter().flat_map(|q| [q[0], q[1], q[2], q[0], q[2], q[3]]).collect();
    (p, i)
}

#[test]
fn a_cube_is_closed_and_has_unit_volume() {
    let (p, i) = cube();
    assert_eq!(check_closed(&i), Ok(()));
    assert!((enclosed_volume(&p, &i) - 1.0).abs() < 1e-12);
    // Moved away from the origin, the volume stays.
    let shifted: Vec<[f32; 3]> = p.iter().map(|v| [v[0] + 3.0, v[1] - 2.0, v[2] + 5.0]).collect();
    assert!((enclosed_volume(&shifted, &i) - 1.0).abs() < 1e-6);
}

#[test]
fn winding_number_is_one_inside_and_zero_outside() {
    let (p, i) = cube();
    for (point, expected) in [([0.5, 0.5, 0.5], 1.0), ([0.01, 0.99, 0.5], 1.0), ([1.5, 0.5, 0.5], 0.0), ([-3.0, 7.0, 2.0], 0.0)] {
        let w = winding_number(&p, &i, glam::Vec3::from(point));
        assert!((w - expected).abs() < 1e-9, "{point:?}: {w}");
    }
}

#[test]
fn holes_and_flipped_triangles_are_found() {
    let (_, mut i) = cube();
    let removed: Vec<u32> = i.drain(..3).collect();
    assert!(check_closed(&i).unwrap_err().contains("hole"));
    i.extend([removed[0], removed[2], removed[1]]);
    assert!(check_closed(&i).unwrap_err().contains("same direction"));
}

#[test]
fn distortion_is_zero_at_rest_and_measures_stretch() {
    let (p, i) = cube();
    let e = edges(&i);
    assert_eq!(e.len(), 18);
    assert_eq!(edge_distortion(&p, &p, &e), (0.0, 0.0));
    let stretched: Vec<[f32; 3]> = p.iter().map(|v| [v[0] * 2.0, v[1], v[2]]).collect();
    let (mean, max) = edge_distortion(&p, &stretched, &e);
    assert!((max - 1.0).abs() < 1e-6, "x edges double: {max}");
    assert!(mean > 0.0 && mean < max);
}

#[test]
fn dqb_keeps_volume_and_radius_where_lb_collapses() {
    let model = build(&HandParams::default()).unwrap();
    assert_eq!(check_closed(model.mesh.indices()), Ok(()));
    let report = measure(std::sync::Arc::new(model)).unwrap();
    let h = report.headline();
    let row = |label: &str| h.iter().find(|r| r.0.starts_with(label)).unwrap_or_else(|| panic!("no row {label}")).1.map(Option::unwrap);
    let [lb, _, dqb] = row("skin-to-bone distance at 90° PIP, smallest");
    assert!(lb < 0.6 && dqb > lb + 0.1, "collapse at 90° PIP: LB {lb}, DQB {dqb}");
    let [lb, _, dqb] = row("section radius at 180° PIP twist");
    assert!(lb < 0.3 && dqb > 0.9, "candy wrapper at 180°: LB {lb}, DQB {dqb}");
    let [_, qb, dqb] = row("skin-to-bone distance at 90° PIP, largest");
    assert!(qb > 2.0 && dqb < 1.3, "QB's rotation-centre artifact: QB {qb}, DQB {dqb}");
    let [lb, _, dqb] = row("volume in a full fist");
    // LB loses volume in a fist; DQB loses none (it bulges a little instead, as published).
    assert!(lb < 1.0 && dqb > 0.99 && dqb > lb, "fist volume: LB {lb}, DQB {dqb}");
    let fist = report.intersections.iter().find(|(g, _)| *g == "fist").unwrap().1;
    assert!(fist[1] > 2 * fist[2], "QB tears the fist's skin through itself: {fist:?}");
    // At rest every method reproduces the mesh: ratios 1, no distortion, no jump.
    for s in &report.sweeps {
        for m in 0..3 {
            let f = s.frames[m][0];
            assert!((f.min_distance - 1.0).abs() < 1e-3 && (f.max_distance - 1.0).abs() < 1e-3, "{} rest: {f:?}", s.name);
            assert!(f.distortion_max < 1e-4 && f.jump == 0.0 && (f.volume.unwrap() - 1.0).abs() < 1e-5, "{} rest: {f:?}", s.name);
        }
    }
}

#[test]
fn dqb_flips_past_180_degrees_of_twist_and_the_report_shows_it() {
    let report = measure(std::sync::Arc::new(build(&HandParams::default()).unwrap())).unwrap();
    let twist = report.sweep("index-pip-twist").unwrap();
    let dqb = &twist.frames[2];
    // At 180° the twisted bone's rotation leaves the hemisphere of its neighbour's, the sign
    // alignment switches, and the skin jumps to the other side; elsewhere it moves smoothly.
    let flip = twist.values.iter().position(|&v| v == 180.0).unwrap();
    let others: f32 = dqb[1..].iter().enumerate().filter(|(i, _)| i + 1 != flip).map(|(_, f)| f.jump).fold(0.0, f32::max);
    assert!(dqb[flip].jump > 3.0 * others, "jump at 170→180°: {}, largest elsewhere: {others}", dqb[flip].jump);
    // The radius itself is kept all the way.
    assert!(dqb.iter().all(|f| f.section_radius > 0.9), "{dqb:?}");
}

#[test]
fn crossing_triangles_are_counted_once_and_neighbours_never() {
    use dqhand::metrics::count_self_intersections;
    // Two triangles piercing each other, and a third sharing a vertex with the first.
    let p = [
        [0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0],
        [0.2, 0.2, -0.5], [0.2, 0.2, 0.5], [0.3, 0.3, 0.5],
        [1.0, 0.0, 0.0], [0.5, 0.5, 0.0], [1.0, 1.0, 0.0],
    ];
    let mut i = vec![0, 1, 2, 3, 4, 5, 1, 7, 8];
    assert_eq!(count_self_intersections(&p, &i), 1);
    i.truncate(6);
    let (cp, ci) = cube();
    assert_eq!(count_self_intersections(&cp, &ci), 0);
    assert_eq!(count_self_intersections(&p, &i), 1);
}
