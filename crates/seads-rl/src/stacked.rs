//! SAC for the members of a population at once (issue: populations on a GPU): the members'
//! actors, critics and targets stacked into `[K, …]` weights with one batched product per layer
//! ([`seads_nn::StackedMlp`]), one optimiser step per network for all members, each member with
//! its own α, γ, τ and learning rate. An epoch's minibatches and noise go to the device at once
//! and its losses come back at once.
//!
//! A stacked update is the solo update ([`Sac::update_with_noise`]) member by member, with the
//! same noise drawn from the member's own stream; only the batched products round differently,
//! so a stacked member follows its solo run closely, not bit for bit. The state is stacked from
//! the members' own agents and written back into them ([`StackedSac::unstack_into`]), where
//! collection, evaluation and checkpoints read it.

use seads_nn::{
    StackedAdam, StackedLinear, StackedMlp, StackedParameters, parameter_layout, upload,
};
use tch::{Device, Kind, Tensor};

use crate::sac::{LOG_STD_MAX, LOG_STD_MIN, squashed_gaussian};
use crate::{RlError, Sac, SacLosses, TransitionBatch};

/// One member's SAC work of an epoch: its minibatches and, per minibatch, the noise of the next
/// actions and of the actor's actions ([`Sac::draw_noise`]).
#[derive(Debug, Default)]
pub(crate) struct SacWork {
    pub minibatches: Vec<TransitionBatch>,
    pub noise: Vec<[Vec<f32>; 2]>,
}

/// The Gaussian-actor SAC agents of K members, stacked on one device.
pub(crate) struct StackedSac {
    device: Device,
    input_dim: i64,
    action_dim: i64,
    /// Per member, `[K, 1, 1]`.
    alpha: Tensor,
    gamma: Tensor,
    /// Per member, `[K, 1]`.
    tau: Tensor,
    scale: Tensor,
    bias: Tensor,
    actor: StackedAdam,
    critic: StackedAdam,
    target: StackedParameters,
    mean: StackedMlp,
    log_std: StackedLinear,
    q: [StackedMlp; 2],
    q_target: [StackedMlp; 2],
}

impl StackedSac {
    /// Stacks `members` (Gaussian actors of equal shapes) onto `device`.
    pub fn stack(members: &[&Sac], device: Device) -> Result<Self, RlError> {
        let parts = members
            .iter()
            .map(|m| m.parts())
            .collect::<Option<Vec<_>>>()
            .ok_or_else(|| RlError::config("only Gaussian SAC actors can be stacked"))?;
        let first = parts
            .first()
            .ok_or_else(|| RlError::config("nothing to stack"))?;
        let actor_layout = parameter_layout(first.actor_vs);
        let critic_layout = parameter_layout(first.critic_vs);
        for (member, p) in members.iter().zip(&parts) {
            if parameter_layout(p.actor_vs) != actor_layout
                || parameter_layout(p.critic_vs) != critic_layout
                || member.input_dim() != members[0].input_dim()
                || !p.scale.equal(first.scale)
                || !p.bias.equal(first.bias)
            {
                return Err(RlError::config(
                    "stacked SAC agents must have networks of the same shapes and the same \
                     action box",
                ));
            }
        }
        let per_member = |f: fn(&crate::SacConfig) -> f64, shape: &[i64]| {
            let values: Vec<f32> = parts.iter().map(|p| f(p.config) as f32).collect();
            upload(&values, shape, device)
        };
        let k = members.len() as i64;
        let actor_opts: Vec<&seads_nn::Adam> = parts.iter().map(|p| p.actor_opt).collect();
        let critic_opts: Vec<&seads_nn::Adam> = parts.iter().map(|p| p.critic_opt).collect();
        let targets: Vec<&Tensor> = parts.iter().map(|p| p.target_flat).collect();
        let actor = StackedAdam::stack(&actor_opts, &actor_layout, device);
        let critic = StackedAdam::stack(&critic_opts, &critic_layout, device);
        let target = StackedParameters::stack(&targets, &critic_layout, device, false);
        let missing = || RlError::config("a SAC agent without its networks");
        let mlp = |params: &StackedParameters, name: &str| {
            StackedMlp::new(params, name).ok_or_else(missing)
        };
        Ok(Self {
            device,
            input_dim: members[0].input_dim() as i64,
            action_dim: members[0].action_dim() as i64,
            alpha: per_member(|c| c.alpha, &[k, 1, 1]),
            gamma: per_member(|c| c.gamma, &[k, 1, 1]),
            tau: per_member(|c| c.tau, &[k, 1]),
            scale: first.scale.to_device(device),
            bias: first.bias.to_device(device),
            mean: mlp(actor.parameters(), "actor")?,
            log_std: StackedLinear::new(actor.parameters(), "actor_log_std").ok_or_else(missing)?,
            q: [
                mlp(critic.parameters(), "q1")?,
                mlp(critic.parameters(), "q2")?,
            ],
            q_target: [mlp(&target, "q1")?, mlp(&target, "q2")?],
            actor,
            critic,
            target,
        })
    }

    /// Number of members.
    pub fn members(&self) -> usize {
        self.target.members()
    }

    /// A reparameterised sample of the tanh-squashed Gaussian and its log-probability, per
    /// member (`[K, B, ·]`), as [`Sac`] samples.
    fn sample(&self, x: &Tensor, noise: &Tensor) -> (Tensor, Tensor) {
        let h = self.mean.features(x);
        let mean = self.mean.head().forward(&h);
        let log_std = self.log_std.forward(&h).clamp(LOG_STD_MIN, LOG_STD_MAX);
        squashed_gaussian(&mean, &log_std, noise, &self.scale, &self.bias)
    }

    fn min_q(q: &[StackedMlp; 2], x: &Tensor, a: &Tensor) -> Tensor {
        let xa = Tensor::cat(&[x, a], 2);
        q[0].forward(&xa).minimum(&q[1].forward(&xa))
    }

    /// The members' SAC steps of an epoch, `work[k]` being member k's; returns each member's
    /// mean losses. Every member must bring as many minibatches of as many rows.
    pub fn update_epoch(&mut self, work: &[SacWork]) -> Result<Vec<SacLosses>, RlError> {
        let k = self.members();
        let updates = work.first().map_or(0, |w| w.minibatches.len());
        let rows = work
            .first()
            .and_then(|w| w.minibatches.first())
            .map_or(0, |b| b.rewards.len());
        let uneven = work.len() != k
            || work.iter().any(|w| {
                w.minibatches.len() != updates
                    || w.noise.len() != updates
                    || w.minibatches.iter().any(|b| b.rewards.len() != rows)
            });
        if uneven {
            return Err(RlError::config(
                "the members of a stacked population must take as many SAC steps on minibatches \
                 of as many transitions (seads.updates_per_epoch, sac.batch_size)",
            ));
        }
        if updates == 0 {
            return Ok(vec![SacLosses::default(); k]);
        }
        // Every field of every minibatch of every member, in one upload per field:
        // [updates, K, rows, width].
        let field = |width: i64, pick: &dyn Fn(&SacWork, usize) -> &[f32]| {
            let mut values = Vec::new();
            for u in 0..updates {
                for w in work {
                    values.extend_from_slice(pick(w, u));
                }
            }
            upload(
                &values,
                &[updates as i64, k as i64, rows as i64, width],
                self.device,
            )
        };
        let (i, a) = (self.input_dim, self.action_dim);
        let obs = field(i, &|w, u| &w.minibatches[u].obs);
        let actions = field(a, &|w, u| &w.minibatches[u].actions);
        let rewards = field(1, &|w, u| &w.minibatches[u].rewards);
        let next_obs = field(i, &|w, u| &w.minibatches[u].next_obs);
        let dones = field(1, &|w, u| &w.minibatches[u].dones);
        let next_noise = field(a, &|w, u| &w.noise[u][0]);
        let policy_noise = field(a, &|w, u| &w.noise[u][1]);
        let mut losses = Vec::with_capacity(updates);
        for u in 0..updates as i64 {
            losses.push(self.update(
                &obs.get(u),
                &actions.get(u),
                &rewards.get(u),
                &next_obs.get(u),
                &dones.get(u),
                &next_noise.get(u),
                &policy_noise.get(u),
            ));
        }
        // [K, 3] means over the epoch's updates, read off the device once.
        let means = Tensor::stack(&losses, 0)
            .mean_dim([0].as_slice(), false, Kind::Float)
            .to_device(Device::Cpu);
        let means = Vec::<f32>::try_from(means.view([-1])).expect("float losses");
        Ok(means
            .chunks(3)
            .map(|l| SacLosses {
                critic: l[0],
                actor: l[1],
                q: l[2],
            })
            .collect())
    }

    /// One step of every member ([`Sac::update_with_noise`] per member); returns the members'
    /// losses, `[K, 3]` (critic, actor, mean min-Q).
    #[allow(clippy::too_many_arguments)] // the fields of a stacked minibatch
    fn update(
        &mut self,
        obs: &Tensor,
        actions: &Tensor,
        rewards: &Tensor,
        next_obs: &Tensor,
        dones: &Tensor,
        next_noise: &Tensor,
        policy_noise: &Tensor,
    ) -> Tensor {
        let per_member = |t: Tensor| t.mean_dim([1, 2].as_slice(), false, Kind::Float);
        let target = tch::no_grad(|| {
            let (next_action, next_log_prob) = self.sample(next_obs, next_noise);
            let soft_q =
                Self::min_q(&self.q_target, next_obs, &next_action) - next_log_prob * &self.alpha;
            rewards + (1.0 - dones) * &self.gamma * soft_q
        });
        let xa = Tensor::cat(&[obs, actions], 2);
        let critic_loss = per_member((self.q[0].forward(&xa) - &target).square())
            + per_member((self.q[1].forward(&xa) - &target).square());
        self.critic.backward_step(&critic_loss.sum(Kind::Float));

        let (new_action, log_prob) = self.sample(obs, policy_noise);
        let q = Self::min_q(&self.q, obs, &new_action);
        let actor_loss = per_member(log_prob * &self.alpha - &q);
        self.actor.backward_step(&actor_loss.sum(Kind::Float));

        tch::no_grad(|| {
            let _ = self
                .target
                .flat()
                .shallow_clone()
                .lerp_tensor_(self.critic.parameters().flat(), &self.tau);
            Tensor::stack(&[critic_loss, actor_loss, per_member(q)], 1)
        })
    }

    /// Writes the members' actors into `members` (enough to collect and evaluate with them).
    pub fn unstack_actors(&self, members: &mut [&mut Sac]) {
        let targets: Vec<Tensor> = members
            .iter_mut()
            .map(|m| m.state_mut().0.parameters().shallow_clone())
            .collect();
        let targets: Vec<&Tensor> = targets.iter().collect();
        self.actor.parameters().unstack_into(&targets);
    }

    /// Writes the members' whole state (networks, optimisers, targets) into `members`.
    pub fn unstack_into(&self, members: &mut [&mut Sac]) {
        let mut actors = Vec::new();
        let mut critics = Vec::new();
        let mut targets = Vec::new();
        for member in members.iter_mut() {
            let (actor, critic, target) = member.state_mut();
            targets.push(target.shallow_clone());
            actors.push(actor);
            critics.push(critic);
        }
        self.actor.unstack_into(&mut actors);
        self.critic.unstack_into(&mut critics);
        let targets: Vec<&Tensor> = targets.iter().collect();
        self.target.unstack_into(&targets);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// Three agents of different seeds, α, γ, τ and learning rates: six stacked steps (two
    /// epochs) follow each agent's own steps with the same noise to rounding, and the state
    /// written back is what the agents hold after their own steps.
    #[test]
    fn stacked_steps_follow_each_agents_own() {
        let (input, low, high) = (6, [-1.0f32, -0.5], [1.0f32, 0.5]);
        let configs: Vec<crate::SacConfig> = (0..3)
            .map(|k| crate::SacConfig {
                hidden: vec![16, 16],
                lr: [3e-4, 1e-3, 3e-3][k],
                alpha: [0.1, 0.01, 0.2][k],
                gamma: [0.99, 0.9, 0.95][k],
                tau: [0.005, 0.05, 0.5][k],
                batch_size: 8,
            })
            .collect();
        let agents = |device| -> Vec<Sac> {
            (0..3)
                .map(|k| Sac::new(input, &low, &high, &configs[k], device, 10 + k as u64))
                .collect()
        };
        let mut data = ChaCha8Rng::seed_from_u64(3);
        let mut batch = |rows: usize| {
            let mut v = |n: usize| -> Vec<f32> {
                (0..n).map(|_| data.random_range(-1.0f32..1.0)).collect()
            };
            TransitionBatch {
                obs: v(rows * input),
                actions: v(rows * 2),
                rewards: v(rows),
                next_obs: v(rows * input),
                dones: (0..rows).map(|r| (r % 3 == 0) as u8 as f32).collect(),
            }
        };
        let mut solo = agents(Device::Cpu);
        let mut copies = agents(Device::Cpu);
        let mut streams: Vec<ChaCha8Rng> = (0..3).map(ChaCha8Rng::seed_from_u64).collect();
        let refs: Vec<&Sac> = copies.iter().collect();
        let mut stacked = StackedSac::stack(&refs, Device::Cpu).unwrap();
        for _epoch in 0..2 {
            let mut work = Vec::new();
            for (agent, rng) in solo.iter_mut().zip(&mut streams) {
                let minibatches: Vec<TransitionBatch> = (0..3).map(|_| batch(8)).collect();
                let noise = agent.draw_noise(&minibatches, &mut rng.clone());
                for minibatch in &minibatches {
                    agent.update(minibatch, rng);
                }
                work.push(SacWork { minibatches, noise });
            }
            let losses = stacked.update_epoch(&work).unwrap();
            assert!(
                losses
                    .iter()
                    .all(|l| l.critic.is_finite() && l.critic > 0.0)
            );
        }
        let mut targets: Vec<&mut Sac> = copies.iter_mut().collect();
        stacked.unstack_into(&mut targets);
        for (ours, theirs) in copies.iter().zip(&solo) {
            let (a, b) = (ours.parts().unwrap(), theirs.parts().unwrap());
            for (x, y) in [
                (a.actor_opt.parameters(), b.actor_opt.parameters()),
                (a.critic_opt.parameters(), b.critic_opt.parameters()),
                (a.target_flat, b.target_flat),
                (a.critic_opt.moments().1, b.critic_opt.moments().1),
            ] {
                let diff = f64::try_from((x - y).abs().max()).unwrap();
                assert!(diff < 1e-5, "{diff}");
            }
            assert_eq!(a.actor_opt.steps_taken(), 6.0);
            let inputs = [0.1f32, -0.2, 0.3, 0.0, 0.5, -0.7];
            let (x, y) = (ours.act(&inputs, None), theirs.act(&inputs, None));
            assert!(
                x.iter().zip(&y).all(|(x, y)| (x - y).abs() < 1e-5),
                "{x:?} {y:?}"
            );
        }
        // Minibatches of other sizes are refused, not stacked.
        let uneven = vec![
            SacWork {
                minibatches: vec![batch(8)],
                noise: vec![[vec![0.0; 16], vec![0.0; 16]]],
            },
            SacWork {
                minibatches: vec![batch(4)],
                noise: vec![[vec![0.0; 8], vec![0.0; 8]]],
            },
            SacWork::default(),
        ];
        assert!(stacked.update_epoch(&uneven).is_err());
    }
}
