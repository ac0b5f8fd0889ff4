//! The environment trait and `Embodied<M>`: a manipulator in front of a board, with the step
//! counter, remaining-time entry and termination rules every embodiment shares (SPEC §2.1).

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use seads_games::{FieldMark, SymbolicState};

use crate::board::BoardState;
use crate::{EnvError, EnvSpec, FieldView, Layout, Push, Scene, Shape, StepOutcome};

/// A continuous manipulator in front of a board game (SPEC §2).
///
/// The observation is `[manipulator state, z, ρ]` with ρ = (T_max − t)/T_max the remaining time
/// of the current skill. A step ends the skill (`done`) when it moved the board or reached T_max.
pub trait Environment: Send + Sync {
    /// Dimensions, bounds and name.
    fn spec(&self) -> &EnvSpec;
    /// Re-seeds the board's and the manipulator's random streams (both from `seed`).
    fn seed(&mut self, seed: u64);
    /// Draws a new board and manipulator state and resets the step counter. Simulations cannot
    /// fail here; hardware can (the robot reports a failed move or tablet).
    fn reset(&mut self) -> Result<(), EnvError>;
    /// Applies one action. Errors on an action of the wrong length or with a non-finite entry,
    /// on a step past the step limit, and when the simulation diverges.
    fn step(&mut self, action: &[f32]) -> Result<StepOutcome, EnvError>;
    /// Writes the current observation (`spec().obs_dim` values).
    fn observe(&self, out: &mut [f32]);
    /// The current symbolic state z = Φ(s).
    fn board(&self) -> SymbolicState;
    /// Puts the board into `board`, keeping the manipulator where it is.
    fn set_board(&mut self, board: SymbolicState) -> Result<(), EnvError>;
    /// Restarts the step counter (before each skill of a plan; the environment is not reset).
    fn reset_step_counter(&mut self);
    /// Changes the step limit (`None`: unlimited, as for recording long episodes).
    fn set_step_limit(&mut self, limit: Option<usize>);
    /// Puts the manipulator into the state given by the manipulator part of an observation.
    fn restore_manipulator(&mut self, state: &[f32]) -> Result<(), EnvError>;
    /// A top view of the board and the manipulator.
    fn scene(&self) -> Scene;
    /// Where the end effector (cursor, fingertip, tool centre point) is above the board, in
    /// normalised board coordinates (u to the right, v down the rows).
    fn end_effector(&self) -> [f64; 2];
    /// Where the last step made its move, if the manipulator has been re-initialised since,
    /// within that step (the Jaco, as in the reference): the point where the arm touched the
    /// board, which the reference's skill figures mark, while [`Environment::end_effector`]
    /// tells the new pose. `None` otherwise.
    fn move_point(&self) -> Option<[f64; 2]> {
        None
    }
    /// A boxed copy (same state, same random streams).
    fn box_clone(&self) -> Box<dyn Environment>;
    /// What of the environment outlives [`Environment::reset`] and [`Environment::seed`], as
    /// text that a checkpoint keeps: a world whose episodes start where the last one ended (the
    /// robot under the paper's protocol, with its tablet and its noise streams). `None`, the
    /// default, when a reset after a seed depends on nothing else, as in every simulation.
    fn carried_state(&self) -> Option<String> {
        None
    }
    /// Puts back what [`Environment::carried_state`] gave, so that a resumed run goes on in the
    /// world the stopped one left. An environment that carries nothing refuses.
    fn restore_carried_state(&mut self, state: &str) -> Result<(), EnvError> {
        let _ = state;
        Err(EnvError::Unsupported {
            env: self.spec().name.clone(),
            what: "restoring a state carried between episodes".into(),
        })
    }

    /// The current observation as a new vector.
    fn observation(&self) -> Vec<f32> {
        let mut obs = vec![0.0; self.spec().obs_dim];
        self.observe(&mut obs);
        obs
    }
}

impl Clone for Box<dyn Environment> {
    fn clone(&self) -> Self {
        self.box_clone()
    }
}

/// Where the manipulator touched the board during a step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Touch {
    /// A push at normalised board coordinates (u, v), resolved by the board's [`Layout`].
    At {
        /// Column direction, 0..1.
        u: f64,
        /// Row direction, 0..1.
        v: f64,
    },
    /// A press detected on the LightsOut field in this row-major position (Jaco's per-field
    /// touch sensors), resolved to a move by the board's [`Layout`].
    Field(usize),
}

/// The embodiment-specific part of an environment: state, dynamics, observation.
pub trait Manipulator: Clone + Send + Sync + 'static {
    /// Length M of the manipulator observation.
    fn state_dim(&self) -> usize;
    /// Lower and upper action bounds.
    fn action_bounds(&self) -> (Vec<f32>, Vec<f32>);
    /// Lower and upper bounds of the observed state (M values each): unbounded unless the
    /// manipulator says otherwise.
    fn state_bounds(&self) -> (Vec<f32>, Vec<f32>) {
        let m = self.state_dim();
        (vec![f32::NEG_INFINITY; m], vec![f32::INFINITY; m])
    }
    /// Default steps per skill T_max.
    fn default_step_limit(&self) -> usize;
    /// Draws a random initial state. It depends on nothing but `rng`: no state of earlier
    /// episodes survives a reset (a resumed run must collect what the killed run would have).
    fn reset(&mut self, rng: &mut ChaCha8Rng);
    /// Advances one environment step under a finite, correctly sized `action`. Each touch of the
    /// board is reported to `touch`, which answers what it did; once it answered a move, later
    /// touches of the same step are ignored by the board. Returns `false` if the state diverged.
    fn step(
        &mut self,
        action: &[f32],
        rng: &mut ChaCha8Rng,
        touch: &mut dyn FnMut(Touch) -> Push,
    ) -> bool;
    /// Writes the manipulator observation (M values).
    fn observe(&self, out: &mut [f32]);
    /// Sets the state from a manipulator observation; `Err(reason)` if it is not a valid state or
    /// the observation does not determine the state.
    fn restore(&mut self, state: &[f32]) -> Result<(), String>;
    /// Whether [`Manipulator::restore`] can rebuild the full state from an observation.
    fn can_restore(&self) -> bool {
        true
    }
    /// The end effector in normalised board coordinates.
    fn end_effector(&self) -> [f64; 2];
    /// Where the last step's move was made (the touch on the board), if the manipulator
    /// re-initialised itself after it within that step ([`Environment::move_point`]); `None`
    /// otherwise.
    fn move_point(&self) -> Option<[f64; 2]> {
        None
    }
    /// Draws the manipulator and widens `extent` to what it can reach.
    fn draw(&self, shapes: &mut Vec<Shape>, extent: &mut [f64; 4]);
    /// Heights of the fields' top surfaces above the table, row-major, metres (empty: flat).
    fn field_heights(&self) -> Vec<f64> {
        Vec::new()
    }
}

/// A manipulator `M` in front of a board: implements [`Environment`] for every embodiment.
#[derive(Clone)]
pub struct Embodied<M: Manipulator> {
    spec: EnvSpec,
    manipulator: M,
    board: BoardState,
    layout: Layout,
    rng: ChaCha8Rng,
    steps: usize,
}

impl<M: Manipulator> Embodied<M> {
    pub(crate) fn new(
        name: &str,
        manipulator: M,
        board: BoardState,
        layout: Layout,
        step_limit: Option<usize>,
    ) -> Result<Self, EnvError> {
        let game = board.game();
        let (action_low, action_high) = manipulator.action_bounds();
        let (state_low, state_high) = manipulator.state_bounds();
        let spec = EnvSpec {
            name: name.to_owned(),
            game: game.kind(),
            board_size: game.size(),
            manipulator_dim: manipulator.state_dim(),
            state_low,
            state_high,
            symbolic_len: game.symbolic_len(),
            obs_dim: manipulator.state_dim() + game.symbolic_len() + 1,
            action_dim: action_low.len(),
            action_low,
            action_high,
            num_skills: game.num_moves(),
            step_limit: Some(step_limit.unwrap_or(manipulator.default_step_limit())),
            exclusive: false,
        };
        let mut env = Self {
            spec,
            manipulator,
            board,
            layout,
            rng: ChaCha8Rng::seed_from_u64(0),
            steps: 0,
        };
        env.seed(0);
        env.draw_initial_state()?;
        Ok(env)
    }

    /// A new board and manipulator state from the random streams, and a fresh step counter.
    fn draw_initial_state(&mut self) -> Result<(), EnvError> {
        self.board.reset()?;
        self.manipulator.reset(&mut self.rng);
        self.steps = 0;
        Ok(())
    }

    /// The manipulator.
    pub fn manipulator(&self) -> &M {
        &self.manipulator
    }
}

impl<M: Manipulator> Environment for Embodied<M> {
    fn spec(&self) -> &EnvSpec {
        &self.spec
    }

    fn seed(&mut self, seed: u64) {
        self.board.seed(seed);
        self.rng = ChaCha8Rng::seed_from_u64(seed);
    }

    fn reset(&mut self) -> Result<(), EnvError> {
        self.draw_initial_state()
    }

    fn step(&mut self, action: &[f32]) -> Result<StepOutcome, EnvError> {
        self.spec.check_action(action)?;
        if let Some(limit) = self.spec.step_limit
            && self.steps >= limit
        {
            return Err(EnvError::StepLimitReached {
                env: self.spec.name.clone(),
                limit,
            });
        }
        let (board, layout) = (&mut self.board, self.layout);
        let mut push = Push::None;
        let finite = self.manipulator.step(action, &mut self.rng, &mut |touch| {
            if matches!(push, Push::Move(_)) {
                return Push::None; // at most one move per step
            }
            let located = match touch {
                Touch::At { u, v } => layout.locate(u, v),
                Touch::Field(index) => layout.field_move(index),
            };
            // A push whose move leaves the board as it is (a sliding tile away from the gap)
            // moves nothing: z did not change.
            let result = match located {
                Some(mv) if board.game().changes(board.board(), mv) => Push::Move(mv),
                _ => Push::Miss,
            };
            match result {
                Push::Move(mv) => {
                    board.apply(mv);
                    push = result;
                }
                Push::Miss => push = Push::Miss,
                Push::None => {}
            }
            result
        });
        self.steps += 1;
        if !finite {
            return Err(EnvError::NonFiniteState {
                env: self.spec.name.clone(),
                steps: self.steps,
            });
        }
        let truncated = self.spec.step_limit.is_some_and(|l| self.steps >= l);
        Ok(StepOutcome { push, truncated })
    }

    fn observe(&self, out: &mut [f32]) {
        self.manipulator
            .observe(&mut out[..self.spec.manipulator_dim]);
        self.spec.observe_board(self.board.board(), self.steps, out);
    }

    fn board(&self) -> SymbolicState {
        self.board.board()
    }

    fn set_board(&mut self, board: SymbolicState) -> Result<(), EnvError> {
        self.board.set(board)
    }

    fn reset_step_counter(&mut self) {
        self.steps = 0;
    }

    fn set_step_limit(&mut self, limit: Option<usize>) {
        self.spec.step_limit = limit;
    }

    fn restore_manipulator(&mut self, state: &[f32]) -> Result<(), EnvError> {
        let invalid = |reason: String| EnvError::InvalidState {
            env: self.spec.name.clone(),
            reason,
        };
        if !self.manipulator.can_restore() {
            let what = "restoring the manipulator from an observation".to_owned();
            return Err(EnvError::Unsupported {
                env: self.spec.name.clone(),
                what,
            });
        }
        if state.len() != self.spec.manipulator_dim {
            return Err(invalid(format!(
                "expected {} values, got {}",
                self.spec.manipulator_dim,
                state.len()
            )));
        }
        if state.iter().any(|v| !v.is_finite()) {
            return Err(invalid("non-finite value".into()));
        }
        self.manipulator.restore(state).map_err(invalid)
    }

    fn scene(&self) -> Scene {
        let game = self.board.game();
        let board = self.board.board();
        let values = game.values(board);
        let heights = self.manipulator.field_heights();
        let fields = self
            .layout
            .fields()
            .into_iter()
            .zip(values)
            .enumerate()
            .map(|(mv, (rect, v))| {
                // Heights are per row-major position; the move of that position is `mv`.
                let height = (0..heights.len())
                    .find(|&i| self.layout.field_move(i) == Some(mv))
                    .map_or(0.0, |i| heights[i]);
                let (lit, label) = match game.field_mark(v) {
                    FieldMark::Light(on) => (Some(on), None),
                    FieldMark::Label(text) => (None, Some(text)),
                    FieldMark::Blank => (None, None),
                };
                FieldView {
                    rect,
                    lit,
                    label,
                    height,
                }
            })
            .collect();
        let mut scene = Scene {
            title: self.spec.name.clone(),
            extent: [0.0, 0.0, 1.0, 1.0],
            fields,
            pivots: self
                .layout
                .pivots()
                .into_iter()
                .map(|(u, v)| [u, v])
                .collect(),
            shapes: Vec::new(),
        };
        self.manipulator.draw(&mut scene.shapes, &mut scene.extent);
        scene
    }

    fn end_effector(&self) -> [f64; 2] {
        self.manipulator.end_effector()
    }

    fn move_point(&self) -> Option<[f64; 2]> {
        self.manipulator.move_point()
    }

    fn box_clone(&self) -> Box<dyn Environment> {
        Box::new(self.clone())
    }
}
