//! Soft actor-critic (SPEC §3.2): tanh-squashed Gaussian policy, twin Q critics with
//! Polyak-averaged targets, a fixed entropy temperature α, Adam.
//!
//! The same agent with a factorised [`RelaxedBernoulli`] policy over (0, 1)^D is the discrete SAC
//! of the HAC baseline's high level (SPEC §5.2; [`Sac::relaxed_bernoulli`]).

use std::path::Path;

use rand::{Rng, RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};
use seads_nn::{Adam, Init, Mlp, flatten_parameters, mean_f32, xavier_linear};
use serde::Serialize;
use tch::nn::{self, Module};
use tch::{Device, Kind, Tensor};

use crate::{RelaxedBernoulli, RlError};
pub use seads_run::SacConfig;

/// A batch of transitions, row-major.
#[derive(Debug, Clone, Default)]
pub struct TransitionBatch {
    /// Policy inputs s_t (B × input_dim).
    pub obs: Vec<f32>,
    /// Actions a_t (B × action_dim).
    pub actions: Vec<f32>,
    /// Rewards r_{t+1} (B).
    pub rewards: Vec<f32>,
    /// Policy inputs s_{t+1} (B × input_dim).
    pub next_obs: Vec<f32>,
    /// 1.0 where the episode ended with this transition (B).
    pub dones: Vec<f32>,
}

/// Losses of one SAC update.
#[derive(Debug, Clone, Copy, Default, Serialize)]
pub struct SacLosses {
    /// MSE of both critics against the soft Bellman target.
    pub critic: f32,
    /// α·log π − min Q.
    pub actor: f32,
    /// Mean min-Q of the policy's actions.
    pub q: f32,
}

/// The actor.
#[derive(Debug)]
enum Actor {
    /// A tanh-squashed Gaussian: an MLP trunk with a mean head and a log σ head.
    Gaussian { mean: Mlp, log_std: nn::Linear },
    /// A factorised RelaxedBernoulli of temperature τ: an MLP giving logits clamped to
    /// [−5, 5].
    Bernoulli { logits: Mlp, temperature: f64 },
}

/// Soft actor-critic on inputs of `input_dim` values and actions in a box.
#[derive(Debug)]
pub struct Sac {
    config: SacConfig,
    input_dim: usize,
    action_dim: usize,
    device: Device,
    scale: Tensor,
    bias: Tensor,
    actor_vs: nn::VarStore,
    critic_vs: nn::VarStore,
    target_vs: nn::VarStore,
    actor: Actor,
    q: [Mlp; 2],
    q_target: [Mlp; 2],
    actor_opt: Adam,
    critic_opt: Adam,
    /// The critics' and the targets' parameters as flat buffers of the same layout.
    critic_flat: Tensor,
    target_flat: Tensor,
}

/// A Gaussian-actor [`Sac`]'s settings, networks and optimisers, borrowed.
pub(crate) struct SacParts<'a> {
    pub config: &'a SacConfig,
    pub actor_vs: &'a nn::VarStore,
    pub critic_vs: &'a nn::VarStore,
    pub scale: &'a Tensor,
    pub bias: &'a Tensor,
    pub actor_opt: &'a Adam,
    pub critic_opt: &'a Adam,
    pub target_flat: &'a Tensor,
}

/// A reparameterised sample a = tanh(mean + σ·ε)·scale + bias of the Gaussian of `mean` and
/// (clamped) `log_std` for standard-normal `noise`, and its log-probability summed over the
/// action's entries (the last dimension, kept); for one agent's rows or for stacked members'.
pub(crate) fn squashed_gaussian(
    mean: &Tensor,
    log_std: &Tensor,
    noise: &Tensor,
    scale: &Tensor,
    bias: &Tensor,
) -> (Tensor, Tensor) {
    let u = mean + log_std.exp() * noise;
    let t = u.tanh();
    let action = &t * scale + bias;
    let log_normal = noise.square() * -0.5 - log_std - 0.5 * (2.0 * std::f64::consts::PI).ln();
    let one_minus_t2: Tensor = 1.0 - t.square();
    let squash = (scale * one_minus_t2 + 1e-6).log();
    let log_prob = (log_normal - squash).sum_dim_intlist(-1, true, Kind::Float);
    (action, log_prob)
}

/// The checkpoint file of the actor: all that executing skills needs.
pub const ACTOR_FILE: &str = "sac_actor.safetensors";
/// The other checkpoint files of SAC (critics, targets, optimiser states): what resuming needs.
pub const RESUME_FILES: [&str; 4] = [
    "sac_critic.safetensors",
    "sac_target.safetensors",
    "sac_actor_adam.safetensors",
    "sac_critic_adam.safetensors",
];

/// The checkpoint files of a SAC agent saved under `prefix` ([`Sac::save_as`]), the actor first:
/// `sac` gives the files of [`Sac::save`].
pub fn checkpoint_files(prefix: &str) -> [String; 5] {
    ["actor", "critic", "target", "actor_adam", "critic_adam"]
        .map(|part| format!("{prefix}_{part}.safetensors"))
}

pub(crate) const LOG_STD_MIN: f64 = -20.0;
pub(crate) const LOG_STD_MAX: f64 = 2.0;
/// The RelaxedBernoulli policy's logit bounds (the reference's `RelaxedBernoulliPolicy`).
const LOGIT_BOUND: f64 = 5.0;

impl Sac {
    /// Fresh networks for inputs of `input_dim` and actions in `[low, high]`, initialised from `seed`.
    pub fn new(
        input_dim: usize,
        low: &[f32],
        high: &[f32],
        config: &SacConfig,
        device: Device,
        seed: u64,
    ) -> Self {
        Self::build(input_dim, low, high, None, config, device, seed)
    }

    /// A discrete SAC for binary actions in {0,1}^`action_dim` (the HAC high level's subgoals):
    /// a factorised RelaxedBernoulli policy of `temperature` τ > 0 whose logits are clamped to
    /// [−5, 5]. Sampled actions lie in (0, 1); deterministic ones are 1 where the logit is
    /// positive. The critics see the relaxed action.
    pub fn relaxed_bernoulli(
        input_dim: usize,
        action_dim: usize,
        temperature: f64,
        config: &SacConfig,
        device: Device,
        seed: u64,
    ) -> Self {
        let (low, high) = (vec![0.0; action_dim], vec![1.0; action_dim]);
        Self::build(
            input_dim,
            &low,
            &high,
            Some(temperature),
            config,
            device,
            seed,
        )
    }

    fn build(
        input_dim: usize,
        low: &[f32],
        high: &[f32],
        temperature: Option<f64>,
        config: &SacConfig,
        device: Device,
        seed: u64,
    ) -> Self {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let action_dim = low.len();
        let (i, a) = (input_dim as i64, action_dim as i64);
        let actor_vs = nn::VarStore::new(device);
        // The reference's SAC networks start Xavier (its `weights_init_`).
        let mean = Mlp::new(
            &(actor_vs.root() / "actor"),
            i,
            &config.hidden,
            a,
            Init::Xavier,
            &mut rng,
        );
        let actor = match temperature {
            None => {
                let last = *config.hidden.last().expect("validated");
                let log_std =
                    xavier_linear(&(actor_vs.root() / "actor_log_std"), last, a, &mut rng);
                Actor::Gaussian { mean, log_std }
            }
            Some(temperature) => Actor::Bernoulli {
                logits: mean,
                temperature,
            },
        };
        // Twin critics (their targets are initialised the same way, then overwritten by a copy).
        let twin_critics = |vs: &nn::VarStore, rng: &mut ChaCha8Rng| {
            ["q1", "q2"].map(|name| {
                Mlp::new(
                    &(vs.root() / name),
                    i + a,
                    &config.hidden,
                    1,
                    Init::Xavier,
                    rng,
                )
            })
        };
        let critic_vs = nn::VarStore::new(device);
        let q = twin_critics(&critic_vs, &mut rng);
        let mut target_vs = nn::VarStore::new(device);
        let q_target = twin_critics(&target_vs, &mut rng);
        target_vs.copy(&critic_vs).expect("same layout");
        let scale: Vec<f32> = low.iter().zip(high).map(|(l, h)| (h - l) / 2.0).collect();
        let bias: Vec<f32> = low.iter().zip(high).map(|(l, h)| (h + l) / 2.0).collect();
        let actor_opt = Adam::new(&actor_vs, config.lr);
        let critic_opt = Adam::new(&critic_vs, config.lr);
        let critic_flat = critic_opt.parameters().shallow_clone();
        let target_flat = flatten_parameters(&target_vs);
        Self {
            config: config.clone(),
            input_dim,
            action_dim,
            device,
            scale: Tensor::from_slice(&scale).to_device(device),
            bias: Tensor::from_slice(&bias).to_device(device),
            actor_vs,
            critic_vs,
            target_vs,
            actor,
            q,
            q_target,
            actor_opt,
            critic_opt,
            critic_flat,
            target_flat,
        }
    }

    /// Length of a policy input.
    pub fn input_dim(&self) -> usize {
        self.input_dim
    }

    /// Length of an action.
    pub fn action_dim(&self) -> usize {
        self.action_dim
    }

    /// The hyper-parameters.
    pub fn config(&self) -> &SacConfig {
        &self.config
    }

    fn tensor(&self, data: &[f32], cols: usize) -> Tensor {
        Tensor::from_slice(data)
            .view([(data.len() / cols) as i64, cols as i64])
            .to_device(self.device)
    }

    /// Standard-normal noise for a Gaussian actor, uniforms on [0, 1) for a RelaxedBernoulli one.
    fn noise<R: Rng + ?Sized>(&self, rows: usize, rng: &mut R) -> Tensor {
        self.tensor(&self.noise_values(rows, rng), self.action_dim)
    }

    /// [`Sac::noise`]'s values, rows × action_dim.
    fn noise_values<R: Rng + ?Sized>(&self, rows: usize, rng: &mut R) -> Vec<f32> {
        match self.actor {
            Actor::Gaussian { .. } => (0..rows * self.action_dim)
                .map(|_| StandardNormal.sample(rng))
                .collect(),
            Actor::Bernoulli { .. } => (0..rows * self.action_dim)
                .map(|_| rng.random::<f32>())
                .collect(),
        }
    }

    /// Mean and log σ of the pre-squash Gaussian.
    fn gaussian(mean: &Mlp, log_std: &nn::Linear, x: &Tensor) -> (Tensor, Tensor) {
        let h = mean.features(x);
        (
            mean.head().forward(&h),
            log_std.forward(&h).clamp(LOG_STD_MIN, LOG_STD_MAX),
        )
    }

    fn bernoulli(logits: &Mlp, temperature: f64, x: &Tensor) -> RelaxedBernoulli {
        RelaxedBernoulli::new(
            temperature,
            logits.forward(x).clamp(-LOGIT_BOUND, LOGIT_BOUND),
        )
    }

    /// A reparameterised sample and its log-probability (summed over the action's entries):
    /// a = tanh(mean + σ·ε)·scale + bias for a Gaussian actor, the relaxed sample for uniforms
    /// `noise` for a RelaxedBernoulli one.
    fn sample(&self, x: &Tensor, noise: &Tensor) -> (Tensor, Tensor) {
        match &self.actor {
            Actor::Gaussian { mean, log_std } => {
                let (mean, log_std) = Self::gaussian(mean, log_std, x);
                squashed_gaussian(&mean, &log_std, noise, &self.scale, &self.bias)
            }
            Actor::Bernoulli {
                logits,
                temperature,
            } => {
                let dist = Self::bernoulli(logits, *temperature, x);
                let action = dist.rsample_with(noise);
                let log_prob = dist.log_prob(&action).sum_dim_intlist(1, true, Kind::Float);
                (action, log_prob)
            }
        }
    }

    /// Actions for a batch of inputs (rows of `input_dim`): sampled from the policy with noise
    /// from `rng`, or deterministic (tanh of the mean; for a RelaxedBernoulli actor the mode)
    /// when `rng` is `None`.
    pub fn act(&self, inputs: &[f32], rng: Option<&mut ChaCha8Rng>) -> Vec<f32> {
        tch::no_grad(|| {
            let x = self.tensor(inputs, self.input_dim);
            let action = match (rng, &self.actor) {
                (Some(rng), _) => {
                    let noise = self.noise(inputs.len() / self.input_dim, rng);
                    self.sample(&x, &noise).0
                }
                (None, Actor::Gaussian { mean, log_std }) => {
                    Self::gaussian(mean, log_std, &x).0.tanh() * &self.scale + &self.bias
                }
                (
                    None,
                    Actor::Bernoulli {
                        logits,
                        temperature,
                    },
                ) => Self::bernoulli(logits, *temperature, &x).mode(),
            };
            Vec::<f32>::try_from(action.view([-1]).to_device(Device::Cpu)).expect("float actions")
        })
    }

    fn min_q(q: &[Mlp; 2], x: &Tensor, a: &Tensor) -> Tensor {
        let xa = Tensor::cat(&[x, a], 1);
        q[0].forward(&xa).minimum(&q[1].forward(&xa))
    }

    /// One SAC step: critics, then actor, then the Polyak update of the targets, with the
    /// policy's noise drawn from `rng` (for the next actions first, then for the actor's).
    pub fn update(&mut self, batch: &TransitionBatch, rng: &mut ChaCha8Rng) -> SacLosses {
        let rows = batch.rewards.len();
        let next_noise = self.noise(rows, rng);
        let policy_noise = self.noise(rows, rng);
        self.update_with_noise(batch, &next_noise, &policy_noise)
    }

    /// [`Sac::update`] with given noise (rows × action_dim each; standard normal for a Gaussian
    /// actor, uniform for a RelaxedBernoulli one): for the next actions of the target and for
    /// the actor's reparameterised actions.
    pub fn update_with_noise(
        &mut self,
        batch: &TransitionBatch,
        next_noise: &Tensor,
        policy_noise: &Tensor,
    ) -> SacLosses {
        let obs = self.tensor(&batch.obs, self.input_dim);
        let actions = self.tensor(&batch.actions, self.action_dim);
        let next_obs = self.tensor(&batch.next_obs, self.input_dim);
        let rewards = self.tensor(&batch.rewards, 1);
        let dones = self.tensor(&batch.dones, 1);
        let (alpha, gamma) = (self.config.alpha, self.config.gamma);

        let target = tch::no_grad(|| {
            let (next_action, next_log_prob) = self.sample(&next_obs, next_noise);
            let soft_q =
                Self::min_q(&self.q_target, &next_obs, &next_action) - next_log_prob * alpha;
            &rewards + (1.0 - &dones) * gamma * soft_q
        });
        let xa = Tensor::cat(&[&obs, &actions], 1);
        let critic_loss = (self.q[0].forward(&xa) - &target)
            .square()
            .mean(Kind::Float)
            + (self.q[1].forward(&xa) - &target)
                .square()
                .mean(Kind::Float);
        self.critic_opt.backward_step(&critic_loss);

        // The actor's loss flows through the critics to the action; only the actor's parameters
        // receive gradients (`backward_step` differentiates with respect to its own parameters).
        let (new_action, log_prob) = self.sample(&obs, policy_noise);
        let q = Self::min_q(&self.q, &obs, &new_action);
        let actor_loss = (log_prob * alpha - &q).mean(Kind::Float);
        self.actor_opt.backward_step(&actor_loss);

        // θ' ← (1 − τ)·θ' + τ·θ.
        tch::no_grad(|| {
            let _ = self.target_flat.lerp_(&self.critic_flat, self.config.tau);
        });
        SacLosses {
            critic: mean_f32(&critic_loss),
            actor: mean_f32(&actor_loss),
            q: mean_f32(&q),
        }
    }

    /// The noise [`Sac::update`] would draw from `rng` for each of `minibatches`, in the same
    /// order (the next actions', then the actor's), as rows × action_dim values each.
    pub(crate) fn draw_noise(
        &self,
        minibatches: &[TransitionBatch],
        rng: &mut ChaCha8Rng,
    ) -> Vec<[Vec<f32>; 2]> {
        minibatches
            .iter()
            .map(|batch| {
                let rows = batch.rewards.len();
                [(); 2].map(|()| self.noise_values(rows, rng))
            })
            .collect()
    }

    /// What a stacked copy of the agent needs ([`crate::stacked::StackedSac`]); `None` for a
    /// RelaxedBernoulli actor.
    pub(crate) fn parts(&self) -> Option<SacParts<'_>> {
        let Actor::Gaussian { .. } = self.actor else {
            return None;
        };
        Some(SacParts {
            config: &self.config,
            actor_vs: &self.actor_vs,
            critic_vs: &self.critic_vs,
            scale: &self.scale,
            bias: &self.bias,
            actor_opt: &self.actor_opt,
            critic_opt: &self.critic_opt,
            target_flat: &self.target_flat,
        })
    }

    /// The optimisers and the targets' flat buffer, to write a stacked copy's state back.
    pub(crate) fn state_mut(&mut self) -> (&mut Adam, &mut Adam, &Tensor) {
        (&mut self.actor_opt, &mut self.critic_opt, &self.target_flat)
    }

    /// Writes networks and optimiser states into `dir` (the actor file and the resume files).
    pub fn save(&self, dir: &Path) -> Result<(), RlError> {
        self.save_as(dir, "sac")
    }

    /// [`Sac::save`] into the files [`checkpoint_files`]`(prefix)`, so that several agents share
    /// a checkpoint folder.
    pub fn save_as(&self, dir: &Path, prefix: &str) -> Result<(), RlError> {
        for (file, vs) in checkpoint_files(prefix).iter().zip(self.stores()) {
            let path = dir.join(file);
            vs.save(&path).map_err(|e| RlError::io(&path, e))?;
        }
        Ok(())
    }

    /// Writes only the actor (enough to execute skills).
    pub fn save_actor(&self, dir: &Path) -> Result<(), RlError> {
        let path = dir.join(ACTOR_FILE);
        self.actor_vs.save(&path).map_err(|e| RlError::io(&path, e))
    }

    /// Reads what [`Sac::save`] wrote; with `actor_only`, just the actor.
    pub fn load(&mut self, dir: &Path, actor_only: bool) -> Result<(), RlError> {
        self.load_as(dir, "sac", actor_only)
    }

    /// Reads what [`Sac::save_as`] wrote under `prefix`; with `actor_only`, just the actor.
    pub fn load_as(&mut self, dir: &Path, prefix: &str, actor_only: bool) -> Result<(), RlError> {
        let count = if actor_only { 1 } else { 5 };
        let files = checkpoint_files(prefix);
        for (file, vs) in files.iter().zip(self.stores_mut()).take(count) {
            let path = dir.join(file);
            seads_nn::load_var_store(vs, &path).map_err(|e| RlError::unreadable(&path, e))?;
        }
        Ok(())
    }

    /// The var stores in the order of [`checkpoint_files`], the actor first.
    fn stores(&self) -> [&nn::VarStore; 5] {
        [
            &self.actor_vs,
            &self.critic_vs,
            &self.target_vs,
            self.actor_opt.state(),
            self.critic_opt.state(),
        ]
    }

    fn stores_mut(&mut self) -> [&mut nn::VarStore; 5] {
        [
            &mut self.actor_vs,
            &mut self.critic_vs,
            &mut self.target_vs,
            self.actor_opt.state_mut(),
            self.critic_opt.state_mut(),
        ]
    }
}
