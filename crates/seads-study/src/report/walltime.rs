//! Where the runs' training time went: each run's wall time and the seconds of each phase, as
//! its last metrics line records them.

use std::fmt::Write as _;

use super::csv_field;
use super::runs::{Group, RunData};

/// The phases the learners' metrics lines time (the names in their `timings`), in table order,
/// with their names in the table. A phase not listed here gets a column of its own after these,
/// named as its line names it.
const KNOWN_PHASES: [(&str, &str); 5] = [
    ("collect", "collect"),
    ("relabel", "relabel"),
    ("skill_model", "skill model"),
    ("sac", "SAC updates"),
    ("evaluate", "evaluate"),
];

/// One run's training time.
#[derive(Debug, Clone, PartialEq)]
struct Spent {
    wall_s: f64,
    env_steps: u64,
    /// Seconds per phase, by the line's names.
    phases: std::collections::BTreeMap<String, f64>,
}

/// What the run's last metrics line says, if it has one.
fn spent(run: &RunData) -> Option<Spent> {
    run.lines.last().map(|m| Spent {
        wall_s: m.wall_s,
        env_steps: m.env_steps,
        phases: m.timings.clone(),
    })
}

/// The phases of the table: the known ones, then any other that a run's line times, as
/// (the line's name, the table's name).
fn phases(groups: &[Group<'_>]) -> Vec<(String, String)> {
    let mut phases: Vec<(String, String)> = KNOWN_PHASES
        .iter()
        .map(|(key, name)| ((*key).to_owned(), (*name).to_owned()))
        .collect();
    for run in groups.iter().flat_map(|g| &g.runs) {
        for key in run.lines.last().into_iter().flat_map(|m| m.timings.keys()) {
            if !phases.iter().any(|(k, _)| k == key) {
                phases.push((key.clone(), key.replace('_', " ")));
            }
        }
    }
    phases
}

fn mean(values: impl Iterator<Item = f64>) -> Option<f64> {
    super::stats::summary(&values.collect::<Vec<_>>()).map(|s| s.mean)
}

/// The wall-time table (markdown, one row per group) and its CSV (one row per run).
pub fn walltime_tables(groups: &[Group<'_>]) -> (String, String) {
    let phases = phases(groups);
    let mut md = String::from(
        "| environment | variant | runs | wall time (min): mean [min, max] | env steps/s |",
    );
    for (_, p) in &phases {
        let _ = write!(md, " {p} (min) |");
    }
    md += "\n|---|---|---|---|---|";
    md += &"---|".repeat(phases.len());
    md.push('\n');
    let mut csv = String::from("env,variant,run,wall_s,env_steps");
    for (_, p) in &phases {
        let _ = write!(csv, ",{}_s", p.replace(' ', "_").to_lowercase());
    }
    csv += ",processor\n";
    let minutes = |s: Option<f64>| s.map_or("–".to_owned(), |s| format!("{:.1}", s / 60.0));
    for g in groups {
        let spent: Vec<(&RunData, Spent)> = g
            .runs
            .iter()
            .filter_map(|r| spent(r).map(|s| (*r, s)))
            .collect();
        if spent.is_empty() {
            continue;
        }
        for (run, s) in &spent {
            let _ = write!(
                csv,
                "{},{},{},{},{}",
                csv_field(&g.env),
                csv_field(&g.variant),
                csv_field(&run.dir.display().to_string()),
                s.wall_s,
                s.env_steps
            );
            for (key, _) in &phases {
                let seconds = s.phases.get(key);
                let _ = write!(csv, ",{}", seconds.map_or(String::new(), |v| v.to_string()));
            }
            // Wall times depend on the processor: which trained the run ("; " between several).
            let processor = if run.processors.is_empty() {
                "unrecorded".to_owned()
            } else {
                run.processors.join("; ")
            };
            let _ = writeln!(csv, ",{}", csv_field(&processor));
        }
        let walls = || spent.iter().map(|(_, s)| s.wall_s);
        let lo = walls().fold(f64::INFINITY, f64::min);
        let hi = walls().fold(f64::NEG_INFINITY, f64::max);
        let rate = mean(
            spent
                .iter()
                .map(|(_, s)| s.env_steps as f64 / s.wall_s.max(1e-9)),
        );
        let _ = write!(
            md,
            "| {} | {} | {} | {} [{}, {}] | {} |",
            g.env,
            g.variant,
            spent.len(),
            minutes(mean(walls())),
            minutes(Some(lo)),
            minutes(Some(hi)),
            rate.map_or("–".to_owned(), |r| format!("{r:.0}"))
        );
        for (key, _) in &phases {
            let _ = write!(
                md,
                " {} |",
                minutes(mean(
                    spent.iter().filter_map(|(_, s)| s.phases.get(key).copied())
                ))
            );
        }
        md.push('\n');
    }
    md += "\nTraining only (the final evaluations are not included), from each run's last metrics \
           line; a resumed run counts its sessions from where each resumed. Phases are the seconds \
           spent in each, summed over the run: relabelling runs on its own thread beside the SAC \
           updates, so the phases may add up to more than the wall time. Runs that shared their \
           cores took longer than they would alone. `walltime.csv` names the processor that trained each \
           run (its `provenance.jsonl`; \"unrecorded\" for runs trained before 2026-11-25).\n";
    (md, csv)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(seed: u32, wall: f64) -> RunData {
        let line = serde_json::json!({
            "epoch": 9, "env_steps": 1000, "skill_coverage": 20.0, "wall_s": wall,
            "mean_reward": 1.0, "changed": 1.0, "skill_model_loss": 0.1,
            "critic_loss": 0.1, "actor_loss": 0.1, "steps_per_s": 1000.0 / wall,
            "timings": {"collect": 60.0, "relabel": 120.0, "skill_model": 30.0,
                        "sac": wall - 90.0, "evaluate": 6.0},
        });
        RunData {
            lines: vec![serde_json::from_value(line).unwrap()],
            processors: if seed == 1 {
                vec!["AMD EPYC, 9554".into(), "Intel(R) Xeon(R)".into()]
            } else {
                Vec::new()
            },
            ..super::super::runs::bare_run(seed)
        }
    }

    #[test]
    fn the_table_averages_hand_made_runs_and_lists_each_in_the_csv() {
        let runs = [run(1, 600.0), run(2, 1200.0)];
        let group = Group {
            env: "lightsout-cursor".into(),
            variant: "seads".into(),
            runs: runs.iter().collect(),
        };
        let (md, csv) = walltime_tables(&[group]);
        // Mean of 10 and 20 minutes; rates 1000/600 and 1000/1200 steps/s average to 1.25; SAC
        // 510 and 1110 s average to 13.5 min.
        assert!(
            md.contains("| lightsout-cursor | seads | 2 | 15.0 [10.0, 20.0] | 1 | 1.0 | 2.0 | 0.5 | 13.5 | 0.1 |"),
            "{md}"
        );
        let lines: Vec<&str> = csv.lines().collect();
        assert_eq!(lines.len(), 3, "{csv}");
        assert!(lines[0].ends_with(",evaluate_s,processor"), "{csv}");
        assert!(
            lines[1].ends_with(",600,1000,60,120,30,510,6,\"AMD EPYC, 9554; Intel(R) Xeon(R)\""),
            "{csv}"
        );
        assert!(
            lines[2].ends_with(",1200,1000,60,120,30,1110,6,unrecorded"),
            "{csv}"
        );
    }
}
