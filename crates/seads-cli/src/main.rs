//! `seads`: the command line of the SEADS workspace — the only crate that prints.
#![allow(clippy::print_stdout, clippy::print_stderr)] // printing is this crate's job

/// `println!` that returns a failed write (a full disk behind stdout, `> /dev/full`) as this
/// function's error, `writing to standard output: …`, instead of panicking. (A closed pipe
/// ends the process quietly before any write fails: `die_quietly_on_closed_pipes`.)
macro_rules! outln {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        writeln!(std::io::stdout().lock(), $($arg)*)
            .map_err(|e| anyhow::anyhow!("writing to standard output: {e}"))?;
    }};
}

mod demo;
mod envs;
mod episodes;
mod games;
mod kernels;
mod migrate;
mod numbers;
mod paths;

mod plan;
mod plot;
mod report;
mod sweep;
mod train;
mod uarm;

use seads_nn::Resolve as _;
use std::process::ExitCode;

use clap::{Parser, Subcommand};

/// `seads --version`: the version, the commit the binary was built from and whether its working
/// tree had uncommitted changes (what a run's provenance records).
const VERSION: &str = concat!(
    env!("CARGO_PKG_VERSION"),
    " (commit ",
    env!("VERGEN_GIT_SHA"),
    ", uncommitted changes: ",
    env!("VERGEN_GIT_DIRTY"),
    ")"
);

/// SEADS: learn reward-free manipulation skills that play board games, and solve boards with them.
#[derive(Debug, Parser)]
#[command(name = "seads", version = VERSION, about, long_about = None, propagate_version = true)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// The discrete board games: depth tables, train/test splits, optimal solutions.
    #[command(subcommand)]
    Games(games::GamesCommand),
    /// The main job on embedded defaults: train a small agent on lightsout-cursor, evaluate it
    /// by planning on test boards, and write the figures.
    Run(demo::RunArgs),
    /// List the embodied environments with their dimensions.
    Envs {
        /// Print JSON.
        #[arg(long)]
        json: bool,
    },
    /// Draw a top view of an environment after reset (board, tile numbers, manipulator), with a
    /// side view of the middle row below it where fields differ in height (lightsout3d-jaco).
    Render(envs::RenderArgs),
    /// Measure environment steps per second with random actions.
    EnvBench(envs::BenchArgs),
    /// Train SEADS skills and their forward model on an environment (no task reward), or the
    /// flat SAC baseline on the task reward (`--algorithm sac`).
    Train(train::TrainArgs),
    /// Solve one board with a trained agent: plan with its forward model, execute its skills.
    Solve(plan::SolveArgs),
    /// Task success of a trained agent per solution depth on test boards (the paper's protocol).
    Evaluate(plan::EvaluateArgs),
    /// Fit SEADS's forward model to the frozen skills of any trained skill learner (DIAYN, VIC,
    /// SEADS), so that they can be planned with (`seads evaluate --fitted-model`).
    FitModel(plan::FitModelArgs),
    /// Figures of a run: skill coverage, success per depth, skill trajectories, push points.
    Plot(plot::PlotArgs),
    /// Planner speed: BFS with a forward model fitted to the LightsOut move table.
    PlanBench(plan::PlanBenchArgs),
    /// Record episodes (random actions or a trained agent) as JSON Lines.
    Record(episodes::RecordArgs),
    /// Replay recorded episodes exactly and recompute their observations and moves.
    Replay(episodes::ReplayArgs),
    /// Tables, Mann–Whitney tests and figures over sweeps and runs (the paper's Table 1 and more).
    Report(report::ReportArgs),
    /// RESULTS' summary table, computed from each study's claims.toml and its committed runs.
    Summary(report::SummaryArgs),
    /// Rewrite runs' configurations, study manifests and evaluation files of older versions'
    /// layouts into today's (once: every other command reads today's layout only).
    Migrate(migrate::MigrateArgs),
    /// Studies over seeds and variants: plan from a manifest, run here or on Slurm, status.
    #[command(subcommand)]
    Sweep(sweep::SweepCommand),
    /// The real robot (uArm Swift Pro + LightsOut tablet) or its simulated twin (`--port sim`).
    #[command(subcommand)]
    Uarm(uarm::UarmCommand),
}

/// Input the user gave that cannot be used (exit code 2, like a usage error).
#[derive(Debug, thiserror::Error)]
#[error(transparent)]
pub struct BadInput(#[from] pub anyhow::Error);

/// The binary, as provenance records it: version and the commit it was built from (`build.rs`).
pub fn build() -> seads_study::provenance::Build<'static> {
    seads_study::provenance::Build {
        version: env!("CARGO_PKG_VERSION"),
        commit: env!("VERGEN_GIT_SHA"),
        dirty: env!("VERGEN_GIT_DIRTY") == "true",
    }
}

/// The most threads or processes an option may ask of this machine: four per core. More would
/// only time-share the cores, and a few hundred thousand exhaust the machine.
pub fn max_threads() -> usize {
    4 * std::thread::available_parallelism().map_or(1, |n| n.get())
}

/// `value` of `option` (threads, workers, cores), as bad input where it exceeds
/// [`max_threads`].
pub fn check_threads(option: &str, value: usize) -> anyhow::Result<()> {
    let most = max_threads();
    if value > most {
        return Err(BadInput(anyhow::anyhow!(
            "{option} {value} is more than this machine can run: at most {most} (four per core)"
        ))
        .into());
    }
    Ok(())
}

/// A progress bar of `len` steps drawn with `template` (indicatif's), hidden when `quiet`.
pub fn progress_bar(len: u64, quiet: bool, template: &str) -> indicatif::ProgressBar {
    if quiet {
        return indicatif::ProgressBar::hidden();
    }
    let style = indicatif::ProgressStyle::with_template(template).expect("a valid template");
    indicatif::ProgressBar::new(len).with_style(style.progress_chars("=> "))
}

/// `device`, once it is known to be usable here; a device that is not (no CUDA in this build, no
/// GPU, an index past the GPUs) is bad input, said in one line.
pub fn usable_device(device: seads_rl::ComputeDevice) -> anyhow::Result<seads_rl::ComputeDevice> {
    device.resolve().map_err(|e| BadInput(e.into()))?;
    Ok(device)
}

/// The boolean environment variable `name`: `1`, `true`, `yes` and `on` (in any case) are true;
/// `0`, `false`, `no`, `off`, an empty value and an unset variable are false. Any other value is
/// bad input naming the variable, since the user set it without a flag to point to.
pub fn env_flag(name: &str) -> anyhow::Result<bool> {
    let Some(value) = std::env::var_os(name) else {
        return Ok(false);
    };
    let text = value.to_string_lossy();
    match text.trim().to_ascii_lowercase().as_str() {
        "1" | "true" | "yes" | "on" => Ok(true),
        "" | "0" | "false" | "no" | "off" => Ok(false),
        _ => Err(bad_input(anyhow::anyhow!(
            "environment variable {name}={text:?} is not a boolean: use 1 or 0, true or false, \
             yes or no, on or off"
        ))
        .into()),
    }
}

/// Any error as bad input (exit 2).
pub fn bad_input(e: impl Into<anyhow::Error>) -> BadInput {
    BadInput(e.into())
}

/// A study library error as the binary's: input the user must fix is bad input (exit 2).
pub fn study_error(e: seads_study::StudyError) -> anyhow::Error {
    if e.is_invalid() {
        BadInput(e.into()).into()
    } else {
        e.into()
    }
}

/// An evaluation's error as the binary's: input the user must fix is bad input (exit 2).
pub fn eval_error(e: seads_evaluation::EvalError) -> anyhow::Error {
    if e.is_invalid() {
        BadInput(e.into()).into()
    } else {
        e.into()
    }
}

/// Takes the run directory `dir` for this command, the one writer it may have at a time (see
/// [`seads_rl::store::RunLock`]); another writer holding it is exit 2, naming it. Waits a moment, for a
/// `sweep status` that looks at the lock.
pub fn lock_run(dir: &std::path::Path) -> anyhow::Result<seads_rl::store::RunLock> {
    // Only a run directory is locked: anything else is said as such.
    run_config(dir)?;
    acquire(dir, std::time::Duration::from_secs(2))
}

/// The configuration of the run the user named in `dir`: a directory that is missing, is a file,
/// loops through links or holds no readable or valid `config.toml` is bad input (exit 2, one
/// line), as any malformed input is.
pub fn run_config(dir: &std::path::Path) -> anyhow::Result<seads_rl::TrainConfig> {
    seads_rl::load_config(dir).map_err(|e| {
        let what = anyhow::Error::from(e).context(format!("loading run {}", dir.display()));
        BadInput(what).into()
    })
}

/// Takes the directory of a new run for this command (creating it) before anything is written
/// into it: of two commands that start the same new run, one trains and the other is told, in one
/// line, that the directory is in use.
pub fn lock_new_run(dir: &std::path::Path) -> anyhow::Result<seads_rl::store::RunLock> {
    use anyhow::Context as _;
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    acquire(dir, std::time::Duration::ZERO)
}

/// The lock of `dir`, naming this command as its holder; another holder is bad input.
fn acquire(
    dir: &std::path::Path,
    patience: std::time::Duration,
) -> anyhow::Result<seads_rl::store::RunLock> {
    // Any argument, UTF-8 or not, as the lock's note of who holds it: at most 200 characters.
    let command: String = std::env::args_os()
        .map(|a| {
            let a = a.to_string_lossy();
            a.rsplit('/').next().unwrap_or_default().to_owned()
        })
        .collect::<Vec<_>>()
        .join(" ")
        .chars()
        .take(200)
        .collect();
    seads_rl::store::RunLock::acquire(dir, &command, patience).map_err(|e| match e {
        seads_run::RunError::Busy { .. } => BadInput(e.into()).into(),
        other => anyhow::Error::from(other),
    })
}

/// Ends the process on a command line that clap refused: `--help` and `--version` print as
/// usual; a usage error becomes one `error:` line naming `--help`, exit code 2, as every other
/// bad input does.
fn usage_error(e: clap::Error) -> ! {
    if !e.use_stderr() {
        e.exit();
    }
    eprintln!("{}", usage_message(&e));
    std::process::exit(2)
}

/// A usage error on one line: the first paragraph of clap's message (the message, and any
/// arguments it lists on the lines below it), pointing to `--help`.
fn usage_message(e: &clap::Error) -> String {
    let text = e.to_string();
    let message: Vec<&str> = text
        .lines()
        .map(str::trim)
        .skip_while(|l| l.is_empty())
        .take_while(|l| !l.is_empty())
        .collect();
    if message.is_empty() {
        "error: invalid arguments (see --help)".to_owned()
    } else {
        format!("{} (see --help)", message.join(" "))
    }
}

/// Whether `command` trains or plans, where libtorch runs parallel regions on several threads
/// (the planner's 8-bit products open one per batch).
fn runs_libtorch_in_parallel(command: &Command) -> bool {
    matches!(
        command,
        Command::Run(_)
            | Command::Train(_)
            | Command::Solve(_)
            | Command::Evaluate(_)
            | Command::FitModel(_)
            | Command::Plot(_)
            | Command::PlanBench(_)
            | Command::Sweep(sweep::SweepCommand::Run(_) | sweep::SweepCommand::Task(_))
            | Command::Uarm(uarm::UarmCommand::Train(_) | uarm::UarmCommand::Evaluate(_))
    )
}

/// Ends the process quietly when its output pipe closes (`seads sweep status | head`), as other
/// Unix tools do: Rust ignores SIGPIPE, so a print to a closed pipe would panic instead.
fn die_quietly_on_closed_pipes() {
    #[cfg(unix)]
    #[allow(unsafe_code)]
    // SAFETY: restores the default disposition of one signal, once, before any other thread
    // exists; no handler of this program is replaced.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
}

/// An error and its causes on one line (as `{:#}` joins them), each cut at its first line:
/// libtorch's messages carry a C++ stack trace on the lines after the first.
fn one_line(err: &anyhow::Error) -> String {
    err.chain()
        .filter_map(|cause| {
            let text = cause.to_string();
            text.lines()
                .map(str::trim)
                .find(|l| !l.is_empty())
                .map(str::to_owned)
        })
        .collect::<Vec<_>>()
        .join(": ")
}

fn main() -> ExitCode {
    seads_nn::process::keep_freed_memory();
    die_quietly_on_closed_pipes();
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => usage_error(e),
    };
    if runs_libtorch_in_parallel(&cli.command) {
        seads_nn::process::spin_briefly_in_libgomp();
    }
    // Every evaluation file this process writes names the binary (`evaluated_by`).
    build().declare();
    let result = match cli.command {
        Command::Games(cmd) => games::run(cmd),
        Command::Run(args) => demo::run(args),
        Command::Envs { json } => envs::envs(json),
        Command::Render(args) => envs::render(args),
        Command::EnvBench(args) => envs::env_bench(args),
        Command::Train(args) => train::train(args),
        Command::Solve(args) => plan::solve_board(args),
        Command::Evaluate(args) => plan::evaluate_run(args),
        Command::FitModel(args) => plan::fit_model(args),
        Command::Plot(args) => plot::plot(args),
        Command::PlanBench(args) => plan::plan_bench(args),
        Command::Record(args) => episodes::record(args),
        Command::Replay(args) => episodes::replay(args),
        Command::Sweep(cmd) => sweep::run(cmd),
        Command::Report(args) => report::report(args),
        Command::Summary(args) => report::summary(args),
        Command::Migrate(args) => migrate::migrate(args),
        Command::Uarm(uarm::UarmCommand::Calibrate(args)) => uarm::calibrate(args),
        Command::Uarm(uarm::UarmCommand::Train(args)) => uarm::train(args),
        Command::Uarm(uarm::UarmCommand::Evaluate(args)) => uarm::evaluate_run(args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(err) => {
            eprintln!("error: {}", one_line(&err));
            if err.is::<BadInput>() {
                ExitCode::from(2)
            } else if sweep::is_taken(&err) {
                ExitCode::from(sweep::TAKEN_EXIT)
            } else {
                ExitCode::FAILURE
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use clap::CommandFactory;
    use clap::error::ErrorKind;

    use super::*;

    /// Every command that runs (a command without subcommands), with the words that name it.
    fn leaves(
        command: &clap::Command,
        path: &[String],
        out: &mut Vec<(Vec<String>, clap::Command)>,
    ) {
        if command.get_subcommands().next().is_none() {
            out.push((path.to_vec(), command.clone()));
        }
        for sub in command.get_subcommands() {
            let mut path = path.to_vec();
            path.push(sub.get_name().to_owned());
            leaves(sub, &path, out);
        }
    }

    /// clap's refusal of `seads PATH --OPTION=VALUE` for that value, if it refuses the value
    /// (other errors, such as a required argument left out, come after the values are read).
    fn refusal(path: &[String], option: &str, value: &str) -> Option<clap::Error> {
        let arg = format!("--{option}={value}");
        let args = std::iter::once("seads")
            .chain(path.iter().map(String::as_str))
            .chain([arg.as_str()]);
        let refused = [ErrorKind::ValueValidation, ErrorKind::InvalidValue];
        Cli::try_parse_from(args)
            .err()
            .filter(|e| refused.contains(&e.kind()))
    }

    /// Every option that takes a number (accepts one of 1, 5, 0.5 and refuses a word) refuses
    /// negative, NaN and infinite values as a one-line usage error, so no such value reaches
    /// the code (issue 13: `--timeout=-1` and `--timeout nan` panicked). Found from the command
    /// line's definition, so a new option is checked without being listed.
    #[test]
    fn every_numeric_option_refuses_negative_nan_and_infinite_values() {
        let mut commands = Vec::new();
        leaves(&Cli::command(), &[], &mut commands);
        let mut checked = Vec::new();
        for (path, command) in &commands {
            for arg in command.get_arguments() {
                let Some(long) = arg.get_long() else { continue };
                let numeric = arg.get_action().takes_values()
                    && ["1", "5", "0.5"]
                        .iter()
                        .any(|v| refusal(path, long, v).is_none())
                    && refusal(path, long, "word").is_some();
                if !numeric {
                    continue;
                }
                for value in ["-1", "nan", "inf", "-inf"] {
                    let e = refusal(path, long, value)
                        .unwrap_or_else(|| panic!("seads {path:?} --{long}={value} is accepted"));
                    let message = usage_message(&e);
                    assert!(
                        message.starts_with("error") && message.lines().count() == 1,
                        "seads {path:?} --{long}={value}: {message}"
                    );
                }
                checked.push(format!("{} --{long}", path.join(" ")));
            }
        }
        // The options the end-to-end test listed by hand before this one found them.
        for known in [
            "run --timeout",
            "render --spacing",
            "uarm calibrate --d-max-mm",
            "plan-bench --threads",
        ] {
            assert!(
                checked.iter().any(|c| c == known),
                "{known} not found: {checked:?}"
            );
        }
    }
}
