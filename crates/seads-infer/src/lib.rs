//! A trained SEADS agent without libtorch (SPEC §3–4): reads a run directory's checkpoint (two
//! safetensors files and the config it was trained with) and evaluates its networks in plain
//! Rust, with `ndarray`'s matrix products:
//!
//! - [`Policy`], the skill policy π(a | s, k): deterministic actions and seeded samples, as the
//!   trainer computes them, and a [`SkillPolicy`](seads_embodiment::SkillPolicy), so the
//!   planner's executor runs its skills;
//! - [`ForwardModel`], the symbolic forward model q(z_T | z_0, k): a
//!   [`Successor`], so the planner plans with it, with the model's
//!   log-probabilities for the most likely plan;
//! - [`MixtureModel`], the mixture of forward models (`skill_model.kind = "mixture"`), planned
//!   with in the same way; [`Model`] holds whichever the run learned.
//!
//! The networks are small perceptrons (two hidden layers of 256, ReLU), so a CPU evaluates them
//! quickly; the crate links neither libtorch nor a physics engine, and so serves the Python
//! package, where a second libtorch beside PyTorch's would crash the process.
//!
//! # Example
//!
//! ```no_run
//! use seads_games::{BoardGame, LightsOut};
//! use seads_infer::Agent;
//! use seads_planner::{PlannerConfig, find_plan};
//!
//! let mut agent = Agent::load("runs/demo".as_ref(), None)?; // the latest checkpoint
//! let game = LightsOut::new(5)?;
//! let board = game.apply_all(game.goal(), &[3, 12]);
//! let plan = find_plan(&mut agent.model, board, game.goal(), &PlannerConfig::default())?;
//! println!("skills {:?}", plan.skills);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod checkpoint;
mod mixture;
mod mlp;
mod model;
mod policy;

use std::path::Path;

use seads_embodiment::{EnvConfig, EnvSpec, make_env};
use seads_games::{Successor, SymbolicState};

pub use checkpoint::{Tensors, checkpoint_dir};
pub use mixture::MixtureModel;
pub use mlp::{Dense, Mlp};
pub use model::ForwardModel;
pub use policy::Policy;

/// Why an agent could not be loaded or asked.
#[derive(Debug, thiserror::Error)]
pub enum InferError {
    /// A file could not be read.
    #[error("{what}: {source}")]
    Io {
        /// What was being done.
        what: String,
        /// The cause.
        #[source]
        source: std::io::Error,
    },
    /// A checkpoint or run that is not there.
    #[error("{0}")]
    Missing(String),
    /// A file that is not what it should be.
    #[error("{path}: {reason}")]
    Damaged {
        /// The file.
        path: String,
        /// What is wrong.
        reason: String,
    },
    /// Networks whose sizes do not fit each other or the environment.
    #[error("{0}")]
    Shape(String),
    /// A question the agent cannot answer (wrong sizes, a skill it does not have, NaN).
    #[error("{0}")]
    Input(String),
    /// The run's environment.
    #[error("environment {env}: {reason}")]
    Environment {
        /// Its name.
        env: String,
        /// What is wrong.
        reason: String,
    },
}

impl From<seads_weights::WeightsError> for InferError {
    /// A weights file that cannot be read, or is damaged, as the agent's error of that kind.
    fn from(e: seads_weights::WeightsError) -> Self {
        match e {
            seads_weights::WeightsError::Io { path, source } => InferError::Io {
                what: format!("reading {path}"),
                source,
            },
            seads_weights::WeightsError::Damaged { path, reason } => {
                InferError::Damaged { path, reason }
            }
        }
    }
}

/// The settings file a robot run keeps beside its config (`seads_uarm::RobotSettings::FILE`).
const ROBOT_SETTINGS: &str = "robot.toml";

/// The file of the forward model in a checkpoint.
pub const MODEL_FILE: &str = "forward_model.safetensors";

/// The file of a mixture skill model (`seads_skillmodel::MixtureModel`) in a checkpoint.
pub const MIXTURE_FILE: &str = "mixture_model.safetensors";

/// The skill model an agent plans with: the paper's forward model or the mixture.
#[derive(Debug, Clone)]
pub enum Model {
    /// The paper's per-bit forward model.
    Forward(ForwardModel),
    /// The mixture of forward models.
    Mixture(MixtureModel),
}

impl Model {
    fn inner(&mut self) -> &mut dyn Successor {
        match self {
            Self::Forward(m) => m,
            Self::Mixture(m) => m,
        }
    }

    fn inner_ref(&self) -> &dyn Successor {
        match self {
            Self::Forward(m) => m,
            Self::Mixture(m) => m,
        }
    }
}

impl Successor for Model {
    fn num_skills(&self) -> usize {
        self.inner_ref().num_skills()
    }

    fn symbolic_len(&self) -> usize {
        self.inner_ref().symbolic_len()
    }

    fn successors(&mut self, states: &[SymbolicState], out: &mut Vec<SymbolicState>) {
        self.inner().successors(states, out);
    }

    fn preferred_batch(&self) -> usize {
        self.inner_ref().preferred_batch()
    }

    fn log_likelihoods(
        &mut self,
        steps: &[(SymbolicState, usize, SymbolicState)],
    ) -> Option<Vec<f32>> {
        self.inner().log_likelihoods(steps)
    }
}
/// The file of the actor in a checkpoint.
pub const ACTOR_FILE: &str = "sac_actor.safetensors";

/// A SEADS agent of one checkpoint: its policy and its forward model.
#[derive(Debug, Clone)]
pub struct Agent {
    /// The skill policy.
    pub policy: Policy,
    /// The forward model.
    pub model: Model,
    /// The environment it was trained on.
    pub env: String,
    /// That environment's options as the run set them (`[env_config]`: board size, spacing,
    /// the manipulator's options, …).
    pub env_config: EnvConfig,
    /// That environment's dimensions, as the agent was loaded for.
    pub spec: EnvSpec,
    /// The checkpoint's epoch.
    pub epoch: u64,
}

/// What a checkpoint's `config.toml` says of its environment and learner.
#[derive(serde::Deserialize)]
struct SavedConfig {
    env: String,
    #[serde(default)]
    algorithm: Option<String>,
    #[serde(default)]
    env_config: EnvConfig,
}

impl Agent {
    /// The agent of the run in `run` at the checkpoint of `epoch`, or the latest; its
    /// environment from the registry with the run's own options (`[env_config]`: a 7×7 run's
    /// agent plays 7×7 boards), so the Cursor, Reacher and Jaco environments; a robot run needs
    /// [`Agent::load_for`] with its environment's spec.
    pub fn load(run: &Path, epoch: Option<u64>) -> Result<Self, InferError> {
        let dir = checkpoint_dir(run, epoch)?;
        let config = saved_config(&dir)?;
        let env =
            make_env(&config.env, &config.env_config).map_err(|e| InferError::Environment {
                env: config.env.clone(),
                // A robot run (its settings file beside its config) acts on the arm or its
                // twin, which the registry does not build (`seads uarm evaluate` does).
                reason: if run.join(ROBOT_SETTINGS).is_file() {
                    "a robot run: its skills act on the uArm or its twin, which `seads uarm \
                     evaluate` builds; Python has no robot environment"
                        .to_owned()
                } else {
                    e.to_string()
                },
            })?;
        Self::load_for(run, epoch, env.spec())
    }

    /// The agent of the run in `run` at the checkpoint of `epoch`, or the latest, for an
    /// environment of `spec` (its observation size and action box).
    pub fn load_for(run: &Path, epoch: Option<u64>, spec: &EnvSpec) -> Result<Self, InferError> {
        let dir = checkpoint_dir(run, epoch)?;
        let config = saved_config(&dir)?;
        if config.algorithm.as_deref().is_some_and(|a| a != "seads") {
            return Err(InferError::Environment {
                env: config.env,
                reason: format!(
                    "a {} run has no forward model to plan with",
                    config.algorithm.unwrap_or_default()
                ),
            });
        }
        if config.env != spec.name {
            return Err(InferError::Environment {
                env: config.env,
                reason: format!("the spec given is of {}", spec.name),
            });
        }
        // The mixture's file where the run learned one (`skill_model.kind = "mixture"`), else
        // the paper's forward model's.
        let model = if dir.join(MIXTURE_FILE).is_file() {
            Model::Mixture(MixtureModel::new(
                Tensors::read(&dir.join(MIXTURE_FILE))?.mlp("mixture_model")?,
                spec.symbolic_len,
            )?)
        } else {
            Model::Forward(ForwardModel::new(
                Tensors::read(&dir.join(MODEL_FILE))?.mlp("forward_model")?,
            )?)
        };
        let actor = Tensors::read(&dir.join(ACTOR_FILE))?;
        let policy = Policy::new(
            actor.mlp("actor")?,
            actor.dense("actor_log_std")?,
            spec.obs_dim,
            &spec.action_low,
            &spec.action_high,
        )?;
        use seads_embodiment::SkillPolicy as _;
        use seads_games::Successor as _;
        if model.symbolic_len() != spec.symbolic_len || model.num_skills() != policy.num_skills() {
            return Err(InferError::Shape(format!(
                "{}: a forward model of {} skills on {} fields and a policy of {} skills, for an \
                 environment of {} fields",
                dir.display(),
                model.num_skills(),
                model.symbolic_len(),
                policy.num_skills(),
                spec.symbolic_len
            )));
        }
        let epoch = dir
            .file_name()
            .and_then(|n| n.to_str())
            .and_then(|n| n.strip_prefix("epoch-"))
            .and_then(|n| n.parse().ok())
            .unwrap_or(0);
        Ok(Self {
            policy,
            model,
            env: config.env,
            env_config: config.env_config,
            spec: spec.clone(),
            epoch,
        })
    }
}

/// The config a checkpoint was saved with.
fn saved_config(dir: &Path) -> Result<SavedConfig, InferError> {
    let path = dir.join("config.toml");
    // A FIFO or a device would block the read or never end it.
    if path.exists() && !path.is_file() {
        return Err(InferError::Damaged {
            path: path.display().to_string(),
            reason: "not a regular file".into(),
        });
    }
    let text = std::fs::read_to_string(&path).map_err(|e| InferError::Io {
        what: format!("reading {}", path.display()),
        source: e,
    })?;
    // Only the fields this crate needs; the trainer validates the rest.
    let table: toml::Table = toml::from_str(&text).map_err(|e| InferError::Damaged {
        path: path.display().to_string(),
        reason: e.message().to_owned(),
    })?;
    let pick = |key: &str| table.get(key).cloned();
    let mut wanted = toml::Table::new();
    for key in ["env", "algorithm", "env_config"] {
        if let Some(value) = pick(key) {
            wanted.insert(key.to_owned(), value);
        }
    }
    wanted
        .try_into()
        .map_err(|e: toml::de::Error| InferError::Damaged {
            path: path.display().to_string(),
            reason: e.message().to_owned(),
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A robot run's agent is named as such (issue 82: "unknown environment
    /// uarm-lightsout-absolute"); a run of an environment that is not there keeps the
    /// registry's word.
    #[test]
    fn a_robot_run_is_named_as_such() {
        let dir = tempfile::tempdir().unwrap();
        let checkpoint = dir.path().join("checkpoints/epoch-000001");
        std::fs::create_dir_all(&checkpoint).unwrap();
        std::fs::write(
            checkpoint.join("config.toml"),
            "env = \"uarm-lightsout-absolute\"\n",
        )
        .unwrap();
        let unknown = Agent::load(dir.path(), None).unwrap_err().to_string();
        assert!(unknown.contains("unknown environment"), "{unknown}");
        std::fs::write(dir.path().join("robot.toml"), "").unwrap();
        let robot = Agent::load(dir.path(), None).unwrap_err().to_string();
        assert!(robot.contains("a robot run"), "{robot}");
    }
}
