//! The training configuration: one TOML file per run, with a preset per environment.

use seads_embodiment::{EnvConfig, env_names};
use seads_skillmodel::{RelabelKind, RewardConfig, SkillModelConfig};
use serde::{Deserialize, Serialize};

use crate::{RlError, SacConfig};

/// Relabelling switches (SPEC §3.6; the ablations set the probabilities to 0).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct RelabelConfig {
    /// Assignment (SEADS) or independent maximum.
    pub kind: RelabelKind,
    /// Probability that an episode of the forward-model batch may be relabelled.
    pub skill_model_p: f64,
    /// Probability that a board-changing episode of the SAC batch may be relabelled.
    pub sac_p: f64,
}

impl Default for RelabelConfig {
    fn default() -> Self {
        Self {
            kind: RelabelKind::Assignment,
            skill_model_p: 1.0,
            sac_p: 0.5,
        }
    }
}

/// Everything a SEADS training run needs. `Default` is the LightsOutCursor preset of the paper.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct TrainConfig {
    /// Environment name (see `seads envs`).
    pub env: String,
    /// Environment options; the reset split is always "train" for training.
    pub env_config: EnvConfig,
    /// Seed of every random choice of the run.
    pub seed: u64,
    /// Budget in environment steps (transitions of training episodes).
    pub env_steps: u64,
    /// Number of skills K (default: the number of game moves; the "more skills" ablation sets 30 / 15).
    pub num_skills: Option<usize>,
    /// New episodes per epoch.
    pub episodes_per_epoch: usize,
    /// Long-term episode buffer capacity.
    pub buffer_capacity: usize,
    /// Short-term list of the most recent episodes.
    pub recent_episodes: usize,
    /// Episodes drawn from the long-term buffer per update.
    pub sampled_episodes: usize,
    /// Soft actor-critic.
    pub sac: SacConfig,
    /// Forward model (or VIC discriminator).
    pub skill_model: SkillModelConfig,
    /// Intrinsic reward.
    pub reward: RewardConfig,
    /// Relabelling.
    pub relabel: RelabelConfig,
    /// Evaluate skill coverage every this many epochs (and at the first and last epoch).
    pub eval_every: u64,
    /// Number of evaluation seeds (444555, 444556, …) for skill coverage.
    pub eval_seeds: u64,
    /// Write a checkpoint every this many epochs (and at the end).
    pub checkpoint_every: u64,
    /// libtorch intra-op threads per training thread (0: libtorch's default; the presets use 1,
    /// since SAC updates and skill-model scoring already run on two threads).
    pub threads: usize,
    /// libtorch threads of the SAC thread once the other training thread has finished preparing
    /// the next epoch's updates and waits (0: keep `threads`). The presets use 2, for a run that
    /// has two cores to itself; set 0 when several runs share the cores, since libtorch's threads
    /// busy-wait and slow down badly when the cores are oversubscribed.
    pub sac_threads_alone: usize,
    /// Run libtorch with kernels that give the same numbers on every x86-64 machine (MKL's
    /// `COMPATIBLE` branch), so that the seed alone fixes the run. About 1.8× slower per SAC
    /// update; off in the presets, on for the demo and the tests (see `seads_rl::numerics`).
    pub portable_numerics: bool,
}

impl Default for TrainConfig {
    fn default() -> Self {
        Self {
            env: "lightsout-cursor".into(),
            env_config: EnvConfig::default(),
            seed: 1,
            env_steps: 500_000,
            num_skills: None,
            episodes_per_epoch: 32,
            buffer_capacity: 2048,
            recent_episodes: 256,
            sampled_episodes: 256,
            sac: SacConfig::default(),
            skill_model: SkillModelConfig::default(),
            reward: RewardConfig::default(),
            relabel: RelabelConfig::default(),
            eval_every: 100,
            eval_seeds: 20,
            checkpoint_every: 100,
            threads: 1,
            sac_threads_alone: 2,
            portable_numerics: false,
        }
    }
}

/// The shipped presets: the paper's settings per environment (`configs/*.toml`).
const PRESETS: &[(&str, &str)] = &[
    (
        "lightsout-cursor",
        include_str!("../configs/lightsout-cursor.toml"),
    ),
    (
        "tileswap-cursor",
        include_str!("../configs/tileswap-cursor.toml"),
    ),
    (
        "lightsout-reacher",
        include_str!("../configs/lightsout-reacher.toml"),
    ),
    (
        "tileswap-reacher",
        include_str!("../configs/tileswap-reacher.toml"),
    ),
    (
        "lightsout-jaco",
        include_str!("../configs/lightsout-jaco.toml"),
    ),
    (
        "tileswap-jaco",
        include_str!("../configs/tileswap-jaco.toml"),
    ),
    (
        "lightsout3d-jaco",
        include_str!("../configs/lightsout3d-jaco.toml"),
    ),
];

impl TrainConfig {
    /// The preset of environment `env` (the paper's settings).
    pub fn preset(env: &str) -> Result<Self, RlError> {
        let text = PRESETS
            .iter()
            .find(|(name, _)| *name == env)
            .map(|(_, text)| *text)
            .ok_or_else(|| {
                RlError::Config(format!(
                    "unknown environment {env:?}; valid environments: {}",
                    env_names().join(", ")
                ))
            })?;
        Self::from_toml(text)
    }

    /// Every preset, as `(environment, TOML text)`.
    pub fn presets() -> &'static [(&'static str, &'static str)] {
        PRESETS
    }

    /// Parses a TOML configuration and validates its values (not the environment: see
    /// [`TrainConfig::validate`]).
    pub fn from_toml(text: &str) -> Result<Self, RlError> {
        let config: Self =
            toml::from_str(text).map_err(|e| RlError::Config(one_line_toml_error(text, &e)))?;
        config.validate_values()?;
        Ok(config)
    }

    /// The configuration as TOML.
    pub fn to_toml(&self) -> String {
        toml::to_string(self).expect("a config serialises")
    }

    /// Checks every value, and that the environment exists with these options.
    pub fn validate(&self) -> Result<(), RlError> {
        if !env_names().contains(&self.env.as_str()) {
            return Err(RlError::Config(format!(
                "unknown environment {:?}; valid environments: {}",
                self.env,
                env_names().join(", ")
            )));
        }
        seads_embodiment::make_env(&self.env, &self.env_config)?;
        self.validate_values()
    }

    /// Checks every value except the environment (robot environments are not in the registry;
    /// the trainer that gets one checks it).
    pub fn validate_values(&self) -> Result<(), RlError> {
        let bad = |m: String| Err(RlError::Config(m));
        self.sac.validate()?;
        self.skill_model.validate()?;
        if self.num_skills == Some(0) {
            return bad("num_skills must be at least 1".into());
        }
        for (name, value) in [
            ("episodes_per_epoch", self.episodes_per_epoch),
            ("buffer_capacity", self.buffer_capacity),
            ("recent_episodes", self.recent_episodes),
            ("sampled_episodes", self.sampled_episodes),
        ] {
            if value == 0 {
                return bad(format!("{name} must be at least 1"));
            }
        }
        if self.sampled_episodes > self.buffer_capacity
            || self.recent_episodes > self.buffer_capacity
        {
            return bad(
                "sampled_episodes and recent_episodes must not exceed buffer_capacity".into(),
            );
        }
        if self.eval_every == 0 || self.checkpoint_every == 0 || self.eval_seeds == 0 {
            return bad("eval_every, eval_seeds and checkpoint_every must be at least 1".into());
        }
        for (name, p) in [
            ("relabel.skill_model_p", self.relabel.skill_model_p),
            ("relabel.sac_p", self.relabel.sac_p),
        ] {
            if !(0.0..=1.0).contains(&p) {
                return bad(format!("{name} must lie in [0, 1], got {p}"));
            }
        }
        Ok(())
    }
}

/// A TOML error as one line: "line L, column C: message".
fn one_line_toml_error(text: &str, e: &toml::de::Error) -> String {
    let message = e.message().trim().replace('\n', " ");
    match e.span() {
        Some(span) => {
            let before = &text[..span.start.min(text.len())];
            let line = before.matches('\n').count() + 1;
            let column = before.len() - before.rfind('\n').map_or(0, |i| i + 1) + 1;
            format!("line {line}, column {column}: {message}")
        }
        None => message,
    }
}
