//! The training configuration: one TOML file per run, with a preset per environment and
//! algorithm.

use crate::ComputeDevice;
use seads_embodiment::{EnvConfig, env_names};
use serde::{Deserialize, Serialize};

use crate::sections::{BaselineConfig, HacConfig, LearnerConfig, SeadsConfig, Section};
use crate::{RunError, SacConfig, SkillModelKind};

/// Everything a training run needs: the run's own settings (environment, seed, budget,
/// evaluation and checkpoint cadence, threads, numerics, device), the soft actor-critic's
/// networks and optimiser that every algorithm trains (`[sac]`; HAC's low level), and its
/// learner: `algorithm` and that learner's section only ([`LearnerConfig`]: `[seads]`,
/// `[sac_baseline]`, `[hac]`, or another learner's). `Default` is the LightsOutCursor preset of
/// the paper.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct TrainConfig {
    /// Environment name (see `seads envs`).
    pub env: String,
    /// Environment options; the reset split is always "train" for training.
    pub env_config: EnvConfig,
    /// Seed of every random choice of the run.
    pub seed: u64,
    /// Budget in environment steps (transitions of training episodes).
    pub env_steps: u64,
    /// Evaluate every this many epochs (and at the first and last epoch): skill coverage for
    /// SEADS, task success for the baselines.
    pub eval_every: u64,
    /// Write a checkpoint every this many epochs (and at the end).
    pub checkpoint_every: u64,
    /// libtorch intra-op threads per training thread (0: libtorch's default; the presets use 1,
    /// since SAC updates and skill-model scoring already run on two threads).
    pub threads: usize,
    /// libtorch threads of the SAC thread once the other training thread has finished preparing
    /// the next epoch's updates and waits (0: keep `threads`). The presets use 2, for a run that
    /// has two cores to itself; set 0 when several runs share the cores, since libtorch's threads
    /// busy-wait and slow down badly when the cores are oversubscribed. The moment SAC widens
    /// depends on timing; at the presets' network sizes the bits do not, with portable numerics
    /// and 32- or 64-wide networks they do (set 0 there for a run that repeats exactly;
    /// `examples/thread_count_bits.rs`).
    pub sac_threads_alone: usize,
    /// Run libtorch with kernels that give the same numbers on every x86-64 machine (MKL's
    /// `COMPATIBLE` branch, and Adam's square root correctly rounded), so that the seed alone
    /// fixes the run. About 1.8× slower per SAC update; off in the presets, on for the demo and
    /// the tests (see `seads_nn::numerics`).
    pub portable_numerics: bool,
    /// Where the networks run: `cpu` (the default) or `cuda`, `cuda:N`. Only the CPU is
    /// bit-exact from the seed; a checkpoint from either loads on the other. Left out of the
    /// written config when `cpu`, and set per command by `--device` (resuming may change it).
    #[serde(skip_serializing_if = "ComputeDevice::is_cpu")]
    pub device: ComputeDevice,
    /// The soft actor-critic's networks and optimiser, for every algorithm.
    pub sac: SacConfig,
    /// What to train (`algorithm`, SEADS where a file names none) and its section.
    #[serde(flatten)]
    pub learner: LearnerConfig,
}

impl Default for TrainConfig {
    fn default() -> Self {
        Self {
            env: "lightsout-cursor".into(),
            env_config: EnvConfig::default(),
            seed: 1,
            env_steps: 500_000,
            eval_every: 100,
            checkpoint_every: 100,
            threads: 1,
            sac_threads_alone: 2,
            portable_numerics: false,
            device: ComputeDevice::Cpu,
            sac: SacConfig::default(),
            learner: LearnerConfig::default(),
        }
    }
}

// The shipped presets, `PRESETS`: every `(algorithm, layer, TOML text)`, found by path
// (build.rs): SEADS's `configs/<layer>.toml`, another learner's `configs/<algorithm>/<layer>.toml`,
// and a learner's settings on every environment, `configs/<algorithm>/every-env.toml` (the
// layer `*`); `TrainConfig::preset_for` lays them together (`preset_layers`).
include!(concat!(env!("OUT_DIR"), "/presets.rs"));

/// The layer of a learner's settings on every environment (`every-env.toml`).
const EVERY_ENV: &str = "*";

/// Every learner with presets, by name, and the name of its section (from its presets: the one
/// table besides the run's own). The learners a configuration may name.
static LEARNERS: std::sync::LazyLock<std::collections::BTreeMap<&'static str, String>> =
    std::sync::LazyLock::new(|| {
        let mut learners = std::collections::BTreeMap::new();
        for &(algorithm, _, text) in PRESETS {
            let table: toml::Table = text.parse().expect("a shipped preset parses");
            let section = table
                .iter()
                .find(|(key, value)| value.is_table() && !RUN_TABLES.contains(&key.as_str()))
                .map(|(key, _)| key.clone());
            if let Some(section) = section {
                learners.entry(algorithm).or_insert(section);
            }
        }
        learners
    });

/// The layers of `configs/` that make environment `env`'s presets, in the order they are laid
/// (each later one over the earlier): its manipulator's, its game's and its own, for an
/// environment named `<game>-<manipulator>` (the registry's names; the robot's environments have
/// their own layer only). A layer of a manipulator or a game may say `like = "<other>"`: that
/// one stands in for it, in every learner's layers (the three-link arm is set up like the
/// two-link one, the sliding puzzle like TileSwap), and what the layer holds besides goes over
/// it.
///
/// ```
/// assert_eq!(
///     seads_run::preset_layers("sliding-reacher3"),
///     ["reacher", "tileswap", "tileswap-reacher", "sliding-reacher3"]
/// );
/// ```
pub fn preset_layers(env: &str) -> Vec<String> {
    let Some((game, manipulator)) = env.rsplit_once('-') else {
        return vec![env.to_owned()];
    };
    let (game, manipulator) = (alias(game), alias(manipulator));
    let mut names = vec![
        manipulator.clone(),
        game.clone(),
        format!("{game}-{manipulator}"),
    ];
    if names[2] != env {
        names.push(env.to_owned());
    }
    names
}

/// What layer `name` stands for: the layer its SEADS layer is `like`, followed to the end.
fn alias(name: &str) -> String {
    let mut name = name.to_owned();
    for _ in 0..PRESETS.len() {
        match preset_file(SeadsConfig::ALGORITHM, &name)
            .and_then(|t| t.get(LIKE).and_then(toml::Value::as_str).map(str::to_owned))
        {
            Some(other) => name = other,
            None => break,
        }
    }
    name
}

/// Whether SEADS's layer `name` is the whole preset of an environment outside the registry
/// (the robot's): it names that environment as its `env`.
fn is_own_preset(name: &str) -> bool {
    preset_file(SeadsConfig::ALGORITHM, name)
        .is_some_and(|t| t.get("env").and_then(toml::Value::as_str) == Some(name))
}

/// The key of a layer that another stands in for.
const LIKE: &str = "like";

/// The layer `name` of learner `algorithm` as a table, if there is one.
fn preset_file(algorithm: &str, name: &str) -> Option<toml::Table> {
    PRESETS
        .iter()
        .find(|(a, n, _)| *a == algorithm && *n == name)
        .map(|(_, _, text)| text.parse().expect("a shipped preset parses"))
}

/// Lays the layers `names` of learner `algorithm` over `table`, and for a manipulator or game
/// that stands in for another, what its own layer holds besides; whether any layer was there.
fn lay(table: &mut toml::Table, algorithm: &str, names: &[String]) -> bool {
    let mut found = false;
    for name in names {
        if let Some(mut layer) = preset_file(algorithm, name) {
            layer.remove(LIKE);
            merge_toml(table, &layer);
            found = true;
        }
    }
    found
}

/// Whether the layers found for `env` make a whole configuration: the environment's own, or a
/// manipulator's (which hold the run's settings), so that a game's layer alone is none.
fn preset_is_complete(env: &str, names: &[String], table: &toml::Table) -> bool {
    let own = names.last().is_some_and(|n| n == env);
    let manipulator = names
        .first()
        .is_some_and(|m| preset_file(SeadsConfig::ALGORITHM, m).is_some());
    (own || manipulator) && table.contains_key("sac")
}

/// The tables of a configuration that are the run's own, not its learner's.
const RUN_TABLES: [&str; 2] = ["env_config", "sac"];

/// The names of the learners a configuration may name (those with presets), sorted.
///
/// ```
/// assert_eq!(seads_run::learner_names(), ["diayn", "hac", "sac", "seads"]);
/// ```
pub fn learner_names() -> Vec<&'static str> {
    LEARNERS.keys().copied().collect()
}

/// The name of learner `algorithm`'s section, if it is a learner with presets.
pub fn section_name(algorithm: &str) -> Option<&'static str> {
    LEARNERS.get(algorithm).map(String::as_str)
}

impl TrainConfig {
    /// Sets the libtorch threads for a run with `cores` cores to itself. SEADS: two training
    /// threads of `cores / 2` each, and all cores for SAC while the other thread waits (a run
    /// alone on one core keeps one thread throughout). A baseline: one training thread of all
    /// `cores`.
    ///
    /// ```
    /// use seads_run::{BaselineConfig, TrainConfig};
    /// let mut config = TrainConfig::default();
    /// config.use_cores(4);
    /// assert_eq!((config.threads, config.sac_threads_alone), (2, 4));
    /// config.use_cores(1);
    /// assert_eq!((config.threads, config.sac_threads_alone), (1, 0));
    /// let mut baseline = TrainConfig::default().with_section(&BaselineConfig::default())?;
    /// baseline.use_cores(4);
    /// assert_eq!((baseline.threads, baseline.sac_threads_alone), (4, 0));
    /// # Ok::<(), seads_run::RunError>(())
    /// ```
    pub fn use_cores(&mut self, cores: usize) {
        let cores = cores.max(1);
        if !self.is::<SeadsConfig>() {
            self.threads = cores;
            self.sac_threads_alone = 0;
            return;
        }
        self.threads = (cores / 2).max(1);
        self.sac_threads_alone = if cores >= 2 { cores } else { 0 };
    }

    /// The learner the run trains (`algorithm`).
    pub fn algorithm(&self) -> &str {
        self.learner.algorithm()
    }

    /// Whether the run trains the learner of section `S`.
    pub fn is<S: Section>(&self) -> bool {
        self.learner.is::<S>()
    }

    /// The learner's section, typed and checked ([`LearnerConfig::section`]).
    pub fn section<S: Section>(&self) -> Result<S, RunError> {
        self.learner.section()
    }

    /// SEADS's section, for a run that must be SEADS: another learner's configuration is an
    /// error.
    pub fn seads(&self) -> Result<SeadsConfig, RunError> {
        self.section()
    }

    /// Changes the learner's section ([`LearnerConfig::edit`]).
    pub fn edit<S: Section>(&mut self, edit: impl FnOnce(&mut S)) -> Result<(), RunError> {
        self.learner.edit(edit)
    }

    /// These settings with the learner of `section` in place of the run's
    /// ([`LearnerConfig::of`]).
    pub fn with_section<S: Section>(self, section: &S) -> Result<Self, RunError> {
        Ok(Self {
            learner: LearnerConfig::of(section)?,
            ..self
        })
    }

    /// The preset of environment `env` (the paper's settings, SEADS).
    pub fn preset(env: &str) -> Result<Self, RunError> {
        Self::preset_for(env, SeadsConfig::ALGORITHM)
    }

    /// The preset of learner `algorithm` on environment `env`, laid together from the layers of
    /// `configs/` ([`preset_layers`]): SEADS's layers of the environment's manipulator, game and
    /// the environment itself, then (for another learner, in place of SEADS's section) that
    /// learner's settings on every environment and its layers of the same three names.
    pub fn preset_for(env: &str, algorithm: &str) -> Result<Self, RunError> {
        if section_name(algorithm).is_none() {
            return Err(unknown_learner(algorithm));
        }
        let no_preset = || {
            RunError::Config(format!(
                "unknown environment {env:?}; valid environments for {algorithm}: {}",
                Self::preset_envs(algorithm).join(", ")
            ))
        };
        let names = preset_layers(env);
        let registered = env_names().contains(&env);
        let mut table = toml::Table::new();
        if !lay(&mut table, SeadsConfig::ALGORITHM, &names)
            || !(registered || is_own_preset(env))
            || !preset_is_complete(env, &names, &table)
        {
            return Err(no_preset());
        }
        if algorithm != SeadsConfig::ALGORITHM {
            table.remove(SeadsConfig::NAME);
            let every = lay(&mut table, algorithm, &[EVERY_ENV.to_owned()]);
            if !lay(&mut table, algorithm, &names) && !every {
                return Err(no_preset());
            }
        }
        table.insert("env".into(), toml::Value::String(env.into()));
        table.insert("algorithm".into(), toml::Value::String(algorithm.into()));
        Self::from_table(table)
    }

    /// The environments with a preset of learner `algorithm`, sorted: the registered ones and
    /// those with a layer of their own (the robot's).
    pub fn preset_envs(algorithm: &str) -> Vec<&'static str> {
        let own = PRESETS
            .iter()
            .filter(|(a, name, _)| *a == SeadsConfig::ALGORITHM && is_own_preset(name))
            .map(|(_, name, _)| *name);
        let mut envs: Vec<&str> = env_names()
            .into_iter()
            .chain(own)
            .filter(|env| {
                let names = preset_layers(env);
                let mut table = toml::Table::new();
                let found = |a: &str, names: &[String], t: &mut toml::Table| lay(t, a, names);
                found(SeadsConfig::ALGORITHM, &names, &mut table)
                    && preset_is_complete(env, &names, &table)
                    && (algorithm == SeadsConfig::ALGORITHM
                        || found(algorithm, &[EVERY_ENV.to_owned()], &mut table)
                        || found(algorithm, &names, &mut table))
            })
            .collect();
        envs.sort_unstable();
        envs.dedup();
        envs
    }

    /// Every preset of learner `algorithm`, as `(environment, configuration)`.
    pub fn presets_of(algorithm: &str) -> Vec<(&'static str, Result<Self, RunError>)> {
        Self::preset_envs(algorithm)
            .into_iter()
            .map(|env| (env, Self::preset_for(env, algorithm)))
            .collect()
    }

    /// Every shipped preset file's text, as `(algorithm, layer, TOML text)`: the layer is a
    /// manipulator, a game or an environment ([`preset_layers`]), or `*` for a learner's
    /// settings on every environment.
    pub fn preset_files() -> &'static [(&'static str, &'static str, &'static str)] {
        PRESETS
    }

    /// A configuration a user wrote (a `--config` file, a run's `config.toml`): it must name its
    /// `env` (or `env` is given here), and what it leaves out comes from that environment's
    /// preset of its `algorithm` (or the given one; SEADS where none is named), never from
    /// generic defaults. Unknown fields, bad values and another algorithm's section are errors
    /// naming the line or the field, and so is an environment with no preset.
    ///
    /// ```
    /// use seads_run::TrainConfig;
    /// let config = TrainConfig::from_user_toml("env = \"tileswap-reacher\"\nseed = 3", None, None)?;
    /// assert_eq!(config.seed, 3);
    /// // The rest is the environment's preset, not the generic defaults.
    /// assert_eq!(config.sac.alpha, TrainConfig::preset("tileswap-reacher")?.sac.alpha);
    /// assert!(TrainConfig::from_user_toml("", None, None).is_err());
    /// // A baseline has no SEADS section.
    /// let text = "env = \"lightsout-cursor\"\nalgorithm = \"sac\"\n[seads]\nnum_skills = 30";
    /// assert!(TrainConfig::from_user_toml(text, None, None).is_err());
    /// # Ok::<(), seads_run::RunError>(())
    /// ```
    pub fn from_user_toml(
        text: &str,
        env: Option<&str>,
        algorithm: Option<&str>,
    ) -> Result<Self, RunError> {
        let mut table = parse_table(text)?;
        let stated = algorithm_of(&table)?;
        let stated = stated.as_deref();
        // Fields and types first, with the user's line numbers (the algorithm in force named
        // ahead of the text where the text names none).
        if stated.is_none() || algorithm.is_none_or(|a| Some(a) == stated) {
            let named = algorithm.or(stated).unwrap_or(SeadsConfig::ALGORITHM);
            let prefix = match stated {
                Some(_) => String::new(),
                None => format!("algorithm = \"{named}\"\n"),
            };
            check_sections(&table, named)?;
            toml::from_str::<Self>(&format!("{prefix}{text}"))
                .map_err(|e| RunError::Config(one_line_toml_error(text, &e, prefix.len())))?;
        }
        if let Some(env) = env {
            table.insert("env".into(), toml::Value::String(env.into()));
        }
        let algorithm = algorithm.or(stated).unwrap_or(SeadsConfig::ALGORITHM);
        table.insert("algorithm".into(), toml::Value::String(algorithm.into()));
        // The values the file states, before what it leaves out is filled in.
        Self::from_table(table.clone())?;
        let Some(toml::Value::String(env)) = table.get("env").cloned() else {
            return Err(RunError::Config(format!(
                "the configuration names no `env` (one of {}); its preset fills in the rest",
                env_names().join(", ")
            )));
        };
        let preset = Self::preset_for(&env, algorithm)?;
        let mut merged: toml::Table = preset
            .to_toml()
            .parse()
            .expect("a serialised preset parses");
        merge_toml(&mut merged, &table);
        Self::from_table(merged)
    }

    /// Parses a complete TOML configuration (fields left out take the generic defaults, which
    /// only the presets rely on: a user's file goes through [`TrainConfig::from_user_toml`]) and
    /// validates its values (not the environment: see [`TrainConfig::validate`]).
    pub fn from_toml(text: &str) -> Result<Self, RunError> {
        Self::from_table(parse_table(text)?)
    }

    /// A configuration from a parsed TOML table (SEADS where it names no `algorithm`; fields left
    /// out take the generic defaults), its values validated.
    pub fn from_table(mut table: toml::Table) -> Result<Self, RunError> {
        let algorithm = algorithm_of(&table)?.unwrap_or_else(|| SeadsConfig::ALGORITHM.into());
        check_sections(&table, &algorithm)?;
        table.insert("algorithm".into(), toml::Value::String(algorithm));
        let mut config: Self = table.try_into().map_err(|e: toml::de::Error| {
            RunError::Config(older_layout_hint(e.message().trim().replace('\n', " ")))
        })?;
        config.learner.complete_known()?;
        config.validate_values()?;
        Ok(config)
    }

    /// The configuration as TOML: the run's settings, `[sac]` and the section of its algorithm
    /// (with its defaults), in that order.
    pub fn to_toml(&self) -> String {
        toml::to_string(self).expect("a config serialises")
    }

    /// Checks every value, and that the environment exists with these options.
    pub fn validate(&self) -> Result<(), RunError> {
        if !env_names().contains(&self.env.as_str()) {
            return Err(RunError::Config(format!(
                "unknown environment {:?}; valid environments: {}",
                self.env,
                env_names().join(", ")
            )));
        }
        let env = seads_embodiment::make_env(&self.env, &self.env_config)?;
        self.validate_values()?;
        self.check_memory(env.spec(), machine_memory_bytes())
    }

    /// Bytes a run of this configuration holds at least (a lower bound, so that a refusal is
    /// never wrong), estimated from the environment's sizes before anything is allocated: the
    /// networks with gradients and Adam's two moments (critics twice, with targets) and one
    /// update's activations; for SEADS the skill model, the episode buffer, an epoch's episodes
    /// and relabelling's cost matrix; for a baseline its replay buffer. In `f64`, so that no
    /// size overflows.
    pub fn memory_estimate(&self, spec: &seads_embodiment::EnvSpec) -> f64 {
        let f = |v: usize| v as f64;
        let (obs, act, board) = (f(spec.obs_dim), f(spec.action_dim), f(spec.symbolic_len));
        // Weights of a multilayer perceptron from `input` through `hidden` to `output`.
        let mlp = |input: f64, hidden: &[i64], output: f64| {
            let mut sizes = vec![input];
            sizes.extend(hidden.iter().map(|&h| h.max(0) as f64));
            sizes.push(output);
            sizes.windows(2).map(|w| (w[0] + 1.0) * w[1]).sum::<f64>()
        };
        let width = |hidden: &[i64]| hidden.iter().map(|&h| h.max(0) as f64).sum::<f64>();
        let sac_activations = f(self.sac.batch_size) * width(&self.sac.hidden) * 3.0;
        let Ok(seads) = self.seads() else {
            // Another learner: its networks see at least the observation.
            let actor = mlp(obs, &self.sac.hidden, 2.0 * act);
            let critic = mlp(obs + act, &self.sac.hidden, 1.0);
            let replay = self
                .baseline_training()
                .map_or(0.0, |b| f(b.replay_capacity));
            return 4.0 * (4.0 * actor + 10.0 * critic + sac_activations + replay * (obs + act));
        };
        let skills = f(seads.num_skills.unwrap_or(spec.num_skills));
        let steps = f(spec.step_limit.unwrap_or(1).max(1));
        let actor = mlp(obs + skills, &self.sac.hidden, 2.0 * act);
        let critic = mlp(obs + skills + act, &self.sac.hidden, 1.0);
        let outputs = match seads.skill_model.kind {
            SkillModelKind::Mixture => f(seads.skill_model.mixture_components()) * (board + 1.0),
            SkillModelKind::Forward | SkillModelKind::Vic => board,
        };
        let forward_model = mlp(board + skills, &seads.skill_model.hidden, outputs);
        let weights = 4.0 * actor + 10.0 * critic + 4.0 * forward_model;
        let activations =
            sac_activations + f(seads.skill_model.batch_size) * width(&seads.skill_model.hidden);
        let episodes = (f(seads.buffer_capacity) + f(seads.episodes_per_epoch)) * steps;
        let relabelling = 2.0 * f(seads.sampled_episodes) * skills;
        4.0 * (weights + activations + episodes * (obs + act) + relabelling)
    }

    /// Refuses a configuration whose [`memory_estimate`](Self::memory_estimate) exceeds
    /// `available` bytes (the machine's memory), naming the sizes to lower.
    pub fn check_memory(
        &self,
        spec: &seads_embodiment::EnvSpec,
        available: u64,
    ) -> Result<(), RunError> {
        let need = self.memory_estimate(spec);
        if need.is_finite() && need <= available as f64 {
            return Ok(());
        }
        let gib = |b: f64| {
            let g = b / f64::from(1u32 << 30);
            if g < 1e6 {
                format!("{g:.1}")
            } else {
                format!("{g:.1e}")
            }
        };
        Err(RunError::Config(format!(
            "this configuration needs at least {} GiB, more than this machine's {} GiB \
             (lower num_skills, the hidden sizes, buffer_capacity, episodes_per_epoch, the batch \
             sizes or the baseline's replay_capacity)",
            gib(need),
            gib(available as f64)
        )))
    }

    /// Checks every value except the environment (robot environments are not in the registry;
    /// the trainer that gets one checks it).
    pub fn validate_values(&self) -> Result<(), RunError> {
        let bad = |m: String| Err(RunError::Config(m));
        self.sac.validate()?;
        self.learner.clone().complete_known()?;
        // Counts that set a pool's size: beyond these a run would spawn more threads than a
        // machine has.
        for (name, value) in [
            ("threads", self.threads),
            ("sac_threads_alone", self.sac_threads_alone),
        ] {
            if value as u64 > MAX_THREADS {
                return bad(format!("{name} must be at most {MAX_THREADS}, got {value}"));
            }
        }
        // TOML integers are 64-bit signed: a larger value would be written into config.toml but
        // never read back.
        for (name, value) in [("seed", self.seed), ("env_steps", self.env_steps)] {
            if i64::try_from(value).is_err() {
                return bad(format!(
                    "{name} must be at most {} (a TOML integer), got {value}",
                    i64::MAX
                ));
            }
        }
        if self.eval_every == 0 || self.checkpoint_every == 0 {
            return bad("eval_every and checkpoint_every must be at least 1".into());
        }
        // A run of no step would write no checkpoint and never finish.
        if self.env_steps == 0 {
            return bad("env_steps must be at least 1".into());
        }
        Ok(())
    }

    /// How a baseline collects and learns (`[sac_baseline]`, or HAC's share of `[hac]`), for a
    /// learner that must be a baseline: SEADS's configuration is an error.
    pub fn baseline_training(&self) -> Result<BaselineConfig, RunError> {
        if self.is::<HacConfig>() {
            return Ok(self.section::<HacConfig>()?.training());
        }
        if self.is::<BaselineConfig>() {
            return self.section::<BaselineConfig>();
        }
        Err(RunError::Config(format!(
            "a {} run is no task-reward baseline",
            self.algorithm()
        )))
    }
}

/// The machine's memory in bytes (`MemTotal` of `/proc/meminfo`), or `u64::MAX` where it
/// cannot be read: a configuration is refused only where its size is known to be too large.
pub fn machine_memory_bytes() -> u64 {
    std::fs::read_to_string("/proc/meminfo")
        .ok()
        .and_then(|text| {
            let line = text.lines().find(|l| l.starts_with("MemTotal:"))?;
            let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
            kib.checked_mul(1024)
        })
        .unwrap_or(u64::MAX)
}

/// Lays `layer` over `base`: a key of `layer` replaces `base`'s, except that two tables merge,
/// key by key. How a partial configuration fills from its preset, and how a study's variant
/// overrides its preset.
pub fn merge_toml(base: &mut toml::Table, layer: &toml::Table) {
    for (key, value) in layer {
        match (base.get_mut(key), value) {
            (Some(toml::Value::Table(b)), toml::Value::Table(l)) => merge_toml(b, l),
            _ => {
                base.insert(key.clone(), value.clone());
            }
        }
    }
}

/// The most threads a configuration may ask for (libtorch's and the environments'): more than
/// any machine this runs on has cores.
const MAX_THREADS: u64 = 1024;

/// Fields that a resumed or evaluated run may change: the budget (`--env-steps`) and the thread
/// counts, which sweeps and the robot set per task and which do not change a run's numbers (a
/// test in `tests/training.rs` checks), and the device (`--device`: a checkpoint moves between
/// devices).
const RESUMABLE_CHANGES: [&str; 4] = ["env_steps", "threads", "sac_threads_alone", "device"];

/// The first field in which two configurations differ, other than those a resumed run may
/// change (the budget, thread counts), as `(dotted name, this value, that value)`.
pub fn config_difference(
    this: &TrainConfig,
    that: &TrainConfig,
) -> Option<(String, String, String)> {
    fn walk(prefix: &str, a: &toml::Table, b: &toml::Table) -> Option<(String, String, String)> {
        let mut keys: Vec<&String> = a.keys().chain(b.keys()).collect();
        keys.sort();
        keys.dedup();
        for key in keys {
            let name = if prefix.is_empty() {
                key.clone()
            } else {
                format!("{prefix}.{key}")
            };
            if RESUMABLE_CHANGES.contains(&name.as_str()) {
                continue;
            }
            match (a.get(key), b.get(key)) {
                (Some(toml::Value::Table(x)), Some(toml::Value::Table(y))) => {
                    if let Some(d) = walk(&name, x, y) {
                        return Some(d);
                    }
                }
                (x, y) if x != y => {
                    let show =
                        |v: Option<&toml::Value>| v.map_or("unset".into(), |v| v.to_string());
                    return Some((name, show(x), show(y)));
                }
                _ => {}
            }
        }
        None
    }
    let table = |c: &TrainConfig| -> toml::Table {
        c.to_toml().parse().expect("a serialised config parses")
    };
    walk("", &table(this), &table(that))
}

/// A configuration's text as a table.
fn parse_table(text: &str) -> Result<toml::Table, RunError> {
    text.parse()
        .map_err(|e| RunError::Config(one_line_toml_error(text, &e, 0)))
}

/// The learner a configuration's table names, if it names one: a learner with presets.
fn algorithm_of(table: &toml::Table) -> Result<Option<String>, RunError> {
    match table.get("algorithm") {
        None => Ok(None),
        Some(toml::Value::String(name)) if section_name(name).is_some() => Ok(Some(name.clone())),
        Some(toml::Value::String(name)) => Err(unknown_learner(name)),
        Some(other) => Err(RunError::Config(format!(
            "algorithm must be a name (one of {}), got {other}",
            learner_names().join(", ")
        ))),
    }
}

/// The error for a learner `name` that has no presets.
fn unknown_learner(name: &str) -> RunError {
    RunError::Config(format!(
        "algorithm: unknown learner {name:?} (one of {})",
        learner_names().join(", ")
    ))
}

/// Refuses a table in `table` that is neither the run's own nor learner `algorithm`'s section,
/// naming the learner whose section it is.
fn check_sections(table: &toml::Table, algorithm: &str) -> Result<(), RunError> {
    let own = section_name(algorithm);
    for (key, value) in table {
        if !value.is_table() || RUN_TABLES.contains(&key.as_str()) || Some(key.as_str()) == own {
            continue;
        }
        let owner = LEARNERS.iter().find(|(_, section)| *section == key);
        return Err(RunError::Config(match owner {
            Some((other, _)) => format!(
                "[{key}] is the section of algorithm {other:?}, not of this run's {algorithm:?}; remove it"
            ),
            None => older_layout_hint(format!(
                "unknown field `{key}` (a run of {algorithm:?} has the section [{}])",
                own.unwrap_or("?")
            )),
        }));
    }
    Ok(())
}

/// `message`, with a pointer to `seads migrate` where it names an unknown field: the older
/// layouts' keys are unknown to today's.
fn older_layout_hint(message: String) -> String {
    if message.contains("unknown field") {
        format!("{message} (a file of an older version? `seads migrate` rewrites it)")
    } else {
        message
    }
}

/// A TOML error in one line, with the line and column of `text` where it has a span; the span is
/// of a text that had `shift` bytes ahead of `text`.
fn one_line_toml_error(text: &str, e: &toml::de::Error, shift: usize) -> String {
    let message = older_layout_hint(e.message().trim().replace('\n', " "));
    match e
        .span()
        .filter(|span| span.start >= shift && span != &(0..0))
    {
        Some(span) => {
            let before = &text[..(span.start - shift).min(text.len())];
            let line = before.matches('\n').count() + 1;
            let column = before.len() - before.rfind('\n').map_or(0, |i| i + 1) + 1;
            format!("line {line}, column {column}: {message}")
        }
        None => message,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::MAX_PER_EPOCH;
    use proptest::prelude::*;

    /// The device is written only when it is not the CPU, so the presets and every CPU run's
    /// config.toml read as before devices existed; a GPU run's says so and reads back.
    #[test]
    fn the_device_is_written_only_for_a_gpu() {
        let cpu = TrainConfig::default();
        assert!(!cpu.to_toml().contains("device"));
        let gpu = TrainConfig {
            device: ComputeDevice::Cuda(1),
            ..TrainConfig::default()
        };
        let text = gpu.to_toml();
        assert!(text.contains("device = \"cuda:1\""), "{text}");
        assert_eq!(TrainConfig::from_user_toml(&text, None, None).unwrap(), gpu);
        let err = TrainConfig::from_user_toml(
            "env = \"lightsout-cursor\"\ndevice = \"cuda:x\"",
            None,
            None,
        )
        .unwrap_err();
        assert!(
            err.to_string().contains("not one of cpu, cuda, cuda:N"),
            "{err}"
        );
    }

    #[test]
    fn the_jaco_presets_take_25_physics_steps_as_the_manipulators_option() {
        let mut jaco = 0;
        for algorithm in learner_names() {
            for env in env_names().into_iter().filter(|e| e.ends_with("-jaco")) {
                let config = TrainConfig::preset_for(env, algorithm).unwrap();
                assert_eq!(
                    config.env_config.manipulator.get("physics_substeps"),
                    Some(&serde_json::Value::from(25)),
                    "{env} {algorithm:?}"
                );
                config.validate().unwrap();
                jaco += 1;
            }
        }
        // Three Jaco environments, each with a preset of all four learners.
        assert_eq!(jaco, 12);
    }

    /// A written configuration holds `algorithm` and its algorithm's section only, and reads
    /// back as it was; every preset of every algorithm does.
    #[test]
    fn a_written_config_holds_its_algorithms_section_only() {
        let mut presets = 0;
        for algorithm in learner_names() {
            for (env, config) in TrainConfig::presets_of(algorithm) {
                let config = config.unwrap();
                assert_eq!(config.algorithm(), algorithm);
                let text = config.to_toml();
                let table: toml::Table = text.parse().unwrap();
                let sections: Vec<&str> = table
                    .iter()
                    .filter(|(k, v)| v.is_table() && !RUN_TABLES.contains(&k.as_str()))
                    .map(|(k, _)| k.as_str())
                    .collect();
                assert_eq!(
                    sections,
                    [section_name(algorithm).unwrap()],
                    "{env}: {text}"
                );
                assert_eq!(
                    table.get("algorithm").and_then(|a| a.as_str()),
                    Some(algorithm)
                );
                assert_eq!(TrainConfig::from_toml(&text).unwrap(), config);
                presets += 1;
            }
        }
        // 14 environments with SEADS, 12 each with SAC and HAC (not the robot's), and DIAYN on
        // all 14 through its settings on every environment.
        assert_eq!(presets, 14 + 12 + 12 + 14);
    }

    /// The robot's presets (seed S.5) are the LightsOutCursor preset with 5000 interactions,
    /// SAC α = 0.1 and, with absolute pushes, 4 new episodes an epoch: the settings the binary
    /// built in code before they were presets.
    #[test]
    fn the_robots_presets_are_the_cursors_with_the_papers_robot_settings() {
        let cursor = TrainConfig::preset("lightsout-cursor").unwrap();
        for (env, episodes) in [
            ("uarm-lightsout-absolute", 4),
            ("uarm-lightsout-displacement", 32),
        ] {
            let mut expected = cursor.clone();
            expected.env = env.into();
            expected.env_steps = 5000;
            expected.sac.alpha = 0.1;
            expected
                .edit(|s: &mut SeadsConfig| s.episodes_per_epoch = episodes)
                .unwrap();
            assert_eq!(TrainConfig::preset(env).unwrap(), expected);
        }
        // A name with no preset is an error that lists the ones there are.
        let e = TrainConfig::from_user_toml("env = \"uarm-lightsout\"", None, None).unwrap_err();
        assert!(
            e.to_string()
                .contains("unknown environment \"uarm-lightsout\"")
                && e.to_string().contains("uarm-lightsout-absolute"),
            "{e}"
        );
    }

    /// Another algorithm's section, the older flat layout and `[sac] updates_per_epoch` are
    /// refused, each in one line naming the field; a type error names the user's line.
    #[test]
    fn misplaced_settings_are_refused_in_one_line() {
        let refused = |text: &str| {
            let e = TrainConfig::from_user_toml(text, None, None)
                .unwrap_err()
                .to_string();
            assert!(!e.contains('\n'), "{e}");
            e
        };
        let e = refused("env = \"lightsout-cursor\"\n[hac]\ntemperature = 0.5");
        assert!(
            e.contains("[hac] is the section of algorithm \"hac\", not of this run's \"seads\""),
            "{e}"
        );
        let e = refused("env = \"lightsout-cursor\"\nnum_skills = 30");
        assert!(e.contains("unknown field `num_skills`"), "{e}");
        let e = refused("env = \"lightsout-cursor\"\n[sac]\nupdates_per_epoch = 4");
        assert!(e.contains("unknown field `updates_per_epoch`"), "{e}");
        let e = refused("env = \"lightsout-jaco\"\n[env_config]\nphysics_substeps = 25");
        assert!(e.contains("unknown field `physics_substeps`"), "{e}");
        // The user's own line and column, though the algorithm was named ahead of the text.
        let e = refused("env = \"lightsout-cursor\"\n\n[sac]\nlr = \"fast\"");
        assert!(
            e.starts_with("invalid configuration: line 4, column 6:"),
            "{e}"
        );
        // The command line's algorithm chooses the section a file may hold.
        let sac = TrainConfig::from_user_toml(
            "env = \"lightsout-cursor\"\n[sac_baseline]\neval_boards = 3",
            None,
            Some("sac"),
        )
        .unwrap();
        assert_eq!(sac.section::<BaselineConfig>().unwrap().eval_boards, 3);
    }

    #[test]
    fn a_user_config_must_name_its_env_and_fills_from_its_preset() {
        let err = TrainConfig::from_user_toml("", None, None).unwrap_err();
        assert!(err.to_string().contains("names no `env`"), "{err}");
        let err = TrainConfig::from_user_toml("seed = 2", None, None).unwrap_err();
        assert!(err.to_string().contains("names no `env`"), "{err}");
        // The issue's case: only the environment, which must get its preset (α 0.01), not the
        // generic defaults (α 0.1).
        let partial =
            TrainConfig::from_user_toml("env = \"tileswap-reacher\"", None, None).unwrap();
        let preset = TrainConfig::preset("tileswap-reacher").unwrap();
        assert_eq!(partial, preset);
        assert_ne!(preset.sac.alpha, TrainConfig::default().sac.alpha);
        // A nested override keeps the rest of its table.
        let lr = TrainConfig::from_user_toml(
            "env = \"lightsout-cursor\"\n[sac]\nlr = 0.001",
            None,
            None,
        )
        .unwrap();
        assert_eq!(lr.sac.lr, 0.001);
        assert_eq!(
            lr.sac.hidden,
            TrainConfig::preset("lightsout-cursor").unwrap().sac.hidden
        );
        // The command line may give the environment and the algorithm.
        let sac =
            TrainConfig::from_user_toml("seed = 4", Some("lightsout-cursor"), Some("sac")).unwrap();
        assert_eq!(
            (sac.seed, sac.sac.hidden.clone()),
            (
                4,
                TrainConfig::preset_for("lightsout-cursor", "sac")
                    .unwrap()
                    .sac
                    .hidden
            )
        );
        for bad in [
            "env = \"nowhere\"",
            "env = \"lightsout-cursor\"\nlrr = 1",
            "env = 3",
        ] {
            assert!(
                TrainConfig::from_user_toml(bad, None, None).is_err(),
                "{bad}"
            );
        }
    }

    /// The estimate for the LightsOutCursor preset, by hand: obs 28, action 3, K 25, T 10,
    /// 25 fields, hidden [256, 256] everywhere. Actor (54·256 + 257·256 + 257·6 = 81158),
    /// critic (57·256 + 257·256 + 257 = 80641), forward model (51·256 + 257·256 + 257·25 =
    /// 85273): 4·81158 + 10·80641 + 4·85273 = 1472134 weights; activations 128·512·3 + 32·512 =
    /// 212992; episodes (2048 + 32)·10·31 = 644800; relabelling 2·256·25 = 12800; 4 bytes each.
    #[test]
    fn the_memory_estimate_of_the_preset_is_the_hand_computed_one() {
        let config = TrainConfig::preset("lightsout-cursor").unwrap();
        let env = seads_embodiment::make_env(&config.env, &config.env_config).unwrap();
        assert_eq!(config.memory_estimate(env.spec()), 9_370_904.0);
        assert!(config.check_memory(env.spec(), 9_370_904).is_ok());
        let refused = config.check_memory(env.spec(), 9_370_903).unwrap_err();
        assert!(refused.to_string().contains("num_skills"), "{refused}");
    }

    // Each strategy gives a value a configuration may hold most of the time (19 in 20) and one
    // it must refuse otherwise, so that the property below sees both branches often (the test
    // counts them: with some twenty values drawn per case, about a third of the cases hold
    // valid values only).
    fn size() -> impl Strategy<Value = usize> {
        prop_oneof![
            38 => 1..5000usize,
            1 => 0..4usize,
            1 => prop_oneof![(1usize << 20)..(1usize << 44), Just(usize::MAX)],
        ]
    }

    fn small() -> impl Strategy<Value = usize> {
        prop_oneof![38 => 1..64usize, 2 => size()]
    }

    fn layers() -> impl Strategy<Value = Vec<i64>> {
        let layer = prop_oneof![
            38 => 1..2048i64,
            1 => -2..4i64,
            1 => prop_oneof![(1i64 << 20)..(1i64 << 40), Just(i64::MAX)],
        ];
        prop_oneof![
            38 => prop::collection::vec(layer, 1..4),
            2 => Just(Vec::new()),
        ]
    }

    fn real() -> impl Strategy<Value = f64> {
        prop_oneof![
            38 => 1e-6..1.0f64,
            1 => prop_oneof![Just(f64::NAN), Just(f64::INFINITY), Just(f64::NEG_INFINITY)],
            1 => prop_oneof![Just(-0.0), Just(0.0), any::<f64>()],
        ]
    }

    fn signed() -> impl Strategy<Value = u64> {
        prop_oneof![38 => 0..=i64::MAX as u64, 2 => any::<u64>()]
    }

    /// Any values of the sizes and rates are checked without a panic, and what is accepted has
    /// positive sizes, finite rates and fits into the machine's memory, and is written and read
    /// back as it was. The cases both accepted and refused are counted: neither branch may go
    /// untested.
    #[test]
    fn any_config_values_are_checked_without_panic_and_accepted_only_if_they_fit() {
        let cases = 300;
        // A fixed stream: the same cases on every run and machine.
        let rng = proptest::test_runner::TestRng::deterministic_rng(
            proptest::test_runner::RngAlgorithm::ChaCha,
        );
        let config = ProptestConfig {
            cases,
            failure_persistence: None,
            ..ProptestConfig::default()
        };
        let mut runner = proptest::test_runner::TestRunner::new_with_rng(config, rng);
        let (accepted, refused) = (std::cell::Cell::new(0u32), std::cell::Cell::new(0u32));
        let values = (
            size(),
            (layers(), layers()),
            (size(), size(), small()),
            (size(), size(), size()),
            (real(), real(), real(), real()),
            any::<bool>(),
            (small(), size(), size()),
            (size(), size()),
            (signed(), signed()),
        );
        runner
            .run(
                &values,
                |(
                    num_skills,
                    (sac_hidden, model_hidden),
                    (episodes, capacity, sampled),
                    (sac_batch, model_batch, replay),
                    (lr, alpha, gamma, p),
                    baseline,
                    (threads, eval_seeds, updates),
                    (samples, boards),
                    (seed, env_steps),
                )| {
                    let mut config = TrainConfig::preset("lightsout-cursor").unwrap();
                    config.sac.hidden = sac_hidden;
                    config.sac.batch_size = sac_batch;
                    config.sac.lr = lr;
                    config.sac.alpha = alpha;
                    config.sac.gamma = gamma;
                    config.threads = threads;
                    config.seed = seed;
                    config.env_steps = env_steps;
                    let learner = if baseline {
                        LearnerConfig::of(&BaselineConfig {
                            replay_capacity: replay,
                            samples_per_epoch: samples,
                            eval_boards: boards,
                            ..BaselineConfig::default()
                        })
                    } else {
                        let mut seads = config.seads().unwrap();
                        seads.num_skills = Some(num_skills);
                        seads.skill_model.hidden = model_hidden;
                        seads.episodes_per_epoch = episodes;
                        seads.buffer_capacity = capacity;
                        seads.sampled_episodes = sampled;
                        seads.recent_episodes = sampled.min(capacity);
                        seads.skill_model.batch_size = model_batch;
                        seads.relabel.sac_p = p;
                        seads.eval_seeds = eval_seeds as u64;
                        seads.updates_per_epoch = updates;
                        LearnerConfig::of(&seads)
                    };
                    // A value beyond TOML's integers cannot be written, so is refused.
                    let valid = learner.map(|l| config.learner = l).is_ok();
                    if !valid || config.validate().is_err() {
                        refused.set(refused.get() + 1);
                        return Ok(());
                    }
                    accepted.set(accepted.get() + 1);
                    let env = seads_embodiment::make_env(&config.env, &config.env_config).unwrap();
                    prop_assert!(
                        config.memory_estimate(env.spec()) <= machine_memory_bytes() as f64
                    );
                    prop_assert!(config.sac.hidden.iter().all(|&h| h > 0));
                    prop_assert!(lr.is_finite() && lr > 0.0 && alpha.is_finite() && alpha > 0.0);
                    prop_assert!((0.0..=1.0).contains(&gamma));
                    prop_assert!(sac_batch > 0);
                    prop_assert!(threads as u64 <= MAX_THREADS);
                    prop_assert!(i64::try_from(seed).is_ok() && i64::try_from(env_steps).is_ok());
                    if baseline {
                        prop_assert!(samples as u64 <= MAX_PER_EPOCH);
                        prop_assert!(boards as u64 <= MAX_PER_EPOCH);
                    } else {
                        prop_assert!(num_skills > 0 && episodes > 0);
                        prop_assert!((0.0..=1.0).contains(&p));
                        prop_assert!((eval_seeds as u64) <= MAX_PER_EPOCH);
                        prop_assert!(updates as u64 <= MAX_PER_EPOCH);
                    }
                    // What is accepted is written and read back as it was.
                    let back = TrainConfig::from_toml(&config.to_toml());
                    prop_assert!(back.is_ok(), "{:?}", back.err());
                    prop_assert_eq!(back.unwrap(), config);
                    Ok(())
                },
            )
            .unwrap();
        assert_eq!(accepted.get() + refused.get(), cases);
        assert!(
            accepted.get() >= cases / 20 && refused.get() >= cases / 20,
            "{} accepted, {} refused of {cases}: both branches need cases",
            accepted.get(),
            refused.get()
        );
    }

    #[test]
    fn config_differences_name_the_field_but_not_the_budget_or_threads() {
        let a = TrainConfig::preset("lightsout-cursor").unwrap();
        let mut b = a.clone();
        b.env_steps += 1000;
        b.threads = 4;
        b.sac_threads_alone = 0;
        assert_eq!(config_difference(&a, &b), None);
        b.edit(|s: &mut SeadsConfig| s.skill_model.lr = 0.5)
            .unwrap();
        let (field, now, then) = config_difference(&b, &a).unwrap();
        assert_eq!(field, "seads.skill_model.lr");
        assert_eq!((now.as_str(), then.as_str()), ("0.5", "0.001"));
    }
}
