//! `seads train`: train a SEADS agent into a run directory, with a progress bar.

use std::path::PathBuf;

use anyhow::{Context, Result};
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use seads_rl::{Hook, Moment, Run, TrainConfig};

use crate::BadInput;

/// Arguments of `seads train`.
#[derive(Debug, Args)]
pub struct TrainArgs {
    /// Environment to train on, with its preset (the paper's settings; see `seads envs`).
    #[arg(long, required_unless_present_any = ["resume", "config"])]
    env: Option<String>,
    /// Run directory to create (config.toml, metrics.jsonl, checkpoints/).
    #[arg(long, required_unless_present = "resume")]
    out: Option<PathBuf>,
    /// Seed of every random choice (default: the preset's).
    #[arg(long)]
    seed: Option<u64>,
    /// Budget in environment steps (default: the preset's, 5·10⁵ Cursor, 10⁷ Reacher and Jaco).
    /// With --resume, raises the run's budget (finished or not) and records it in its config.
    #[arg(long)]
    env_steps: Option<u64>,
    /// A full configuration file (TOML) instead of the preset; see `configs/`.
    #[arg(long)]
    config: Option<PathBuf>,
    /// Continue the run in this directory from its last checkpoint. What a crash left (a torn
    /// metrics line, an unreadable checkpoint, temporary files) is repaired and reported.
    #[arg(long, conflicts_with_all = ["env", "out", "seed", "config"])]
    resume: Option<PathBuf>,
    /// No progress bar; one line per evaluation instead.
    #[arg(long)]
    quiet: bool,
}

/// Builds the configuration the arguments ask for.
fn config(args: &TrainArgs) -> Result<TrainConfig> {
    let mut config = match (&args.config, &args.env) {
        (Some(path), env) => {
            let text = std::fs::read_to_string(path)
                .with_context(|| format!("reading {}", path.display()))?;
            let mut config = TrainConfig::from_toml(&text)
                .map_err(|e| BadInput(anyhow::anyhow!("{}: {e}", path.display())))?;
            if let Some(env) = env {
                config.env = env.clone();
            }
            config
        }
        (None, Some(env)) => TrainConfig::preset(env).map_err(|e| BadInput(e.into()))?,
        (None, None) => unreachable!("clap requires --env or --config"),
    };
    if let Some(seed) = args.seed {
        config.seed = seed;
    }
    if let Some(steps) = args.env_steps {
        config.env_steps = steps;
    }
    config.validate().map_err(|e| BadInput(e.into()))?;
    Ok(config)
}

/// Runs `seads train`.
pub fn train(args: TrainArgs) -> Result<()> {
    let mut run = match &args.resume {
        Some(dir) => {
            if let Some(steps) = args.env_steps {
                seads_rl::raise_budget(dir, steps).map_err(|e| match e {
                    seads_rl::RlError::Config(_) => BadInput(e.into()).into(),
                    other => anyhow::Error::from(other),
                })?;
            }
            let config = seads_rl::load_config(dir)
                .with_context(|| format!("resuming {}", dir.display()))?;
            crate::kernels::use_kernels(config.portable_numerics)?;
            resume(dir, Run::resume(dir))?
        }
        None => {
            let config = config(&args)?;
            crate::kernels::use_kernels(config.portable_numerics)?;
            let out = args.out.as_ref().expect("clap requires --out");
            Run::create(out, config).map_err(|e| match e {
                seads_rl::RlError::Config(_) => BadInput(e.into()).into(),
                other => anyhow::Error::from(other),
            })?
        }
    };
    drive(&mut run, args.quiet)
}

/// The resumed run, after telling on stderr what resuming repaired.
pub fn resume(dir: &std::path::Path, run: Result<Run, seads_rl::RlError>) -> Result<Run> {
    let run = run.with_context(|| format!("resuming {}", dir.display()))?;
    for repair in run.repairs() {
        eprintln!("seads: {}: {repair}", dir.display());
    }
    Ok(run)
}

/// The variable of the crash-point tests (`crates/seads-cli/tests/crash.rs`): `list` names every
/// [`Moment`] of the run on stderr as it passes; a number N stops the process at the N-th moment
/// (counted from 1 in this process), says so on stderr and waits there to be killed.
pub const CRASH_POINT_VAR: &str = "SEADS_CRASH_POINT";

/// The hook [`CRASH_POINT_VAR`] asks for, if it is set.
fn crash_hook() -> Result<Option<Hook>> {
    let Ok(value) = std::env::var(CRASH_POINT_VAR) else {
        return Ok(None);
    };
    if value == "list" {
        return Ok(Some(Box::new(|moment: Moment| {
            eprintln!("seads: moment {}", moment.name());
        })));
    }
    let stop: u64 = value.parse().map_err(|_| {
        BadInput(anyhow::anyhow!(
            "{CRASH_POINT_VAR} must be `list` or a moment number, got {value:?}"
        ))
    })?;
    let mut count = 0;
    Ok(Some(Box::new(move |moment: Moment| {
        count += 1;
        if count == stop {
            eprintln!("seads: stopped at moment {count} ({})", moment.name());
            loop {
                std::thread::park();
            }
        }
    })))
}

/// Trains `run` to its budget, showing progress, and prints a summary.
pub fn drive(run: &mut Run, quiet: bool) -> Result<()> {
    if let Some(hook) = crash_hook()? {
        run.set_hook(hook);
    }
    let budget = run.trainer().config().env_steps;
    let bar = if quiet {
        ProgressBar::hidden()
    } else {
        ProgressBar::new(budget)
    };
    bar.set_style(
        ProgressStyle::with_template("{elapsed_precise} [{bar:30}] {pos}/{len} steps {msg}")
            .expect("valid template")
            .progress_chars("=> "),
    );
    bar.set_position(run.trainer().env_steps().min(budget));
    // A resumed run shows its last evaluation until the next one.
    let mut coverage = seads_rl::read_metrics(run.dir())
        .ok()
        .and_then(|m| m.last().map(|m| m.skill_coverage))
        .unwrap_or(f64::NAN);
    let k = run.trainer().num_skills();
    while !run.finished() {
        let event = run.step().context("training")?;
        if let Some(m) = &event.metrics {
            coverage = m.skill_coverage;
            let line = format!(
                "epoch {:>6}  steps {:>9}  coverage {:>5.2}/{}  reward {:>6.2}  {:>6.0} steps/s",
                m.epoch, m.env_steps, m.skill_coverage, k, m.mean_reward, m.steps_per_s
            );
            // A hidden bar (quiet, or output not a terminal) drops `println`: print directly.
            if bar.is_hidden() {
                println!("{line}");
            } else {
                bar.println(line);
            }
        }
        let steps_per_s = event.stats.env_steps as f64 / run.wall_s().max(1e-9);
        bar.set_position(event.stats.env_steps.min(budget));
        bar.set_message(format!(
            "epoch {} coverage {:.2}/{} reward {:.2} {:.0} steps/s",
            event.stats.epoch + 1,
            coverage,
            k,
            event.stats.mean_reward,
            steps_per_s
        ));
    }
    bar.finish_and_clear();
    let t = run.trainer().timings();
    println!(
        "trained {} epochs, {} steps in {:.0} s: skill coverage {:.2}/{}; run directory {}",
        run.trainer().epoch(),
        run.trainer().env_steps(),
        run.wall_s(),
        coverage,
        k,
        run.dir().display()
    );
    println!(
        "time per phase: collect {:.1} s, relabel {:.1} s, skill model {:.1} s, SAC {:.1} s, evaluation {:.1} s",
        t.collect, t.relabel, t.skill_model, t.sac, t.evaluate
    );
    Ok(())
}
