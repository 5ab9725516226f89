//! Two hands in one scene: a large box carried between two flat palms, and a baton handed
//! from the right hand to the left; each hand built as itself (the left one generated as a
//! left hand), records of each side driving their own hand.

use std::sync::{Arc, OnceLock};

use dqhand::collision::ObjectColliders;
use dqhand::grasp::{GraspEvent, GraspParams};
use dqhand::input::Tracking;
use dqhand::hand::{HandParams, Side};
use dqhand::input::InputConfig;
use dqhand::interaction::benchmark::{self, RunScore};
use dqhand::interaction::grasp_script::{self, Script};
use dqhand::interaction::ManipulationLoop;
use dqhand::kinematics::JointModel;
use dqhand::model::Model;
use dqhand::scene::Scene;
use glam::Vec3;

/// The built-in hand as a left and as a right hand.
fn models() -> [Arc<Model>; 2] {
    static MODELS: OnceLock<[Arc<Model>; 2]> = OnceLock::new();
    MODELS.get_or_init(|| [Side::Left, Side::Right].map(|side| Arc::new(dqhand::hand::build(&HandParams { side, ..HandParams::default() }).unwrap()))).clone()
}

fn two_handed(scene: &Scene) -> ManipulationLoop {
    let [l, r] = models();
    ManipulationLoop::two_handed([(l, None), (r, None)], JointModel::Full, InputConfig::default(), None, scene, GraspParams::default()).unwrap()
}

fn run(scene: &Scene, script: &Script, object: &str, carried_to: Vec3) -> (RunScore, ManipulationLoop) {
    let mut manip = two_handed(scene);
    let i = manip.names().iter().position(|n| n == object).unwrap();
    let score = benchmark::score(&mut manip, script, i, carried_to);
    (score, manip)
}

#[test]
fn a_large_box_is_carried_between_two_flat_palms_and_set_down_when_they_draw_apart() {
    let scene = Scene::named("two-hands").unwrap();
    let objects = ObjectColliders::new(&scene).unwrap();
    let [l, r] = models();
    let carry = Vec3::new(0.0, 0.0, 0.2);
    let script = grasp_script::carry_between([&l, &r], "two-hands", &objects, "box", 0.12, carry).unwrap();
    let start = scene.objects[0].position;
    let (score, _) = run(&scene, &script, "box", start + carry);
    let RunScore { step_s: _, ..} = &score;
    eprintln!("success {} place {:.4} pen {:.4} slip {:.4} {:.2}deg lag {:.4} drift {:.4} tunnel {}", score.success, score.place_error_m, score.max_penetration_m, score.slip_m, score.slip_deg, score.carry_lag_m, score.release_drift_m, score.tunnelled);
    assert!(score.success);
}

#[test]
fn a_baton_is_handed_from_the_right_hand_to_the_left() {
    let scene = Scene::named("two-hands").unwrap();
    let objects = ObjectColliders::new(&scene).unwrap();
    let [l, r] = models();
    let carry = Vec3::new(0.0, 0.0, 0.15);
    let script = grasp_script::hand_over([&l, &r], "two-hands", &objects, "baton", 0.08, 0.12, carry).unwrap();
    let start = scene.objects[1].position;
    let (score, _) = run(&scene, &script, "baton", start + 2.0 * carry);
    let RunScore { step_s: _, ..} = &score;
    eprintln!("success {} place {:.4} pen {:.4} slip {:.4} {:.2}deg lag {:.4} drift {:.4} tunnel {}", score.success, score.place_error_m, score.max_penetration_m, score.slip_m, score.slip_deg, score.carry_lag_m, score.release_drift_m, score.tunnelled);
    assert!(score.success);
}

#[test]
fn a_box_held_between_two_hands_falls_when_one_hand_is_lost() {
    let scene = Scene::named("two-hands").unwrap();
    let objects = ObjectColliders::new(&scene).unwrap();
    let [l, r] = models();
    let mut script = grasp_script::carry_between([&l, &r], "two-hands", &objects, "box", 0.12, Vec3::new(0.0, 0.0, 0.2)).unwrap();
    // The left hand's tracking is lost for good half way through the carry.
    let lost = (script.times.carry_start + script.times.carry_end) / 2.0;
    script.records.retain(|r| r.side == Side::Right || r.time < lost);
    let mut manip = two_handed(&scene);
    let (mut released, mut lowest) = (None, f32::INFINITY);
    let mut k = 0;
    while k < script.records.len() {
        let t = script.records[k].time;
        while k < script.records.len() && script.records[k].time == t {
            manip.push(&script.records[k]).unwrap();
            k += 1;
        }
        let events = manip.step(t);
        if t < lost {
            assert_eq!(manip.hands().iter().map(|h| h.held()).collect::<Vec<_>>(), [manip.hands()[0].held(); 2], "both hold it or neither");
        }
        for (hand, e) in events.iter() {
            if let GraspEvent::Release { object: 0, .. } = e {
                released.get_or_insert((hand, t));
            }
        }
        if released.is_some() {
            lowest = lowest.min(manip.poses()[0].1.y);
        }
    }
    let (_, at) = released.expect("the box is let go");
    assert_eq!(manip.hands()[0].tracking(), Tracking::Lost);
    // Judged lost after the input's grace, then held through the grasp's.
    let grace = InputConfig::default().grace_s + GraspParams::default().loss_grace_s;
    assert!(at > lost + grace - 0.05 && at < lost + grace + 0.05, "dropped {at:.3} s, lost at {lost:.3} s");
    assert!(manip.hands().iter().all(|h| h.held().is_none()), "the right hand alone does not hold it");
    // It falls back onto the table: its bottom (10 cm below its centre) on the top at 0.75.
    assert!((lowest - 0.85).abs() < 0.01, "rests at {lowest}");
}
