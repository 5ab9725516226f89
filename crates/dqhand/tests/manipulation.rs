//! The manipulation loop end to end: scripted recordings grasp, carry and release objects.

use std::path::Path;
use std::sync::Arc;

use dqhand::collision::ObjectColliders;
use dqhand::grasp::GraspParams;
use dqhand::hand::{HandParams, Side};
use dqhand::input::InputConfig;
use dqhand::interaction::grasp_script::{self, GraspTask};
use dqhand::interaction::ManipulationLoop;
use dqhand::kinematics::JointModel;
use dqhand::scene::Scene;
use glam::Vec3;

fn scene(name: &str) -> Scene {
    Scene::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("data/scenes").join(name)).unwrap()
}

#[test]
fn diagnose_ball() {
    let model = Arc::new(dqhand::hand::build(&HandParams::default()).unwrap());
    let scene = scene("grasp.json");
    let objects = ObjectColliders::new(&scene).unwrap();
    let task = GraspTask { object: "ball".into(), approach: -Vec3::Y, fingers: -Vec3::Z, speed: 0.5, lift: 0.12, carry: Vec3::new(0.0, 0.0, 0.3), pinch: false };
    let script = grasp_script::grasp(model.clone(), "grasp.json", &objects, &task, Side::Right).unwrap();
    let mut manip = ManipulationLoop::new(model, JointModel::Full, None, InputConfig::default(), None, &scene, GraspParams::default()).unwrap();
    for (i, r) in script.records.iter().enumerate() {
        manip.push(r, None).unwrap();
        let e = manip.step(r.time);
        if e.is_some() || i % 15 == 0 {
            let c = manip.constraint().closure();
            let contacts: Vec<String> = manip.contacts().iter().map(|c| format!("{:?}:{:.2?}", c.part, c.normal)).collect();
            println!("t={:.2} held={:?} ev={e:?} ball={:.3?} wristback={} closure={:?} contacts={contacts:?}", r.time, manip.held(), manip.poses()[0].1, manip.constraint().wrist_held_back(), c.iter().map(|c| (c.tracked.to_degrees() as i32, c.rendered.to_degrees() as i32)).collect::<Vec<_>>());
        }
    }
    println!("{:?}", script.times);
}
