//! Soft actor-critic (SPEC §3.2): tanh-squashed Gaussian policy, twin Q critics with
//! Polyak-averaged targets, a fixed entropy temperature α, Adam.

use std::path::Path;

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};
use seads_skillmodel::nn::{Adam, Mlp, flatten_parameters, mean_f32, xavier_linear};
use serde::{Deserialize, Serialize};
use tch::nn::{self, Module};
use tch::{Device, Kind, Tensor};

use crate::RlError;

/// SAC hyper-parameters. `Default` = the reference's SEADS settings (Cursor α).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SacConfig {
    /// Hidden layer sizes of actor and critics (reference code: [256, 256]; the paper's table
    /// says 512).
    pub hidden: Vec<i64>,
    /// Adam learning rate of actor and critics.
    pub lr: f64,
    /// Discount γ.
    pub gamma: f64,
    /// Polyak coefficient τ of the target critics.
    pub tau: f64,
    /// Fixed entropy temperature α.
    pub alpha: f64,
    /// Transitions per gradient step.
    pub batch_size: usize,
    /// Gradient steps per epoch.
    pub updates_per_epoch: usize,
}

impl Default for SacConfig {
    fn default() -> Self {
        Self {
            hidden: vec![256, 256],
            lr: 3e-4,
            gamma: 0.99,
            tau: 0.005,
            alpha: 0.1,
            batch_size: 128,
            updates_per_epoch: 16,
        }
    }
}

impl SacConfig {
    /// Checks the values.
    pub fn validate(&self) -> Result<(), RlError> {
        let bad = |m: String| Err(RlError::Config(m));
        if self.hidden.is_empty() || self.hidden.iter().any(|&h| h <= 0) {
            return bad(format!(
                "sac.hidden must be positive layer sizes, got {:?}",
                self.hidden
            ));
        }
        let positive = |name: &str, v: f64| {
            if v > 0.0 && v.is_finite() {
                Ok(())
            } else {
                bad(format!("sac.{name} must be positive, got {v}"))
            }
        };
        positive("lr", self.lr)?;
        positive("alpha", self.alpha)?;
        if !(0.0..=1.0).contains(&self.gamma) {
            return bad(format!("sac.gamma must lie in [0, 1], got {}", self.gamma));
        }
        if !(self.tau > 0.0 && self.tau <= 1.0) {
            return bad(format!("sac.tau must lie in (0, 1], got {}", self.tau));
        }
        if self.batch_size == 0 {
            return bad("sac.batch_size must be at least 1".into());
        }
        Ok(())
    }
}

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

/// The actor: an MLP trunk with a mean head and a log σ head.
#[derive(Debug)]
struct Actor {
    mean: Mlp,
    log_std: nn::Linear,
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

/// The checkpoint file of the actor: all that executing skills needs.
pub const ACTOR_FILE: &str = "sac_actor.safetensors";
/// The other checkpoint files of SAC (critics, targets, optimiser states): what resuming needs.
pub const RESUME_FILES: [&str; 4] = [
    "sac_critic.safetensors",
    "sac_target.safetensors",
    "sac_actor_adam.safetensors",
    "sac_critic_adam.safetensors",
];

const LOG_STD_MIN: f64 = -20.0;
const LOG_STD_MAX: f64 = 2.0;

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
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let action_dim = low.len();
        let (i, a) = (input_dim as i64, action_dim as i64);
        let actor_vs = nn::VarStore::new(device);
        let mean = Mlp::new(&(actor_vs.root() / "actor"), i, &config.hidden, a, &mut rng);
        let last = *config.hidden.last().expect("validated");
        let log_std = xavier_linear(&(actor_vs.root() / "actor_log_std"), last, a, &mut rng);
        // Twin critics (their targets are initialised the same way, then overwritten by a copy).
        let twin_critics = |vs: &nn::VarStore, rng: &mut ChaCha8Rng| {
            ["q1", "q2"].map(|name| Mlp::new(&(vs.root() / name), i + a, &config.hidden, 1, rng))
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
            actor: Actor { mean, log_std },
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

    fn gaussian<R: Rng + ?Sized>(&self, rows: usize, rng: &mut R) -> Tensor {
        let noise: Vec<f32> = (0..rows * self.action_dim)
            .map(|_| StandardNormal.sample(rng))
            .collect();
        self.tensor(&noise, self.action_dim)
    }

    /// Mean and log σ of the pre-squash Gaussian.
    fn distribution(&self, x: &Tensor) -> (Tensor, Tensor) {
        let h = self.actor.mean.features(x);
        (
            self.actor.mean.head().forward(&h),
            self.actor
                .log_std
                .forward(&h)
                .clamp(LOG_STD_MIN, LOG_STD_MAX),
        )
    }

    /// A reparameterised sample a = tanh(mean + σ·ε)·scale + bias and its log-probability.
    fn sample(&self, x: &Tensor, noise: &Tensor) -> (Tensor, Tensor) {
        let (mean, log_std) = self.distribution(x);
        let u = &mean + log_std.exp() * noise;
        let t = u.tanh();
        let action = &t * &self.scale + &self.bias;
        let log_normal = noise.square() * -0.5 - &log_std - 0.5 * (2.0 * std::f64::consts::PI).ln();
        let one_minus_t2: Tensor = 1.0 - t.square();
        let squash = (&self.scale * one_minus_t2 + 1e-6).log();
        let log_prob = (log_normal - squash).sum_dim_intlist(1, true, Kind::Float);
        (action, log_prob)
    }

    /// Actions for a batch of inputs (rows of `input_dim`): sampled from the policy with noise
    /// from `rng`, or deterministic (tanh of the mean) when `rng` is `None`.
    pub fn act(&self, inputs: &[f32], rng: Option<&mut ChaCha8Rng>) -> Vec<f32> {
        tch::no_grad(|| {
            let x = self.tensor(inputs, self.input_dim);
            let action = match rng {
                Some(rng) => {
                    let noise = self.gaussian(inputs.len() / self.input_dim, rng);
                    self.sample(&x, &noise).0
                }
                None => self.distribution(&x).0.tanh() * &self.scale + &self.bias,
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
        let next_noise = self.gaussian(rows, rng);
        let policy_noise = self.gaussian(rows, rng);
        self.update_with_noise(batch, &next_noise, &policy_noise)
    }

    /// [`Sac::update`] with given standard-normal noise (rows × action_dim each): for the next
    /// actions of the target and for the actor's reparameterised actions.
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

    /// Writes networks and optimiser states into `dir` (the actor file and the resume files).
    pub fn save(&self, dir: &Path) -> Result<(), RlError> {
        for (file, vs) in self.stores() {
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
        let count = if actor_only { 1 } else { 5 };
        for (file, vs) in self.stores_mut().into_iter().take(count) {
            let path = dir.join(file);
            vs.load(&path).map_err(|e| RlError::unreadable(&path, e))?;
        }
        Ok(())
    }

    /// The var stores and their files, the actor first.
    fn stores(&self) -> [(&'static str, &nn::VarStore); 5] {
        [
            (ACTOR_FILE, &self.actor_vs),
            (RESUME_FILES[0], &self.critic_vs),
            (RESUME_FILES[1], &self.target_vs),
            (RESUME_FILES[2], self.actor_opt.state()),
            (RESUME_FILES[3], self.critic_opt.state()),
        ]
    }

    fn stores_mut(&mut self) -> [(&'static str, &mut nn::VarStore); 5] {
        [
            (ACTOR_FILE, &mut self.actor_vs),
            (RESUME_FILES[0], &mut self.critic_vs),
            (RESUME_FILES[1], &mut self.target_vs),
            (RESUME_FILES[2], self.actor_opt.state_mut()),
            (RESUME_FILES[3], self.critic_opt.state_mut()),
        ]
    }
}
