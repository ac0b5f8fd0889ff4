//! `cargo xtask ci`: the one command CI and developers run before a change lands.

use std::io::{BufRead, BufReader};
use std::process::{Command, Stdio};

use anyhow::{Context, Result, bail};

use crate::{PACKAGE, root, setup, step, step_with_env};

/// Set-up, formatting, lints (warnings are errors), then every test of every crate, the
/// integration tests under `tests/` and the benches in test mode (each bench runs once). Ends
/// with one line summing up every test binary: `N passed, M failed`.
pub fn run() -> Result<()> {
    setup()?;
    step("cargo", &["fmt", "--all", "--check"])?;
    step(
        "cargo",
        &[
            "clippy",
            "--workspace",
            "--all-targets",
            "--",
            "-D",
            "warnings",
        ],
    )?;
    // The API docs build without a warning (broken intra-doc links included).
    step_with_env(
        "cargo",
        &["doc", "--workspace", "--no-deps"],
        &[("RUSTDOCFLAGS", "-D warnings")],
    )?;
    // Every library crate packages (manifest metadata, README, only files inside the crate).
    // Without verification: building each package again from scratch would double CI's time;
    // `cargo xtask package` verifies them.
    step(
        "cargo",
        &[&PACKAGE[..], &["--no-verify", "--allow-dirty"]].concat(),
    )?;
    let mut totals = Totals::default();
    test(&["test", "--workspace", "--doc"], &mut totals)?;
    test(&["test", "--workspace", "--all-targets"], &mut totals)?;
    println!("ci: {} passed, {} failed", totals.passed, totals.failed);
    Ok(())
}

#[derive(Default)]
struct Totals {
    passed: u64,
    failed: u64,
}

/// Runs `cargo <args>`, echoing its output and adding up its `test result:` lines.
fn test(args: &[&str], totals: &mut Totals) -> Result<()> {
    eprintln!("xtask: $ cargo {}", args.join(" "));
    let mut child = Command::new("cargo")
        .args(args)
        .current_dir(root())
        .stdout(Stdio::piped())
        .spawn()
        .context("could not start cargo")?;
    let stdout = child.stdout.take().expect("piped");
    for line in BufReader::new(stdout).lines() {
        let line = line?;
        println!("{line}");
        if let Some(rest) = line.strip_prefix("test result: ") {
            totals.passed += count(rest, " passed");
            totals.failed += count(rest, " failed");
        }
    }
    let status = child.wait()?;
    if !status.success() {
        println!(
            "ci: {} passed, {} failed",
            totals.passed,
            totals.failed.max(1)
        );
        bail!("`cargo {}` failed ({status})", args.join(" "));
    }
    Ok(())
}

/// The number before `label` in a `test result:` line ("ok. 5 passed; 0 failed; …").
fn count(line: &str, label: &str) -> u64 {
    line.split(';')
        .find_map(|part| {
            part.trim()
                .trim_start_matches("ok. ")
                .trim_start_matches("FAILED. ")
                .strip_suffix(label)?
                .parse()
                .ok()
        })
        .unwrap_or(0)
}
