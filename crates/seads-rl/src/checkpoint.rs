//! The training state in a checkpoint folder beyond the networks: the episode buffer as a typed
//! table, the prepared next updates, and the names of every checkpoint file. Every error names
//! the file, and sizes read from a file are checked before use.

use std::collections::VecDeque;
use std::path::Path;

use seads_games::SymbolicState;
use tch::{Kind, Tensor};

use crate::{Episode, RlError, TransitionBatch};

pub use seads_run::store::{ENVIRONMENT_FILE, EPISODES_FILE, PREPARED_FILE, PROGRESS_FILE};

/// Every file of a checkpoint that only resuming needs (evaluation needs the actor and the
/// skill model's parameters): they are dropped from all but the two newest checkpoints.
pub fn resume_only_files() -> Vec<&'static str> {
    crate::sac::RESUME_FILES
        .iter()
        .chain(&seads_skillmodel::OPTIMISER_FILES)
        .chain(&[
            EPISODES_FILE,
            PREPARED_FILE,
            PROGRESS_FILE,
            ENVIRONMENT_FILE,
        ])
        .copied()
        .collect()
}

/// Writes the episodes as a table: one row per episode in `lengths`, `skills`, `moves` (−1: no
/// move), `z0` and `zt` (the symbolic states' 64-bit words, [`SymbolicState::WORDS`] a row;
/// `seads migrate` widens the three-word tables of older versions), and the steps of all
/// episodes concatenated in `obs` (T + 1 rows each) and `actions` (T rows each).
pub fn save_episodes(
    path: &Path,
    episodes: &VecDeque<Episode>,
    action_dim: usize,
) -> Result<(), RlError> {
    let column = |f: &dyn Fn(&Episode) -> i64| -> Tensor {
        Tensor::from_slice(&episodes.iter().map(f).collect::<Vec<i64>>())
    };
    let words = |f: &dyn Fn(&Episode) -> SymbolicState| -> Tensor {
        let values: Vec<i64> = episodes
            .iter()
            .flat_map(|e| f(e).words().map(|w| w as i64))
            .collect();
        Tensor::from_slice(&values).view([-1, SymbolicState::WORDS as i64])
    };
    let floats = |f: &dyn Fn(&Episode) -> &[f32]| -> Tensor {
        Tensor::from_slice(
            &episodes
                .iter()
                .flat_map(|e| f(e).iter().copied())
                .collect::<Vec<f32>>(),
        )
    };
    let tensors = [
        ("lengths", column(&|e| e.len(action_dim) as i64)),
        ("skills", column(&|e| e.skill as i64)),
        ("moves", column(&|e| e.game_move.map_or(-1, |m| m as i64))),
        ("z0", words(&|e| e.z0)),
        ("zt", words(&|e| e.zt)),
        ("obs", floats(&|e| &e.obs)),
        ("actions", floats(&|e| &e.actions)),
    ];
    Tensor::write_safetensors(&tensors, path).map_err(|e| RlError::io(path, e))
}

/// Reads what [`save_episodes`] wrote, for observations of `obs_dim`, actions of `action_dim`
/// and `k` skills.
pub fn load_episodes(
    path: &Path,
    obs_dim: usize,
    action_dim: usize,
    k: usize,
) -> Result<VecDeque<Episode>, RlError> {
    let file = TensorFile::read(path)?;
    let mismatch = || file.corrupt("episode table does not match the environment".into());
    let (obs, actions) = (file.floats("obs")?, file.floats("actions")?);
    let (lengths, skills, moves) = (
        file.ints("lengths")?,
        file.ints("skills")?,
        file.ints("moves")?,
    );
    let (z0, zt) = (file.ints("z0")?, file.ints("zt")?);
    let n = lengths.len();
    let width = SymbolicState::WORDS;
    if skills.len() != n || moves.len() != n || z0.len() != width * n || zt.len() != width * n {
        return Err(mismatch());
    }
    let state = |words: &[i64], i: usize| {
        let mut state = [0u64; SymbolicState::WORDS];
        for (w, &word) in state.iter_mut().zip(&words[width * i..width * (i + 1)]) {
            *w = word as u64;
        }
        SymbolicState::from_words(state)
    };
    let (mut po, mut pa) = (0usize, 0usize);
    let mut episodes = VecDeque::with_capacity(n);
    for i in 0..n {
        // Lengths and labels are checked against the data before they are used: no negative or
        // overflowing lengths, no label beyond K.
        let len = usize::try_from(lengths[i]).map_err(|_| mismatch())?;
        let skill = usize::try_from(skills[i])
            .ok()
            .filter(|&s| s < k)
            .ok_or_else(mismatch)?;
        let obs_end = len
            .checked_add(1)
            .and_then(|rows| rows.checked_mul(obs_dim))
            .and_then(|values| values.checked_add(po))
            .filter(|&end| end <= obs.len())
            .ok_or_else(mismatch)?;
        let act_end = len
            .checked_mul(action_dim)
            .and_then(|values| values.checked_add(pa))
            .filter(|&end| end <= actions.len())
            .ok_or_else(mismatch)?;
        episodes.push_back(Episode {
            skill,
            obs: obs[po..obs_end].to_vec(),
            actions: actions[pa..act_end].to_vec(),
            z0: state(&z0, i),
            zt: state(&zt, i),
            game_move: usize::try_from(moves[i]).ok(),
        });
        (po, pa) = (obs_end, act_end);
    }
    if po != obs.len() || pa != actions.len() {
        return Err(file.corrupt("trailing episode data".into()));
    }
    Ok(episodes)
}

/// The tensors of a checkpoint file, by name; every error names the file.
pub(crate) struct TensorFile<'a> {
    path: &'a Path,
    tensors: Vec<(String, Tensor)>,
}

impl<'a> TensorFile<'a> {
    fn read(path: &'a Path) -> Result<Self, RlError> {
        let tensors = Tensor::read_safetensors(path).map_err(|e| RlError::unreadable(path, e))?;
        Ok(Self { path, tensors })
    }

    fn corrupt(&self, reason: String) -> RlError {
        RlError::from(seads_run::RunError::Checkpoint {
            path: self.path.display().to_string(),
            reason,
        })
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

/// An epoch's skill-model update done and its SAC minibatches relabelled, ready for SAC: part
/// of a checkpoint when the run stopped between preparing and using them.
#[derive(Debug)]
pub(crate) struct Prepared {
    pub(crate) minibatches: Vec<TransitionBatch>,
    pub(crate) mean_reward: f32,
    pub(crate) skill_model_loss: f32,
}

impl Prepared {
    /// Writes the minibatches (stacked) and the two statistics.
    pub(crate) fn save(&self, path: &Path) -> Result<(), RlError> {
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
    pub(crate) fn load(path: &Path, width: usize, action_dim: usize) -> Result<Self, RlError> {
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

#[cfg(test)]
mod tests {
    use super::*;

    /// Episode tables read back as written; a table whose states have three words (as before
    /// symbolic states grew to four; `seads migrate` widens them) or any other number but four
    /// is refused.
    #[test]
    fn episode_tables_read_back_and_other_widths_are_refused() {
        let mut z = SymbolicState::ZERO;
        for bit in [0, 70, 150, 191] {
            z.set(bit, true);
        }
        let episodes: VecDeque<Episode> = [
            Episode {
                skill: 2,
                obs: vec![0.5; 3 * 4],
                actions: vec![0.25; 2 * 3],
                z0: z,
                zt: SymbolicState::from_u64(5),
                game_move: Some(7),
            },
            Episode {
                skill: 0,
                obs: vec![1.0; 2 * 4],
                actions: vec![-1.0; 3],
                z0: SymbolicState::ZERO,
                zt: z,
                game_move: None,
            },
        ]
        .into();
        let dir = tempfile::tempdir().unwrap();
        let now = dir.path().join("now.safetensors");
        save_episodes(&now, &episodes, 3).unwrap();
        assert_eq!(load_episodes(&now, 4, 3, 3).unwrap(), episodes);
        // The same table with three words a state, as older versions wrote it.
        let old = dir.path().join("old.safetensors");
        let tensors: Vec<(String, Tensor)> = Tensor::read_safetensors(&now)
            .unwrap()
            .into_iter()
            .map(|(name, t)| {
                let t = if name == "z0" || name == "zt" {
                    t.narrow(1, 0, 3).contiguous()
                } else {
                    t
                };
                (name, t)
            })
            .collect();
        Tensor::write_safetensors(&tensors, &old).unwrap();
        assert!(load_episodes(&old, 4, 3, 3).is_err());
        let short = dir.path().join("short.safetensors");
        let tensors: Vec<(String, Tensor)> = tensors
            .into_iter()
            .map(|(name, t)| {
                let t = if name == "z0" || name == "zt" {
                    t.narrow(1, 0, 2).contiguous()
                } else {
                    t
                };
                (name, t)
            })
            .collect();
        Tensor::write_safetensors(&tensors, &short).unwrap();
        assert!(load_episodes(&short, 4, 3, 3).is_err());
    }
}
