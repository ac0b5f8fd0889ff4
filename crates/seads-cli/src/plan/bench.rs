//! `seads plan-bench`: breadth-first search with a forward model fitted to a game's move table
//! (LightsOut 5×5 by default), timed per depth.

use anyhow::{Context, Result};
use clap::Args;
use seads_evaluation::bench::PlanBench;

/// Arguments of `seads plan-bench`.
#[derive(Debug, Args)]
pub struct PlanBenchArgs {
    /// The game whose move table the model is fitted to (one whose boards can be listed).
    #[arg(long, default_value = "lightsout")]
    game: seads_games::GameKind,
    /// Hidden layer sizes of the forward model (the paper's: 256,256), each from 1 to 16384.
    #[arg(long, default_value = "256,256", value_delimiter = ',',
          value_parser = clap::value_parser!(i64).range(1..=MAX_WIDTH))]
    hidden: Vec<i64>,
    /// Solution depths of the benchmark boards.
    #[arg(long, default_value = "5,7,9", value_delimiter = ',')]
    depths: Vec<usize>,
    /// Boards per depth (test split).
    #[arg(long, default_value_t = 3)]
    boards: usize,
    /// Threads of the search (libtorch's and the bookkeeping's; 1: the one-core figure).
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..))]
    threads: u32,
    /// Where the forward model's successors are computed: cpu, cuda or cuda:N. The model is
    /// fitted on the CPU either way, so the plans and counts are comparable.
    #[arg(long, default_value = "cpu")]
    device: seads_rl::ComputeDevice,
    /// Time limit per search, seconds: the first depth that hits it is the last one run.
    #[arg(long, value_parser = crate::numbers::positive_finite)]
    timeout: Option<f64>,
    /// Compute every logit in float32, without the 8-bit screen (the same plans, more
    /// arithmetic; for comparison). Without it the bench screens on any processor, while the
    /// planner screens only on processors with 8-bit dot products (VNNI).
    #[arg(long)]
    float32: bool,
    /// Which plan each search returns: most-likely (default), most-likely-wary (the same for a
    /// single search) or first-found (the paper's), to compare the choices' cost with one binary.
    #[arg(long, value_name = "CHOICE", default_value = "most-likely")]
    plan: seads_planner::PlanChoice,
    /// How each search goes: breadth (default, the paper's) or both-ends, to compare the two
    /// searches' cost with one binary.
    #[arg(long, value_name = "SEARCH", default_value = "breadth")]
    search: seads_planner::Search,
    /// Print JSON.
    #[arg(long)]
    json: bool,
}

/// The widest hidden layer `--hidden` may ask for (the paper's is 256): a size beyond it would
/// exhaust memory inside libtorch.
const MAX_WIDTH: i64 = 16_384;

/// `seads plan-bench`: BFS with a forward model fitted to a game's move table.
pub fn plan_bench(args: PlanBenchArgs) -> Result<()> {
    let device = crate::usable_device(args.device)?;
    let threads = args.threads as usize;
    crate::check_threads("--threads", threads)?;
    // The search's parts and bookkeeping run on the pool, each part on one libtorch thread.
    seads_rl::set_threads(1);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .context("starting the search's threads")?;
    let bench = PlanBench {
        game: args.game,
        hidden: args.hidden.clone(),
        depths: args.depths.clone(),
        boards: args.boards,
        float32: args.float32,
        device,
        timeout_s: args.timeout,
        plan: args.plan,
        search: args.search,
    };
    // A line per depth as it is timed; a failed write ends the command after the benchmark.
    let mut written = Ok(());
    let report = pool
        .install(|| {
            bench.run(|row| {
                if !args.json && written.is_ok() {
                    use std::io::Write as _;
                    written = writeln!(std::io::stdout().lock(), "{}", row.summary());
                }
            })
        })
        .map_err(crate::eval_error)?;
    written.map_err(|e| anyhow::anyhow!("writing to standard output: {e}"))?;
    if args.json {
        outln!("{}", serde_json::to_string(&report)?);
    } else {
        outln!("{}", report.summary());
    }
    Ok(())
}
