//! Running evaluations of trained runs; what they write into a run directory, and reading it
//! back, is `seads-study`'s ([`seads_study::evaluation`], [`seads_study::evaluation::journal`]), so that
//! reports and sweeps read evaluations without libtorch.
//!
//! - [`evaluation`]: a trained agent planning on the evaluation protocol
//!   ([`evaluation::run_evaluation`], resuming task by task) and a baseline's policy alone
//!   ([`evaluation::run_policy_evaluation`]);
//! - [`over_training`]: the kept checkpoints of a run, with and without re-planning (Fig. 3);
//! - [`robot`]: the real uArm or its twin;
//! - [`bench`](mod@bench): the planner's benchmark on a forward model fitted to the game.
//!
//! The `seads` command (`seads evaluate`, `seads uarm evaluate`, `seads bench`) is the front end;
//! this crate never prints.
//!
//! ```
//! use seads_evaluation::over_training::Selection;
//!
//! // `seads evaluate --checkpoints 2`: every second kept checkpoint, and always the last.
//! let kept: Vec<(u64, ())> = [100, 200, 300, 400].map(|epoch| (epoch, ())).to_vec();
//! let chosen = "2".parse::<Selection>()?.choose(&kept)?;
//! assert_eq!(chosen.iter().map(|c| c.0).collect::<Vec<_>>(), [100, 300, 400]);
//! # Ok::<(), String>(())
//! ```

pub mod bench;
pub mod evaluation;
pub mod over_training;
pub mod robot;

use seads_study::StudyError;

/// What went wrong in an evaluation: the study's files and inputs, or the learner's networks.
#[derive(Debug, thiserror::Error)]
pub enum EvalError {
    /// Reading or writing the run's files, or an input that cannot be evaluated
    /// ([`StudyError::is_invalid`]).
    #[error(transparent)]
    Study(#[from] StudyError),
    /// Loading or running the learner's networks.
    #[error(transparent)]
    Learning(#[from] seads_rl::RlError),
}

impl EvalError {
    /// Whether the input was bad (a run, option or file that cannot be evaluated), not the
    /// work.
    pub fn is_invalid(&self) -> bool {
        match self {
            Self::Study(e) => e.is_invalid(),
            // What the run cannot do as asked (plan without a model, with a model fitted to
            // another checkpoint).
            Self::Learning(seads_rl::RlError::Run(seads_run::RunError::Config(_))) => true,
            _ => false,
        }
    }
}

impl From<seads_run::RunError> for EvalError {
    fn from(e: seads_run::RunError) -> Self {
        Self::Study(e.into())
    }
}

/// The result of an evaluation.
pub type Result<T, E = EvalError> = std::result::Result<T, E>;
