//! RESULTS' summary table, generated from the committed runs: each study declares in
//! `docs/results/<study>/claims.toml` which of the paper's numbers (or which of ours beyond the
//! paper) its runs measure, and [`summary_table`] computes every row from the runs under the
//! study's `runs/` folder. No number of the table is typed by hand: the paper's side comes from
//! the claim (or, for a cell of Table 1, from `data/paper/table1.csv`), ours from the runs.
//!
//! A claims file:
//!
//! ```toml
//! order = 10                       # the study's place in the table
//!
//! [[claim]]
//! what = "LightsOutCursor coverage, no relabelling (Table 1)"
//! env = "lightsout-cursor"
//! variants = ["no-relabelling"]     # the runs of these variants form the cell
//! metric = "coverage"
//! against = ["seads"]               # one-sided Mann–Whitney test: the cell is lower
//! # paper = "24.72 ± 0.39"          # the paper's number; for Table 1 cells taken from the data
//! ```

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use serde::Deserialize;

use super::runs::{self, RunData};
use super::stats::{median, summary, worse_than};
use super::tables::solved_share;
use crate::{Context as _, Result, StudyError};
use seads_planner::DepthResult;

/// The file of a study's claims, beside its data.
pub const CLAIMS: &str = "claims.toml";

/// The lines around the generated table in RESULTS.
pub const BEGIN: &str = "<!-- The summary below is written by `seads summary`; edit the claims.toml files, not the table. -->";
/// See [`BEGIN`].
pub const END: &str = "<!-- End of the summary written by `seads summary`. -->";

/// What a study claims.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Claims {
    /// Its place in the table (smaller first; ties by folder name).
    pub order: u32,
    /// The folders that hold its sweeps and runs, relative to the study (default `["runs"]`;
    /// a study may rest on another's runs too).
    #[serde(default = "default_runs")]
    pub runs: Vec<PathBuf>,
    /// Its rows.
    #[serde(rename = "claim")]
    pub claims: Vec<Claim>,
}

fn default_runs() -> Vec<PathBuf> {
    vec![PathBuf::from("runs")]
}

/// One row of the summary: a cell of runs and what is measured on it.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Claim {
    /// The row's label.
    pub what: String,
    /// The paper's number as the paper gives it; `None`: from the paper's Table 1 for a
    /// coverage claim on one of its cells, else "–" (not in the paper).
    #[serde(default)]
    pub paper: Option<String>,
    /// Environment of the runs.
    pub env: String,
    /// The variants whose finished runs form the cell (a run outside a sweep is named by its
    /// directory).
    pub variants: Vec<String>,
    /// What is measured.
    pub metric: Metric,
    /// A cell of the same environment to test against (one-sided Mann–Whitney U: this cell is
    /// lower), for the metrics measured once per run.
    #[serde(default)]
    pub against: Option<Vec<String>>,
    /// Step counts, for [`Metric::CoverageAt`].
    #[serde(default)]
    pub steps: Vec<u64>,
    /// Action noise σ, for [`Metric::NoisyReplan`] and [`Metric::NoisyPlanOnce`].
    #[serde(default)]
    pub sigma: Option<f64>,
    /// Instead of runs: a folder, relative to the study, whose subfolders each hold one
    /// agent's `evaluation-replan.json` (evaluations of agents whose training lies elsewhere),
    /// for [`Metric::SuccessReplan`] only.
    #[serde(default)]
    pub evaluations: Option<PathBuf>,
}

/// What a claim measures.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Metric {
    /// Skill coverage at the end of training, per run.
    Coverage,
    /// Mean skill coverage over training (the held curve's area over its steps), per run.
    CoverageOverTraining,
    /// The cell's mean coverage at each of [`Claim::steps`] (each run's last evaluation at or
    /// before the count).
    CoverageAt,
    /// Share of all test tasks solved, per run: SEADS with re-planning, a baseline's policy
    /// acting alone.
    Success,
    /// Share of all test tasks solved with re-planning, per run.
    SuccessReplan,
    /// Share of all test tasks solved planning once, per run.
    SuccessPlanOnce,
    /// Share solved with re-planning by a forward model fitted to the frozen skills, per run.
    SuccessFitted,
    /// Share solved with re-planning under action noise [`Claim::sigma`], per run.
    NoisyReplan,
    /// Share solved planning once under action noise [`Claim::sigma`], per run.
    NoisyPlanOnce,
    /// The deeper search: share of the cell's tasks solved at each of its depths.
    DeepSearch,
    /// The median skill length (manipulator steps) over the cell's solved tasks with
    /// re-planning.
    SkillLength,
}

impl Metric {
    /// Whether it gives one value per run, in percent.
    fn per_run_percent(self) -> bool {
        matches!(
            self,
            Self::Success
                | Self::SuccessReplan
                | Self::SuccessPlanOnce
                | Self::SuccessFitted
                | Self::NoisyReplan
                | Self::NoisyPlanOnce
        )
    }

    /// Whether it gives one value per run.
    fn per_run(self) -> bool {
        self.per_run_percent() || matches!(self, Self::Coverage | Self::CoverageOverTraining)
    }
}

/// A run's value of a per-run metric (`None`: the run lacks it).
fn run_value(run: &RunData, claim: &Claim) -> Option<f64> {
    let share = |results: Option<&Vec<DepthResult>>| results.map(|r| 100.0 * solved_share(r));
    let noisy = |replan: bool| {
        let sigma = claim.sigma?;
        run.noisy
            .iter()
            .find(|(s, r, _)| *r == replan && (s - sigma).abs() < 1e-12)
            .map(|(_, _, results)| 100.0 * solved_share(results))
    };
    match claim.metric {
        Metric::Coverage => run.final_coverage(),
        Metric::CoverageOverTraining => super::curves::mean_over_training(&curve(run)),
        Metric::Success => share(run.replan.as_ref().or(run.policy.as_ref())),
        Metric::SuccessReplan => share(run.replan.as_ref()),
        Metric::SuccessPlanOnce => share(run.plan_once.as_ref()),
        Metric::SuccessFitted => share(run.fitted[0].as_ref().map(|(r, _)| r)),
        Metric::NoisyReplan => noisy(true),
        Metric::NoisyPlanOnce => noisy(false),
        Metric::CoverageAt | Metric::DeepSearch | Metric::SkillLength => None,
    }
}

/// The protocol of the evaluation a run's value of `metric` comes from, in a few words
/// (`standard`, or how it departs from it); `None` for metrics that are not task success of a
/// final evaluation.
fn run_protocol(run: &RunData, metric: Metric) -> Option<&str> {
    let label = |i: usize| run.success_protocols[i].as_deref();
    match metric {
        Metric::Success if run.replan.is_some() => label(0),
        Metric::Success => label(2),
        Metric::SuccessReplan => label(0),
        Metric::SuccessPlanOnce => label(1),
        Metric::SuccessFitted => run.fitted[0].as_ref().map(|(_, l)| l.as_str()),
        _ => None,
    }
}

/// The one protocol of a cell's evaluations for `metric`, as a row says it ("" for the standard
/// one); an error when its runs were evaluated under different protocols, which a row must not
/// pool (as a report never does).
fn cell_protocol(study: &Study, claim: &Claim, runs: &[&RunData]) -> Result<String> {
    let mut labels: Vec<&str> = runs
        .iter()
        .filter_map(|r| run_protocol(r, claim.metric))
        .collect();
    labels.sort_unstable();
    labels.dedup();
    match labels[..] {
        [] | ["standard"] => Ok(String::new()),
        [one] => Ok(format!(" [protocol: {one}]")),
        _ => Err(StudyError::failed(format!(
            "{}: claim {:?}: its runs were evaluated under different protocols ({}), which one row \
             cannot pool",
            study.name,
            claim.what,
            labels.join("; ")
        ))),
    }
}

/// A run's coverage curve: (environment steps, coverage) in the order of training.
fn curve(run: &RunData) -> Vec<(u64, f64)> {
    run.lines
        .iter()
        .filter_map(|m| Some((m.env_steps, m.skill_coverage?)))
        .collect()
}

/// A study's claims file, read and checked.
pub fn read_claims(path: &Path) -> Result<Claims> {
    let text = std::fs::read_to_string(path).doing(|| format!("reading {}", path.display()))?;
    let claims: Claims = toml::from_str(&text)
        .map_err(|e| StudyError::invalid(format!("{}: {}", path.display(), e.message())))?;
    let bad = |what: &str, message: String| {
        StudyError::invalid(format!("{}: claim {what:?}: {message}", path.display()))
    };
    if claims.claims.is_empty() {
        return Err(StudyError::invalid(format!(
            "{}: no [[claim]]",
            path.display()
        )));
    }
    for c in &claims.claims {
        if c.variants.is_empty() && c.evaluations.is_none() {
            return Err(bad(&c.what, "names no variant".into()));
        }
        if c.against.as_ref().is_some_and(|a| a.is_empty()) {
            return Err(bad(&c.what, "tests against no variant".into()));
        }
        if c.against.is_some() && !c.metric.per_run() {
            return Err(bad(
                &c.what,
                format!(
                    "{:?} is not measured per run, so it cannot be tested",
                    c.metric
                ),
            ));
        }
        if (c.metric == Metric::CoverageAt) == c.steps.is_empty() {
            return Err(bad(
                &c.what,
                "`steps` goes with the metric coverage-at, and only with it".into(),
            ));
        }
        if c.evaluations.is_some() && (c.metric != Metric::SuccessReplan || c.against.is_some()) {
            return Err(bad(
                &c.what,
                "`evaluations` goes with the metric success-replan only, untested".into(),
            ));
        }
        let noisy = matches!(c.metric, Metric::NoisyReplan | Metric::NoisyPlanOnce);
        if noisy != c.sigma.is_some() {
            return Err(bad(
                &c.what,
                "`sigma` goes with the metrics noisy-replan and noisy-plan-once, and only with them"
                    .into(),
            ));
        }
    }
    Ok(claims)
}

/// The sweeps and lone runs under `dir`, as a report takes them.
fn inputs(dir: &Path) -> Result<Vec<PathBuf>> {
    let mut found = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        if d.join(crate::sweep::INDEX).is_file() || d.join("config.toml").is_file() {
            found.push(d);
            continue;
        }
        for entry in std::fs::read_dir(&d).doing(|| format!("reading {}", d.display()))? {
            let path = entry.doing(|| format!("reading {}", d.display()))?.path();
            if path.is_dir() {
                stack.push(path);
            }
        }
    }
    found.sort();
    Ok(found)
}

/// Each agent's share of tasks solved (percent) in the `evaluation-replan.json` of each
/// subfolder of `dir`, in the subfolders' order.
fn evaluated_shares(dir: &Path) -> Result<Vec<f64>> {
    let mut agents: Vec<PathBuf> = std::fs::read_dir(dir)
        .doing(|| format!("reading {}", dir.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.is_dir())
        .collect();
    agents.sort();
    let mut shares = Vec::new();
    for agent in agents {
        let file = agent.join("evaluation-replan.json");
        if let Some(record) = crate::evaluation::read_evaluation(&file)? {
            shares.push(100.0 * solved_share(&record.results));
        }
    }
    Ok(shares)
}

/// One study: its folder's name, its claims and its finished runs.
struct Study {
    dir: PathBuf,
    name: String,
    claims: Claims,
    runs: Vec<RunData>,
}

/// The studies under `results` that have a claims file, in their order.
fn studies(results: &Path) -> Result<Vec<Study>> {
    let mut studies = Vec::new();
    for entry in std::fs::read_dir(results).doing(|| format!("reading {}", results.display()))? {
        let dir = entry
            .doing(|| format!("reading {}", results.display()))?
            .path();
        let file = dir.join(CLAIMS);
        if !file.is_file() {
            continue;
        }
        let claims = read_claims(&file)?;
        let mut runs = Vec::new();
        if claims.claims.iter().any(|c| c.evaluations.is_none()) {
            let mut found = Vec::new();
            for runs_dir in &claims.runs {
                found.extend(inputs(&dir.join(runs_dir))?);
            }
            let collection = runs::collect(&found)
                .map_err(|e| StudyError::invalid(format!("{}: {e}", dir.display())))?;
            if let Some((run, why)) = collection.unreadable.first() {
                return Err(StudyError::failed(format!(
                    "{} cannot be read: {why}",
                    run.display()
                )));
            }
            runs = collection.runs;
        }
        let name = dir
            .file_name()
            .map_or_else(String::new, |n| n.to_string_lossy().into_owned());
        studies.push(Study {
            dir,
            name,
            claims,
            runs,
        });
    }
    studies.sort_by(|a, b| (a.claims.order, &a.name).cmp(&(b.claims.order, &b.name)));
    Ok(studies)
}

/// The finished, undamaged runs of a cell.
fn cell<'a>(study: &'a Study, env: &str, variants: &[String]) -> Vec<&'a RunData> {
    study
        .runs
        .iter()
        .filter(|r| r.damage.is_empty() && r.finished())
        .filter(|r| r.config.env == env && variants.contains(&r.variant))
        .collect()
}

/// A number as the table shows it: coverage with 2 decimals, a share in percent with 1.
fn number(value: f64, percent: bool) -> String {
    if percent {
        format!("{value:.1} %")
    } else {
        format!("{value:.2}")
    }
}

/// Mean ± sample std of per-run values, each run's value listed for up to three runs.
fn spread(values: &[f64], percent: bool) -> String {
    let Some(s) = summary(values) else {
        return String::from("–");
    };
    let digits = if percent { 1 } else { 2 };
    let bare = |v: f64| format!("{v:.digits$}");
    let each = || {
        values
            .iter()
            .map(|v| bare(*v))
            .collect::<Vec<_>>()
            .join(", ")
    };
    match s.n {
        1 => number(s.mean, percent),
        2 | 3 => format!("{} ± {} ({})", number(s.mean, percent), bare(s.std), each()),
        _ => format!("{} ± {}", number(s.mean, percent), bare(s.std)),
    }
}

/// The paper's side of a row.
fn paper_side(claim: &Claim, table1: &[super::paper::PaperCell]) -> String {
    if let Some(text) = &claim.paper {
        return text.clone();
    }
    if claim.metric == Metric::Coverage
        && let [variant] = &claim.variants[..]
        && let Some(p) = table1
            .iter()
            .find(|p| p.env == claim.env && p.variant == *variant)
    {
        return format!("{} ± {}", p.summary.mean, p.summary.std);
    }
    String::from("–")
}

/// Our side of a row and the number of runs it rests on.
fn our_side(study: &Study, claim: &Claim) -> Result<(String, usize)> {
    if let Some(folder) = &claim.evaluations {
        let shares = evaluated_shares(&study.dir.join(folder))?;
        if shares.is_empty() {
            return Err(StudyError::failed(format!(
                "{}: claim {:?}: no evaluation-replan.json under {}",
                study.name,
                claim.what,
                folder.display()
            )));
        }
        return Ok((spread(&shares, true), shares.len()));
    }
    let runs = cell(study, &claim.env, &claim.variants);
    if runs.is_empty() {
        return Err(StudyError::failed(format!(
            "{}: claim {:?}: no finished run of {} {:?}",
            study.name, claim.what, claim.env, claim.variants
        )));
    }
    let percent = claim.metric.per_run_percent();
    let text = match claim.metric {
        Metric::CoverageAt => {
            let curves: Vec<Vec<(u64, f64)>> = runs.iter().map(|r| curve(r)).collect();
            claim
                .steps
                .iter()
                .map(|&s| {
                    let at: Vec<f64> = curves
                        .iter()
                        .filter_map(|c| super::curves::coverage_at(c, s))
                        .collect();
                    summary(&at).map_or_else(|| String::from("–"), |m| number(m.mean, false))
                })
                .collect::<Vec<_>>()
                .join(" / ")
        }
        Metric::DeepSearch => {
            let deep: Vec<&Vec<DepthResult>> = runs
                .iter()
                .filter_map(|r| r.deep.as_ref().map(|d| &d.results))
                .collect();
            let mut depths: Vec<usize> = deep
                .iter()
                .flat_map(|d| d.iter().map(|r| r.depth))
                .collect();
            depths.sort_unstable();
            depths.dedup();
            if depths.is_empty() {
                String::from("–")
            } else {
                let shares: Vec<String> = depths
                    .iter()
                    .map(|depth| {
                        let at: Vec<DepthResult> = deep
                            .iter()
                            .filter_map(|d| d.iter().find(|r| r.depth == *depth).cloned())
                            .collect();
                        format!("{:.0}", 100.0 * solved_share(&at))
                    })
                    .collect();
                format!(
                    "{} % at depths {}–{}",
                    shares.join(" / "),
                    depths[0],
                    depths[depths.len() - 1]
                )
            }
        }
        Metric::SkillLength => {
            let steps: Vec<f64> = runs
                .iter()
                .filter_map(|r| r.replan.as_ref())
                .flat_map(|e| {
                    e.iter()
                        .flat_map(|d| d.skill_steps.iter().map(|&s| s as f64))
                })
                .collect();
            median(&steps).map_or_else(|| String::from("–"), |m| format!("{m}"))
        }
        _ => {
            let values: Vec<f64> = runs.iter().filter_map(|r| run_value(r, claim)).collect();
            let mut text = spread(&values, percent) + &cell_protocol(study, claim, &runs)?;
            if let Some(against) = &claim.against {
                let reference: Vec<f64> = cell(study, &claim.env, against)
                    .iter()
                    .filter_map(|r| run_value(r, claim))
                    .collect();
                if reference.is_empty() {
                    return Err(StudyError::failed(format!(
                        "{}: claim {:?}: no finished run of {} {against:?} to test against",
                        study.name, claim.what, claim.env
                    )));
                }
                if let Some(t) = worse_than(&values, &reference) {
                    let reach = if t.can_be_significant() {
                        String::new()
                    } else {
                        format!(
                            "; {:.2} is the least {} against {} runs allow",
                            t.min_p,
                            values.len(),
                            reference.len()
                        )
                    };
                    let against = against.join(", ");
                    let test = format!(
                        "below {against}: {}, Cliff's δ {:.2}{reach}",
                        t.shown(),
                        t.delta
                    );
                    text = if t.significant() {
                        format!("**{text}** ({test})")
                    } else {
                        format!("{text} ({test})")
                    };
                }
            }
            let n = values.len();
            return Ok((text, n));
        }
    };
    Ok((text, runs.len()))
}

/// The summary table of every study under `results` (the folder `docs/results`) that has a
/// claims file, as Markdown, with its notes. Links are relative to the folder above `results`.
pub fn summary_table(results: &Path) -> Result<String> {
    let table1 = super::paper::table1()?;
    let studies = studies(results)?;
    let folder = results.file_name().map_or_else(
        || String::from("results"),
        |n| n.to_string_lossy().into_owned(),
    );
    let mut md = String::from(
        "| the paper's number | paper | ours | runs | study |\n|---|---|---|---|---|\n",
    );
    for study in &studies {
        for claim in &study.claims.claims {
            let (ours, n) = our_side(study, claim)?;
            let _ = writeln!(
                md,
                "| {} | {} | {ours} | {n} | [{}]({folder}/{}/) |",
                claim.what,
                paper_side(claim, &table1),
                study.name,
                study.name
            );
        }
    }
    md += "\nOurs: mean ± sample standard deviation over the runs (each run's value in brackets \
           for up to three runs); coverage in distinct game moves of the skills, task success as \
           the share of all test tasks (depths 1–5 unless a row says otherwise). Where a row \
           tests a cell against another: the one-sided Mann–Whitney U test that it is lower \
           (SciPy's p, and the exact permutation p; only the exact p where SciPy's falls below \
           what the run counts allow), and Cliff's δ; **bold**: both p < 0.01. The paper's \
           Table 1 cells are its mean ± std over 10 agents.\n";
    Ok(md)
}

/// `document` with the text between [`BEGIN`] and [`END`] replaced by `table`; an error when
/// the markers are missing or out of order.
pub fn replace_summary(document: &str, table: &str) -> Result<String> {
    let (Some(begin), Some(end)) = (document.find(BEGIN), document.find(END)) else {
        return Err(StudyError::invalid(format!(
            "the document lacks the lines {BEGIN:?} and {END:?} around its summary"
        )));
    };
    if end < begin {
        return Err(StudyError::invalid(
            "the summary's end marker comes before its begin marker",
        ));
    }
    let head = &document[..begin + BEGIN.len()];
    let tail = &document[end..];
    Ok(format!("{head}\n\n{table}\n{tail}"))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::report::runs::bare_run;
    use seads_run::MetricsRecord;

    fn line(env_steps: u64, coverage: f64) -> MetricsRecord {
        MetricsRecord {
            epoch: env_steps / 100,
            env_steps,
            wall_s: 0.0,
            steps_per_s: 0.0,
            timings: Default::default(),
            skill_coverage: Some(coverage),
            success: None,
            mean_success: None,
        }
    }

    /// A finished run of `variant` whose coverage curve is `curve` (steps, coverage), ending at
    /// the config's budget.
    fn run(seed: u32, variant: &str, curve: &[(u64, f64)]) -> RunData {
        let mut r = bare_run(seed);
        r.variant = variant.into();
        let budget = r.config.env_steps;
        r.lines = curve.iter().map(|&(s, c)| line(s, c)).collect();
        let last = curve.last().map_or(0.0, |c| c.1);
        r.lines.push(line(budget, last));
        r
    }

    fn depth(depth: usize, tasks: usize, solved: usize, skill_steps: Vec<usize>) -> DepthResult {
        let mut d = DepthResult::new(depth);
        d.tasks = tasks;
        d.solved = solved;
        d.skill_steps = skill_steps;
        d
    }

    fn claim(text: &str) -> Claim {
        let claims: Claims = toml::from_str(&format!("order = 1\n[[claim]]\n{text}")).unwrap();
        claims.claims.into_iter().next().unwrap()
    }

    fn study(runs: Vec<RunData>) -> Study {
        Study {
            dir: PathBuf::from("nowhere"),
            name: "test".into(),
            claims: Claims {
                order: 1,
                runs: default_runs(),
                claims: Vec::new(),
            },
            runs,
        }
    }

    const ENV: &str = "env = \"lightsout-cursor\"\n";

    /// Coverage, mean ± sample std with each run's value, and the test against a cell whose
    /// every run is higher: U = 0 and the exact p of 3 against 3, 1/20 (computed by hand).
    #[test]
    fn a_coverage_row_is_the_runs_mean_and_spread_with_its_test() {
        let s = study(vec![
            run(1, "ablated", &[(1000, 24.0)]),
            run(2, "ablated", &[(1000, 25.0)]),
            run(3, "ablated", &[(1000, 23.0)]),
            run(4, "seads", &[(1000, 25.5)]),
            run(5, "seads", &[(1000, 26.0)]),
            run(6, "seads", &[(1000, 25.25)]),
        ]);
        let c = claim(&format!(
            "what = \"x\"\n{ENV}variants = [\"ablated\"]\nmetric = \"coverage\"\nagainst = [\"seads\"]"
        ));
        let (text, n) = our_side(&s, &c).unwrap();
        assert_eq!(n, 3);
        assert!(
            text.starts_with("24.00 ± 1.00 (24.00, 25.00, 23.00) (below seads: U = 0,"),
            "{text}"
        );
        assert!(
            text.contains("exact 0.0500") || text.contains("exact p = 0.0500"),
            "{text}"
        );
        assert!(
            text.contains("0.05 is the least 3 against 3 runs allow"),
            "{text}"
        );
        assert!(
            !text.starts_with("**"),
            "3 against 3 cannot be significant: {text}"
        );
    }

    /// The held curve: each run's last evaluation at or before the step count, averaged.
    #[test]
    fn a_curve_row_holds_each_runs_last_value() {
        let s = study(vec![
            run(1, "seads", &[(100, 10.0), (200, 20.0)]),
            run(2, "seads", &[(100, 12.0), (250, 22.0)]),
        ]);
        let c = claim(&format!(
            "what = \"x\"\n{ENV}variants = [\"seads\"]\nmetric = \"coverage-at\"\nsteps = [150, 200, 300]"
        ));
        // At 150: 10 and 12; at 200: 20 and 12; at 300: 20 and 22.
        assert_eq!(our_side(&s, &c).unwrap().0, "11.00 / 16.00 / 21.00");
    }

    /// Task success pools a run's depths (solved over tasks), in percent per run; the skill
    /// length is the median over every solved task's skills of every run.
    #[test]
    fn success_and_skill_length_rows_count_tasks() {
        let mut a = run(1, "seads", &[(1000, 25.0)]);
        a.replan = Some(vec![
            depth(1, 20, 20, vec![3, 3]),
            depth(2, 20, 10, vec![4]),
        ]);
        let mut b = run(2, "seads", &[(1000, 25.0)]);
        b.replan = Some(vec![
            depth(1, 20, 19, vec![2]),
            depth(2, 20, 20, vec![5, 6]),
        ]);
        let s = study(vec![a, b]);
        let success = claim(&format!(
            "what = \"x\"\n{ENV}variants = [\"seads\"]\nmetric = \"success-replan\""
        ));
        // 30 of 40 = 75 %, 39 of 40 = 97.5 %: mean 86.25, std 15.91.
        assert_eq!(
            our_side(&s, &success).unwrap().0,
            "86.2 % ± 15.9 (75.0, 97.5)"
        );
        let length = claim(&format!(
            "what = \"x\"\n{ENV}variants = [\"seads\"]\nmetric = \"skill-length\""
        ));
        // 2, 3, 3, 4, 5, 6: median 3.5.
        assert_eq!(our_side(&s, &length).unwrap().0, "3.5");
    }

    /// Task success of runs evaluated under different protocols is never pooled in a row; one
    /// protocol other than the standard one is named in the row.
    #[test]
    fn a_row_names_its_protocol_and_never_pools_two() {
        let evaluated = |seed: u32, protocol: &str| {
            let mut r = run(seed, "seads", &[(1000, 25.0)]);
            r.replan = Some(vec![depth(1, 20, 20, vec![3])]);
            r.success_protocols[0] = Some(protocol.into());
            r
        };
        let c = claim(&format!(
            "what = \"x\"\n{ENV}variants = [\"seads\"]\nmetric = \"success-replan\""
        ));
        let same = study(vec![
            evaluated(1, "first-found"),
            evaluated(2, "first-found"),
        ]);
        assert_eq!(
            our_side(&same, &c).unwrap().0,
            "100.0 % ± 0.0 (100.0, 100.0) [protocol: first-found]"
        );
        let standard = study(vec![evaluated(1, "standard")]);
        assert_eq!(our_side(&standard, &c).unwrap().0, "100.0 %");
        let mixed = study(vec![evaluated(1, "standard"), evaluated(2, "first-found")]);
        let e = our_side(&mixed, &c).unwrap_err().to_string();
        assert!(e.contains("different protocols"), "{e}");
    }

    /// A claim on a cell without a finished run is an error, never an empty row.
    #[test]
    fn a_claim_without_runs_is_an_error() {
        let s = study(vec![run(1, "seads", &[(1000, 25.0)])]);
        let c = claim(&format!(
            "what = \"x\"\n{ENV}variants = [\"vic\"]\nmetric = \"coverage\""
        ));
        let e = our_side(&s, &c).unwrap_err().to_string();
        assert!(e.contains("no finished run"), "{e}");
    }

    /// Claims that cannot be computed are refused when read, naming the claim.
    #[test]
    fn inconsistent_claims_are_refused_on_load() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join(CLAIMS);
        for (body, says) in [
            ("variants = []\nmetric = \"coverage\"", "names no variant"),
            ("variants = [\"a\"]\nmetric = \"coverage-at\"", "`steps`"),
            (
                "variants = [\"a\"]\nmetric = \"coverage\"\nsteps = [1]",
                "`steps`",
            ),
            ("variants = [\"a\"]\nmetric = \"noisy-replan\"", "`sigma`"),
            (
                "variants = [\"a\"]\nmetric = \"deep-search\"\nagainst = [\"b\"]",
                "cannot be tested",
            ),
            (
                "variants = [\"a\"]\nmetric = \"coverage\"\nagainst = []",
                "against no variant",
            ),
            (
                "variants = [\"a\"]\nmetric = \"coverage\"\nsurprise = 1",
                "unknown field",
            ),
            ("variants = [\"a\"]\nmetric = \"speed\"", "unknown variant"),
        ] {
            std::fs::write(
                &path,
                format!("order = 1\n[[claim]]\nwhat = \"w\"\n{ENV}{body}\n"),
            )
            .unwrap();
            let e = read_claims(&path).unwrap_err();
            assert!(e.is_invalid(), "{body}: {e}");
            assert!(e.to_string().contains(says), "{body}: {e}");
        }
    }

    /// The table goes between the markers, replacing what was there; text around stays.
    #[test]
    fn the_summary_replaces_the_text_between_its_markers() {
        let document = format!("# R\n\n{BEGIN}\nold\n{END}\n\nafter\n");
        let new = replace_summary(&document, "| t |\n").unwrap();
        assert_eq!(new, format!("# R\n\n{BEGIN}\n\n| t |\n\n{END}\n\nafter\n"));
        assert_eq!(replace_summary(&new, "| t |\n").unwrap(), new);
        assert!(replace_summary("# R\n", "x").unwrap_err().is_invalid());
        let reversed = format!("{END}\n{BEGIN}\n");
        assert!(replace_summary(&reversed, "x").is_err());
    }
}
