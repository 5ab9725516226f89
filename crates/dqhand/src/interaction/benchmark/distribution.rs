//! The spread of measured samples (latencies, times per record): benchmarks report a median
//! and a tail, never one run.

use serde::Serialize;

/// Count, median, 95th percentile and maximum of a set of samples: the sample at rank
/// `round((n − 1) q)` of the sorted ones (for an even count, the upper of the middle two).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Distribution {
    /// Number of samples.
    pub count: usize,
    /// The middle sample.
    pub median: f64,
    /// The sample 95 % of the way up.
    pub p95: f64,
    /// The largest sample.
    pub max: f64,
}

impl Distribution {
    /// The distribution of `samples`, which it sorts; `None` when there are none.
    #[must_use]
    pub fn of(samples: &mut [f64]) -> Option<Self> {
        let last = samples.len().checked_sub(1)?;
        samples.sort_by(f64::total_cmp);
        let at = |q: f64| samples[(last as f64 * q).round() as usize];
        Some(Self { count: samples.len(), median: at(0.5), p95: at(0.95), max: samples[last] })
    }

    /// The same distribution in another unit (`factor` 1000: seconds to milliseconds).
    #[must_use]
    pub fn scaled(self, factor: f64) -> Self {
        Self { median: self.median * factor, p95: self.p95 * factor, max: self.max * factor, ..self }
    }
}
