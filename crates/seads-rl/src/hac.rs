//! The two-level HAC baseline with the task reward (SPEC §5.2), after Levy et al.'s
//! Hierarchical Actor-Critic.
//!
//! - The **high level** is a discrete SAC ([`Sac::relaxed_bernoulli`]) on the environment's
//!   observation and a goal board, as Levy's top level is conditioned on the task's goal. Its
//!   action is a subgoal z ∈ {0,1}^D, a symbolic state: the relaxed sample thresholded at 0.5 (in
//!   training), the mode (in evaluation). Its reward is the task reward: 1 when the board reaches
//!   the goal (the game's goal board; in hindsight, a board the episode reached), which ends the
//!   return.
//! - The **low level** is a Gaussian SAC on the observation and the subgoal. It pursues a subgoal
//!   for at most H steps and is rewarded 1 (and its return ends) on the step whose board is z.
//!
//! What the seed leaves open (SPEC §9.7) follows Levy's HAC; the reasons are below:
//! - *hindsight action transitions*: the high level stores each subgoal attempt with the board
//!   actually reached as its action, so every attempt teaches it a reachable subgoal;
//! - *hindsight goal transitions*: the low level also stores every attempt that missed its
//!   subgoal as if the board it ended on had been the subgoal; at the end of an episode the high
//!   level stores its attempts again toward boards the episode reached (the last attempt's and
//!   up to two more, Levy's three), so it learns which subgoals lead where long before it solves
//!   a board;
//! - *subgoal testing*: a share λ of subgoals is pursued without exploration noise, and a tested
//!   subgoal that is missed gives the high level a terminal transition of reward −1 for it: worse
//!   than any return of the task (0 to 1), as Levy's penalty −H is at least as bad as any return
//!   of his −1-per-step rewards;
//!
//! # Choices where the seed is silent, and why
//!
//! - Subgoal horizon H = the environment's steps per skill T_max (10 Cursor, 50 Reacher/Jaco): a
//!   subgoal is one board change away at best, and T_max is what a skill gets for one move. The
//!   low level's attempt ends when the board equals the subgoal (checked after every step, so a
//!   subgoal equal to the current board is reached by one step that changes nothing), after H
//!   steps, or when the episode ends.
//! - Low-level reward: 1 on the step whose board is the subgoal, which also ends its return (the
//!   0/1 form of Levy's −1/0; it matches the task reward's scale). Running out of H steps does
//!   not end the return.
//! - Hindsight goal transitions of the low level use the "final" strategy: the board an attempt
//!   ended on is always reached at least at the last step, so every attempt yields a reward.
//! - Subgoal testing with probability λ = 0.3 (Levy's value). With the 0/1 task reward every
//!   return lies in [0, 1], so −1 is the penalty on that scale (Levy's −H is at least as bad as
//!   any return of his −1 per step).
//! - The high level is conditioned on a goal board. Without its hindsight goal transitions
//!   (tried first, with an unconditioned top level) its only signal before its first solved
//!   board is the testing penalty, whose values differ from the others' by 1 − γ: 30 k steps of
//!   LightsOutCursor reached none of their subgoals (0.0 %); with them 0.1 % of the attempts of
//!   the first 30 k steps reached theirs, and the share was rising.
//! - Schedule and buffers as the SAC baseline's: 8 environments stepped once per epoch, N
//!   gradient steps per epoch for each level once its replay holds a batch (Levy also updates
//!   both levels equally often), replay buffers of 10⁶ transitions each, batch 256 (Levy: 1024;
//!   SAC's 256 keeps the two baselines comparable). N is not in the seed for HAC: the presets
//!   use the SAC baseline's best N per environment.
//! - Both levels reuse [`Sac`]: the high level is [`Sac::relaxed_bernoulli`], the same critics
//!   and updates with a factorised RelaxedBernoulli actor (logits clamped to [−5, 5],
//!   log-probability summed over the D entries, deterministic action = logit > 0, as the
//!   reference's `RelaxedBernoulliPolicy`). `[sac]` configures the low level (α = α_low); the
//!   high level copies it with α = `hac.alpha_high`.
//! - Exact resume: as the SAC baseline's, plus each environment's subgoal (bits, tested, start
//!   step, reward so far) and the start and end steps of the open episode's ended attempts.
//!
//! An epoch steps each of the 8 environments once (as the SAC baseline does) and then takes N
//! gradient steps of each level whose replay holds a batch. Resuming is exact, as for the SAC
//! baseline: the open episodes are replayed from their seeds and actions, which also restores
//! each environment's observations since its subgoal began.

use seads_nn::Resolve as _;
use std::path::Path;
use std::time::Instant;

use rand::RngExt;
use seads_embodiment::EnvSpec;
use seads_games::SymbolicState;
use seads_planner::{DepthResult, TaskSet};
use serde::{Deserialize, Serialize};

use crate::TaskTimings;
use crate::learner::Learner;
use crate::replay::Replay;
use crate::task_episodes::{
    self, LossMean, OpenEpisode, Streams, TaskEpisodes, TaskEpochStats, read_progress, updates_due,
    write_progress,
};
use crate::task_policy::TaskPolicy;
use crate::{
    HacConfig, Moment, Purpose, RlError, Sac, SacConfig, TaskMetrics, TrainConfig, derived_seed,
    task_success,
};

/// File prefix of the high level's networks in a checkpoint ([`crate::sac::checkpoint_files`]).
pub const HIGH_PREFIX: &str = "hac_high";
/// File prefix of the low level's networks in a checkpoint.
pub const LOW_PREFIX: &str = "hac_low";
/// The high level's replay buffer in a checkpoint.
pub const HIGH_REPLAY_FILE: &str = "hac-high-replay.safetensors";
/// The low level's replay buffer in a checkpoint.
pub const LOW_REPLAY_FILE: &str = "hac-low-replay.safetensors";
/// Epoch, steps, random streams, open episodes and subgoals of a checkpoint.
pub const HAC_PROGRESS_FILE: &str = "hac-progress.json";

/// Goals per ended episode for the high level's hindsight goal transitions (Levy's number).
const HINDSIGHT_GOALS: usize = 3;

/// Reward (with the return's end) of a tested subgoal that was missed: below every return of the
/// task reward, which lie in [0, 1].
const MISSED_TEST_REWARD: f32 = -1.0;

/// An attempt of the open episode that has ended: what the high level's hindsight goals need.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
struct Ended {
    /// The steps of the episode it started and ended at.
    start: usize,
    end: usize,
}

/// A subgoal being pursued in one environment.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
struct Attempt {
    subgoal: SymbolicState,
    /// Pursued without exploration noise.
    testing: bool,
    /// The step of the episode it started at.
    start: usize,
    /// Task reward collected since (1 if the board was solved).
    reward: f32,
}

/// HAC's progress: the baselines' shared progress and the state of its subgoals.
#[derive(Debug, Clone)]
struct Progress {
    shared: task_episodes::Progress,
    /// Subgoal attempts ended, and how many reached their subgoal.
    attempts: u64,
    reached: u64,
    /// `attempts` and `reached` at the last metrics line.
    reported: (u64, u64),
    /// The subgoal of each environment (`None` between attempts).
    subgoals: Vec<Option<Attempt>>,
    /// The ended attempts of each environment's open episode.
    ended_attempts: Vec<Vec<Ended>>,
}

/// [`HAC_PROGRESS_FILE`]: [`Progress`] as one flat object, the shared fields beside HAC's, as
/// the file has always been (serde's `flatten` cannot carry the streams' 128-bit counters).
#[derive(Serialize, Deserialize)]
struct ProgressFile {
    epoch: u64,
    env_steps: u64,
    episodes: u64,
    ended: u64,
    solved: u64,
    attempts: u64,
    reached: u64,
    #[serde(default)]
    reported: (u64, u64),
    timings: TaskTimings,
    streams: Streams,
    open: Vec<OpenEpisode>,
    subgoals: Vec<Option<Attempt>>,
    ended_attempts: Vec<Vec<Ended>>,
}

impl From<ProgressFile> for Progress {
    fn from(f: ProgressFile) -> Self {
        Self {
            shared: task_episodes::Progress {
                epoch: f.epoch,
                env_steps: f.env_steps,
                episodes: f.episodes,
                ended: f.ended,
                solved: f.solved,
                timings: f.timings,
                streams: f.streams,
                open: f.open,
            },
            attempts: f.attempts,
            reached: f.reached,
            reported: f.reported,
            subgoals: f.subgoals,
            ended_attempts: f.ended_attempts,
        }
    }
}

impl From<&Progress> for ProgressFile {
    fn from(p: &Progress) -> Self {
        let s = p.shared.clone();
        Self {
            epoch: s.epoch,
            env_steps: s.env_steps,
            episodes: s.episodes,
            ended: s.ended,
            solved: s.solved,
            attempts: p.attempts,
            reached: p.reached,
            reported: p.reported,
            timings: s.timings,
            streams: s.streams,
            open: s.open,
            subgoals: p.subgoals.clone(),
            ended_attempts: p.ended_attempts.clone(),
        }
    }
}

/// A two-level HAC agent in training on the task reward.
pub struct Hac {
    config: TrainConfig,
    /// The configuration's HAC section.
    hac: HacConfig,
    spec: EnvSpec,
    episodes: TaskEpisodes,
    /// Every observation of each environment's open episode, row-major (steps + 1 rows).
    observations: Vec<Vec<f32>>,
    high: Sac,
    low: Sac,
    high_replay: Replay,
    low_replay: Replay,
    progress: Progress,
    /// The game's goal board.
    goal: SymbolicState,
    /// Reused buffers for a transition's two inputs (no allocation per environment step).
    scratch: [Vec<f32>; 2],
}

/// An input of either level: the observation followed by a board's D bits (the low level's
/// subgoal, the high level's goal).
fn with_board(obs: &[f32], subgoal: SymbolicState, d: usize, out: &mut Vec<f32>) {
    out.extend_from_slice(obs);
    let at = out.len();
    out.resize(at + d, 0.0);
    subgoal.write_f32(&mut out[at..]);
}

/// A subgoal from the high level's action: 1 where it exceeds 0.5.
fn threshold(action: &[f32]) -> SymbolicState {
    SymbolicState::from_bools(&action.iter().map(|&v| v > 0.5).collect::<Vec<_>>())
}

/// The goal board of the game of `spec`.
fn game_goal(spec: &EnvSpec) -> Result<SymbolicState, RlError> {
    let game = spec
        .game
        .build(spec.board_size)
        .map_err(seads_embodiment::EnvError::from)?;
    Ok(game.goal())
}

/// The run's HAC section: another algorithm's configuration is an error.
fn hac_section(config: &TrainConfig) -> Result<HacConfig, RlError> {
    Ok(config.section::<HacConfig>()?)
}

/// The two levels' networks for `config` on an environment of `spec`.
fn levels(config: &TrainConfig, spec: &EnvSpec) -> Result<(Sac, Sac), RlError> {
    let hac = hac_section(config)?;
    let device = config.device.resolve()?;
    let d = spec.symbolic_len;
    let high_config = SacConfig {
        alpha: hac.alpha_high,
        ..config.sac.clone()
    };
    let high = Sac::relaxed_bernoulli(
        spec.obs_dim + d,
        d,
        hac.temperature,
        &high_config,
        device,
        derived_seed(config.seed, Purpose::SacInit, 1),
    );
    let low = Sac::new(
        spec.obs_dim + d,
        &spec.action_low,
        &spec.action_high,
        &config.sac,
        device,
        derived_seed(config.seed, Purpose::SacInit, 2),
    );
    Ok((high, low))
}

impl Hac {
    /// A fresh agent for `config` (validated; `config.algorithm()` is not checked here).
    pub fn new(config: TrainConfig) -> Result<Self, RlError> {
        let (episodes, shared) = TaskEpisodes::new(&config)?;
        let spec = episodes.spec().clone();
        let (high, low) = levels(&config, &spec)?;
        let d = spec.symbolic_len;
        let goal = game_goal(&spec)?;
        let hac = hac_section(&config)?.clone();
        let capacity = hac.replay_capacity;
        let n = episodes.len();
        let progress = Progress {
            shared,
            attempts: 0,
            reached: 0,
            reported: (0, 0),
            subgoals: vec![None; n],
            ended_attempts: vec![Vec::new(); n],
        };
        let mut agent = Self {
            observations: vec![Vec::new(); n],
            high_replay: Replay::new(capacity, spec.obs_dim + d, d),
            goal,
            scratch: [Vec::new(), Vec::new()],
            low_replay: Replay::new(capacity, spec.obs_dim + d, spec.action_dim),
            config,
            hac,
            spec,
            episodes,
            high,
            low,
            progress,
        };
        for slot in 0..n {
            agent.start_episode(slot)?;
        }
        Ok(agent)
    }

    /// Resets environment `slot` for the next episode, seeded by the episode's number.
    fn start_episode(&mut self, slot: usize) -> Result<(), RlError> {
        let obs = &mut self.observations[slot];
        obs.clear();
        self.episodes.start(slot, &mut self.progress.shared, obs)?;
        self.progress.subgoals[slot] = None;
        self.progress.ended_attempts[slot].clear();
        Ok(())
    }

    /// Row `i` of environment `slot`'s episode observations.
    fn observation(&self, slot: usize, i: usize) -> &[f32] {
        let o = self.spec.obs_dim;
        &self.observations[slot][i * o..(i + 1) * o]
    }

    /// The current observation of environment `slot`.
    fn current(&self, slot: usize) -> &[f32] {
        let rows = self.observations[slot].len() / self.spec.obs_dim;
        self.observation(slot, rows - 1)
    }

    /// The configuration.
    pub fn config(&self) -> &TrainConfig {
        &self.config
    }

    /// Epochs run so far.
    pub fn epoch(&self) -> u64 {
        self.progress.shared.epoch
    }

    /// Environment steps so far.
    pub fn env_steps(&self) -> u64 {
        self.progress.shared.env_steps
    }

    /// Whether the step budget is spent.
    pub fn finished(&self) -> bool {
        self.progress.shared.env_steps >= self.config.env_steps
    }

    /// Time spent per phase.
    pub fn timings(&self) -> TaskTimings {
        self.progress.shared.timings
    }

    /// The deterministic two-level policy.
    pub fn policy(&self) -> HacPolicy<'_> {
        HacPolicy::new(
            &self.high,
            &self.low,
            &self.spec,
            self.goal,
            self.hac.subgoal_horizon,
        )
    }

    /// Gives environment `slot` a subgoal from the stochastic high level, tested with
    /// probability λ.
    fn propose(&mut self, slot: usize) {
        let o = self.spec.obs_dim;
        let start = self.observations[slot].len() / o - 1;
        let mut input = Vec::new();
        with_board(
            &self.observations[slot][start * o..],
            self.goal,
            self.spec.symbolic_len,
            &mut input,
        );
        let streams = &mut self.progress.shared.streams;
        let action = self.high.act(&input, Some(&mut streams.collect));
        let testing = streams.collect.random::<f64>() < self.hac.subgoal_test_p;
        self.progress.subgoals[slot] = Some(Attempt {
            subgoal: threshold(&action),
            testing,
            start,
            reward: 0.0,
        });
    }

    /// One epoch: a step of every environment (new subgoals where needed), then the gradient
    /// steps due of both levels.
    pub fn run_epoch(&mut self) -> Result<TaskEpochStats, RlError> {
        let start = Instant::now();
        let (d, a) = (self.spec.symbolic_len, self.spec.action_dim);
        for slot in 0..self.episodes.len() {
            if self.progress.subgoals[slot].is_none() {
                self.propose(slot);
            }
        }
        let mut inputs = Vec::new();
        for slot in 0..self.episodes.len() {
            let attempt = self.progress.subgoals[slot].as_ref().expect("proposed");
            with_board(self.current(slot), attempt.subgoal, d, &mut inputs);
        }
        let noisy = self
            .low
            .act(&inputs, Some(&mut self.progress.shared.streams.collect));
        let tested = self.progress.subgoals.iter().flatten().any(|s| s.testing);
        let deterministic = tested.then(|| self.low.act(&inputs, None));
        for slot in 0..self.episodes.len() {
            let attempt = self.progress.subgoals[slot].clone().expect("proposed");
            let action = match (&deterministic, attempt.testing) {
                (Some(actions), true) => &actions[slot * a..(slot + 1) * a],
                _ => &noisy[slot * a..(slot + 1) * a],
            };
            let o = self.spec.obs_dim;
            let rows = self.observations[slot].len();
            self.observations[slot].resize(rows + o, 0.0);
            let step = self.episodes.step(
                slot,
                action,
                &mut self.progress.shared,
                &mut self.observations[slot][rows..],
            )?;
            let reached = self.spec.phi(self.current(slot)) == attempt.subgoal;
            // The low level's transition toward its subgoal.
            let [mut from, mut to] = std::mem::take(&mut self.scratch);
            from.clear();
            to.clear();
            let steps = self.progress.shared.open[slot].actions.len() / a;
            with_board(
                self.observation(slot, steps - 1),
                attempt.subgoal,
                d,
                &mut from,
            );
            with_board(self.current(slot), attempt.subgoal, d, &mut to);
            let reward = if reached { 1.0 } else { 0.0 };
            self.low_replay.push(&from, action, reward, &to, reached);
            self.scratch = [from, to];
            let attempt = Attempt {
                reward: attempt.reward + step.reward,
                ..attempt
            };
            let over = reached || steps - attempt.start >= self.hac.subgoal_horizon || step.done;
            if over {
                self.end_attempt(slot, &attempt, reached, step.done);
            } else {
                self.progress.subgoals[slot] = Some(attempt);
            }
            if step.done {
                self.relabel_episode(slot);
                self.start_episode(slot)?;
            }
        }
        self.progress.shared.collected(self.episodes.len(), start);

        let start = Instant::now();
        let due = updates_due(self.progress.shared.epoch, self.hac.updates_per_epoch);
        let batch_size = self.config.sac.batch_size;
        let mut losses = LossMean::default();
        for _ in 0..due {
            let streams = &mut self.progress.shared.streams;
            if self.low_replay.len() >= batch_size {
                let batch = self.low_replay.sample(batch_size, &mut streams.sample);
                losses.add(self.low.update(&batch, &mut streams.sac));
            }
            if self.high_replay.len() >= batch_size {
                let batch = self.high_replay.sample(batch_size, &mut streams.sample);
                self.high.update(&batch, &mut streams.sac);
            }
        }
        Ok(self.progress.shared.end_epoch(start, losses))
    }

    /// Stores what an ended subgoal attempt teaches both levels.
    fn end_attempt(&mut self, slot: usize, attempt: &Attempt, reached: bool, episode_done: bool) {
        let (d, a) = (self.spec.symbolic_len, self.spec.action_dim);
        let actions = &self.progress.shared.open[slot].actions;
        let end = actions.len() / a;
        let achieved = self.spec.phi(self.current(slot));
        // Hindsight goal transitions: the missed attempt as one toward the board it ended on.
        let [mut from, mut to] = std::mem::take(&mut self.scratch);
        if !reached {
            for i in attempt.start..end {
                let next = self.spec.phi(self.observation(slot, i + 1)) == achieved;
                from.clear();
                to.clear();
                with_board(self.observation(slot, i), achieved, d, &mut from);
                with_board(self.observation(slot, i + 1), achieved, d, &mut to);
                let reward = if next { 1.0 } else { 0.0 };
                self.low_replay
                    .push(&from, &actions[i * a..(i + 1) * a], reward, &to, next);
            }
        }
        // The hindsight action transition: the board reached as the subgoal proposed.
        let mut reached_bits = vec![0.0; d];
        achieved.write_f32(&mut reached_bits);
        from.clear();
        to.clear();
        with_board(
            self.observation(slot, attempt.start),
            self.goal,
            d,
            &mut from,
        );
        with_board(self.current(slot), self.goal, d, &mut to);
        self.high_replay
            .push(&from, &reached_bits, attempt.reward, &to, episode_done);
        // Subgoal testing: a missed tested subgoal ends its return with the penalty.
        if attempt.testing && !reached {
            let mut proposed = vec![0.0; d];
            attempt.subgoal.write_f32(&mut proposed);
            self.high_replay
                .push(&from, &proposed, MISSED_TEST_REWARD, &to, true);
        }
        self.scratch = [from, to];
        self.progress.ended_attempts[slot].push(Ended {
            start: attempt.start,
            end,
        });
        self.progress.attempts += 1;
        self.progress.reached += u64::from(reached);
        self.progress.subgoals[slot] = None;
    }

    /// The high level's hindsight goal transitions of environment `slot`'s ended episode: toward
    /// the board its last attempt ended on and those of two more attempts drawn at random, each
    /// attempt up to that one is stored again (the board it reached as its action), rewarded 1
    /// and ending its return where it reached the goal.
    fn relabel_episode(&mut self, slot: usize) {
        let ended = std::mem::take(&mut self.progress.ended_attempts[slot]);
        let Some(last) = ended.len().checked_sub(1) else {
            return;
        };
        let mut goals = vec![last];
        for _ in 1..HINDSIGHT_GOALS {
            goals.push(
                self.progress
                    .shared
                    .streams
                    .collect
                    .random_range(0..ended.len()),
            );
        }
        let d = self.spec.symbolic_len;
        let mut bits = vec![0.0; d];
        let (mut from, mut to) = (Vec::new(), Vec::new());
        for j in goals {
            let goal = self.spec.phi(self.observation(slot, ended[j].end));
            for attempt in &ended[..=j] {
                let achieved = self.spec.phi(self.observation(slot, attempt.end));
                achieved.write_f32(&mut bits);
                from.clear();
                to.clear();
                with_board(self.observation(slot, attempt.start), goal, d, &mut from);
                with_board(self.observation(slot, attempt.end), goal, d, &mut to);
                let hit = achieved == goal;
                let reward = if hit { 1.0 } else { 0.0 };
                self.high_replay.push(&from, &bits, reward, &to, hit);
            }
        }
    }

    /// Task success of the deterministic policy on `boards` test boards of each depth 1–5.
    pub fn task_success(&mut self, boards: usize) -> Result<Vec<DepthResult>, RlError> {
        let start = Instant::now();
        let config = self.config.clone();
        let results = task_success(
            &config,
            &mut self.policy(),
            &TaskSet::standard(boards),
            |_, _, _, _| {},
        )?;
        self.progress.shared.timings.evaluate += start.elapsed().as_secs_f64();
        Ok(results)
    }

    /// Writes the complete training state into `dir` (which must exist).
    pub fn save(&self, dir: &Path) -> Result<(), RlError> {
        self.high.save_as(dir, HIGH_PREFIX)?;
        self.low.save_as(dir, LOW_PREFIX)?;
        self.high_replay.save(&dir.join(HIGH_REPLAY_FILE))?;
        self.low_replay.save(&dir.join(LOW_REPLAY_FILE))?;
        write_progress(
            &dir.join(HAC_PROGRESS_FILE),
            &ProgressFile::from(&self.progress),
        )
    }

    /// Restores what [`Hac::save`] wrote, replaying each environment's open episode.
    pub fn load(&mut self, dir: &Path) -> Result<(), RlError> {
        self.high.load_as(dir, HIGH_PREFIX, false)?;
        self.low.load_as(dir, LOW_PREFIX, false)?;
        self.high_replay.load(&dir.join(HIGH_REPLAY_FILE))?;
        self.low_replay.load(&dir.join(LOW_REPLAY_FILE))?;
        let path = dir.join(HAC_PROGRESS_FILE);
        let progress = Progress::from(read_progress::<ProgressFile>(&path)?);
        let n = self.episodes.len();
        if progress.subgoals.len() != n || progress.ended_attempts.len() != n {
            return Err(RlError::from(seads_run::RunError::Checkpoint {
                path: path.display().to_string(),
                reason: format!("{} subgoals for {n} environments", progress.subgoals.len()),
            }));
        }
        let observations = &mut self.observations;
        observations.iter_mut().for_each(Vec::clear);
        self.episodes.replay(&progress.shared, &path, |slot, obs| {
            observations[slot].extend_from_slice(obs)
        })?;
        let a = self.spec.action_dim;
        for (slot, open) in progress.shared.open.iter().enumerate() {
            let steps = open.actions.len() / a;
            let late = progress.subgoals[slot]
                .as_ref()
                .is_some_and(|attempt| attempt.start > steps)
                || progress.ended_attempts[slot]
                    .iter()
                    .any(|e| e.start > e.end || e.end > steps);
            if late {
                return Err(RlError::from(seads_run::RunError::Checkpoint {
                    path: path.display().to_string(),
                    reason: format!("a subgoal of environment {slot} starts after its episode"),
                }));
            }
        }
        self.progress = progress;
        Ok(())
    }
}

/// The deterministic HAC policy: the high level's mode as the subgoal, a new one when it is
/// reached or after H steps, and the low level's deterministic action toward it.
pub struct HacPolicy<'a> {
    levels: Levels<'a>,
    symbolic: SymbolicSlice,
    horizon: usize,
    subgoal: Option<(SymbolicState, usize)>,
    input: Vec<f32>,
}

/// The two levels, borrowed from an agent in training or loaded from a checkpoint.
enum Levels<'a> {
    Borrowed(&'a Sac, &'a Sac),
    Owned(Box<(Sac, Sac)>),
}

/// Where the symbolic state lies in an observation, and the game's goal board.
#[derive(Clone, Copy)]
struct SymbolicSlice {
    start: usize,
    len: usize,
    goal: SymbolicState,
}

impl SymbolicSlice {
    fn of(spec: &EnvSpec, goal: SymbolicState) -> Self {
        Self {
            start: spec.manipulator_dim,
            len: spec.symbolic_len,
            goal,
        }
    }

    fn phi(self, obs: &[f32]) -> SymbolicState {
        SymbolicState::from_observation(&obs[self.start..self.start + self.len])
    }
}

impl<'a> HacPolicy<'a> {
    fn new(
        high: &'a Sac,
        low: &'a Sac,
        spec: &EnvSpec,
        goal: SymbolicState,
        horizon: usize,
    ) -> Self {
        Self {
            levels: Levels::Borrowed(high, low),
            symbolic: SymbolicSlice::of(spec, goal),
            horizon,
            subgoal: None,
            input: Vec::new(),
        }
    }
}

impl HacPolicy<'static> {
    /// The policy saved in a checkpoint folder of a HAC run with `config` on `spec` (only the
    /// actors are read).
    pub fn load(config: &TrainConfig, spec: &EnvSpec, checkpoint: &Path) -> Result<Self, RlError> {
        let (mut high, mut low) = levels(config, spec)?;
        high.load_as(checkpoint, HIGH_PREFIX, true)?;
        low.load_as(checkpoint, LOW_PREFIX, true)?;
        Ok(Self {
            levels: Levels::Owned(Box::new((high, low))),
            symbolic: SymbolicSlice::of(spec, game_goal(spec)?),
            horizon: hac_section(config)?.subgoal_horizon,
            subgoal: None,
            input: Vec::new(),
        })
    }
}

impl TaskPolicy for HacPolicy<'_> {
    fn begin(&mut self) {
        self.subgoal = None;
    }

    fn act(&mut self, obs: &[f32]) -> Vec<f32> {
        let (high, low) = match &self.levels {
            Levels::Borrowed(high, low) => (*high, *low),
            Levels::Owned(levels) => (&levels.0, &levels.1),
        };
        let board = self.symbolic.phi(obs);
        let d = self.symbolic.len;
        let subgoal = match self.subgoal {
            Some((z, steps)) if steps < self.horizon && !(steps > 0 && board == z) => (z, steps),
            _ => {
                self.input.clear();
                with_board(obs, self.symbolic.goal, d, &mut self.input);
                (threshold(&high.act(&self.input, None)), 0)
            }
        };
        self.subgoal = Some((subgoal.0, subgoal.1 + 1));
        self.input.clear();
        with_board(obs, subgoal.0, d, &mut self.input);
        low.act(&self.input, None)
    }
}

impl Learner for Hac {
    type Section = crate::HacConfig;
    type Stats = TaskEpochStats;
    type Metrics = TaskMetrics;

    fn build(config: TrainConfig) -> Result<Self, RlError> {
        Self::new(config)
    }
    fn config(&self) -> &TrainConfig {
        &self.config
    }
    fn epoch(&self) -> u64 {
        self.progress.shared.epoch
    }
    fn finished(&self) -> bool {
        Hac::finished(self)
    }
    fn run_epoch_observed(
        &mut self,
        hook: &mut dyn FnMut(Moment),
    ) -> Result<TaskEpochStats, RlError> {
        let stats = self.run_epoch()?;
        hook(Moment::Collected);
        Ok(stats)
    }
    fn metrics(&mut self, stats: &TaskEpochStats, wall_s: f64) -> Result<TaskMetrics, RlError> {
        let results = self.task_success(self.hac.eval_boards)?;
        let p = &mut self.progress;
        let mut line = crate::task_sac::task_metrics(&results, &p.shared, wall_s, stats);
        let (attempts, reached) = (p.attempts - p.reported.0, p.reached - p.reported.1);
        line.subgoals_reached = Some(reached as f64 / attempts.max(1) as f64);
        p.reported = (p.attempts, p.reached);
        Ok(line)
    }
    fn save(&self, dir: &Path) -> Result<(), RlError> {
        Hac::save(self, dir)
    }
    fn load(&mut self, dir: &Path) -> Result<(), RlError> {
        Hac::load(self, dir)
    }
    fn resume_only_files() -> Vec<&'static str> {
        // The actors stay in every checkpoint (they are the policy); the rest is for resuming.
        const FILES: [&str; 11] = [
            "hac_high_critic.safetensors",
            "hac_high_target.safetensors",
            "hac_high_actor_adam.safetensors",
            "hac_high_critic_adam.safetensors",
            "hac_low_critic.safetensors",
            "hac_low_target.safetensors",
            "hac_low_actor_adam.safetensors",
            "hac_low_critic_adam.safetensors",
            HIGH_REPLAY_FILE,
            LOW_REPLAY_FILE,
            HAC_PROGRESS_FILE,
        ];
        FILES.to_vec()
    }
    fn load_task_policy(
        config: &TrainConfig,
        spec: &seads_embodiment::EnvSpec,
        checkpoint: &std::path::Path,
    ) -> Result<Box<dyn TaskPolicy>, RlError> {
        Ok(Box::new(HacPolicy::load(config, spec, checkpoint)?))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn small(test_p: f64) -> TrainConfig {
        let mut config = TrainConfig::preset_for("lightsout-cursor", "hac").unwrap();
        config.sac.hidden = vec![16];
        config.sac.batch_size = 16;
        config
            .edit(|hac: &mut HacConfig| (hac.subgoal_horizon, hac.subgoal_test_p) = (4, test_p))
            .unwrap();
        config.portable_numerics = true;
        config
    }

    /// Every transition in both replays follows the rules of HAC: a low-level transition is
    /// rewarded 1, and ends, exactly when its next board is the subgoal in its input (hindsight
    /// goals included); a high-level transition either has the board reached as its action
    /// (hindsight action) or is the terminal −1 of a missed tested subgoal. With every subgoal
    /// tested there is one penalty per missed attempt; with none, none.
    #[test]
    fn replays_hold_hacs_transitions() {
        for test_p in [0.0, 1.0] {
            let mut hac = Hac::new(small(test_p)).unwrap();
            for _ in 0..60 {
                hac.run_epoch().unwrap();
            }
            let (o, d) = (hac.spec.obs_dim, hac.spec.symbolic_len);
            let phi = |row: &[f32]| hac.spec.phi(row);
            let low = &hac.low_replay;
            let mut hindsight_rewards = 0;
            for i in 0..low.len() {
                let next = &low.next_obs[i * (o + d)..(i + 1) * (o + d)];
                let goal = SymbolicState::from_observation(&next[o..]);
                let hit = phi(&next[..o]) == goal;
                assert_eq!(
                    low.rewards[i],
                    f32::from(u8::from(hit)),
                    "low transition {i}"
                );
                assert_eq!(low.dones[i], low.rewards[i]);
                hindsight_rewards += usize::from(hit);
            }
            assert!(
                hindsight_rewards > 0,
                "hindsight goals reward the boards reached"
            );
            let high = &hac.high_replay;
            let (mut penalties, mut relabelled) = (0, 0);
            for i in 0..high.len() {
                let next = &high.next_obs[i * (o + d)..(i + 1) * (o + d)];
                let goal = SymbolicState::from_observation(&next[o..]);
                let action = threshold(&high.actions[i * d..(i + 1) * d]);
                if action != phi(&next[..o]) {
                    assert_eq!((high.rewards[i], high.dones[i]), (-1.0, 1.0), "{i}");
                    penalties += 1;
                    continue;
                }
                let hit = phi(&next[..o]) == goal;
                assert_eq!(
                    high.rewards[i],
                    f32::from(u8::from(hit)),
                    "high transition {i}"
                );
                assert!(high.dones[i] >= high.rewards[i]);
                relabelled += usize::from(goal != hac.goal);
            }
            assert!(relabelled > 0, "hindsight goals other than the game's");
            let p = &hac.progress;
            assert!(p.attempts > 20);
            let missed = (p.attempts - p.reached) as usize;
            assert_eq!(penalties, if test_p > 0.0 { missed } else { 0 });
        }
    }

    /// The resume-only files are the checkpoint files of both levels except their actors.
    #[test]
    fn resume_only_files_are_all_but_the_actors() {
        let mut expected: Vec<String> = [HIGH_PREFIX, LOW_PREFIX]
            .iter()
            .flat_map(|p| crate::sac::checkpoint_files(p).into_iter().skip(1))
            .collect();
        expected.extend([HIGH_REPLAY_FILE, LOW_REPLAY_FILE, HAC_PROGRESS_FILE].map(String::from));
        assert_eq!(Hac::resume_only_files(), expected);
    }
}
