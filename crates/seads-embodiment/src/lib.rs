//! Embodied environments of SEADS (SPEC §2): a continuous manipulator — Cursor, planar Reacher,
//! Kinova Jaco — in front of a board game.
//!
//! [`Environment`] is the narrow trait every later stage uses: reset with a seed, step, the
//! observation `[manipulator state, z, ρ]`, the ground-truth symbolic mapping Φ(s) = z, setting
//! the board. [`Embodied`] implements it once for every [`Manipulator`]; the board side (reset
//! distribution, push layout, step counter) is shared. Environments are built by name with
//! [`make_env`], and [`VecEnv`] steps a batch of them.
//!
//! Architecture invariant: pure simulation. No printing and no files; randomness only from the
//! seeded streams of each environment (`seed`), so the same seed gives the same episode.

mod board;
mod config;
mod cursor;
mod embodied;
mod error;
mod jaco;
mod layout;
mod policy;
mod reacher;
mod record;
mod registry;
mod runner;
mod scene;
mod spec;

pub use config::EnvConfig;
pub use cursor::Cursor;
pub use embodied::{Embodied, Environment, Manipulator, Touch};
pub use error::EnvError;
pub use jaco::{DEFAULT_SUBSTEPS as JACO_DEFAULT_SUBSTEPS, Jaco, JacoBoard};
pub use layout::Layout;
pub use policy::{SkillPolicy, SkillRun, execute_skill};
pub use reacher::Reacher;
pub use record::{
    Comparison, EpisodeRecord, ReplayError, StepRecord, compare, record_episode, replay_episode,
};
pub use registry::{EnvInfo, env_names, list_envs, make_env};
pub use runner::{VecEnv, random_rollout};
pub use scene::{FieldView, Scene, Shape};
pub use spec::{EnvSpec, Push, StepOutcome};
