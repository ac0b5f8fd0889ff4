//! The planning benchmark of `seads plan-bench`: breadth-first search with a forward model fitted
//! to a game's move table (LightsOut 5×5 by default), timed per depth on test boards.

use seads_nn::Resolve as _;
use std::time::Instant;

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use seads_games::{BoardDataset, GameKind, Split};
use seads_planner::{PlanError, PlannerConfig, find_plan};
use seads_rl::ComputeDevice;
use seads_skillmodel::{SkillModelConfig, agreement_with_game, fit_to_game};
use serde::Serialize;

use seads_study::StudyError;

use crate::Result;

/// What to time.
#[derive(Debug, Clone)]
pub struct PlanBench {
    /// The game, at its default size, whose move table the model is fitted to.
    pub game: GameKind,
    /// Hidden layer sizes of the forward model.
    pub hidden: Vec<i64>,
    /// Solution depths of the boards.
    pub depths: Vec<usize>,
    /// Boards per depth.
    pub boards: usize,
    /// Every logit in float32, without the 8-bit screen (otherwise the screen is on, whatever
    /// `seads_skillmodel::fast_int8_products` says).
    pub float32: bool,
    /// Where the model's successors are computed. The model is fitted on the CPU either way
    /// (the same weights, so the same plans and counts) and then copied there.
    pub device: ComputeDevice,
    /// A time limit per search, seconds: a depth whose search hits it is reported as such, and
    /// deeper depths are not run (`None`: no limit).
    pub timeout_s: Option<f64>,
    /// Which plan each search returns.
    pub plan: seads_planner::PlanChoice,
    /// How each search goes.
    pub search: seads_planner::Search,
}

/// The timings of one depth.
#[derive(Debug, Clone, Serialize)]
pub struct PlanBenchDepth {
    /// Solution depth of the boards.
    pub depth: usize,
    /// Seconds per plan.
    pub seconds: Vec<f64>,
    /// Their mean.
    pub mean_s: f64,
    /// Skills per plan.
    pub plan_lengths: Vec<usize>,
    /// Nodes expanded per plan.
    pub expanded: Vec<usize>,
    /// Whether a search hit the time limit (the depth's other figures are then incomplete).
    pub timed_out: bool,
}

/// The benchmark's result.
#[derive(Debug, Clone, Serialize)]
pub struct PlanBenchReport {
    /// Hidden layer sizes of the model.
    pub hidden: Vec<i64>,
    /// Where the successors were computed.
    pub device: ComputeDevice,
    /// The GPU's name, for a CUDA device.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub gpu: Option<String>,
    /// Threads of the search's bookkeeping (the rayon pool it ran in).
    pub threads: usize,
    /// Whether the screen was off.
    pub float32: bool,
    /// The fitted model's agreement with the move table.
    pub model_agreement: f64,
    /// (state, skill) pairs screened in 8-bit arithmetic.
    pub screened: u64,
    /// Those of them computed in float32 after all.
    pub recomputed: u64,
    /// Per depth.
    pub depths: Vec<PlanBenchDepth>,
    /// Peak resident memory of the process (Linux `VmHWM`), MiB; NaN elsewhere.
    pub peak_rss_mib: f64,
}

impl PlanBenchDepth {
    /// One line on this depth's searches.
    pub fn summary(&self) -> String {
        if self.timed_out {
            return format!(
                "depth {}: a search hit the time limit; deeper depths not run",
                self.depth
            );
        }
        format!(
            "depth {}: mean {:.3} s per plan over {} boards (plan lengths {:?}, expanded {:?})",
            self.depth,
            self.mean_s,
            self.seconds.len(),
            self.plan_lengths,
            self.expanded
        )
    }
}

impl PlanBenchReport {
    /// The lines after the depths': device, model and memory; the 8-bit screen's counts.
    pub fn summary(&self) -> String {
        let mut text = format!(
            "{} ({} thread(s)), model hidden {:?}, agreement with the move table {:.5}, peak \
             memory {:.0} MiB",
            self.gpu.as_deref().unwrap_or("cpu"),
            self.threads,
            self.hidden,
            self.model_agreement,
            self.peak_rss_mib
        );
        if self.screened > 0 {
            text += &format!(
                "\n8-bit screen: {} (state, skill) pairs, {} of them computed again in float32",
                self.screened, self.recomputed
            );
        }
        text
    }
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

impl PlanBench {
    /// Fits the model, then plans `boards` test boards of each depth, calling `on_depth` after
    /// each depth. Empty or non-positive settings are [`StudyError::Invalid`].
    pub fn run(&self, mut on_depth: impl FnMut(&PlanBenchDepth)) -> Result<PlanBenchReport> {
        let Some(&max_depth) = self.depths.iter().max() else {
            return Err(StudyError::invalid("--depths must name a depth").into());
        };
        if self.hidden.is_empty()
            || self.hidden.iter().any(|&h| h <= 0)
            || self.depths.contains(&0)
            || self.boards == 0
        {
            return Err(
                StudyError::invalid("--hidden, --depths and --boards must be positive").into(),
            );
        }
        let game = self
            .game
            .build(self.game.default_size())
            .map_err(|e| StudyError::invalid(e.to_string()))?;
        let game = game.as_ref();
        let listed = game.enumerable().ok_or_else(|| {
            StudyError::invalid(format!("{}: its boards cannot be listed", self.game))
        })?;
        let config = SkillModelConfig {
            hidden: self.hidden.clone(),
            batch_size: 256,
            ..SkillModelConfig::default()
        };
        let device = self
            .device
            .resolve()
            .map_err(|e| StudyError::invalid(e.to_string()))?;
        let mut model = fit_to_game(game, &config, 1500, 1);
        let model_agreement = agreement_with_game(&mut model, game, 2000, 2);
        model.set_int8_screen(!self.float32);
        if self.device.is_cuda() {
            model = model
                .on_device(&config, device)
                .map_err(|e| StudyError::Failed(format!("copying the model to the device: {e}")))?;
        }
        let before = model.screen_counts();
        let boards = BoardDataset::build(listed, max_depth)
            .map_err(|e| StudyError::invalid(format!("boards up to depth {max_depth}: {e}")))?;
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let mut depths = Vec::new();
        for &depth in &self.depths {
            let mut row = PlanBenchDepth {
                depth,
                seconds: Vec::new(),
                mean_s: 0.0,
                plan_lengths: Vec::new(),
                expanded: Vec::new(),
                timed_out: false,
            };
            let planner = PlannerConfig {
                timeout_s: self.timeout_s,
                plan: self.plan,
                search: self.search,
                ..PlannerConfig::default()
            };
            for _ in 0..self.boards {
                let board = boards.sample(depth, Split::Test, &mut rng).ok_or_else(|| {
                    StudyError::invalid(format!("{} has no test board of depth {depth}", self.game))
                })?;
                let start = Instant::now();
                let plan = find_plan(&mut model, board, game.goal(), &planner);
                row.seconds.push(start.elapsed().as_secs_f64());
                if let Err(PlanError::Timeout { .. }) = plan {
                    row.timed_out = true;
                    break;
                }
                let plan = plan.map_err(|e| StudyError::Failed(format!("depth {depth}: {e}")))?;
                row.plan_lengths.push(plan.skills.len());
                row.expanded.push(plan.expanded);
            }
            row.mean_s = row.seconds.iter().sum::<f64>() / row.seconds.len() as f64;
            on_depth(&row);
            let timed_out = row.timed_out;
            depths.push(row);
            if timed_out {
                break;
            }
        }
        let after = model.screen_counts();
        Ok(PlanBenchReport {
            hidden: self.hidden.clone(),
            device: self.device,
            gpu: self.device.gpu_name(),
            threads: rayon::current_num_threads(),
            float32: self.float32,
            model_agreement,
            screened: after.0 - before.0,
            recomputed: after.1 - before.1,
            depths,
            peak_rss_mib: peak_rss_mib(),
        })
    }
}
