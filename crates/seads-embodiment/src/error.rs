//! Errors of the environments.

use seads_games::GameError;

/// What can go wrong when building or stepping an environment.
#[derive(Debug, thiserror::Error)]
pub enum EnvError {
    /// No environment of this name is registered.
    #[error("unknown environment {name:?}; valid environments: {valid}")]
    UnknownEnv {
        /// The requested name.
        name: String,
        /// The registered names, comma-separated.
        valid: String,
    },
    /// An action vector of the wrong length.
    #[error("{env}: an action has {expected} values, got {found}")]
    ActionLength {
        /// Environment name.
        env: String,
        /// Expected length.
        expected: usize,
        /// Given length.
        found: usize,
    },
    /// An action with a NaN or infinite entry.
    #[error("{env}: action entry {index} is {value}, not a finite number")]
    NonFiniteAction {
        /// Environment name.
        env: String,
        /// Index of the offending entry.
        index: usize,
        /// The value.
        value: f32,
    },
    /// The simulated state became NaN or infinite.
    #[error("{env}: the physics state became non-finite after {steps} steps (simulation diverged)")]
    NonFiniteState {
        /// Environment name.
        env: String,
        /// Steps since the last reset.
        steps: usize,
    },
    /// A task episode was stepped after it ended (solved or out of time) without a reset.
    #[error("{env}: the task episode is over (solved or out of time); reset it first")]
    EpisodeOver {
        /// Environment name.
        env: String,
    },
    /// `step` was called after the skill's step limit without a reset.
    #[error(
        "{env}: the step limit of {limit} steps is reached; reset the environment or its step counter first"
    )]
    StepLimitReached {
        /// Environment name.
        env: String,
        /// The limit.
        limit: usize,
    },
    /// A configuration value that cannot be used.
    #[error("invalid environment configuration: {0}")]
    InvalidConfig(String),
    /// The manipulator's options (`EnvConfig::manipulator`) do not fit its options type.
    #[error("{env}: invalid manipulator options: {source}")]
    ManipulatorOptions {
        /// Environment name.
        env: String,
        /// What the options type said.
        source: serde_json::Error,
    },
    /// A manipulator state of the wrong length or out of range.
    #[error("{env}: invalid manipulator state: {reason}")]
    InvalidState {
        /// Environment name.
        env: String,
        /// What is wrong.
        reason: String,
    },
    /// The operation is not available for this environment.
    #[error("{env}: {what} is not supported")]
    Unsupported {
        /// Environment name.
        env: String,
        /// The operation.
        what: String,
    },
    /// The robot hardware failed (the arm was left at hover height where possible).
    #[error("{env}: hardware failure")]
    Hardware {
        /// Environment name.
        env: String,
        /// What failed.
        #[source]
        source: Box<dyn std::error::Error + Send + Sync>,
    },
    /// A board that the game does not accept.
    #[error(transparent)]
    Game(#[from] GameError),
}
