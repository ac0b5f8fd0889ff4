//! Interval estimates over runs, as Agarwal et al. (2021, "Deep Reinforcement Learning at the
//! Edge of the Statistical Precipice") define them and their `rliable` package computes them:
//! the interquartile mean (IQM), percentile bootstrap 95 % confidence intervals of it and of the
//! mean, the probability of improvement of one variant over another with its interval, and run
//! score distributions (performance profiles). A run is the unit: one value per run, never per
//! task or evaluation episode. Each cell of a report is one environment, so the stratified
//! bootstrap (runs resampled within each task) is the plain bootstrap over its runs.
//!
//! The bootstrap draws from ChaCha8 keyed by [`BOOTSTRAP_SEED`], its stream the CRC-32 of what
//! is estimated (environment, variant, metric), so that a report repeats exactly and a cell's
//! interval does not depend on which other cells the report holds. Checked against rliable 1.2
//! on committed studies (`data/reference/rliable/`): the IQM exactly, the intervals within
//! bootstrap error.

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// The seed of every report's bootstrap.
pub const BOOTSTRAP_SEED: u64 = 0;

/// Bootstrap resamples per interval (rliable's default).
pub const RESAMPLES: usize = 50_000;

/// The confidence of the intervals.
pub const CONFIDENCE: f64 = 0.95;

/// The interquartile mean: the mean of the values left when a quarter is cut from each end of
/// the sorted values (⌊n / 4⌋ each; SciPy's `trim_mean(values, 0.25)`, which rliable's IQM is).
/// `None` for no values.
pub fn iqm(values: &[f64]) -> Option<f64> {
    if values.is_empty() {
        return None;
    }
    let mut sorted = values.to_vec();
    sorted.sort_by(f64::total_cmp);
    let cut = sorted.len() / 4;
    Some(mean(&sorted[cut..sorted.len() - cut]))
}

/// The arithmetic mean of values (none: NaN).
pub fn mean(values: &[f64]) -> f64 {
    values.iter().sum::<f64>() / values.len() as f64
}

/// The probability that a run of `x` scores higher than a run of `y`, ties counting half:
/// P(X > Y) + ½ P(X = Y) over every pair (rliable's `probability_of_improvement` for one task,
/// the Mann–Whitney U of `x` over n_x · n_y). `None` if either has no values.
pub fn probability_of_improvement(x: &[f64], y: &[f64]) -> Option<f64> {
    if x.is_empty() || y.is_empty() {
        return None;
    }
    let wins: f64 = x
        .iter()
        .flat_map(|a| {
            y.iter().map(move |b| match a.total_cmp(b) {
                std::cmp::Ordering::Greater => 1.0,
                std::cmp::Ordering::Equal => 0.5,
                std::cmp::Ordering::Less => 0.0,
            })
        })
        .sum();
    Some(wins / (x.len() * y.len()) as f64)
}

/// The share of `values` above `tau` (a point of a run score distribution: rliable's
/// performance profile, one task).
pub fn share_above(values: &[f64], tau: f64) -> f64 {
    values.iter().filter(|&&v| v > tau).count() as f64 / values.len() as f64
}

/// An estimate and its percentile bootstrap confidence interval.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Interval {
    /// The statistic on the runs themselves.
    pub estimate: f64,
    /// Lower end of the interval.
    pub low: f64,
    /// Upper end of the interval.
    pub high: f64,
}

impl Interval {
    /// `estimate [low, high]` with `digits` decimals.
    pub fn show(&self, digits: usize) -> String {
        format!(
            "{:.digits$} [{:.digits$}, {:.digits$}]",
            self.estimate, self.low, self.high
        )
    }
}

/// The bootstrap stream of what `key` names (e.g. `"iqm/lightsout-cursor/seads/coverage"`).
fn stream(key: &str) -> ChaCha8Rng {
    let mut rng = ChaCha8Rng::seed_from_u64(BOOTSTRAP_SEED);
    rng.set_stream(u64::from(crc32fast::hash(key.as_bytes())));
    rng
}

/// A resample of `values` with replacement (as many as there are) into `out`.
fn resample(rng: &mut ChaCha8Rng, values: &[f64], out: &mut Vec<f64>) {
    out.clear();
    out.extend((0..values.len()).map(|_| values[rng.random_range(0..values.len())]));
}

/// The `q`-quantile of sorted values with linear interpolation between neighbours (NumPy's
/// default `percentile`).
fn quantile(sorted: &[f64], q: f64) -> f64 {
    let at = q * (sorted.len() - 1) as f64;
    let (below, above) = (at.floor() as usize, at.ceil() as usize);
    sorted[below] + (sorted[above] - sorted[below]) * (at - below as f64)
}

/// The central [`CONFIDENCE`] interval of the statistics of the resamples.
fn percentile_interval(estimate: f64, mut statistics: Vec<f64>) -> Interval {
    statistics.sort_by(f64::total_cmp);
    let tail = (1.0 - CONFIDENCE) / 2.0;
    Interval {
        estimate,
        low: quantile(&statistics, tail),
        high: quantile(&statistics, 1.0 - tail),
    }
}

/// `statistic` of `values` with its bootstrap interval over [`RESAMPLES`] resamples drawn from
/// the stream of `key`. `None` for no values or a statistic that is not a number.
pub fn bootstrap(
    values: &[f64],
    statistic: impl Fn(&[f64]) -> Option<f64>,
    key: &str,
) -> Option<Interval> {
    let estimate = statistic(values).filter(|v| !v.is_nan())?;
    let mut rng = stream(key);
    let mut drawn = Vec::with_capacity(values.len());
    let statistics = (0..RESAMPLES)
        .map(|_| {
            resample(&mut rng, values, &mut drawn);
            statistic(&drawn).unwrap_or(f64::NAN)
        })
        .collect();
    Some(percentile_interval(estimate, statistics))
}

/// The probability of improvement of `x` over `y` with its bootstrap interval, the two groups
/// resampled independently ([`RESAMPLES`] times, from the stream of `key`).
pub fn improvement_interval(x: &[f64], y: &[f64], key: &str) -> Option<Interval> {
    let estimate = probability_of_improvement(x, y)?;
    let mut rng = stream(key);
    let (mut xs, mut ys) = (Vec::with_capacity(x.len()), Vec::with_capacity(y.len()));
    let statistics = (0..RESAMPLES)
        .map(|_| {
            resample(&mut rng, x, &mut xs);
            resample(&mut rng, y, &mut ys);
            probability_of_improvement(&xs, &ys).unwrap_or(f64::NAN)
        })
        .collect();
    Some(percentile_interval(estimate, statistics))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// By hand: 8 values lose 2 at each end; 3 values keep all; 5 lose one at each end.
    #[test]
    fn the_iqm_cuts_a_quarter_from_each_end() {
        let eight = [8.0, 1.0, 7.0, 2.0, 6.0, 3.0, 5.0, 100.0];
        assert_eq!(iqm(&eight), Some((3.0 + 5.0 + 6.0 + 7.0) / 4.0));
        assert_eq!(iqm(&[1.0, 2.0, 9.0]), Some(4.0));
        assert_eq!(iqm(&[0.0, 1.0, 2.0, 3.0, 40.0]), Some(2.0));
        assert_eq!(iqm(&[]), None);
    }

    /// By hand: of the 6 pairs of {1, 2, 3} against {2, 4}, x wins (3, 2) and ties (2, 2).
    #[test]
    fn the_probability_of_improvement_counts_ties_half() {
        let p = probability_of_improvement(&[1.0, 2.0, 3.0], &[2.0, 4.0]).unwrap();
        assert!((p - 1.5 / 6.0).abs() < 1e-15, "{p}");
        assert_eq!(probability_of_improvement(&[5.0], &[1.0, 2.0]), Some(1.0));
        assert_eq!(probability_of_improvement(&[], &[1.0]), None);
    }

    /// NumPy's `percentile([1, 2, 3, 4], 25)` is 1.75; the 0.5-quantile of five values their
    /// middle.
    #[test]
    fn quantiles_interpolate_as_numpy_does() {
        assert!((quantile(&[1.0, 2.0, 3.0, 4.0], 0.25) - 1.75).abs() < 1e-15);
        assert_eq!(quantile(&[1.0, 2.0, 3.0, 4.0, 5.0], 0.5), 3.0);
    }

    /// An interval repeats exactly for its key, holds its estimate, and another key draws from
    /// another stream; identical runs leave no room for an interval.
    #[test]
    fn intervals_repeat_for_their_key_and_hold_the_estimate() {
        let values = [20.1, 21.7, 23.9, 24.0, 24.6];
        let a = bootstrap(&values, iqm, "iqm/e/v/coverage").unwrap();
        assert_eq!(a, bootstrap(&values, iqm, "iqm/e/v/coverage").unwrap());
        assert!(a.low <= a.estimate && a.estimate <= a.high, "{a:?}");
        assert!(a.low >= 20.1 && a.high <= 24.6, "{a:?}");
        assert_ne!(
            stream("iqm/e/v/coverage").random::<u64>(),
            stream("iqm/e/w/coverage").random::<u64>()
        );
        let flat = bootstrap(&[3.0; 4], |v| Some(mean(v)), "k").unwrap();
        assert_eq!((flat.low, flat.estimate, flat.high), (3.0, 3.0, 3.0));
        let sure = improvement_interval(&[5.0, 6.0], &[1.0, 2.0], "k").unwrap();
        assert_eq!((sure.low, sure.estimate, sure.high), (1.0, 1.0, 1.0));
    }
}
