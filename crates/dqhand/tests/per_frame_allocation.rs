//! The per-frame path allocates nothing: pose → local transforms → forward kinematics →
//! skinning transforms → deformation, with buffers made once beforehand; and so does a
//! viewer session's frame (playback, three methods, heat map, encoding).

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::sync::Arc;

use dqhand::gesture::tour;
use dqhand::hand::{build, HandParams};
use dqhand::kinematics::{HandRig, JointModel, Limits};
use dqhand::model::PoseBuffers;
use dqhand::skin::{Deformed, Deformer, Method};
use dqhand::stream::{Command, Session};

/// Counts the allocations of each thread (tests run on threads of their own).
struct Counting;

thread_local! {
    static ALLOCATIONS: Cell<usize> = const { Cell::new(0) };
}

fn allocations() -> usize {
    ALLOCATIONS.with(Cell::get)
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let _ = ALLOCATIONS.try_with(|c| c.set(c.get() + 1));
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

#[test]
fn posing_and_skinning_a_frame_allocates_nothing() {
    let model = build(&HandParams::default()).unwrap();
    let rig = HandRig::new(&model.skeleton, JointModel::Full).unwrap();
    let poses = tour(JointModel::Full, 3);
    let mut buffers = PoseBuffers::new(rig.skeleton());
    let mut out = Deformed::new(&model.mesh);
    let mut deformers: Vec<Deformer> = Method::ALL.iter().map(|&m| Deformer::new(m, &model.mesh)).collect();
    let before = allocations();
    for pose in &poses {
        rig.locals(pose, Limits::Anatomical, &mut buffers.locals);
        let skinning = buffers.evaluate(rig.skeleton(), model.mesh.inverse_bind());
        for d in &mut deformers {
            d.deform(&model.mesh, skinning, &mut out);
        }
    }
    assert_eq!(allocations() - before, 0, "allocations during {} frames", poses.len());
}

#[test]
fn a_viewer_session_frame_allocates_nothing() {
    let model = Arc::new(build(&HandParams { vertices: 2000, ..HandParams::default() }).unwrap());
    let mut session = Session::new(model, JointModel::Full).unwrap();
    for c in [r#"{"type":"view","methods":["lb","qb","dqb"]}"#, r#"{"type":"heatmap","on":true}"#] {
        session.apply(&Command::parse(c).unwrap()).unwrap();
    }
    let mut frame = Vec::new();
    session.render(120.0, &mut frame);
    let before = allocations();
    for _ in 0..30 {
        session.advance(1.0 / 30.0);
        session.render(120.0, &mut frame);
    }
    assert_eq!(allocations() - before, 0, "allocations during 30 session frames");
    session.apply(&Command::parse(r#"{"type":"gesture","name":"fist"}"#).unwrap()).unwrap();
    let before = allocations();
    for _ in 0..30 {
        session.advance(1.0 / 30.0);
        session.render(120.0, &mut frame);
    }
    assert_eq!(allocations() - before, 0, "allocations during 30 frames of a move to a gesture");
}
