//! The deeper search (the paper's Fig. S.7): task success with re-planning at solution depths
//! beyond the standard 1–5, and the search time it took, per depth over the runs evaluated so.

use std::fmt::Write as _;

use super::csv_field;
use super::runs::Group;
use super::stats::{median, summary};

/// Per group and depth: runs, boards solved, success over runs, search time per task (mean and
/// median over all tasks), tasks whose search stopped at the clock, and the median manipulator
/// steps of the solved tasks; Markdown and CSV, `None` if no run was evaluated deeper.
pub fn deep_tables(groups: &[Group<'_>]) -> Option<(String, String)> {
    let mut md = String::from(
        "| environment | variant | depth | runs | solved | success (mean ± sd over runs) | \
         search per task, mean / median | tasks stopped at the clock | median steps (solved) |\n\
         |---|---|---|---|---|---|---|---|---|\n",
    );
    let mut csv = String::from(
        "env,variant,depth,runs,tasks,solved,mean_success,std_success,mean_search_s,\
         median_search_s,timeouts,median_solution_steps,timeout_s,max_expanded\n",
    );
    let mut limits = Vec::new();
    for g in groups {
        let evaluated: Vec<_> = g.runs.iter().filter_map(|r| r.deep.as_ref()).collect();
        let mut depths: Vec<usize> = evaluated
            .iter()
            .flat_map(|d| d.results.iter().map(|r| r.depth))
            .collect();
        depths.sort_unstable();
        depths.dedup();
        for depth in depths {
            let rows: Vec<_> = evaluated
                .iter()
                .filter_map(|d| {
                    let r = d.results.iter().find(|r| r.depth == depth)?;
                    Some((d.limits, r))
                })
                .collect();
            let rates: Vec<f64> = rows.iter().map(|(_, r)| r.success_rate()).collect();
            let Some(rate) = summary(&rates) else {
                continue;
            };
            let search: Vec<f64> = rows
                .iter()
                .flat_map(|(_, r)| r.planning_s.iter().copied())
                .collect();
            let steps: Vec<f64> = rows
                .iter()
                .flat_map(|(_, r)| r.solution_steps.iter().map(|&s| s as f64))
                .collect();
            let (tasks, solved, timeouts) = rows.iter().fold((0, 0, 0), |(t, s, o), (_, r)| {
                (t + r.tasks, s + r.solved, o + r.timeouts)
            });
            let mean_search = summary(&search).map_or(f64::NAN, |s| s.mean);
            let median_search = median(&search).unwrap_or(f64::NAN);
            let median_steps = median(&steps);
            let limit = rows[0].0;
            if !limits.contains(&limit) {
                limits.push(limit);
            }
            let _ = writeln!(
                md,
                "| {} | {} | {depth} | {} | {solved} / {tasks} | {:.1} ± {:.1} % | {:.1} s / {:.1} s \
                 | {timeouts} | {} |",
                g.env,
                g.variant,
                rows.len(),
                100.0 * rate.mean,
                100.0 * rate.std,
                mean_search,
                median_search,
                median_steps.map_or("–".into(), |m| format!("{m}")),
            );
            let _ = writeln!(
                csv,
                "{},{},{depth},{},{tasks},{solved},{:.4},{:.4},{:.3},{:.3},{timeouts},{},{},{}",
                csv_field(&g.env),
                csv_field(&g.variant),
                rows.len(),
                rate.mean,
                rate.std,
                mean_search,
                median_search,
                median_steps.map_or(String::new(), |m| m.to_string()),
                limit.timeout_s.map_or(String::new(), |t| t.to_string()),
                limit.max_expanded.map_or(String::new(), |m| m.to_string()),
            );
        }
    }
    if limits.is_empty() {
        return None;
    }
    let limits: Vec<String> = limits
        .iter()
        .map(seads_planner::SearchLimits::describe)
        .collect();
    let _ = write!(
        md,
        "\nBoards of exactly the given solution depth from the test split, solved with re-planning \
         at the end of training (`seads evaluate --replan --depths 6-10`), each search stopped \
         after {}. Search time is that of all a task's searches together; a task stopped at the \
         clock has an outcome that depends on the machine's speed.\n",
        limits.join(", ")
    );
    Some((md, csv))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::report::runs::{DeepSearch, bare_run};
    use seads_planner::{DepthResult, SearchLimits};

    fn depth(depth: usize, solved: usize, planning_s: Vec<f64>, timeouts: usize) -> DepthResult {
        DepthResult {
            depth,
            tasks: planning_s.len(),
            solved,
            plan_found: solved,
            solution_steps: vec![10 + depth; solved],
            skill_steps: Vec::new(),
            planning_s,
            timeouts,
        }
    }

    /// By hand: depth 9 solved 2/2 and 1/2 (100 % and 50 %: mean 75 %, sd √0.125 = 35.4 %);
    /// search times 1, 3, 60, 4 s: mean 17.0 s, median 3.5 s; one task stopped at the clock.
    /// A run without the deeper search is left out; a report without any has no table.
    #[test]
    fn deep_rows_pool_the_runs_evaluated_deeper() {
        let limits = SearchLimits {
            timeout_s: Some(60.0),
            max_expanded: None,
            plan: seads_planner::PlanChoice::FirstFound,
            search: seads_planner::Search::Breadth,
            memory_limit_mib: None,
        };
        let mut a = bare_run(1);
        a.deep = Some(DeepSearch {
            limits,
            boards: 2,
            results: vec![depth(9, 2, vec![1.0, 3.0], 0)],
        });
        let mut b = bare_run(2);
        b.deep = Some(DeepSearch {
            limits,
            boards: 2,
            results: vec![depth(9, 1, vec![60.0, 4.0], 1)],
        });
        let c = bare_run(3);
        let group = Group {
            env: "lightsout-cursor".into(),
            variant: "seads".into(),
            runs: vec![&a, &b, &c],
        };
        let (md, csv) = deep_tables(std::slice::from_ref(&group)).expect("deep runs");
        assert!(
            md.contains("| lightsout-cursor | seads | 9 | 2 | 3 / 4 | 75.0 ± 35.4 % | 17.0 s / 3.5 s | 1 | 19 |"),
            "{md}"
        );
        assert!(md.contains("60 s"), "{md}");
        assert_eq!(
            csv.lines().nth(1),
            Some("lightsout-cursor,seads,9,2,4,3,0.7500,0.3536,17.000,3.500,1,19,60,")
        );
        let none = Group {
            runs: vec![&c],
            ..group
        };
        assert!(deep_tables(&[none]).is_none());
    }
}
