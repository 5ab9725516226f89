//! Two hands in one scene: a large box carried between two flat palms, and a baton handed
//! from the right hand to the left; each hand built as itself (the left one generated as a
//! left hand), records of each side driving their own hand.

use std::sync::{Arc, OnceLock};

use dqhand::collision::ObjectColliders;
use dqhand::gesture::{GestureSet, TwoHandEvent};
use dqhand::grasp::{GraspEvent, GraspParams};
use dqhand::input::Tracking;
use dqhand::hand::{HandParams, Side};
use dqhand::input::InputConfig;
use dqhand::interaction::benchmark::{self, RunScore};
use dqhand::interaction::grasp_script::{self, Script};
use dqhand::interaction::{HandEvents, ManipulationLoop};
use dqhand::kinematics::JointModel;
use dqhand::model::Model;
use dqhand::scene::Scene;
use dqhand::collision::{fit_proxies, pose_of, HandProxies, PROXY_MARGIN};
use glam::{Affine3A, Vec3};

/// The built-in hand as a left and as a right hand.
fn models() -> [Arc<Model>; 2] {
    static MODELS: OnceLock<[Arc<Model>; 2]> = OnceLock::new();
    MODELS.get_or_init(|| [Side::Left, Side::Right].map(|side| Arc::new(dqhand::hand::build(&HandParams { side, ..HandParams::default() }).unwrap()))).clone()
}

fn two_handed(scene: &Scene) -> ManipulationLoop {
    let [l, r] = models();
    ManipulationLoop::two_handed([(l, None), (r, None)], JointModel::Full, InputConfig::default(), None, scene, GraspParams::default()).unwrap()
}

/// Scores the script `make` writes for the built-in hands on the `two-hands` scene, whose
/// `object` it carries `carried` from where the scene puts it: a success.
fn assert_succeeds(object: &str, carried: Vec3, make: impl FnOnce([&Model; 2], &ObjectColliders) -> dqhand::Result<Script>) {
    let scene = Scene::named("two-hands").unwrap();
    let [l, r] = models();
    let script = make([&l, &r], &ObjectColliders::new(&scene).unwrap()).unwrap();
    let mut manip = two_handed(&scene);
    let i = manip.names().iter().position(|n| n == object).unwrap();
    let score = benchmark::score(&mut manip, &script, i, scene.objects[i].position + carried);
    assert!(score.success, "{:?}", RunScore { step_s: Vec::new(), ..score });
}

/// Plays `script` through `manip` a frame at a time (the records of one time, then a step),
/// calling `each` with the loop, the time and the frame's events.
fn play(manip: &mut ManipulationLoop, script: &Script, mut each: impl FnMut(&ManipulationLoop, f64, HandEvents)) {
    let mut k = 0;
    while k < script.records.len() {
        let t = script.records[k].time;
        while k < script.records.len() && script.records[k].time == t {
            manip.push(&script.records[k]).unwrap();
            k += 1;
        }
        let events = manip.step(t);
        each(manip, t, events);
    }
}

#[test]
fn a_large_box_is_carried_between_two_flat_palms_and_set_down_when_they_draw_apart() {
    let carry = Vec3::new(0.0, 0.0, 0.2);
    assert_succeeds("box", carry, |models, objects| grasp_script::carry_between(models, "two-hands", objects, "box", 0.12, carry));
}

#[test]
fn a_baton_is_handed_from_the_right_hand_to_the_left() {
    let carry = Vec3::new(0.0, 0.0, 0.12);
    assert_succeeds("baton", 2.0 * carry, |models, objects| grasp_script::hand_over(models, "two-hands", objects, "baton", 0.08, 0.12, carry));
}

/// Tracked as a headset tracks it (grasp-bench's seed), the left hand comes down on the bar the
/// right one holds with its thumb touching it: parry's directional cast read the touch as an
/// overlap being left and let the hand 26 mm into the bar, through its surface; then, with the
/// thumb's metacarpal 0.04 mm off the bar, parry's contact gave no answer and the wrist went on
/// 5.4 mm into it; and the right hand's jitter carried the bar 2.9 mm into the left fingers
/// closing on it. The skin stays within the benchmark's 1 mm, and the bar is handed over.
#[test]
fn a_headset_tracked_hand_over_keeps_the_left_hand_out_of_the_bar() {
    let scene = Scene::named("two-hands").unwrap();
    let [l, r] = models();
    let script = grasp_script::hand_over([&l, &r], "two-hands", &ObjectColliders::new(&scene).unwrap(), "baton", 0.08, 0.12, Vec3::new(0.0, 0.0, 0.12)).unwrap();
    let script = grasp_script::HeadsetTracking::QUEST_LIKE.track(&script, 125);
    let mut manip = two_handed(&scene);
    let i = manip.names().iter().position(|n| n == "baton").unwrap();
    let score = benchmark::score(&mut manip, &script, i, scene.objects[i].position + Vec3::new(0.0, 0.0, 0.24));
    assert!(score.success && !score.tunnelled && score.max_penetration_m <= 0.001, "{:?}", RunScore { step_s: Vec::new(), ..score });
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
    let mut path = Vec::new();
    play(&mut manip, &script, |manip, t, events| {
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
        path.push((t, manip.poses()[0].1));
    });
    let (_, at) = released.expect("the box is let go");
    assert_eq!(manip.hands()[0].tracking(), Tracking::Lost);
    // Judged lost after the input's grace, then held through the grasp's.
    let grace = InputConfig::default().grace_s + GraspParams::default().loss_grace_s;
    assert!(at > lost + grace - 0.05 && at < lost + grace + 0.05, "dropped {at:.3} s, lost at {lost:.3} s");
    // While the left hand is judged lost, the box stays where it was, the right hand moving on.
    let judged = lost + InputConfig::default().grace_s + 0.02;
    let still: Vec<Vec3> = path.iter().filter(|(t, _)| *t > judged && *t < at - 0.02).map(|(_, p)| *p).collect();
    assert!(still.len() > 20 && still.iter().all(|p| p.distance(still[0]) < 1e-4), "the box moved while a hand was lost: {:?}", still.first().zip(still.last()));
    assert!(manip.hands().iter().all(|h| h.held().is_none()), "the right hand alone does not hold it");
    // It falls back onto the table: its bottom (10 cm below its centre) on the top at 0.75.
    assert!((lowest - 0.85).abs() < 0.01, "rests at {lowest}");
}

#[test]
fn the_rendered_hands_stop_at_each_other_where_the_tracked_ones_overlap() {
    let scene = Scene::named("two-hands").unwrap();
    let [l, r] = models();
    // Palm to palm over the table's free middle, each tracked hand 3 cm past the other's.
    let script = grasp_script::clap([&l, &r], Vec3::new(0.0, 1.0, -0.05), 0.03).unwrap();
    let mut manip = two_handed(&scene);
    let proxies: Vec<HandProxies> = manip.hands().iter().map(|h| HandProxies::new(&fit_proxies(h.input().model(), PROXY_MARGIN), h.rendered().skeleton())).collect();
    let overlap = |worlds: [&[Affine3A]; 2]| -> (f32, f32) {
        // The deepest overlap of any left proxy with any right one (m), and the least gap.
        let mut deepest = 0.0f32;
        let mut gap = f32::INFINITY;
        for a in proxies[0].colliders() {
            for b in proxies[1].colliders() {
                let d = parry3d::query::distance(&pose_of(&worlds[0][a.joint]), &*a.shape, &pose_of(&worlds[1][b.joint]), &*b.shape).unwrap().distance;
                gap = gap.min(d);
                if d <= 0.0 {
                    let c = parry3d::query::contact(&pose_of(&worlds[0][a.joint]), &*a.shape, &pose_of(&worlds[1][b.joint]), &*b.shape, 0.0).unwrap();
                    deepest = deepest.max(c.map_or(0.0, |c| -c.dist));
                }
            }
        }
        (deepest, gap)
    };
    let (mut rendered_deepest, mut tracked_deepest, mut closest) = (0.0f32, 0.0f32, f32::INFINITY);
    play(&mut manip, &script, |manip, _, _| {
        let h = manip.hands();
        let (deep, gap) = overlap([h[0].rendered().world(), h[1].rendered().world()]);
        rendered_deepest = rendered_deepest.max(deep);
        closest = closest.min(gap);
        tracked_deepest = tracked_deepest.max(overlap([h[0].constraint().tracked_world(), h[1].constraint().tracked_world()]).0);
    });
    assert!(tracked_deepest > 0.02, "the tracked hands overlap: {tracked_deepest}");
    assert!(rendered_deepest < 0.001, "the rendered ones do not: {rendered_deepest} m deep");
    assert!(closest < 0.003, "they meet: {closest} m apart at the closest");
}

#[test]
fn two_hands_of_one_side_are_refused() {
    let [_, r] = models();
    let scene = Scene::named("two-hands").unwrap();
    let e = ManipulationLoop::two_handed([(r.clone(), None), (r, None)], JointModel::Full, InputConfig::default(), None, &scene, GraspParams::default()).err().unwrap().to_string();
    assert!(e.contains("a left and a right") && e.contains("right"), "{e}");
}

#[test]
fn both_palms_open_and_brought_together_are_gestures_of_both_hands() {
    let scene = Scene::named("two-hands").unwrap();
    let [l, r] = models();
    let script = grasp_script::clap([&l, &r], Vec3::new(0.0, 1.0, -0.05), 0.03).unwrap();
    let mut manip = ManipulationLoop::two_handed([(l, None), (r, None)], JointModel::Full, InputConfig::default(), Some(GestureSet::builtin()), &scene, GraspParams::default()).unwrap();
    let names: Vec<String> = manip.two_hand_gestures().unwrap().gestures().iter().map(|g| g.name.clone()).collect();
    let mut began = Vec::new();
    play(&mut manip, &script, |_, t, events| {
        for e in events.two_hand() {
            if let TwoHandEvent::Start(i) = e {
                began.push((names[i].clone(), t));
            }
        }
    });
    let order: Vec<&str> = began.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(order, ["both_palms_open", "hands_together", "both_palms_open"], "{began:?}");
    // Together while the tracked palms press (from when they meet until they draw apart).
    let together = began[1].1;
    assert!(together > script.times.reached - 0.4 && together < script.times.closed, "{began:?} {:?}", script.times);
}
