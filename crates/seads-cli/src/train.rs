//! `seads train`: train a SEADS agent into a run directory, with a progress bar.

use std::path::PathBuf;

use anyhow::{Context, Result};
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use seads_rl::{Run, TrainConfig};

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
    #[arg(long)]
    env_steps: Option<u64>,
    /// A full configuration file (TOML) instead of the preset; see `configs/`.
    #[arg(long)]
    config: Option<PathBuf>,
    /// Continue the run in this directory from its last checkpoint.
    #[arg(long, conflicts_with_all = ["env", "out", "seed", "env_steps", "config"])]
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
        Some(dir) => Run::resume(dir).with_context(|| format!("resuming {}", dir.display()))?,
        None => {
            let config = config(&args)?;
            let out = args.out.as_ref().expect("clap requires --out");
            Run::create(out, config).map_err(|e| match e {
                seads_rl::RlError::Config(_) => BadInput(e.into()).into(),
                other => anyhow::Error::from(other),
            })?
        }
    };
    drive(&mut run, args.quiet)
}

/// Trains `run` to its budget, showing progress, and prints a summary.
pub fn drive(run: &mut Run, quiet: bool) -> Result<()> {
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
