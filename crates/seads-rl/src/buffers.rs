//! The episode buffers of training (SPEC §3.7) and what an update draws from them: the update
//! batches, their scores and relabelling (SPEC §3.6), the skill model's tuples and SAC's
//! minibatches with the reward on each episode's last transition (SPEC §3.5).

use std::collections::VecDeque;

use rand::RngExt;
use rand_chacha::ChaCha8Rng;
use seads_embodiment::EnvSpec;
use seads_games::SymbolicState;
use seads_skillmodel::{SkillModel, SkillTransition, episode_rewards, minimum_reward, relabel};

use crate::episode::policy_input;
use crate::{Episode, SeadsConfig, TrainConfig, TransitionBatch};

/// The episode buffers with what an update needs to draw from them: the long-term buffer is the
/// last `buffer_capacity` episodes, the short-term list its last `recent_episodes`.
pub(crate) struct Buffers<'a> {
    pub(crate) config: &'a TrainConfig,
    /// The run's SEADS section (of `config`).
    pub(crate) seads: &'a SeadsConfig,
    pub(crate) k: usize,
    pub(crate) episodes: &'a mut VecDeque<Episode>,
    pub(crate) rng: &'a mut ChaCha8Rng,
    /// Sees every joint relabelling (diagnostics; [`crate::Trainer::observe_relabelling`]).
    pub(crate) observer: Option<&'a mut RelabelObserver>,
}

/// Which update batch a relabelling served.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RelabelBatch {
    /// The skill model's batch (every episode may be relabelled, p = `skill_model_p`).
    SkillModel,
    /// SAC's batch (board-changing episodes only, p = `sac_p`).
    Sac,
}

/// One relabelling as training solved it: the chosen episodes' clipped log-posteriors
/// (`k` per episode, row-major), the labels they were collected with and the labels they got.
#[derive(Debug, Clone, Copy)]
pub struct Relabelling<'a> {
    /// The batch it served.
    pub batch: RelabelBatch,
    /// The number of skills.
    pub k: usize,
    /// `C_e[k]` of each chosen episode, row-major.
    pub clipped: &'a [f32],
    /// Each chosen episode's label before relabelling.
    pub labels: &'a [usize],
    /// Each chosen episode's label after relabelling.
    pub relabelled: &'a [usize],
}

/// A callback that sees each relabelling of training.
pub type RelabelObserver = dyn FnMut(&Relabelling<'_>) + Send;

impl Buffers<'_> {
    /// Updates start once the buffer holds `sampled_episodes` episodes.
    pub(crate) fn ready(&self) -> bool {
        self.episodes.len() >= self.seads.sampled_episodes
    }

    /// Appends new episodes, dropping the oldest beyond the capacity.
    pub(crate) fn push(&mut self, new: Vec<Episode>) {
        for episode in new {
            if self.episodes.len() == self.seads.buffer_capacity {
                self.episodes.pop_front();
            }
            self.episodes.push_back(episode);
        }
    }

    /// Indices of an update batch: `sampled_episodes` drawn with replacement from the long-term
    /// buffer (all of it if it holds exactly that many), followed by the recent episodes.
    fn update_batch(&mut self) -> Vec<usize> {
        let n = self.episodes.len();
        let mut batch: Vec<usize> = if n == self.seads.sampled_episodes {
            (0..n).collect()
        } else {
            (0..self.seads.sampled_episodes)
                .map(|_| self.rng.random_range(0..n))
                .collect()
        };
        batch.extend(n.saturating_sub(self.seads.recent_episodes)..n);
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
            let (c, r) = episode_rewards(row, likelihoods, &self.seads.reward);
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
        which: RelabelBatch,
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
        let new = relabel(self.seads.relabel.kind, &chosen_clipped, k, &chosen_labels);
        if let Some(observer) = self.observer.as_mut() {
            observer(&Relabelling {
                batch: which,
                k,
                clipped: &chosen_clipped,
                labels: &chosen_labels,
                relabelled: &new,
            });
        }
        for (&e, new) in chosen.iter().zip(new) {
            labels[eligible[e]] = new;
        }
        labels
    }

    /// The skill-model batch: every episode of an update batch relabelled with p = 1 (episodes
    /// that did not change the board take part), as (z_0, label, z_T) tuples.
    pub(crate) fn skill_model_batch(&mut self, model: &dyn SkillModel) -> Vec<SkillTransition> {
        let batch = self.update_batch();
        let eligible: Vec<usize> = (0..batch.len()).collect();
        let (clipped, _) = if self.seads.relabel.skill_model_p > 0.0 {
            self.score(model, &batch)
        } else {
            Default::default()
        };
        let labels = self.relabelled(
            RelabelBatch::SkillModel,
            &batch,
            &eligible,
            &clipped,
            self.seads.relabel.skill_model_p,
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
    pub(crate) fn sac_minibatches(
        &mut self,
        model: &dyn SkillModel,
        spec: &EnvSpec,
    ) -> (Vec<TransitionBatch>, f32) {
        let (config, seads) = (self.config, self.seads);
        let batch = self.update_batch();
        // Only board-changing episodes need scores: the others get the minimum reward and are
        // never relabelled.
        let eligible: Vec<usize> = (0..batch.len())
            .filter(|&j| self.episodes[batch[j]].changed())
            .collect();
        let changed: Vec<usize> = eligible.iter().map(|&j| batch[j]).collect();
        let (clipped, rewards) = self.score(model, &changed);
        let labels = self.relabelled(
            RelabelBatch::Sac,
            &batch,
            &eligible,
            &clipped,
            seads.relabel.sac_p,
        );
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
        let minibatches = (0..seads.updates_per_epoch)
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

#[cfg(test)]
mod tests {
    use std::path::Path;

    use rand::SeedableRng;
    use seads_skillmodel::SkillModelError;

    use super::*;

    /// A skill model that explains move m by skill m: log q(z_T | z_0, k) = 0 when z_T is z_0
    /// with bit k flipped, −10 otherwise.
    struct MoveIsSkill {
        k: usize,
    }

    impl SkillModel for MoveIsSkill {
        fn num_skills(&self) -> usize {
            self.k
        }
        fn scores(&self, pairs: &[(SymbolicState, SymbolicState)]) -> Vec<f32> {
            pairs
                .iter()
                .flat_map(|&(z0, zt)| {
                    (0..self.k).map(move |k| {
                        if (z0 ^ zt) == SymbolicState::from_u64(1 << k) {
                            0.0
                        } else {
                            -10.0
                        }
                    })
                })
                .collect()
        }
        fn scores_are_likelihoods(&self) -> bool {
            true
        }
        fn train_step(&mut self, _: &[SkillTransition]) -> f32 {
            0.0
        }
        fn save(&self, _: &Path) -> Result<(), SkillModelError> {
            Ok(())
        }
        fn load(&mut self, _: &Path, _: bool) -> Result<(), SkillModelError> {
            Ok(())
        }
    }

    /// An episode of `skill` with observations `first, first + 1, …` (one value each) and actions
    /// 0.1, 0.2, …; it flips bit `moved` of the board, or none.
    fn episode(skill: usize, steps: usize, first: f32, moved: Option<usize>) -> Episode {
        let z0 = SymbolicState::from_u64(0b100);
        Episode {
            skill,
            obs: (0..=steps).map(|t| first + t as f32).collect(),
            actions: (1..=steps).map(|t| t as f32 / 10.0).collect(),
            z0,
            zt: moved.map_or(z0, |m| z0 ^ SymbolicState::from_u64(1 << m)),
            game_move: moved,
        }
    }

    fn config(sampled: usize, recent: usize, capacity: usize) -> TrainConfig {
        let mut config = TrainConfig::default();
        config
            .edit(|seads: &mut SeadsConfig| {
                seads.sampled_episodes = sampled;
                seads.recent_episodes = recent;
                seads.buffer_capacity = capacity;
                seads.relabel.sac_p = 1.0;
            })
            .unwrap();
        config
    }

    /// Buffers of K = 2 skills over `episodes`.
    fn buffers<'a>(
        config: &'a TrainConfig,
        seads: &'a SeadsConfig,
        episodes: &'a mut VecDeque<Episode>,
        rng: &'a mut ChaCha8Rng,
    ) -> Buffers<'a> {
        Buffers {
            config,
            seads,
            k: 2,
            episodes,
            rng,
            observer: None,
        }
    }

    fn spec() -> EnvSpec {
        let mut spec = seads_embodiment::make_env("lightsout-cursor", &Default::default())
            .unwrap()
            .spec()
            .clone();
        (spec.obs_dim, spec.action_dim) = (1, 1);
        spec
    }

    #[test]
    fn the_oldest_episodes_are_evicted_and_updates_wait_for_a_full_batch() {
        let config = config(3, 1, 3);
        let (mut episodes, mut rng) = (VecDeque::new(), ChaCha8Rng::seed_from_u64(0));
        let seads = config.seads().unwrap();
        let mut buffers = buffers(&config, &seads, &mut episodes, &mut rng);
        buffers.push((0..2).map(|s| episode(s, 1, 0.0, None)).collect());
        assert!(!buffers.ready());
        buffers.push((2..5).map(|s| episode(s, 1, 0.0, None)).collect());
        assert!(buffers.ready());
        let skills: Vec<usize> = buffers.episodes.iter().map(|e| e.skill).collect();
        assert_eq!(skills, [2, 3, 4]);
        // A buffer of exactly `sampled_episodes` is taken whole, then the recent tail.
        assert_eq!(buffers.update_batch(), [0, 1, 2, 2]);
    }

    /// The SAC rows by hand: [s_t, onehot(final label)], the action, reward 0 and done 0 except
    /// on an episode's last transition, which carries the episode's reward and done 1.
    #[test]
    fn only_the_last_transition_carries_the_reward() {
        let config = config(2, 1, 8);
        let mut episodes: VecDeque<Episode> =
            [episode(0, 2, 10.0, Some(0)), episode(1, 1, 20.0, None)].into();
        let mut rng = ChaCha8Rng::seed_from_u64(0);
        let seads = config.seads().unwrap();
        let buffers = buffers(&config, &seads, &mut episodes, &mut rng);
        let rows = buffers.transition_batch(
            &spec(),
            &[0, 1],
            &[1, 0],
            &[5.0, -7.0],
            &[(0, 0), (0, 1), (1, 0)],
        );
        assert_eq!(rows.obs, [10.0, 0.0, 1.0, 11.0, 0.0, 1.0, 20.0, 1.0, 0.0]);
        assert_eq!(
            rows.next_obs,
            [11.0, 0.0, 1.0, 12.0, 0.0, 1.0, 21.0, 1.0, 0.0]
        );
        assert_eq!(rows.actions, [0.1, 0.2, 0.1]);
        assert_eq!(rows.rewards, [0.0, 5.0, -7.0]);
        assert_eq!(rows.dones, [0.0, 1.0, 1.0]);
    }

    /// Rewards by hand (K = 2, the model explains move 0 by skill 0): the board-changing episode
    /// gets R_0 = clipped log posterior (−log(1 + e^−10)) minus the runner-up (clipped to
    /// −2 log 2) plus the novelty bonus (0: skill 0 explains it); the episode that changed
    /// nothing is not eligible and gets the minimum reward −2 log 2.
    #[test]
    fn only_board_changing_episodes_are_scored_and_relabelled() {
        let mut config = config(2, 1, 8);
        config.sac.batch_size = 64;
        config
            .edit(|s: &mut SeadsConfig| s.updates_per_epoch = 1)
            .unwrap();
        let mut episodes: VecDeque<Episode> =
            [episode(0, 2, 10.0, Some(0)), episode(1, 1, 20.0, None)].into();
        let mut rng = ChaCha8Rng::seed_from_u64(0);
        let seads = config.seads().unwrap();
        let mut buffers = buffers(&config, &seads, &mut episodes, &mut rng);
        let (minibatches, mean_reward) = buffers.sac_minibatches(&MoveIsSkill { k: 2 }, &spec());
        let r0 = -(1.0f64 + (-10.0f64).exp()).ln() + 2.0 * 2f64.ln();
        let minimum = -2.0 * 2f64.ln();
        // The batch is both episodes, then the recent one (the second) again.
        let expected_mean = (r0 + 2.0 * minimum) / 3.0;
        assert!(
            (f64::from(mean_reward) - expected_mean).abs() < 1e-6,
            "{mean_reward}"
        );
        let rows = &minibatches[0];
        for (row, &reward) in rows.rewards.iter().enumerate() {
            let first_obs = rows.obs[row * 3];
            let expected = match first_obs as i32 {
                10 => 0.0,
                11 => r0,
                20 => minimum,
                other => panic!("no transition starts at {other}"),
            };
            assert!((f64::from(reward) - expected).abs() < 1e-6, "row {row}");
        }
    }

    /// The skill model's tuples after relabelling with p = 1: the batch is both episodes and the
    /// recent one (the second) again, labels {1, 0, 0}. The first episode made move 0 and gets
    /// label 0; the one label 1 goes to a copy of the second, which made move 1.
    #[test]
    fn the_skill_model_batch_swaps_labels_to_the_moves_they_explain() {
        let config = config(2, 1, 8);
        let mut episodes: VecDeque<Episode> =
            [episode(1, 1, 0.0, Some(0)), episode(0, 1, 0.0, Some(1))].into();
        let mut rng = ChaCha8Rng::seed_from_u64(0);
        let seads = config.seads().unwrap();
        let mut buffers = buffers(&config, &seads, &mut episodes, &mut rng);
        let tuples = buffers.skill_model_batch(&MoveIsSkill { k: 2 });
        let mut labels: Vec<usize> = tuples.iter().map(|t| t.skill).collect();
        assert_eq!(labels[0], 0);
        labels[1..].sort_unstable();
        assert_eq!(labels, [0, 0, 1]);
    }
}
