//! Episodes (one skill execution each) and how they are collected with a policy.

use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use seads_embodiment::{EnvError, Environment};
use seads_games::{MoveId, SymbolicState};

use crate::Sac;

/// One execution of one skill, from its first observation until it ended (a move or T_max).
#[derive(Debug, Clone, PartialEq)]
pub struct Episode {
    /// The label the episode was collected with.
    pub skill: usize,
    /// Observations s_0 … s_T, row-major (T + 1 rows).
    pub obs: Vec<f32>,
    /// Actions a_0 … a_{T−1}, row-major.
    pub actions: Vec<f32>,
    /// Φ(s_0).
    pub z0: SymbolicState,
    /// Φ(s_T).
    pub zt: SymbolicState,
    /// The ground-truth move of the last step (logging and coverage only).
    pub game_move: Option<MoveId>,
}

impl Episode {
    /// Number of transitions T.
    pub fn len(&self, action_dim: usize) -> usize {
        self.actions.len() / action_dim
    }

    /// Whether the episode has no transition.
    pub fn is_empty(&self) -> bool {
        self.actions.is_empty()
    }

    /// Whether the skill changed the board.
    pub fn changed(&self) -> bool {
        self.z0 != self.zt
    }
}

/// Writes `[obs, onehot(skill)]` into `row`.
pub fn policy_input(obs: &[f32], skill: usize, row: &mut [f32]) {
    row[..obs.len()].copy_from_slice(obs);
    row[obs.len()..].fill(0.0);
    row[obs.len() + skill] = 1.0;
}

/// Runs skill `skills[i]` on `envs[i]` (already reset or positioned) until each skill ends, with
/// one batched policy call per time step. Actions are sampled with noise from `rng`, or
/// deterministic when `rng` is `None`. Environments are stepped on rayon's pool, except
/// exclusive ones (clones of one robot, [`EnvSpec::exclusive`](seads_embodiment::EnvSpec)):
/// their episodes run one after another, each starting where the previous one left the robot.
pub fn run_episodes(
    envs: &mut [Box<dyn Environment>],
    skills: &[usize],
    policy: &Sac,
    num_skills: usize,
    mut rng: Option<&mut ChaCha8Rng>,
) -> Result<Vec<Episode>, EnvError> {
    let Some(first) = envs.first() else {
        return Ok(Vec::new());
    };
    if first.spec().exclusive && envs.len() > 1 {
        let mut episodes = Vec::with_capacity(envs.len());
        for (env, &skill) in envs.iter_mut().zip(skills) {
            let one = std::slice::from_mut(env);
            episodes.extend(run_episodes(
                one,
                &[skill],
                policy,
                num_skills,
                rng.as_deref_mut(),
            )?);
        }
        return Ok(episodes);
    }
    let spec = first.spec().clone();
    let (o, a, width) = (spec.obs_dim, spec.action_dim, spec.obs_dim + num_skills);
    let mut episodes: Vec<Episode> = envs
        .iter()
        .zip(skills)
        .map(|(env, &skill)| {
            let obs = env.observation();
            let z0 = env.board();
            Episode {
                skill,
                obs,
                actions: Vec::new(),
                z0,
                zt: z0,
                game_move: None,
            }
        })
        .collect();
    let mut active: Vec<usize> = (0..envs.len()).collect();
    let mut inputs = Vec::new();
    while !active.is_empty() {
        inputs.clear();
        inputs.resize(active.len() * width, 0.0);
        for (row, &i) in inputs.chunks_mut(width).zip(&active) {
            let e = &episodes[i];
            policy_input(&e.obs[e.obs.len() - o..], e.skill, row);
        }
        let actions = policy.act(&inputs, rng.as_deref_mut());
        // Step the active environments in parallel; each writes only its own episode.
        let mut slots: Vec<(&mut Box<dyn Environment>, &mut Episode, &[f32])> =
            Vec::with_capacity(active.len());
        let mut next = active.iter().peekable();
        for (i, (env, episode)) in envs.iter_mut().zip(episodes.iter_mut()).enumerate() {
            if next.peek() == Some(&&i) {
                let row = slots.len();
                slots.push((env, episode, &actions[row * a..(row + 1) * a]));
                next.next();
            }
        }
        let done: Vec<bool> = slots
            .into_par_iter()
            .map(|(env, episode, action)| {
                let outcome = env.step(action)?;
                episode.actions.extend_from_slice(action);
                let start = episode.obs.len();
                episode.obs.resize(start + o, 0.0);
                env.observe(&mut episode.obs[start..]);
                if outcome.done() {
                    episode.zt = env.board();
                    episode.game_move = outcome.game_move();
                }
                Ok(outcome.done())
            })
            .collect::<Result<_, EnvError>>()?;
        active = active
            .into_iter()
            .zip(done)
            .filter(|&(_, d)| !d)
            .map(|(i, _)| i)
            .collect();
    }
    Ok(episodes)
}

/// Distinct ground-truth moves made by the skills: the skill-coverage protocol of the paper
/// (SPEC §4.5). For each evaluation seed, every skill starts from the identically seeded reset
/// of `template` (which should use the test split) and runs deterministically until it ends.
/// Returns the number of distinct moves per seed.
pub fn skill_coverage(
    template: &dyn Environment,
    policy: &Sac,
    num_skills: usize,
    seeds: &[u64],
) -> Result<Vec<usize>, EnvError> {
    let mut envs: Vec<Box<dyn Environment>> = Vec::with_capacity(seeds.len() * num_skills);
    let mut skills = Vec::with_capacity(seeds.len() * num_skills);
    for &seed in seeds {
        let mut env = template.box_clone();
        env.seed(seed);
        env.reset()?;
        for k in 0..num_skills {
            envs.push(env.box_clone());
            skills.push(k);
        }
    }
    let episodes = run_episodes(&mut envs, &skills, policy, num_skills, None)?;
    Ok(episodes
        .chunks(num_skills)
        .map(|per_seed| {
            let mut moves: Vec<MoveId> = per_seed.iter().filter_map(|e| e.game_move).collect();
            moves.sort_unstable();
            moves.dedup();
            moves.len()
        })
        .collect())
}
