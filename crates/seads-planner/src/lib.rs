//! Planning with learned skills (SPEC §4): breadth-first search over skill sequences on
//! bit-packed symbolic states through the [`Successor`](seads_games::Successor) trait, plan
//! execution with and without re-planning, and the task evaluation protocol.
//!
//! Architecture invariant: no tensors. The learned forward model reaches the planner only
//! through `Successor` (implemented in `seads-skillmodel`), the skill policy only through
//! `SkillPolicy` (implemented in `seads-rl`); the ground-truth game implements `Successor` too,
//! so the same search runs on the real rules for comparison.
//!
//! # Example: plan with the true game's successor
//!
//! ```
//! use seads_games::{BoardGame, GameSuccessor, LightsOut};
//! use seads_planner::{PlannerConfig, bfs_plan};
//!
//! let game = LightsOut::new(5)?;
//! // A board three moves from the goal.
//! let start = game.apply_all(game.goal(), &[3, 12, 20]);
//! // Skill k performs move k; a learned forward model plugs in the same way.
//! let plan = bfs_plan(&mut GameSuccessor::new(&game), start, game.goal(), &PlannerConfig::default())?;
//! assert_eq!(plan.skills.len(), 3); // breadth-first: a shortest plan
//! assert_eq!(game.apply_all(start, &plan.skills), game.goal());
//! assert_eq!(plan.predicted.last(), Some(&game.goal()));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! `cargo run -p seads-planner --example plan` plans on a LightsOut board and executes the plan
//! in `lightsout-cursor` with a scripted skill policy, with and without re-planning.

mod bfs;
mod evaluate;
mod execute;
mod meet;
mod memo;
mod protocol;

pub use bfs::{Interrupt, Plan, PlanChoice, PlanError, PlannerConfig, Search, bfs_plan};
pub use evaluate::{
    CheckpointId, DepthResult, Evaluation, EvaluationRecord, EvaluationSummary, Evaluator,
    TaskRecord, TaskSummary, evaluate, evaluate_resuming, summarise,
};
pub use execute::{Deviation, SolveConfig, SolveOutcome, solve};
pub use meet::meet_plan;
pub use memo::Memo;
pub use protocol::{
    DEFAULT_MAX_EXPANDED, EVALUATION_SEEDS, EvaluationKind, PlanModel, Protocol, STANDARD_BOARDS,
    STANDARD_DEPTHS, SearchLimits, TASK_STREAM_SEED, TaskSet,
};

/// A plan from `start` to `goal` by the search `config.search` names.
pub fn find_plan(
    successor: &mut dyn seads_games::Successor,
    start: seads_games::SymbolicState,
    goal: seads_games::SymbolicState,
    config: &PlannerConfig,
) -> Result<Plan, PlanError> {
    match config.search {
        Search::Breadth => bfs_plan(successor, start, goal, config),
        Search::BothEnds => meet_plan(successor, start, goal, config),
    }
}
