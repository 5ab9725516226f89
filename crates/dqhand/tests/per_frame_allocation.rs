//! The per-frame path allocates nothing: pose → local transforms → forward kinematics →
//! skinning transforms → deformation, with buffers made once beforehand.

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

use dqhand::gesture::tour;
use dqhand::hand::{build, HandParams};
use dqhand::kinematics::{HandRig, JointModel, Limits};
use dqhand::model::PoseBuffers;
use dqhand::skin::{Deformed, Deformer, Method};

/// Counts every allocation of this test binary.
struct Counting;

static ALLOCATIONS: AtomicUsize = AtomicUsize::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
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
    let before = ALLOCATIONS.load(Ordering::Relaxed);
    for pose in &poses {
        rig.locals(pose, Limits::Anatomical, &mut buffers.locals);
        let skinning = buffers.evaluate(rig.skeleton(), model.mesh.inverse_bind());
        for d in &mut deformers {
            d.deform(&model.mesh, skinning, &mut out);
        }
    }
    assert_eq!(ALLOCATIONS.load(Ordering::Relaxed) - before, 0, "allocations during {} frames", poses.len());
}
