//! A persistent crew of helper threads that split one short job with the calling thread.
//!
//! A frame of the built-in hand takes ~10 µs on one core, less than a sleeping thread takes
//! to wake (rayon's workers sleep microseconds after their queues empty, and a wake costs
//! tens of µs in a VM). So the crew's helpers spin for a while after each job, waiting for
//! the next (OpenMP's active wait policy), and only then park; and the caller never waits
//! for a helper to wake: it claims pieces of the job itself, and a helper that wakes late
//! finds nothing left. Each thread has a home range of the pieces, which it claims first and
//! the others only once theirs are done, so a thread deforms the same vertices frame after
//! frame, from its own cache, when all are awake. Allocates nothing per job.

use std::ops::Range;
use std::sync::atomic::{AtomicBool, AtomicPtr, AtomicUsize, Ordering::*};
use std::sync::{Arc, Condvar, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// The next piece of one thread's home range, counted from its start; a cache line of its
/// own, so that claims in one range do not slow claims in another.
#[repr(align(128))]
struct Cursor(AtomicUsize);

/// One job: `pieces` calls of `f`, each index claimed once through its range's cursor.
struct Job<'a> {
    f: &'a (dyn Fn(usize) + Sync),
    pieces: usize,
    /// One per thread, at zero when the job is offered.
    cursors: &'a [Cursor],
}

impl Job<'_> {
    /// Thread `r`'s home range of the pieces.
    fn range(&self, r: usize) -> Range<usize> {
        let n = self.cursors.len();
        r * self.pieces / n..(r + 1) * self.pieces / n
    }

    /// Claims and runs pieces, from thread `home`'s range on, until none is left.
    fn work(&self, home: usize) {
        let n = self.cursors.len();
        for r in (home..n).chain(0..home) {
            let range = self.range(r);
            loop {
                let i = range.start + self.cursors[r].0.fetch_add(1, Relaxed);
                if i >= range.end {
                    break;
                }
                (self.f)(i);
            }
        }
    }
}

/// What the caller and the helpers share.
struct Shared {
    /// The job on offer (a `Job` on the caller's stack), or null.
    job: AtomicPtr<Job<'static>>,
    /// Jobs offered so far: a helper takes part in each once.
    epoch: AtomicUsize,
    /// Helpers between taking `job` and being done with it: the caller waits for none
    /// before its job leaves the stack.
    active: AtomicUsize,
    /// Helpers parked (or about to) on `wake`.
    parked: AtomicUsize,
    lock: Mutex<()>,
    wake: Condvar,
    /// One caller at a time; a second runs its job alone.
    busy: AtomicBool,
    stop: AtomicBool,
    /// Set if a piece panicked on a helper.
    poisoned: AtomicBool,
    spin: Duration,
    /// The job's cursors, one per thread (the caller's first), reset by each caller.
    cursors: Box<[Cursor]>,
}

/// A crew of `threads − 1` helper threads, started once; see the module docs.
pub struct Crew {
    shared: Arc<Shared>,
    helpers: Vec<JoinHandle<()>>,
}

impl core::fmt::Debug for Crew {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("Crew").field("threads", &self.threads()).field("spin", &self.shared.spin).finish()
    }
}

impl Crew {
    /// Helpers spin this long after a job before parking, by default: longer than the gap
    /// between the deformations of one frame, far shorter than a 90 Hz frame.
    pub const SPIN: Duration = Duration::from_millis(1);

    /// A crew that runs jobs on `threads` threads: the caller's and `threads − 1` helpers,
    /// which spin for `spin` after each job, then park until the next.
    ///
    /// # Errors
    /// If a thread cannot be started.
    pub fn new(threads: usize, spin: Duration) -> std::io::Result<Self> {
        let shared = Arc::new(Shared {
            job: AtomicPtr::new(core::ptr::null_mut()),
            epoch: AtomicUsize::new(0),
            active: AtomicUsize::new(0),
            parked: AtomicUsize::new(0),
            lock: Mutex::new(()),
            wake: Condvar::new(),
            busy: AtomicBool::new(false),
            stop: AtomicBool::new(false),
            poisoned: AtomicBool::new(false),
            spin,
            cursors: (0..threads.max(1)).map(|_| Cursor(AtomicUsize::new(0))).collect(),
        });
        let helpers = (1..threads.max(1))
            .map(|i| {
                let shared = Arc::clone(&shared);
                std::thread::Builder::new().name(format!("dqhand-crew-{i}")).spawn(move || helper(i, &shared))
            })
            .collect::<std::io::Result<_>>()?;
        Ok(Self { shared, helpers })
    }

    /// Threads a job runs on, the caller's included.
    #[must_use]
    pub fn threads(&self) -> usize {
        self.helpers.len() + 1
    }

    /// Runs `f(0)` … `f(pieces − 1)`, each once, on the calling thread and any helpers that
    /// are awake or wake in time; returns when all have run.
    ///
    /// # Panics
    /// If a piece panicked on a helper (a piece that panics on the caller unwinds as usual,
    /// after the helpers are done with the job).
    pub fn run(&self, pieces: usize, f: &(dyn Fn(usize) + Sync)) {
        let s = &*self.shared;
        if self.helpers.is_empty() || s.busy.swap(true, Acquire) {
            return (0..pieces).for_each(f);
        }
        // No helper touches the cursors between jobs (see `Withdraw`); the job's offer below
        // publishes the reset.
        for c in &s.cursors {
            c.0.store(0, Relaxed);
        }
        let job = Job { f, pieces, cursors: &s.cursors };
        s.poisoned.store(false, Relaxed);
        // Withdraws the job and waits out the helpers on every way out, unwinding included:
        // after this no helper touches the job.
        struct Withdraw<'a>(&'a Shared);
        impl Drop for Withdraw<'_> {
            fn drop(&mut self) {
                self.0.job.store(core::ptr::null_mut(), SeqCst);
                while self.0.active.load(SeqCst) != 0 {
                    core::hint::spin_loop();
                }
                self.0.busy.store(false, Release);
            }
        }
        let withdraw = Withdraw(s);
        // SAFETY: the pointer is only dereferenced by helpers counted in `active`, and
        // `Withdraw` waits for those to finish before `job` goes out of scope.
        s.epoch.fetch_add(1, SeqCst);
        s.job.store((&raw const job).cast_mut().cast(), SeqCst);
        if s.parked.load(SeqCst) > 0 {
            let _guard = s.lock.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
            s.wake.notify_all();
        }
        job.work(0);
        drop(withdraw);
        assert!(!s.poisoned.load(Acquire), "a crew thread panicked");
    }
}

impl Drop for Crew {
    fn drop(&mut self) {
        self.shared.stop.store(true, SeqCst);
        {
            let _guard = self.shared.lock.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
            self.shared.wake.notify_all();
        }
        for h in self.helpers.drain(..) {
            let _ = h.join();
        }
    }
}

/// Helper `home`'s life: take part in each job on offer once, spin `spin` after it, then
/// park.
fn helper(home: usize, s: &Shared) {
    let (mut seen, mut last) = (0, Instant::now());
    let offered = |seen: usize| s.epoch.load(SeqCst) != seen && !s.job.load(SeqCst).is_null();
    while !s.stop.load(Relaxed) {
        let epoch = s.epoch.load(Acquire);
        if epoch == seen || s.job.load(Relaxed).is_null() {
            if last.elapsed() < s.spin {
                core::hint::spin_loop();
                continue;
            }
            let mut guard = s.lock.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
            // Counted before looking: a caller that has seen no helper parked has already
            // offered its job, so this look finds it.
            s.parked.fetch_add(1, SeqCst);
            while !offered(seen) && !s.stop.load(SeqCst) {
                guard = s.wake.wait(guard).unwrap_or_else(std::sync::PoisonError::into_inner);
            }
            s.parked.fetch_sub(1, SeqCst);
            continue;
        }
        // Counted before the job is read again: a caller that has seen no helper active has
        // already withdrawn its job, so this read then finds none (or a later caller's,
        // which is as alive).
        s.active.fetch_add(1, SeqCst);
        let job = s.job.load(SeqCst);
        if !job.is_null() {
            // SAFETY: counted in `active` before this read found the job, so its caller is
            // still waiting in `Withdraw` and the job is alive.
            let job = unsafe { &*job };
            // A panicking piece is the caller's to report; the helper stays for the next job.
            if std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| job.work(home))).is_err() {
                s.poisoned.store(true, Release);
            }
        }
        s.active.fetch_sub(1, SeqCst);
        (seen, last) = (epoch, Instant::now());
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Runs `jobs` jobs of `pieces` pieces and checks each piece ran exactly once per job.
    fn each_piece_once(crew: &Crew, jobs: usize, pieces: usize) {
        let counts: Vec<AtomicUsize> = (0..pieces).map(|_| AtomicUsize::new(0)).collect();
        for j in 1..=jobs {
            crew.run(pieces, &|i| {
                counts[i].fetch_add(1, Relaxed);
            });
            assert!(counts.iter().all(|c| c.load(Relaxed) == j), "job {j}: a piece ran other than once");
        }
    }

    #[test]
    fn every_piece_runs_once_whether_helpers_spin_or_park() {
        for spin in [Duration::ZERO, Duration::from_micros(50), Crew::SPIN] {
            let crew = Crew::new(3, spin).unwrap();
            assert_eq!(crew.threads(), 3);
            each_piece_once(&crew, 2000, 7);
            each_piece_once(&crew, 10, 0);
            // After the helpers have parked.
            std::thread::sleep(spin + Duration::from_millis(5));
            each_piece_once(&crew, 3, 1000);
        }
        each_piece_once(&Crew::new(1, Crew::SPIN).unwrap(), 5, 9);
    }

    /// A thread claims its own range first, then the others' in turn, each piece once.
    #[test]
    fn a_thread_starts_at_its_home_range_and_then_takes_the_others() {
        let cursors: Vec<Cursor> = (0..3).map(|_| Cursor(AtomicUsize::new(0))).collect();
        let order = Mutex::new(Vec::new());
        let job = Job { f: &|i| order.lock().unwrap().push(i), pieces: 10, cursors: &cursors };
        assert_eq!([0, 1, 2].map(|r| job.range(r)), [0..3, 3..6, 6..10]);
        job.work(1);
        assert_eq!(*order.lock().unwrap(), [3, 4, 5, 6, 7, 8, 9, 0, 1, 2]);
        job.work(0);
        assert_eq!(order.lock().unwrap().len(), 10, "nothing left for a second thread");
    }

    #[test]
    fn helpers_take_part() {
        let crew = Crew::new(2, Crew::SPIN).unwrap();
        let caller = std::thread::current().id();
        let elsewhere = AtomicUsize::new(0);
        for _ in 0..200 {
            crew.run(4, &|_| {
                if std::thread::current().id() != caller {
                    elsewhere.fetch_add(1, Relaxed);
                }
                std::thread::sleep(Duration::from_micros(200));
            });
        }
        assert!(elsewhere.load(Relaxed) > 0, "no piece ran on the helper");
    }

    #[test]
    fn two_callers_at_once_each_get_their_job_done() {
        let crew = Crew::new(3, Crew::SPIN).unwrap();
        std::thread::scope(|s| {
            for _ in 0..2 {
                s.spawn(|| each_piece_once(&crew, 500, 5));
            }
        });
    }

    #[test]
    fn a_panicking_piece_reaches_the_caller_and_the_crew_goes_on() {
        let crew = Crew::new(3, Crew::SPIN).unwrap();
        for _ in 0..20 {
            let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                crew.run(64, &|i| {
                    std::thread::sleep(Duration::from_micros(20));
                    assert!(i != 63, "piece 63 fails");
                });
            }));
            assert!(r.is_err());
        }
        each_piece_once(&crew, 50, 9);
    }
}
