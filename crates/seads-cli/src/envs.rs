//! `seads envs`, `seads render`, `seads env-bench`: the embodied environments.

use std::path::PathBuf;

use anyhow::{Context, Result};
use clap::Args;
use seads_embodiment::{EnvConfig, Environment, Throughput, list_envs, make_env};

use crate::BadInput;

/// Builds an environment, turning configuration mistakes into exit code 2.
pub fn build_env(name: &str, config: &EnvConfig) -> Result<Box<dyn Environment>> {
    make_env(name, config).map_err(|e| BadInput(e.into()).into())
}

/// `seads envs`: every registered environment with its dimensions.
pub fn envs(json: bool) -> Result<()> {
    let envs = list_envs();
    if json {
        outln!("{}", serde_json::to_string(&envs)?);
        return Ok(());
    }
    outln!(
        "{:<18} {:>7} {:>6} {:>6} {:>5}  description",
        "name",
        "obs",
        "action",
        "skills",
        "T_max"
    );
    for e in envs {
        outln!(
            "{:<18} {:>7} {:>6} {:>6} {:>5}  {}",
            e.name,
            e.obs_dim,
            e.action_dim,
            e.num_skills,
            e.step_limit,
            e.description
        );
    }
    Ok(())
}

/// Arguments of `seads render`.
#[derive(Debug, Args)]
pub struct RenderArgs {
    /// Environment name (see `seads envs`).
    #[arg(long)]
    env: String,
    /// Seed of the reset (board and manipulator).
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Output image: .png or .svg.
    #[arg(long)]
    out: PathBuf,
    /// Board side for lightsout-cursor (5, 7, 9, 13).
    #[arg(long)]
    board_size: Option<usize>,
    /// Relative spacing between fields (spaced LightsOut boards), in [0, 1].
    #[arg(long, value_parser = crate::numbers::positive_finite)]
    spacing: Option<f64>,
}

/// `seads render`: a top view of a freshly reset environment (and a side view where fields
/// differ in height).
pub fn render(args: RenderArgs) -> Result<()> {
    let config = EnvConfig {
        board_size: args.board_size,
        spacing: args.spacing,
        ..EnvConfig::default()
    };
    let mut env = build_env(&args.env, &config)?;
    env.seed(args.seed);
    env.reset()?;
    let title = format!("{} (seed {})", args.env, args.seed);
    seads_study::draw::render_scene(&env.scene(), &title, &args.out)?;
    outln!("wrote {}", args.out.display());
    Ok(())
}

/// Arguments of `seads env-bench`.
#[derive(Debug, Args)]
pub struct BenchArgs {
    /// Environment name (see `seads envs`).
    #[arg(long)]
    env: String,
    /// Total environment steps (random actions, reset when a skill ends).
    #[arg(long, default_value_t = 1_000_000)]
    steps: usize,
    /// Threads, each stepping its own environment.
    #[arg(long, default_value_t = 1)]
    threads: usize,
    /// An option of the manipulator, as KEY=VALUE in TOML (repeatable), e.g.
    /// `--manipulator physics_substeps=25` for the Jaco (physics steps per environment step;
    /// reference: 50). The Cursor and the Reachers have none.
    #[arg(long = "manipulator", value_name = "KEY=VALUE", value_parser = manipulator_option)]
    manipulator: Vec<(String, serde_json::Value)>,
    /// Print JSON.
    #[arg(long)]
    json: bool,
}

/// `seads env-bench`: environment steps per second with random actions.
pub fn env_bench(args: BenchArgs) -> Result<()> {
    if args.threads == 0 || args.steps == 0 {
        return Err(BadInput(anyhow::anyhow!("--steps and --threads must be at least 1")).into());
    }
    crate::check_threads("--threads", args.threads)?;
    let config = EnvConfig {
        manipulator: args.manipulator.into_iter().collect(),
        ..EnvConfig::default()
    };
    let env = build_env(&args.env, &config)?;
    let report = Throughput::measure(env.as_ref(), args.steps, args.threads)
        .context("stepping the environment")?;
    if args.json {
        outln!("{}", serde_json::to_string(&report)?);
    } else {
        outln!(
            "{}: {} steps on {} thread(s) in {:.3} s = {:.0} steps/s",
            report.env,
            report.steps,
            report.threads,
            report.seconds,
            report.steps_per_sec
        );
    }
    Ok(())
}

/// One manipulator option from `KEY=VALUE`, the value read as TOML (`25`, `0.5`, `"text"`).
fn manipulator_option(text: &str) -> Result<(String, serde_json::Value), String> {
    let bad =
        || format!("expected KEY=VALUE with a TOML value, like physics_substeps=25, got {text:?}");
    let (key, value) = text.split_once('=').ok_or_else(bad)?;
    let table: toml::Table = format!("v = {}", value.trim()).parse().map_err(|_| bad())?;
    let value = serde_json::to_value(&table["v"]).map_err(|_| bad())?;
    let key = key.trim();
    if key.is_empty() {
        return Err(bad());
    }
    Ok((key.to_owned(), value))
}

#[cfg(test)]
mod tests {
    use super::manipulator_option;

    #[test]
    fn manipulator_options_are_read_as_toml_values() {
        assert_eq!(
            manipulator_option("physics_substeps=25"),
            Ok(("physics_substeps".into(), 25.into()))
        );
        assert_eq!(
            manipulator_option(" gain = 0.5").unwrap().1,
            serde_json::json!(0.5)
        );
        for bad in ["physics_substeps", "=3", "x=", "x=not toml"] {
            assert!(manipulator_option(bad).is_err(), "{bad}");
        }
    }
}
