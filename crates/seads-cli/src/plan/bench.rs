//! `seads plan-bench`: breadth-first search with a forward model fitted to the LightsOut 5×5
//! move table, timed per depth.

use anyhow::Result;
use clap::Args;
use seads_study::bench::PlanBench;

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

/// `seads plan-bench`: BFS with a forward model fitted to the LightsOut 5×5 move table.
pub fn plan_bench(args: PlanBenchArgs) -> Result<()> {
    seads_rl::set_threads(args.threads.max(1));
    let bench = PlanBench {
        hidden: args.hidden.clone(),
        depths: args.depths.clone(),
        boards: args.boards,
        float32: args.float32,
    };
    // A line per depth as it is timed; a failed write ends the command after the benchmark.
    let mut written = Ok(());
    let report = bench
        .run(|row| {
            if !args.json && written.is_ok() {
                use std::io::Write as _;
                written = writeln!(
                    std::io::stdout().lock(),
                    "depth {}: mean {:.3} s per plan over {} boards (plan lengths {:?})",
                    row.depth,
                    row.mean_s,
                    args.boards,
                    row.plan_lengths
                );
            }
        })
        .map_err(crate::study_error)?;
    written.map_err(|e| anyhow::anyhow!("writing to standard output: {e}"))?;
    if args.json {
        outln!("{}", serde_json::to_string(&report)?);
    } else {
        outln!(
            "model hidden {:?}, agreement with the move table {:.5}, peak memory {:.0} MiB",
            args.hidden,
            report.model_agreement,
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
