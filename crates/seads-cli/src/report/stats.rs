//! The statistics of the report: mean ± standard deviation per group, and the one-sided
//! Mann–Whitney U test of a variant against the reference (SPEC §6.1: "significantly worse"
//! at p < 0.01), as SciPy's `mannwhitneyu(variant, reference, alternative="less")` computes
//! it: exact when neither sample exceeds 8 values and there are no ties, the tie-corrected
//! normal approximation with continuity correction otherwise (statrs implements both).

use statrs::stats_tests::Alternative;
use statrs::stats_tests::mannwhitneyu::{MannWhitneyUMethod, mannwhitneyu};

/// The significance level of the paper's Table 1.
pub const ALPHA: f64 = 0.01;

/// Mean, sample standard deviation (n − 1; 0 for one value), minimum and maximum.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Summary {
    /// Number of values.
    pub n: usize,
    /// Mean.
    pub mean: f64,
    /// Sample standard deviation.
    pub std: f64,
    /// Smallest value.
    pub min: f64,
    /// Largest value.
    pub max: f64,
}

/// The summary of `values` (`None` when empty).
pub fn summary(values: &[f64]) -> Option<Summary> {
    if values.is_empty() {
        return None;
    }
    let n = values.len();
    let mean = values.iter().sum::<f64>() / n as f64;
    let var = if n > 1 {
        values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1) as f64
    } else {
        0.0
    };
    Some(Summary {
        n,
        mean,
        std: var.sqrt(),
        min: values.iter().copied().fold(f64::INFINITY, f64::min),
        max: values.iter().copied().fold(f64::NEG_INFINITY, f64::max),
    })
}

/// The median of `values` (mean of the two middle values for an even count).
pub fn median(values: &[f64]) -> Option<f64> {
    let mut v: Vec<f64> = values.iter().copied().filter(|x| !x.is_nan()).collect();
    if v.is_empty() {
        return None;
    }
    v.sort_by(f64::total_cmp);
    let m = v.len() / 2;
    Some(if v.len() % 2 == 1 {
        v[m]
    } else {
        (v[m - 1] + v[m]) / 2.0
    })
}

/// A one-sided test result.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Test {
    /// U statistic of the variant's sample.
    pub u: f64,
    /// p-value of "the variant is stochastically smaller than the reference".
    pub p: f64,
}

impl Test {
    /// Whether the variant is significantly worse at [`ALPHA`].
    pub fn significant(&self) -> bool {
        self.p < ALPHA
    }
}

/// One-sided Mann–Whitney U test that `variant` is smaller than `reference` (SciPy's
/// `method="auto"`). `None` when a sample is empty or holds a NaN.
pub fn worse_than(variant: &[f64], reference: &[f64]) -> Option<Test> {
    if variant.is_empty()
        || reference.is_empty()
        || variant.iter().chain(reference).any(|v| v.is_nan())
    {
        return None;
    }
    mannwhitneyu(
        variant,
        reference,
        MannWhitneyUMethod::Automatic,
        Alternative::Less,
    )
    .ok()
    .map(|(u, p)| Test { u, p })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn summary_and_median_by_hand() {
        let s = summary(&[24.0, 25.0, 25.0, 23.0]).unwrap();
        assert_eq!((s.n, s.mean, s.min, s.max), (4, 24.25, 23.0, 25.0));
        // Squared deviations 0.0625 + 0.5625·2 + 1.5625 = 2.75; / 3.
        assert!((s.std - (2.75f64 / 3.0).sqrt()).abs() < 1e-12);
        assert_eq!(summary(&[3.0]).unwrap().std, 0.0);
        assert!(summary(&[]).is_none());
        assert_eq!(median(&[3.0, 1.0, 2.0]), Some(2.0));
        assert_eq!(median(&[4.0, 1.0, 3.0, 2.0]), Some(2.5));
        assert_eq!(median(&[]), None);
    }

    #[test]
    fn five_against_five_all_below_is_the_smallest_exact_p() {
        // Every variant value below every reference value: U = 0 and the exact one-sided p is
        // 1 / C(10, 5) = 1/252 — why five seeds are the least that can reach p < 0.01.
        let t = worse_than(&[1.0, 2.0, 3.0, 4.0, 5.0], &[6.0, 7.0, 8.0, 9.0, 10.0]).unwrap();
        assert_eq!(t.u, 0.0);
        assert!((t.p - 1.0 / 252.0).abs() < 1e-12, "{}", t.p);
        assert!(t.significant());
        // Four against four cannot: 1 / C(8, 4) = 1/70.
        let t = worse_than(&[1.0, 2.0, 3.0, 4.0], &[6.0, 7.0, 8.0, 9.0]).unwrap();
        assert!((t.p - 1.0 / 70.0).abs() < 1e-12);
        assert!(!t.significant());
        assert!(worse_than(&[], &[1.0]).is_none());
        assert!(worse_than(&[f64::NAN], &[1.0]).is_none());
    }

    #[test]
    fn the_test_gives_scipys_u_and_p() {
        #[derive(serde::Deserialize)]
        struct Case {
            x: Vec<f64>,
            y: Vec<f64>,
            u: f64,
            p: f64,
        }
        #[derive(serde::Deserialize)]
        struct Reference {
            cases: Vec<Case>,
        }
        let reference: Reference =
            serde_json::from_str(include_str!("../../../../data/reference/mannwhitneyu.json"))
                .unwrap();
        assert!(reference.cases.len() >= 10);
        for c in &reference.cases {
            let t = worse_than(&c.x, &c.y).unwrap();
            assert_eq!(t.u, c.u, "U of {:?} vs {:?}", c.x, c.y);
            assert!(
                (t.p - c.p).abs() <= 1e-9 * c.p.max(1e-3),
                "p of {:?} vs {:?}: {} against SciPy's {}",
                c.x,
                c.y,
                t.p,
                c.p
            );
        }
    }
}
