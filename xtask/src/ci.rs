//! `cargo xtask ci`: the one command CI and developers run before a change lands.

use std::io::{BufRead, BufReader};
use std::process::{Command, Stdio};

use anyhow::{Context, Result, bail};

use crate::{PACKAGE, root, setup, step, step_with_env};

/// Set-up, formatting, lints (warnings are errors), then every test of every crate, the
/// integration tests under `tests/`, the benches in test mode (each bench runs once) and the
/// Python package's pytest suite. Ends
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
    // `cargo xtask package` verifies them. Offline: each package's lock file comes from the
    // workspace's, whose crates the lint step has just fetched, so updating the registry's index
    // adds nothing to the check but a wait on the network (24.7 s against 1.5 s in a clone).
    step(
        "cargo",
        &[&PACKAGE[..], &["--no-verify", "--allow-dirty", "--offline"]].concat(),
    )?;
    let mut totals = Totals::default();
    test(&["test", "--workspace", "--doc"], &mut totals)?;
    test(&["test", "--workspace", "--all-targets"], &mut totals)?;
    python_tests(&mut totals)?;
    println!("ci: {} passed, {} failed", totals.passed, totals.failed);
    Ok(())
}

/// The Python package: installed from `crates/seads-py` into the virtual environment
/// `target/py-venv` (made on first use; pip fetches maturin, NumPy, Gymnasium and pytest), built
/// with the dev profile into the workspace's `target/` (reusing the workspace build's
/// dependencies: the package's manifest asks for the features the workspace turns on, since
/// maturin builds it alone), then its pytest suite with the newest Gymnasium and, leaving out the
/// tests that touch no Gymnasium API, with the lowest; each closing line is added to the totals.
fn python_tests(totals: &mut Totals) -> Result<()> {
    let python = py_venv()?;
    pip_install(
        &python,
        &["./crates/seads-py[test]"],
        &[("MATURIN_PEP517_ARGS", "--profile dev")],
    )?;
    // The newest Gymnasium first, then the lowest the package supports (its pin).
    pip_install(&python, &["--upgrade", "gymnasium"], &[])?;
    pytest(&python, &[], totals)?;
    let lowest = lowest_gymnasium()?;
    pip_install(&python, &[&format!("gymnasium=={lowest}")], &[])?;
    eprintln!("xtask: again with gymnasium {lowest}, the lowest the package supports");
    // The tests that touch no Gymnasium API (marked in the suite) ran once already.
    pytest(&python, &["-m", "not without_gymnasium"], totals)
}

/// `python -m pip install --quiet <args>` with extra environment variables.
fn pip_install(python: &str, args: &[&str], env: &[(&str, &str)]) -> Result<()> {
    let quiet = [
        "-m",
        "pip",
        "install",
        "--quiet",
        "--disable-pip-version-check",
    ];
    step_with_env(python, &[&quiet[..], args].concat(), env)
}

/// The Python of the virtual environment `target/py-venv`, made on first use.
pub fn py_venv() -> Result<String> {
    let venv = root().join("target").join("py-venv");
    let python = venv.join("bin").join("python");
    if !python.exists() {
        step("python3", &["-m", "venv", &venv.to_string_lossy()])?;
    }
    Ok(python.to_string_lossy().into_owned())
}

/// `cargo xtask package`'s wheel: one stripped, optimised abi3 wheel of the Python package for
/// every CPython ≥ 3.9 of this platform, built by maturin (installed into `target/py-venv`) into
/// `target/wheels`. Returns its path.
pub fn wheel() -> Result<std::path::PathBuf> {
    let python = py_venv()?;
    pip_install(&python, &["maturin>=1.9,<2"], &[])?;
    let out = root().join("target").join("wheels");
    // A wheel of an earlier build would be taken for this one.
    if out.exists() {
        std::fs::remove_dir_all(&out).context("clearing target/wheels")?;
    }
    step(
        &python,
        &[
            "-m",
            "maturin",
            "build",
            "--release",
            "--strip",
            "--manifest-path",
            "crates/seads-py/Cargo.toml",
            "--out",
            &out.to_string_lossy(),
        ],
    )?;
    let wheels: Vec<_> = std::fs::read_dir(&out)?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "whl"))
        .collect();
    match wheels.as_slice() {
        [wheel] if wheel.to_string_lossy().contains("-abi3-") => Ok(wheel.clone()),
        _ => bail!("maturin built {wheels:?}, not one abi3 wheel"),
    }
}

/// The lowest Gymnasium `crates/seads-py/pyproject.toml` asks for (`"gymnasium>=X"`).
fn lowest_gymnasium() -> Result<String> {
    let text = std::fs::read_to_string(root().join("crates/seads-py/pyproject.toml"))?;
    text.split('"')
        .find_map(|item| item.strip_prefix("gymnasium>="))
        .map(str::to_owned)
        .context("crates/seads-py/pyproject.toml pins no gymnasium>=X")
}

/// The package's pytest suite with `python` and `extra` arguments; its closing line is added to
/// the totals.
fn pytest(python: &str, extra: &[&str], totals: &mut Totals) -> Result<()> {
    let shown: Vec<&str> = extra
        .iter()
        .copied()
        .chain(["crates/seads-py/tests"])
        .collect();
    eprintln!("xtask: $ {python} -m pytest {}", shown.join(" "));
    // The binary the Rust tests built, for the tests that train a run with it (`SEADS_BIN`
    // switches them on).
    let target = std::env::var_os("CARGO_TARGET_DIR")
        .map_or_else(|| root().join("target"), std::path::PathBuf::from);
    let output = Command::new(python)
        .args(["-m", "pytest", "-q", "-p", "no:cacheprovider"])
        .args(extra)
        .arg("crates/seads-py/tests")
        .env("SEADS_BIN", target.join("debug").join("seads"))
        .current_dir(root())
        .output()
        .context("could not start pytest")?;
    let text = String::from_utf8_lossy(&output.stdout);
    print!("{text}");
    eprint!("{}", String::from_utf8_lossy(&output.stderr));
    // The closing line: "3 failed, 29 passed, 14 warnings in 1.11s".
    let last = text
        .lines()
        .rev()
        .find(|l| l.contains(" in "))
        .unwrap_or("");
    let counted = |label: &str| {
        last.trim_matches('=')
            .split(',')
            .find_map(|part| {
                part.trim()
                    .split(" in ")
                    .next()?
                    .strip_suffix(label)?
                    .trim()
                    .parse()
                    .ok()
            })
            .unwrap_or(0u64)
    };
    totals.passed += counted(" passed");
    totals.failed += counted(" failed") + counted(" error") + counted(" errors");
    if !output.status.success() {
        println!(
            "ci: {} passed, {} failed",
            totals.passed,
            totals.failed.max(1)
        );
        bail!("pytest failed ({})", output.status);
    }
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
    let mut command = Command::new("cargo");
    if std::env::var_os("OMP_WAIT_POLICY").is_none() && std::env::var_os("GOMP_SPINCOUNT").is_none()
    {
        // libtorch's OpenMP threads sleep at once when idle instead of spinning: the harness runs
        // two tests at a time, each with libtorch threads for every core, and on CI's two cores
        // the spinning held the cores the working threads needed (seads-rl's
        // `sac_learns_to_track_a_target` beside three busy processes: 175 s, and 12 s passive).
        // Waiting changes no number (`seads_nn::process::spin_briefly_in_libgomp`).
        command.env("OMP_WAIT_POLICY", "PASSIVE");
    }
    let mut child = command
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
