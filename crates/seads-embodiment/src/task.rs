//! Task mode (SPEC §5.1), what the task-reward baselines learn in: every episode starts on a board
//! of solution depth S from the environment's reset distribution (S ~ U{1..5} on the train split
//! for training; a fixed depth on the test split for evaluation), pays reward 1 on the step that
//! solves it and 0 otherwise, and ends when the board is solved or after T_lim = T_max·S steps
//! (10·S for the Cursor, 50·S for Reacher and Jaco, T_max being the environment's steps per
//! skill).

use std::collections::BTreeMap;
use std::sync::{Arc, OnceLock};

use crate::board::{Shared, shared};

use seads_games::{BoardGame, GameKind, SymbolicState};

use crate::{EnvError, EnvSpec, Environment};

/// What one step of a task episode did.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TaskStep {
    /// 1 on the step that solved the board, else 0.
    pub reward: f32,
    /// The board is the goal.
    pub solved: bool,
    /// The episode ends: solved, or the time limit T_lim is reached.
    pub done: bool,
    /// The game move the step made, if any.
    pub game_move: Option<seads_games::MoveId>,
}

/// An environment in task mode. The observation is the environment's own, whose last value (the
/// remaining share of the step limit) counts down over T_lim.
pub struct TaskEnv {
    env: Box<dyn Environment>,
    game: Box<dyn BoardGame>,
    goal: SymbolicState,
    /// Where the reset boards' solution depths come from.
    depths: Depths,
    steps_per_depth: usize,
    max_depth: usize,
    depth: usize,
    limit: usize,
    steps: usize,
    over: bool,
}

impl TaskEnv {
    /// Task mode of `env`, whose boards come from its own reset distribution (split, depths).
    ///
    /// ```
    /// use seads_embodiment::{EnvConfig, TaskEnv, make_env};
    /// let config = EnvConfig { max_solution_depth: 2, random_solution_depth: false, ..EnvConfig::default() };
    /// let mut task = TaskEnv::new(make_env("lightsout-cursor", &config)?, 2)?;
    /// task.seed(5);
    /// // A reset says the board's solution depth; the episode may take T_max per move.
    /// assert_eq!(task.reset()?, 2);
    /// assert_eq!(task.limit(), 2 * 10);
    /// # Ok::<(), seads_embodiment::EnvError>(())
    /// ```
    pub fn new(env: Box<dyn Environment>, max_depth: usize) -> Result<Self, EnvError> {
        let spec = env.spec();
        let steps_per_depth = spec.step_limit.ok_or_else(|| {
            EnvError::InvalidConfig(format!(
                "{}: task mode needs a step limit per skill",
                spec.name
            ))
        })?;
        let game = spec.game.build(spec.board_size)?;
        let goal = game.goal();
        let depths = Depths::of(spec.game, spec.board_size, max_depth, game.as_ref());
        Ok(Self {
            env,
            game,
            goal,
            depths,
            steps_per_depth,
            max_depth,
            depth: 0,
            limit: 0,
            steps: 0,
            over: true,
        })
    }

    /// The wrapped environment's dimensions (its step limit is T_lim of the current episode).
    pub fn spec(&self) -> &EnvSpec {
        self.env.spec()
    }

    /// Re-seeds the environment.
    pub fn seed(&mut self, seed: u64) {
        self.env.seed(seed);
    }

    /// Starts an episode; returns its solution depth S.
    pub fn reset(&mut self) -> Result<usize, EnvError> {
        self.env.reset()?;
        let board = self.env.board();
        self.depth = self
            .depths
            .depth(self.game.as_ref(), board)
            .filter(|&d| d <= self.max_depth)
            .ok_or_else(|| {
                EnvError::InvalidConfig(format!(
                    "{}: a reset board lies deeper than the task's largest depth {}",
                    self.env.spec().name,
                    self.max_depth
                ))
            })?;
        self.limit = self.steps_per_depth * self.depth.max(1);
        self.env.set_step_limit(Some(self.limit));
        self.env.reset_step_counter();
        self.steps = 0;
        self.over = false;
        Ok(self.depth)
    }

    /// Solution depth S of the episode's board.
    pub fn depth(&self) -> usize {
        self.depth
    }

    /// The episode's time limit T_lim.
    pub fn limit(&self) -> usize {
        self.limit
    }

    /// Steps taken in this episode.
    pub fn steps(&self) -> usize {
        self.steps
    }

    /// One step; an error once the episode is over (reset first).
    pub fn step(&mut self, action: &[f32]) -> Result<TaskStep, EnvError> {
        if self.over {
            return Err(EnvError::EpisodeOver {
                env: self.env.spec().name.clone(),
            });
        }
        let outcome = self.env.step(action)?;
        self.steps += 1;
        let solved = self.env.board() == self.goal;
        self.over = solved || outcome.truncated;
        Ok(TaskStep {
            reward: if solved { 1.0 } else { 0.0 },
            solved,
            done: self.over,
            game_move: outcome.game_move(),
        })
    }

    /// Writes the current observation.
    pub fn observe(&self, out: &mut [f32]) {
        self.env.observe(out);
    }

    /// The wrapped environment (for scenes and the end effector).
    pub fn env(&self) -> &dyn Environment {
        self.env.as_ref()
    }
}

/// Where a task's solution depths come from.
enum Depths {
    /// The game's own optimal solver (LightsOut by GF(2) algebra, TileSwap by its depth table):
    /// nothing to build, whatever the task's largest depth.
    Solver,
    /// A game without a solver: every board up to the task's largest depth, mapped once by
    /// breadth-first search from the goal.
    Map(Arc<BTreeMap<SymbolicState, usize>>),
}

impl Depths {
    /// The depth source of `game`'s tasks up to `max_depth`.
    fn of(kind: GameKind, size: usize, max_depth: usize, game: &dyn BoardGame) -> Self {
        if game.solution_depth(game.goal()).is_some() {
            Depths::Solver
        } else {
            Depths::Map(depth_map(kind, size, max_depth, game))
        }
    }

    /// The solution depth of `board`, `None` if it has none up to the mapped depth.
    fn depth(&self, game: &dyn BoardGame, board: SymbolicState) -> Option<usize> {
        match self {
            Depths::Solver => game.solution_depth(board).and_then(Result::ok),
            Depths::Map(map) => map.get(&board).copied(),
        }
    }
}

/// The solution depth of every board of `game` up to `max_depth`, by breadth-first search from
/// the goal (moves that undo themselves make the distance from the goal the distance to it).
/// Computed once per game, size and depth and shared, so that many task environments (a vector
/// of them) cost one map.
fn depth_map(
    kind: GameKind,
    size: usize,
    max_depth: usize,
    game: &dyn BoardGame,
) -> Arc<BTreeMap<SymbolicState, usize>> {
    static CACHE: Shared<(GameKind, usize, usize), BTreeMap<SymbolicState, usize>> =
        OnceLock::new();
    shared(&CACHE, (kind, size, max_depth), || {
        let goal = game.goal();
        let mut depths = BTreeMap::from([(goal, 0)]);
        let mut layer = vec![goal];
        for depth in 1..=max_depth {
            let mut next = Vec::new();
            for &board in &layer {
                for mv in 0..game.num_moves() {
                    let after = game.apply(board, mv);
                    if let std::collections::btree_map::Entry::Vacant(e) = depths.entry(after) {
                        e.insert(depth);
                        next.push(after);
                    }
                }
            }
            layer = next;
        }
        depths
    })
}
