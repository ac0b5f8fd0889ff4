//! The failed tasks of the runs' final evaluation with re-planning, read from their per-task
//! files (`evaluation-replan-tasks.jsonl`, written by `seads evaluate` and sweeps): why each task
//! failed, and which skills left another board than the forward model predicted.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;

use crate::Result;
use serde::Deserialize;

use super::csv_field;
use super::runs::{Group, RunData};

/// What the report reads of one line of a per-task file (`failed_tasks.rs` lists the failed
/// ones).
#[derive(Debug, Deserialize)]
pub(super) struct TaskLine {
    pub depth: usize,
    pub solved: bool,
    pub plan_found: bool,
    pub timed_out: bool,
    /// The skills executed, in order.
    pub executed: Vec<usize>,
    /// The manipulator steps each executed skill took (missing in files from before it was
    /// written).
    #[serde(default)]
    pub skill_steps: Vec<usize>,
    pub deviations: Vec<DeviationLine>,
}

/// A skill that left another board than predicted (boards as `seads solve --board` takes them).
#[derive(Debug, Deserialize)]
pub(super) struct DeviationLine {
    /// Its index among the executed skills.
    pub step: usize,
    pub skill: usize,
    pub before: String,
    pub predicted: String,
    pub reached: String,
}

/// The failures and deviations of one group's tasks.
#[derive(Debug, Default, PartialEq)]
struct Summary {
    runs: usize,
    tasks: usize,
    failed: usize,
    /// Failed without a plan from the first search.
    no_plan: usize,
    /// Failed after executing a plan (re-planning did not reach the goal).
    after_plan: usize,
    /// Tasks in which a search stopped at the clock.
    timed_out: usize,
    /// Deviations in all tasks, those that left the board unchanged, and those in failed tasks.
    deviations: usize,
    unchanged: usize,
    in_failed: usize,
    /// Deviations per skill: (all, board unchanged).
    per_skill: BTreeMap<usize, (usize, usize)>,
}

impl Summary {
    fn add(&mut self, tasks: &[TaskLine]) {
        self.runs += 1;
        for t in tasks {
            self.tasks += 1;
            if !t.solved {
                self.failed += 1;
                if t.plan_found {
                    self.after_plan += 1;
                } else {
                    self.no_plan += 1;
                }
                self.in_failed += t.deviations.len();
            }
            self.timed_out += usize::from(t.timed_out);
            for d in &t.deviations {
                let unchanged = d.before == d.reached;
                self.deviations += 1;
                self.unchanged += usize::from(unchanged);
                let entry = self.per_skill.entry(d.skill).or_default();
                entry.0 += 1;
                entry.1 += usize::from(unchanged);
            }
        }
    }

    /// The skills with the most deviations, most first (ties: lower skill first).
    fn worst_skills(&self, n: usize) -> Vec<(usize, usize)> {
        let mut skills: Vec<(usize, usize)> = self
            .per_skill
            .iter()
            .map(|(&k, &(all, _))| (k, all))
            .collect();
        skills.sort_by(|a, b| b.1.cmp(&a.1).then(a.0.cmp(&b.0)));
        skills.truncate(n);
        skills
    }
}

/// The per-task lines of the re-planning evaluation a report takes of `run` (its standard one,
/// else its one of another protocol: [`RunData::replan_tasks`]), or `None` if it has no
/// per-task file.
pub(super) fn read_tasks(run: &RunData) -> Result<Option<Vec<TaskLine>>> {
    read_tasks_file(&run.dir.join(&run.replan_tasks))
}

/// The per-task lines of the file `path`, or `None` if there is none.
fn read_tasks_file(path: &Path) -> Result<Option<Vec<TaskLine>>> {
    if !path.exists() {
        return Ok(None);
    }
    Ok(Some(seads_run::store::read_json_lines(path)?.0))
}

/// The markdown section (without its heading) and two CSV tables (`failures.csv` per group,
/// `deviations.csv` per group and skill), or `None` if no run has a per-task file.
pub fn failure_tables(groups: &[Group<'_>]) -> Result<Option<(String, String, String)>> {
    let mut summaries = Vec::new();
    for g in groups {
        let mut summary = Summary::default();
        for run in &g.runs {
            if let Some(tasks) = read_tasks(run)? {
                summary.add(&tasks);
            }
        }
        if summary.runs > 0 {
            summaries.push((g, summary));
        }
    }
    if summaries.is_empty() {
        return Ok(None);
    }
    let mut md = String::from(
        "| environment | variant | runs | tasks | failed | no plan | not reached after re-planning | timed out | deviations | board unchanged | in failed tasks | skills with most deviations |\n\
         |---|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    let mut csv = String::from(
        "env,variant,runs,tasks,failed,no_plan,after_plan,timed_out,deviations,unchanged,in_failed\n",
    );
    let mut per_skill = String::from("env,variant,skill,deviations,unchanged\n");
    for (g, s) in &summaries {
        let worst: Vec<String> = s
            .worst_skills(3)
            .iter()
            .map(|(k, n)| format!("{k} ({n})"))
            .collect();
        let counts = [
            s.runs,
            s.tasks,
            s.failed,
            s.no_plan,
            s.after_plan,
            s.timed_out,
            s.deviations,
            s.unchanged,
            s.in_failed,
        ]
        .map(|n| n.to_string());
        let worst = if worst.is_empty() {
            "–".to_owned()
        } else {
            worst.join(", ")
        };
        let _ = writeln!(
            md,
            "| {} | {} | {} | {worst} |",
            g.env,
            g.variant,
            counts.join(" | ")
        );
        let _ = writeln!(
            csv,
            "{},{},{}",
            csv_field(&g.env),
            csv_field(&g.variant),
            counts.join(",")
        );
        for (k, (all, unchanged)) in &s.per_skill {
            let _ = writeln!(
                per_skill,
                "{},{},{k},{all},{unchanged}",
                csv_field(&g.env),
                csv_field(&g.variant)
            );
        }
    }
    md += "\nFrom each run's `evaluation-replan-tasks.jsonl`, or the per-task file of its one \
           re-planning evaluation of another protocol (runs evaluated before that file existed \
           are not counted). A deviation is an executed skill that left another board than the \
           forward model predicted; \"board unchanged\" ones did nothing to the board (no push, or \
           the step limit). Every deviation with its boards is in the per-task files.\n";
    Ok(Some((md, csv, per_skill)))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn line(text: &str) -> TaskLine {
        serde_json::from_str(text).unwrap()
    }

    /// Counted by hand: three tasks, one solved with a deviation on the way, one failed without
    /// a plan, one failed after executing with two deviations (one leaving the board unchanged).
    #[test]
    fn failures_and_deviations_are_counted_by_kind_and_skill() {
        let tasks = [
            line(
                r#"{"depth":2,"solved":true,"plan_found":true,"timed_out":false,"failure":null,"executed":[4,1],
                "deviations":[{"step":0,"skill":4,"before":"1,0","predicted":"0,0","reached":"1,1"}]}"#,
            ),
            line(
                r#"{"depth":5,"solved":false,"plan_found":false,"timed_out":true,"failure":"no plan","executed":[],"deviations":[]}"#,
            ),
            line(
                r#"{"depth":5,"solved":false,"plan_found":true,"timed_out":false,"failure":null,"executed":[4,2],
                "deviations":[{"step":1,"skill":4,"before":"0,1","predicted":"0,0","reached":"0,1"},
                              {"step":2,"skill":2,"before":"0,1","predicted":"0,0","reached":"1,0"}]}"#,
            ),
        ];
        let mut s = Summary::default();
        s.add(&tasks);
        let expected = Summary {
            runs: 1,
            tasks: 3,
            failed: 2,
            no_plan: 1,
            after_plan: 1,
            timed_out: 1,
            deviations: 3,
            unchanged: 1,
            in_failed: 2,
            per_skill: BTreeMap::from([(2, (1, 0)), (4, (2, 1))]),
        };
        assert_eq!(s, expected);
        assert_eq!(s.worst_skills(3), vec![(4, 2), (2, 1)]);
    }

    #[test]
    fn a_run_without_a_per_task_file_is_skipped_and_a_broken_line_is_an_error() {
        use seads_planner::{EvaluationKind, STANDARD_DEPTHS};
        let dir = tempfile::tempdir().unwrap();
        let path = dir
            .path()
            .join(EvaluationKind::Replan.tasks_file(&STANDARD_DEPTHS, None));
        assert!(read_tasks_file(&path).unwrap().is_none());
        std::fs::write(&path, "{\"solved\": true}\n").unwrap();
        let err = read_tasks_file(&path).unwrap_err();
        assert!(format!("{err:#}").contains("tasks.jsonl:1"), "{err:#}");
    }
}
