//! `cargo xtask <command>`: project automation, so that local checks and CI are one command.
#![allow(clippy::print_stdout, clippy::print_stderr)] // a command-line tool

mod ci;
mod gen_splits;
mod golden;
mod population_bench;

use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode};

use anyhow::{Context, Result, bail};

const HELP: &str = "\
cargo xtask <command>

Commands:
  run          set up libtorch if needed, build in release mode and run `seads run` (the main job)
  ci           set up, then fmt --check, clippy -D warnings, doc -D warnings, package, every test,
               and the Python package's pytest suite in target/py-venv (CI)
  setup        install libtorch for tch (once per machine, linked as .libtorch; scripts/setup.sh);
               `setup --cuda` adds the CUDA libraries (then build with --features cuda)
  package      cargo package every library crate in dependency order, building each package (slow),
               then the Python package's one abi3 wheel (every CPython >= 3.9) into target/wheels
  gen-splits   write data/depth_counts.csv and data/split_counts.csv from a fresh enumeration
  golden       train the golden run (data/golden/) and say whether this processor repeats it
               (`--record` makes this processor's run the golden); not part of ci
  population-bench
               populations of K LightsOutCursor runs against the same runs one by one, summed
               steps/s (`population-bench --help`); not part of ci
";

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let result = match args.first().map(String::as_str) {
        Some("run") => run_main_job(&args[1..]),
        Some("ci") => ci::run(),
        Some("setup") => match args.get(1).map(String::as_str) {
            None => setup(),
            Some("--cuda") => step("bash", &["scripts/setup.sh", "--cuda"]),
            Some(other) => {
                eprint!("unknown option {other:?} of setup\n\n{HELP}");
                return ExitCode::from(2);
            }
        },
        Some("package") => setup()
            .and_then(|()| step("cargo", &[&PACKAGE[..], &["--allow-dirty"]].concat()))
            .and_then(|()| ci::wheel())
            .map(|wheel| {
                println!("Python wheel: {}", wheel.display());
                println!(
                    "install it into any Python ≥ 3.9: pip install {}",
                    wheel.display()
                );
            }),
        Some("gen-splits") => gen_splits::run(&root()),
        Some("golden") => match args.get(1).map(String::as_str) {
            None => golden::run(&root(), false),
            Some("--record") => golden::run(&root(), true),
            Some(other) => {
                eprint!("unknown option {other:?} of golden\n\n{HELP}");
                return ExitCode::from(2);
            }
        },
        Some("population-bench") => population_bench::run(&root(), &args[1..]),
        Some("help" | "--help" | "-h") | None => {
            print!("{HELP}");
            Ok(())
        }
        Some(other) => {
            eprint!("unknown command {other:?}\n\n{HELP}");
            return ExitCode::from(2);
        }
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(err) => {
            eprintln!("xtask: {err:#}");
            ExitCode::FAILURE
        }
    }
}

/// The repository root (the parent of this crate's folder).
fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("xtask lives in the workspace")
        .to_path_buf()
}

/// `cargo package` of every library crate (the workspace without xtask, the tests crate and
/// the Python package, which is distributed as a wheel).
const PACKAGE: [&str; 8] = [
    "package",
    "--workspace",
    "--exclude",
    "xtask",
    "--exclude",
    "seads-tests",
    "--exclude",
    "seads-py",
];

/// Runs a command in the repository root and fails if it fails.
fn step(program: &str, args: &[&str]) -> Result<()> {
    step_with_env(program, args, &[])
}

/// Runs `program args` in the repository root with extra environment variables.
fn step_with_env(program: &str, args: &[&str], env: &[(&str, &str)]) -> Result<()> {
    eprintln!("xtask: $ {program} {}", args.join(" "));
    let status = Command::new(program)
        .args(args)
        .envs(env.iter().copied())
        .current_dir(root())
        .status()
        .with_context(|| format!("could not start {program}"))?;
    if !status.success() {
        bail!("`{program} {}` failed ({status})", args.join(" "));
    }
    Ok(())
}

fn setup() -> Result<()> {
    step("bash", &["scripts/setup.sh"])
}

fn run_main_job(extra: &[String]) -> Result<()> {
    setup()?;
    let mut args = vec![
        "run",
        "--release",
        "--quiet",
        "-p",
        "seads-cli",
        "--",
        "run",
    ];
    args.extend(extra.iter().map(String::as_str));
    step("cargo", &args)
}
