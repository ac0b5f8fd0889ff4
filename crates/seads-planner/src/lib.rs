//! Planning with learned skills (SPEC §4): breadth-first search over skill sequences on
//! bit-packed symbolic states through the [`Successor`](seads_games::Successor) trait, plan
//! execution with and without re-planning, and the task evaluation protocol.
//!
//! Architecture invariant: no tensors. The learned forward model reaches the planner only
//! through `Successor` (implemented in `seads-skillmodel`), the skill policy only through
//! `SkillPolicy` (implemented in `seads-rl`); the ground-truth game implements `Successor` too,
//! so the same search runs on the real rules for comparison.

mod bfs;
mod evaluate;
mod execute;

pub use bfs::{Plan, PlanError, PlannerConfig, bfs_plan};
pub use evaluate::{
    DepthResult, EVALUATION_SEEDS, Evaluation, EvaluationSummary, evaluate, summarise,
};
pub use execute::{SolveConfig, SolveOutcome, solve};
