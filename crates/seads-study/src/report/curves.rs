//! Skill coverage over training, as SPEC §6.1 reads the authors' curve: each run's coverage at
//! fixed step counts (its last evaluation at or before the count, held until the next), averaged
//! over a group's runs; and each run's mean coverage over training (the area under that held
//! curve divided by the steps it spans), tested against the reference variant. "Learns slower"
//! is a statement about the second, which the end point alone cannot make.

use std::fmt::Write as _;

use super::csv_field;
use super::runs::Group;
use super::stats::{summary, worse_than};

/// The step counts of the table (SPEC §6.1's reading of the authors' LightsOutCursor curve).
pub const STEPS: [u64; 4] = [20_000, 50_000, 100_000, 150_000];

/// The step counts of the table for groups that train 5·10⁶ steps or more, the arms' 10⁷
/// (SPEC §6.1: "Reacher ≈ 23/25 by 2.5·10⁶; Jaco rises over the whole 10⁷").
pub const LONG_STEPS: [u64; 4] = [1_000_000, 2_500_000, 5_000_000, 10_000_000];

/// The step counts for a group whose runs' curves are `runs`: [`LONG_STEPS`] when its longest
/// run reaches 5·10⁶ steps, else [`STEPS`].
fn steps_for(runs: &[Curve]) -> &'static [u64; 4] {
    let longest = runs.iter().filter_map(|c| c.last()).map(|(s, _)| *s).max();
    if longest.is_some_and(|s| s >= 5_000_000) {
        &LONG_STEPS
    } else {
        &STEPS
    }
}

/// A run's coverage at `steps`: its last evaluation at or before then (`None` before the first).
/// `curve` is (environment steps, coverage) in the order of training.
pub fn coverage_at(curve: &[(u64, f64)], steps: u64) -> Option<f64> {
    curve
        .iter()
        .take_while(|(s, _)| *s <= steps)
        .last()
        .map(|(_, c)| *c)
}

/// A run's mean coverage over training: each evaluation's value held until the next, integrated
/// from the first evaluation to the last and divided by the steps between them (`None` for fewer
/// than two evaluations).
pub fn mean_over_training(curve: &[(u64, f64)]) -> Option<f64> {
    let (first, last) = (curve.first()?.0, curve.last()?.0);
    if last <= first {
        return None;
    }
    let area: f64 = curve
        .windows(2)
        .map(|w| w[0].1 * (w[1].0 - w[0].0) as f64)
        .sum();
    Some(area / (last - first) as f64)
}

/// One group's row of the table, and its lines of the CSV.
fn row(
    md: &mut String,
    csv: &mut String,
    g: &Group<'_>,
    runs: &[Curve],
    steps: &[u64],
    groups: &[Group<'_>],
    reference: Option<&str>,
) {
    let _ = write!(md, "| {} | {} | {} |", g.env, g.variant, runs.len());
    // A CSV line: the group, the measure (at `steps`, or over training) and its summary.
    let mut line = |measure: &str, steps: String, v: &super::stats::Summary| {
        let (env, variant) = (csv_field(&g.env), csv_field(&g.variant));
        let (n, mean, std) = (v.n, v.mean, v.std);
        let _ = writeln!(
            csv,
            "{env},{variant},{n},{measure},{steps},{mean:.4},{std:.4}"
        );
    };
    for &s in steps {
        let values: Vec<f64> = runs.iter().filter_map(|c| coverage_at(c, s)).collect();
        match summary(&values) {
            Some(v) => {
                let _ = write!(md, " {:.2} |", v.mean);
                line("coverage_at", s.to_string(), &v);
            }
            None => *md += " – |",
        }
    }
    let means: Vec<f64> = runs.iter().filter_map(|c| mean_over_training(c)).collect();
    match summary(&means) {
        Some(v) => {
            let _ = write!(md, " {:.2} ± {:.2} |", v.mean, v.std);
            line("mean_over_training", String::new(), &v);
        }
        None => *md += " – |",
    }
    let reference_means = reference
        .filter(|r| *r != g.variant)
        .and_then(|r| groups.iter().find(|o| o.env == g.env && o.variant == r))
        .map(|o| {
            curves(o)
                .iter()
                .filter_map(|c| mean_over_training(c))
                .collect::<Vec<f64>>()
        });
    match reference_means.and_then(|r| worse_than(&means, &r)) {
        Some(t) => {
            let text = t.shown();
            if t.significant() {
                let _ = writeln!(md, " **{text}** |");
            } else {
                let _ = writeln!(md, " {text} |");
            }
        }
        None => *md += " – |\n",
    }
}

/// A run's coverage curve: (environment steps, coverage) in the order of training.
type Curve = Vec<(u64, f64)>;

/// The coverage curve of each SEADS run of a group.
fn curves(group: &Group<'_>) -> Vec<Curve> {
    group
        .runs
        .iter()
        .map(|r| {
            r.lines
                .iter()
                .filter_map(|m| Some((m.env_steps, m.skill_coverage?)))
                .collect::<Curve>()
        })
        .filter(|curve| !curve.is_empty())
        .collect()
}

/// The table (Markdown) and its CSV; `None` when no group has coverage curves. Groups of long
/// runs (the arms) get a table of their own, at [`LONG_STEPS`].
pub fn coverage_over_training(
    groups: &[Group<'_>],
    reference: Option<&str>,
) -> Option<(String, String)> {
    let mut md = String::new();
    let mut csv = String::from("env,variant,runs,measure,steps,mean,std\n");
    let with_curves: Vec<(&Group<'_>, Vec<Curve>)> = groups
        .iter()
        .map(|g| (g, curves(g)))
        .filter(|(_, runs)| !runs.is_empty())
        .collect();
    if with_curves.is_empty() {
        return None;
    }
    let mut long_table = false;
    for steps in [&STEPS, &LONG_STEPS] {
        let rows: Vec<_> = with_curves
            .iter()
            .filter(|(_, runs)| steps_for(runs) == steps)
            .collect();
        if rows.is_empty() {
            continue;
        }
        long_table |= steps == &LONG_STEPS;
        if !md.is_empty() {
            md.push('\n');
        }
        md += "| environment | variant | runs |";
        for s in steps {
            let _ = write!(md, " {s} steps |");
        }
        md += " mean over training | against the reference |\n|---|---|---|";
        md += &"---|".repeat(steps.len() + 2);
        md.push('\n');
        for (g, runs) in rows {
            row(&mut md, &mut csv, g, runs, steps, groups, reference);
        }
    }
    let _ = write!(
        md,
        "\nMean skill coverage over a group's runs at each step count: a run's value is its last \
         evaluation at or before that count, held until the next (how SPEC §6.1 reads the \
         authors' curve{}). Mean over training: the area under a run's held curve divided by the \
         steps it spans, mean ± sample standard deviation over the runs, with the one-sided \
         Mann–Whitney test that it is lower than `{}`'s (SciPy's p and the exact permutation p; \
         **bold**: both below 0.01).\n",
        if long_table {
            "; groups whose runs train 5·10⁶ steps or more, the arms, at 10⁶ to 10⁷ steps"
        } else {
            ""
        },
        reference.unwrap_or("-")
    );
    Some((md, csv))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn coverage_is_held_until_the_next_evaluation() {
        let curve = [(100, 0.0), (10_000, 5.0), (30_000, 20.0), (60_000, 24.0)];
        assert_eq!(coverage_at(&curve, 50), None);
        assert_eq!(coverage_at(&curve, 20_000), Some(5.0));
        assert_eq!(coverage_at(&curve, 30_000), Some(20.0));
        assert_eq!(coverage_at(&curve, 150_000), Some(24.0));
    }

    #[test]
    fn long_runs_are_read_at_the_arms_step_counts() {
        let cursor = vec![vec![(100, 0.0), (500_000, 24.0)]];
        let arm = vec![vec![(10_000, 0.0), (2_000_000, 20.0), (10_000_032, 24.0)]];
        assert_eq!(steps_for(&cursor), &STEPS);
        assert_eq!(steps_for(&arm), &LONG_STEPS);
        // The arm's held curve at 10⁶, 2.5·10⁶, 5·10⁶ and 10⁷ steps.
        let at: Vec<Option<f64>> = LONG_STEPS
            .iter()
            .map(|&s| coverage_at(&arm[0], s))
            .collect();
        assert_eq!(at, [Some(0.0), Some(20.0), Some(20.0), Some(20.0)]);
    }

    #[test]
    fn the_mean_over_training_is_the_held_area_by_hand() {
        // 0 over 100..10,000, 5 over 10,000..30,000, 20 over 30,000..60,000:
        // (0·9,900 + 5·20,000 + 20·30,000) / 59,900 = 700,000 / 59,900.
        let curve = [(100, 0.0), (10_000, 5.0), (30_000, 20.0), (60_000, 24.0)];
        let mean = mean_over_training(&curve).unwrap();
        assert!((mean - 700_000.0 / 59_900.0).abs() < 1e-12, "{mean}");
        assert_eq!(mean_over_training(&curve[..1]), None);
    }
}
