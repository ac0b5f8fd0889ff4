//! Crash-point tests: `seads train` is killed with SIGKILL at many moments of its life, resumed,
//! and must end with exactly the metrics of the run that was never killed.
//!
//! The moments are deterministic: with `SEADS_CRASH_POINT=N` the binary stops at the N-th moment
//! of the run (after collecting an epoch, while SAC updates, after an epoch, after a metrics
//! append, between the steps of a checkpoint write) and waits there to be killed. CI kills at 24
//! moments spread over the run plus the first of each kind; `SEADS_CRASH_TEST_ALL=1` kills at
//! every moment (the long variant, 190 kills), `SEADS_CRASH_TEST_EVERY=N` at every N-th.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;

use serde_json::Value;

use crate::common::{
    TensorDamage, copy_dir, damage_tensor, kill_at_moment, metrics_without_clock, park_at_moment,
};

const SEADS: &str = env!("CARGO_BIN_EXE_seads");

/// A small run: 800 steps in epochs of 8 short episodes, updates from epoch 4 (4 small SAC
/// batches an epoch: each kill point costs about one whole run), an evaluation every 4 epochs
/// (14 in all) and a checkpoint every 5 (so checkpoints fall between evaluations too); 190
/// moments.
fn config(dir: &Path) -> PathBuf {
    // The Cursor's layer of the presets, on LightsOut.
    let mut text = "env = \"lightsout-cursor\"\n".to_owned()
        + &std::fs::read_to_string(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../configs/cursor.toml"
        ))
        .unwrap();
    for (from, to) in [
        ("seed = 1", "seed = 5"),
        ("env_steps = 500000", "env_steps = 800"),
        ("episodes_per_epoch = 32", "episodes_per_epoch = 8"),
        ("hidden = [256, 256]", "hidden = [32, 32]"),
        ("batch_size = 128", "batch_size = 32"),
        ("updates_per_epoch = 16", "updates_per_epoch = 4"),
        ("sampled_episodes = 256", "sampled_episodes = 32"),
        ("recent_episodes = 256", "recent_episodes = 16"),
        ("eval_every = 100", "eval_every = 4"),
        ("checkpoint_every = 100", "checkpoint_every = 5"),
        ("eval_seeds = 20", "eval_seeds = 1"),
        ("sac_threads_alone = 2", "sac_threads_alone = 0"),
        ("portable_numerics = false", "portable_numerics = true"),
    ] {
        // A preset that no longer says `from` would leave the run silently larger.
        assert!(text.contains(from), "the preset no longer says {from:?}");
        text = text.replace(from, to);
    }
    let path = dir.join("crash.toml");
    std::fs::write(&path, text).unwrap();
    path
}

fn train(config: &Path, out: &Path) -> Command {
    let mut cmd = Command::new(SEADS);
    cmd.args(["train", "--quiet", "--config"])
        .arg(config)
        .arg("--out")
        .arg(out);
    cmd
}

fn resume(out: &Path) -> std::process::Output {
    let output = Command::new(SEADS)
        .args(["train", "--quiet", "--resume"])
        .arg(out)
        .output()
        .unwrap();
    assert!(
        output.status.success(),
        "resuming {}: {}",
        out.display(),
        String::from_utf8_lossy(&output.stderr)
    );
    output
}

struct Baseline {
    _dir: tempfile::TempDir,
    config: PathBuf,
    metrics: Vec<Value>,
    /// The name of every moment of the run, in order.
    moments: Vec<String>,
}

/// The run that is never killed, and the list of its moments.
fn baseline() -> &'static Baseline {
    static BASELINE: OnceLock<Baseline> = OnceLock::new();
    BASELINE.get_or_init(|| {
        let dir = tempfile::tempdir().unwrap();
        let config = config(dir.path());
        let out = dir.path().join("base");
        let output = train(&config, &out)
            .env("SEADS_CRASH_POINT", "list")
            .output()
            .unwrap();
        assert!(output.status.success());
        let moments: Vec<String> = String::from_utf8_lossy(&output.stderr)
            .lines()
            .filter_map(|l| l.strip_prefix("seads: moment "))
            .map(str::to_owned)
            .collect();
        let metrics = metrics_without_clock(&out);
        assert!(metrics.len() >= 10, "{} evaluations", metrics.len());
        Baseline {
            _dir: dir,
            config,
            metrics,
            moments,
        }
    })
}

/// Starts a fresh run of `config` into `out` and kills it with SIGKILL where it stopped, at
/// moment `point`.
fn start_and_kill(config: &Path, out: &Path, point: usize) {
    kill_at_moment(train(config, out), point);
}

/// The moment right after the fourth `latest` update: older complete checkpoints exist.
fn after_a_later_checkpoint(base: &Baseline) -> usize {
    1 + base
        .moments
        .iter()
        .enumerate()
        .filter(|(_, m)| *m == "latest-written")
        .nth(3)
        .unwrap()
        .0
}

/// Starts a fresh run, kills it at moment `point`, then resumes it to the end; returns the
/// resumed run's stderr.
fn kill_and_resume(point: usize, tear: bool) -> String {
    let base = baseline();
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("run");
    start_and_kill(&base.config, &out, point);
    if tear {
        // A crash during the append: the last line lost its second half and its newline.
        let path = out.join("metrics.jsonl");
        let text = std::fs::read_to_string(&path).unwrap();
        let body = text.trim_end_matches('\n');
        let start = body.rfind('\n').map_or(0, |i| i + 1);
        let cut = start + (body.len() - start) / 2;
        std::fs::write(&path, &body[..cut]).unwrap();
    }
    let output = resume(&out);
    assert_eq!(
        metrics_without_clock(&out),
        base.metrics,
        "killed at moment {point} ({}), the resumed run differs",
        base.moments[point - 1]
    );
    String::from_utf8_lossy(&output.stderr).into_owned()
}

/// The moments to kill at: 24 spread over the run and the first of each kind; every moment with
/// `SEADS_CRASH_TEST_ALL=1`, every N-th with `SEADS_CRASH_TEST_EVERY=N`.
fn points() -> Vec<usize> {
    let moments = &baseline().moments;
    let n = moments.len();
    assert!(n >= 60, "{n} moments");
    if std::env::var_os("SEADS_CRASH_TEST_ALL").is_some() {
        return (1..=n).collect();
    }
    if let Ok(every) = std::env::var("SEADS_CRASH_TEST_EVERY") {
        let every: usize = every.parse().expect("SEADS_CRASH_TEST_EVERY is a number");
        return (1..=n).step_by(every.max(1)).collect();
    }
    let mut points: Vec<usize> = (0..24).map(|i| 1 + i * (n - 1) / 23).collect();
    for kind in [
        "collected",
        "prepared",
        "epoch-done",
        "metrics-appended",
        "checkpoint-written",
        "checkpoint-renamed",
        "latest-written",
    ] {
        let first = moments.iter().position(|m| m == kind);
        points.push(1 + first.unwrap_or_else(|| panic!("no moment {kind}")));
    }
    points.sort_unstable();
    points.dedup();
    points
}

fn kill_at_every_other_point(parity: usize) {
    let moments = &baseline().moments;
    for (i, point) in points().into_iter().enumerate() {
        if i % 2 == parity {
            let tear = moments[point - 1] == "metrics-appended";
            kill_and_resume(point, tear);
        }
    }
}

/// Half of the kill points (the two halves run side by side).
#[test]
fn killed_runs_resume_to_the_same_metrics_a() {
    kill_at_every_other_point(0);
}

/// The other half.
#[test]
fn killed_runs_resume_to_the_same_metrics_b() {
    kill_at_every_other_point(1);
}

/// A run killed right after an append whose line was torn, and whose latest checkpoint is
/// unreadable: resuming drops the torn line, falls back to the checkpoint before, says both on
/// stderr, and still ends exactly as the run that was never killed.
#[test]
fn a_torn_line_and_a_corrupt_latest_checkpoint_are_repaired() {
    let base = baseline();
    // The second checkpoint's pointer update: an older complete checkpoint exists.
    let point = after_a_later_checkpoint(base);
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("run");
    start_and_kill(&base.config, &out, point);
    let latest = std::fs::read_to_string(out.join("checkpoints/latest")).unwrap();
    std::fs::write(
        out.join("checkpoints")
            .join(latest.trim())
            .join("progress.json"),
        "{",
    )
    .unwrap();
    std::fs::create_dir(out.join("checkpoints/.epoch-000099.tmp")).unwrap();
    let mut text = std::fs::read_to_string(out.join("metrics.jsonl")).unwrap();
    text.push_str("{\"epoch\": 1");
    std::fs::write(out.join("metrics.jsonl"), text).unwrap();
    let stderr = String::from_utf8_lossy(&resume(&out).stderr).into_owned();
    assert!(stderr.contains("passed over checkpoint"), "{stderr}");
    assert!(stderr.contains("torn last line"), "{stderr}");
    assert!(stderr.contains(".epoch-000099.tmp"), "{stderr}");
    assert_eq!(metrics_without_clock(&out), base.metrics);
}

/// A latest checkpoint whose actor holds a float64 tensor (issue 82: `train --resume` panicked
/// on it) or whose forward model holds NaN is passed over like any unreadable checkpoint: the
/// run resumes from the one before, says so, and ends as the run that was never damaged.
#[test]
fn a_latest_checkpoint_with_a_damaged_tensor_is_passed_over() {
    let base = baseline();
    let point = after_a_later_checkpoint(base);
    let dir = tempfile::tempdir().unwrap();
    for (file, damage) in [
        ("sac_actor.safetensors", TensorDamage::Float64),
        ("forward_model.safetensors", TensorDamage::NotANumber),
    ] {
        let out = dir.path().join(file);
        start_and_kill(&base.config, &out, point);
        let latest = std::fs::read_to_string(out.join("checkpoints/latest")).unwrap();
        damage_tensor(
            &out.join("checkpoints").join(latest.trim()).join(file),
            damage,
        );
        let output = resume(&out);
        let stderr = String::from_utf8_lossy(&output.stderr).into_owned();
        assert!(output.status.success(), "{file}: {stderr}");
        assert!(
            stderr.contains("passed over checkpoint"),
            "{file}: {stderr}"
        );
        assert!(!stderr.contains("panicked"), "{file}: {stderr}");
        assert_eq!(metrics_without_clock(&out), base.metrics, "{file}");
    }
}

/// `--env-steps` with `--resume` raises a finished run's budget and records it; lowering it is
/// bad input.
#[test]
fn a_finished_run_can_be_extended() {
    let base = baseline();
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("run");
    assert!(train(&base.config, &out).output().unwrap().status.success());
    let run = out.to_str().unwrap();
    let output = Command::new(SEADS)
        .args(["train", "--quiet", "--resume", run, "--env-steps", "2000"])
        .output()
        .unwrap();
    assert!(output.status.success());
    let config = std::fs::read_to_string(out.join("config.toml")).unwrap();
    assert!(config.contains("env_steps = 2000"), "{config}");
    let metrics = metrics_without_clock(&out);
    assert!(metrics.last().unwrap()["env_steps"].as_u64().unwrap() >= 2000);
    // The rows up to the old end are the old run's.
    assert_eq!(metrics[..base.metrics.len()], base.metrics[..]);
    let output = Command::new(SEADS)
        .args(["train", "--quiet", "--resume", run, "--env-steps", "100"])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("can only be raised"), "{stderr}");
}

/// One writer per run directory: while a run trains (here waiting at a moment after its first
/// checkpoint), a second `train --resume`, an evaluation and a plot of it are refused with exit
/// 2 in one line naming the holder, and change nothing; `sweep status`-style readers and the
/// resume after the holder is gone work.
#[test]
fn a_second_writer_is_refused_while_the_run_trains() {
    let dir = tempfile::tempdir().unwrap();
    let config = config(dir.path());
    let out = dir.path().join("run");
    let mut first = park_at_moment(train(&config, &out), 40);
    let before = std::fs::read(out.join("metrics.jsonl")).unwrap();
    let figures = dir.path().join("figures");
    let run = out.to_str().unwrap();
    for args in [
        vec!["train", "--quiet", "--resume", run],
        vec!["evaluate", "--run", run, "--boards", "1", "--quiet"],
        vec!["plot", "--run", run, "--out", figures.to_str().unwrap()],
    ] {
        let output = Command::new(SEADS).args(&args).output().unwrap();
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert_eq!(output.status.code(), Some(2), "{args:?}: {stderr}");
        assert!(
            stderr.contains(&format!("pid {} (seads train", first.id()))
                && stderr.contains("one writer at a time"),
            "{args:?}: {stderr}"
        );
        assert_eq!(stderr.trim().lines().count(), 1, "{stderr}");
    }
    assert_eq!(std::fs::read(out.join("metrics.jsonl")).unwrap(), before);
    assert!(!figures.exists(), "a refused plot writes nothing");
    first.kill().unwrap();
    first.wait().unwrap();
    resume(&out);
}

/// Resume has one rule for damage: a `latest` pointer that names no checkpoint of the run (bytes
/// that are not text, a directory, a path leading outside the run) is ignored with a word on
/// stderr and the newest checkpoint is taken, ending as the run that was never damaged; a
/// removed `metrics.jsonl` or emptied `checkpoints/` is refused with exit 2 in one line, and
/// nothing is retrained or changed.
#[test]
fn damaged_runs_are_repaired_with_a_word_or_refused_never_retrained() {
    let base = baseline();
    let point = after_a_later_checkpoint(base);
    let dir = tempfile::tempdir().unwrap();
    let killed = dir.path().join("killed");
    start_and_kill(&base.config, &killed, point);
    let copy = |name: &str| {
        let to = dir.path().join(name);
        let status = Command::new("cp")
            .arg("-r")
            .arg(&killed)
            .arg(&to)
            .status()
            .unwrap();
        assert!(status.success());
        to
    };
    let outside = dir.path().join("outside");
    std::fs::create_dir_all(outside.join("epoch-000010")).unwrap();
    type Damage = fn(&Path, &Path);
    let repaired: [(&str, Damage); 3] = [
        ("not-text", |run, _| {
            std::fs::write(run.join("checkpoints/latest"), [0xff, 0xfe, 0x00]).unwrap();
        }),
        ("directory", |run, _| {
            std::fs::remove_file(run.join("checkpoints/latest")).unwrap();
            std::fs::create_dir(run.join("checkpoints/latest")).unwrap();
        }),
        ("leads-outside", |run, outside| {
            assert!(outside.join("epoch-000010").is_dir());
            std::fs::write(run.join("checkpoints/latest"), "../../outside/epoch-000010").unwrap();
        }),
    ];
    for (name, damage) in repaired {
        let run = copy(name);
        damage(&run, &outside);
        let stderr = String::from_utf8_lossy(&resume(&run).stderr).into_owned();
        assert!(
            stderr.contains("ignored the latest pointer"),
            "{name}: {stderr}"
        );
        assert_eq!(metrics_without_clock(&run), base.metrics, "{name}");
    }
    assert_eq!(std::fs::read_dir(&outside).unwrap().count(), 1);
    let refused: [(&str, Damage, &str); 2] = [
        (
            "no-metrics",
            |run, _| std::fs::remove_file(run.join("metrics.jsonl")).unwrap(),
            "metrics.jsonl is missing",
        ),
        (
            "emptied",
            |run, _| {
                std::fs::remove_dir_all(run.join("checkpoints")).unwrap();
                std::fs::create_dir(run.join("checkpoints")).unwrap();
            },
            "holds no checkpoint",
        ),
    ];
    for (name, damage, says) in refused {
        let run = copy(name);
        damage(&run, &outside);
        let before = std::fs::read(run.join("metrics.jsonl")).ok();
        let output = Command::new(SEADS)
            .args(["train", "--quiet", "--resume"])
            .arg(&run)
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert_eq!(output.status.code(), Some(2), "{name}: {stderr}");
        assert_eq!(stderr.trim().lines().count(), 1, "{name}: {stderr}");
        assert!(stderr.contains(says), "{name}: {stderr}");
        assert_eq!(
            std::fs::read(run.join("metrics.jsonl")).ok(),
            before,
            "{name}"
        );
        assert_eq!(
            std::fs::read_dir(run.join("checkpoints")).unwrap().count() > 0,
            name == "no-metrics",
            "{name}: nothing is retrained"
        );
    }
}

/// A robot run on the noisy twin (`seads uarm train --port sim`), killed ten epochs after its
/// checkpoint at epoch 100 and resumed, ends as the run never killed: the same metrics, the same
/// twin in its last checkpoint and the same evaluation. The paper's protocol resets neither the
/// board nor the pen, and the twin's noise draws go on from run to run, so this holds only
/// because the checkpoint keeps what the twin carries: a checkpoint without it (as before it was
/// kept) is resumed with a fresh twin, says so, and parts from the whole run.
#[test]
fn a_twin_run_killed_and_resumed_is_the_run_never_killed() {
    let dir = tempfile::tempdir().unwrap();
    let uarm = |out: &Path, extra: &[&str]| {
        let mut cmd = Command::new(SEADS);
        cmd.args(["uarm", "train", "--port", "sim:2", "--boards", "1"])
            .args(["--max-expanded", "1000", "--quiet", "--out"])
            .arg(out)
            .args(extra);
        cmd
    };
    let new = [
        "--env-steps",
        "500",
        "--updates-per-epoch",
        "2",
        "--tap-sd-mm",
        "8",
        "--late-reports",
        "0.2",
    ];
    let whole = dir.path().join("whole");
    let output = uarm(&whole, &new)
        .env("SEADS_CRASH_POINT", "list")
        .output()
        .unwrap();
    assert!(output.status.success(), "{output:?}");
    let moments: Vec<String> = String::from_utf8_lossy(&output.stderr)
        .lines()
        .filter_map(|l| l.strip_prefix("seads: moment "))
        .map(str::to_owned)
        .collect();
    // Ten epochs after the first checkpoint (at epoch 100).
    let checkpoint = moments.iter().position(|m| m == "latest-written").unwrap();
    let point = 1
        + checkpoint
        + moments[checkpoint..]
            .iter()
            .enumerate()
            .filter(|(_, m)| *m == "epoch-done")
            .nth(9)
            .unwrap()
            .0;
    let resumed = dir.path().join("resumed");
    kill_at_moment(uarm(&resumed, &new), point);
    // A checkpoint that lost the twin's state although its origin says it kept it is damaged,
    // not old (issue 82: it was resumed with a fresh twin, "written before checkpoints kept
    // it"): it is passed over, and with no other checkpoint the resume is refused, saying why.
    let damaged = dir.path().join("damaged");
    copy_dir(&resumed, &damaged);
    let checkpoint = damaged.join("checkpoints/epoch-000100");
    let origin = std::fs::read_to_string(checkpoint.join("origin.json")).unwrap();
    assert!(origin.contains("\"carried_state\":true"), "{origin}");
    std::fs::remove_file(checkpoint.join("environment.json")).unwrap();
    let before = std::fs::read(damaged.join("metrics.jsonl")).unwrap();
    let output = uarm(&damaged, &["--resume"]).output().unwrap();
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(!output.status.success(), "{stderr}");
    assert!(stderr.contains("environment.json is missing"), "{stderr}");
    assert_eq!(
        std::fs::read(damaged.join("metrics.jsonl")).unwrap(),
        before
    );
    // The same run with a checkpoint from before checkpoints kept the twin (no environment.json,
    // and an origin that does not say it kept one): it says that it goes on with a fresh twin,
    // and it parts from the whole run.
    let stale = dir.path().join("stale");
    copy_dir(&resumed, &stale);
    let checkpoint = stale.join("checkpoints/epoch-000100");
    std::fs::remove_file(checkpoint.join("environment.json")).unwrap();
    std::fs::write(
        checkpoint.join("origin.json"),
        origin.replace(",\"carried_state\":true", ""),
    )
    .unwrap();
    let output = uarm(&stale, &["--resume"]).output().unwrap();
    assert!(output.status.success(), "{output:?}");
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(stderr.contains("holds no state of the twin"), "{stderr}");
    assert_ne!(metrics_without_clock(&stale), metrics_without_clock(&whole));
    let output = uarm(&resumed, &["--resume"]).output().unwrap();
    assert!(output.status.success(), "{output:?}");
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(!stderr.contains("twin"), "{stderr}");
    assert_eq!(
        metrics_without_clock(&resumed),
        metrics_without_clock(&whole)
    );
    let read = |run: &Path, file: &str| std::fs::read_to_string(run.join(file)).unwrap();
    let last = "checkpoints/epoch-000125/environment.json";
    assert_eq!(read(&resumed, last), read(&whole, last));
    // The evaluation, without the search times that differ between machines.
    let results = |run: &Path| {
        let mut v: Value =
            serde_json::from_str(&read(run, "evaluation-replan-boards-1-expanded-1000.json"))
                .unwrap();
        for r in v["results"].as_array_mut().unwrap() {
            r.as_object_mut().unwrap().remove("planning_s");
        }
        v
    };
    assert_eq!(results(&resumed), results(&whole));
    const TASKS: &str = "evaluation-replan-boards-1-expanded-1000-tasks.jsonl";
    assert_eq!(read(&resumed, TASKS), read(&whole, TASKS));
}
