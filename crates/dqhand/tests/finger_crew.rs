//! The fingers closed across a crew of threads ([`ContactConstraint::set_crew`]) over a grasp
//! of the teapot: the rendered hand is the one the same constraint closes finger after finger
//! without a crew, bit for bit, and no thread allocates. A binary of one test, since it counts every thread's allocations
//! (tests running beside it would add theirs).

use std::sync::Arc;

use dqhand::collision::{fit_proxies, ContactConstraint, HandProxies, ObjectColliders, PROXY_MARGIN};
use dqhand::grasp::{GraspEvent, GraspParams};
use dqhand::hand::{build, HandParams, Side};
use dqhand::input::InputConfig;
use dqhand::interaction::grasp_script::{self, GraspTask};
use dqhand::interaction::ManipulationLoop;
use dqhand::kinematics::JointModel;
use dqhand::scene::Scene;
use dqhand::skin::Crew;
use glam::Vec3;

#[path = "support/allocations.rs"]
mod allocations;

#[test]
fn fingers_closed_on_a_crew_render_the_same_hand_and_allocate_nothing() {
    let model = Arc::new(build(&HandParams { vertices: 2000, ..HandParams::default() }).unwrap());
    // Where the benchmark puts it: alone on the table, taken from above.
    let mut scene = Scene::named("objects").unwrap();
    scene.objects.retain(|o| o.name == "teapot");
    scene.objects[0].position = Vec3::new(-0.25, scene.objects[0].position.y, -0.3);
    let objects = ObjectColliders::new(&scene).unwrap();
    let script = grasp_script::grasp(model.clone(), "objects", &objects, &GraspTask::from_above("teapot"), Side::Right).unwrap();
    // The loop moves the teapot; the two constraints beside it solve the same hand against it.
    let mut manip = ManipulationLoop::new(model.clone(), JointModel::Full, None, InputConfig::default(), None, &scene, GraspParams::default()).unwrap();
    let tracked = manip.hands()[0].input().kinematics().clone();
    let proxies = HandProxies::new(&fit_proxies(&model, PROXY_MARGIN), tracked.skeleton());
    // Each made as the loop makes one (a clone's buffers start without their capacity).
    let mut alone = ContactConstraint::new(proxies.clone(), tracked.clone());
    let mut split = ContactConstraint::new(proxies, tracked);
    let crew = Arc::new(Crew::new(3, Crew::SPIN).unwrap());
    split.set_crew(Some(Arc::clone(&crew)));
    let (mut allocated, mut touching) = (0, 0);
    for (i, r) in script.records.iter().enumerate() {
        manip.push(r).unwrap();
        if let Some(GraspEvent::Grasp { object }) = manip.step(r.time).of(0) {
            for c in [&mut alone, &mut split] {
                c.grip(object, &manip.objects().objects()[object].pose);
            }
        }
        let hand = &manip.hands()[0];
        let (pose, world, held) = (hand.input().pipeline().pose(), hand.input().kinematics().world(), hand.held());
        alone.track(pose, world);
        alone.solve(manip.objects(), held, r.time);
        let before = allocations::all_threads_allocations();
        split.track(pose, world);
        split.solve(manip.objects(), held, r.time);
        if i > 0 {
            allocated += allocations::all_threads_allocations() - before;
        }
        let bits = |c: &ContactConstraint| c.rendered().angles.iter().map(|a| a.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&split), bits(&alone), "frame {i}: the rendered angles differ");
        assert_eq!(split.world(), alone.world(), "frame {i}: the rendered joints differ");
        assert_eq!(split.contacts(), alone.contacts(), "frame {i}: the contacts differ");
        touching += usize::from(!alone.contacts().is_empty());
    }
    assert_eq!(allocated, 0, "allocations on any thread while the fingers closed on the crew, over {} frames", script.records.len());
    assert!(touching > 30, "the hand touched the teapot in {touching} frames");
    assert!(crew.jobs() > 30, "the fingers were split across the crew in {} frames", crew.jobs());
    assert!(crew.pieces_helped() > 0, "no finger closed on a helper thread");
}
