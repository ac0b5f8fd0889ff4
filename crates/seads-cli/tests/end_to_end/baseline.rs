//! The task-reward baselines through the binary: `seads train --algorithm sac|hac` with their
//! presets, tiny runs trained, extended by `--resume`, killed and resumed, evaluated on the SEADS
//! protocol and reported beside SEADS's modes; the planning commands refuse them in one line.

use std::path::{Path, PathBuf};

use crate::common::*;

/// The policy evaluation of `seads evaluate --boards 2`: named by its protocol's boards.
const POLICY_TWO: &str = "evaluation-policy-boards-2.json";

/// A tiny baseline run of `algorithm` (sac or hac): 30 epochs of 8 steps, evaluations and
/// checkpoints every 10 epochs.
fn tiny_config(dir: &Path, algorithm: &str) -> PathBuf {
    let path = dir.join(format!("{algorithm}.toml"));
    let (section, hac) = if algorithm == "hac" {
        ("hac", "subgoal_horizon = 4\n")
    } else {
        ("sac_baseline", "")
    };
    std::fs::write(
        &path,
        format!(
            r#"
algorithm = "{algorithm}"
env = "lightsout-cursor"
seed = 3
env_steps = 240
eval_every = 10
checkpoint_every = 10
portable_numerics = true

[sac]
hidden = [16, 16]
batch_size = 16
alpha = 0.1

[{section}]
replay_capacity = 100
eval_boards = 1
{hac}"#
        ),
    )
    .unwrap();
    path
}

fn metrics(run: &Path) -> Vec<serde_json::Value> {
    std::fs::read_to_string(run.join("metrics.jsonl"))
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect()
}

/// The metrics without the wall-clock fields.
fn numbers(run: &Path) -> Vec<serde_json::Value> {
    metrics(run)
        .into_iter()
        .map(|mut m| {
            for key in ["wall_s", "steps_per_s", "timings"] {
                m.as_object_mut().unwrap().remove(key);
            }
            m
        })
        .collect()
}

#[test]
fn the_presets_are_the_papers_baselines() {
    let dir = tempfile::tempdir().unwrap();
    let run = dir.path().join("sac");
    let args = [
        "train",
        "--env",
        "tileswap-cursor",
        "--algorithm",
        "sac",
        "--env-steps",
        "8",
        "--out",
        s(&run),
        "--quiet",
    ];
    let out = seads_ok(&args);
    assert!(String::from_utf8_lossy(&out.stdout).contains("task success"));
    let config = std::fs::read_to_string(run.join("config.toml")).unwrap();
    for line in [
        "algorithm = \"sac\"",
        "hidden = [512, 512, 512]",
        "updates_per_epoch = 1.0",
    ] {
        assert!(config.contains(line), "{config}");
    }
    assert_eq!(metrics(&run)[0]["success"].as_array().unwrap().len(), 5);

    let run = dir.path().join("hac");
    let out = seads_ok(&[
        "train",
        "--env",
        "tileswap-cursor",
        "--algorithm",
        "hac",
        "--env-steps",
        "8",
        "--out",
        s(&run),
        "--quiet",
    ]);
    assert!(String::from_utf8_lossy(&out.stdout).contains("subgoals reached"));
    let config = std::fs::read_to_string(run.join("config.toml")).unwrap();
    for line in [
        "algorithm = \"hac\"",
        "hidden = [512, 512]",
        "temperature = 0.5",
        "alpha_high = 0.001",
        "subgoal_horizon = 10",
    ] {
        assert!(config.contains(line), "{config}");
    }
}

/// A mistaken algorithm or setting is one line on stderr and exit 2, and no run is created.
#[test]
fn bad_baseline_settings_are_bad_input() {
    let dir = tempfile::tempdir().unwrap();
    let run = dir.path().join("run");
    let out = seads(&[
        "train",
        "--env",
        "lightsout-cursor",
        "--algorithm",
        "ppo",
        "--out",
        s(&run),
    ]);
    assert_eq!(out.status.code(), Some(2));
    for (text, needle) in [
        (
            "algorithm = \"hac\"\n[hac]\ntemperature = 0.0\n",
            "hac.temperature",
        ),
        (
            "algorithm = \"sac\"\n[sac_baseline]\nupdates_per_epoch = -1.0\n",
            "sac_baseline.updates_per_epoch must be positive",
        ),
        (
            "algorithm = \"sac\"\n[seads]\nnum_skills = 30\n",
            "[seads] is the section of algorithm \"seads\", not of this run's \"sac\"",
        ),
        (
            "[sac_baseline]\nupdates_per_epoch = 0.5\n",
            "[sac_baseline] is the section",
        ),
        // A file of the older, flat layout is refused, pointing to `seads migrate`.
        (
            "algorithm = \"sac\"\nnum_skills = 30\n",
            "unknown field `num_skills` (a file of an older version? `seads migrate` rewrites it)",
        ),
    ] {
        let config = dir.path().join("bad.toml");
        std::fs::write(&config, text).unwrap();
        check_bad_input(&["train", "--config", s(&config), "--out", s(&run)], needle);
        assert!(!run.exists(), "{text}");
    }
}

#[test]
fn a_sac_run_trains_resumes_evaluates_and_is_reported() {
    trains_resumes_evaluates_and_is_reported("sac");
}

#[test]
fn a_hac_run_trains_resumes_evaluates_and_is_reported() {
    trains_resumes_evaluates_and_is_reported("hac");
}

fn trains_resumes_evaluates_and_is_reported(algorithm: &str) {
    let dir = tempfile::tempdir().unwrap();
    let config = tiny_config(dir.path(), algorithm);
    let run = dir.path().join("run");
    seads_ok(&["train", "--config", s(&config), "--out", s(&run), "--quiet"]);
    let epochs: Vec<u64> = metrics(&run)
        .iter()
        .map(|m| m["epoch"].as_u64().unwrap())
        .collect();
    assert_eq!(epochs, [1, 10, 20, 30]);
    // HAC records the share of subgoals reached since the previous line; SAC has none.
    for m in metrics(&run) {
        match m.get("subgoals_reached").and_then(|v| v.as_f64()) {
            Some(share) => assert!(algorithm == "hac" && (0.0..=1.0).contains(&share), "{m}"),
            None => assert_eq!(algorithm, "sac", "{m}"),
        }
    }
    // More budget: the run continues from its last checkpoint.
    seads_ok(&[
        "train",
        "--resume",
        s(&run),
        "--env-steps",
        "320",
        "--quiet",
    ]);
    let m = metrics(&run);
    assert_eq!(m.last().unwrap()["epoch"], 40);
    assert_eq!(m.last().unwrap()["env_steps"], 320);

    let v = json(&["evaluate", "--run", s(&run), "--boards", "2", "--json"]);
    assert_eq!(v["success_rate"].as_object().unwrap().len(), 5, "{v}");
    let saved: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(run.join(POLICY_TWO)).unwrap()).unwrap();
    // The record names the checkpoint it evaluated and its protocol.
    assert_eq!(saved["checkpoint"]["epoch"], 40, "{saved}");
    assert_eq!(saved["checkpoint"]["env_steps"], 320, "{saved}");
    assert_eq!(saved["protocol"]["kind"], "policy", "{saved}");
    assert_eq!(saved["protocol"]["tasks"]["boards"], 2, "{saved}");
    let results = saved["results"].as_array().unwrap();
    assert!(results.iter().all(|d| d["tasks"] == 2));
    let tasks =
        std::fs::read_to_string(run.join("evaluation-policy-boards-2-tasks.jsonl")).unwrap();
    assert_eq!(tasks.lines().count(), 10, "one line per task");

    check_bad_input(
        &[
            "solve",
            "--run",
            s(&run),
            "--board",
            "1,1,0,0,0,1,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0",
        ],
        "baseline run",
    );
    check_bad_input(
        &["evaluate", "--run", s(&run), "--checkpoints", "all"],
        "metrics.jsonl",
    );

    let report = dir.path().join("report");
    seads_ok(&["report", s(&run), "--out", s(&report)]);
    let md = std::fs::read_to_string(report.join("report.md")).unwrap();
    assert!(md.contains("| run | policy | boards-2 | 1 |"), "{md}");
    assert!(report.join("success-lightsout-cursor.png").is_file());
}

/// Killed with SIGKILL at moments spread over its life (collection, metrics appends, checkpoint
/// writes; `SEADS_CRASH_POINT` counts them) and resumed, a baseline run ends as the uninterrupted
/// one: the replay buffers, the streams, the open episodes and HAC's subgoals come back exactly.
#[test]
fn a_killed_sac_run_resumes_to_the_same_run() {
    killed_run_resumes_to_the_same_run("sac", &[3, 24, 29, 47, 66]);
}

#[test]
fn a_killed_hac_run_resumes_to_the_same_run() {
    killed_run_resumes_to_the_same_run("hac", &[5, 29, 47, 66]);
}

fn killed_run_resumes_to_the_same_run(algorithm: &str, points: &[usize]) {
    let dir = tempfile::tempdir().unwrap();
    let config = tiny_config(dir.path(), algorithm);
    let whole = dir.path().join("whole");
    seads_ok(&[
        "train",
        "--config",
        s(&config),
        "--out",
        s(&whole),
        "--quiet",
    ]);
    for &point in points {
        let out = dir.path().join(format!("killed-{point}"));
        let mut command = seads_command();
        command.args(["train", "--config", s(&config), "--out", s(&out), "--quiet"]);
        kill_at_moment(command, point);
        seads_ok(&["train", "--resume", s(&out), "--quiet"]);
        assert_eq!(numbers(&out), numbers(&whole), "killed at moment {point}");
    }
}

/// A study with SAC and HAC variants: the sweep trains each from its baseline's preset,
/// evaluates its policy, shows its progress, and the report puts its success beside SEADS's.
#[test]
fn a_sweep_trains_and_reports_the_baseline_beside_seads() {
    let dir = tempfile::tempdir().unwrap();
    let manifest = dir.path().join("study.toml");
    std::fs::write(
        &manifest,
        r#"
name = "tiny-baselines"
environments = ["lightsout-cursor"]
seeds = [1]
reference = "seads"

[overrides]
env_steps = 240
eval_every = 10
checkpoint_every = 10
portable_numerics = true
sac = { hidden = [16, 16], batch_size = 16 }

[evaluation]
boards = 1
timeout = 600
max_expanded = 500

[[variant]]
name = "seads"
overrides = { seads = { sampled_episodes = 16, recent_episodes = 16, episodes_per_epoch = 8, skill_model = { hidden = [16, 16] } } }

[[variant]]
name = "sac"
overrides = { algorithm = "sac", sac_baseline = { replay_capacity = 100, eval_boards = 1 } }

[[variant]]
name = "hac"
overrides = { algorithm = "hac", hac = { replay_capacity = 100, eval_boards = 1, subgoal_horizon = 4 } }
"#,
    )
    .unwrap();
    let sweep = dir.path().join("sweep");
    seads_ok(&["sweep", "plan", s(&manifest), "--out", s(&sweep)]);
    let sac = sweep.join("runs/lightsout-cursor/sac/seed-1");
    let config = std::fs::read_to_string(sac.join("config.toml")).unwrap();
    assert!(
        config.contains("algorithm = \"sac\"") && config.contains("[sac_baseline]"),
        "{config}"
    );
    seads_ok(&["sweep", "run", s(&sweep), "--quiet"]);
    let status = json(&["sweep", "status", s(&sweep), "--json"]);
    assert_eq!(status["done"], 3, "{status}");
    // Both trained their budget (SEADS finishes its last episodes: a few steps more).
    assert!(
        status["runs"]
            .as_array()
            .unwrap()
            .iter()
            .all(|r| r["env_steps"].as_u64().unwrap() >= 240),
        "{status}"
    );
    // Named by the manifest's protocol: 1 board per depth.
    assert!(sac.join("evaluation-policy-boards-1.json").is_file());
    let hac = sweep.join("runs/lightsout-cursor/hac/seed-1");
    assert!(hac.join("evaluation-policy-boards-1.json").is_file());
    let report = dir.path().join("report");
    seads_ok(&["report", s(&sweep), "--out", s(&report)]);
    let md = std::fs::read_to_string(report.join("report.md")).unwrap();
    for row in [
        "| seads | re-planning | boards-1, expanded-500, timeout-600s | 1 |",
        "| sac | policy | boards-1 | 1 |",
        "| hac | policy | boards-1 | 1 |",
    ] {
        assert!(md.contains(row), "{row}: {md}");
    }
    // The comparison: each run's success over all depths, SAC tested against SEADS.
    let comparison = &md[md.find("## SEADS against the baselines").expect(&md)..];
    assert!(
        comparison.contains("| lightsout-cursor | seads | re-planning | 1 |"),
        "{comparison}"
    );
    let sac_row = comparison
        .lines()
        .find(|l| l.starts_with("| lightsout-cursor | sac | policy | 1 |"))
        .expect(comparison);
    assert!(sac_row.contains("U = "), "{sac_row}");
    assert!(
        comparison.contains("| lightsout-cursor | hac | policy | 1 |"),
        "{comparison}"
    );
}
