//! The quantile of measured samples, one rule for every report (benchmarks, calibration):
//! the sample at rank `round((n − 1) q)` of the sorted ones, so for an even count the median
//! is the upper of the middle two.

/// The `q` quantile (0–1) of `values`, which it sorts (by IEEE total order); `None` when
/// there are none.
pub fn quantile<T: Copy + Into<f64>>(values: &mut [T], q: f64) -> Option<T> {
    let last = values.len().checked_sub(1)?;
    values.sort_by(|a, b| (*a).into().total_cmp(&(*b).into()));
    Some(values[(last as f64 * q.clamp(0.0, 1.0)).round() as usize])
}

#[cfg(test)]
mod tests {
    use super::quantile;

    #[test]
    fn the_rounded_rank_of_the_sorted_samples() {
        let mut v: Vec<f64> = (1..=20).rev().map(f64::from).collect();
        // Rank round(19 q) + 1 of 1..=20, written out.
        assert_eq!(quantile(&mut v, 0.5), Some(11.0));
        assert_eq!(quantile(&mut v, 0.95), Some(19.0));
        assert_eq!(quantile(&mut v, 0.0), Some(1.0));
        assert_eq!(quantile(&mut v, 1.0), Some(20.0));
        assert_eq!(v, (1..=20).map(f64::from).collect::<Vec<_>>(), "sorted in place");
        let mut odd = [3.0f32, 1.0, 2.0];
        assert_eq!(quantile(&mut odd, 0.5), Some(2.0));
        assert_eq!(quantile::<f32>(&mut [], 0.5), None);
    }
}
