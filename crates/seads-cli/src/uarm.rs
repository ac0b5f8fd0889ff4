//! `seads uarm …`: the real robot (uArm Swift Pro + LightsOut tablet) or its simulated twin.

use std::io::BufRead;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use clap::{Args, Subcommand};
use seads_embodiment::Environment;
use seads_rl::{Run, TrainConfig, Trainer, find_checkpoint, load_config};
use seads_uarm::{
    ActionSpace, AdbTablet, Calibration, CalibrationFile, DriverConfig, Observation, RobotSettings,
    SerialTransport, Swift, Tablet, Twin, TwinNoise, UarmConfig, UarmEnv, UarmError,
    twin_screen_corners,
};

use crate::BadInput;

/// Subcommands of `seads uarm`.
#[derive(Debug, Subcommand)]
pub enum UarmCommand {
    /// Record the four screen corners with the pen and write a calibration file.
    Calibrate(CalibrateArgs),
    /// Train SEADS on the robot (or its twin) and report success on test boards.
    Train(UarmTrainArgs),
    /// Success on test boards of a robot run's checkpoint (the latest, or --checkpoint).
    Evaluate(UarmEvaluateArgs),
}

/// Where the robot is.
#[derive(Debug, Args)]
pub struct Connection {
    /// Serial port of the arm (e.g. /dev/ttyACM0), or `sim` / `sim:SEED` for the simulated twin.
    #[arg(long, default_value = "sim")]
    port: String,
    /// The `adb` program that reads the tablet's log (real robot only).
    #[arg(long, default_value = "adb")]
    adb: String,
}

impl Connection {
    /// Whether the port names the twin.
    fn is_twin(&self) -> bool {
        self.port == "sim" || self.port.starts_with("sim:")
    }

    /// The twin that `--port sim` or `sim:SEED` asks for, with `noise`; any other port is a
    /// serial port, which takes no noise.
    fn twin(&self, noise: TwinNoise) -> Result<Option<Twin>> {
        let Some(seed) = self.twin_seed()? else {
            if noise.is_none() {
                return Ok(None);
            }
            bail!(BadInput(anyhow::anyhow!(
                "--tap-sd-mm and --late-reports need the twin (--port sim): a real arm has its own noise"
            )));
        };
        Ok(Some(
            Twin::with_noise(seed, noise).map_err(|e| BadInput(e.into()))?,
        ))
    }

    /// The seed of the twin that `--port sim` (0) or `sim:SEED` names; `None` for a serial port.
    fn twin_seed(&self) -> Result<Option<u64>> {
        if self.port == "sim" {
            return Ok(Some(0));
        }
        let Some(seed) = self.port.strip_prefix("sim:") else {
            return Ok(None);
        };
        let seed = seed.parse().map_err(|_| {
            BadInput(anyhow::anyhow!(
                "--port {}: the twin's seed must be a whole number (sim:SEED)",
                self.port
            ))
        })?;
        Ok(Some(seed))
    }

    fn arm(&self, twin: Option<&Twin>) -> Result<Swift> {
        let transport = match twin {
            Some(twin) => twin.transport(),
            None => Box::new(SerialTransport::open(&self.port)?),
        };
        Ok(Swift::new(transport, DriverConfig::default()))
    }

    fn tablet(&self, twin: Option<&Twin>) -> Result<Box<dyn Tablet>> {
        Ok(match twin {
            Some(twin) => twin.tablet(),
            None => Box::new(AdbTablet::start(&self.adb)?),
        })
    }
}

/// Arguments of `seads uarm calibrate`.
#[derive(Debug, Args)]
pub struct CalibrateArgs {
    #[command(flatten)]
    connection: Connection,
    /// Where to write the calibration.
    #[arg(long, default_value = "uarm-calibration.toml")]
    out: PathBuf,
    /// Distance from the screen for z = 1, mm.
    #[arg(long, default_value_t = 100.0, value_parser = crate::numbers::positive_finite)]
    d_max_mm: f64,
}

const CORNERS: [&str; 4] = ["top-left", "top-right", "bottom-right", "bottom-left"];

/// Records the corners: a person places the pen on each (with the twin, a simulated person).
/// Each is printed unless `quiet`.
fn record_corners(arm: &mut Swift, twin: Option<&Twin>, quiet: bool) -> Result<[[f64; 3]; 4]> {
    arm.detach().context("detaching the servos")?;
    let mut corners = [[0.0; 3]; 4];
    let stdin = std::io::stdin();
    for (i, name) in CORNERS.iter().enumerate() {
        match twin {
            Some(twin) => twin.move_by_hand(twin_screen_corners()[i]),
            None => {
                outln!(
                    "Move the pen tip onto the {name} corner of the usable screen area, then press Enter."
                );
                let mut line = String::new();
                stdin.lock().read_line(&mut line)?;
            }
        }
        corners[i] = arm
            .position()
            .with_context(|| format!("reading the {name} corner"))?;
        if !quiet {
            outln!(
                "{name}: X {:.1}  Y {:.1}  Z {:.1} mm",
                corners[i][0],
                corners[i][1],
                corners[i][2]
            );
        }
    }
    arm.attach().context("attaching the servos")?;
    Ok(corners)
}

/// `seads uarm calibrate`.
pub fn calibrate(args: CalibrateArgs) -> Result<()> {
    let twin = args.connection.twin(TwinNoise::default())?;
    let mut arm = args.connection.arm(twin.as_ref())?;
    let corners = record_corners(&mut arm, twin.as_ref(), false)?;
    let calibration = Calibration::fit(CalibrationFile {
        corners,
        d_max_mm: args.d_max_mm,
    })
    .map_err(|e| BadInput(e.into()))?;
    calibration.save(&args.out)?;
    outln!(
        "wrote {} (largest corner distance from the fitted plane {:.2} mm)",
        args.out.display(),
        calibration.plane_residual_mm
    );
    Ok(())
}

/// Arguments of `seads uarm train`.
#[derive(Debug, Args)]
pub struct UarmTrainArgs {
    #[command(flatten)]
    connection: Connection,
    /// Calibration file (default for the twin: calibrate it on the spot).
    #[arg(long)]
    calibration: Option<PathBuf>,
    /// Action space: absolute (press at (x, y)) or displacement (the Cursor in hardware).
    #[arg(long, default_value = "absolute")]
    action_space: ActionSpace,
    /// Interactions (environment steps) to train for [default: 5000, the paper's with absolute
    /// pushes]. With --resume: raises the run's budget to this many.
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..=i64::MAX as u64))]
    env_steps: Option<u64>,
    /// Run directory.
    #[arg(long, default_value = "runs/uarm")]
    out: PathBuf,
    /// Seed of the run.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Test boards per solution depth 1–5 in the final evaluation (1 to 200000).
    #[arg(long, value_parser = clap::builder::RangedU64ValueParser::<usize>::new().range(1..=200_000), default_value_t = 20)]
    boards: usize,
    /// The search limits of the evaluation.
    #[command(flatten)]
    search: crate::plan::SearchArgs,
    /// Continue the run in --out from its last checkpoint (on the twin, with the twin as the
    /// checkpoint left it: the same run as one never stopped).
    #[arg(long)]
    resume: bool,
    /// One line per evaluation instead of a progress bar.
    #[arg(long)]
    quiet: bool,
    /// Cores this run may use; its libtorch threads follow them (default: the preset's threads,
    /// for a machine that runs nothing else).
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..=1024))]
    cores: Option<u64>,
    /// The twin only: draw a new board and pen position at the start of every training episode.
    /// The paper's arm resets neither (seed S.5), and neither does the twin without this flag.
    #[arg(long)]
    reset_board: bool,
    /// What the skills see: board-and-pen, board, pen or nothing (what is not seen reads 0; the
    /// forward model always sees the board). Default: pen with absolute pushes (a press is the
    /// same whatever the board shows; on the twin it solves every board where seeing the board
    /// too does not, docs/results/uarm-ablations), board-and-pen with displacements (the
    /// Cursor's). A resumed run keeps its own.
    #[arg(long)]
    observe: Option<Observation>,
    /// The twin only: standard deviation, mm, of where a tap lands around the commanded point
    /// (pen offset, the arm's repeatability). A resumed run keeps its own.
    #[arg(long, default_value_t = 0.0, value_name = "MM",
          value_parser = crate::numbers::non_negative_finite)]
    tap_sd_mm: f64,
    /// The twin only: probability that the tablet logs a tap too late for its press (the report
    /// comes with the next press's). A resumed run keeps its own.
    #[arg(long, default_value_t = 0.0, value_name = "P", value_parser = crate::numbers::probability)]
    late_reports: f64,
    /// The training settings that a new run may change from the robot's (`seads uarm train`'s
    /// defaults); a resumed run keeps its `config.toml`.
    #[command(flatten)]
    training: RobotTraining,
}

/// Training settings of a new robot run that the paper does not state for the robot (seed S.5
/// gives α and the episodes per epoch; the rest is the Cursor's).
#[derive(Debug, Args)]
pub struct RobotTraining {
    /// SAC updates per epoch (default: the Cursor's 16).
    #[arg(long, value_name = "N", conflicts_with = "resume",
          value_parser = clap::value_parser!(u64).range(1..=100_000))]
    updates_per_epoch: Option<u64>,
    /// New episodes per epoch (default: 4 with absolute pushes, as the paper's robot; the
    /// Cursor's 32 with displacements).
    #[arg(long, value_name = "N", conflicts_with = "resume",
          value_parser = clap::value_parser!(u64).range(1..=100_000))]
    episodes_per_epoch: Option<u64>,
    /// SAC's entropy temperature α (default: the paper's 0.1 for the robot).
    #[arg(long, value_name = "ALPHA", conflicts_with = "resume",
          value_parser = crate::numbers::positive_finite)]
    alpha: Option<f64>,
}

impl UarmTrainArgs {
    /// The twin's noise these options ask for.
    fn noise(&self) -> TwinNoise {
        TwinNoise {
            tap_sd_mm: self.tap_sd_mm,
            late_report_p: self.late_reports,
        }
    }

    /// What the run records in `robot.toml`.
    fn settings(&self) -> RobotSettings {
        RobotSettings {
            action_space: self.action_space,
            reset_board: self.reset_board,
            observe: self
                .observe
                .unwrap_or_else(|| self.action_space.observation()),
            twin_noise: self.noise(),
        }
    }
}

fn build_env(
    connection: &Connection,
    calibration: Option<&Path>,
    settings: &RobotSettings,
    twin: Option<&Twin>,
) -> Result<UarmEnv> {
    let RobotSettings {
        action_space,
        reset_board,
        observe,
        twin_noise: _,
    } = *settings;
    if reset_board && twin.is_none() {
        bail!(BadInput(anyhow::anyhow!(
            "--reset-board needs the twin (--port sim): the real tablet's board cannot be set"
        )));
    }
    let calibration = match (calibration, twin) {
        (Some(path), _) => Calibration::load(path).map_err(|e| BadInput(e.into()))?,
        (None, Some(twin)) => calibrate_twin(connection, twin)?,
        (None, None) => bail!(BadInput(anyhow::anyhow!(
            "the real arm needs --calibration (see `seads uarm calibrate`)"
        ))),
    };
    let config = UarmConfig {
        action_space,
        step_limit: action_space.step_limit(),
        reset_board,
        tap_timeout_s: if twin.is_some() { 0.0 } else { 2.0 },
        observe,
    };
    let arm = connection.arm(twin)?;
    let tablet = connection.tablet(twin)?;
    let env = UarmEnv::new(arm, tablet, calibration, config)?;
    Ok(match twin {
        Some(twin) => env.on_twin(twin.clone()),
        None => env,
    })
}

/// The twin calibrated on the spot, as a person would calibrate the arm (silently: `seads uarm
/// calibrate` is where corners are shown).
fn calibrate_twin(connection: &Connection, twin: &Twin) -> Result<Calibration> {
    let mut arm = connection.arm(Some(twin))?;
    Ok(Calibration::fit(CalibrationFile {
        corners: record_corners(&mut arm, Some(twin), true)?,
        d_max_mm: 100.0,
    })?)
}

/// The twin acting as the robot run in `run` (with `config`) did, to show its skills: the run's
/// observation and noise, and every reset draws a new board and pen position, like the Cursor's
/// coverage initialisations. `None` when `config` is not a robot run.
pub fn twin_for_figures(run: &Path, config: &TrainConfig) -> Result<Option<UarmEnv>> {
    let Some(space) = ActionSpace::of_env(&config.env) else {
        return Ok(None);
    };
    let settings = RobotSettings {
        reset_board: true,
        ..run_settings(run, space)?
    };
    let twin = Twin::with_noise(0, settings.twin_noise).map_err(|e| BadInput(e.into()))?;
    let connection = Connection {
        port: "sim".into(),
        adb: String::new(),
    };
    build_env(&connection, None, &settings, Some(&twin)).map(Some)
}

/// The settings the robot run in `run` records; a run from before `robot.toml` had `space`'s
/// defaults.
fn run_settings(run: &Path, space: ActionSpace) -> Result<RobotSettings> {
    let recorded = RobotSettings::read(run).map_err(|e| match e {
        UarmError::Config(_) => BadInput(e.into()).into(),
        other => anyhow::Error::from(other),
    })?;
    Ok(recorded.unwrap_or(RobotSettings {
        action_space: space,
        reset_board: false,
        observe: Observation::default(),
        twin_noise: TwinNoise::default(),
    }))
}

/// The training settings of a new robot run: its action space's preset
/// (`configs/uarm-lightsout-<space>.toml`, the paper's robot settings), with the options given.
fn robot_config(env: &UarmEnv, args: &UarmTrainArgs) -> Result<TrainConfig> {
    let mut config = TrainConfig::preset(&env.spec().name)?;
    if let Some(steps) = args.env_steps {
        config.env_steps = steps;
    }
    config.seed = args.seed;
    let training = &args.training;
    config.edit(|seads: &mut seads_rl::SeadsConfig| {
        if let Some(n) = training.updates_per_epoch {
            seads.updates_per_epoch = n as usize;
        }
        if let Some(n) = training.episodes_per_epoch {
            seads.episodes_per_epoch = n as usize;
        }
    })?;
    if let Some(alpha) = training.alpha {
        config.sac.alpha = alpha;
    }
    config.validate_values().map_err(|e| BadInput(e.into()))?;
    Ok(config)
}

/// `seads uarm train`.
pub fn train(mut args: UarmTrainArgs) -> Result<()> {
    // Before the twin or the arm starts a thread: the kernels of the run (the preset's when new).
    let portable = if args.resume {
        load_config(&args.out)?.portable_numerics
    } else {
        TrainConfig::preset(args.action_space.env_name())?.portable_numerics
    };
    crate::kernels::use_kernels(portable)?;
    if args.resume {
        adopt_run_settings(&mut args)?;
    }
    let twin = args.connection.twin(args.noise())?;
    let env = build_env(
        &args.connection,
        args.calibration.as_deref(),
        &args.settings(),
        twin.as_ref(),
    )?;
    let cores = args.cores.map(|c| c as usize);
    if let Some(cores) = cores {
        seads_rl::set_threads(cores);
    }
    let trainer = |mut config: TrainConfig| {
        if let Some(cores) = cores {
            config.use_cores(cores);
        }
        Trainer::with_environments(config, env.box_clone(), env.box_clone())
    };
    let (mut run, _lock) = if args.resume {
        let lock = crate::lock_run(&args.out)?;
        if let Some(steps) = args.env_steps {
            seads_rl::raise_budget(&args.out, steps).map_err(|e| match e {
                seads_run::RunError::Config(_) => BadInput(e.into()).into(),
                other => anyhow::Error::from(other),
            })?;
        }
        let run = crate::train::resume(&args.out, Run::resume_with(&args.out, trainer))?;
        if run.trainer().resumed_without_carried_state() {
            eprintln!(
                "seads: {}: its checkpoint holds no state of the twin (it was written before \
                 checkpoints kept it), so training goes on with a fresh twin and parts from the \
                 run never stopped",
                args.out.display()
            );
        }
        (run, lock)
    } else {
        let config = robot_config(&env, &args)?;
        // The lock first: nothing is written into a directory another command holds.
        let lock = crate::lock_new_run(&args.out)?;
        let run = Run::with_trainer(&args.out, trainer(config)?).map_err(|e| BadInput(e.into()))?;
        args.settings().write(&args.out)?;
        (run, lock)
    };
    crate::train::drive(&mut run, args.quiet)?;
    drop(run);
    // On the twin, the evaluation plays a fresh one, as `seads uarm evaluate` does: its outcome
    // does not depend on where training left the pen and the noise, nor on whether the run was
    // resumed. The real arm stays connected.
    let (env, twin_seed) = match args.connection.twin_seed()? {
        Some(_) => {
            drop((env, twin));
            evaluation_env(&args.connection, args.calibration.as_deref(), &args.out)?
        }
        None => (env, None),
    };
    evaluate(
        &args.out,
        None,
        env,
        twin_seed,
        args.boards,
        args.search.limits(),
        args.quiet,
    )
}

/// A resumed run acts and sees as it was trained, on a twin with its noise, whatever the options
/// say. A run from before `robot.toml` keeps the flags given; its skills saw everything unless
/// `--observe` says otherwise.
fn adopt_run_settings(args: &mut UarmTrainArgs) -> Result<()> {
    match RobotSettings::read(&args.out).map_err(|e| match e {
        UarmError::Config(_) => BadInput(e.into()).into(),
        other => anyhow::Error::from(other),
    })? {
        Some(settings) => {
            args.action_space = settings.action_space;
            args.reset_board = settings.reset_board;
            args.observe = Some(settings.observe);
            args.tap_sd_mm = settings.twin_noise.tap_sd_mm;
            args.late_reports = settings.twin_noise.late_report_p;
        }
        None => {
            args.observe.get_or_insert_default();
        }
    }
    Ok(())
}

/// Arguments of `seads uarm evaluate`.
#[derive(Debug, Args)]
pub struct UarmEvaluateArgs {
    #[command(flatten)]
    connection: Connection,
    /// Calibration file (default for the twin: calibrate it on the spot).
    #[arg(long)]
    calibration: Option<PathBuf>,
    /// Run directory of a robot run (from `seads uarm train`).
    #[arg(long)]
    run: PathBuf,
    /// Evaluate the checkpoint of this epoch instead of the latest; its results go to
    /// `evaluation-replan-epoch-<EPOCH>.json`.
    #[arg(long)]
    checkpoint: Option<u64>,
    /// Test boards per solution depth 1–5 (1 to 200000).
    #[arg(long, value_parser = clap::builder::RangedU64ValueParser::<usize>::new().range(1..=200_000), default_value_t = 20)]
    boards: usize,
    /// The search limits of the evaluation.
    #[command(flatten)]
    search: crate::plan::SearchArgs,
    /// No progress bar.
    #[arg(long)]
    quiet: bool,
}

/// `seads uarm evaluate`: success with re-planning of a robot run's checkpoint, as at the end of
/// `seads uarm train`.
pub fn evaluate_run(args: UarmEvaluateArgs) -> Result<()> {
    let config = crate::run_config(&args.run)?;
    let _lock = crate::lock_run(&args.run)?;
    crate::kernels::use_kernels(config.portable_numerics)?;
    let (env, twin_seed) =
        evaluation_env(&args.connection, args.calibration.as_deref(), &args.run)?;
    evaluate(
        &args.run,
        args.checkpoint,
        env,
        twin_seed,
        args.boards,
        args.search.limits(),
        args.quiet,
    )
}

/// The arm, or a fresh twin with the run's noise, that the robot run in `run` is evaluated on:
/// its skills see what they saw in training, and boards are set, not reset. With the twin's seed
/// (`None` for the real arm).
fn evaluation_env(
    connection: &Connection,
    calibration: Option<&Path>,
    run: &Path,
) -> Result<(UarmEnv, Option<u64>)> {
    let config = crate::run_config(run)?;
    let action_space = ActionSpace::of_env(&config.env).ok_or_else(|| {
        BadInput(anyhow::anyhow!(
            "{} is a {} run, not a robot run (see `seads evaluate`)",
            run.display(),
            config.env
        ))
    })?;
    let settings = RobotSettings {
        reset_board: false,
        ..run_settings(run, action_space)?
    };
    let noise = if connection.is_twin() {
        settings.twin_noise
    } else {
        TwinNoise::default()
    };
    let twin = connection.twin(noise)?;
    let env = build_env(connection, calibration, &settings, twin.as_ref())?;
    Ok((env, connection.twin_seed()?))
}

/// Success with re-planning on the protocol's tasks of depth 1–5 (the twin's boards are set to
/// them: the boards a Cursor evaluation plays), or on the boards the app shows (the real
/// tablet's cannot be set), of the checkpoint of `epoch` or the latest. Saved per depth as
/// `evaluation-replan.json` (the file `seads plot` and `seads report` read), or
/// `evaluation-replan-epoch-<EPOCH>.json` for an earlier checkpoint, with one line per task. A
/// stopped evaluation resumes from its finished tasks (on the twin, exactly: they are replayed).
fn evaluate(
    run: &Path,
    epoch: Option<u64>,
    env: UarmEnv,
    twin_seed: Option<u64>,
    boards: usize,
    limits: seads_planner::SearchLimits,
    quiet: bool,
) -> Result<()> {
    let checkpoint = find_checkpoint(run, epoch).map_err(|e| BadInput(e.into()))?;
    let evaluation = seads_evaluation::robot::RobotEvaluation {
        twin_seed,
        boards,
        limits,
    };
    let before = evaluation
        .finished_before(run, &checkpoint)
        .map_err(crate::eval_error)?;
    let tasks = 5 * boards as u64;
    crate::plan::warn_damaged_journal(run, before.damaged);
    let before = before.finished;
    if before > 0 {
        eprintln!(
            "resuming a robot evaluation: {before} of {tasks} tasks finished before{}",
            if twin_seed.is_some() {
                " (the twin replays them)"
            } else {
                ""
            }
        );
    }
    let bar = crate::progress_bar(tasks, quiet, "{wide_bar} {pos}/{len}");
    let record = evaluation
        .run(run, &checkpoint, env, || bar.inc(1))
        .map_err(crate::eval_error)?;
    bar.finish_and_clear();
    let results = record.results;
    let (solved, tasks) = results
        .iter()
        .fold((0, 0), |(s, t), r| (s + r.solved, t + r.tasks));
    outln!(
        "solved {solved} of {tasks} boards with re-planning (per depth: {})",
        results
            .iter()
            .map(|r| format!("{}: {}/{}", r.depth, r.solved, r.tasks))
            .collect::<Vec<_>>()
            .join(", ")
    );
    Ok(())
}
