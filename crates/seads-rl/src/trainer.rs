//! The SEADS training loop (SPEC §3.7, Algorithm 3): collect episodes with the skill policy,
//! relabel them with the skill model, update the skill model and SAC.

use std::collections::VecDeque;
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use rand::RngExt;
use rand_chacha::ChaCha8Rng;
use seads_embodiment::{EnvConfig, EnvSpec, Environment, make_env};
use seads_games::{Split, SymbolicState};
use seads_skillmodel::{SkillModel, SkillTransition, episode_rewards, minimum_reward, relabel};
use serde::{Deserialize, Serialize};
use tch::{Device, Kind, Tensor};

use crate::episode::{policy_input, run_episodes, skill_coverage};
use crate::seeds::{Purpose, derived_seed, stream, train_env_seed};
use crate::{Episode, Moment, RlError, Sac, SacLosses, TrainConfig, TransitionBatch};

/// First seed of the skill-coverage evaluation (the paper's 444555 … 444574).
pub const COVERAGE_SEED: u64 = 444_555;

/// Independent random streams of a run (one per purpose).
#[derive(Debug, Clone, Serialize, Deserialize)]
struct Streams {
    /// Skill labels of new episodes.
    labels: ChaCha8Rng,
    /// Policy noise while collecting.
    collect: ChaCha8Rng,
    /// Buffer sampling and relabelling choices.
    sample: ChaCha8Rng,
    /// SAC update noise.
    sac: ChaCha8Rng,
}

/// Seconds spent per phase since the start of the run (the epoch profile). Relabelling and the
/// skill-model steps run beside SAC (see [`Trainer::run_epoch`]), so the phases add up to more
/// than the wall time.
#[derive(Debug, Clone, Copy, Default, Serialize, Deserialize)]
pub struct Timings {
    /// Episode collection (environment steps and policy calls).
    pub collect: f64,
    /// Skill-model scores, rewards and assignments for both batches, and SAC minibatch assembly.
    pub relabel: f64,
    /// Skill-model gradient steps.
    pub skill_model: f64,
    /// SAC gradient steps.
    pub sac: f64,
    /// Skill-coverage evaluations.
    pub evaluate: f64,
}

/// What one epoch did.
#[derive(Debug, Clone, Default, Serialize)]
pub struct EpochStats {
    /// Epoch index (0-based) of the epoch just run.
    pub epoch: u64,
    /// Environment steps so far.
    pub env_steps: u64,
    /// Whether updates ran (they start once the buffer holds `sampled_episodes` episodes).
    pub updated: bool,
    /// Mean final reward of the SAC batch.
    pub mean_reward: f32,
    /// Fraction of the new episodes that changed the board.
    pub changed: f32,
    /// Mean skill-model loss of this epoch.
    pub skill_model_loss: f32,
    /// Mean SAC losses of this epoch.
    pub sac: SacLosses,
}

/// Progress counters saved with every checkpoint.
#[derive(Debug, Clone, Serialize, Deserialize)]
struct Progress {
    epoch: u64,
    env_steps: u64,
    timings: Timings,
    streams: Streams,
}

/// The checkpoint file of the prepared next updates (absent when there are none).
pub(crate) const PREPARED_FILE: &str = "prepared.safetensors";

/// A SEADS agent in training.
pub struct Trainer {
    config: TrainConfig,
    spec: EnvSpec,
    k: usize,
    envs: Vec<Box<dyn Environment>>,
    eval_env: Box<dyn Environment>,
    sac: Sac,
    model: Box<dyn SkillModel>,
    episodes: VecDeque<Episode>,
    progress: Progress,
    /// The next epoch's updates, prepared while SAC updated: the skill model has taken its
    /// steps, and the SAC minibatches wait here.
    prepared: Option<Prepared>,
}

/// An epoch's skill-model update done and its SAC minibatches relabelled, ready for SAC.
#[derive(Debug)]
struct Prepared {
    minibatches: Vec<TransitionBatch>,
    mean_reward: f32,
    skill_model_loss: f32,
}

impl Trainer {
    /// A fresh agent for `config` (validated).
    pub fn new(config: TrainConfig) -> Result<Self, RlError> {
        config.validate()?;
        let train_env = EnvConfig {
            reset_split: Split::Train,
            ..config.env_config.clone()
        };
        let template = make_env(&config.env, &train_env)?;
        // Coverage is measured on test boards drawn as in training (random depth up to the max).
        let eval_config = EnvConfig {
            reset_split: Split::Test,
            ..config.env_config.clone()
        };
        let eval_env = make_env(&config.env, &eval_config)?;
        Self::with_environments(config, template, eval_env)
    }

    /// A fresh agent training on `template` (cloned per episode slot) and measuring skill
    /// coverage on `eval_env`: for environments outside the registry, such as the robot.
    /// `config.env` and `config.env_config` are not used to build environments.
    pub fn with_environments(
        config: TrainConfig,
        template: Box<dyn Environment>,
        eval_env: Box<dyn Environment>,
    ) -> Result<Self, RlError> {
        config.validate_values()?;
        crate::numerics::check(config.portable_numerics)?;
        if config.threads > 0 {
            tch::set_num_threads(config.threads as i32);
        }
        let spec = template.spec().clone();
        let k = config.num_skills.unwrap_or(spec.num_skills);
        // Seeded before every epoch (`train_env_seed`).
        let envs = (0..config.episodes_per_epoch)
            .map(|_| template.box_clone())
            .collect();
        let device = Device::Cpu;
        let sac = Sac::new(
            spec.obs_dim + k,
            &spec.action_low,
            &spec.action_high,
            &config.sac,
            device,
            derived_seed(config.seed, Purpose::SacInit, 0),
        );
        let model = config.skill_model.build(
            spec.symbolic_len,
            k,
            device,
            derived_seed(config.seed, Purpose::SkillModelInit, 0),
        );
        let streams = Streams {
            labels: stream(config.seed, Purpose::Labels),
            collect: stream(config.seed, Purpose::Collect),
            sample: stream(config.seed, Purpose::Sample),
            sac: stream(config.seed, Purpose::Sac),
        };
        let progress = Progress {
            epoch: 0,
            env_steps: 0,
            timings: Timings::default(),
            streams,
        };
        Ok(Self {
            config,
            spec,
            k,
            envs,
            eval_env,
            sac,
            model,
            episodes: VecDeque::new(),
            progress,
            prepared: None,
        })
    }

    /// The configuration.
    pub fn config(&self) -> &TrainConfig {
        &self.config
    }

    /// The environment's dimensions.
    pub fn spec(&self) -> &EnvSpec {
        &self.spec
    }

    /// Number of skills K.
    pub fn num_skills(&self) -> usize {
        self.k
    }

    /// Epochs run so far.
    pub fn epoch(&self) -> u64 {
        self.progress.epoch
    }

    /// Environment steps so far.
    pub fn env_steps(&self) -> u64 {
        self.progress.env_steps
    }

    /// Time spent per phase.
    pub fn timings(&self) -> Timings {
        self.progress.timings
    }

    /// Whether the step budget is spent.
    pub fn finished(&self) -> bool {
        self.progress.env_steps >= self.config.env_steps
    }

    /// The skill policy.
    pub fn policy(&self) -> &Sac {
        &self.sac
    }

    /// The skill model.
    pub fn skill_model(&self) -> &dyn SkillModel {
        self.model.as_ref()
    }

    /// One epoch of Algorithm 3.
    ///
    /// The updates of epoch n use the buffers as they were before its new episodes arrive and
    /// need nothing from its collection, so they are prepared ahead: while SAC takes epoch n's
    /// steps on one thread, the calling thread appends epoch n's episodes, takes epoch n + 1's
    /// skill-model steps (on a batch relabelled with p = 1) and scores and relabels epoch n + 1's
    /// SAC batch (p = 0.5, only board-changing episodes) with the updated model. That is the
    /// same computation as Algorithm 3 done in order; only the two halves run side by side.
    /// Once the calling thread has finished preparing, SAC may take more libtorch threads
    /// (`TrainConfig::sac_threads_alone`).
    /// Episodes are collected first, with the parameters of the start of the epoch (the
    /// reference collects in the background while it updates).
    pub fn run_epoch(&mut self) -> Result<EpochStats, RlError> {
        self.run_epoch_observed(&mut |_| {})
    }

    /// [`Trainer::run_epoch`], calling `hook` once the episodes are collected and once the next
    /// epoch's updates are prepared (from the calling thread, while SAC may still update).
    pub fn run_epoch_observed(
        &mut self,
        hook: &mut dyn FnMut(Moment),
    ) -> Result<EpochStats, RlError> {
        let mut stats = EpochStats {
            epoch: self.progress.epoch,
            ..EpochStats::default()
        };

        let start = Instant::now();
        let skills: Vec<usize> = (0..self.envs.len())
            .map(|_| self.progress.streams.labels.random_range(0..self.k))
            .collect();
        let slots = self.envs.len();
        for (slot, env) in self.envs.iter_mut().enumerate() {
            env.seed(train_env_seed(
                self.config.seed,
                self.progress.epoch,
                slots,
                slot,
            ));
            env.reset()?;
        }
        let new = run_episodes(
            &mut self.envs,
            &skills,
            &self.sac,
            self.k,
            Some(&mut self.progress.streams.collect),
        )?;
        self.progress.timings.collect += start.elapsed().as_secs_f64();
        hook(Moment::Collected);
        stats.changed = new.iter().filter(|e| e.changed()).count() as f32 / new.len().max(1) as f32;
        let new_steps: u64 = new.iter().map(|e| e.len(self.spec.action_dim) as u64).sum();
        let finished = self.progress.env_steps + new_steps >= self.config.env_steps;

        let mut prepare = Prepare {
            buffers: Buffers {
                config: &self.config,
                k: self.k,
                episodes: &mut self.episodes,
                rng: &mut self.progress.streams.sample,
            },
            model: self.model.as_mut(),
            spec: &self.spec,
            timings: &mut self.progress.timings,
        };
        // The first epoch with a full buffer prepares its own updates (as does the first after
        // resuming from a checkpoint written before checkpoints kept them).
        let prepared = match self.prepared.take() {
            Some(prepared) => Some(prepared),
            None => prepare.buffers.ready().then(|| prepare.updates()),
        };
        if let Some(prepared) = prepared {
            stats.updated = true;
            stats.mean_reward = prepared.mean_reward;
            stats.skill_model_loss = prepared.skill_model_loss;
            let (sac, sac_rng) = (&mut self.sac, &mut self.progress.streams.sac);
            let threads = SacThreads {
                threads: self.config.threads,
                alone: self.config.sac_threads_alone,
                prepared: AtomicBool::new(false),
            };
            let ((losses, sac_s), next) = std::thread::scope(|scope| {
                let threads = &threads;
                let updates = scope.spawn(move || {
                    let start = Instant::now();
                    let losses = sac_updates(sac, &prepared.minibatches, sac_rng, threads);
                    (losses, start.elapsed().as_secs_f64())
                });
                prepare.buffers.push(new);
                // No next epoch once the budget is spent: the final skill model is epoch n's.
                let next = (!finished && prepare.buffers.ready()).then(|| prepare.updates());
                threads.prepared.store(true, Ordering::Release);
                hook(Moment::Prepared);
                (updates.join().expect("SAC thread"), next)
            });
            stats.sac = losses;
            self.prepared = next;
            self.progress.timings.sac += sac_s;
        } else {
            prepare.buffers.push(new);
        }
        self.progress.env_steps += new_steps;
        self.progress.epoch += 1;
        stats.env_steps = self.progress.env_steps;
        Ok(stats)
    }

    /// Skill coverage (SPEC §4.5): distinct game moves made by the K skills from identical
    /// test-split resets, averaged over the evaluation seeds.
    pub fn skill_coverage(&mut self) -> Result<f64, RlError> {
        let start = Instant::now();
        let seeds: Vec<u64> = (0..self.config.eval_seeds)
            .map(|i| COVERAGE_SEED + i)
            .collect();
        let per_seed = skill_coverage(self.eval_env.as_ref(), &self.sac, self.k, &seeds)?;
        self.progress.timings.evaluate += start.elapsed().as_secs_f64();
        Ok(per_seed.iter().sum::<usize>() as f64 / per_seed.len() as f64)
    }

    /// Writes the complete training state into `dir` (which must exist).
    pub fn save(&self, dir: &Path) -> Result<(), RlError> {
        self.save_agent(dir)?;
        self.sac.save(dir)?;
        self.model.save(dir)?;
        self.save_buffer(&dir.join("episodes.safetensors"))?;
        if let Some(prepared) = &self.prepared {
            prepared.save(&dir.join(PREPARED_FILE))?;
        }
        let path = dir.join("progress.json");
        std::fs::write(
            &path,
            serde_json::to_string(&self.progress).expect("progress serialises"),
        )
        .map_err(|e| RlError::io(&path, e))
    }

    /// Writes what is needed to execute and plan with the agent: the actor and the skill model.
    pub fn save_agent(&self, dir: &Path) -> Result<(), RlError> {
        self.sac.save_actor(dir)?;
        self.model.save(dir)?;
        Ok(())
    }

    /// Restores the complete training state written by [`Trainer::save`].
    pub fn load(&mut self, dir: &Path) -> Result<(), RlError> {
        self.sac.load(dir, false)?;
        self.model.load(dir, true)?;
        self.load_buffer(&dir.join("episodes.safetensors"))?;
        let path = dir.join(PREPARED_FILE);
        self.prepared = if path.exists() {
            let width = self.spec.obs_dim + self.k;
            Some(Prepared::load(&path, width, self.spec.action_dim)?)
        } else {
            None
        };
        let path = dir.join("progress.json");
        let text = std::fs::read_to_string(&path).map_err(|e| RlError::io(&path, e))?;
        self.progress = serde_json::from_str(&text).map_err(|e| RlError::unreadable(&path, e))?;
        Ok(())
    }

    fn save_buffer(&self, path: &Path) -> Result<(), RlError> {
        let a = self.spec.action_dim;
        let obs: Vec<f32> = self
            .episodes
            .iter()
            .flat_map(|e| e.obs.iter().copied())
            .collect();
        let actions: Vec<f32> = self
            .episodes
            .iter()
            .flat_map(|e| e.actions.iter().copied())
            .collect();
        let meta: Vec<i64> = self
            .episodes
            .iter()
            .flat_map(|e| {
                let (z0, zt) = (e.z0.words(), e.zt.words());
                [
                    e.len(a) as i64,
                    e.skill as i64,
                    e.game_move.map_or(-1, |m| m as i64),
                ]
                .into_iter()
                .chain(z0.into_iter().chain(zt).map(|w| w as i64))
            })
            .collect();
        let tensors = [
            ("obs", Tensor::from_slice(&obs)),
            ("actions", Tensor::from_slice(&actions)),
            ("meta", Tensor::from_slice(&meta).view([-1, 9])),
        ];
        Tensor::write_safetensors(&tensors, path).map_err(|e| RlError::io(path, e))
    }

    fn load_buffer(&mut self, path: &Path) -> Result<(), RlError> {
        let file = TensorFile::read(path)?;
        let corrupt = |reason: String| file.corrupt(reason);
        let (obs, actions) = (file.floats("obs")?, file.floats("actions")?);
        let meta = file.ints("meta")?;
        let (o, a) = (self.spec.obs_dim, self.spec.action_dim);
        let (mut po, mut pa) = (0, 0);
        self.episodes.clear();
        let mismatch = || corrupt("episode table does not match the environment".into());
        for m in meta.chunks(9) {
            // The length is checked against the data before it is used: no negative or
            // overflowing lengths.
            if m.len() != 9
                || !(0..=obs.len() as i64).contains(&m[0])
                || m[1] < 0
                || m[1] as usize >= self.k
            {
                return Err(mismatch());
            }
            let len = m[0] as usize;
            let (obs_end, act_end) = (po + (len + 1) * o, pa + len * a);
            if obs_end > obs.len() || act_end > actions.len() {
                return Err(mismatch());
            }
            let word = |i: usize| m[i] as u64;
            self.episodes.push_back(Episode {
                skill: m[1] as usize,
                obs: obs[po..obs_end].to_vec(),
                actions: actions[pa..act_end].to_vec(),
                z0: SymbolicState::from_words([word(3), word(4), word(5)]),
                zt: SymbolicState::from_words([word(6), word(7), word(8)]),
                game_move: (m[2] >= 0).then_some(m[2] as usize),
            });
            (po, pa) = (obs_end, act_end);
        }
        if po != obs.len() || pa != actions.len() {
            return Err(corrupt("trailing episode data".into()));
        }
        Ok(())
    }
}

/// The tensors of a checkpoint file, by name; every error names the file.
struct TensorFile<'a> {
    path: &'a Path,
    tensors: Vec<(String, Tensor)>,
}

impl<'a> TensorFile<'a> {
    fn read(path: &'a Path) -> Result<Self, RlError> {
        let tensors = Tensor::read_safetensors(path).map_err(|e| RlError::unreadable(path, e))?;
        Ok(Self { path, tensors })
    }

    fn corrupt(&self, reason: String) -> RlError {
        RlError::Checkpoint {
            path: self.path.display().to_string(),
            reason,
        }
    }

    fn get(&self, name: &str) -> Result<&Tensor, RlError> {
        self.tensors
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, t)| t)
            .ok_or_else(|| self.corrupt(format!("no tensor {name:?}")))
    }

    /// The named tensor's values as f32, flattened.
    fn floats(&self, name: &str) -> Result<Vec<f32>, RlError> {
        Vec::<f32>::try_from(self.get(name)?.to_kind(Kind::Float).view([-1]))
            .map_err(|e| self.corrupt(e.to_string()))
    }

    /// The named tensor's values as i64, flattened.
    fn ints(&self, name: &str) -> Result<Vec<i64>, RlError> {
        Vec::<i64>::try_from(self.get(name)?.to_kind(Kind::Int64).view([-1]))
            .map_err(|e| self.corrupt(e.to_string()))
    }
}

impl Prepared {
    /// Writes the minibatches (stacked) and the two statistics.
    fn save(&self, path: &Path) -> Result<(), RlError> {
        let stack = |part: fn(&TransitionBatch) -> &[f32]| {
            Tensor::from_slice(
                &self
                    .minibatches
                    .iter()
                    .flat_map(|b| part(b).iter().copied())
                    .collect::<Vec<f32>>(),
            )
        };
        let rows: Vec<i64> = self
            .minibatches
            .iter()
            .map(|b| b.rewards.len() as i64)
            .collect();
        let tensors = [
            ("obs", stack(|b| &b.obs)),
            ("actions", stack(|b| &b.actions)),
            ("rewards", stack(|b| &b.rewards)),
            ("next_obs", stack(|b| &b.next_obs)),
            ("dones", stack(|b| &b.dones)),
            ("rows", Tensor::from_slice(&rows)),
            (
                "stats",
                Tensor::from_slice(&[self.mean_reward, self.skill_model_loss]),
            ),
        ];
        Tensor::write_safetensors(&tensors, path).map_err(|e| RlError::io(path, e))
    }

    /// Reads what [`Prepared::save`] wrote, for policy inputs of `width` and actions of
    /// `action_dim` values.
    fn load(path: &Path, width: usize, action_dim: usize) -> Result<Self, RlError> {
        let file = TensorFile::read(path)?;
        let rows: Vec<usize> = file
            .ints("rows")?
            .into_iter()
            .map(usize::try_from)
            .collect::<Result<_, _>>()
            .map_err(|_| file.corrupt("negative minibatch size".into()))?;
        let total = rows
            .iter()
            .try_fold(0usize, |sum, &n| sum.checked_add(n))
            .ok_or_else(|| file.corrupt("minibatch sizes overflow".into()))?;
        let floats = |name| file.floats(name);
        let (obs, actions, rewards) = (floats("obs")?, floats("actions")?, floats("rewards")?);
        let (next_obs, dones, stats) = (floats("next_obs")?, floats("dones")?, floats("stats")?);
        // Rewards first: their length bounds `total`, so the products below cannot overflow.
        if rewards.len() != total
            || dones.len() != total
            || obs.len() != total * width
            || next_obs.len() != total * width
            || actions.len() != total * action_dim
            || stats.len() != 2
        {
            return Err(file.corrupt("prepared minibatches do not match the environment".into()));
        }
        let mut minibatches = Vec::with_capacity(rows.len());
        let mut first = 0;
        for n in rows {
            let part =
                |values: &[f32], cols: usize| values[first * cols..(first + n) * cols].to_vec();
            minibatches.push(TransitionBatch {
                obs: part(&obs, width),
                actions: part(&actions, action_dim),
                rewards: part(&rewards, 1),
                next_obs: part(&next_obs, width),
                dones: part(&dones, 1),
            });
            first += n;
        }
        Ok(Self {
            minibatches,
            mean_reward: stats[0],
            skill_model_loss: stats[1],
        })
    }
}

/// How many libtorch threads the SAC thread of an epoch uses.
struct SacThreads {
    /// While the calling thread prepares (`TrainConfig::threads`; 0: libtorch's default).
    threads: usize,
    /// Once it has finished (`TrainConfig::sac_threads_alone`; 0: no change).
    alone: usize,
    /// Set by the calling thread once it has finished preparing the next epoch's updates.
    prepared: AtomicBool,
}

/// SAC steps on the given minibatches; returns their mean losses. The thread count changes only
/// how fast they run: libtorch's results are the same with one or two threads (checked by a
/// test), so the moment SAC takes more threads does not change the run.
fn sac_updates(
    sac: &mut Sac,
    minibatches: &[TransitionBatch],
    rng: &mut ChaCha8Rng,
    threads: &SacThreads,
) -> SacLosses {
    // libtorch's thread count is per thread, and a fresh thread starts with the value any thread
    // set last: set it.
    if threads.threads > 0 {
        tch::set_num_threads(threads.threads as i32);
    }
    let mut alone = threads.alone == 0;
    let mut total = SacLosses::default();
    for minibatch in minibatches {
        if !alone && threads.prepared.load(Ordering::Acquire) {
            tch::set_num_threads(threads.alone as i32);
            alone = true;
        }
        let l = sac.update(minibatch, rng);
        total.critic += l.critic;
        total.actor += l.actor;
        total.q += l.q;
    }
    let n = minibatches.len().max(1) as f32;
    SacLosses {
        critic: total.critic / n,
        actor: total.actor / n,
        q: total.q / n,
    }
}

/// What preparing an epoch's updates works on: everything but SAC, which updates meanwhile.
struct Prepare<'a> {
    buffers: Buffers<'a>,
    model: &'a mut dyn SkillModel,
    spec: &'a EnvSpec,
    timings: &'a mut Timings,
}

impl Prepare<'_> {
    /// Steps 3a and 3b of an epoch up to SAC: the skill-model update on a batch relabelled with
    /// p = 1, then an independent batch scored and relabelled with the updated model and cut
    /// into SAC minibatches.
    fn updates(&mut self) -> Prepared {
        let start = Instant::now();
        let tuples = self.buffers.skill_model_batch(&*self.model);
        self.timings.relabel += start.elapsed().as_secs_f64();

        let start = Instant::now();
        let config = &self.buffers.config.skill_model;
        let mut loss = 0.0;
        for _ in 0..config.updates_per_epoch {
            let minibatch: Vec<SkillTransition> = (0..config.batch_size)
                .map(|_| tuples[self.buffers.rng.random_range(0..tuples.len())])
                .collect();
            loss += self.model.train_step(&minibatch);
        }
        self.timings.skill_model += start.elapsed().as_secs_f64();

        let start = Instant::now();
        let (minibatches, mean_reward) = self.buffers.sac_minibatches(&*self.model, self.spec);
        self.timings.relabel += start.elapsed().as_secs_f64();
        Prepared {
            minibatches,
            mean_reward,
            skill_model_loss: loss / config.updates_per_epoch.max(1) as f32,
        }
    }
}

/// The episode buffers with what an update needs to draw from them: the long-term buffer is the
/// last `buffer_capacity` episodes, the short-term list its last `recent_episodes`.
struct Buffers<'a> {
    config: &'a TrainConfig,
    k: usize,
    episodes: &'a mut VecDeque<Episode>,
    rng: &'a mut ChaCha8Rng,
}

impl Buffers<'_> {
    /// Updates start once the buffer holds `sampled_episodes` episodes.
    fn ready(&self) -> bool {
        self.episodes.len() >= self.config.sampled_episodes
    }

    /// Appends new episodes, dropping the oldest beyond the capacity.
    fn push(&mut self, new: Vec<Episode>) {
        for episode in new {
            if self.episodes.len() == self.config.buffer_capacity {
                self.episodes.pop_front();
            }
            self.episodes.push_back(episode);
        }
    }

    /// Indices of an update batch: `sampled_episodes` drawn with replacement from the long-term
    /// buffer (all of it if it holds exactly that many), followed by the recent episodes.
    fn update_batch(&mut self) -> Vec<usize> {
        let n = self.episodes.len();
        let mut batch: Vec<usize> = if n == self.config.sampled_episodes {
            (0..n).collect()
        } else {
            (0..self.config.sampled_episodes)
                .map(|_| self.rng.random_range(0..n))
                .collect()
        };
        batch.extend(n.saturating_sub(self.config.recent_episodes)..n);
        batch
    }

    /// Clipped posteriors C and rewards R (K per episode, row-major) of the given episodes.
    fn score(&self, model: &dyn SkillModel, batch: &[usize]) -> (Vec<f32>, Vec<f32>) {
        let pairs: Vec<(SymbolicState, SymbolicState)> = batch
            .iter()
            .map(|&i| (self.episodes[i].z0, self.episodes[i].zt))
            .collect();
        let scores = model.scores(&pairs);
        let likelihoods = model.scores_are_likelihoods();
        let mut clipped = Vec::with_capacity(scores.len());
        let mut rewards = Vec::with_capacity(scores.len());
        for row in scores.chunks(self.k) {
            let (c, r) = episode_rewards(row, likelihoods, &self.config.reward);
            clipped.extend(c);
            rewards.extend(r);
        }
        (clipped, rewards)
    }

    /// Final labels: each episode of `batch` is chosen with probability `p` (among `eligible`),
    /// and the chosen ones are relabelled together. `clipped` holds the K clipped posteriors of
    /// each eligible episode, in `eligible` order.
    fn relabelled(
        &mut self,
        batch: &[usize],
        eligible: &[usize],
        clipped: &[f32],
        p: f64,
    ) -> Vec<usize> {
        let mut labels: Vec<usize> = batch.iter().map(|&i| self.episodes[i].skill).collect();
        if p <= 0.0 {
            return labels;
        }
        let k = self.k;
        let chosen: Vec<usize> = (0..eligible.len())
            .filter(|_| self.rng.random::<f64>() < p)
            .collect();
        let chosen_clipped: Vec<f32> = chosen
            .iter()
            .flat_map(|&e| clipped[e * k..(e + 1) * k].iter().copied())
            .collect();
        let chosen_labels: Vec<usize> = chosen.iter().map(|&e| labels[eligible[e]]).collect();
        for (&e, new) in chosen.iter().zip(relabel(
            self.config.relabel.kind,
            &chosen_clipped,
            k,
            &chosen_labels,
        )) {
            labels[eligible[e]] = new;
        }
        labels
    }

    /// The skill-model batch: every episode of an update batch relabelled with p = 1 (episodes
    /// that did not change the board take part), as (z_0, label, z_T) tuples.
    fn skill_model_batch(&mut self, model: &dyn SkillModel) -> Vec<SkillTransition> {
        let batch = self.update_batch();
        let eligible: Vec<usize> = (0..batch.len()).collect();
        let (clipped, _) = if self.config.relabel.skill_model_p > 0.0 {
            self.score(model, &batch)
        } else {
            Default::default()
        };
        let labels = self.relabelled(
            &batch,
            &eligible,
            &clipped,
            self.config.relabel.skill_model_p,
        );
        batch
            .iter()
            .zip(labels)
            .map(|(&i, skill)| SkillTransition {
                z0: self.episodes[i].z0,
                skill,
                zt: self.episodes[i].zt,
            })
            .collect()
    }

    /// The SAC minibatches of an epoch: an update batch relabelled with p = 0.5 among the
    /// board-changing episodes; each episode's last transition carries R of its final label (or
    /// the minimum reward if the board did not change). Returns the minibatches and the mean
    /// final reward.
    fn sac_minibatches(
        &mut self,
        model: &dyn SkillModel,
        spec: &EnvSpec,
    ) -> (Vec<TransitionBatch>, f32) {
        let config = self.config;
        let batch = self.update_batch();
        // Only board-changing episodes need scores: the others get the minimum reward and are
        // never relabelled.
        let eligible: Vec<usize> = (0..batch.len())
            .filter(|&j| self.episodes[batch[j]].changed())
            .collect();
        let changed: Vec<usize> = eligible.iter().map(|&j| batch[j]).collect();
        let (clipped, rewards) = self.score(model, &changed);
        let labels = self.relabelled(&batch, &eligible, &clipped, config.relabel.sac_p);
        let mut finals = vec![minimum_reward(self.k); batch.len()];
        for (e, &j) in eligible.iter().enumerate() {
            finals[j] = rewards[e * self.k + labels[j]];
        }
        let a = spec.action_dim;
        let transitions: Vec<(usize, usize)> = batch
            .iter()
            .enumerate()
            .flat_map(|(j, &i)| (0..self.episodes[i].len(a)).map(move |t| (j, t)))
            .collect();
        let minibatches = (0..config.sac.updates_per_epoch)
            .map(|_| {
                let picks: Vec<(usize, usize)> = (0..config.sac.batch_size)
                    .map(|_| transitions[self.rng.random_range(0..transitions.len())])
                    .collect();
                self.transition_batch(spec, &batch, &labels, &finals, &picks)
            })
            .collect();
        let mean_reward = finals.iter().sum::<f32>() / finals.len().max(1) as f32;
        (minibatches, mean_reward)
    }

    /// SAC inputs for the picked transitions: `[s, onehot(final label)]`, the reward only on an
    /// episode's last transition, done = 1 there (moves and time-outs alike).
    fn transition_batch(
        &self,
        spec: &EnvSpec,
        batch: &[usize],
        labels: &[usize],
        finals: &[f32],
        picks: &[(usize, usize)],
    ) -> TransitionBatch {
        let (o, a) = (spec.obs_dim, spec.action_dim);
        let width = o + self.k;
        let mut out = TransitionBatch {
            obs: vec![0.0; picks.len() * width],
            actions: Vec::with_capacity(picks.len() * a),
            rewards: Vec::with_capacity(picks.len()),
            next_obs: vec![0.0; picks.len() * width],
            dones: Vec::with_capacity(picks.len()),
        };
        for (row, &(j, t)) in picks.iter().enumerate() {
            let e = &self.episodes[batch[j]];
            let last = t + 1 == e.len(a);
            policy_input(
                &e.obs[t * o..(t + 1) * o],
                labels[j],
                &mut out.obs[row * width..(row + 1) * width],
            );
            policy_input(
                &e.obs[(t + 1) * o..(t + 2) * o],
                labels[j],
                &mut out.next_obs[row * width..(row + 1) * width],
            );
            out.actions
                .extend_from_slice(&e.actions[t * a..(t + 1) * a]);
            out.rewards.push(if last { finals[j] } else { 0.0 });
            out.dones.push(if last { 1.0 } else { 0.0 });
        }
        out
    }
}
