//! `seads train`: train a SEADS agent (or the flat SAC baseline) into a run directory, with a
//! progress bar.

use std::path::PathBuf;

use anyhow::{Context, Result};
use clap::Args;
use seads_rl::store::MetricsLine as _;
use seads_rl::{ComputeDevice, Hook, InWords, Learner, Moment, Run, TrainConfig, WithLearner};

use crate::BadInput;

/// Arguments of `seads train`.
#[derive(Debug, Args)]
pub struct TrainArgs {
    /// Environment to train on, with its preset (the paper's settings; see `seads envs`).
    #[arg(long, required_unless_present_any = ["resume", "config"])]
    env: Option<String>,
    /// What to train, a learner of the registry (`seads_rl::learners`): `seads`, or a baseline
    /// with the task reward: flat SAC (`sac`, SPEC §5.1; presets `configs/sac/*.toml`) or
    /// two-level HAC (`hac`, SPEC §5.2; presets `configs/hac/*.toml`); beyond the paper, DIAYN
    /// (`diayn`: skills from a discriminator, no forward model). Default: the config's, else
    /// seads.
    #[arg(
        long,
        value_parser = clap::builder::PossibleValuesParser::new(seads_rl::learners::names()),
        conflicts_with = "resume"
    )]
    algorithm: Option<String>,
    /// Run directory to create (config.toml, metrics.jsonl, provenance.jsonl, checkpoints/).
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
    /// Where the networks run: cpu, cuda (the first GPU) or cuda:N. Default: the config's
    /// (cpu in the presets); with --resume, the run's, and a run may resume on another device.
    /// Only the CPU repeats a run exactly from its seed.
    #[arg(long)]
    device: Option<ComputeDevice>,
    /// No progress bar; one line per evaluation instead.
    #[arg(long)]
    quiet: bool,
}

/// Builds the configuration the arguments ask for.
fn config(args: &TrainArgs) -> Result<TrainConfig> {
    let mut config = match (&args.config, &args.env) {
        (Some(path), env) => {
            let text = std::fs::read_to_string(path)
                .map_err(|e| BadInput(anyhow::anyhow!("reading {}: {e}", path.display())))?;
            // What the file leaves out comes from its environment's preset.
            TrainConfig::from_user_toml(&text, env.as_deref(), args.algorithm.as_deref())
                .map_err(|e| BadInput(anyhow::anyhow!("{}: {e}", path.display())))?
        }
        (None, Some(env)) => {
            let algorithm = args.algorithm.as_deref();
            TrainConfig::preset_for(
                env,
                algorithm.unwrap_or(<seads_rl::SeadsConfig as seads_rl::Section>::ALGORITHM),
            )
            .map_err(|e| BadInput(e.into()))?
        }
        (None, None) => unreachable!("clap requires --env or --config"),
    };
    if let Some(seed) = args.seed {
        config.seed = seed;
    }
    if let Some(steps) = args.env_steps {
        config.env_steps = steps;
    }
    if let Some(device) = args.device {
        config.device = device;
    }
    crate::usable_device(config.device)?;
    config.validate().map_err(|e| BadInput(e.into()))?;
    seads_rl::learners::complete(&mut config).map_err(|e| match &args.config {
        Some(path) => BadInput(anyhow::anyhow!("{}: {e}", path.display())),
        None => BadInput(e.into()),
    })?;
    Ok(config)
}

/// Runs `seads train`.
pub fn train(args: TrainArgs) -> Result<()> {
    match &args.resume {
        Some(dir) => {
            let _lock = crate::lock_run(dir)?;
            // The device is checked before anything is written.
            let device = match args.device {
                Some(device) => device,
                None => crate::run_config(dir)?.device,
            };
            crate::usable_device(device)?;
            if let Some(steps) = args.env_steps {
                seads_rl::raise_budget(dir, steps).map_err(|e| match e {
                    seads_run::RunError::Config(_) => BadInput(e.into()).into(),
                    other => anyhow::Error::from(other),
                })?;
            }
            let config = crate::run_config(dir)?;
            crate::kernels::use_kernels(config.portable_numerics)?;
            seads_rl::with_learner(
                config.algorithm(),
                Resume {
                    dir,
                    device,
                    quiet: args.quiet,
                },
            )?
        }
        None => {
            let config = config(&args)?;
            crate::kernels::use_kernels(config.portable_numerics)?;
            let out = args.out.as_ref().expect("clap requires --out");
            let algorithm = config.algorithm().to_owned();
            seads_rl::with_learner(
                &algorithm,
                Create {
                    out,
                    config,
                    quiet: args.quiet,
                },
            )?
        }
    }
}

/// `seads train --resume`'s work with the run's learner.
struct Resume<'a> {
    dir: &'a std::path::Path,
    device: ComputeDevice,
    quiet: bool,
}

impl WithLearner for Resume<'_> {
    type Output = Result<()>;
    fn run<L: InWords + Send>(self) -> Result<()> {
        drive(&mut resume_on::<L>(self.dir, self.device)?, self.quiet)
    }
}

/// `seads train`'s work with a new run's learner.
struct Create<'a> {
    out: &'a std::path::Path,
    config: TrainConfig,
    quiet: bool,
}

impl WithLearner for Create<'_> {
    type Output = Result<()>;
    fn run<L: InWords + Send>(self) -> Result<()> {
        drive(&mut create::<L>(self.out, self.config)?.0, self.quiet)
    }
}

/// A new run and the lock on its directory, held while it trains; a configuration error is
/// bad input.
fn create<L: Learner>(
    out: &std::path::Path,
    config: TrainConfig,
) -> Result<(Run<L>, seads_rl::store::RunLock)> {
    // The lock first: nothing is written into a directory another command holds.
    let lock = crate::lock_new_run(out)?;
    let run = Run::create(out, config).map_err(|e| match e {
        seads_rl::RlError::Run(seads_run::RunError::Config(_)) => {
            anyhow::Error::from(BadInput(e.into()))
        }
        other => anyhow::Error::from(other),
    })?;
    Ok((run, lock))
}

/// The run in `dir` resumed on `device` (which may differ from the one it trained on so far).
fn resume_on<L: Learner>(dir: &std::path::Path, device: ComputeDevice) -> Result<Run<L>> {
    resume(
        dir,
        Run::resume_with(dir, |mut config| {
            config.device = device;
            L::build(config)
        }),
    )
}

/// The resumed run, after telling on stderr what resuming repaired.
pub fn resume<L: Learner>(
    dir: &std::path::Path,
    run: Result<Run<L>, seads_rl::RlError>,
) -> Result<Run<L>> {
    // A run damaged beyond repair is bad input, as any malformed input file is.
    let run = run.map_err(|e| match e {
        seads_rl::RlError::Run(seads_run::RunError::Damaged { .. })
        | seads_rl::RlError::CheckpointsMissing { .. }
        | seads_rl::RlError::NoCheckpoint { .. }
        | seads_rl::RlError::Run(seads_run::RunError::Config(_)) => BadInput(e.into()).into(),
        other => anyhow::Error::from(other),
    });
    let run = run.with_context(|| format!("resuming {}", dir.display()))?;
    for repair in run.repairs() {
        eprintln!("seads: {}: {repair}", dir.display());
    }
    Ok(run)
}

/// The variable of the crash-point tests (`crates/seads-cli/tests/end_to_end/crash.rs`): `list` names every
/// [`Moment`] of the run on stderr as it passes; a number N stops the process at the N-th moment
/// (counted from 1 in this process), says so on stderr and waits there to be killed.
pub const CRASH_POINT_VAR: &str = "SEADS_CRASH_POINT";

/// The hook [`CRASH_POINT_VAR`] asks for, if it is set.
pub fn crash_hook() -> Result<Option<Hook>> {
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
pub fn drive<L: InWords>(run: &mut Run<L>, quiet: bool) -> Result<()> {
    if let Some(hook) = crash_hook()? {
        run.set_hook(hook);
    }
    let budget = run.trainer().config().env_steps;
    record_provenance(run, &crate::build()).context("recording the run's provenance")?;
    let template = "{elapsed_precise} [{bar:30}] {pos}/{len} steps {msg}";
    let bar = crate::progress_bar(budget, quiet, template);
    bar.set_position(run.trainer().steps().min(budget));
    // A resumed run shows its last evaluation until the next one.
    let mut headline = seads_rl::store::read_metrics_as::<L::Metrics>(run.dir())
        .ok()
        .and_then(|m| m.last().map(|m| run.trainer().headline(m)))
        .unwrap_or_default();
    while !run.finished() {
        let event = run.step().context("training")?;
        if let Some(m) = &event.metrics {
            headline = run.trainer().headline(m);
            let (epoch, steps, per_s) = (m.epoch(), m.env_steps(), m.steps_per_s());
            let line =
                format!("epoch {epoch:>6}  steps {steps:>9}  {headline}  {per_s:>6.0} steps/s");
            // A hidden bar (quiet, or output not a terminal) drops `println`: print directly.
            if bar.is_hidden() {
                outln!("{line}");
            } else {
                bar.println(line);
            }
        }
        let (epoch, steps) = (run.trainer().epoch(), run.trainer().steps());
        let steps_per_s = steps as f64 / run.wall_s().max(1e-9);
        bar.set_position(steps.min(budget));
        bar.set_message(format!(
            "epoch {} {headline} {steps_per_s:.0} steps/s",
            epoch + 1
        ));
    }
    bar.finish_and_clear();
    outln!(
        "trained {} epochs, {} steps in {:.0} s: {headline}; run directory {}",
        run.trainer().epoch(),
        run.trainer().steps(),
        run.wall_s(),
        run.dir().display()
    );
    outln!("time per phase: {}", run.trainer().phases());
    Ok(())
}

/// Appends this process of `build` to the provenance of `run`, about to train it on from where
/// it stands; nothing for a run that has finished.
pub fn record_provenance<L: InWords>(
    run: &Run<L>,
    build: &seads_study::provenance::Build,
) -> Result<(), seads_rl::RlError> {
    if run.finished() {
        return Ok(());
    }
    let trainer = run.trainer();
    let at = (trainer.epoch(), trainer.steps());
    Ok(seads_study::provenance::Provenance::record(
        run.dir(),
        trainer.config(),
        at,
        build,
    )?)
}
