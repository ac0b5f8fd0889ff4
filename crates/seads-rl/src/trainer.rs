//! The SEADS training loop (SPEC §3.7, Algorithm 3): collect episodes with the skill policy,
//! relabel them with the skill model, update the skill model and SAC.

use seads_nn::Resolve as _;
use std::collections::VecDeque;
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use rand::RngExt;
use rand_chacha::ChaCha8Rng;
use seads_embodiment::{EnvConfig, EnvSpec, Environment, make_env};
use seads_games::Split;
use seads_skillmodel::{SkillModel, SkillTransition};
use serde::{Deserialize, Serialize};

use crate::Timings;
use crate::buffers::{Buffers, RelabelObserver};
use crate::checkpoint::{self, Prepared};
use crate::episode::{run_episodes, skill_coverage};
use crate::seeds::{Purpose, derived_seed, stream, train_env_seed};
use crate::stacked::SacWork;
use crate::{Episode, Moment, RlError, Sac, SacLosses, SeadsConfig, TrainConfig, TransitionBatch};
use seads_skillmodel::BuildSkillModel as _;

pub use seads_run::COVERAGE_SEED;

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

/// A SEADS agent in training.
pub struct Trainer {
    config: TrainConfig,
    /// The configuration's SEADS section.
    seads: SeadsConfig,
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
    /// Sees each joint relabelling (diagnostics only; not part of a checkpoint).
    relabel_observer: Option<Box<RelabelObserver>>,
    /// The last [`Trainer::load`] found no carried state for environments that carry one.
    carried_missing: bool,
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
        let seads = config.seads()?;
        crate::numerics::check(config.portable_numerics)?;
        if config.threads > 0 {
            tch::set_num_threads(config.threads as i32);
        }
        let spec = template.spec().clone();
        let k = seads.num_skills.unwrap_or(spec.num_skills);
        // Seeded before every epoch (`train_env_seed`).
        let envs = (0..seads.episodes_per_epoch)
            .map(|_| template.box_clone())
            .collect();
        let device = config.device.resolve()?;
        let sac = Sac::new(
            spec.obs_dim + k,
            &spec.action_low,
            &spec.action_high,
            &config.sac,
            device,
            derived_seed(config.seed, Purpose::SacInit, 0),
        );
        let model = seads.skill_model.build(
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
            seads,
            spec,
            k,
            envs,
            eval_env,
            sac,
            model,
            episodes: VecDeque::new(),
            progress,
            prepared: None,
            relabel_observer: None,
            carried_missing: false,
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

    /// Calls `observer` with every joint relabelling that training solves from now on (the
    /// cost matrix, the labels in and out), for diagnostics such as the label-tie study
    /// (`examples/relabel_dump.rs`). Observing changes nothing in the run.
    pub fn observe_relabelling(&mut self, observer: Box<RelabelObserver>) {
        self.relabel_observer = Some(observer);
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
        let mut epoch = self.collect(hook)?;
        let Some(updates) = epoch.take_updates() else {
            self.prepare_after(&mut epoch, hook);
            return Ok(self.conclude(epoch, None));
        };
        let threads = SacThreads {
            threads: self.config.threads,
            alone: self.config.sac_threads_alone,
            prepared: AtomicBool::new(false),
        };
        let (sac, sac_rng, mut prepare) = self.split();
        let (sac, next) = std::thread::scope(|scope| {
            let threads = &threads;
            let updates = scope.spawn(move || {
                let start = Instant::now();
                let losses = sac_updates(sac, &updates.minibatches, sac_rng, threads);
                (losses, start.elapsed().as_secs_f64())
            });
            let next = prepare.after(&mut epoch);
            threads.prepared.store(true, Ordering::Release);
            hook(Moment::Prepared);
            (updates.join().expect("SAC thread"), next)
        });
        self.prepared = next;
        Ok(self.conclude(epoch, Some(sac)))
    }

    /// The first part of an epoch: its episodes collected with the current policy, and its
    /// updates (those prepared by the previous epoch, or prepared now by the first epoch with a
    /// full buffer). Calls `hook` with [`Moment::Collected`].
    pub(crate) fn collect(&mut self, hook: &mut dyn FnMut(Moment)) -> Result<Collected, RlError> {
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
        // The first epoch with a full buffer prepares its own updates (as does the first after
        // resuming from a checkpoint written before checkpoints kept them).
        let updates = match self.prepared.take() {
            Some(prepared) => Some(prepared),
            None => {
                let (_, _, mut prepare) = self.split();
                prepare.buffers.ready().then(|| prepare.updates())
            }
        };
        Ok(Collected {
            stats,
            new,
            new_steps,
            finished,
            updates,
        })
    }

    /// The agent and its noise stream, and what preparing the next epoch's updates works on
    /// meanwhile: everything else.
    fn split(&mut self) -> (&mut Sac, &mut ChaCha8Rng, Prepare<'_>) {
        let prepare = Prepare {
            buffers: Buffers {
                config: &self.config,
                seads: &self.seads,
                k: self.k,
                episodes: &mut self.episodes,
                rng: &mut self.progress.streams.sample,
                observer: self.relabel_observer.as_deref_mut(),
            },
            model: self.model.as_mut(),
            spec: &self.spec,
            timings: &mut self.progress.timings,
        };
        (&mut self.sac, &mut self.progress.streams.sac, prepare)
    }

    /// The part of an epoch that may run beside its SAC steps: its episodes join the buffers and
    /// the next epoch's updates are prepared. Calls `hook` with [`Moment::Prepared`].
    pub(crate) fn prepare_after(&mut self, epoch: &mut Collected, hook: &mut dyn FnMut(Moment)) {
        let next = self.split().2.after(epoch);
        if epoch.stats.updated {
            hook(Moment::Prepared);
        }
        self.prepared = next;
    }

    /// The SAC work of an epoch's updates, with the noise [`Sac::update`] would draw from the
    /// run's SAC stream: for a stacked update ([`crate::stacked::StackedSac`]).
    pub(crate) fn sac_work(&mut self, updates: Prepared) -> SacWork {
        let noise = self
            .sac
            .draw_noise(&updates.minibatches, &mut self.progress.streams.sac);
        SacWork {
            minibatches: updates.minibatches,
            noise,
        }
    }

    /// The agent, for a stacked update to write back into.
    pub(crate) fn sac_mut(&mut self) -> &mut Sac {
        &mut self.sac
    }

    /// The end of an epoch whose SAC steps gave `sac` (mean losses, seconds), if it updated.
    pub(crate) fn conclude(
        &mut self,
        epoch: Collected,
        sac: Option<(SacLosses, f64)>,
    ) -> EpochStats {
        let mut stats = epoch.stats;
        if let Some((losses, seconds)) = sac {
            stats.sac = losses;
            self.progress.timings.sac += seconds;
        }
        self.progress.env_steps += epoch.new_steps;
        self.progress.epoch += 1;
        stats.env_steps = self.progress.env_steps;
        stats
    }

    /// Skill coverage (SPEC §4.5): distinct game moves made by the K skills from identical
    /// test-split resets, averaged over the evaluation seeds.
    pub fn skill_coverage(&mut self) -> Result<f64, RlError> {
        let start = Instant::now();
        let seeds: Vec<u64> = (0..self.seads.eval_seeds)
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
        checkpoint::save_episodes(
            &dir.join(checkpoint::EPISODES_FILE),
            &self.episodes,
            self.spec.action_dim,
        )?;
        if let Some(prepared) = &self.prepared {
            prepared.save(&dir.join(checkpoint::PREPARED_FILE))?;
        }
        let path = dir.join(checkpoint::PROGRESS_FILE);
        let text = serde_json::to_string(&self.progress).map_err(|e| RlError::io(&path, e))?;
        std::fs::write(&path, text).map_err(|e| RlError::io(&path, e))?;
        self.save_carried(dir)
    }

    /// Every environment, the training slots then the coverage environment.
    fn all_envs(&mut self) -> impl Iterator<Item = &mut Box<dyn Environment>> {
        self.envs
            .iter_mut()
            .chain(std::iter::once(&mut self.eval_env))
    }

    /// What each environment carries between episodes, in [`Trainer::all_envs`]'s order.
    fn carried_states(&self) -> Vec<Option<String>> {
        self.envs
            .iter()
            .chain(std::iter::once(&self.eval_env))
            .map(|env| env.carried_state())
            .collect()
    }

    /// Writes [`checkpoint::ENVIRONMENT_FILE`] if any environment carries state between
    /// episodes (the robot); simulations write nothing.
    fn save_carried(&self, dir: &Path) -> Result<(), RlError> {
        let states = self.carried_states();
        if states.iter().all(Option::is_none) {
            return Ok(());
        }
        let path = dir.join(checkpoint::ENVIRONMENT_FILE);
        let text = serde_json::to_string(&states).map_err(|e| RlError::io(&path, e))?;
        std::fs::write(&path, text).map_err(|e| RlError::io(&path, e))
    }

    /// Restores what [`Trainer::save_carried`] wrote. A checkpoint without the file (from
    /// before it, or of environments that carry nothing) leaves the environments as they are;
    /// one whose origin says it was written with the file is damaged (passed over on resume).
    fn load_carried(&mut self, dir: &Path) -> Result<(), RlError> {
        let path = dir.join(checkpoint::ENVIRONMENT_FILE);
        self.carried_missing = false;
        let text = match std::fs::read_to_string(&path) {
            Ok(text) => text,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
                if crate::store::keeps_carried_state(dir) {
                    return Err(RlError::from(seads_run::RunError::Checkpoint {
                        path: dir.display().to_string(),
                        reason: format!(
                            "{} is missing, though the checkpoint was written with the state its \
                             environments carry (origin.json)",
                            checkpoint::ENVIRONMENT_FILE
                        ),
                    }));
                }
                self.carried_missing = self.carried_states().iter().any(Option::is_some);
                return Ok(());
            }
            Err(e) => return Err(RlError::io(&path, e)),
        };
        let states: Vec<Option<String>> =
            serde_json::from_str(&text).map_err(|e| RlError::unreadable(&path, e))?;
        let count = self.envs.len() + 1;
        if states.len() != count {
            return Err(RlError::from(seads_run::RunError::Checkpoint {
                path: path.display().to_string(),
                reason: format!(
                    "it holds {} environment states where the run has {count} environments",
                    states.len()
                ),
            }));
        }
        for (env, state) in self.all_envs().zip(states) {
            if let Some(state) = state {
                env.restore_carried_state(&state)?;
            }
        }
        Ok(())
    }

    /// Whether the last [`Trainer::load`] found no state for environments that carry one from
    /// episode to episode (a robot run's checkpoint from before checkpoints kept the twin's):
    /// training goes on in the world as it is now, so the run parts from the one never stopped.
    pub fn resumed_without_carried_state(&self) -> bool {
        self.carried_missing
    }

    /// Writes what is needed to execute and plan with the agent: the actor and the skill model.
    pub fn save_agent(&self, dir: &Path) -> Result<(), RlError> {
        self.sac.save_actor(dir)?;
        self.model.save(dir)?;
        Ok(())
    }

    /// Restores the complete training state written by [`Trainer::save`]; every file must be
    /// there (a fresh optimiser or buffer would change the run).
    pub fn load(&mut self, dir: &Path) -> Result<(), RlError> {
        self.sac.load(dir, false)?;
        self.model.load(dir, true)?;
        self.episodes = checkpoint::load_episodes(
            &dir.join(checkpoint::EPISODES_FILE),
            self.spec.obs_dim,
            self.spec.action_dim,
            self.k,
        )?;
        let path = dir.join(checkpoint::PREPARED_FILE);
        self.prepared = if path.exists() {
            let width = self.spec.obs_dim + self.k;
            Some(Prepared::load(&path, width, self.spec.action_dim)?)
        } else {
            None
        };
        let path = dir.join(checkpoint::PROGRESS_FILE);
        let text = std::fs::read_to_string(&path).map_err(|e| RlError::io(&path, e))?;
        self.progress = serde_json::from_str(&text).map_err(|e| RlError::unreadable(&path, e))?;
        self.load_carried(dir)
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

/// SAC steps on the given minibatches; returns their mean losses. At the presets' sizes the thread
/// count changes only how fast they run: libtorch's results are the same with one or two threads
/// (`sac_updates_do_not_depend_on_the_thread_count`), so the moment SAC takes more threads does
/// not change the run. With portable kernels and narrow networks it may: MKL then splits a narrow
/// layer's products over its inputs, and the columns at the seam round differently
/// (`examples/thread_count_bits.rs`), so such a configuration repeats exactly only with
/// `sac_threads_alone = 0`.
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

/// An epoch between its collection and its updates ([`Trainer::collect`]).
pub(crate) struct Collected {
    stats: EpochStats,
    /// The new episodes, until they join the buffers.
    new: Vec<Episode>,
    new_steps: u64,
    /// Whether the budget is spent with this epoch.
    finished: bool,
    updates: Option<Prepared>,
}

impl Collected {
    /// The epoch's updates, if it has any, recorded in its statistics.
    pub(crate) fn take_updates(&mut self) -> Option<Prepared> {
        let updates = self.updates.take()?;
        self.stats.updated = true;
        self.stats.mean_reward = updates.mean_reward;
        self.stats.skill_model_loss = updates.skill_model_loss;
        Some(updates)
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
    /// The epoch's new episodes join the buffers; then the next epoch's updates, unless the
    /// budget is spent (the final skill model is this epoch's) or the buffer is not yet full.
    fn after(&mut self, epoch: &mut Collected) -> Option<Prepared> {
        self.buffers.push(std::mem::take(&mut epoch.new));
        (epoch.stats.updated && !epoch.finished && self.buffers.ready()).then(|| self.updates())
    }

    /// Steps 3a and 3b of an epoch up to SAC: the skill-model update on a batch relabelled with
    /// p = 1, then an independent batch scored and relabelled with the updated model and cut
    /// into SAC minibatches.
    fn updates(&mut self) -> Prepared {
        let start = Instant::now();
        let tuples = self.buffers.skill_model_batch(&*self.model);
        self.timings.relabel += start.elapsed().as_secs_f64();

        let start = Instant::now();
        let config = &self.buffers.seads.skill_model;
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
