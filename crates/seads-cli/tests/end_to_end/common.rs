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
