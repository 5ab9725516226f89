//! The contact pass after skinning, judged by the self-contact metric (winding numbers over
//! the whole posed skin; it shares nothing with the pass's fields) on every gesture of the
//! library under every method.

mod support;

use std::sync::{Arc, LazyLock};

use dqhand::geometry::winding_number;
use dqhand::gesture::GESTURES;
use dqhand::hand::{build, HandParams};
use dqhand::kinematics::JointModel;
use dqhand::metrics::{hand_parts, self_contact, SelfContact};
use dqhand::model::Model;
use dqhand::skin::{ContactPassReport, Deformed, Deformer, Method, SelfContactPass, CLEARANCE};
use glam::Vec3;

static HAND: LazyLock<Arc<Model>> = LazyLock::new(|| Arc::new(build(&HandParams::default()).unwrap()));

/// Per method and gesture: the self-contact before and after the pass, its pushes, and the
/// positions before and after.
fn run_all(model: &Model, mut each: impl FnMut(Method, &str, SelfContact, SelfContact, ContactPassReport, &[[f32; 3]], &[[f32; 3]])) {
    let parts = hand_parts(model);
    let mut hand = model.hand_kinematics(JointModel::Full).unwrap();
    let mut pass = SelfContactPass::new(&model.mesh, &model.skeleton);
    for method in Method::ALL {
        let mut deformer = Deformer::new(method, &model.mesh);
        let mut out = Deformed::new(&model.mesh);
        for g in &GESTURES {
            hand.pose(&g.pose(JointModel::Full));
            deformer.deform(&model.mesh, hand.layer(), &mut out);
            let before_positions = out.positions().to_vec();
            let before = self_contact(out.positions(), model.mesh.indices(), &parts);
            let report = pass.apply(hand.layer().skinning(), &mut out);
            let after = self_contact(out.positions(), model.mesh.indices(), &parts);
            eprintln!("{method:?} {}: {:.2} mm, {:.1} mm³ → {:.2} mm, {:.1} mm³ ({} pushes, {:.2} mm at most)", g.name, before.depth_m * 1e3, before.volume_m3 * 1e9, after.depth_m * 1e3, after.volume_m3 * 1e9, report.pushed, report.deepest_m * 1e3);
            each(method, g.name, before, after, report, &before_positions, out.positions());
        }
    }
}

#[test]
fn the_pass_takes_skin_out_of_skin_and_moves_nothing_else() {
    let model = &*HAND;
    let mut fist_dqb = None;
    let mut clear = std::collections::BTreeMap::<&str, (bool, usize, f32)>::new();
    run_all(model, |method, gesture, before, after, pass, _, _| {
        let g = clear.entry(GESTURES.iter().find(|g| g.name == gesture).unwrap().name).or_insert((true, 0, 0.0));
        *g = (g.0 && before.vertices == 0, g.1 + pass.pushed, g.2.max(pass.deepest_m));
        // Never deeper, never more shared space.
        assert!(after.depth_m <= before.depth_m + 1e-5 && after.volume_m3 <= before.volume_m3 * 1.001 + 1e-12, "{method:?} {gesture}: {before:?} → {after:?}");
        // Under DQB, LB and CoR, where fingers curl into the palm or onto each other (more than
        // 100 mm³ shared), the skin comes out within 3 mm and shares less than half as much
        // (QB throws skin centimetres off the bones, which the rest fields do not follow; the
        // three and four, 30–54 mm³ by the folded thumb's web, are left as they are).
        if method != Method::Qb && before.volume_m3 > 1e-7 {
            assert!(after.depth_m < 0.003 && after.volume_m3 < 0.5 * before.volume_m3, "{method:?} {gesture}: {before:?} → {after:?}");
        }
        if (method, gesture) == (Method::Dqb, "fist") {
            fist_dqb = Some((before, after));
        }
    });
    // Where no method puts skin in another part's (the open hand, the pinch), the open hand is
    // left as it is and no vertex moves by more than the target depth. (Under QB alone, the
    // "three" has pushes that the metric does not confirm.)
    assert_eq!(clear["open_palm"], (true, 0, 0.0), "the open hand");
    let untouched: Vec<_> = clear.iter().filter(|(_, (clear, _, _))| *clear).collect();
    assert!(untouched.len() >= 2 && untouched.iter().all(|(_, (_, _, deepest))| *deepest < 0.0005), "{untouched:?}");
    let (before, after) = fist_dqb.expect("the fist under DQB");
    assert!(after.volume_m3 < 0.1 * before.volume_m3 && after.depth_m < 0.5 * before.depth_m, "the fist under DQB: {before:?} → {after:?}");
}

/// At rest (the bind pose the fields were built on) nothing moves, under any method.
#[test]
fn the_rest_pose_is_left_as_it_is() {
    let model = &*HAND;
    let skinning = vec![glam::Affine3A::IDENTITY; model.mesh.inverse_bind().len()];
    let mut pass = SelfContactPass::new(&model.mesh, &model.skeleton);
    for method in Method::ALL {
        let mut out = Deformed::new(&model.mesh);
        Deformer::new(method, &model.mesh).deform(&model.mesh, &skinning, &mut out);
        assert_eq!(pass.apply(&skinning, &mut out).pushed, 0, "{method:?}");
    }
}

/// A pushed vertex moves from inside the other part's skin towards its surface: it ends where
/// the skin was before the pass (inside it, or within the clearance of it), so the pass
/// cannot put skin into an object the posed skin was clear of.
#[test]
fn pushed_skin_stays_where_the_skin_was() {
    let model = &*HAND;
    let indices = model.mesh.indices();
    let mut checked = 0;
    run_all(model, |method, gesture, _, _, _, before, after| {
        if !matches!(gesture, "fist" | "thumbs_up" | "ok") || method != Method::Dqb {
            return;
        }
        for (v, (a, b)) in before.iter().zip(after).enumerate().filter(|(_, (a, b))| a != b) {
            let (a, b) = (Vec3::from(*a), Vec3::from(*b));
            let inside = winding_number(before, indices, b) >= 0.5;
            let near = (0..indices.len() / 3).any(|t| {
                let c = [0, 1, 2].map(|k| Vec3::from(before[indices[3 * t + k] as usize]));
                dqhand::math::triangle_closest(b, c).distance(b) <= 2.0 * CLEARANCE
            });
            assert!(inside || near, "{gesture}: vertex {v} moved from {a} to {b}, out of the skin as it was");
            checked += 1;
        }
    });
    assert!(checked > 100, "{checked} pushed vertices checked");
}


/// A skin layer given the pass runs it after each of its methods: its skin is the deformer's
/// with the pass applied, and the fist's skin comes out of itself.
#[test]
fn a_skin_layer_runs_the_pass_after_each_method() {
    let model = Arc::new(build(&HandParams { vertices: 3000, ..HandParams::default() }).unwrap());
    let mut hand = model.hand_kinematics(JointModel::Full).unwrap();
    hand.pose(&dqhand::gesture::gesture("fist").unwrap().pose(JointModel::Full));
    let mut layer = dqhand::skin::SkinLayer::new(Arc::clone(&model.mesh), dqhand::skin::MethodSet::ALL);
    layer.set_contact_pass(Some(SelfContactPass::new(&model.mesh, &model.skeleton)));
    layer.deform(hand.layer());
    let mut pass = SelfContactPass::new(&model.mesh, &model.skeleton);
    let parts = hand_parts(&model);
    for method in Method::ALL {
        let mut out = Deformed::new(&model.mesh);
        Deformer::new(method, &model.mesh).deform(&model.mesh, hand.layer(), &mut out);
        let before = self_contact(out.positions(), model.mesh.indices(), &parts);
        assert!(pass.apply(hand.layer().skinning(), &mut out).pushed > 0, "{method:?}");
        assert_eq!(layer.deformed(method).unwrap(), &out, "{method:?}");
        let after = self_contact(out.positions(), model.mesh.indices(), &parts);
        assert!(after.volume_m3 < before.volume_m3, "{method:?}: {before:?} → {after:?}");
    }
}

/// On a hand the project did not make (the WebXR generic hand, 1,360 vertices, not closed, so
/// the winding-number metric does not apply): a fist's skin is moved, by less than a finger's
/// thickness, and the open hand an order of magnitude less. (It is not left as it is, as the
/// built-in hand is: 2 vertices move by 1.9 mm in the open palm, 4 by 2.5 mm in the pinch, where
/// nothing touches; its fields are narrowed on its bind pose only, and its triangles are coarse.
/// A known defect, in docs/realism.md.)
#[test]
fn the_webxr_generic_hand_is_moved_in_a_fist() {
    let model = support::webxr_hand();
    let mut hand = model.hand_kinematics(JointModel::Full).unwrap();
    let mut pass = SelfContactPass::new(&model.mesh, &model.skeleton);
    let mut out = Deformed::new(&model.mesh);
    let mut moved = std::collections::BTreeMap::new();
    for name in ["open_palm", "pinch", "fist"] {
        hand.pose(&dqhand::gesture::gesture(name).unwrap().pose(JointModel::Full));
        Deformer::new(Method::Dqb, &model.mesh).deform(&model.mesh, hand.layer(), &mut out);
        let report = pass.apply(hand.layer().skinning(), &mut out);
        eprintln!("WebXR hand, {name}: {report:?}");
        moved.insert(name, report);
    }
    assert!(moved["fist"].pushed > 0 && moved["fist"].deepest_m < 0.015, "{moved:?}");
    assert!(10 * moved["open_palm"].pushed < moved["fist"].pushed, "{moved:?}");
}
