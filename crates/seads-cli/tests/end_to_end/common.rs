//! Helpers shared by the binary's end-to-end tests: running `seads` and checking its exit.

#![allow(dead_code)] // each test file uses some of them

use std::io::{BufRead, BufReader};
use std::path::Path;
use std::process::{Command, Output, Stdio};

/// The `seads` binary of this build, as a command. Studies may train with it even when it was
/// built from a working tree with uncommitted changes (`SEADS_ALLOW_DIRTY`), as a developer's
/// test build usually is; `a_study_refuses_a_dirty_binary` runs without that.
pub fn seads_command() -> Command {
    let mut command = Command::new(env!("CARGO_BIN_EXE_seads"));
    command.env("SEADS_ALLOW_DIRTY", "true");
    command
}

/// Runs the `seads` binary of this build.
pub fn seads(args: &[&str]) -> Output {
    seads_command().args(args).output().expect("run seads")
}

/// Runs seads and asserts that it succeeded.
pub fn seads_ok(args: &[&str]) -> Output {
    let out = seads(args);
    assert!(
        out.status.success(),
        "seads {args:?}: {}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// The JSON a successful call prints.
pub fn json(args: &[&str]) -> serde_json::Value {
    serde_json::from_slice(&seads_ok(args).stdout).expect("valid JSON")
}

/// Exit code 2 and a single `error:` line on stderr that says `needle`.
pub fn check_bad_input(args: &[&str], needle: &str) {
    let out = seads(args);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "seads {args:?}: {stderr}");
    assert_eq!(stderr.lines().count(), 1, "one line: {stderr}");
    assert!(
        stderr.starts_with("error: ") && stderr.contains(needle),
        "seads {args:?}: {stderr:?} should say {needle:?}"
    );
}

/// A path as the `&str` an argument list wants.
pub fn s(p: &Path) -> &str {
    p.to_str().expect("UTF-8 path")
}

/// Starts `command` (a `seads` call) stopped at moment `point` of its run (`SEADS_CRASH_POINT`)
/// and kills it there with SIGKILL.
pub fn kill_at_moment(command: Command, point: usize) {
    let mut child = park_at_moment(command, point);
    child.kill().expect("SIGKILL");
    child.wait().expect("reaped");
}

/// Starts `command` with `SEADS_CRASH_POINT=point` and returns it once it waits at that moment,
/// alive and holding whatever it holds there.
pub fn park_at_moment(mut command: Command, point: usize) -> std::process::Child {
    let mut child = command
        .env("SEADS_CRASH_POINT", point.to_string())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("run seads");
    let stderr = BufReader::new(child.stderr.take().expect("piped stderr"));
    let stopped = stderr
        .lines()
        .any(|l| l.is_ok_and(|l| l.starts_with("seads: stopped at moment")));
    assert!(stopped, "the run never reached moment {point}");
    child
}

/// Waits until `holds`, looking again every few milliseconds, while `alive` says that what
/// could make it hold (a process, a job) is still at work; once that has ended, `holds` must
/// hold (else the test fails, naming `what`). There is no deadline: how long the work takes
/// depends on the machine, and what ends it is an event, not the clock.
pub fn wait_until(what: &str, mut holds: impl FnMut() -> bool, mut alive: impl FnMut() -> bool) {
    while !holds() {
        if !alive() {
            assert!(holds(), "{what}: what it waited on ended first");
            return;
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
}

/// The metrics lines of the run in `run`, without what depends on the clock.
pub fn metrics_without_clock(run: &Path) -> Vec<serde_json::Value> {
    std::fs::read_to_string(run.join("metrics.jsonl"))
        .expect("metrics.jsonl")
        .lines()
        .map(|line| {
            let mut v: serde_json::Value = serde_json::from_str(line).expect("a metrics line");
            let map = v.as_object_mut().expect("an object");
            for key in ["wall_s", "steps_per_s", "timings"] {
                map.remove(key).expect("a clock field");
            }
            v
        })
        .collect()
}

/// Copies the directory `from` into `to` (created), files and folders alike: a test's own copy
/// of a run that other tests use at the same time.
pub fn copy_dir(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).expect("create the copy");
    for entry in std::fs::read_dir(from).expect("read the directory") {
        let entry = entry.expect("a directory entry");
        let target = to.join(entry.file_name());
        if entry.file_type().expect("a file type").is_dir() {
            copy_dir(&entry.path(), &target);
        } else {
            std::fs::copy(entry.path(), &target).expect("copy a file");
        }
    }
}

/// Every file under `dir` with its bytes, in path order.
pub fn snapshot(dir: &Path) -> Vec<(std::path::PathBuf, Vec<u8>)> {
    let mut files = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for entry in std::fs::read_dir(&d).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                stack.push(path);
            } else {
                files.push((path.clone(), std::fs::read(&path).unwrap()));
            }
        }
    }
    files.sort();
    files
}

/// How [`damage_tensor`] changes one tensor of a checkpoint file.
#[derive(Debug, Clone, Copy)]
pub enum TensorDamage {
    /// A `[1, n]` weight where the network has `[m, n]`: a copy would broadcast it.
    Broadcast,
    /// A scalar where the network has a matrix.
    Scalar,
    /// The first value NaN.
    NotANumber,
    /// The first value infinite.
    Infinite,
    /// The values stored as float64.
    Float64,
}

/// Rewrites the first two-dimensional tensor (of more than one row) of the safetensors file
/// `path` as `damage` says, leaving the others as they were (safetensors: a little-endian header
/// length, the JSON header, the data). Returns the tensor's name.
pub fn damage_tensor(path: &Path, damage: TensorDamage) -> String {
    let bytes = std::fs::read(path).unwrap();
    let length = u64::from_le_bytes(bytes[..8].try_into().unwrap()) as usize;
    let header: serde_json::Map<String, serde_json::Value> =
        serde_json::from_slice(&bytes[8..8 + length]).unwrap();
    let data = &bytes[8 + length..];
    let mut tensors: Vec<(String, serde_json::Value)> = header
        .into_iter()
        .filter(|(name, _)| name != "__metadata__")
        .collect();
    tensors.sort_by_key(|(_, info)| info["data_offsets"][0].as_u64().unwrap());
    let target = tensors
        .iter()
        .find(|(_, info)| {
            let shape = info["shape"].as_array().unwrap();
            shape.len() == 2 && shape[0].as_u64().unwrap() > 1
        })
        .expect("a matrix of more than one row")
        .0
        .clone();
    let mut out_header = serde_json::Map::new();
    let mut out_data = Vec::new();
    for (name, info) in tensors {
        let (start, end) = (
            info["data_offsets"][0].as_u64().unwrap() as usize,
            info["data_offsets"][1].as_u64().unwrap() as usize,
        );
        let mut values: Vec<u8> = data[start..end].to_vec();
        let mut info = info.clone();
        if name == target {
            let shape: Vec<u64> = info["shape"]
                .as_array()
                .unwrap()
                .iter()
                .map(|d| d.as_u64().unwrap())
                .collect();
            match damage {
                TensorDamage::Broadcast => {
                    values.truncate(4 * shape[1] as usize);
                    info["shape"] = serde_json::json!([1, shape[1]]);
                }
                TensorDamage::Scalar => {
                    values.truncate(4);
                    info["shape"] = serde_json::json!([]);
                }
                TensorDamage::NotANumber => values[..4].copy_from_slice(&f32::NAN.to_le_bytes()),
                TensorDamage::Infinite => {
                    values[..4].copy_from_slice(&f32::INFINITY.to_le_bytes());
                }
                TensorDamage::Float64 => {
                    values = values
                        .chunks_exact(4)
                        .flat_map(|b| {
                            f64::from(f32::from_le_bytes(b.try_into().unwrap())).to_le_bytes()
                        })
                        .collect();
                    info["dtype"] = "F64".into();
                }
            }
        }
        info["data_offsets"] = serde_json::json!([out_data.len(), out_data.len() + values.len()]);
        out_data.extend(values);
        out_header.insert(name, info);
    }
    let text = serde_json::to_vec(&out_header).unwrap();
    let mut file = (text.len() as u64).to_le_bytes().to_vec();
    file.extend(&text);
    file.extend(out_data);
    std::fs::write(path, file).unwrap();
    target
}

/// [`snapshot`] without the run lock's note of who held it last (`task.lock`), which every
/// command that takes the lock rewrites: the data of a run directory.
pub fn data_snapshot(dir: &Path) -> Vec<(std::path::PathBuf, Vec<u8>)> {
    snapshot(dir)
        .into_iter()
        .filter(|(path, _)| path.file_name().is_none_or(|n| n != "task.lock"))
        .collect()
}

// Shared by the commands' tests: a tiny trained run and its evaluations.

/// A tiny training configuration (small networks, small budget) written into `dir`.
pub fn tiny_config(dir: &std::path::Path) -> std::path::PathBuf {
    // The Cursor's layer of the presets, on LightsOut.
    let layer = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../configs/cursor.toml"
    ))
    .unwrap();
    let text = format!("env = \"lightsout-cursor\"\n{layer}")
        .replace("env_steps = 500000", "env_steps = 600")
        .replace("hidden = [256, 256]", "hidden = [32, 32]")
        .replace("sampled_episodes = 256", "sampled_episodes = 32")
        .replace("recent_episodes = 256", "recent_episodes = 16")
        .replace("eval_every = 100", "eval_every = 5")
        .replace("checkpoint_every = 100", "checkpoint_every = 5")
        .replace("eval_seeds = 20", "eval_seeds = 1")
        // Tests run side by side: SAC taking a second thread would oversubscribe the cores.
        .replace("sac_threads_alone = 2", "sac_threads_alone = 0")
        .replace("portable_numerics = false", "portable_numerics = true");
    let path = dir.join("tiny.toml");
    std::fs::write(&path, text).unwrap();
    path
}

/// A copy of the shared tiny run at `to`, for a test that writes into it.
pub fn copy_tiny_run(to: &std::path::Path) {
    copy_dir(&tiny_run().join("run"), to);
}

/// The stem of the files [`evaluate_two_boards_of_depths_1_2`] writes: named by every part of
/// its protocol that departs from the standard one.
pub const TWO_BOARDS: &str = "evaluation-replan-depths-1-2-boards-2-expanded-2000";

/// `seads evaluate --json` of `run` with re-planning on 2 boards of depths 1 and 2 (searches
/// bounded by 2,000 states); it writes [`TWO_BOARDS`]`*` into the run.
pub fn evaluate_two_boards_of_depths_1_2(run: &str) -> serde_json::Value {
    serde_json::from_slice(&evaluate_two_boards_of_depths_1_2_output(run).stdout).unwrap()
}

/// What [`evaluate_two_boards_of_depths_1_2`] prints, standard error included.
pub fn evaluate_two_boards_of_depths_1_2_output(run: &str) -> std::process::Output {
    seads_ok(&[
        "evaluate",
        "--run",
        run,
        "--depths",
        "1-2",
        "--boards",
        "2",
        "--max-expanded",
        "2000",
        "--replan",
        "--json",
    ])
}

/// One tiny trained run shared by the planning tests.
pub fn tiny_run() -> &'static std::path::Path {
    static RUN: std::sync::OnceLock<tempfile::TempDir> = std::sync::OnceLock::new();
    RUN.get_or_init(|| {
        let dir = tempfile::tempdir().unwrap();
        let config = tiny_config(dir.path());
        let run = dir.path().join("run");
        seads_ok(&[
            "train",
            "--config",
            config.to_str().unwrap(),
            "--out",
            run.to_str().unwrap(),
            "--quiet",
        ]);
        dir
    })
    .path()
}

/// What a process did with a command line: its exit code, or `None` if it was still working
/// after `patience` (then it is killed), and its stderr.
pub fn run_for(args: &[String], patience: std::time::Duration) -> (Option<i32>, String) {
    use std::io::Read as _;
    use std::os::unix::process::ExitStatusExt;
    let mut child = seads_command()
        .args(args)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let start = std::time::Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break Some(status);
        }
        if start.elapsed() > patience {
            let _ = child.kill();
            let _ = child.wait();
            break None;
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    };
    let mut stderr = String::new();
    let _ = child.stderr.take().unwrap().read_to_string(&mut stderr);
    if let Some(status) = status {
        assert_eq!(status.signal(), None, "{args:?} died of a signal: {stderr}");
    }
    (status.and_then(|s| s.code()), stderr)
}

/// Copies the run's last checkpoint under the epoch before it, which stands in for an earlier
/// checkpoint (a run keeps only its last); returns the last epoch and the earlier one.
pub fn add_an_earlier_checkpoint(run: &std::path::Path) -> (u64, u64) {
    let (last, _) = seads_rl::store::checkpoints(run).unwrap().pop().unwrap();
    let earlier = last - 1;
    let status = std::process::Command::new("cp")
        .arg("-r")
        .arg(run.join(format!("checkpoints/epoch-{last:06}")))
        .arg(run.join(format!("checkpoints/epoch-{earlier:06}")))
        .status()
        .unwrap();
    assert!(status.success());
    (last, earlier)
}
