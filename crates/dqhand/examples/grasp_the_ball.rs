//! Grasp the ball in a scene and print what is held:
//! `cargo run -p dqhand --features synthetic --example grasp_the_ball` (the scripted grasp
//! is a generator of the `synthetic` feature; a real hand's records drive the loop the same way).
//!
//! The manipulation loop (the paper's Figure 9) on the built-in grasp scene: a table, a ball
//! and the Utah teapot. A scripted hand (made from the hand's own kinematics) reaches for the
//! ball from above, closes, carries it and lets go; each record drives the tracked hand, the
//! contact-constrained rendered hand (it never sinks in), the grasp heuristics and the
//! physics. The loop prints when the grasp and the release happen and where the ball is.

use std::sync::Arc;

use dqhand::collision::ObjectColliders;
use dqhand::grasp::{GraspEvent, GraspParams};
use dqhand::hand::{build, HandParams, Side};
use dqhand::input::InputConfig;
use dqhand::interaction::grasp_script::{grasp, GraspTask};
use dqhand::interaction::ManipulationLoop;
use dqhand::kinematics::JointModel;
use dqhand::scene::Scene;

fn main() -> Result<(), dqhand::Error> {
    let hand = Arc::new(build(&HandParams::default())?);
    let scene = Scene::named("grasp")?;
    let script = grasp(Arc::clone(&hand), "grasp", &ObjectColliders::new(&scene)?, &GraspTask::from_above("ball"), Side::Right)?;
    let mut manipulation = ManipulationLoop::new(hand, JointModel::Full, None, InputConfig::default(), None, &scene, GraspParams::default())?;
    let ball = manipulation.names().iter().position(|n| n == "ball").expect("the grasp scene has a ball");
    let mut held_frames = 0;
    for record in &script.records {
        // A scripted record is always good; a live one may be refused (counted, the hand kept).
        let _ = manipulation.push(record);
        match manipulation.step(record.time).of(0) {
            Some(GraspEvent::Grasp { object }) => println!("{:6.2} s  grasped {}", record.time, manipulation.names()[object]),
            Some(GraspEvent::Release { object, linvel, .. }) => {
                println!("{:6.2} s  released {} at {:.2} m/s", record.time, manipulation.names()[object], linvel.length());
            }
            None => {}
        }
        held_frames += usize::from(manipulation.hands()[0].held() == Some(ball));
    }
    let (_, at) = manipulation.poses()[ball];
    println!("held the ball for {held_frames} of {} frames; it rests at ({:.3}, {:.3}, {:.3}) m", script.records.len(), at.x, at.y, at.z);
    Ok(())
}
