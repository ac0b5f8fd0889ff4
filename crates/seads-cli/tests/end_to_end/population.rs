//! Populations (`seads sweep task --index A,B,…`, `seads sweep run --population K`): runs trained
//! together in one process must write exactly what each writes trained alone — the same metrics
//! row for row (but the clock) — and a killed population must resume every member exactly.

use std::path::{Path, PathBuf};
use std::process::Command;

use serde_json::Value;

use crate::common::*;

/// Tiny runs of seeds 1–3 in two variants of different network shapes, no evaluation by planning
/// (training is what a population changes).
const MANIFEST: &str = r#"
name = "pop"
environments = ["lightsout-cursor"]
seeds = [1, 2, 3]

[overrides]
env_steps = 800
eval_every = 4
checkpoint_every = 5
portable_numerics = true
# A member's SAC takes one libtorch thread; at these tiny widths a second thread changes the
# bits (at the presets' sizes it does not: seads-rl's tests/training.rs), so the solo runs take
# one too.
sac_threads_alone = 0
sac = { hidden = [32, 32] }
seads = { episodes_per_epoch = 8, sampled_episodes = 32, recent_episodes = 16, eval_seeds = 1, skill_model = { hidden = [32, 32] } }

[evaluation]
every = 0
last = false

[[variant]]
name = "seads"

[[variant]]
name = "wide"
overrides = { sac = { hidden = [48, 32] } }
"#;

fn plan(dir: &Path) -> PathBuf {
    let manifest = dir.join("manifest.toml");
    std::fs::write(&manifest, MANIFEST).unwrap();
    let sweep = dir.join("sweep");
    seads_ok(&["sweep", "plan", s(&manifest), "--out", s(&sweep)]);
    sweep
}

fn run(sweep: &Path, variant: &str, seed: u64) -> PathBuf {
    sweep.join(format!("runs/lightsout-cursor/{variant}/seed-{seed}"))
}

/// The index of a run in the sweep (from `sweep status --json`).
fn index(sweep: &Path, variant: &str, seed: u64) -> usize {
    let status: Value =
        serde_json::from_slice(&seads_ok(&["sweep", "status", s(sweep), "--json"]).stdout).unwrap();
    let runs = status["runs"].as_array().unwrap();
    runs.iter()
        .position(|r| r["variant"] == variant && r["seed"] == seed)
        .unwrap_or_else(|| panic!("no run {variant} {seed} in {status}"))
}

/// Each run's metrics trained alone with `seads train`, from its planned config.
fn solo(dir: &Path, runs: &[PathBuf]) -> Vec<Vec<Value>> {
    runs.iter()
        .enumerate()
        .map(|(i, run)| {
            let out = dir.join(format!("solo-{i}"));
            let config = run.join("config.toml");
            seads_ok(&["train", "--quiet", "--config", s(&config), "--out", s(&out)]);
            metrics_without_clock(&out)
        })
        .collect()
}

fn task(sweep: &Path, indices: &str) -> Command {
    let mut command = seads_command();
    command.args([
        "sweep",
        "task",
        s(sweep),
        "--index",
        indices,
        "--cores",
        "2",
    ]);
    command
}

#[test]
fn members_equal_their_solo_runs_and_resume_exactly_after_kills() {
    let tmp = tempfile::tempdir().unwrap();
    let sweep = plan(tmp.path());
    let runs: Vec<PathBuf> = (1..=3).map(|seed| run(&sweep, "seads", seed)).collect();
    let list = (1..=3)
        .map(|seed| index(&sweep, "seads", seed).to_string())
        .collect::<Vec<_>>()
        .join(",");
    let alone = solo(tmp.path(), &runs);
    assert!(alone[0].len() >= 10, "{} evaluations", alone[0].len());
    assert_ne!(
        alone[0], alone[1],
        "seeds 1 and 2 must differ for the test to mean anything"
    );

    // Killed at moments spread over the population's life (all members' moments counted
    // together), then resumed by the same task.
    for point in [3, 40, 97, 150, 233] {
        kill_at_moment(task(&sweep, &list), point);
    }
    let output = task(&sweep, &list).output().unwrap();
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    for (run, alone) in runs.iter().zip(&alone) {
        assert_eq!(
            &metrics_without_clock(run),
            alone,
            "{} differs from its solo run",
            run.display()
        );
        // A member's checkpoint is a single run's: it resumes and evaluates as one.
        seads_ok(&["train", "--quiet", "--resume", s(run)]);
        let evaluation = json(&[
            "evaluate",
            "--run",
            s(run),
            "--depths",
            "1",
            "--boards",
            "2",
            "--max-expanded",
            "500",
            "--json",
        ]);
        assert!(evaluation["success_rate"]["1"].is_number(), "{evaluation}");
    }
    let status: Value =
        serde_json::from_slice(&seads_ok(&["sweep", "status", s(&sweep), "--json"]).stdout)
            .unwrap();
    let done = status["runs"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|r| r["variant"] == "seads" && r["status"] == "done")
        .count();
    assert_eq!(done, 3, "members are shown as runs: {status}");
}

#[test]
fn bad_populations_are_refused_before_anything_is_written() {
    let tmp = tempfile::tempdir().unwrap();
    let sweep = plan(tmp.path());
    let (a, b) = (index(&sweep, "seads", 1), index(&sweep, "wide", 1));
    check_bad_input(
        &["sweep", "task", s(&sweep), "--index", &format!("{a},{b}")],
        "sac.hidden differs",
    );
    for dir in [run(&sweep, "seads", 1), run(&sweep, "wide", 1)] {
        assert!(
            !dir.join("task.json").exists(),
            "{} was written",
            dir.display()
        );
        assert_eq!(
            std::fs::read_to_string(dir.join("metrics.jsonl")).ok(),
            None
        );
    }
    check_bad_input(
        &["sweep", "run", s(&sweep), "--population", "0"],
        "--population must be at least 1",
    );
    check_bad_input(
        &["sweep", "slurm", s(&sweep), "--population", "0"],
        "--population must be at least 1",
    );
    // A member that another population's task holds: the task started by `sweep run` says
    // "taken" (exit 3) and leaves the other member alone.
    let c = index(&sweep, "seads", 2);
    let mut holder = park_at_moment(task(&sweep, &c.to_string()), 1);
    let output = task(&sweep, &format!("{a},{c}"))
        .arg("--child")
        .output()
        .unwrap();
    assert_eq!(output.status.code(), Some(3), "{output:?}");
    assert!(!run(&sweep, "seads", 1).join("task.json").exists());
    // Started by hand, the same population is the user's to fix: exit 2, once the wait is over.
    let output = task(&sweep, &format!("{a},{c}"))
        .args(["--wait", "1"])
        .output()
        .unwrap();
    assert_eq!(output.status.code(), Some(2), "{output:?}");
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        stderr.contains("a member belongs to another population's task"),
        "{stderr}"
    );
    assert_eq!(stderr.trim_end().lines().count(), 1, "{stderr}");
    assert!(!run(&sweep, "seads", 1).join("task.json").exists());
    holder.kill().expect("SIGKILL");
    holder.wait().expect("reaped");
}

#[test]
fn sweep_run_groups_compatible_runs_into_populations_and_slurm_writes_one_task_each() {
    let tmp = tempfile::tempdir().unwrap();
    let sweep = plan(tmp.path());
    let out = seads_ok(&["sweep", "slurm", s(&sweep), "--population", "2"]);
    let script = std::fs::read_to_string(sweep.join("slurm/array.sbatch")).unwrap();
    // seads: seeds 1-3 in populations of 2 and 1; wide: 2 and 1.
    assert!(script.contains("#SBATCH --array=0-3\n"), "{script}");
    assert!(script.contains("POPULATIONS=("), "{script}");
    assert!(
        script.contains("--index \"${POPULATIONS[$SLURM_ARRAY_TASK_ID]}\""),
        "{script}"
    );
    assert!(String::from_utf8_lossy(&out.stdout).contains("array.sbatch"));
    let out = seads_ok(&[
        "sweep",
        "run",
        s(&sweep),
        "--population",
        "3",
        "--seeds",
        "1-2",
        "--quiet",
    ]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("in 2 population(s)"), "{text}");
    let log = std::fs::read_to_string(run(&sweep, "seads", 2).join("task.log")).unwrap();
    assert!(log.contains("trained in a population with runs"), "{log}");
    let first = std::fs::read_to_string(run(&sweep, "seads", 1).join("task.log")).unwrap();
    assert!(first.contains("as one population"), "{first}");
}
