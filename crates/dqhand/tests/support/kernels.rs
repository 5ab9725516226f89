//! The skinning kernels a test runs on this CPU, said aloud, and required where asked.
//!
//! A test that runs every kernel this CPU has skips the others: [`kernels`] prints which ran
//! and which were skipped (once per test; seen with `cargo test -- --nocapture`), and its
//! `Display` goes into the test's failure messages. `DQHAND_REQUIRE_KERNELS`, a comma list of
//! kernel names (`avx512,avx2`; `make test` sets it from the machine's CPU flags), turns a
//! required kernel this CPU lacks into a failure instead of a skip, so that a machine that has
//! it cannot pass without running it.

use std::cell::Cell;
use std::fmt;

use dqhand::skin::Kernel;

/// The environment variable naming the kernels a test must run.
pub const REQUIRE: &str = "DQHAND_REQUIRE_KERNELS";

/// The kernels a test runs and those it skips, slowest first.
#[derive(Clone, Debug)]
pub struct Kernels {
    pub run: Vec<Kernel>,
    pub skipped: Vec<Kernel>,
    /// What [`REQUIRE`] asked for (all of it run, or [`kernels`] failed).
    pub required: Vec<Kernel>,
}

thread_local! {
    /// Whether this thread (one test) has said which kernels it runs.
    static SAID: Cell<bool> = const { Cell::new(false) };
}

/// The kernels this CPU runs, and those it lacks, said once per test; fails if
/// [`REQUIRE`] names one it lacks, or a name that is not a kernel's.
///
/// # Panics
/// As said.
#[must_use]
pub fn kernels() -> Kernels {
    let (run, skipped): (Vec<Kernel>, Vec<Kernel>) = Kernel::ALL.into_iter().partition(|k| k.available());
    let required = required();
    let kernels = Kernels { run, skipped, required };
    if !SAID.with(|s| s.replace(true)) {
        eprintln!("{}: {kernels}", std::thread::current().name().unwrap_or("this test"));
    }
    let missing: Vec<&str> = kernels.required.iter().filter(|k| kernels.skipped.contains(k)).map(|k| k.name()).collect();
    assert!(missing.is_empty(), "{REQUIRE} requires the {} kernel(s), which this CPU lacks: {kernels}", missing.join(", "));
    kernels
}

/// The kernels [`REQUIRE`] names (none when it is unset or empty).
fn required() -> Vec<Kernel> {
    let list = std::env::var(REQUIRE).unwrap_or_default();
    list.split(',')
        .map(str::trim)
        .filter(|name| !name.is_empty())
        .map(|name| {
            Kernel::named(name).unwrap_or_else(|| {
                let names: Vec<&str> = Kernel::ALL.iter().map(|k| k.name()).collect();
                panic!("{REQUIRE}={list}: {name:?} is not a kernel ({})", names.join(", "))
            })
        })
        .collect()
}

impl fmt::Display for Kernels {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let names = |ks: &[Kernel]| if ks.is_empty() { "none".to_owned() } else { ks.iter().map(|k| k.name()).collect::<Vec<_>>().join(", ") };
        write!(f, "kernel paths run: {}; skipped (this CPU or build lacks them): {}", names(&self.run), names(&self.skipped))?;
        match std::env::var(REQUIRE) {
            Ok(list) => write!(f, "; {REQUIRE}={list}"),
            Err(_) => write!(f, "; {REQUIRE} unset (a skipped kernel is not a failure)"),
        }
    }
}
