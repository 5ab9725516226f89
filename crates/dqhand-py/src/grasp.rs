//! A hand closed on a ball by the engine's contact-constrained hand: grasps that touch the
//! object without sinking into it, for the data sets' held objects (`dqhand.synth`).

use std::sync::atomic::{AtomicBool, Ordering};

use dqhand::collision::{fit_proxies, ContactConstraint, HandProxies, ObjectColliders, PROXY_MARGIN, STOP_DISTANCE};
use dqhand::glam::{Quat, Vec3};
use dqhand::kinematics::Pose;
use dqhand::scene::{ObjectShape, Scene, SceneObject};
use numpy::{PyArray, PyArray1};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

use crate::{batch_one, numbers, Hand};

/// The rendered angles (B, D) of the hands closed on their balls, and whether each open hand was
/// clear of its ball (B,).
pub(crate) type Grasps<'py> = (Bound<'py, PyArray<f32, numpy::Ix2>>, Bound<'py, PyArray1<bool>>);

/// The smallest and largest ball taken (m): a marble to a large grapefruit.
const RADIUS_M: (f64, f64) = (0.005, 0.2);

/// The rendered angles (B, D) of the hand, its wrist at rest, closing from open towards
/// `angles` (B, D) on a ball at `centres` (B, 3), m, of `radii` (B,), m: each finger stops
/// where its collision proxies touch the ball (the contact constraint's finger stage:
/// conservative advancement, so nothing passes through), its distal joints closing on; and
/// (B,) whether the open hand was clear of the ball. Where it was not (a proxy within the
/// stop distance of it), a finger touching it open cannot close from open: it keeps its open
/// pose, or its target where that is clear; the ball may even be in the hand.
pub(crate) fn close_on_ball<'py>(hand: &Hand, py: Python<'py>, angles: &Bound<'py, PyAny>, centres: &Bound<'py, PyAny>, radii: &Bound<'py, PyAny>, limits: bool) -> PyResult<Grasps<'py>> {
    let poses = hand.batch_of(angles, None)?;
    let count = poses.count;
    let centres = numbers(centres, "centres", &[Some(count), Some(3)], "each ball's centre, m")?;
    let radii = numbers(radii, "radii", &[Some(count)], "each ball's radius, m")?;
    let (centres, radii) = (centres.as_slice().expect("contiguous"), radii.as_slice().expect("contiguous"));
    if let Some(b) = radii.iter().position(|r| !(RADIUS_M.0..=RADIUS_M.1).contains(r)) {
        return Err(PyValueError::new_err(format!("radii[{b}]: {} m is not a ball's radius ({} to {} m)", radii[b], RADIUS_M.0, RADIUS_M.1)));
    }
    let source = poses.source();
    let (kinematics, pose) = hand.kinematics(limits);
    let proxies = HandProxies::new(&fit_proxies(&hand.model, PROXY_MARGIN), kinematics.skeleton());
    // Each pose starts from this fresh constraint, so that its result is its own.
    let fresh = ContactConstraint::new(proxies, kinematics.clone());
    let open = Pose::rest(hand.joint_model.dof_count());
    let clear: Vec<AtomicBool> = (0..count).map(|_| AtomicBool::new(false)).collect();
    let rendered = batch_one(py, &[count, hand.joint_model.dof_count()], (kinematics, pose), |(k, pose), b, out| {
        let at = Vec3::new(centres[3 * b] as f32, centres[3 * b + 1] as f32, centres[3 * b + 2] as f32);
        let scene = Scene { table: None, objects: vec![ball(radii[b] as f32, at)], actions: Vec::new() };
        let objects = ObjectColliders::new(&scene).expect("a ball needs no file");
        let mut constraint = fresh.clone();
        // Two frames, the open hand, then the grasp, as the live loop would see them: each
        // finger closes from open where the open finger is clear of the ball.
        k.pose(&open);
        constraint.track(&open, k.world());
        constraint.solve(&objects, None, 0.0);
        clear[b].store(constraint.contacts().iter().all(|c| c.distance > STOP_DISTANCE), Ordering::Relaxed);
        k.pose(source.read(b, pose));
        constraint.track(pose, k.world());
        constraint.solve(&objects, None, 1.0 / 60.0);
        out.copy_from_slice(&constraint.rendered().angles);
    })?;
    Ok((rendered, PyArray1::from_iter(py, clear.iter().map(|c| c.load(Ordering::Relaxed)))))
}

/// A ball of `radius` at `at`, as a scene object (its mass, friction and restitution unused).
fn ball(radius: f32, at: Vec3) -> SceneObject {
    SceneObject { name: "ball".to_owned(), shape: ObjectShape::Sphere { radius }, position: at, rotation: Quat::IDENTITY, mass: 0.1, friction: 0.5, restitution: 0.3 }
}
