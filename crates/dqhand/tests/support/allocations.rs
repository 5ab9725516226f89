//! A global allocator that counts each thread's allocations, for the per-frame tests (each
//! test runs on a thread of its own), and records where each was made while a thread asks
//! (`TRACING`); it also counts every thread's together, which only a binary of one test
//! can read (the others' would add to it).
#![allow(dead_code)]

use std::alloc::{GlobalAlloc, Layout, System};
use std::backtrace::Backtrace;
use std::cell::{Cell, RefCell};
use std::sync::atomic::{AtomicUsize, Ordering::Relaxed};

/// Counts the allocations of each thread (tests run on threads of their own); while
/// its `TRACING` is on, also records where each one was made.
struct Counting;

thread_local! {
    static ALLOCATIONS: Cell<usize> = const { Cell::new(0) };
    /// Whether this thread's allocations are traced, and whether one is being traced now
    /// (taking a backtrace allocates too).
    pub static TRACING: Cell<(bool, bool)> = const { Cell::new((false, false)) };
    pub static TRACES: RefCell<Vec<Backtrace>> = const { RefCell::new(Vec::new()) };
}

/// Every thread's allocations so far.
static ALL: AtomicUsize = AtomicUsize::new(0);

pub fn allocations() -> usize {
    ALLOCATIONS.with(Cell::get)
}

pub fn all_threads_allocations() -> usize {
    ALL.load(Relaxed)
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALL.fetch_add(1, Relaxed);
        match TRACING.try_with(Cell::get) {
            Ok((_, true)) => {}
            Ok((true, false)) => {
                let _ = ALLOCATIONS.try_with(|c| c.set(c.get() + 1));
                TRACING.with(|t| t.set((true, true)));
                let trace = Backtrace::force_capture();
                TRACES.with(|t| t.borrow_mut().push(trace));
                TRACING.with(|t| t.set((true, false)));
            }
            _ => {
                let _ = ALLOCATIONS.try_with(|c| c.set(c.get() + 1));
            }
        }
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;
