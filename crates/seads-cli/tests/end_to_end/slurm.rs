//! `seads sweep slurm` against a real single-node Slurm cluster (slurmctld, slurmd and munge
//! from Debian's packages), started and stopped by `scripts/slurm/{start,stop}.sh`: a job array
//! of a small sweep runs to the end, a re-queued task and killed tasks resume, a failing task
//! shows as failed, and the dependent job writes the report. It needs Slurm, so it is switched on
//! explicitly: built only with `SEADS_TEST_SLURM=1` (which `.ci/run` sets), and then it fails
//! where Slurm cannot be started (not installed, not root), saying why.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::Duration;

use crate::common::wait_until;

const MANIFEST: &str = r#"
name = "slurm-test"
environments = ["lightsout-cursor"]
seeds = [1, 2]

[overrides]
env_steps = 1500
eval_every = 5
checkpoint_every = 5
portable_numerics = true
sac = { hidden = [32, 32] }
seads = { sampled_episodes = 32, recent_episodes = 16, eval_seeds = 1, skill_model = { hidden = [32, 32] } }

[evaluation]
boards = 1
timeout = 600
max_expanded = 2000

[[variant]]
name = "seads"

[[variant]]
name = "no-relabelling"
overrides = { seads = { relabel = { skill_model_p = 0.0, sac_p = 0.0 } } }
"#;

fn scripts() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scripts/slurm")
}

/// A private cluster, stopped (and its folder removed) when dropped, also when a check fails.
struct Cluster {
    dir: tempfile::TempDir,
    conf: PathBuf,
}

impl Cluster {
    /// Starts one, or says why it cannot (`Err`).
    fn start() -> Result<Self, String> {
        let dir = tempfile::tempdir().unwrap();
        let out = Command::new("bash")
            .arg(scripts().join("start.sh"))
            .arg(dir.path())
            // Four CPUs advertised: the four tasks of the first submission run at once.
            .env("SLURM_CPUS", "4")
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr).trim().to_owned();
        match out.status.code() {
            Some(0) => Ok(Self {
                conf: dir.path().join("etc/slurm.conf"),
                dir,
            }),
            Some(3) => Err(stderr),
            _ => panic!("starting Slurm failed: {stderr}"),
        }
    }

    /// A command with this cluster's configuration.
    fn command(&self, program: &str) -> Command {
        let mut c = Command::new(program);
        c.env("SLURM_CONF", &self.conf);
        // sbatch passes the environment on: the tasks may train with a developer's dirty build.
        c.env("SEADS_ALLOW_DIRTY", "true");
        c
    }

    fn seads(&self, args: &[&str], crash_point: Option<u32>) -> Output {
        let mut c = self.command(env!("CARGO_BIN_EXE_seads"));
        c.args(args);
        match crash_point {
            Some(n) => c.env("SEADS_CRASH_POINT", n.to_string()),
            None => c.env_remove("SEADS_CRASH_POINT"),
        };
        let out = c.output().unwrap();
        assert!(
            out.status.success(),
            "seads {args:?}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        out
    }

    fn run(&self, program: &str, args: &[&str]) -> String {
        let out = self.command(program).args(args).output().unwrap();
        assert!(
            out.status.success(),
            "{program} {args:?}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        String::from_utf8_lossy(&out.stdout).into_owned()
    }

    /// Whether any of `jobs` is pending or running.
    fn queued(&self, jobs: &[&str]) -> bool {
        let left = self.run(
            "squeue",
            &[
                "-h",
                "-j",
                &jobs.join(","),
                "-t",
                "pending,running,configuring,completing,suspended",
            ],
        );
        !left.trim().is_empty()
    }

    /// Waits until none of `jobs` is pending or running (each ends at its own time limit at the
    /// latest, `--time` of the submission).
    fn wait_for(&self, jobs: &[&str]) {
        wait_until("the jobs leave the queue", || !self.queued(jobs), || true);
    }
}

impl Drop for Cluster {
    fn drop(&mut self) {
        let _ = Command::new("bash")
            .arg(scripts().join("stop.sh"))
            .arg(self.dir.path())
            .output();
    }
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// Submits the sweep; returns (array job, report job).
fn submit(cluster: &Cluster, sweep: &Path, crash_point: Option<u32>) -> (String, String) {
    let out = cluster.seads(
        &[
            "sweep",
            "slurm",
            s(sweep),
            "--cpus-per-task",
            "1",
            "--max-parallel",
            "4",
            "--time",
            "10",
            "--submit",
        ],
        crash_point,
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    let line = stdout
        .lines()
        .find(|l| l.starts_with("submitted job array"))
        .unwrap_or_else(|| panic!("{stdout}"));
    let words: Vec<&str> = line.split_whitespace().collect();
    (words[3].to_string(), (*words.last().unwrap()).to_string())
}

fn status(cluster: &Cluster, sweep: &Path) -> serde_json::Value {
    let out = cluster.seads(&["sweep", "status", s(sweep), "--json"], None);
    serde_json::from_slice(&out.stdout).unwrap()
}

fn attempts(run: &Path) -> u64 {
    let record: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(run.join("task.json")).unwrap()).unwrap();
    record["attempts"].as_u64().unwrap()
}

#[test]
fn a_sweep_runs_as_a_slurm_job_array_and_its_tasks_resume() {
    let cluster = Cluster::start().unwrap_or_else(|why| {
        panic!("SEADS_TEST_SLURM=1 switches this test on, but Slurm cannot start: {why}")
    });
    let tmp = tempfile::tempdir().unwrap();
    let manifest = tmp.path().join("manifest.toml");
    std::fs::write(&manifest, MANIFEST).unwrap();
    let sweep = tmp.path().join("sweep");
    cluster.seads(&["sweep", "plan", s(&manifest), "--out", s(&sweep)], None);
    let runs: Vec<PathBuf> = status(&cluster, &sweep)["runs"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| PathBuf::from(r["dir"].as_str().unwrap()))
        .collect();
    assert_eq!(runs.len(), 4);
    // Run 3 cannot resume: its latest checkpoint is missing and there is no other.
    std::fs::create_dir_all(runs[3].join("checkpoints")).unwrap();
    std::fs::write(runs[3].join("checkpoints/latest"), "epoch-000005").unwrap();
    std::fs::write(runs[3].join("metrics.jsonl"), "").unwrap();

    // First submission: every task stops after its first checkpoint (moment 22 of its
    // training) and waits there, as a task does that has not finished when its time is up.
    let (array, report) = submit(&cluster, &sweep, Some(22));
    let script = std::fs::read_to_string(sweep.join("slurm/array.sbatch")).unwrap();
    assert!(
        script.contains("#SBATCH --array=0-3%4")
            && script.contains("--index \"$SLURM_ARRAY_TASK_ID\""),
        "{script}"
    );
    let log = |i: usize| {
        std::fs::read_to_string(sweep.join(format!("slurm/logs/task-{i}.out"))).unwrap_or_default()
    };
    let queued = || cluster.queued(&[&array]);
    wait_until(
        "tasks 0-2 stop at the crash point",
        || (0..3).all(|i| log(i).contains("stopped at moment")),
        queued,
    );
    wait_until(
        "task 3 fails",
        || status(&cluster, &sweep)["failed"] == 1,
        queued,
    );
    assert_eq!(status(&cluster, &sweep)["running"], 3);

    // Re-queued, task 0 is killed, starts again and resumes its run from the checkpoint.
    let task0 = format!("{array}_0");
    cluster.run("scontrol", &["requeue", &task0]);
    // Slurm holds a re-queued job for two minutes (its begin time), so that the node has
    // finished cleaning up the killed one; the test waits for that clean-up (no job completing,
    // the node idle or mixed again) and then lets the job start at once.
    let task0_queued = || cluster.queued(&[&task0]);
    wait_until(
        "task 0 is pending and its old run cleaned up",
        || {
            cluster
                .run("scontrol", &["show", "job", &task0])
                .contains("JobState=PENDING")
                && cluster
                    .run("squeue", &["-h", "-t", "completing"])
                    .trim()
                    .is_empty()
                && !cluster
                    .run("sinfo", &["-h", "-N", "-o", "%T"])
                    .contains("completing")
        },
        task0_queued,
    );
    std::thread::sleep(Duration::from_secs(3));
    cluster.run(
        "scontrol",
        &["update", &format!("JobId={task0}"), "StartTime=now"],
    );
    wait_until(
        "task 0 resumes from epoch 5 (its log)",
        || {
            log(0)
                .split("training from epoch 5")
                .nth(1)
                .is_some_and(|rest| rest.contains("stopped at moment"))
        },
        task0_queued,
    );
    assert_eq!(attempts(&runs[0]), 2);

    // Killing the array leaves the runs pending (not running, not failed): nothing is lost.
    cluster.run("scancel", &[&array]);
    cluster.wait_for(&[&array, &report]);
    let st = status(&cluster, &sweep);
    assert_eq!(
        (
            st["pending"].as_u64(),
            st["failed"].as_u64(),
            st["running"].as_u64()
        ),
        (Some(3), Some(1), Some(0)),
        "{st}"
    );

    // Submitted again, every task resumes to the end; the failing one fails again, and the
    // report job, which waits for the whole array, writes the report of the finished runs.
    let (array, report) = submit(&cluster, &sweep, None);
    cluster.wait_for(&[&array, &report]);
    let st = status(&cluster, &sweep);
    assert_eq!(
        (st["done"].as_u64(), st["failed"].as_u64()),
        (Some(3), Some(1)),
        "{st}"
    );
    assert!(
        st["runs"][3]["error"]
            .as_str()
            .unwrap()
            .contains("can be loaded")
    );
    assert_eq!(attempts(&runs[0]), 3);
    assert_eq!(attempts(&runs[1]), 2);
    for run in &runs[..3] {
        let metrics = std::fs::read_to_string(run.join("metrics.jsonl")).unwrap();
        let last: serde_json::Value =
            serde_json::from_str(metrics.lines().last().unwrap()).unwrap();
        assert!(last["env_steps"].as_u64().unwrap() >= 1500);
        // Named by how the manifest's protocol departs from the standard one.
        assert!(
            run.join("evaluation-replan-boards-1-expanded-2000-timeout-600s.json")
                .is_file()
        );
    }
    let job = cluster.run("scontrol", &["show", "job", &format!("{array}_3")]);
    assert!(job.contains("JobState=FAILED"), "{job}");
    let md = std::fs::read_to_string(sweep.join("report/report.md")).unwrap();
    assert!(md.contains("3 finished, 1 unfinished"), "{md}");
}
