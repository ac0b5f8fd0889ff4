//! DIAYN, "Diversity is all you need" (Eysenbach et al., 2019): reward-free skills from a
//! discriminator q(k | s) that tells the skills apart by the states they reach. Added as a
//! learner the way a newcomer adds one (`docs/ARCHITECTURE.md`): this file, a line in the
//! registry (`learners.rs`) and one preset (`crates/seads-run/configs/diayn/every-env.toml`).
//!
//! Each epoch runs `episodes_per_epoch` skill episodes, a skill k drawn uniformly per episode,
//! from the environment's resets, as SEADS does (an episode ends when the board changes or at
//! the skill's step limit). Their transitions go into a replay buffer of policy inputs
//! `[s, onehot(k)]`. Then `updates_per_epoch` times: a minibatch trains the discriminator on
//! (s', k) by cross-entropy, and SAC takes a step on the same minibatch with DIAYN's reward
//! r = log q(k | s') − log p(k), p(k) = 1/K uniform, computed with the discriminator of the
//! moment (as the authors' code does, so that old transitions are scored by today's
//! discriminator). The discriminator sees the environment's whole observation (manipulator and
//! board), the skill policy is SAC on `[s, onehot(k)]` with the run's `[sac]` settings, and the
//! last transition of an episode ends its return, as in SEADS. Skill coverage (SPEC §4.5) is its
//! evaluation, as for SEADS, so that the two compare on the same metric.
//!
//! DIAYN learns no forward model: `seads fit-model` fits SEADS's to its frozen skills for
//! planning. Resuming is exact: a checkpoint holds the networks, both optimisers, the replay
//! buffer and the random streams; episodes never span epochs.

use std::path::Path;
use std::time::Instant;

use rand::RngExt;
use rand_chacha::ChaCha8Rng;
use seads_embodiment::{EnvConfig, EnvSpec, Environment, make_env};
use seads_games::Split;
use seads_nn::{Adam, Init, Mlp, Resolve as _};
use seads_run::{Metrics, RunError, Section, Timings};
use serde::{Deserialize, Serialize};
use tch::{Kind, Tensor, nn, nn::Module};

use crate::episode::{policy_input, run_episodes, skill_coverage};
use crate::replay::Replay;
use crate::{
    COVERAGE_SEED, InWords, Learner, Moment, Purpose, RlError, Sac, TrainConfig, derived_seed,
    stream,
};

/// DIAYN's section, `[diayn]`, with the defaults of the authors' code where the paper's
/// environments leave no choice, and SEADS's collection where they do.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct DiaynConfig {
    /// Number of skills K (default: the number of game moves, as SEADS).
    pub num_skills: Option<usize>,
    /// New skill episodes per epoch.
    pub episodes_per_epoch: usize,
    /// Transitions kept in the replay buffer (the most recent).
    pub replay_capacity: usize,
    /// Gradient steps of the discriminator and of SAC per epoch.
    pub updates_per_epoch: usize,
    /// Hidden layers of the discriminator q(k | s).
    pub discriminator_hidden: Vec<i64>,
    /// The discriminator's Adam learning rate.
    pub discriminator_lr: f64,
    /// Number of evaluation seeds (444555, 444556, …) for skill coverage.
    pub eval_seeds: u64,
}

impl Default for DiaynConfig {
    fn default() -> Self {
        Self {
            num_skills: None,
            episodes_per_epoch: 32,
            replay_capacity: 1_000_000,
            updates_per_epoch: 16,
            discriminator_hidden: vec![256, 256],
            discriminator_lr: 3e-4,
            eval_seeds: 20,
        }
    }
}

impl Section for DiaynConfig {
    const ALGORITHM: &'static str = "diayn";
    const NAME: &'static str = "diayn";

    fn validate(&self) -> Result<(), RunError> {
        let bad = |m: String| Err(RunError::Config(m));
        let most = seads_run::MAX_PER_EPOCH;
        for (name, value) in [
            ("episodes_per_epoch", self.episodes_per_epoch as u64),
            ("replay_capacity", self.replay_capacity as u64),
            ("updates_per_epoch", self.updates_per_epoch as u64),
            ("eval_seeds", self.eval_seeds),
            ("num_skills", self.num_skills.map_or(1, |k| k as u64)),
        ] {
            if value == 0 {
                return bad(format!("diayn.{name} must be at least 1"));
            }
            if name != "replay_capacity" && value > most {
                return bad(format!("diayn.{name} must be at most {most}, got {value}"));
            }
        }
        if self
            .discriminator_hidden
            .iter()
            .any(|&h| !(1..=16_384).contains(&h))
        {
            return bad(format!(
                "diayn.discriminator_hidden must hold sizes from 1 to 16384, got {:?}",
                self.discriminator_hidden
            ));
        }
        let lr = self.discriminator_lr;
        if !(lr.is_finite() && lr > 0.0) {
            return bad(format!("diayn.discriminator_lr must be positive, got {lr}"));
        }
        Ok(())
    }
}

/// The discriminator's weights and its optimiser's state in a checkpoint.
const DISCRIMINATOR_FILE: &str = "diayn_discriminator.safetensors";
const DISCRIMINATOR_ADAM_FILE: &str = "diayn_discriminator_adam.safetensors";
/// The replay buffer, and epoch, steps, phase times and random streams.
const REPLAY_FILE: &str = "diayn_replay.safetensors";
const PROGRESS_FILE: &str = "diayn_progress.json";

/// The random streams of a run, each from (seed, purpose).
#[derive(Debug, Clone, Serialize, Deserialize)]
struct Streams {
    /// Skills of new episodes.
    labels: ChaCha8Rng,
    /// Policy noise while collecting.
    collect: ChaCha8Rng,
    /// Minibatch picks.
    sample: ChaCha8Rng,
    /// SAC update noise.
    sac: ChaCha8Rng,
}

/// How far a run is.
#[derive(Debug, Clone, Serialize, Deserialize)]
struct Progress {
    epoch: u64,
    env_steps: u64,
    timings: Timings,
    streams: Streams,
}

/// What one epoch did.
#[derive(Debug, Clone, Copy, Default)]
pub struct DiaynEpochStats {
    /// Mean DIAYN reward of the epoch's minibatches.
    pub mean_reward: f32,
    /// Share of the epoch's episodes that changed the board.
    pub changed: f32,
    /// Mean cross-entropy of the discriminator.
    pub discriminator_loss: f32,
    /// Mean critic and actor losses.
    pub critic_loss: f32,
    /// Mean actor loss.
    pub actor_loss: f32,
}

/// A DIAYN agent in training.
pub struct Diayn {
    config: TrainConfig,
    section: DiaynConfig,
    spec: EnvSpec,
    k: usize,
    envs: Vec<Box<dyn Environment>>,
    eval_env: Box<dyn Environment>,
    sac: Sac,
    discriminator: Mlp,
    discriminator_vs: nn::VarStore,
    discriminator_opt: Adam,
    replay: Replay,
    progress: Progress,
}

impl Diayn {
    /// A fresh agent for `config` (its `[diayn]` section checked).
    pub fn new(config: TrainConfig) -> Result<Self, RlError> {
        config.validate()?;
        let section: DiaynConfig = config.section()?;
        crate::numerics::check(config.portable_numerics)?;
        if config.threads > 0 {
            tch::set_num_threads(config.threads as i32);
        }
        let env_with = |reset_split| EnvConfig {
            reset_split,
            ..config.env_config.clone()
        };
        let template = make_env(&config.env, &env_with(Split::Train))?;
        let eval_env = make_env(&config.env, &env_with(Split::Test))?;
        let spec = template.spec().clone();
        let k = section.num_skills.unwrap_or(spec.num_skills);
        let device = config.device.resolve()?;
        let sac = Sac::new(
            spec.obs_dim + k,
            &spec.action_low,
            &spec.action_high,
            &config.sac,
            device,
            derived_seed(config.seed, Purpose::SacInit, 0),
        );
        let discriminator_vs = nn::VarStore::new(device);
        let mut init = stream(config.seed, Purpose::SkillModelInit);
        let discriminator = Mlp::new(
            &discriminator_vs.root(),
            spec.obs_dim as i64,
            &section.discriminator_hidden,
            k as i64,
            Init::TorchDefault,
            &mut init,
        );
        let discriminator_opt = Adam::new(&discriminator_vs, section.discriminator_lr);
        let progress = Progress {
            epoch: 0,
            env_steps: 0,
            timings: Timings::default(),
            streams: Streams {
                labels: stream(config.seed, Purpose::Labels),
                collect: stream(config.seed, Purpose::Collect),
                sample: stream(config.seed, Purpose::Sample),
                sac: stream(config.seed, Purpose::Sac),
            },
        };
        Ok(Self {
            envs: (0..section.episodes_per_epoch)
                .map(|_| template.box_clone())
                .collect(),
            replay: Replay::new(section.replay_capacity, spec.obs_dim + k, spec.action_dim),
            config,
            section,
            spec,
            k,
            eval_env,
            sac,
            discriminator,
            discriminator_vs,
            discriminator_opt,
            progress,
        })
    }

    /// The skill policy.
    pub fn policy(&self) -> &Sac {
        &self.sac
    }

    /// Number of skills K.
    pub fn num_skills(&self) -> usize {
        self.k
    }

    /// log q(k | s) for each row of `obs` (observations) and its skill.
    fn log_q(&self, obs: &Tensor, skills: &Tensor) -> Tensor {
        self.discriminator
            .forward(obs)
            .log_softmax(-1, Kind::Float)
            .gather(1, &skills.unsqueeze(1), false)
            .squeeze_dim(1)
    }

    /// DIAYN's reward log q(k | s) − log p(k), p(k) = 1/K, for each row of `states` and its skill.
    fn rewards(&self, states: &Tensor, skills: &Tensor) -> Vec<f32> {
        let log_p = -(self.k as f64).ln();
        let rewards =
            tch::no_grad(|| (self.log_q(states, skills) - log_p).to_device(tch::Device::Cpu));
        Vec::<f32>::try_from(&rewards).unwrap_or_default()
    }

    /// One epoch: its episodes, then the discriminator's and SAC's steps.
    pub fn run_epoch(&mut self) -> Result<DiaynEpochStats, RlError> {
        let start = Instant::now();
        let skills: Vec<usize> = (0..self.envs.len())
            .map(|_| self.progress.streams.labels.random_range(0..self.k))
            .collect();
        let (seed, epoch, slots) = (self.config.seed, self.progress.epoch, self.envs.len());
        for (slot, env) in self.envs.iter_mut().enumerate() {
            env.seed(crate::seeds::train_env_seed(seed, epoch, slots, slot));
            env.reset()?;
        }
        let episodes = run_episodes(
            &mut self.envs,
            &skills,
            &self.sac,
            self.k,
            Some(&mut self.progress.streams.collect),
        )?;
        let (o, a, width) = (
            self.spec.obs_dim,
            self.spec.action_dim,
            self.spec.obs_dim + self.k,
        );
        let (mut input, mut next) = (vec![0.0; width], vec![0.0; width]);
        let mut steps = 0;
        for e in &episodes {
            let length = e.len(a);
            for t in 0..length {
                policy_input(&e.obs[t * o..(t + 1) * o], e.skill, &mut input);
                policy_input(&e.obs[(t + 1) * o..(t + 2) * o], e.skill, &mut next);
                let action = &e.actions[t * a..(t + 1) * a];
                self.replay
                    .push(&input, action, 0.0, &next, t + 1 == length);
            }
            steps += length as u64;
        }
        let timings = &mut self.progress.timings;
        timings.collect += start.elapsed().as_secs_f64();

        let mut stats = DiaynEpochStats {
            changed: episodes.iter().filter(|e| e.changed()).count() as f32
                / episodes.len().max(1) as f32,
            ..DiaynEpochStats::default()
        };
        let batch_size = self.config.sac.batch_size;
        if self.replay.len() >= batch_size {
            let n = self.section.updates_per_epoch as f32;
            for _ in 0..self.section.updates_per_epoch {
                let (reward, loss, critic, actor) = self.update(batch_size);
                stats.mean_reward += reward / n;
                stats.discriminator_loss += loss / n;
                stats.critic_loss += critic / n;
                stats.actor_loss += actor / n;
            }
        }
        self.progress.env_steps += steps;
        self.progress.epoch += 1;
        Ok(stats)
    }

    /// One minibatch: a discriminator step on (s', k), then a SAC step with DIAYN's reward
    /// from the discriminator as it now is. Returns the mean reward and the three losses.
    fn update(&mut self, batch_size: usize) -> (f32, f32, f32, f32) {
        let start = Instant::now();
        let mut batch = self
            .replay
            .sample(batch_size, &mut self.progress.streams.sample);
        let (o, width) = (
            self.spec.obs_dim as i64,
            (self.spec.obs_dim + self.k) as i64,
        );
        let device = self.discriminator_vs.device();
        let next = Tensor::from_slice(&batch.next_obs)
            .view([-1, width])
            .to_device(device);
        let states = next.narrow(1, 0, o);
        let skills = next.narrow(1, o, self.k as i64).argmax(1, false);
        // Cross-entropy of the discriminator on (s', k).
        let loss = -self.log_q(&states, &skills).mean(Kind::Float);
        self.discriminator_opt.backward_step(&loss);
        let loss = f32::try_from(&loss).unwrap_or(f32::NAN);
        batch.rewards = self.rewards(&states, &skills);
        let timings = &mut self.progress.timings;
        timings.skill_model += start.elapsed().as_secs_f64();
        let start = Instant::now();
        let reward = batch.rewards.iter().sum::<f32>() / batch.rewards.len().max(1) as f32;
        let sac = self.sac.update(&batch, &mut self.progress.streams.sac);
        self.progress.timings.sac += start.elapsed().as_secs_f64();
        (reward, loss, sac.critic, sac.actor)
    }

    /// Skill coverage (SPEC §4.5), as SEADS measures it.
    pub fn skill_coverage(&mut self) -> Result<f64, RlError> {
        let start = Instant::now();
        let seeds: Vec<u64> = (0..self.section.eval_seeds)
            .map(|i| COVERAGE_SEED + i)
            .collect();
        let per_seed = skill_coverage(self.eval_env.as_ref(), &self.sac, self.k, &seeds)?;
        self.progress.timings.evaluate += start.elapsed().as_secs_f64();
        Ok(per_seed.iter().sum::<usize>() as f64 / per_seed.len() as f64)
    }
}

impl Learner for Diayn {
    type Section = DiaynConfig;
    type Stats = DiaynEpochStats;
    type Metrics = Metrics;

    fn build(config: TrainConfig) -> Result<Self, RlError> {
        Self::new(config)
    }
    fn config(&self) -> &TrainConfig {
        &self.config
    }
    fn epoch(&self) -> u64 {
        self.progress.epoch
    }
    fn finished(&self) -> bool {
        self.progress.env_steps >= self.config.env_steps
    }
    fn run_epoch_observed(
        &mut self,
        hook: &mut dyn FnMut(Moment),
    ) -> Result<DiaynEpochStats, RlError> {
        let stats = self.run_epoch()?;
        hook(Moment::Collected);
        Ok(stats)
    }
    fn metrics(&mut self, stats: &DiaynEpochStats, wall_s: f64) -> Result<Metrics, RlError> {
        let skill_coverage = self.skill_coverage()?;
        Ok(Metrics {
            epoch: self.progress.epoch,
            env_steps: self.progress.env_steps,
            skill_coverage,
            wall_s,
            mean_reward: stats.mean_reward,
            changed: stats.changed,
            skill_model_loss: stats.discriminator_loss,
            critic_loss: stats.critic_loss,
            actor_loss: stats.actor_loss,
            steps_per_s: self.progress.env_steps as f64 / wall_s.max(1e-9),
            timings: self.progress.timings,
        })
    }
    fn save(&self, dir: &Path) -> Result<(), RlError> {
        self.sac.save(dir)?;
        let save = |vs: &nn::VarStore, name: &str| {
            let path = dir.join(name);
            vs.save(&path).map_err(|e| RlError::io(&path, e))
        };
        save(&self.discriminator_vs, DISCRIMINATOR_FILE)?;
        save(self.discriminator_opt.state(), DISCRIMINATOR_ADAM_FILE)?;
        self.replay.save(&dir.join(REPLAY_FILE))?;
        let path = dir.join(PROGRESS_FILE);
        let text = serde_json::to_string(&self.progress).map_err(|e| RlError::io(&path, e))?;
        std::fs::write(&path, text).map_err(|e| RlError::io(&path, e))
    }
    fn load(&mut self, dir: &Path) -> Result<(), RlError> {
        self.sac.load(dir, false)?;
        let load = |vs: &mut nn::VarStore, name: &str| {
            let path = dir.join(name);
            seads_nn::load_var_store(vs, &path).map_err(|e| RlError::unreadable(&path, e))
        };
        load(&mut self.discriminator_vs, DISCRIMINATOR_FILE)?;
        load(self.discriminator_opt.state_mut(), DISCRIMINATOR_ADAM_FILE)?;
        self.replay.load(&dir.join(REPLAY_FILE))?;
        let path = dir.join(PROGRESS_FILE);
        let text = std::fs::read_to_string(&path).map_err(|e| RlError::io(&path, e))?;
        self.progress = serde_json::from_str(&text).map_err(|e| RlError::unreadable(&path, e))?;
        Ok(())
    }
    fn resume_only_files() -> Vec<&'static str> {
        crate::sac::RESUME_FILES
            .iter()
            .chain(&[DISCRIMINATOR_ADAM_FILE, REPLAY_FILE, PROGRESS_FILE])
            .copied()
            .collect()
    }
    fn load_task_policy(
        _: &TrainConfig,
        _: &EnvSpec,
        _: &Path,
    ) -> Result<Box<dyn crate::TaskPolicy>, RlError> {
        Err(RlError::config(
            "a DIAYN run has skills, not a task policy; fit a forward model to plan with them",
        ))
    }
}

impl InWords for Diayn {
    fn steps(&self) -> u64 {
        self.progress.env_steps
    }
    fn headline(&self, m: &Metrics) -> String {
        format!(
            "coverage {:>5.2}/{}  reward {:>6.2}  discriminator loss {:.3}",
            m.skill_coverage, self.k, m.mean_reward, m.skill_model_loss
        )
    }
    fn phases(&self) -> String {
        let t = self.progress.timings;
        format!(
            "collect {:.1} s, discriminator {:.1} s, SAC {:.1} s, evaluation {:.1} s",
            t.collect, t.skill_model, t.sac, t.evaluate
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A small LightsOutCursor run of DIAYN.
    fn small(steps: u64) -> TrainConfig {
        let mut config = TrainConfig::preset_for("lightsout-cursor", "diayn").unwrap();
        config.env_steps = steps;
        config.sac.hidden = vec![32, 32];
        config.sac.batch_size = 32;
        config.portable_numerics = true;
        config.sac_threads_alone = 0;
        config
            .edit(|d: &mut DiaynConfig| {
                d.discriminator_hidden = vec![32];
                (d.episodes_per_epoch, d.updates_per_epoch, d.eval_seeds) = (8, 4, 2);
            })
            .unwrap();
        config
    }

    /// DIAYN's reward by hand: with a discriminator that outputs logits (2, 0, 0) for every
    /// state, q = (e²/(e²+2), 1/(e²+2), 1/(e²+2)), so skill 0 earns log q(0) + log 3 and
    /// skill 1 log q(1) + log 3.
    #[test]
    fn the_reward_is_log_q_minus_log_p() {
        let mut diayn = Diayn::new(small(1000)).unwrap();
        assert_eq!(diayn.num_skills(), 25);
        let mut config = small(1000);
        config
            .edit(|d: &mut DiaynConfig| d.num_skills = Some(3))
            .unwrap();
        diayn = Diayn::new(config).unwrap();
        tch::no_grad(|| {
            let head = diayn.discriminator.head();
            let _ = head.ws.shallow_clone().zero_();
            let bias = head.bs.as_ref().unwrap();
            bias.shallow_clone()
                .copy_(&Tensor::from_slice(&[2.0f32, 0.0, 0.0]));
        });
        let obs = Tensor::zeros(
            [2, diayn.spec.obs_dim as i64],
            (Kind::Float, tch::Device::Cpu),
        );
        let rewards = diayn.rewards(&obs, &Tensor::from_slice(&[0i64, 1]));
        let (e2, log_3) = (2f64.exp(), 3f64.ln());
        let expected = [
            (e2 / (e2 + 2.0)).ln() + log_3,
            (1.0 / (e2 + 2.0)).ln() + log_3,
        ];
        assert_eq!(rewards.len(), 2);
        for (got, want) in rewards.iter().zip(expected) {
            assert!(
                (f64::from(*got) - want).abs() < 1e-6,
                "{got} against {want}"
            );
        }
    }

    /// A run resumed from a checkpoint is the run never stopped, to the bit.
    #[test]
    fn a_resumed_run_is_the_uninterrupted_run() {
        let mut whole = Diayn::new(small(2000)).unwrap();
        let mut first = Diayn::new(small(2000)).unwrap();
        for _ in 0..3 {
            whole.run_epoch().unwrap();
            first.run_epoch().unwrap();
        }
        let dir = tempfile::tempdir().unwrap();
        first.save(dir.path()).unwrap();
        let mut resumed = Diayn::new(small(2000)).unwrap();
        resumed.load(dir.path()).unwrap();
        for _ in 0..3 {
            let a = whole.run_epoch().unwrap();
            let b = resumed.run_epoch().unwrap();
            assert_eq!(a.mean_reward.to_bits(), b.mean_reward.to_bits());
            assert_eq!(a.critic_loss.to_bits(), b.critic_loss.to_bits());
        }
        assert_eq!(whole.progress.env_steps, resumed.progress.env_steps);
        let inputs = vec![0.5f32; whole.sac.input_dim()];
        assert_eq!(whole.sac.act(&inputs, None), resumed.sac.act(&inputs, None));
    }

    /// The discriminator learns to tell skills apart from states that differ by skill: on a
    /// replay where skill k's next state is the one-hot of k, its loss falls far below log K.
    #[test]
    fn the_discriminator_learns_to_tell_skills_apart() {
        let mut config = small(1000);
        config
            .edit(|d: &mut DiaynConfig| (d.num_skills, d.discriminator_lr) = (Some(4), 0.01))
            .unwrap();
        let mut diayn = Diayn::new(config).unwrap();
        let (o, width) = (diayn.spec.obs_dim, diayn.spec.obs_dim + 4);
        let mut rng = stream(7, Purpose::Sample);
        for _ in 0..256 {
            let k = rng.random_range(0..4usize);
            let mut state = vec![0.0f32; o];
            state[k] = 1.0;
            let mut row = vec![0.0; width];
            policy_input(&state, k, &mut row);
            let action = vec![0.0; diayn.spec.action_dim];
            diayn.replay.push(&row, &action, 0.0, &row, true);
        }
        let first = diayn.update(32).1;
        let mut last = first;
        for _ in 0..300 {
            last = diayn.update(32).1;
        }
        assert!((f64::from(first) - 4f64.ln()).abs() < 0.3, "{first}");
        assert!(last < 0.1, "the loss fell from {first} to {last} only");
    }
}
