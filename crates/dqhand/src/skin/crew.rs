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
//!
//! Waking a parked helper is not free either: on the 2-core Intel Xeon VM of
//! docs/performance.md the wake call alone took the caller 15 µs (an interrupt to a halted
//! virtual CPU), and the helper joined later still, so a 16 µs frame woken into took 32.
//! So the caller times the job's first piece and wakes parked helpers only where the work
//! left outlasts what waking them costs, as measured on this crew's earlier wakes
//! ([`worth_waking`]), or where jobs come in a stream (the last two each began within the
//! spin of the one before), which a woken helper then stays awake for. A caller that knows
//! its next job is long (the fingers' closure of `collision::ContactConstraint`, hundreds of
//! µs) wakes them ahead of it ([`Crew::wake_ahead`]), so that they join it from its start.

use std::ops::Range;
use std::sync::atomic::{AtomicBool, AtomicPtr, AtomicU64, AtomicUsize, Ordering::*};
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

    /// Claims and runs pieces, from thread `home`'s range on, until none is left or
    /// `limit` have run; returns how many ran.
    fn work(&self, home: usize, limit: usize) -> usize {
        let n = self.cursors.len();
        let mut ran = 0;
        for r in (home..n).chain(0..home) {
            let range = self.range(r);
            while ran < limit {
                let i = range.start + self.cursors[r].0.fetch_add(1, Relaxed);
                if i >= range.end {
                    break;
                }
                (self.f)(i);
                ran += 1;
            }
        }
        ran
    }

    /// Pieces no thread has claimed yet.
    fn unclaimed(&self) -> usize {
        (0..self.cursors.len()).map(|r| self.range(r).len().saturating_sub(self.cursors[r].0.load(Relaxed))).sum()
    }
}

/// Whether waking `parked` helpers shortens a job that has `left` of one thread's work still
/// unclaimed, which `awake` threads (the caller's included) are working on, when a woken
/// helper joins `join` after the wake and the wake costs the caller `wake`.
///
/// Without waking the job ends after `left / awake`. Waking, by the time the helpers join
/// the awake threads have done `awake · join − wake` of it, and all `awake + parked` share
/// the rest.
fn worth_waking(left: Duration, awake: usize, parked: usize, join: Duration, wake: Duration) -> bool {
    let (r, a, h) = (left.as_secs_f64(), awake.max(1) as f64, parked as f64);
    let (l, c) = (join.as_secs_f64(), wake.as_secs_f64());
    l + (r - a * l + c).max(0.0) / (a + h) < r / a
}

/// The last [`Samples::LEN`] measurements of one cost. Medians, since a wake that met a
/// descheduled virtual CPU can take a thousand times the usual.
#[derive(Default)]
struct Samples {
    ring: [Duration; Self::LEN],
    /// Samples taken (the ring's next slot, modulo its length).
    taken: usize,
}

impl Samples {
    const LEN: usize = 8;
    /// Samples taken before the median decides (until then the caller wakes for any job of
    /// more than one piece).
    const TRUSTED: usize = 3;

    fn push(&mut self, d: Duration) {
        self.ring[self.taken % Self::LEN] = d;
        self.taken += 1;
    }

    fn median(&self) -> Option<Duration> {
        if self.taken < Self::TRUSTED {
            return None;
        }
        let mut v = [Duration::ZERO; Self::LEN];
        let v = &mut v[..self.taken.min(Self::LEN)];
        v.copy_from_slice(&self.ring[..v.len()]);
        v.sort_unstable();
        Some(v[v.len() / 2])
    }
}

/// What waking a parked helper costs: the time from the caller's wake call until the
/// helper returned from its wait, and the call itself.
#[derive(Default)]
struct WakeCosts {
    join: Samples,
    wake: Samples,
}

impl WakeCosts {
    /// The median join and wake times, once both are measured.
    fn medians(&self) -> Option<(Duration, Duration)> {
        Some((self.join.median()?, self.wake.median()?))
    }
}

/// What the caller and the helpers share.
struct Shared {
    /// The job on offer (a `Job` on the caller's stack), or null.
    job: AtomicPtr<Job<'static>>,
    /// Jobs offered so far: a helper takes part in each once.
    epoch: AtomicUsize,
    /// Pieces the helpers have run.
    helped: AtomicUsize,
    /// Helpers that have started.
    started: AtomicUsize,
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
    /// When the crew started: the origin of `woken_at`.
    origin: Instant,
    /// Nanoseconds from `origin` to the caller's last wake call.
    woken_at: AtomicU64,
    /// Wake calls so far: a helper whose wait returns with a newer count was woken by one
    /// (not spuriously, nor by the crew's drop) and times it.
    wakes: AtomicUsize,
    /// Jobs the caller chose not to wake parked helpers for: every [`Crew::REMEASURE`]th
    /// wakes them anyway, so that the medians follow the machine.
    refused: AtomicUsize,
    /// When the last two jobs were offered (nanoseconds from `origin`, the latest first).
    offered_at: [AtomicU64; 2],
    costs: Mutex<WakeCosts>,
    /// The job's cursors, one per thread (the caller's first), reset by each caller.
    cursors: Box<[Cursor]>,
}

impl Shared {
    /// Nanoseconds since `origin`.
    fn nanos(&self) -> u64 {
        u64::try_from(self.origin.elapsed().as_nanos()).unwrap_or(u64::MAX)
    }
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

    /// Of the jobs a parked helper is not woken for, one in this many wakes it anyway, to
    /// measure the wake again (~15 µs once in 64 frames on the Intel VM).
    const REMEASURE: usize = 64;

    /// A crew that runs jobs on `threads` threads: the caller's and `threads − 1` helpers,
    /// which spin for `spin` after each job, then park until the next.
    ///
    /// # Errors
    /// If a thread cannot be started.
    pub fn new(threads: usize, spin: Duration) -> std::io::Result<Self> {
        let shared = Arc::new(Shared {
            job: AtomicPtr::new(core::ptr::null_mut()),
            epoch: AtomicUsize::new(0),
            helped: AtomicUsize::new(0),
            started: AtomicUsize::new(0),
            active: AtomicUsize::new(0),
            parked: AtomicUsize::new(0),
            lock: Mutex::new(()),
            wake: Condvar::new(),
            busy: AtomicBool::new(false),
            stop: AtomicBool::new(false),
            poisoned: AtomicBool::new(false),
            spin,
            origin: Instant::now(),
            woken_at: AtomicU64::new(0),
            wakes: AtomicUsize::new(0),
            refused: AtomicUsize::new(0),
            offered_at: [AtomicU64::new(0), AtomicU64::new(0)],
            costs: Mutex::new(WakeCosts::default()),
            cursors: (0..threads.max(1)).map(|_| Cursor(AtomicUsize::new(0))).collect(),
        });
        let helpers = (1..threads.max(1))
            .map(|i| {
                let shared = Arc::clone(&shared);
                std::thread::Builder::new().name(format!("dqhand-crew-{i}")).spawn(move || helper(i, &shared))
            })
            .collect::<std::io::Result<Vec<_>>>()?;
        // Started before the first job: a thread's start (which allocates) is not a job's.
        while shared.started.load(Acquire) < helpers.len() {
            std::thread::yield_now();
        }
        Ok(Self { shared, helpers })
    }

    /// Threads a job runs on, the caller's included.
    #[must_use]
    pub fn threads(&self) -> usize {
        self.helpers.len() + 1
    }

    /// Jobs offered to the helpers so far; a job run on the caller alone (a crew of one
    /// thread, or one busy with another caller's job) is not counted.
    #[must_use]
    pub fn jobs(&self) -> usize {
        self.shared.epoch.load(Relaxed)
    }

    /// Pieces of those jobs the helpers ran (the caller ran the rest).
    #[must_use]
    pub fn pieces_helped(&self) -> usize {
        self.shared.helped.load(Relaxed)
    }

    /// What waking a parked helper has cost in this crew, as medians of its last wakes: the
    /// time from the wake until the helper ran, and the wake call on the caller. `None` until
    /// measured.
    #[must_use]
    pub fn wake_costs(&self) -> Option<(Duration, Duration)> {
        self.shared.costs.lock().unwrap_or_else(std::sync::PoisonError::into_inner).medians()
    }

    /// Runs `f(0)` … `f(pieces − 1)`, each once, on the calling thread and any helpers that
    /// are awake or wake in time; returns when all have run. Parked helpers are woken where
    /// jobs come in a stream, or where the job's first piece, timed, says the rest outlasts
    /// waking them (and once in [`Self::REMEASURE`] jobs it does not, to measure again).
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
        // Only one caller at a time gets here (`busy`), so these need no more than Relaxed.
        let now = s.nanos();
        let previous = s.offered_at.each_ref().map(|t| t.load(Relaxed));
        s.offered_at[1].store(previous[0], Relaxed);
        s.offered_at[0].store(now, Relaxed);
        let spin = u64::try_from(s.spin.as_nanos()).unwrap_or(u64::MAX);
        let stream = previous[1] > 0 && now.saturating_sub(previous[0]) < spin && previous[0].saturating_sub(previous[1]) < spin;
        // Helpers woken within the spin (by `wake_ahead`) are on their way: not woken again.
        let roused = s.wakes.load(Relaxed) > 0 && now.saturating_sub(s.woken_at.load(Relaxed)) < spin;
        let parked = if roused { 0 } else { s.parked.load(SeqCst) };
        if parked > 0 && stream {
            self.wake();
        } else if parked > 0 {
            let start = Instant::now();
            let ran = job.work(0, 1);
            if ran == 1 {
                let left = start.elapsed().saturating_mul(u32::try_from(job.unclaimed()).unwrap_or(u32::MAX));
                let awake = self.threads() - parked;
                // A helper holding the lock (recording a join) may be descheduled: then no wake.
                match s.costs.try_lock().map(|c| c.medians()) {
                    Ok(Some((join, wake))) if !worth_waking(left, awake, parked, join, wake) => {
                        if s.refused.fetch_add(1, Relaxed) % Self::REMEASURE == Self::REMEASURE - 1 {
                            self.wake();
                        }
                    }
                    Ok(_) => self.wake(),
                    Err(_) => {}
                }
            }
        }
        job.work(0, usize::MAX);
        drop(withdraw);
        assert!(!s.poisoned.load(Acquire), "a crew thread panicked");
    }

    /// Wakes the parked helpers now, ahead of a job the caller is about to offer and knows to
    /// outlast waking them: they then join it from its start, not after its first piece has
    /// been timed, and spin until it comes (for [`Self::SPIN`]).
    pub fn wake_ahead(&self) {
        if self.shared.parked.load(SeqCst) > 0 {
            self.wake();
        }
    }

    /// Wakes the parked helpers, timing the call.
    fn wake(&self) {
        let s = &*self.shared;
        let start = Instant::now();
        s.woken_at.store(s.nanos(), SeqCst);
        s.wakes.fetch_add(1, SeqCst);
        {
            let _guard = s.lock.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
            s.wake.notify_all();
        }
        let took = start.elapsed();
        s.costs.lock().unwrap_or_else(std::sync::PoisonError::into_inner).wake.push(took);
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
    s.started.fetch_add(1, Release);
    let (mut seen, mut last) = (0, Instant::now());
    let spin = u64::try_from(s.spin.as_nanos()).unwrap_or(u64::MAX);
    let offered = |seen: usize| s.epoch.load(SeqCst) != seen && !s.job.load(SeqCst).is_null();
    while !s.stop.load(Relaxed) {
        let epoch = s.epoch.load(Acquire);
        if epoch == seen || s.job.load(Relaxed).is_null() {
            // It spins for `spin` after its last job and after the last wake (one ahead of a
            // job may come before it).
            let woken = s.wakes.load(Relaxed) > 0 && s.nanos().saturating_sub(s.woken_at.load(Relaxed)) < spin;
            if last.elapsed() < s.spin || woken {
                core::hint::spin_loop();
                continue;
            }
            let mut guard = s.lock.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
            // The wakes read before it counts itself parked: a caller that sees it parked and
            // wakes it counts a wake it then sees.
            let wakes = s.wakes.load(SeqCst);
            // Counted before looking: a caller that has seen no helper parked has already
            // offered its job, so this look finds it.
            s.parked.fetch_add(1, SeqCst);
            // The time from the first wake call after parking until this wait returned, taken
            // whether or not a job is still on offer by then.
            let mut joined = None;
            // Until a job is offered, or a wake ahead of one (`wake_ahead`) comes.
            while !offered(seen) && !s.stop.load(SeqCst) && s.wakes.load(SeqCst) == wakes {
                guard = s.wake.wait(guard).unwrap_or_else(std::sync::PoisonError::into_inner);
                if joined.is_none() && s.wakes.load(SeqCst) != wakes {
                    joined = Some(Duration::from_nanos(s.nanos().saturating_sub(s.woken_at.load(SeqCst))));
                }
            }
            s.parked.fetch_sub(1, SeqCst);
            drop(guard);
            if let Some(joined) = joined {
                s.costs.lock().unwrap_or_else(std::sync::PoisonError::into_inner).join.push(joined);
            }
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
            match std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| job.work(home, usize::MAX))) {
                Ok(ran) => _ = s.helped.fetch_add(ran, Relaxed),
                Err(_) => s.poisoned.store(true, Release),
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

    /// Runs one job of `pieces` pieces that sleep `piece` each; returns how many ran on a
    /// helper.
    fn pieces_elsewhere(crew: &Crew, pieces: usize, piece: Duration) -> usize {
        let caller = std::thread::current().id();
        let elsewhere = AtomicUsize::new(0);
        crew.run(pieces, &|_| {
            if std::thread::current().id() != caller {
                elsewhere.fetch_add(1, Relaxed);
            }
            std::thread::sleep(piece);
        });
        elsewhere.into_inner()
    }

    #[test]
    fn every_piece_runs_once_whether_helpers_spin_or_park() {
        for spin in [Duration::ZERO, Duration::from_micros(50), Crew::SPIN] {
            let crew = Crew::new(3, spin).unwrap();
            assert_eq!(crew.threads(), 3);
            each_piece_once(&crew, 2000, 7);
            assert_eq!(crew.jobs(), 2000);
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
        assert_eq!(job.work(1, 2), 2);
        assert_eq!(job.unclaimed(), 8);
        assert_eq!(job.work(1, usize::MAX), 8);
        assert_eq!(*order.lock().unwrap(), [3, 4, 5, 6, 7, 8, 9, 0, 1, 2]);
        assert_eq!(job.unclaimed(), 0);
        job.work(0, usize::MAX);
        assert_eq!(order.lock().unwrap().len(), 10, "nothing left for a second thread");
    }

    #[test]
    fn waking_pays_only_for_work_that_outlasts_it() {
        let us = Duration::from_micros;
        // One thread awake, one parked, joining 40 µs after a wake that costs 15 µs.
        assert!(!worth_waking(us(16), 1, 1, us(40), us(15)));
        assert!(!worth_waking(us(45), 1, 1, us(40), us(15)));
        assert!(worth_waking(us(100), 1, 1, us(40), us(15)));
        // Alone it would end at 60 µs; woken, at 40 + (60 − 40 + 15) / 2 = 57.5 µs.
        assert!(worth_waking(us(60), 1, 1, us(40), us(15)));
        assert!(!worth_waking(us(50), 1, 1, us(40), us(15)));
        // Three awake already gain less from a fourth.
        assert!(!worth_waking(us(150), 3, 1, us(40), us(15)));
        // Free and instant wakes always pay.
        assert!(worth_waking(us(1), 1, 3, Duration::ZERO, Duration::ZERO));
    }

    /// Helpers that park after every job are woken for long jobs, and, once the wakes are
    /// measured, not for jobs far shorter than a wake.
    #[test]
    fn parked_helpers_are_woken_for_long_jobs_only() {
        let crew = Crew::new(2, Duration::ZERO).unwrap();
        let mut elsewhere = 0;
        // Until the wakes are measured (on a loaded machine a helper may not have parked
        // before a job, and then it records no wake), at least 40 jobs.
        for j in 0..400 {
            if j >= 40 && crew.wake_costs().is_some() {
                break;
            }
            std::thread::sleep(Duration::from_millis(1));
            elsewhere += pieces_elsewhere(&crew, 8, Duration::from_micros(300));
        }
        assert!(elsewhere > 0, "no piece of a long job ran on the helper");
        assert!(crew.wake_costs().is_some(), "wakes measured");
        let wakes = |crew: &Crew| crew.shared.costs.lock().unwrap().wake.taken;
        let before = wakes(&crew);
        for _ in 0..100 {
            std::thread::sleep(Duration::from_micros(500));
            each_piece_once(&crew, 1, 8);
        }
        // A piece descheduled for a millisecond can still justify a wake, and one refused job
        // in `REMEASURE` wakes anyway; without the measurement every one of these jobs would
        // wake the helper.
        assert!(wakes(&crew) - before <= 12, "{} of 100 jobs of instant pieces woke the helper", wakes(&crew) - before);
    }

    /// A helper woken ahead of a job spins until it comes, and is not woken again for it.
    #[test]
    fn a_helper_woken_ahead_waits_for_the_job() {
        let spin = Duration::from_secs(1);
        let crew = Crew::new(2, spin).unwrap();
        let parked = |crew: &Crew| crew.shared.parked.load(SeqCst);
        let wait_until = |done: &dyn Fn() -> bool| (0..2000).any(|_| done() || (std::thread::sleep(Duration::from_millis(1)), false).1);
        assert!(wait_until(&|| parked(&crew) == 1), "the helper parked at the start");
        crew.wake_ahead();
        assert!(wait_until(&|| parked(&crew) == 0), "the helper woke");
        // Longer than a wake, shorter than the spin.
        std::thread::sleep(Duration::from_millis(20));
        assert_eq!(parked(&crew), 0, "the helper went back to sleep before the job came");
        let elsewhere = pieces_elsewhere(&crew, 8, Duration::from_micros(300));
        assert!(elsewhere > 0, "no piece ran on the helper");
        assert_eq!(crew.pieces_helped(), elsewhere);
        assert_eq!(crew.shared.wakes.load(SeqCst), 1, "woken again for the job");
    }

    #[test]
    fn helpers_take_part() {
        let crew = Crew::new(2, Crew::SPIN).unwrap();
        let elsewhere: usize = (0..200).map(|_| pieces_elsewhere(&crew, 4, Duration::from_micros(200))).sum();
        assert!(elsewhere > 0, "no piece ran on the helper");
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
