//! The algorithms and their sections of a run's configuration: `[seads]`, `[sac_baseline]` and
//! `[hac]`, each with the paper's defaults and its own checks. A run's configuration holds its
//! algorithm's section only: [`LearnerConfig`] is one of them, tagged by `algorithm`.

use crate::{RelabelKind, RewardConfig, SkillModelConfig};
use serde::{Deserialize, Serialize};

use crate::RunError;

/// What a run trains.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Algorithm {
    /// SEADS: reward-free skills and their forward model (SPEC §3).
    #[default]
    Seads,
    /// The flat SAC baseline with the task reward (SPEC §5.1).
    Sac,
    /// The two-level HAC baseline with the task reward (SPEC §5.2).
    Hac,
}

impl Algorithm {
    /// The name in configs and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Algorithm::Seads => "seads",
            Algorithm::Sac => "sac",
            Algorithm::Hac => "hac",
        }
    }

    /// Whether it is a task-reward baseline (SAC or HAC).
    pub fn is_baseline(self) -> bool {
        self != Algorithm::Seads
    }

    /// The name of its section in a configuration file.
    pub fn section(self) -> &'static str {
        match self {
            Algorithm::Seads => "seads",
            Algorithm::Sac => "sac_baseline",
            Algorithm::Hac => "hac",
        }
    }

    /// Every algorithm.
    pub const ALL: [Algorithm; 3] = [Algorithm::Seads, Algorithm::Sac, Algorithm::Hac];

    /// The algorithm of this name ([`Algorithm::name`]), if there is one.
    ///
    /// ```
    /// use seads_run::Algorithm;
    /// assert_eq!(Algorithm::named("hac"), Some(Algorithm::Hac));
    /// assert_eq!(Algorithm::named("diayn"), None);
    /// ```
    pub fn named(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|a| a.name() == name)
    }

    /// The names of every algorithm, for help texts and errors.
    pub fn names() -> Vec<&'static str> {
        Self::ALL.into_iter().map(Self::name).collect()
    }
}

/// The learner of a run and its section: `algorithm = "seads"` reads `[seads]`, `"sac"`
/// `[sac_baseline]`, `"hac"` `[hac]`; a section left out takes its defaults (the paper's), and any
/// other section is an unknown field. Flattened into [`TrainConfig`](crate::TrainConfig).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "algorithm", rename_all = "lowercase", deny_unknown_fields)]
pub enum LearnerConfig {
    /// SEADS.
    Seads {
        /// Its section.
        #[serde(default)]
        seads: SeadsConfig,
    },
    /// The flat SAC baseline.
    Sac {
        /// Its section.
        #[serde(default)]
        sac_baseline: BaselineConfig,
    },
    /// The two-level HAC baseline.
    Hac {
        /// Its section.
        #[serde(default)]
        hac: HacConfig,
    },
}

impl Default for LearnerConfig {
    fn default() -> Self {
        Self::of(Algorithm::Seads)
    }
}

impl LearnerConfig {
    /// `algorithm` with its section's defaults.
    pub fn of(algorithm: Algorithm) -> Self {
        match algorithm {
            Algorithm::Seads => Self::Seads {
                seads: SeadsConfig::default(),
            },
            Algorithm::Sac => Self::Sac {
                sac_baseline: BaselineConfig::default(),
            },
            Algorithm::Hac => Self::Hac {
                hac: HacConfig::default(),
            },
        }
    }

    /// Which algorithm it is.
    pub fn algorithm(&self) -> Algorithm {
        match self {
            Self::Seads { .. } => Algorithm::Seads,
            Self::Sac { .. } => Algorithm::Sac,
            Self::Hac { .. } => Algorithm::Hac,
        }
    }

    /// Checks every value of the section.
    pub fn validate(&self) -> Result<(), RunError> {
        match self {
            Self::Seads { seads } => seads.validate(),
            Self::Sac { sac_baseline } => sac_baseline.validate("sac_baseline"),
            Self::Hac { hac } => hac.validate(),
        }
    }

    /// SEADS's section, if the learner is SEADS.
    pub fn seads(&self) -> Option<&SeadsConfig> {
        match self {
            Self::Seads { seads } => Some(seads),
            _ => None,
        }
    }

    /// SEADS's section to change, if the learner is SEADS.
    pub fn seads_mut(&mut self) -> Option<&mut SeadsConfig> {
        match self {
            Self::Seads { seads } => Some(seads),
            _ => None,
        }
    }

    /// The SAC baseline's section, if the learner is the SAC baseline.
    pub fn sac_baseline(&self) -> Option<&BaselineConfig> {
        match self {
            Self::Sac { sac_baseline } => Some(sac_baseline),
            _ => None,
        }
    }

    /// The SAC baseline's section to change, if the learner is the SAC baseline.
    pub fn sac_baseline_mut(&mut self) -> Option<&mut BaselineConfig> {
        match self {
            Self::Sac { sac_baseline } => Some(sac_baseline),
            _ => None,
        }
    }

    /// HAC's section, if the learner is HAC.
    pub fn hac(&self) -> Option<&HacConfig> {
        match self {
            Self::Hac { hac } => Some(hac),
            _ => None,
        }
    }

    /// HAC's section to change, if the learner is HAC.
    pub fn hac_mut(&mut self) -> Option<&mut HacConfig> {
        match self {
            Self::Hac { hac } => Some(hac),
            _ => None,
        }
    }

    /// How a task-reward baseline collects and learns: `[sac_baseline]`, or HAC's share of
    /// `[hac]`; `None` for SEADS.
    pub fn baseline_training(&self) -> Option<BaselineConfig> {
        match self {
            Self::Seads { .. } => None,
            Self::Sac { sac_baseline } => Some(sac_baseline.clone()),
            Self::Hac { hac } => Some(hac.training()),
        }
    }
}

/// First seed of the skill-coverage evaluation (the paper's 444555 … 444574): SEADS's
/// [`SeadsConfig::eval_seeds`] count from it.
pub const COVERAGE_SEED: u64 = 444_555;

/// SEADS's own settings (`[seads]`, SPEC §3): skills, episode buffers, SAC's gradient steps, the
/// skill model, the intrinsic reward and relabelling. Its SAC's networks are the `[sac]` section.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SeadsConfig {
    /// Number of skills K (default: the number of game moves; the "more skills" ablation sets
    /// 30 / 15).
    pub num_skills: Option<usize>,
    /// New episodes per epoch.
    pub episodes_per_epoch: usize,
    /// Long-term episode buffer capacity.
    pub buffer_capacity: usize,
    /// Short-term list of the most recent episodes.
    pub recent_episodes: usize,
    /// Episodes drawn from the long-term buffer per update.
    pub sampled_episodes: usize,
    /// Number of evaluation seeds (444555, 444556, …) for skill coverage.
    pub eval_seeds: u64,
    /// SAC's gradient steps per epoch (the skill model's are `skill_model.updates_per_epoch`).
    pub updates_per_epoch: usize,
    /// Forward model (or VIC discriminator).
    pub skill_model: SkillModelConfig,
    /// Intrinsic reward.
    pub reward: RewardConfig,
    /// Relabelling.
    pub relabel: RelabelConfig,
}

impl Default for SeadsConfig {
    fn default() -> Self {
        Self {
            num_skills: None,
            episodes_per_epoch: 32,
            buffer_capacity: 2048,
            recent_episodes: 256,
            sampled_episodes: 256,
            eval_seeds: 20,
            updates_per_epoch: 16,
            skill_model: SkillModelConfig::default(),
            reward: RewardConfig::default(),
            relabel: RelabelConfig::default(),
        }
    }
}

impl SeadsConfig {
    /// Checks every value.
    pub fn validate(&self) -> Result<(), RunError> {
        let bad = |m: String| Err(RunError::Config(m));
        self.skill_model.validate()?;
        if self.num_skills == Some(0) {
            return bad("seads.num_skills must be at least 1".into());
        }
        if self.eval_seeds == 0 {
            return bad("seads.eval_seeds must be at least 1".into());
        }
        for (name, value) in [
            ("eval_seeds", self.eval_seeds),
            ("updates_per_epoch", self.updates_per_epoch as u64),
        ] {
            if value > MAX_PER_EPOCH {
                return bad(format!(
                    "seads.{name} must be at most {MAX_PER_EPOCH}, got {value}"
                ));
            }
        }
        for (name, value) in [
            ("episodes_per_epoch", self.episodes_per_epoch),
            ("buffer_capacity", self.buffer_capacity),
            ("recent_episodes", self.recent_episodes),
            ("sampled_episodes", self.sampled_episodes),
        ] {
            if value == 0 {
                return bad(format!("seads.{name} must be at least 1"));
            }
        }
        if self.sampled_episodes > self.buffer_capacity
            || self.recent_episodes > self.buffer_capacity
        {
            return bad(
                "seads.sampled_episodes and seads.recent_episodes must not exceed \
                 seads.buffer_capacity"
                    .into(),
            );
        }
        for (name, p) in [
            ("seads.relabel.skill_model_p", self.relabel.skill_model_p),
            ("seads.relabel.sac_p", self.relabel.sac_p),
        ] {
            check_probability(name, p)?;
        }
        Ok(())
    }
}

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

/// How a task-reward baseline collects and learns (SPEC §5.1): the flat SAC baseline's section
/// `[sac_baseline]`, and the part of `[hac]` that HAC shares with it ([`HacConfig::training`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct BaselineConfig {
    /// Transitions kept in the replay buffer (the most recent).
    pub replay_capacity: usize,
    /// Environments stepped once per epoch: the new transitions of an epoch.
    pub samples_per_epoch: usize,
    /// Gradient steps per epoch N; N < 1 means one step every 1/N epochs.
    pub updates_per_epoch: f64,
    /// Test boards per depth 1–5 of each task-success evaluation.
    pub eval_boards: usize,
}

impl Default for BaselineConfig {
    fn default() -> Self {
        Self {
            replay_capacity: 1_000_000,
            samples_per_epoch: 8,
            updates_per_epoch: 1.0,
            eval_boards: 20,
        }
    }
}

impl BaselineConfig {
    /// Checks every value; `section` names the section in messages.
    pub fn validate(&self, section: &str) -> Result<(), RunError> {
        let bad = |m: String| Err(RunError::Config(m));
        if self.replay_capacity == 0 || self.samples_per_epoch == 0 || self.eval_boards == 0 {
            return bad(format!(
                "{section}.replay_capacity, {section}.samples_per_epoch and \
                 {section}.eval_boards must be at least 1"
            ));
        }
        for (name, value) in [
            ("samples_per_epoch", self.samples_per_epoch),
            ("eval_boards", self.eval_boards),
        ] {
            if value as u64 > MAX_PER_EPOCH {
                return bad(format!(
                    "{section}.{name} must be at most {MAX_PER_EPOCH}, got {value}"
                ));
            }
        }
        let n = self.updates_per_epoch;
        if !(n.is_finite() && n > 0.0) {
            return bad(format!(
                "{section}.updates_per_epoch must be positive, got {n}"
            ));
        }
        if n > MAX_PER_EPOCH as f64 {
            return bad(format!(
                "{section}.updates_per_epoch must be at most {MAX_PER_EPOCH}, got {n}"
            ));
        }
        Ok(())
    }
}

/// The HAC baseline's section `[hac]` (SPEC §5.2): how it collects and learns, as the SAC
/// baseline does, and its high level. The low level is the `[sac]` section (its α is α_low);
/// the high level has the same networks and optimiser with its own α. Choices where the seed is
/// silent follow Levy's HAC (`src/hac.rs`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct HacConfig {
    /// Low-level transitions kept in the replay buffer (the most recent).
    pub replay_capacity: usize,
    /// Environments stepped once per epoch.
    pub samples_per_epoch: usize,
    /// Gradient steps of each level per epoch N; N < 1 means one step every 1/N epochs.
    pub updates_per_epoch: f64,
    /// Test boards per depth 1–5 of each task-success evaluation.
    pub eval_boards: usize,
    /// Temperature τ_RB of the high level's RelaxedBernoulli policy.
    pub temperature: f64,
    /// Fixed entropy temperature α_high of the high level.
    pub alpha_high: f64,
    /// Low-level steps a subgoal may take, H (the presets: the environment's steps per skill).
    pub subgoal_horizon: usize,
    /// Share of subgoals tested: pursued without exploration noise, and penalised when missed.
    pub subgoal_test_p: f64,
}

impl Default for HacConfig {
    fn default() -> Self {
        let training = BaselineConfig::default();
        Self {
            replay_capacity: training.replay_capacity,
            samples_per_epoch: training.samples_per_epoch,
            updates_per_epoch: training.updates_per_epoch,
            eval_boards: training.eval_boards,
            temperature: 0.1,
            alpha_high: 0.001,
            subgoal_horizon: 10,
            subgoal_test_p: 0.3,
        }
    }
}

impl HacConfig {
    /// How HAC collects and learns, in the SAC baseline's terms.
    pub fn training(&self) -> BaselineConfig {
        BaselineConfig {
            replay_capacity: self.replay_capacity,
            samples_per_epoch: self.samples_per_epoch,
            updates_per_epoch: self.updates_per_epoch,
            eval_boards: self.eval_boards,
        }
    }

    /// Checks every value.
    pub fn validate(&self) -> Result<(), RunError> {
        self.training().validate("hac")?;
        check_probability("hac.subgoal_test_p", self.subgoal_test_p)?;
        for (name, v) in [
            ("hac.temperature", self.temperature),
            ("hac.alpha_high", self.alpha_high),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(RunError::Config(format!(
                    "{name} must be positive, got {v}"
                )));
            }
        }
        if self.subgoal_horizon == 0 {
            return Err(RunError::Config(
                "hac.subgoal_horizon must be at least 1".into(),
            ));
        }
        Ok(())
    }
}

fn check_probability(name: &str, p: f64) -> Result<(), RunError> {
    if (0.0..=1.0).contains(&p) {
        Ok(())
    } else {
        Err(RunError::Config(format!(
            "{name} must lie in [0, 1], got {p}"
        )))
    }
}

/// The most evaluations, updates, samples or boards a configuration may ask for per epoch (or
/// per evaluation): a million, far beyond the paper's settings (tens to thousands), far below
/// what would never end.
pub const MAX_PER_EPOCH: u64 = 1_000_000;
