//! The long studies' scripts: the chains `scripts/studies/resume.sh` writes and starts.

use std::path::Path;
use std::process::Command;

use crate::{read, root};

/// The commits `resume.sh` freezes (its `FROZEN=(…)` line).
fn frozen() -> Vec<String> {
    let script = read("scripts/studies/resume.sh");
    let line = script
        .lines()
        .find_map(|l| l.strip_prefix("FROZEN=("))
        .expect("resume.sh has a FROZEN=(…) line");
    line.trim_end_matches(')')
        .split_whitespace()
        .map(str::to_owned)
        .collect()
}

/// Runs `command` to its end; fails the test, with its error output, when it does not succeed.
fn run_ok(command: &mut Command, what: &str) {
    let out = command
        .output()
        .unwrap_or_else(|e| panic!("{what} does not start: {e}"));
    assert!(
        out.status.success(),
        "{what}: {}: {}",
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
}

/// Writes the chains into `sweeps` (`resume.sh --chains`), naming binaries under `frozen`.
fn write_chains(sweeps: &Path, frozen: &Path) {
    run_ok(
        Command::new("bash")
            .arg(root().join("scripts/studies/resume.sh"))
            .arg("--chains")
            .env("SEADS_SWEEPS", sweeps)
            .env("SEADS_FROZEN", frozen),
        "resume.sh --chains",
    );
}

/// The commit after each `prefix` in `text` (`<prefix><commit>/bin/seads`).
fn binaries<'a>(text: &'a str, prefix: &str) -> Vec<&'a str> {
    text.match_indices(prefix)
        .filter_map(|(at, _)| text[at + prefix.len()..].split_once("/bin/seads"))
        .map(|(commit, _)| commit)
        .collect()
}

/// Every chain `resume.sh --chains` writes parses (`bash -n`: an empty wait list once wrote
/// `while ; do`), runs only binaries the script freezes, and every chain that trains a sweep's runs
/// index by index leaves alone a run another chain holds, so two chains can share one sweep.
#[test]
fn the_study_chains_parse_and_run_only_frozen_binaries() {
    let out = tempfile::tempdir().expect("a temporary folder");
    let fake_frozen = "/nonexistent-frozen-for-the-test";
    write_chains(out.path(), Path::new(fake_frozen));
    let frozen = frozen();
    let mut chains = 0;
    for entry in std::fs::read_dir(out.path()).expect("the chains' folder") {
        let path = entry.expect("an entry").path();
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        let text = std::fs::read_to_string(&path).expect("a chain");
        run_ok(
            Command::new("bash").arg("-n").arg(&path),
            &format!("{name} parses"),
        );
        for commit in binaries(&text, &format!("{fake_frozen}/")) {
            assert!(
                frozen.iter().any(|f| f == commit),
                "{name} runs {commit}, which resume.sh does not freeze ({frozen:?})"
            );
        }
        if text.contains("sweep task") {
            assert!(
                text.contains("done | copied | running) continue"),
                "{name} trains index by index but would take a run another chain holds"
            );
        }
        chains += name.starts_with("chain") as usize;
    }
    assert!(chains >= 2, "resume.sh --chains wrote {chains} chains");
}

/// A restarted chain resumes the runs it had begun before it starts new ones, and leaves alone
/// the finished runs and those another chain holds. The chain runs against a stand-in `seads`
/// (a shell script) that reports a sweep's runs from a JSON file and, asked to train one, logs its
/// index and marks it done.
#[test]
fn a_restarted_chain_resumes_its_begun_runs_before_new_ones() {
    let out = tempfile::tempdir().expect("a temporary folder");
    let sweeps = out.path().join("sweeps");
    let frozen = out.path().join("frozen");
    std::fs::create_dir_all(&sweeps).expect("the sweeps' folder");
    write_chains(&sweeps, &frozen);
    let chain = std::fs::read_to_string(sweeps.join("chainS.sh")).expect("chainS.sh");
    // The sweep of its first segment and the binary that trains it: `B="<frozen>/<commit>/bin/seads"`
    // then `… sweep status <sweep> --json …`.
    let commit = binaries(&chain, &format!("{}/", frozen.display()))
        .first()
        .copied()
        .expect("chainS.sh names a frozen binary")
        .to_owned();
    let sweep = chain
        .split_once("sweep status ")
        .and_then(|(_, rest)| rest.split_whitespace().next())
        .expect("chainS.sh reads a sweep's status")
        .to_owned();
    // Its segments on that sweep, in order: each `for i in …; do` line is followed by the line
    // that reads the status of the sweep it trains.
    let lines: Vec<&str> = chain.lines().collect();
    let segments: Vec<Vec<usize>> = lines
        .windows(2)
        .filter(|w| w[1].contains(&format!("sweep status {sweep} ")))
        .filter_map(|w| w[0].trim().strip_prefix("for i in ")?.strip_suffix("; do"))
        .map(|l| {
            l.split_whitespace()
                .map(|i| i.parse().expect("an index"))
                .collect()
        })
        .collect();
    let (order, later) = segments
        .split_first()
        .expect("chainS.sh trains its first sweep");
    let later: Vec<usize> = later.concat();
    assert!(order.len() >= 4, "chainS.sh trains {order:?} of {sweep}");
    // The sweep: the first index finished, the second held by another chain, the last begun.
    let (finished, held, begun) = (order[0], order[1], order[order.len() - 1]);
    let last = order.iter().chain(&later).max().copied().unwrap_or(0);
    let runs: Vec<serde_json::Value> = (0..=last)
        .map(|i| {
            let status = match i {
                _ if i == finished => "done",
                _ if i == held => "running",
                _ => "pending",
            };
            let steps = if i == begun { 35_412 } else { 0 };
            serde_json::json!({"index": i, "status": status, "env_steps": steps})
        })
        .collect();
    let state = sweeps.join(format!("{sweep}.json"));
    std::fs::write(&state, serde_json::json!({ "runs": runs }).to_string()).expect("the state");
    // The stand-in stands for the first sweep's binary only: the other segments, by other
    // binaries, find none and train nothing.
    let fake = frozen.join(&commit).join("bin");
    std::fs::create_dir_all(&fake).expect("the stand-in's folder");
    let seads = r#"#!/usr/bin/env bash
# sweep status <sweep> --json | sweep task <sweep> --index <i> --cores 1
state="$(dirname "$0")/../../../sweeps/$3.json"
case $2 in
  status) cat "$state" ;;
  task)
    echo "$5" >> "$(dirname "$0")/../../../trained"
    python3 - "$state" "$5" <<'PY'
import json, sys
path, i = sys.argv[1], int(sys.argv[2])
state = json.load(open(path))
state["runs"][i]["status"] = "done"
json.dump(state, open(path, "w"))
PY
    ;;
esac
"#;
    let bin = fake.join("seads");
    std::fs::write(&bin, seads).expect("the stand-in");
    run_ok(Command::new("chmod").arg("+x").arg(&bin), "chmod");
    // Without its wait for other chains, which a study running on this machine would make long.
    let unwaited: String = chain
        .lines()
        .filter(|l| !l.starts_with("while "))
        .map(|l| format!("{l}\n"))
        .collect();
    run_ok(
        Command::new("bash")
            .arg("-c")
            .arg(unwaited)
            .current_dir(&sweeps),
        "chainS.sh",
    );
    let trained: Vec<usize> = std::fs::read_to_string(out.path().join("trained"))
        .expect("the stand-in logged the runs it trained")
        .lines()
        .map(|i| i.parse().expect("an index"))
        .collect();
    // The begun run first, then the segment's others but the finished and the held, then the
    // later segments' runs on the same sweep.
    let mut expected = vec![begun];
    expected.extend(order[2..order.len() - 1].iter().copied());
    expected.extend(later.iter().copied());
    assert_eq!(
        trained, expected,
        "chainS.sh's order {order:?}, then {later:?}"
    );
}
