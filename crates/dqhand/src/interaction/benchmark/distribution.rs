//! The spread of measured samples (latencies, times per record): benchmarks report a median
//! and a tail, never one run.

use serde::Serialize;

use crate::math::quantile;

/// Count, median, 95th percentile and maximum of a set of samples (by [`quantile`]'s rule).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Distribution {
    /// Number of samples.
    pub count: usize,
    /// The middle sample.
    pub median: f64,
    /// The sample 95 % of the way up.
    pub p95: f64,
    /// The sample 99 % of the way up: the hiccups a frame budget must absorb.
    pub p99: f64,
    /// The largest sample.
    pub max: f64,
}

impl Distribution {
    /// The distribution of `samples`, which it sorts; `None` when there are none.
    #[must_use]
    pub fn of(samples: &mut [f64]) -> Option<Self> {
        let (median, p95, p99, max) = (quantile(samples, 0.5)?, quantile(samples, 0.95)?, quantile(samples, 0.99)?, quantile(samples, 1.0)?);
        Some(Self { count: samples.len(), median, p95, p99, max })
    }

    /// The same distribution in another unit (`factor` 1000: seconds to milliseconds).
    #[must_use]
    pub fn scaled(self, factor: f64) -> Self {
        Self { median: self.median * factor, p95: self.p95 * factor, p99: self.p99 * factor, max: self.max * factor, ..self }
    }
}
