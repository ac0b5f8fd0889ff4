//! The learners' sections of a run's configuration ([`Section`]): SEADS's `[seads]` and the
//! baselines' `[sac_baseline]` and `[hac]`, each with the paper's defaults and its own checks,
//! and [`LearnerConfig`], the one section a run's configuration holds.

use std::fmt::Debug;

use crate::{RelabelKind, RewardConfig, SkillModelConfig};
use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};

use crate::RunError;

/// A learner's section of a run's configuration: its own settings, with their defaults (the
/// paper's where the paper sets them) and their checks. A run's configuration holds its
/// learner's name (`algorithm = "<ALGORITHM>"`) and that learner's section only (`[<NAME>]`),
/// which [`LearnerConfig`] keeps as the file states it and gives typed with
/// [`LearnerConfig::section`]. SEADS's section and the baselines' are here, since the data side
/// reads them (populations, memory estimates); another learner's lives beside the learner.
pub trait Section:
    Serialize + DeserializeOwned + Default + Clone + Debug + PartialEq + Send + Sync + 'static
{
    /// The learner's name: in configs (`algorithm`), on the command line and in manifests.
    const ALGORITHM: &'static str;
    /// The section's name in a configuration file.
    const NAME: &'static str;
    /// Checks every value.
    fn validate(&self) -> Result<(), RunError>;
}

impl Section for SeadsConfig {
    const ALGORITHM: &'static str = "seads";
    const NAME: &'static str = "seads";
    fn validate(&self) -> Result<(), RunError> {
        SeadsConfig::validate(self)
    }
}

impl Section for BaselineConfig {
    const ALGORITHM: &'static str = "sac";
    const NAME: &'static str = "sac_baseline";
    fn validate(&self) -> Result<(), RunError> {
        BaselineConfig::validate(self, Self::NAME)
    }
}

impl Section for HacConfig {
    const ALGORITHM: &'static str = "hac";
    const NAME: &'static str = "hac";
    fn validate(&self) -> Result<(), RunError> {
        HacConfig::validate(self)
    }
}

/// The learner of a run and its section, as the file states them: `algorithm` (SEADS where a
/// file names none) and at most one table besides the run's own (`[env_config]`, `[sac]`), which
/// is that learner's section (a section left out takes the learner's defaults). Any other key is
/// an unknown field. Flattened into [`TrainConfig`](crate::TrainConfig); which section belongs
/// to which learner is checked against the presets when a configuration is read
/// ([`TrainConfig::from_table`](crate::TrainConfig::from_table)), and a section's values when
/// it is read typed, or by the learners' registry (`seads_rl::learners`) as a run starts.
#[derive(Debug, Clone, PartialEq)]
pub struct LearnerConfig {
    algorithm: String,
    section: Option<(String, toml::Table)>,
}

impl Default for LearnerConfig {
    fn default() -> Self {
        Self::of(&SeadsConfig::default()).expect("SEADS's defaults are written in TOML")
    }
}

impl LearnerConfig {
    /// The learner of `section`, with these settings: an error where a value cannot be
    /// written in TOML (an integer beyond 2⁶³ − 1).
    pub fn of<S: Section>(section: &S) -> Result<Self, RunError> {
        let table = toml::Table::try_from(section).map_err(|e| {
            RunError::Config(format!("[{}] cannot be written in TOML: {e}", S::NAME))
        })?;
        Ok(Self {
            algorithm: S::ALGORITHM.into(),
            section: Some((S::NAME.into(), table)),
        })
    }

    /// Learner `algorithm` with its section as stated (`None`: left out).
    pub fn stated(algorithm: &str, section: Option<(String, toml::Table)>) -> Self {
        Self {
            algorithm: algorithm.into(),
            section,
        }
    }

    /// The learner's name (`algorithm`).
    pub fn algorithm(&self) -> &str {
        &self.algorithm
    }

    /// The section's name and values as stated, if the file states them.
    pub fn stated_section(&self) -> Option<(&str, &toml::Table)> {
        self.section
            .as_ref()
            .map(|(name, table)| (name.as_str(), table))
    }

    /// The number of skills the learner's section states (`num_skills`, a key every skill
    /// learner's section names alike); `None` where it states none (the environment's then).
    pub fn stated_num_skills(&self) -> Option<usize> {
        self.stated_section()?
            .1
            .get("num_skills")?
            .as_integer()
            .and_then(|k| usize::try_from(k).ok())
    }

    /// Whether the learner is the one of section `S`.
    pub fn is<S: Section>(&self) -> bool {
        self.algorithm == S::ALGORITHM
    }

    /// The learner's section, typed and checked: an error if the learner is another, or if the
    /// section has unknown fields or bad values.
    pub fn section<S: Section>(&self) -> Result<S, RunError> {
        let section: S = self.read()?;
        section.validate()?;
        Ok(section)
    }

    /// The learner's section, typed but not checked.
    fn read<S: Section>(&self) -> Result<S, RunError> {
        if !self.is::<S>() {
            return Err(RunError::Config(format!(
                "a {} run has no [{}] section: it is no {} run",
                self.algorithm,
                S::NAME,
                S::ALGORITHM
            )));
        }
        let section: S = match &self.section {
            None => S::default(),
            Some((name, _)) if name != S::NAME => {
                return Err(RunError::Config(format!(
                    "[{name}] is no section of algorithm {:?}, which reads [{}]",
                    self.algorithm,
                    S::NAME
                )));
            }
            Some((_, table)) => {
                toml::Value::Table(table.clone())
                    .try_into()
                    .map_err(|e: toml::de::Error| {
                        RunError::Config(format!(
                            "[{}]: {}",
                            S::NAME,
                            e.message().trim().replace('\n', " ")
                        ))
                    })?
            }
        };
        Ok(section)
    }

    /// Checks the section of SEADS or of a baseline, whose types this crate holds, and writes it
    /// out in full (every field, its defaults included, as the type writes it); another
    /// learner's section stays as stated, and is checked and completed by its entry in the
    /// learners' registry (`seads_rl::learners::complete`) as a run starts.
    pub fn complete_known(&mut self) -> Result<(), RunError> {
        if self.is::<SeadsConfig>() {
            self.complete::<SeadsConfig>()
        } else if self.is::<BaselineConfig>() {
            self.complete::<BaselineConfig>()
        } else if self.is::<HacConfig>() {
            self.complete::<HacConfig>()
        } else {
            Ok(())
        }
    }

    /// Checks the section of learner `S` and writes it out in full: every field, its defaults
    /// included, as `S` writes it (an error if the learner is another).
    pub fn complete<S: Section>(&mut self) -> Result<(), RunError> {
        *self = Self::of(&self.section::<S>()?)?;
        Ok(())
    }

    /// Changes the learner's section with `edit`: an error if the learner is another, if the
    /// section has unknown fields, or if a value cannot be written in TOML. The values are
    /// checked when the configuration is ([`TrainConfig::validate`](crate::TrainConfig::validate)),
    /// so that several edits may pass through a state that is not valid.
    pub fn edit<S: Section>(&mut self, edit: impl FnOnce(&mut S)) -> Result<(), RunError> {
        let mut section = self.read::<S>()?;
        edit(&mut section);
        *self = Self::of(&section)?;
        Ok(())
    }
}

impl Serialize for LearnerConfig {
    fn serialize<Ser: serde::Serializer>(&self, serializer: Ser) -> Result<Ser::Ok, Ser::Error> {
        use serde::ser::SerializeMap;
        let mut map = serializer.serialize_map(None)?;
        map.serialize_entry("algorithm", &self.algorithm)?;
        if let Some((name, table)) = &self.section {
            map.serialize_entry(name, table)?;
        }
        map.end()
    }
}

impl<'de> Deserialize<'de> for LearnerConfig {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        use serde::de::Error;
        let mut algorithm = None;
        let mut section: Option<(String, toml::Table)> = None;
        let keys: std::collections::BTreeMap<String, toml::Value> =
            Deserialize::deserialize(deserializer)?;
        for (key, value) in keys {
            match (key.as_str(), value) {
                ("algorithm", toml::Value::String(name)) => algorithm = Some(name),
                ("algorithm", other) => {
                    return Err(D::Error::custom(format!(
                        "algorithm must be a name, got {other}"
                    )));
                }
                (_, toml::Value::Table(table)) => {
                    if let Some((first, _)) = &section {
                        return Err(D::Error::custom(format!(
                            "two learners' sections, [{first}] and [{key}]: a run has one"
                        )));
                    }
                    section = Some((key, table));
                }
                _ => return Err(D::Error::custom(format!("unknown field `{key}`"))),
            }
        }
        Ok(Self {
            algorithm: algorithm.unwrap_or_else(|| SeadsConfig::ALGORITHM.into()),
            section,
        })
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
