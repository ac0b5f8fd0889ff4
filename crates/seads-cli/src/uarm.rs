//! `seads uarm …`: the real robot (uArm Swift Pro + LightsOut tablet) or its simulated twin.

use std::io::BufRead;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use clap::{Args, Subcommand};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use seads_embodiment::Environment;
use seads_games::{BoardDataset, BoardGame, Gf2Solver, LightsOut, Split};
use seads_planner::{PlannerConfig, SolveConfig, solve};
use seads_rl::{Agent, Run, TrainConfig, Trainer, latest_checkpoint, load_config};
use seads_uarm::{
    ActionSpace, AdbTablet, Calibration, CalibrationFile, DriverConfig, SerialTransport, Swift,
    Tablet, Twin, UarmConfig, UarmEnv, twin_screen_corners,
};

use crate::BadInput;

/// Subcommands of `seads uarm`.
#[derive(Debug, Subcommand)]
pub enum UarmCommand {
    /// Record the four screen corners with the pen and write a calibration file.
    Calibrate(CalibrateArgs),
    /// Train SEADS on the robot (or its twin) and report success on test boards.
    Train(UarmTrainArgs),
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
    /// The twin that `--port sim` or `sim:SEED` asks for; any other port is a serial port.
    fn twin(&self) -> Result<Option<Twin>> {
        if self.port == "sim" {
            return Ok(Some(Twin::new(0)));
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
        Ok(Some(Twin::new(seed)))
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
    #[arg(long, default_value_t = 100.0, value_parser = crate::positive_finite)]
    d_max_mm: f64,
}

const CORNERS: [&str; 4] = ["top-left", "top-right", "bottom-right", "bottom-left"];

/// Records the corners: a person places the pen on each (with the twin, a simulated person).
fn record_corners(arm: &mut Swift, twin: Option<&Twin>) -> Result<[[f64; 3]; 4]> {
    arm.detach().context("detaching the servos")?;
    let mut corners = [[0.0; 3]; 4];
    let stdin = std::io::stdin();
    for (i, name) in CORNERS.iter().enumerate() {
        match twin {
            Some(twin) => twin.move_by_hand(twin_screen_corners()[i]),
            None => {
                println!(
                    "Move the pen tip onto the {name} corner of the usable screen area, then press Enter."
                );
                let mut line = String::new();
                stdin.lock().read_line(&mut line)?;
            }
        }
        corners[i] = arm
            .position()
            .with_context(|| format!("reading the {name} corner"))?;
        println!(
            "{name}: X {:.1}  Y {:.1}  Z {:.1} mm",
            corners[i][0], corners[i][1], corners[i][2]
        );
    }
    arm.attach().context("attaching the servos")?;
    Ok(corners)
}

/// `seads uarm calibrate`.
pub fn calibrate(args: CalibrateArgs) -> Result<()> {
    let twin = args.connection.twin()?;
    let mut arm = args.connection.arm(twin.as_ref())?;
    let corners = record_corners(&mut arm, twin.as_ref())?;
    let calibration = Calibration::fit(CalibrationFile {
        corners,
        d_max_mm: args.d_max_mm,
    })
    .map_err(|e| BadInput(e.into()))?;
    calibration.save(&args.out)?;
    println!(
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
    #[arg(long, default_value = "absolute", value_parser = parse_space)]
    action_space: ActionSpace,
    /// Interactions (environment steps) to train for (the paper: 5000 with absolute pushes).
    #[arg(long, default_value_t = 5000)]
    env_steps: u64,
    /// Run directory.
    #[arg(long, default_value = "runs/uarm")]
    out: PathBuf,
    /// Seed of the run.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Test boards per solution depth 1–5 in the final evaluation.
    #[arg(long, default_value_t = 20)]
    boards: usize,
    /// Time limit per search in the final evaluation, seconds.
    #[arg(long, default_value_t = 60.0, value_parser = crate::positive_finite)]
    timeout: f64,
    /// Continue the run in --out from its last checkpoint.
    #[arg(long)]
    resume: bool,
    /// One line per evaluation instead of a progress bar.
    #[arg(long)]
    quiet: bool,
}

fn parse_space(text: &str) -> Result<ActionSpace, String> {
    match text {
        "absolute" => Ok(ActionSpace::Absolute),
        "displacement" => Ok(ActionSpace::Displacement),
        other => Err(format!(
            "unknown action space {other:?} (valid: absolute, displacement)"
        )),
    }
}

fn build_env(args: &UarmTrainArgs, twin: Option<&Twin>) -> Result<UarmEnv> {
    let calibration = match (&args.calibration, twin) {
        (Some(path), _) => Calibration::load(path).map_err(|e| BadInput(e.into()))?,
        (None, Some(twin)) => {
            let mut arm = args.connection.arm(Some(twin))?;
            Calibration::fit(CalibrationFile {
                corners: record_corners(&mut arm, Some(twin))?,
                d_max_mm: 100.0,
            })?
        }
        (None, None) => bail!(BadInput(anyhow::anyhow!(
            "the real arm needs --calibration (see `seads uarm calibrate`)"
        ))),
    };
    let step_limit = match args.action_space {
        ActionSpace::Absolute => 1,
        ActionSpace::Displacement => 10,
    };
    let config = UarmConfig {
        action_space: args.action_space,
        step_limit,
        reset_board: twin.is_some(),
        tap_timeout_s: if twin.is_some() { 0.0 } else { 2.0 },
    };
    let arm = args.connection.arm(twin)?;
    let tablet = args.connection.tablet(twin)?;
    Ok(UarmEnv::new(arm, tablet, calibration, config)?)
}

/// The training settings of the robot (seed S.5): the Cursor's, with SAC α = 0.1 and, for
/// absolute pushes, 4 new episodes per epoch.
fn robot_config(env: &UarmEnv, args: &UarmTrainArgs) -> Result<TrainConfig> {
    let mut config = TrainConfig::preset("lightsout-cursor")?;
    config.env = env.spec().name.clone();
    config.env_steps = args.env_steps;
    config.seed = args.seed;
    config.sac.alpha = 0.1;
    if args.action_space == ActionSpace::Absolute {
        config.episodes_per_epoch = 4;
    }
    Ok(config)
}

/// `seads uarm train`.
pub fn train(args: UarmTrainArgs) -> Result<()> {
    // Before the twin or the arm starts a thread: the kernels of the run (the preset's when new).
    let portable = if args.resume {
        load_config(&args.out)?.portable_numerics
    } else {
        TrainConfig::preset("lightsout-cursor")?.portable_numerics
    };
    crate::kernels::use_kernels(portable)?;
    let twin = args.connection.twin()?;
    let env = build_env(&args, twin.as_ref())?;
    let trainer =
        |config: TrainConfig| Trainer::with_environments(config, env.box_clone(), env.box_clone());
    let mut run = if args.resume {
        crate::train::resume(&args.out, Run::resume_with(&args.out, trainer))?
    } else {
        Run::with_trainer(&args.out, trainer(robot_config(&env, &args)?)?)
            .map_err(|e| BadInput(e.into()))?
    };
    crate::train::drive(&mut run, args.quiet)?;
    drop(run);
    evaluate(&args.out, env, twin.is_some(), args.boards, args.timeout)
}

/// Success with re-planning on test boards of depth 1–5 (the twin's boards can be set), or on the
/// boards the app shows (the real tablet's cannot).
fn evaluate(
    run: &Path,
    mut env: UarmEnv,
    settable: bool,
    boards: usize,
    timeout: f64,
) -> Result<()> {
    let config = load_config(run)?;
    let checkpoint = latest_checkpoint(run)?.context("the run has no checkpoint")?;
    let mut agent = Agent::load_for(config, env.spec().clone(), &checkpoint)?;
    let (policy, model) = agent.parts()?;
    let game = LightsOut::new(5)?;
    let solver = Gf2Solver::new(&game);
    let data = BoardDataset::build(&game, 5)?;
    let mut rng = ChaCha8Rng::seed_from_u64(4343);
    let solve_config = SolveConfig {
        replan: true,
        planner: PlannerConfig {
            timeout_s: Some(timeout),
            ..PlannerConfig::default()
        },
        ..SolveConfig::default()
    };
    let mut solved_per_depth = [0usize; 6];
    let mut tasks_per_depth = [0usize; 6];
    for depth in 1..=5 {
        for _ in 0..boards {
            if settable {
                env.set_board(
                    data.sample(depth, Split::Test, &mut rng)
                        .expect("boards of depth 1..5"),
                )?;
            }
            let d = solver.depth(env.board()).unwrap_or(0).min(5);
            let outcome = solve(&mut env, policy, model, game.goal(), &solve_config)?;
            tasks_per_depth[d] += 1;
            solved_per_depth[d] += outcome.solved as usize;
        }
    }
    let (solved, tasks): (usize, usize) =
        (solved_per_depth.iter().sum(), tasks_per_depth.iter().sum());
    println!(
        "solved {solved} of {tasks} boards with re-planning (per depth 1–5: {})",
        (1..=5)
            .map(|d| format!("{}/{}", solved_per_depth[d], tasks_per_depth[d]))
            .collect::<Vec<_>>()
            .join(", ")
    );
    Ok(())
}
