//! The statistics of the report: mean ± standard deviation per group, and the one-sided
//! Mann–Whitney U test of a variant against the reference (SPEC §6.1: "significantly worse"
//! at p < 0.01), as SciPy's `mannwhitneyu(variant, reference, alternative="less")` computes
//! it with `method="auto"`: the exact null distribution when a sample holds at most 8 values
//! and there are no ties, else the normal approximation with tie and continuity correction.
//! (statrs 0.19's `mannwhitneyu` gives 1 − SciPy's p for the exact one-sided test, so only its
//! `erfc` is used here.) Checked against SciPy's values in `data/reference/mannwhitneyu.json`.

use statrs::function::erf::erfc;

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
    /// p-value of "the variant is stochastically smaller than the reference", as SciPy's
    /// `mannwhitneyu` computes it (the paper's method).
    pub p: f64,
    /// The exact permutation p-value of the same test with ties kept: the share of all splits of
    /// the pooled values whose U is at most this one (SciPy's `permutation_test`). Where ties
    /// send SciPy to the normal approximation, small samples can get a p below what any split
    /// allows (3 against 5 runs: 0.0084 against the exact minimum 1/56).
    pub p_exact: f64,
    /// The smallest exact one-sided p that samples of these sizes allow, reached when every
    /// variant value lies below every reference value: 1 / C(n₁ + n₂, n₁). Three runs against
    /// three cannot go below 1/20 = 0.05, so [`ALPHA`] is out of reach whatever the runs give.
    pub min_p: f64,
    /// Cliff's δ, an effect size that needs no distribution: over every (variant, reference)
    /// pair, the share where the reference is higher minus the share where the variant is
    /// (ties count for neither); 1 − 2U / (n₁n₂). From −1 to 1; 1 when every variant value lies
    /// below every reference value.
    pub delta: f64,
}

impl Test {
    /// Whether the variant is significantly worse at [`ALPHA`]: both p-values agree.
    pub fn significant(&self) -> bool {
        self.p < ALPHA && self.p_exact < ALPHA
    }

    /// Whether the sample sizes allow an exact p below [`ALPHA`] at all.
    pub fn can_be_significant(&self) -> bool {
        self.min_p < ALPHA
    }

    /// The test in words for a table: U, SciPy's p and the exact p; but where SciPy's normal
    /// approximation (taken for ties) gives a p below the smallest that the run counts allow
    /// ([`Test::min_p`]: 0.05 for 3 against 3), only the exact p, since no split of the runs is
    /// that unlikely.
    pub fn shown(&self) -> String {
        if self.p < self.min_p {
            format!("U = {}, exact p {}", self.u, p_value(self.p_exact))
        } else {
            format!(
                "U = {}, p {}, exact {}",
                self.u,
                p_value(self.p),
                p_value(self.p_exact).trim_start_matches("= ")
            )
        }
    }
}

/// A p-value as a table says it: "= 0.0136" with four decimals, or "< 0.0001" for one that
/// four decimals would show as 0.
pub fn p_value(p: f64) -> String {
    if p < 0.000_05 {
        String::from("< 0.0001")
    } else {
        format!("= {p:.4}")
    }
}

/// Cohen's d of a variant against the reference: the reference's mean minus the variant's, over
/// the pooled sample standard deviation, so positive when the variant is lower. It needs only the
/// groups' mean ± std (and sizes), so it also measures the paper's Table 1, which gives nothing
/// else. `None` where it is undefined: a group of one value (its spread unknown, the other
/// group's alone would stand for both), or no spread in either group.
pub fn cohens_d(variant: &Summary, reference: &Summary) -> Option<f64> {
    if variant.n < 2 || reference.n < 2 {
        return None;
    }
    let dof = variant.n + reference.n - 2;
    let pooled = (variant.n - 1) as f64 * variant.std.powi(2)
        + (reference.n - 1) as f64 * reference.std.powi(2);
    let pooled = pooled / dof as f64;
    let sd = pooled.sqrt();
    (sd > 0.0 && sd.is_finite()).then(|| (reference.mean - variant.mean) / sd)
}

/// 1 / C(n₁ + n₂, n₁), as a product of n₁ ratios (no overflow for any run count).
fn smallest_exact_p(n1: usize, n2: usize) -> f64 {
    (1..=n1).map(|i| i as f64 / (n2 + i) as f64).product()
}

/// One-sided Mann–Whitney U test that `variant` is smaller than `reference`. `None` when a
/// sample is empty or holds a NaN.
pub fn worse_than(variant: &[f64], reference: &[f64]) -> Option<Test> {
    if variant.is_empty()
        || reference.is_empty()
        || variant.iter().chain(reference).any(|v| v.is_nan())
    {
        return None;
    }
    let (n1, n2) = (variant.len(), reference.len());
    let (ranks, ties) = average_ranks(&[variant, reference].concat());
    let r1: f64 = ranks[..n1].iter().sum();
    let u1 = r1 - (n1 * (n1 + 1)) as f64 / 2.0;
    // "Less" is the upper tail of the reference's U, as SciPy computes it.
    let u2 = (n1 * n2) as f64 - u1;
    let tied = ties.iter().any(|&t| t > 1);
    let p = if (n1 > 8 && n2 > 8) || tied {
        normal_sf(u2, n1, n2, &ties)
    } else {
        exact_sf(u2.round() as usize, n1, n2)
    };
    Some(Test {
        u: u1,
        p: p.clamp(0.0, 1.0),
        p_exact: exact_permutation_p(&ranks, n1, r1),
        min_p: smallest_exact_p(n1, n2),
        delta: 1.0 - 2.0 * u1 / (n1 * n2) as f64,
    })
}

/// P(R ≤ r1) where R is the rank sum of `n1` values drawn without replacement from `ranks`
/// (every split of the pooled sample equally likely): counts of subsets by their rank sum, the
/// ranks doubled so that midranks are whole numbers.
fn exact_permutation_p(ranks: &[f64], n1: usize, r1: f64) -> f64 {
    let doubled: Vec<usize> = ranks.iter().map(|r| (2.0 * r).round() as usize).collect();
    let max: usize = doubled.iter().sum();
    // ways[j][s]: subsets of j of the ranks seen so far whose doubled sum is s.
    let mut ways = vec![vec![0.0f64; max + 1]; n1 + 1];
    ways[0][0] = 1.0;
    for &r in &doubled {
        for j in (1..=n1).rev() {
            for s in (r..=max).rev() {
                ways[j][s] += ways[j - 1][s - r];
            }
        }
    }
    let observed = (2.0 * r1).round() as usize;
    let total: f64 = ways[n1].iter().sum();
    let below: f64 = ways[n1][..=observed.min(max)].iter().sum();
    (below / total).clamp(0.0, 1.0)
}

/// Ranks 1..=n with ties given their average rank, and the size of every group of equal values.
fn average_ranks(values: &[f64]) -> (Vec<f64>, Vec<usize>) {
    let mut order: Vec<usize> = (0..values.len()).collect();
    order.sort_by(|&a, &b| values[a].total_cmp(&values[b]));
    let mut ranks = vec![0.0; values.len()];
    let mut ties = Vec::new();
    let mut start = 0;
    while start < order.len() {
        let mut end = start + 1;
        while end < order.len() && values[order[end]] == values[order[start]] {
            end += 1;
        }
        // Positions start..end (0-based) share the mean of ranks start+1..=end.
        let rank = (start + 1 + end) as f64 / 2.0;
        for &i in &order[start..end] {
            ranks[i] = rank;
        }
        ties.push(end - start);
        start = end;
    }
    (ranks, ties)
}

/// P(U ≥ u) under the null hypothesis without ties, for samples of n1 and n2 values: the
/// distribution of U built by the recurrence on the largest value, which belongs to the first
/// sample (adding n2 to U) with probability n1 / (n1 + n2).
fn exact_sf(u: usize, n1: usize, n2: usize) -> f64 {
    // pmf[j]: the distribution of U for samples of i and j values, for the current i.
    let mut pmf: Vec<Vec<f64>> = (0..=n2).map(|_| vec![1.0]).collect();
    for i in 1..=n1 {
        let mut next: Vec<Vec<f64>> = vec![vec![1.0]];
        for j in 1..=n2 {
            let mut dist = vec![0.0; i * j + 1];
            let (a, b) = (i as f64 / (i + j) as f64, j as f64 / (i + j) as f64);
            // Largest value in the first sample: it exceeds all j of the second.
            for (k, p) in pmf[j].iter().enumerate() {
                dist[k + j] += a * p;
            }
            // Largest value in the second sample: U unchanged.
            for (k, p) in next[j - 1].iter().enumerate() {
                dist[k] += b * p;
            }
            next.push(dist);
        }
        pmf = next;
    }
    pmf[n2].iter().skip(u).sum()
}

/// P(Z ≥ z) for the standardised U with tie correction and continuity correction (SciPy's
/// asymptotic method).
fn normal_sf(u: f64, n1: usize, n2: usize, ties: &[usize]) -> f64 {
    let (n1f, n2f) = (n1 as f64, n2 as f64);
    let n = n1f + n2f;
    let tie_term: f64 = ties.iter().map(|&t| (t * t * t - t) as f64).sum();
    let s = (n1f * n2f / 12.0 * ((n + 1.0) - tie_term / (n * (n - 1.0)))).sqrt();
    let numerator = u - n1f * n2f / 2.0 - 0.5;
    if s == 0.0 {
        // Every value equal: z = ±∞ (U = mean, so the numerator is −0.5 and p = 1).
        return if numerator > 0.0 { 0.0 } else { 1.0 };
    }
    0.5 * erfc(numerator / s / std::f64::consts::SQRT_2)
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

    /// Three runs all below three tied ones: SciPy's normal approximation (ties) gives a p
    /// below 1 / C(6, 3) = 0.05, which no split of six runs reaches; the table shows only the
    /// exact p, 0.05 (issue 79). Where SciPy's p is reachable, both are shown.
    #[test]
    fn an_unreachable_p_is_never_shown() {
        let t = worse_than(&[20.9, 21.55, 22.7], &[24.8, 24.95, 24.95]).unwrap();
        assert!(t.p < t.min_p, "{t:?}");
        assert!((t.p_exact - 0.05).abs() < 1e-12, "{t:?}");
        assert_eq!(t.shown(), "U = 0, exact p = 0.0500");
        let t = worse_than(&[1.0, 2.0, 3.0, 4.0, 5.0], &[6.0, 7.0, 8.0, 9.0, 10.0]).unwrap();
        assert_eq!(
            t.shown(),
            format!("U = 0, p = {:.4}, exact {:.4}", t.p, t.p_exact)
        );
        // Ten runs all below ten: 1 / C(20, 10) ≈ 5.4e-6, never shown as 0.
        let t = worse_than(
            &(0..10).map(f64::from).collect::<Vec<_>>(),
            &(10..20).map(f64::from).collect::<Vec<_>>(),
        )
        .unwrap();
        assert!(t.p_exact < 1e-5, "{t:?}");
        assert_eq!(t.shown(), format!("U = 0, p = {:.4}, exact < 0.0001", t.p));
        assert_eq!(p_value(0.00005), "= 0.0001");
        assert_eq!(p_value(0.00004), "< 0.0001");
    }

    #[test]
    fn the_test_gives_scipys_u_and_p() {
        #[derive(serde::Deserialize)]
        struct Case {
            x: Vec<f64>,
            y: Vec<f64>,
            u: f64,
            p: f64,
            p_exact: f64,
            delta: f64,
            d: Option<f64>,
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
            assert!(
                (t.p_exact - c.p_exact).abs() <= 1e-12,
                "exact p of {:?} vs {:?}: {} against SciPy's permutation_test {}",
                c.x,
                c.y,
                t.p_exact,
                c.p_exact
            );
            assert!(
                (t.delta - c.delta).abs() <= 1e-12,
                "Cliff's delta of {:?} vs {:?}: {} against the pair count {}",
                c.x,
                c.y,
                t.delta,
                c.delta
            );
            let d = cohens_d(&summary(&c.x).unwrap(), &summary(&c.y).unwrap());
            match (d, c.d) {
                (Some(ours), Some(numpy)) => assert!(
                    (ours - numpy).abs() <= 1e-9 * numpy.abs().max(1.0),
                    "Cohen's d of {:?} vs {:?}: {ours} against NumPy's {numpy}",
                    c.x,
                    c.y
                ),
                (ours, numpy) => assert_eq!(ours, numpy, "Cohen's d of {:?} vs {:?}", c.x, c.y),
            }
        }
    }

    #[test]
    fn the_smallest_p_of_three_against_three_is_one_in_twenty() {
        // 1 / C(6, 3): three seeds a side cannot reach the paper's 0.01, however far apart.
        let t = worse_than(&[1.0, 2.0, 3.0], &[7.0, 8.0, 9.0]).unwrap();
        assert!((t.min_p - 0.05).abs() < 1e-15, "{}", t.min_p);
        assert!((t.p_exact - 0.05).abs() < 1e-12);
        assert_eq!(t.delta, 1.0);
        assert!(!t.can_be_significant() && !t.significant());
        // 1 / C(10, 5) = 1/252 and 1 / C(20, 10) = 1/184756 can.
        let t = worse_than(&[5.0; 5], &[6.0; 5]).unwrap();
        assert!((t.min_p - 1.0 / 252.0).abs() < 1e-15);
        assert!(t.can_be_significant());
        let t = worse_than(&[1.0; 10], &[2.0; 10]).unwrap();
        assert!((t.min_p - 1.0 / 184_756.0).abs() < 1e-18);
        // One run against one: 1/2.
        assert_eq!(worse_than(&[1.0], &[2.0]).unwrap().min_p, 0.5);
    }

    #[test]
    fn cohens_d_by_hand_and_where_it_is_undefined() {
        let s = |n, mean, std| Summary {
            n,
            mean,
            std,
            min: mean,
            max: mean,
        };
        // The paper's LightsOutReacher without relabelling (16.58 ± 4.62) against SEADS
        // (24.3 ± 0.28), ten agents each: pooled sd √((4.62² + 0.28²) / 2).
        let d = cohens_d(&s(10, 16.58, 4.62), &s(10, 24.3, 0.28)).unwrap();
        let by_hand = 7.72 / ((4.62f64 * 4.62 + 0.28 * 0.28) / 2.0).sqrt();
        assert!((d - by_hand).abs() < 1e-12, "{d} against {by_hand}");
        assert!(cohens_d(&s(3, 12.0, 0.0), &s(3, 12.0, 0.0)).is_none());
        assert!(cohens_d(&s(1, 1.0, 0.0), &s(1, 2.0, 0.0)).is_none());
        // One run against two: the pair's spread alone would stand for both groups.
        assert!(cohens_d(&s(2, 18.2, 0.07), &s(1, 23.6, 0.0)).is_none());
        assert!(cohens_d(&s(2, 18.2, 0.07), &s(2, 23.6, 0.0)).is_some());
        assert!(cohens_d(&s(3, 1.0, f64::NAN), &s(3, 2.0, 1.0)).is_none());
    }

    proptest::proptest! {
        /// No split of the pooled values gives an exact p below the smallest the sizes allow;
        /// Cliff's δ lies in [−1, 1] and changes sign when the samples swap.
        #[test]
        fn exact_p_is_never_below_the_smallest_and_delta_is_antisymmetric(
            x in proptest::collection::vec(0u8..6, 1..7),
            y in proptest::collection::vec(0u8..6, 1..7),
        ) {
            let x: Vec<f64> = x.into_iter().map(f64::from).collect();
            let y: Vec<f64> = y.into_iter().map(f64::from).collect();
            let t = worse_than(&x, &y).unwrap();
            proptest::prop_assert!(t.p_exact >= t.min_p * (1.0 - 1e-12), "{} < {}", t.p_exact, t.min_p);
            proptest::prop_assert!((-1.0..=1.0).contains(&t.delta));
            let swapped = worse_than(&y, &x).unwrap();
            proptest::prop_assert!((t.delta + swapped.delta).abs() < 1e-12);
        }
    }
}
