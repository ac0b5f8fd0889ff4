//! `seads plan-bench`: breadth-first search with a forward model fitted to the LightsOut 5×5
//! move table, timed per depth.

use std::time::Instant;

use anyhow::{Context, Result, bail};
use clap::Args;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use seads_games::{BoardDataset, BoardGame, LightsOut, Split};
use seads_planner::{PlannerConfig, bfs_plan};
use seads_skillmodel::{SkillModelConfig, agreement_with_game, fit_to_game};
use serde::Serialize;

use crate::BadInput;

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
            outln!(
                "depth {depth}: mean {:.3} s per plan over {} boards (plan lengths {:?})",
                row.mean_s,
                args.boards,
                row.plan_lengths
            );
        }
        report.depths.push(row);
    }
    report.peak_rss_mib = peak_rss_mib();
    let after = model.screen_counts();
    (report.screened, report.recomputed) = (after.0 - before.0, after.1 - before.1);
    if args.json {
        outln!("{}", serde_json::to_string(&report)?);
    } else {
        outln!(
            "model hidden {:?}, agreement with the move table {:.5}, peak memory {:.0} MiB",
            args.hidden,
            agreement,
            report.peak_rss_mib
        );
        if !args.float32 {
            outln!(
                "8-bit screen: {} (state, skill) pairs, {} of them computed again in float32",
                report.screened,
                report.recomputed
            );
        }
    }
    Ok(())
}
