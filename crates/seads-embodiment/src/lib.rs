//! Embodied environments of SEADS (SPEC §2): a continuous manipulator — Cursor, planar Reacher,
//! Kinova Jaco — in front of a board game.
//!
//! [`Environment`] is the narrow trait every later stage uses: reset with a seed, step, the
//! observation `[manipulator state, z, ρ]`, the ground-truth symbolic mapping Φ(s) = z, setting
//! the board. [`Embodied`] implements it once for every [`Manipulator`]; the board side (reset
//! distribution, push layout, step counter) is shared. Environments are built by name with
//! [`make_env`].
//!
//! Architecture invariant: pure simulation. No printing and no files; randomness only from the
//! seeded streams of each environment (`seed`), so the same seed gives the same episode.
//!
//! The Jaco environments (rapier3d) sit behind the default feature `jaco`; with
//! `default-features = false` the crate has Cursor and Reacher only and no physics engine.
//!
//! # Example: a rollout and its observation layout
//!
//! ```
//! use seads_embodiment::{EnvConfig, Push, make_env};
//!
//! let mut env = make_env("lightsout-cursor", &EnvConfig::default())?;
//! let spec = env.spec().clone();
//! // Observation: [manipulator state, z (the board's bits), ρ (steps left, scaled)].
//! assert_eq!(spec.obs_dim, spec.manipulator_dim + spec.symbolic_len + 1);
//! assert_eq!((spec.manipulator_dim, spec.symbolic_len, spec.action_dim), (2, 25, 3));
//! env.seed(7);
//! env.reset()?;
//! let before = env.board();
//! // The cursor moves by (dx, dy) and pushes where it lands when the third value is positive.
//! let obs = env.observation();
//! let (x, y) = (obs[0], obs[1]);
//! let target = [0.1f32, 0.1]; // the centre of field 0 (row 0, column 0)
//! let mut step = env.step(&[(target[0] - x).clamp(-0.2, 0.2), (target[1] - y).clamp(-0.2, 0.2), -1.0])?;
//! while (env.observation()[0] - target[0]).abs() > 1e-3 || (env.observation()[1] - target[1]).abs() > 1e-3 {
//!     let o = env.observation();
//!     step = env.step(&[(target[0] - o[0]).clamp(-0.2, 0.2), (target[1] - o[1]).clamp(-0.2, 0.2), -1.0])?;
//! }
//! step = env.step(&[0.0, 0.0, 1.0])?;
//! assert_eq!(step.push, Push::Move(0));
//! assert_ne!(env.board(), before);
//! # Ok::<(), seads_embodiment::EnvError>(())
//! ```
//!
//! The examples: `cargo run -p seads-embodiment --example rollout` (random actions, what they
//! press, and a frame as SVG).

mod board;
mod config;
mod cursor;
mod embodied;
mod error;
mod filmed;
#[cfg(feature = "jaco")]
mod jaco;
mod layout;
mod noise;
mod policy;
mod reacher;
mod reacher3;
mod record;
mod registry;
mod runner;
mod scene;
mod spec;
mod task;
mod wrapper;

pub use board::BoardState;
pub use config::{EnvConfig, NoOptions};
pub use cursor::Cursor;
pub use embodied::{Embodied, Environment, Manipulator, Touch};
pub use error::EnvError;
pub use filmed::{Film, Filmed};
#[cfg(feature = "jaco")]
pub use jaco::{DEFAULT_SUBSTEPS as JACO_DEFAULT_SUBSTEPS, Jaco, JacoBoard, JacoOptions};
pub use layout::Layout;
pub use noise::{ACTION_NOISE_STREAM, ActionNoise, Noise};
pub use policy::{SkillPolicy, SkillRun, execute_skill};
pub use reacher::Reacher;
pub use reacher3::Reacher3;
pub use record::{
    Comparison, EpisodeRecord, ReplayError, StepRecord, compare, record_episode, replay_episode,
    restore_state,
};
pub use registry::{EnvInfo, env_names, list_envs, make_env};
pub use runner::{Throughput, random_rollout};
pub use scene::{FieldView, Scene, Shape};
pub use spec::{EnvSpec, Push, StepOutcome};
pub use task::{TaskEnv, TaskStep};
pub use wrapper::{Layer, Wrapped};
