//! The replay buffer of the task-reward baselines: the most recent transitions in a ring, saved
//! whole in a checkpoint so that resuming is exact.

use std::path::Path;

use rand::RngExt;
use rand_chacha::ChaCha8Rng;
use tch::Tensor;

use crate::{RlError, TransitionBatch};

/// The most recent transitions, in a ring.
#[derive(Debug, Clone, PartialEq, Default)]
pub(crate) struct Replay {
    capacity: usize,
    obs_dim: usize,
    action_dim: usize,
    pub(crate) obs: Vec<f32>,
    pub(crate) actions: Vec<f32>,
    pub(crate) rewards: Vec<f32>,
    pub(crate) next_obs: Vec<f32>,
    pub(crate) dones: Vec<f32>,
    /// Where the next transition goes once the ring is full.
    next: usize,
}

impl Replay {
    pub(crate) fn new(capacity: usize, obs_dim: usize, action_dim: usize) -> Self {
        Self {
            capacity,
            obs_dim,
            action_dim,
            ..Self::default()
        }
    }

    pub(crate) fn len(&self) -> usize {
        self.rewards.len()
    }

    pub(crate) fn push(
        &mut self,
        obs: &[f32],
        action: &[f32],
        reward: f32,
        next_obs: &[f32],
        done: bool,
    ) {
        let done = if done { 1.0 } else { 0.0 };
        if self.len() < self.capacity {
            self.obs.extend_from_slice(obs);
            self.actions.extend_from_slice(action);
            self.rewards.push(reward);
            self.next_obs.extend_from_slice(next_obs);
            self.dones.push(done);
        } else {
            let (i, o, a) = (self.next, self.obs_dim, self.action_dim);
            self.obs[i * o..(i + 1) * o].copy_from_slice(obs);
            self.actions[i * a..(i + 1) * a].copy_from_slice(action);
            self.rewards[i] = reward;
            self.next_obs[i * o..(i + 1) * o].copy_from_slice(next_obs);
            self.dones[i] = done;
            self.next = (self.next + 1) % self.capacity;
        }
    }

    /// `rows` transitions drawn uniformly with replacement.
    pub(crate) fn sample(&self, rows: usize, rng: &mut ChaCha8Rng) -> TransitionBatch {
        let (o, a) = (self.obs_dim, self.action_dim);
        let mut batch = TransitionBatch::default();
        for _ in 0..rows {
            let i = rng.random_range(0..self.len());
            batch.obs.extend_from_slice(&self.obs[i * o..(i + 1) * o]);
            batch
                .actions
                .extend_from_slice(&self.actions[i * a..(i + 1) * a]);
            batch.rewards.push(self.rewards[i]);
            batch
                .next_obs
                .extend_from_slice(&self.next_obs[i * o..(i + 1) * o]);
            batch.dones.push(self.dones[i]);
        }
        batch
    }

    pub(crate) fn save(&self, path: &Path) -> Result<(), RlError> {
        let (o, a) = (self.obs_dim as i64, self.action_dim as i64);
        let tensors = [
            ("obs", Tensor::from_slice(&self.obs).view([-1, o])),
            ("actions", Tensor::from_slice(&self.actions).view([-1, a])),
            ("rewards", Tensor::from_slice(&self.rewards)),
            ("next_obs", Tensor::from_slice(&self.next_obs).view([-1, o])),
            ("dones", Tensor::from_slice(&self.dones)),
            ("next", Tensor::from_slice(&[self.next as i64])),
        ];
        Tensor::write_safetensors(&tensors, path).map_err(|e| RlError::io(path, e))
    }

    pub(crate) fn load(&mut self, path: &Path) -> Result<(), RlError> {
        let bad = |reason: String| {
            RlError::from(seads_run::RunError::Checkpoint {
                path: path.display().to_string(),
                reason,
            })
        };
        let named = Tensor::read_safetensors(path).map_err(|e| RlError::unreadable(path, e))?;
        let get = |name: &str| -> Result<&Tensor, RlError> {
            named
                .iter()
                .find(|(n, _)| n == name)
                .map(|(_, t)| t)
                .ok_or_else(|| bad(format!("no tensor {name:?}")))
        };
        let floats = |name: &str| -> Result<Vec<f32>, RlError> {
            Vec::<f32>::try_from(get(name)?.view([-1])).map_err(|e| bad(format!("{name}: {e}")))
        };
        let rewards = floats("rewards")?;
        let n = rewards.len();
        let (obs, actions, next_obs, dones) = (
            floats("obs")?,
            floats("actions")?,
            floats("next_obs")?,
            floats("dones")?,
        );
        let next =
            Vec::<i64>::try_from(get("next")?.view([-1])).map_err(|e| bad(format!("next: {e}")))?;
        let next = match next.as_slice() {
            [i] if *i >= 0 && (*i as usize) < self.capacity.max(1) => *i as usize,
            _ => return Err(bad("a bad ring position".into())),
        };
        if n > self.capacity
            || obs.len() != n * self.obs_dim
            || next_obs.len() != n * self.obs_dim
            || actions.len() != n * self.action_dim
            || dones.len() != n
        {
            return Err(bad(format!(
                "a replay buffer of another shape ({n} transitions, capacity {})",
                self.capacity
            )));
        }
        *self = Self {
            obs,
            actions,
            rewards,
            next_obs,
            dones,
            next,
            ..self.clone()
        };
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The ring keeps the most recent `capacity` transitions, and a checkpoint restores it
    /// exactly; a buffer of another shape is refused.
    #[test]
    fn the_replay_ring_keeps_the_newest_and_round_trips() {
        let mut replay = Replay::new(3, 2, 1);
        for i in 0..5 {
            let x = i as f32;
            replay.push(&[x, x], &[-x], x, &[x + 0.5, x], i == 4);
        }
        // Transitions 3 and 4 overwrote 0 and 1; the next goes where 2 is.
        assert_eq!(replay.rewards, [3.0, 4.0, 2.0]);
        assert_eq!(replay.obs, [3.0, 3.0, 4.0, 4.0, 2.0, 2.0]);
        assert_eq!(replay.dones, [0.0, 1.0, 0.0]);
        assert_eq!(replay.next, 2);
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("replay.safetensors");
        replay.save(&path).unwrap();
        let mut back = Replay::new(3, 2, 1);
        back.load(&path).unwrap();
        assert_eq!(back, replay);
        let mut other = Replay::new(3, 3, 1);
        assert!(matches!(
            other.load(&path),
            Err(RlError::Run(seads_run::RunError::Checkpoint { .. }))
        ));
    }
}
