//! The report's tables, as Markdown for `report.md` and as CSV: final skill coverage with the
//! Mann–Whitney test against the reference (Table 1), final task success per depth, and the
//! median skill and solution lengths.

use std::collections::BTreeMap;
use std::fmt::Write as _;

use seads_planner::{DEFAULT_MAX_EXPANDED, DepthResult, STANDARD_BOARDS};

use super::csv_field;
use super::runs::{Group, RunData};
use super::stats::{Summary, Test, cohens_d, median, summary, worse_than};
use seads_planner::EvaluationKind as Mode;

/// One cell of Table 1.
pub struct CoverageCell {
    /// Environment.
    pub env: String,
    /// Variant.
    pub variant: String,
    /// Final coverage over the runs.
    pub summary: Summary,
    /// Skills K of the runs.
    pub skills: usize,
    /// The test against the reference (none for the reference itself).
    pub test: Option<Test>,
    /// Cohen's d against the reference (none for the reference itself, or where undefined).
    pub d: Option<f64>,
}

/// Skills of a run: the configured K, or the game's moves.
pub fn skills(run: &RunData) -> usize {
    run.skills
}

/// The cells of Table 1, in group order.
pub fn coverage_cells(groups: &[Group<'_>], reference: Option<&str>) -> Vec<CoverageCell> {
    let finals =
        |g: &Group<'_>| -> Vec<f64> { g.runs.iter().filter_map(|r| r.final_coverage()).collect() };
    groups
        .iter()
        .filter_map(|g| {
            let values = finals(g);
            let summary = summary(&values)?;
            let reference_values = reference
                .filter(|r| *r != g.variant)
                .and_then(|r| groups.iter().find(|o| o.env == g.env && o.variant == r))
                .map(finals);
            let test = reference_values
                .as_deref()
                .and_then(|r| worse_than(&values, r));
            let d = reference_values
                .as_deref()
                .and_then(super::stats::summary)
                .and_then(|r| cohens_d(&summary, &r));
            Some(CoverageCell {
                env: g.env.clone(),
                variant: g.variant.clone(),
                summary,
                skills: skills(g.runs[0]),
                test,
                d,
            })
        })
        .collect()
}

/// In order of first appearance.
fn ordered<'a>(items: impl Iterator<Item = &'a str>) -> Vec<&'a str> {
    let mut out: Vec<&str> = Vec::new();
    for item in items {
        if !out.contains(&item) {
            out.push(item);
        }
    }
    out
}

/// Table 1 in Markdown: a row per variant, a column per environment.
pub fn coverage_markdown(cells: &[CoverageCell], reference: Option<&str>) -> String {
    let envs = ordered(cells.iter().map(|c| c.env.as_str()));
    let variants = ordered(cells.iter().map(|c| c.variant.as_str()));
    let mut md = String::from("| variant |");
    for env in &envs {
        let k = cells.iter().find(|c| c.env == *env).map_or(0, |c| c.skills);
        let _ = write!(md, " {env} (of {k}) |");
    }
    md += "\n|---|";
    md += &"---|".repeat(envs.len());
    md.push('\n');
    for variant in &variants {
        let _ = write!(md, "| {variant} |");
        for env in &envs {
            match cells
                .iter()
                .find(|c| c.env == *env && c.variant == *variant)
            {
                None => md += " – |",
                Some(c) => {
                    let value = format!("{:.2} ± {:.2}", c.summary.mean, c.summary.std);
                    let value = if c.test.is_some_and(|t| t.significant()) {
                        format!("**{value}**")
                    } else {
                        value
                    };
                    let test = c.test.map_or(String::new(), |t| {
                        let out_of_reach = if t.can_be_significant() { "" } else { " †" };
                        format!("; {}{out_of_reach}", t.shown())
                    });
                    let _ = write!(md, " {value} (n = {}{test}) |", c.summary.n);
                }
            }
        }
        md.push('\n');
    }
    let _ = write!(
        md,
        "\nMean ± sample standard deviation of the skill coverage at the end of training (distinct game \
         moves of the K skills, mean over 20 test initialisations). U and p: one-sided Mann–Whitney U \
         test that the variant is worse than `{}` (SciPy's `mannwhitneyu(variant, reference, \
         alternative=\"less\")`: exact without ties for up to 8 values, tie-corrected normal otherwise), \
         and its exact permutation p with ties kept (SciPy's `permutation_test`; alone where SciPy's \
         normal approximation falls below the smallest p the run counts allow); **bold**: both p < 0.01. \
         †: p < 0.01 is out of reach with so few runs, whatever they give: the smallest exact p of n₁ \
         runs against n₂ is 1 / C(n₁ + n₂, n₁) (3 against 3: 0.05; 5 against 5: 0.004); compare \
         effect sizes instead (Cliff's δ and Cohen's d in `table1.csv`; beside the paper's below, \
         where it has the cell).\n",
        reference.unwrap_or("-")
    );
    md
}

/// Table 1 as CSV.
pub fn coverage_csv(cells: &[CoverageCell]) -> String {
    let mut csv = String::from(
        "env,variant,skills,n,mean,std,min,max,u,p,p_exact,significantly_worse,min_p,cliffs_delta,cohens_d\n",
    );
    for c in cells {
        let s = &c.summary;
        let (u, p, p_exact, sig, min_p, delta) = c.test.map_or(Default::default(), |t| {
            (
                t.u.to_string(),
                format!("{:.6}", t.p),
                format!("{:.6}", t.p_exact),
                t.significant().to_string(),
                format!("{:.6}", t.min_p),
                format!("{:.4}", t.delta),
            )
        });
        let d = c.d.map_or(String::new(), |d| format!("{d:.4}"));
        let _ = writeln!(
            csv,
            "{},{},{},{},{:.4},{:.4},{:.4},{:.4},{u},{p},{p_exact},{sig},{min_p},{delta},{d}",
            csv_field(&c.env),
            csv_field(&c.variant),
            c.skills,
            s.n,
            s.mean,
            s.std,
            s.min,
            s.max
        );
    }
    csv
}

/// How a table names an evaluation.
fn label(mode: Mode) -> &'static str {
    match mode {
        Mode::Replan => "re-planning",
        Mode::PlanOnce => "plan once",
        Mode::Policy => "policy",
    }
}

/// The final evaluation of a run in one mode.
fn evaluation(run: &RunData, mode: Mode) -> Option<&Vec<DepthResult>> {
    match mode {
        Mode::Replan => run.replan.as_ref(),
        Mode::PlanOnce => run.plan_once.as_ref(),
        Mode::Policy => run.policy.as_ref(),
    }
}

/// The protocol of a run's final evaluation in one mode, in a few words (`standard`, or how it
/// departs from the standard one).
fn protocol(run: &RunData, mode: Mode) -> &str {
    let index = match mode {
        Mode::Replan => 0,
        Mode::PlanOnce => 1,
        Mode::Policy => 2,
    };
    run.success_protocols[index]
        .as_deref()
        .unwrap_or("standard")
}

/// The run's final evaluation in one mode planning with a fitted model, with its protocol's
/// label.
fn fitted(run: &RunData, mode: Mode) -> Option<(&Vec<DepthResult>, &str)> {
    let index = match mode {
        Mode::Replan => 0,
        Mode::PlanOnce => 1,
        Mode::Policy => return None,
    };
    run.fitted[index]
        .as_ref()
        .map(|(results, label)| (results, label.as_str()))
}

/// Depths evaluated in a group.
fn depths(groups: &[Group<'_>]) -> Vec<usize> {
    let mut depths: Vec<usize> = groups
        .iter()
        .flat_map(|g| g.runs.iter())
        .flat_map(|r| {
            r.replan
                .iter()
                .chain(&r.plan_once)
                .chain(&r.policy)
                .chain(r.fitted.iter().flatten().map(|(e, _)| e))
        })
        .flat_map(|e| e.iter().map(|d| d.depth))
        .collect();
    depths.sort_unstable();
    depths.dedup();
    depths
}

/// Task success under action noise beside the same runs' success without it, per group, noise
/// and mode (Markdown and CSV); `None` if no run was evaluated under noise.
pub fn noise_tables(groups: &[Group<'_>]) -> Option<(String, String)> {
    let depths = depths(groups);
    let mut md = String::from("| environment | variant | mode | σ | runs |");
    for d in &depths {
        let _ = write!(md, " depth {d} |");
    }
    md += " all |\n|---|---|---|---|---|";
    md += &"---|".repeat(depths.len() + 1);
    md.push('\n');
    let mut csv = String::from("env,variant,mode,noise,runs,depth,mean_success,std_success\n");
    let mut any = false;
    for g in groups {
        let mut keys: Vec<(f64, bool)> = g
            .runs
            .iter()
            .flat_map(|r| r.noisy.iter().map(|(s, replan, _)| (*s, *replan)))
            .collect();
        keys.sort_by(|a, b| a.0.total_cmp(&b.0).then(b.1.cmp(&a.1)));
        keys.dedup();
        for (std, replan) in keys {
            // The runs evaluated under this noise, each with its noiseless evaluation.
            let pairs: Vec<(&Vec<DepthResult>, &Vec<DepthResult>)> = g
                .runs
                .iter()
                .filter_map(|r| {
                    let noisy = r
                        .noisy
                        .iter()
                        .find(|(s, p, _)| *s == std && *p == replan)
                        .map(|(_, _, e)| e)?;
                    let plain = if replan {
                        r.replan.as_ref()
                    } else {
                        r.plan_once.as_ref()
                    }?;
                    Some((plain, noisy))
                })
                .collect();
            if pairs.is_empty() {
                continue;
            }
            any = true;
            let mode = label(if replan { Mode::Replan } else { Mode::PlanOnce });
            for (sigma, pick) in [(0.0, 0usize), (std, 1)] {
                let _ = write!(
                    md,
                    "| {} | {} | {mode} | {sigma} | {} |",
                    g.env,
                    g.variant,
                    pairs.len()
                );
                let evaluations: Vec<&Vec<DepthResult>> = pairs
                    .iter()
                    .map(|p| if pick == 0 { p.0 } else { p.1 })
                    .collect();
                let row = format!(
                    "{},{},{mode},{sigma}",
                    csv_field(&g.env),
                    csv_field(&g.variant)
                );
                let all = depth_cells(&mut md, &mut csv, &row, &depths, &evaluations);
                match summary(&all) {
                    Some(s) => {
                        let _ = writeln!(md, " {:.1} % |", 100.0 * s.mean);
                    }
                    None => md += " – |\n",
                }
            }
        }
    }
    md += "\nShare of the same test boards solved at the end of training without (σ = 0) and with \
           Gaussian noise of standard deviation σ on every low-level action (`seads evaluate \
           --action-noise`), mean over the runs evaluated both ways.\n";
    any.then_some((md, csv))
}

/// One table row's success cells, a depth each: the mean over `evaluations` of each one's success
/// rate at that depth in Markdown (`–` where none has the depth), and a CSV line `row,runs,depth,
/// mean,std`. Returns every rate it counted, for a row's total.
fn depth_cells(
    md: &mut String,
    csv: &mut String,
    row: &str,
    depths: &[usize],
    evaluations: &[&Vec<DepthResult>],
) -> Vec<f64> {
    let mut all = Vec::new();
    for d in depths {
        let rates: Vec<f64> = evaluations
            .iter()
            .filter_map(|e| e.iter().find(|r| r.depth == *d))
            .map(DepthResult::success_rate)
            .collect();
        match summary(&rates) {
            Some(s) => {
                let _ = write!(md, " {:.1} % |", 100.0 * s.mean);
                let _ = writeln!(csv, "{row},{},{d},{:.4},{:.4}", s.n, s.mean, s.std);
            }
            None => *md += " – |",
        }
        all.extend(rates);
    }
    all
}

/// Final task success per depth (mean over runs of each run's success rate), Markdown and CSV:
/// one row per group, mode and evaluation protocol, so that runs evaluated under other boards or
/// limits are never pooled with, or taken for, the standard evaluation.
pub fn success_tables(groups: &[Group<'_>]) -> (String, String) {
    let depths = depths(groups);
    let mut md = String::from("| environment | variant | mode | protocol | runs |");
    for d in &depths {
        let _ = write!(md, " depth {d} |");
    }
    md += "\n|---|---|---|---|---|";
    md += &"---|".repeat(depths.len());
    md.push('\n');
    let mut csv = String::from("env,variant,mode,protocol,runs,depth,mean_success,std_success\n");
    let mut other_protocols = false;
    for g in groups {
        for mode in [Mode::Replan, Mode::PlanOnce, Mode::Policy] {
            let mut by_protocol: BTreeMap<&str, Vec<&Vec<DepthResult>>> = BTreeMap::new();
            for run in &g.runs {
                if let Some(e) = evaluation(run, mode) {
                    by_protocol.entry(protocol(run, mode)).or_default().push(e);
                }
                if let Some((e, label)) = fitted(run, mode) {
                    by_protocol.entry(label).or_default().push(e);
                }
            }
            for (protocol, evaluated) in by_protocol {
                other_protocols |= protocol != "standard";
                let mode = label(mode);
                let _ = write!(
                    md,
                    "| {} | {} | {mode} | {protocol} | {} |",
                    g.env,
                    g.variant,
                    evaluated.len()
                );
                let row = format!(
                    "{},{},{mode},{}",
                    csv_field(&g.env),
                    csv_field(&g.variant),
                    csv_field(protocol)
                );
                depth_cells(&mut md, &mut csv, &row, &depths, &evaluated);
                md.push('\n');
            }
        }
    }
    let _ = writeln!(
        md,
        "\nShare of test boards solved at the end of training, per solution depth, mean over the \
         runs. The standard protocol: {STANDARD_BOARDS} test boards per depth and run (the authors' \
         seeds), each search bounded by {DEFAULT_MAX_EXPANDED} expanded states without a clock, \
         the most likely plan, breadth-first."
    );
    if other_protocols {
        md += "Another protocol is named by how it departs from the standard one (`boards-N`, \
               `expanded-N` or `unbounded`, `timeout-Ns`, the plan choice, `both-ends`, \
               `memory-NNmib`, `fitted-model` for planning with a forward model fitted to the \
               run's frozen skills afterwards; `not recorded` for a record older than \
               protocols); runs of different protocols are never pooled in one row.\n";
    }
    let timeouts: usize = groups
        .iter()
        .flat_map(|g| g.runs.iter())
        .flat_map(|r| r.replan.iter().chain(&r.plan_once).chain(&r.policy))
        .flat_map(|e| e.iter().map(|d| d.timeouts))
        .sum();
    if timeouts > 0 {
        let _ = writeln!(
            md,
            "{timeouts} task(s) ended at the search time limit: their outcome depends on the \
             machine's speed."
        );
    }
    (md, csv)
}

/// The forward models fitted to the runs' frozen skills (`seads fit-model`), per group: how often
/// the model's most likely successor is the board a held-out execution left, the mean held-out
/// log-likelihood, and how many executions changed the board (mean ± std over the runs);
/// `None` if no run has one.
pub fn fit_table(groups: &[Group<'_>]) -> Option<String> {
    let mut md = String::from(
        "| environment | variant | runs | most likely successor right | log-likelihood (nats) | \
         executions that changed the board |\n|---|---|---|---|---|---|\n",
    );
    let mut any = false;
    for g in groups {
        let fits: Vec<_> = g.runs.iter().filter_map(|r| r.fit).collect();
        let (Some(right), Some(ll), Some(changed)) = (
            summary(
                &fits
                    .iter()
                    .map(|f| 100.0 * f.mode_accuracy)
                    .collect::<Vec<_>>(),
            ),
            summary(&fits.iter().map(|f| f.log_likelihood).collect::<Vec<_>>()),
            summary(&fits.iter().map(|f| 100.0 * f.changed).collect::<Vec<_>>()),
        ) else {
            continue;
        };
        any = true;
        let _ = writeln!(
            md,
            "| {} | {} | {} | {:.1} ± {:.1} % | {:.3} ± {:.3} | {:.1} ± {:.1} % |",
            g.env,
            g.variant,
            right.n,
            right.mean,
            right.std,
            ll.mean,
            ll.std,
            changed.mean,
            changed.std
        );
    }
    let _ = writeln!(
        md,
        "\nSEADS's forward model (the environment's preset), fitted after training to executions of \
         each run's frozen skills from training boards; measured on the tenth of them held out. \
         The rows `fitted-model` of the task-success table plan with these models."
    );
    any.then_some(md)
}

/// A run's final task success over all depths, in the mode it is compared in: SEADS with
/// re-planning, a baseline's policy alone.
fn pooled_success(run: &RunData) -> Option<(Mode, f64)> {
    let (mode, results) = match (&run.replan, &run.policy) {
        (Some(r), _) => (Mode::Replan, r),
        (None, Some(p)) => (Mode::Policy, p),
        (None, None) => return None,
    };
    Some((mode, solved_share(results)))
}

/// The share of all tasks solved over an evaluation's depths (0 for none).
pub(super) fn solved_share(results: &[DepthResult]) -> f64 {
    let (solved, tasks) = results
        .iter()
        .fold((0, 0), |(s, t), d| (s + d.solved, t + d.tasks));
    solved as f64 / tasks.max(1) as f64
}

/// SEADS against the baselines on task success (the paper's Fig. 3 at the end of training):
/// each run's share of solved test tasks over all depths, tested against the reference with
/// the one-sided Mann–Whitney U test. `None` when no baseline was evaluated (a Table 1 study).
pub fn success_comparison(groups: &[Group<'_>], reference: Option<&str>) -> Option<String> {
    let values = |g: &Group<'_>| -> (Vec<f64>, Option<Mode>) {
        let pooled: Vec<(Mode, f64)> = g.runs.iter().filter_map(|r| pooled_success(r)).collect();
        (
            pooled.iter().map(|p| p.1).collect(),
            pooled.first().map(|p| p.0),
        )
    };
    if !groups
        .iter()
        .any(|g| g.runs.iter().any(|r| r.policy.is_some()))
    {
        return None;
    }
    let mut md = String::from(
        "| environment | variant | mode | runs | solved (all depths) | test against the reference |\n|---|---|---|---|---|---|\n",
    );
    for g in groups {
        let (v, mode) = values(g);
        let (Some(s), Some(mode)) = (summary(&v), mode) else {
            continue;
        };
        let test = reference
            .filter(|r| *r != g.variant)
            .and_then(|r| groups.iter().find(|o| o.env == g.env && o.variant == r))
            .and_then(|o| worse_than(&v, &values(o).0));
        let value = format!("{:.1} ± {:.1} %", 100.0 * s.mean, 100.0 * s.std);
        let (value, test) = match test {
            Some(t) if t.significant() => (format!("**{value}**"), t.shown()),
            Some(t) => (value, t.shown()),
            None => (value, String::from("–")),
        };
        let _ = writeln!(
            md,
            "| {} | {} | {} | {} | {value} | {test} |",
            g.env,
            g.variant,
            label(mode),
            s.n
        );
    }
    let _ = write!(
        md,
        "\nShare of all test tasks (every depth) solved at the end of training, mean ± sample \
         standard deviation over the runs; SEADS with re-planning, a baseline's policy acting alone. \
         U and p: one-sided Mann–Whitney U test that the variant solves less than `{}` (SciPy's p, \
         and the exact permutation p with ties kept); **bold**: both p < 0.01.\n",
        reference.unwrap_or("-")
    );
    Some(md)
}

/// The metrics the interval estimates are given for: each run's final skill coverage, its share
/// of all test tasks solved at the end of training (SEADS with re-planning, a baseline's policy
/// acting alone, as [`success_comparison`] compares them), and the same with re-planning by a
/// forward model fitted to its frozen skills (`seads fit-model`).
fn interval_metrics(g: &Group<'_>) -> [(&'static str, Vec<f64>); 3] {
    [
        (
            "coverage",
            g.runs.iter().filter_map(|r| r.final_coverage()).collect(),
        ),
        (
            "success",
            g.runs
                .iter()
                .filter_map(|r| pooled_success(r).map(|p| p.1))
                .collect(),
        ),
        (
            "success, fitted model",
            g.runs
                .iter()
                .filter_map(|r| fitted(r, Mode::Replan).map(|(e, _)| solved_share(e)))
                .collect(),
        ),
    ]
}

/// Interval estimates per cell and metric, runs the unit (`intervals`): the IQM and the mean,
/// each with its bootstrap 95 % confidence interval, and the probability that a run of the
/// variant scores higher than a run of the reference, with its interval; Markdown and CSV.
/// `None` when no group has a value.
pub fn interval_tables(groups: &[Group<'_>], reference: Option<&str>) -> Option<(String, String)> {
    use super::intervals::{bootstrap, improvement_interval, iqm, mean};
    let mut md = format!(
        "| environment | variant | metric | runs | IQM [95 % CI] | mean [95 % CI] | \
         P(run > {} run) [95 % CI] |\n|---|---|---|---|---|---|---|\n",
        reference.unwrap_or("reference")
    );
    let mut csv = String::from(
        "env,variant,metric,runs,iqm,iqm_low,iqm_high,mean,mean_low,mean_high,\
         improvement,improvement_low,improvement_high\n",
    );
    let mut any = false;
    for g in groups {
        // The reference's values of each metric, once per group.
        let reference_metrics = reference
            .filter(|r| *r != g.variant)
            .and_then(|r| groups.iter().find(|o| o.env == g.env && o.variant == r))
            .map(interval_metrics);
        for (i, (metric, values)) in interval_metrics(g).into_iter().enumerate() {
            let key = |what: &str| format!("{what}/{}/{}/{metric}", g.env, g.variant);
            let (Some(q), Some(m)) = (
                bootstrap(&values, iqm, &key("iqm")),
                bootstrap(&values, |v| Some(mean(v)), &key("mean")),
            ) else {
                continue;
            };
            any = true;
            // Success in percent, coverage in moves.
            let (scale, digits) = if metric == "coverage" {
                (1.0, 2)
            } else {
                (100.0, 1)
            };
            let scaled = |i: super::intervals::Interval| super::intervals::Interval {
                estimate: scale * i.estimate,
                low: scale * i.low,
                high: scale * i.high,
            };
            let improvement = reference_metrics
                .as_ref()
                .and_then(|r| improvement_interval(&values, &r[i].1, &key("improvement")));
            let _ = writeln!(
                md,
                "| {} | {} | {metric}{} | {} | {} | {} | {} |",
                g.env,
                g.variant,
                if metric == "coverage" { "" } else { " (%)" },
                values.len(),
                scaled(q).show(digits),
                scaled(m).show(digits),
                improvement.map_or("–".to_owned(), |p| p.show(2))
            );
            let number = |v: Option<f64>| v.map_or(String::new(), |v| format!("{v:.6}"));
            let _ = writeln!(
                csv,
                "{},{},{},{},{},{},{},{},{},{},{},{},{}",
                csv_field(&g.env),
                csv_field(&g.variant),
                csv_field(metric),
                values.len(),
                number(Some(q.estimate)),
                number(Some(q.low)),
                number(Some(q.high)),
                number(Some(m.estimate)),
                number(Some(m.low)),
                number(Some(m.high)),
                number(improvement.map(|p| p.estimate)),
                number(improvement.map(|p| p.low)),
                number(improvement.map(|p| p.high)),
            );
        }
    }
    let _ = write!(
        md,
        "\nA run is the unit: its final skill coverage (distinct moves), and its share of all test \
         tasks solved at the end of training (SEADS with re-planning, a baseline's policy alone; \
         with a fitted model: re-planning with SEADS's forward model fitted to the frozen skills). \
         IQM: the mean of the middle half of the runs (a quarter cut from each end, as rliable \
         computes it). Intervals: percentile bootstrap over the runs, {} resamples, seeded, so a \
         report repeats exactly; with 3 or 5 runs they are wide and coarse. P(run > reference \
         run): the probability that a run of the variant scores higher than one of `{}`, ties \
         counting half (0.5: no difference), the two groups resampled independently. The \
         Mann–Whitney tests above and below stay the paper's tests.\n",
        super::intervals::RESAMPLES,
        reference.unwrap_or("-")
    );
    any.then_some((md, csv))
}

/// Median skill length and median solution length (manipulator steps, solved tasks, with
/// re-planning), pooled over the runs of a group; Markdown and CSV.
pub fn length_tables(groups: &[Group<'_>]) -> (String, String) {
    let depths = depths(groups);
    let mut md = String::from("| environment | variant | median skill length |");
    for d in &depths {
        let _ = write!(md, " solution, depth {d} |");
    }
    md += "\n|---|---|---|";
    md += &"---|".repeat(depths.len());
    md.push('\n');
    let mut csv =
        String::from("env,variant,depth,solved,median_skill_steps,median_solution_steps\n");
    let fmt = |v: Option<f64>| v.map_or("–".to_owned(), |x| format!("{x:.1}"));
    for g in groups {
        let evaluated: Vec<&Vec<DepthResult>> =
            g.runs.iter().filter_map(|r| r.replan.as_ref()).collect();
        if evaluated.is_empty() {
            continue;
        }
        let all_skills: Vec<f64> = evaluated
            .iter()
            .flat_map(|e| {
                e.iter()
                    .flat_map(|r| r.skill_steps.iter().map(|&s| s as f64))
            })
            .collect();
        let _ = write!(
            md,
            "| {} | {} | {} |",
            g.env,
            g.variant,
            fmt(median(&all_skills))
        );
        for d in &depths {
            let at = |f: &dyn Fn(&DepthResult) -> Vec<f64>| -> Vec<f64> {
                evaluated
                    .iter()
                    .filter_map(|e| e.iter().find(|r| r.depth == *d))
                    .flat_map(f)
                    .collect()
            };
            let solutions = at(&|r| r.solution_steps.iter().map(|&s| s as f64).collect());
            let skills = at(&|r| r.skill_steps.iter().map(|&s| s as f64).collect());
            let _ = write!(md, " {} |", fmt(median(&solutions)));
            let _ = writeln!(
                csv,
                "{},{},{d},{},{},{}",
                csv_field(&g.env),
                csv_field(&g.variant),
                solutions.len(),
                median(&skills).map_or(String::new(), |v| v.to_string()),
                median(&solutions).map_or(String::new(), |v| v.to_string())
            );
        }
        md.push('\n');
    }
    md += "\nMedians in manipulator steps over the solved tasks of all runs, with re-planning (the seed's \
           Figs. S.5, S.6 show their distributions; see the box plots).\n";
    (md, csv)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::report::runs::bare_run;

    /// Results of one depth: `solved` of 20.
    fn depth(d: usize, solved: usize) -> DepthResult {
        DepthResult {
            tasks: 20,
            solved,
            ..DepthResult::new(d)
        }
    }

    /// By hand: without noise both runs solve 20/20 at depth 1 and 18/20, 20/20 at depth 2 (95 %);
    /// under σ = 0.05 they solve 10/20 and 20/20 (75 %), 9/20 and 11/20 (50 %); over both depths
    /// 97.5 % and 62.5 %. A run without a noisy evaluation is left out of its row.
    #[test]
    fn noise_rows_compare_the_same_runs_with_and_without_noise() {
        let mut a = bare_run(1);
        a.replan = Some(vec![depth(1, 20), depth(2, 18)]);
        a.noisy = vec![(0.05, true, vec![depth(1, 10), depth(2, 9)])];
        let mut b = bare_run(2);
        b.replan = Some(vec![depth(1, 20), depth(2, 20)]);
        b.noisy = vec![(0.05, true, vec![depth(1, 20), depth(2, 11)])];
        let mut c = bare_run(3);
        c.replan = Some(vec![depth(1, 0), depth(2, 0)]);
        let runs = [a, b, c];
        let group = Group {
            env: "lightsout-cursor".into(),
            variant: "seads".into(),
            runs: runs.iter().collect(),
        };
        let (md, csv) = noise_tables(&[group]).expect("noisy runs");
        assert!(
            md.contains(
                "| lightsout-cursor | seads | re-planning | 0 | 2 | 100.0 % | 95.0 % | 97.5 % |"
            ),
            "{md}"
        );
        assert!(
            md.contains(
                "| lightsout-cursor | seads | re-planning | 0.05 | 2 | 75.0 % | 50.0 % | 62.5 % |"
            ),
            "{md}"
        );
        assert_eq!(csv.lines().count(), 5, "{csv}");
        assert!(
            noise_tables(&[Group {
                env: "x".into(),
                variant: "y".into(),
                runs: vec![&runs[2]],
            }])
            .is_none()
        );
    }

    /// The fitted models' table, by hand: two runs whose models are right 90 % and 70 % of the
    /// time give 80.0 ± 14.1 % (the sample std of 90 and 70); a group without fits has no row,
    /// and no fits at all no table.
    #[test]
    fn fitted_models_are_summarised_per_group() {
        let fit = |mode_accuracy, log_likelihood| seads_run::fitted::FitQuality {
            held_out: 10,
            log_likelihood,
            mode_accuracy,
            changed: 1.0,
        };
        let mut a = bare_run(1);
        a.fit = Some(fit(0.9, -1.0));
        let mut b = bare_run(2);
        b.fit = Some(fit(0.7, -3.0));
        let c = bare_run(3);
        let (fitted, bare) = ([a, b], [c]);
        let groups = [("diayn", &fitted[..]), ("seads", &bare[..])].map(|(variant, runs)| Group {
            env: "lightsout-cursor".into(),
            variant: variant.into(),
            runs: runs.iter().collect(),
        });
        let md = fit_table(&groups).unwrap();
        assert!(
            md.contains(
                "| lightsout-cursor | diayn | 2 | 80.0 ± 14.1 % | -2.000 ± 1.414 | 100.0 ± 0.0 % |"
            ),
            "{md}"
        );
        assert!(!md.contains("| seads |"), "{md}");
        assert!(fit_table(&groups[1..]).is_none());
    }

    /// Runs evaluated under different protocols are never pooled (issue 82: an evaluation of 2
    /// boards with a 1-state limit sat beside the standard ones under a caption saying "20 boards
    /// per depth"): one row per protocol, each named, by hand: the standard runs solve 20/20 and
    /// 18/20 (95 %), the other 0/2.
    #[test]
    fn success_rows_are_one_per_protocol_and_name_it() {
        let mut a = bare_run(1);
        a.replan = Some(vec![depth(1, 20)]);
        let mut b = bare_run(2);
        b.replan = Some(vec![depth(1, 18)]);
        let mut c = bare_run(3);
        c.replan = Some(vec![DepthResult {
            tasks: 2,
            solved: 0,
            ..DepthResult::new(1)
        }]);
        c.success_protocols[0] = Some("boards-2, expanded-1".into());
        for run in [&mut a, &mut b] {
            run.success_protocols[0] = Some("standard".into());
        }
        let runs = [a, b, c];
        let group = Group {
            env: "lightsout-cursor".into(),
            variant: "seads".into(),
            runs: runs.iter().collect(),
        };
        let (md, csv) = success_tables(&[group]);
        assert!(
            md.contains("| lightsout-cursor | seads | re-planning | standard | 2 | 95.0 % |"),
            "{md}"
        );
        assert!(
            md.contains(
                "| lightsout-cursor | seads | re-planning | boards-2, expanded-1 | 1 | 0.0 % |"
            ),
            "{md}"
        );
        assert!(md.contains("never pooled"), "{md}");
        assert!(!md.contains("20 boards per depth and run unless"), "{md}");
        let rows: Vec<&str> = csv.lines().collect();
        assert_eq!(
            rows[0],
            "env,variant,mode,protocol,runs,depth,mean_success,std_success"
        );
        assert!(
            rows.contains(
                &"lightsout-cursor,seads,re-planning,\"boards-2, expanded-1\",1,1,0.0000,0.0000"
            ),
            "{csv}"
        );
    }
}
