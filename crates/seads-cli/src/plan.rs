//! `seads solve`, `seads evaluate`, `seads plan-bench`: planning with a trained agent.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, Result, bail};
use clap::Args;
use indicatif::ProgressBar;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use seads_games::{BoardDataset, BoardGame, LightsOut, Split};
use seads_planner::{
    DepthResult, EVALUATION_SEEDS, Evaluation, PlannerConfig, SolveConfig, TaskRecord, bfs_plan,
    evaluate, solve, summarise,
};
use seads_rl::Agent;
use seads_skillmodel::{SkillModelConfig, agreement_with_game, fit_to_game};
use serde::Serialize;

use crate::BadInput;
use crate::envs::build_env;

/// Loads the agent of a run, turning a missing or foreign directory into a clear error.
pub fn load_agent(run: &Path, checkpoint: Option<u64>) -> Result<Agent> {
    let config = seads_rl::load_config(run)
        .with_context(|| format!("loading the agent of run {}", run.display()))?;
    crate::kernels::use_kernels(config.portable_numerics)?;
    if config.algorithm != seads_rl::Algorithm::Seads {
        bail!(BadInput(anyhow::anyhow!(
            "{} is a {} baseline run: it has no skills to plan with (`seads evaluate --run` \
             measures its policy's task success)",
            run.display(),
            config.algorithm.name()
        )));
    }
    Agent::load(run, checkpoint)
        .with_context(|| format!("loading the agent of run {}", run.display()))
}

/// Arguments of `seads solve`.
#[derive(Debug, Args)]
pub struct SolveArgs {
    /// Run directory of a trained agent (from `seads train`).
    #[arg(long)]
    run: PathBuf,
    /// The board to solve, comma-separated field values (see `seads games solve --help`).
    #[arg(long)]
    board: String,
    /// Re-plan when the board deviates from the prediction (Algorithm 2); otherwise plan once.
    #[arg(long)]
    replan: bool,
    /// Use the checkpoint of this epoch instead of the latest.
    #[arg(long)]
    checkpoint: Option<u64>,
    /// Seed of the manipulator's initial state.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Time limit per search, seconds.
    #[arg(long, default_value_t = 300.0, value_parser = crate::positive_finite)]
    timeout: f64,
    /// Draw the board and the executed skills' paths into this image (.png or .svg).
    #[arg(long)]
    render: Option<PathBuf>,
    /// Print JSON.
    #[arg(long)]
    json: bool,
}

/// `seads solve`.
pub fn solve_board(args: SolveArgs) -> Result<()> {
    let mut agent = load_agent(&args.run, args.checkpoint)?;
    let mut env = build_env(&agent.config.env, &agent.config.env_config)?;
    let game = env.spec().game.build(env.spec().board_size)?;
    let board = game.parse(&args.board).map_err(|e| BadInput(e.into()))?;
    env.seed(args.seed);
    env.reset()?;
    env.set_board(board).map_err(|e| BadInput(e.into()))?;
    let before = env.scene();
    let config = SolveConfig {
        replan: args.replan,
        planner: PlannerConfig {
            timeout_s: Some(args.timeout),
            ..PlannerConfig::default()
        },
        ..SolveConfig::default()
    };
    let (policy, model) = agent.parts()?;
    let outcome = solve(env.as_mut(), policy, model, game.goal(), &config)?;
    if let Some(out) = &args.render {
        let status = if outcome.solved {
            "solved"
        } else {
            "not solved"
        };
        let title = format!(
            "{}: {} in {} steps",
            agent.config.env, status, outcome.manipulator_steps
        );
        crate::draw::render_solution(&before, &outcome.runs, &title, out)?;
    }
    if args.json {
        #[derive(Serialize)]
        struct Report<'a> {
            board: String,
            checkpoint: String,
            #[serde(flatten)]
            outcome: &'a seads_planner::SolveOutcome,
        }
        let report = Report {
            board: game.format(board),
            checkpoint: agent.checkpoint.display().to_string(),
            outcome: &outcome,
        };
        println!("{}", serde_json::to_string(&report)?);
    } else {
        let list = |v: &[usize]| {
            v.iter()
                .map(|s| s.to_string())
                .collect::<Vec<_>>()
                .join(" ")
        };
        if outcome.plan_found {
            println!(
                "plan ({} skills): {}   search {:.3} s over {} plan(s)",
                outcome.first_plan.len(),
                list(&outcome.first_plan),
                outcome.planning_s,
                outcome.plans
            );
        }
        println!(
            "executed skills: {}   manipulator steps per skill: {}",
            list(&outcome.executed),
            list(&outcome.skill_steps)
        );
        match &outcome.failure {
            None => println!("solved in {} manipulator steps", outcome.manipulator_steps),
            Some(why) => println!("not solved: {why}"),
        }
    }
    Ok(())
}

/// Parses "1-5", "6,8,10" or "3".
fn parse_depths(text: &str) -> Result<Vec<usize>> {
    let bad = || {
        BadInput(anyhow::anyhow!(
            "--depths takes a range like 1-5 or a list like 1,3,5, got {text:?}"
        ))
    };
    let depths: Vec<usize> = if let Some((a, b)) = text.split_once('-') {
        let (a, b): (usize, usize) = (
            a.trim().parse().map_err(|_| bad())?,
            b.trim().parse().map_err(|_| bad())?,
        );
        (a..=b).collect()
    } else {
        text.split(',')
            .map(|d| d.trim().parse().map_err(|_| bad()))
            .collect::<Result<_, _>>()?
    };
    if depths.is_empty() || depths.contains(&0) {
        return Err(bad().into());
    }
    Ok(depths)
}

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
    checkpoints: Option<crate::overtraining::Selection>,
    /// Time limit per search, seconds (the authors' evaluation used 60).
    #[arg(long, default_value_t = 60.0, value_parser = crate::positive_finite)]
    timeout: f64,
    /// Also stop each search after expanding this many states: a limit that, unlike the clock,
    /// gives the same results on every machine.
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..))]
    max_expanded: Option<u64>,
    /// Print JSON.
    #[arg(long)]
    json: bool,
}

/// Environment seeds of the tasks: the authors' 20 by default, else drawn from `seed`.
pub fn task_seeds(boards: usize, seed: Option<u64>) -> Vec<u64> {
    match seed {
        None if boards <= EVALUATION_SEEDS.len() => EVALUATION_SEEDS[..boards].to_vec(),
        _ => {
            let mut rng = ChaCha8Rng::seed_from_u64(seed.unwrap_or(4343));
            (0..boards)
                .map(|_| rng.random_range(0..100_000_000))
                .collect()
        }
    }
}

/// How an evaluation acts, as its files in the run directory name it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EvaluationKind {
    /// Plan, and plan again after every skill that deviated from the forward model.
    Replan,
    /// Plan once and execute the whole plan.
    PlanOnce,
    /// A baseline's policy acting alone, no planning.
    Policy,
}

impl EvaluationKind {
    /// The planning evaluation, with or without re-planning.
    pub fn planning(replan: bool) -> Self {
        if replan { Self::Replan } else { Self::PlanOnce }
    }

    fn name(self) -> &'static str {
        match self {
            Self::Replan => "replan",
            Self::PlanOnce => "plan-once",
            Self::Policy => "policy",
        }
    }

    /// The stem of this evaluation's files for these depths: `evaluation-replan` for the
    /// standard depths 1–5, which plots and reports read; `evaluation-replan-depths-6-12` for
    /// other studies, kept beside them.
    pub fn stem(self, depths: &[usize]) -> String {
        match (depths.first(), depths.last()) {
            (Some(a), Some(b)) if depths != [1, 2, 3, 4, 5] => {
                format!("evaluation-{}-depths-{a}-{b}", self.name())
            }
            _ => format!("evaluation-{}", self.name()),
        }
    }

    /// The per-depth results of the standard evaluation (`evaluation-replan.json`).
    pub fn results_file(self) -> String {
        format!("evaluation-{}.json", self.name())
    }

    /// Every task of the standard evaluation, one JSON line each
    /// (`evaluation-replan-tasks.jsonl`).
    pub fn tasks_file(self) -> String {
        format!("evaluation-{}-tasks.jsonl", self.name())
    }
}

/// Limits of each search of an evaluation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SearchLimits {
    /// Seconds per search.
    pub timeout: f64,
    /// States expanded per search (`None`: no bound).
    pub max_expanded: Option<usize>,
}

/// The tasks of an evaluation.
pub struct Tasks {
    /// Solution depths.
    pub depths: Vec<usize>,
    /// Environment seeds (one task per seed and depth).
    pub seeds: Vec<u64>,
    /// Board split.
    pub split: Split,
    /// Re-plan on deviations.
    pub replan: bool,
    /// Limits of each search.
    pub limits: SearchLimits,
}

/// Evaluates the agent on `tasks`, advancing `bar` by one per task.
pub fn evaluate_agent(
    agent: &mut Agent,
    tasks: &Tasks,
    bar: &ProgressBar,
) -> Result<Vec<DepthResult>> {
    evaluate_agent_with(agent, tasks, bar, |_| {})
}

/// [`evaluate_agent`], calling `each` with every task as it ends.
fn evaluate_agent_with(
    agent: &mut Agent,
    tasks: &Tasks,
    bar: &ProgressBar,
    mut each: impl FnMut(&TaskRecord<'_>),
) -> Result<Vec<DepthResult>> {
    let evaluation = Evaluation {
        env: agent.config.env.clone(),
        env_config: agent.config.env_config.clone(),
        depths: tasks.depths.clone(),
        seeds: tasks.seeds.clone(),
        split: tasks.split,
        solve: SolveConfig {
            replan: tasks.replan,
            planner: PlannerConfig {
                timeout_s: Some(tasks.limits.timeout),
                max_expanded: tasks.limits.max_expanded,
                ..PlannerConfig::default()
            },
            ..SolveConfig::default()
        },
    };
    let (policy, model) = agent.parts()?;
    evaluate(&evaluation, policy, model, |task| {
        bar.set_message(format!("depth {}", task.depth));
        bar.inc(1);
        each(task);
    })
    .map_err(|e| BadInput(e.into()).into())
}

/// Evaluates the agent and saves the per-depth results into the run directory
/// (`evaluation-replan.json` or `evaluation-plan-once.json`).
pub fn run_evaluation(
    agent: &mut Agent,
    run: &Path,
    tasks: Tasks,
    quiet: bool,
) -> Result<Vec<DepthResult>> {
    let bar = if quiet {
        ProgressBar::hidden()
    } else {
        ProgressBar::new((tasks.depths.len() * tasks.seeds.len()) as u64)
    };
    let spec = seads_embodiment::make_env(&agent.config.env, &agent.config.env_config)?
        .spec()
        .clone();
    let game = spec.game.build(spec.board_size)?;
    let mut lines = String::new();
    let results = evaluate_agent_with(agent, &tasks, &bar, |task| {
        lines += &task_line(game.as_ref(), task).to_string();
        lines.push('\n');
    })?;
    bar.finish_and_clear();
    let stem = EvaluationKind::planning(tasks.replan).stem(&tasks.depths);
    seads_rl::write_atomic(
        &run.join(format!("{stem}.json")),
        serde_json::to_string_pretty(&results)?.as_bytes(),
    )?;
    seads_rl::write_atomic(&run.join(format!("{stem}-tasks.jsonl")), lines.as_bytes())?;
    Ok(results)
}

/// One line of `evaluation-*-tasks.jsonl`: a task, how it ended, and every skill that left
/// another board than the forward model predicted (boards as `seads solve --board` takes them).
fn task_line(game: &dyn BoardGame, task: &TaskRecord<'_>) -> serde_json::Value {
    let o = task.outcome;
    let deviations: Vec<serde_json::Value> = o
        .deviations
        .iter()
        .map(|d| {
            serde_json::json!({
                "step": d.step,
                "skill": d.skill,
                "before": game.format(d.before),
                "predicted": game.format(d.predicted),
                "reached": game.format(d.reached),
            })
        })
        .collect();
    serde_json::json!({
        "depth": task.depth,
        "seed": task.seed,
        "board": game.format(task.board),
        "solved": o.solved,
        "plan_found": o.plan_found,
        "plans": o.plans,
        "first_plan": o.first_plan,
        "executed": o.executed,
        "skill_steps": o.skill_steps,
        "timed_out": o.timed_out,
        "failure": o.failure,
        "deviations": deviations,
    })
}

/// `seads evaluate`.
pub fn evaluate_run(args: EvaluateArgs) -> Result<()> {
    let depths = parse_depths(&args.depths)?;
    let limits = SearchLimits {
        timeout: args.timeout,
        max_expanded: args
            .max_expanded
            .map(|m| m.try_into().unwrap_or(usize::MAX)),
    };
    if args.boards == 0 {
        bail!(BadInput(anyhow::anyhow!("--boards must be at least 1")));
    }
    let config = seads_rl::load_config(&args.run)
        .with_context(|| format!("loading run {}", args.run.display()))?;
    if config.algorithm.is_baseline() {
        if args.checkpoints.is_some() {
            bail!(BadInput(anyhow::anyhow!(
                "{}: a baseline's task success over training is in its metrics.jsonl; \
                 --checkpoints is for SEADS runs",
                args.run.display()
            )));
        }
        return evaluate_policy(&args, &config, &depths);
    }
    if let Some(selection) = args.checkpoints {
        let added = crate::overtraining::evaluate_checkpoints(
            &args.run,
            selection,
            &depths,
            args.boards,
            limits,
            args.json,
        )?;
        let lines = crate::overtraining::read(&args.run)?;
        if args.json {
            println!("{}", serde_json::to_string(&lines)?);
        } else {
            println!(
                "{added} new evaluation(s); {} in {}",
                lines.len(),
                args.run.join(crate::overtraining::FILE).display()
            );
            println!("     epoch   env steps  mode            success per depth");
            for l in &lines {
                let rates: Vec<String> = l
                    .results
                    .iter()
                    .map(|r| format!("{:.0}%", 100.0 * r.solved as f64 / r.tasks.max(1) as f64))
                    .collect();
                println!(
                    "{:>10}  {:>10}  {:<14}  {}",
                    l.epoch,
                    l.env_steps,
                    if l.replan { "re-planning" } else { "plan once" },
                    rates.join(" ")
                );
            }
        }
        return Ok(());
    }
    let mut agent = load_agent(&args.run, args.checkpoint)?;
    let seeds = task_seeds(args.boards, args.seed);
    let tasks = Tasks {
        depths,
        seeds,
        split: args.split,
        replan: args.replan,
        limits,
    };
    let results = run_evaluation(&mut agent, &args.run, tasks, args.json)?;
    let summary = summarise(&results);
    if args.json {
        println!("{}", serde_json::to_string(&summary)?);
    } else {
        println!(
            "{} (epoch {}), {}, {} boards per depth",
            agent.config.env,
            agent.epoch,
            if args.replan {
                "with re-planning"
            } else {
                "plan once"
            },
            args.boards
        );
        println!(" depth  success  plan found  search s  median steps  median skill steps");
        for r in &results {
            let key = r.depth;
            let fmt = |v: Option<f64>| v.map_or("-".to_owned(), |x| format!("{x:.1}"));
            println!(
                "{:>6}  {:>6.0}%  {:>9.0}%  {:>8.3}  {:>12}  {:>18}",
                r.depth,
                summary.success_rate[&key] * 100.0,
                summary.plan_found[&key] * 100.0,
                summary.planning_s[&key],
                fmt(summary.solution_steps[&key]),
                fmt(summary.skill_steps[&key])
            );
        }
    }
    Ok(())
}

/// `seads evaluate` on a baseline run: its policy alone on the test boards of each depth, saved
/// as `evaluation-policy.json` (depths 1–5) or `evaluation-policy-depths-A-B.json`.
fn evaluate_policy(
    args: &EvaluateArgs,
    config: &seads_rl::TrainConfig,
    depths: &[usize],
) -> Result<()> {
    crate::kernels::use_kernels(config.portable_numerics)?;
    let checkpoint = match args.checkpoint {
        Some(epoch) => args
            .run
            .join("checkpoints")
            .join(seads_rl::checkpoint_name(epoch)),
        None => seads_rl::latest_checkpoint(&args.run)?.ok_or_else(|| {
            BadInput(anyhow::anyhow!(
                "{} has no checkpoint yet",
                args.run.display()
            ))
        })?,
    };
    let mut policy = seads_rl::load_policy(config, &checkpoint)
        .with_context(|| format!("loading the policy of run {}", args.run.display()))?;
    let results = seads_rl::task_success(config, policy.as_mut(), depths, args.boards)?;
    let name = format!("{}.json", EvaluationKind::Policy.stem(depths));
    seads_rl::write_atomic(
        &args.run.join(name),
        serde_json::to_string_pretty(&results)?.as_bytes(),
    )?;
    let summary = summarise(&results);
    if args.json {
        println!("{}", serde_json::to_string(&summary)?);
    } else {
        println!(
            "{} ({}), its policy alone, {} boards per depth",
            args.run.display(),
            checkpoint.display(),
            args.boards
        );
        for r in &results {
            println!("depth {}: {}/{} solved", r.depth, r.solved, r.tasks);
        }
    }
    Ok(())
}

/// Arguments of `seads plan-bench`.
#[derive(Debug, Args)]
pub struct PlanBenchArgs {
    /// Hidden layer sizes of the forward model (the paper's: 256,256).
    #[arg(long, default_value = "256,256", value_delimiter = ',')]
    hidden: Vec<i64>,
    /// Solution depths of the benchmark boards.
    #[arg(long, default_value = "5,7,9", value_delimiter = ',')]
    depths: Vec<usize>,
    /// Boards per depth (test split).
    #[arg(long, default_value_t = 3)]
    boards: usize,
    /// libtorch threads (1: the one-core figure).
    #[arg(long, default_value_t = 1)]
    threads: usize,
    /// Compute every logit in float32, without the 8-bit screen (the same plans, more
    /// arithmetic; for comparison).
    #[arg(long)]
    float32: bool,
    /// Print JSON.
    #[arg(long)]
    json: bool,
}

#[derive(Serialize)]
struct PlanBenchReport {
    hidden: Vec<i64>,
    float32: bool,
    model_agreement: f64,
    /// (state, skill) pairs screened in 8-bit arithmetic, and those computed in float32 after all.
    screened: u64,
    recomputed: u64,
    depths: Vec<PlanBenchDepth>,
    peak_rss_mib: f64,
}

#[derive(Serialize)]
struct PlanBenchDepth {
    depth: usize,
    seconds: Vec<f64>,
    mean_s: f64,
    plan_lengths: Vec<usize>,
    expanded: Vec<usize>,
}

/// Peak resident memory of this process (Linux `VmHWM`), MiB.
fn peak_rss_mib() -> f64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("VmHWM:"))
                .and_then(|l| l.split_whitespace().nth(1)?.parse::<f64>().ok())
        })
        .map_or(f64::NAN, |kib| kib / 1024.0)
}

/// `seads plan-bench`: BFS with a forward model fitted to the LightsOut 5×5 move table.
pub fn plan_bench(args: PlanBenchArgs) -> Result<()> {
    if args.hidden.is_empty()
        || args.hidden.iter().any(|&h| h <= 0)
        || args.depths.contains(&0)
        || args.boards == 0
    {
        bail!(BadInput(anyhow::anyhow!(
            "--hidden, --depths and --boards must be positive"
        )));
    }
    seads_rl::set_threads(args.threads.max(1));
    let game = LightsOut::new(5)?;
    let config = SkillModelConfig {
        hidden: args.hidden.clone(),
        batch_size: 256,
        ..SkillModelConfig::default()
    };
    let mut model = fit_to_game(&game, &config, 1500, 1);
    let agreement = agreement_with_game(&mut model, &game, 2000, 2);
    model.set_int8_screen(!args.float32);
    let before = model.screen_counts();
    let max_depth = *args.depths.iter().max().expect("non-empty");
    let boards = BoardDataset::build(&game, max_depth)?;
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let mut report = PlanBenchReport {
        hidden: args.hidden.clone(),
        float32: args.float32,
        model_agreement: agreement,
        screened: 0,
        recomputed: 0,
        depths: Vec::new(),
        peak_rss_mib: 0.0,
    };
    for &depth in &args.depths {
        let mut row = PlanBenchDepth {
            depth,
            seconds: Vec::new(),
            mean_s: 0.0,
            plan_lengths: Vec::new(),
            expanded: Vec::new(),
        };
        for _ in 0..args.boards {
            let board = boards
                .sample(depth, Split::Test, &mut rng)
                .context("no board of that depth")?;
            let start = Instant::now();
            let plan = bfs_plan(&mut model, board, game.goal(), &PlannerConfig::default());
            row.seconds.push(start.elapsed().as_secs_f64());
            match plan {
                Ok(plan) => {
                    row.plan_lengths.push(plan.skills.len());
                    row.expanded.push(plan.expanded);
                }
                Err(e) => bail!("depth {depth}: {e}"),
            }
        }
        row.mean_s = row.seconds.iter().sum::<f64>() / row.seconds.len() as f64;
        if !args.json {
            println!(
                "depth {depth}: mean {:.3} s per plan over {} boards (plan lengths {:?})",
                row.mean_s, args.boards, row.plan_lengths
            );
        }
        report.depths.push(row);
    }
    report.peak_rss_mib = peak_rss_mib();
    let after = model.screen_counts();
    (report.screened, report.recomputed) = (after.0 - before.0, after.1 - before.1);
    if args.json {
        println!("{}", serde_json::to_string(&report)?);
    } else {
        println!(
            "model hidden {:?}, agreement with the move table {:.5}, peak memory {:.0} MiB",
            args.hidden, agreement, report.peak_rss_mib
        );
        if !args.float32 {
            println!(
                "8-bit screen: {} (state, skill) pairs, {} of them computed again in float32",
                report.screened, report.recomputed
            );
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn evaluation_files_name_the_standard_depths_plainly_and_other_studies_by_range() {
        let replan = EvaluationKind::planning(true);
        assert_eq!(replan.stem(&[1, 2, 3, 4, 5]), "evaluation-replan");
        assert_eq!(
            EvaluationKind::planning(false).stem(&[6, 7, 8, 9, 10, 11, 12]),
            "evaluation-plan-once-depths-6-12"
        );
        assert_eq!(
            EvaluationKind::Policy.stem(&[1, 2, 3]),
            "evaluation-policy-depths-1-3"
        );
        assert_eq!(replan.results_file(), "evaluation-replan.json");
        assert_eq!(replan.tasks_file(), "evaluation-replan-tasks.jsonl");
        assert_eq!(
            EvaluationKind::Policy.results_file(),
            "evaluation-policy.json"
        );
    }
}
