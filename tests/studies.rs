//! The long studies' scripts: the chains `scripts/studies/resume.sh` writes and starts.

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
    let status = std::process::Command::new("bash")
        .arg(root().join("scripts/studies/resume.sh"))
        .arg("--chains")
        .env("SEADS_SWEEPS", out.path())
        .env("SEADS_FROZEN", fake_frozen)
        .status()
        .expect("bash runs");
    assert!(status.success(), "resume.sh --chains: {status}");
    let frozen = frozen();
    let mut chains = 0;
    for entry in std::fs::read_dir(out.path()).expect("the chains' folder") {
        let path = entry.expect("an entry").path();
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        let text = std::fs::read_to_string(&path).expect("a chain");
        let parsed = std::process::Command::new("bash")
            .arg("-n")
            .arg(&path)
            .output()
            .expect("bash runs");
        assert!(
            parsed.status.success(),
            "{name} does not parse: {}",
            String::from_utf8_lossy(&parsed.stderr)
        );
        // The chains name the binaries under $SEADS_FROZEN, `arms-run.sh` under its $F.
        let used = [
            binaries(&text, &format!("{fake_frozen}/")),
            binaries(&text, "$F/"),
        ]
        .concat();
        for commit in used {
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
