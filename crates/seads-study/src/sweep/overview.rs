//! Where every run of a sweep stands, as `seads sweep status` shows it: one row per run and the
//! counts per [`Status`], as a table or as JSON.

use std::fmt::Write as _;
use std::path::Path;

use serde::Serialize;

use super::index::Sweep;
use super::state::{self, Status};
use crate::Result;

/// One run's row.
#[derive(Debug, Clone, Serialize)]
pub struct RunStatus {
    /// Its index in the sweep.
    pub index: usize,
    /// Its environment.
    pub env: String,
    /// Its variant.
    pub variant: String,
    /// Its seed.
    pub seed: u64,
    /// Its run directory.
    pub dir: String,
    /// Where it stands.
    pub status: Status,
    /// Environment steps at its last evaluation line.
    pub env_steps: u64,
    /// Its step budget (0 where its config cannot be read).
    pub budget: u64,
    /// Tasks that have worked on it.
    pub attempts: u32,
    /// Why it failed or is damaged.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub error: Option<String>,
}

/// The environment steps the run in `run` has trained so far (from its metrics, at most its
/// budget), or its budget when it is `done`.
pub fn progress(run: &Path, done: bool) -> u64 {
    let budget = seads_run::load_config(run).map_or(0, |c| c.env_steps);
    if done {
        return budget;
    }
    seads_run::store::last_env_steps(run)
        .unwrap_or(0)
        .min(budget)
}

/// Where the runs `chosen` of `sweep` in `dir` stand, for a progress bar: their environment steps
/// so far (a done run counts its budget) and one word with a count per status ("done 3 running
/// 2 …"; copied runs only if there are some).
pub fn tally(dir: &Path, sweep: &Sweep, chosen: &[usize]) -> (u64, String) {
    let mut steps = 0;
    let mut counts = [0usize; Status::ALL.len()];
    for &i in chosen {
        let run = dir.join(&sweep.runs[i].dir);
        let s = state::status(&run).map_or(Status::Pending, |s| s.0);
        counts[Status::ALL.iter().position(|x| *x == s).unwrap_or(3)] += 1;
        steps += progress(&run, s == Status::Done);
    }
    let words: Vec<String> = Status::ALL
        .iter()
        .zip(counts)
        .filter(|&(s, n)| n > 0 || *s != Status::Copied)
        .map(|(s, n)| format!("{} {n}", s.name()))
        .collect();
    (steps, words.join(" "))
}

/// Every run of a sweep and the counts per status (the JSON of `seads sweep status --json`).
#[derive(Debug, Clone, Serialize)]
pub struct Overview {
    /// The sweep's name.
    pub sweep: String,
    /// Runs in all.
    pub total: usize,
    /// Trained and evaluated.
    pub done: usize,
    /// Worked on now.
    pub running: usize,
    /// Whose last task failed.
    pub failed: usize,
    /// Not started or interrupted.
    pub pending: usize,
    /// Copied in without checkpoints.
    pub copied: usize,
    /// Whose task record cannot be read.
    pub damaged: usize,
    /// One row per run, in sweep order.
    pub runs: Vec<RunStatus>,
}

impl Overview {
    /// Reads where each run of `sweep`, planned in `dir`, stands.
    pub fn read(dir: &Path, sweep: &Sweep) -> Result<Self> {
        let mut runs = Vec::with_capacity(sweep.runs.len());
        for (index, run) in sweep.runs.iter().enumerate() {
            let path = dir.join(&run.dir);
            let (status, record) = state::status(&path)?;
            let error = match status {
                Status::Damaged | Status::Pending => {
                    state::damage(&path).or_else(|| record.as_ref().and_then(|r| r.error.clone()))
                }
                _ => record.as_ref().and_then(|r| r.error.clone()),
            };
            runs.push(RunStatus {
                index,
                env: run.env.clone(),
                variant: run.variant.clone(),
                seed: run.seed,
                dir: path.display().to_string(),
                status,
                env_steps: seads_run::store::last_env_steps(&path).unwrap_or(0),
                budget: seads_run::load_config(&path).map_or(0, |c| c.env_steps),
                attempts: record.as_ref().map_or(0, |r| r.attempts),
                error,
            });
        }
        let count = |s: Status| runs.iter().filter(|r| r.status == s).count();
        Ok(Self {
            sweep: sweep.name.clone(),
            total: runs.len(),
            done: count(Status::Done),
            running: count(Status::Running),
            failed: count(Status::Failed),
            pending: count(Status::Pending),
            copied: count(Status::Copied),
            damaged: count(Status::Damaged),
            runs,
        })
    }

    /// One line per run under a header, columns as wide as their longest entry, and a summary
    /// line.
    pub fn table(&self) -> String {
        let width = |f: fn(&RunStatus) -> usize, min: usize| {
            self.runs.iter().map(f).max().unwrap_or(0).max(min)
        };
        let env_w = width(|r| r.env.len(), 3);
        let variant_w = width(|r| r.variant.len(), 7);
        let mut out = format!(
            " index  status   {:<env_w$}  {:<variant_w$}  seed      steps / budget  tries\n",
            "env", "variant"
        );
        for r in &self.runs {
            let error = r.error.as_ref().map_or(String::new(), |e| {
                format!("  error: {}", e.lines().next().unwrap_or(""))
            });
            let _ = writeln!(
                out,
                "{:>6}  {:<7}  {:<env_w$}  {:<variant_w$}  {:>4}  {:>9} / {:<9} {:>3}{error}",
                r.index,
                r.status.name(),
                r.env,
                r.variant,
                r.seed,
                r.env_steps,
                r.budget,
                r.attempts,
            );
        }
        let _ = write!(
            out,
            "sweep {:?}: {} runs: {} done, {} running, {} failed, {} pending",
            self.sweep, self.total, self.done, self.running, self.failed, self.pending
        );
        if self.copied > 0 {
            let _ = write!(out, ", {} copied in without checkpoints", self.copied);
        }
        if self.damaged > 0 {
            let _ = write!(
                out,
                ", {} damaged (left alone; see their errors)",
                self.damaged
            );
        }
        out
    }
}
