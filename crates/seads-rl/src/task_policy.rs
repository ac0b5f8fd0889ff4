//! What the task-reward baselines share at evaluation: a policy acting in task mode, its task
//! success on the SEADS protocol's boards (`agent.rs` loads one from a checkpoint).

use seads_embodiment::{EnvConfig, TaskEnv, make_env};
use seads_games::SymbolicState;
use seads_planner::{DepthResult, TaskSet};

use crate::{RlError, Sac, TrainConfig};

/// A deterministic policy acting in task mode: one action per observation of an episode.
pub trait TaskPolicy {
    /// A new episode starts (a hierarchical policy forgets its subgoal).
    fn begin(&mut self) {}
    /// The action for the episode's current observation.
    fn act(&mut self, obs: &[f32]) -> Vec<f32>;
}

/// The flat SAC baseline: the deterministic action of its Gaussian policy.
impl TaskPolicy for &Sac {
    fn act(&mut self, obs: &[f32]) -> Vec<f32> {
        Sac::act(self, obs, None)
    }
}

impl TaskPolicy for Sac {
    fn act(&mut self, obs: &[f32]) -> Vec<f32> {
        Sac::act(self, obs, None)
    }
}

/// Task success of `policy` on the tasks of the SEADS protocol (the boards a planning
/// evaluation with the same task set plays), each episode until solved or T_lim. `each` is
/// called with every task as it ends: (depth, seed, board, solved).
pub fn task_success(
    config: &TrainConfig,
    policy: &mut dyn TaskPolicy,
    tasks: &TaskSet,
    mut each: impl FnMut(usize, u64, SymbolicState, bool),
) -> Result<Vec<DepthResult>, RlError> {
    let seeds = tasks.seeds();
    let mut results = Vec::new();
    for &depth in &tasks.depths {
        let env_config = EnvConfig {
            reset_split: tasks.split,
            max_solution_depth: depth,
            random_solution_depth: false,
            ..config.env_config.clone()
        };
        let mut env = TaskEnv::new(make_env(&config.env, &env_config)?, depth)?;
        let mut result = DepthResult::new(depth);
        let mut obs = vec![0.0; env.spec().obs_dim];
        for &seed in &seeds {
            env.seed(seed);
            env.reset()?;
            let board = env.env().board();
            policy.begin();
            result.tasks += 1;
            loop {
                env.observe(&mut obs);
                let action = policy.act(&obs);
                let step = env.step(&action)?;
                if step.done {
                    if step.solved {
                        result.solved += 1;
                        result.solution_steps.push(env.steps());
                    }
                    each(depth, seed, board, step.solved);
                    break;
                }
            }
        }
        results.push(result);
    }
    Ok(results)
}
