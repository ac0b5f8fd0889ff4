//! `seads evaluate`: task success of a trained agent (planning, with or without re-planning),
//! of its checkpoints over training, or of a baseline's policy.

use std::path::PathBuf;

use anyhow::{Result, bail};
use clap::Args;
use seads_games::Split;
use seads_planner::{EvaluationKind, PlanModel, Protocol, TaskSet, summarise};
use seads_rl::ComputeDevice;

use super::{evaluate_with_bar, load_agent};
use crate::BadInput;
use seads_evaluation::evaluation::run_policy_evaluation;
use seads_study::evaluation;

/// Arguments of `seads evaluate`.
#[derive(Debug, Args)]
pub struct EvaluateArgs {
    /// Run directory of a trained agent.
    #[arg(long)]
    run: PathBuf,
    /// Solution depths of the boards: a range (1-5; 6-12 for the deep study) or a list.
    #[arg(long, default_value = "1-5")]
    depths: String,
    /// Boards per depth.
    #[arg(long, default_value_t = 20)]
    boards: usize,
    /// Board split.
    #[arg(long, default_value = "test")]
    split: Split,
    /// Re-plan when the board deviates from the prediction (Algorithm 2).
    #[arg(long)]
    replan: bool,
    /// Seed of the task list (default: the 20 seeds of the authors' evaluation).
    #[arg(long)]
    seed: Option<u64>,
    /// Use the checkpoint of this epoch instead of the latest.
    #[arg(long)]
    checkpoint: Option<u64>,
    /// Success over training: evaluate `all` kept checkpoints, every N-th (and the last), or the
    /// listed epochs (`100,300,1000`; one epoch: `500,`), with and without re-planning,
    /// appending to evaluation-over-training.jsonl in the run directory. Checkpoints already
    /// there are skipped.
    #[arg(long, conflicts_with_all = ["checkpoint", "replan", "seed"])]
    checkpoints: Option<seads_evaluation::over_training::Selection>,
    #[command(flatten)]
    search: super::SearchArgs,
    /// Execute skills with Gaussian noise of this standard deviation on every low-level action
    /// (the authors' evaluation under noise used 0.05 for the cursor), drawn from each task's
    /// seed; the files are named `evaluation-replan-noise-STD…`.
    #[arg(long, value_parser = crate::numbers::non_negative_finite, conflicts_with = "checkpoints")]
    action_noise: Option<f64>,
    /// Plan with the forward model fitted to the run's skills (`seads fit-model`) instead of
    /// its own: the one way to plan with the skills of a learner that learns no model (DIAYN,
    /// VIC). The files are named `evaluation-replan-fitted-model…`.
    #[arg(long, conflicts_with = "checkpoints")]
    fitted_model: bool,
    /// Where the networks run: cpu, cuda (the first GPU) or cuda:N, whichever device the run
    /// trained on. The plans are the same on either.
    #[arg(long, default_value = "cpu")]
    device: ComputeDevice,
    /// No progress bar.
    #[arg(long)]
    quiet: bool,
    /// Print JSON (implies --quiet).
    #[arg(long)]
    json: bool,
}

/// `seads evaluate`.
pub fn evaluate_run(args: EvaluateArgs) -> Result<()> {
    let depths = crate::numbers::depths(&args.depths)
        .map_err(|e| BadInput(anyhow::anyhow!("--depths: {e}")))?;
    // The planner's parts run on rayon's threads, each on one libtorch thread.
    seads_rl::set_threads(1);
    let limits = args.search.limits();
    let asked = TaskSet {
        depths: depths.clone(),
        ..TaskSet::standard(args.boards)
    };
    if let Some(problem) = asked.problem() {
        bail!(BadInput(anyhow::anyhow!(
            "--boards {}: {problem}",
            args.boards
        )));
    }
    let mut config = crate::run_config(&args.run)?;
    config.device = crate::usable_device(args.device)?;
    let _lock = crate::lock_run(&args.run)?;
    if config.baseline_training().is_ok() {
        if args.action_noise.is_some() || args.fitted_model {
            bail!(BadInput(anyhow::anyhow!(
                "--action-noise and --fitted-model are for planning evaluations of skill \
                 learners; {} is a baseline",
                args.run.display()
            )));
        }
        if args.checkpoints.is_some() {
            bail!(BadInput(anyhow::anyhow!(
                "{}: a baseline's task success over training is in its metrics.jsonl; \
                 --checkpoints is for SEADS runs",
                args.run.display()
            )));
        }
        let tasks = TaskSet {
            depths,
            boards: args.boards,
            split: args.split,
            seed: args.seed,
        };
        return evaluate_policy(&args, &config, tasks);
    }
    if let Some(selection) = args.checkpoints {
        let tasks = TaskSet {
            depths,
            ..TaskSet::standard(args.boards)
        };
        let added = super::evaluate_checkpoints_with_bar(
            &args.run,
            selection,
            &tasks,
            limits,
            args.quiet || args.json,
            args.device,
        )?;
        let lines = evaluation::read_over_training_of(&args.run, &tasks, limits)?;
        if args.json {
            outln!("{}", serde_json::to_string(&lines)?);
        } else {
            outln!(
                "{added} new evaluation(s); {} in {}",
                lines.len(),
                args.run.join(evaluation::OVER_TRAINING).display()
            );
            outln!("{}", evaluation::over_training_table(&lines));
        }
        return Ok(());
    }
    let mut agent = load_agent(&args.run, args.checkpoint, args.device)?;
    let protocol = Protocol {
        kind: EvaluationKind::planning(args.replan),
        tasks: TaskSet {
            depths,
            boards: args.boards,
            split: args.split,
            seed: args.seed,
        },
        limits: Some(limits),
        action_noise: args.action_noise,
        model: if args.fitted_model {
            PlanModel::Fitted
        } else {
            PlanModel::Own
        },
    };
    let record = evaluate_with_bar(&mut agent, &args.run, &protocol, args.quiet || args.json)?;
    let results = record.results;
    let summary = summarise(&results);
    if args.json {
        outln!("{}", serde_json::to_string(&summary)?);
    } else {
        outln!(
            "{} (epoch {}), {}{}, {} boards per depth{}",
            agent.config.env,
            agent.epoch,
            if args.replan {
                "with re-planning"
            } else {
                "plan once"
            },
            if args.fitted_model {
                " with the fitted model"
            } else {
                ""
            },
            args.boards,
            args.action_noise
                .map_or(String::new(), |s| format!(", action noise σ = {s}"))
        );
        outln!("{}", summary.table());
    }
    Ok(())
}

/// `seads evaluate` on a baseline run: its policy alone on the tasks of the protocol, saved as
/// `evaluation-policy.json` (depths 1–5) or `evaluation-policy-depths-A-B.json`, with one line
/// per task (the boards a planning evaluation of the same tasks plays).
fn evaluate_policy(
    args: &EvaluateArgs,
    config: &seads_rl::TrainConfig,
    tasks: TaskSet,
) -> Result<()> {
    crate::kernels::use_kernels(config.portable_numerics)?;
    let checkpoint =
        seads_rl::find_checkpoint(&args.run, args.checkpoint).map_err(|e| BadInput(e.into()))?;
    let record = run_policy_evaluation(config, &args.run, &checkpoint, tasks)?;
    let results = record.results;
    let summary = summarise(&results);
    if args.json {
        outln!("{}", serde_json::to_string(&summary)?);
    } else {
        outln!(
            "{} ({}), its policy alone, {} boards per depth",
            args.run.display(),
            checkpoint.display(),
            args.boards
        );
        for r in &results {
            outln!("depth {}: {}/{} solved", r.depth, r.solved, r.tasks);
        }
    }
    Ok(())
}
