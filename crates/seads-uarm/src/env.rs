//! The uArm environment (SPEC §7.3): the arm pushing on the tablet's LightsOut, with either the
//! absolute-push or the displacement action space, over the real hardware or the twin.

use std::sync::{Arc, Mutex, MutexGuard};
use std::time::Duration;

use rand::RngExt;
use seads_embodiment::{
    BoardState, EnvConfig, EnvError, EnvSpec, Environment, FieldView, Layout, Push, Scene, Shape,
    StepOutcome,
};
use seads_games::{BoardGame, SymbolicState};
use serde::{Deserialize, Serialize};

use crate::UarmError;
use crate::calibration::Calibration;
use crate::driver::Swift;
use crate::tablet::Tablet;
use crate::twin::{Twin, TwinNoise, TwinState};

/// How actions move the pen.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ActionSpace {
    /// `a = (x, y) ∈ [0, 1]²`: hover at z = 0.2, press, hover (SPEC §7.3, seed S.5.1).
    Absolute,
    /// a = (Δx, Δy, p): move at z = 0.3 by at most 0.2 per axis, press when p > 0.6 (the
    /// Cursor in hardware, seed S.5.2).
    Displacement,
}

impl ActionSpace {
    /// The environment's name in run configs.
    pub fn env_name(self) -> &'static str {
        match self {
            Self::Absolute => "uarm-lightsout-absolute",
            Self::Displacement => "uarm-lightsout-displacement",
        }
    }

    /// The action space of the environment called `name`, if it is the uArm's.
    ///
    /// ```
    /// use seads_uarm::ActionSpace;
    /// let space = ActionSpace::of_env("uarm-lightsout-displacement");
    /// assert_eq!(space, Some(ActionSpace::Displacement));
    /// assert_eq!(space.unwrap().env_name(), "uarm-lightsout-displacement");
    /// assert_eq!(ActionSpace::of_env("lightsout-cursor"), None);
    /// ```
    pub fn of_env(name: &str) -> Option<Self> {
        [Self::Absolute, Self::Displacement]
            .into_iter()
            .find(|space| space.env_name() == name)
    }

    /// What a new run's skills see unless told otherwise. With absolute pushes, the pen's
    /// position only: a skill is one press, the same wherever the lights are, and on the twin
    /// (`docs/results/uarm-ablations/`) skills that saw the board as well scattered their
    /// presses with it (87 and 100 of 100 boards over two seeds), where skills that saw the pen
    /// only solved 100 of 100 on both. The paper states no observation for the robot. With
    /// displacements, the board and the pen, as the Cursor sees its world.
    pub fn observation(self) -> Observation {
        match self {
            Self::Absolute => Observation::Pen,
            Self::Displacement => Observation::BoardAndPen,
        }
    }

    /// Steps per skill: one press, or as many displacements as the Cursor's skills take.
    pub fn step_limit(self) -> usize {
        match self {
            Self::Absolute => 1,
            Self::Displacement => 10,
        }
    }
}

impl std::str::FromStr for ActionSpace {
    type Err = String;

    /// `absolute` or `displacement`.
    fn from_str(text: &str) -> Result<Self, String> {
        match text {
            "absolute" => Ok(Self::Absolute),
            "displacement" => Ok(Self::Displacement),
            other => Err(format!(
                "unknown action space {other:?} (valid: absolute, displacement)"
            )),
        }
    }
}

/// What the skills see of the world. The observation keeps its size; what is not seen reads 0.
/// The forward model sees the board in every case (it reads the tablet's report).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Observation {
    /// The pen's position and the board (as the Cursor sees its world).
    #[default]
    BoardAndPen,
    /// The board only.
    Board,
    /// The pen's position only.
    Pen,
    /// Neither: every absolute push is the same whatever the world shows.
    Nothing,
}

impl Observation {
    /// Every choice, in `--observe`'s order.
    pub const ALL: [Self; 4] = [Self::BoardAndPen, Self::Board, Self::Pen, Self::Nothing];

    /// The name in options and files.
    pub fn name(self) -> &'static str {
        match self {
            Self::BoardAndPen => "board-and-pen",
            Self::Board => "board",
            Self::Pen => "pen",
            Self::Nothing => "nothing",
        }
    }

    fn pen(self) -> bool {
        matches!(self, Self::BoardAndPen | Self::Pen)
    }

    fn board(self) -> bool {
        matches!(self, Self::BoardAndPen | Self::Board)
    }
}

impl std::str::FromStr for Observation {
    type Err = String;

    /// `board-and-pen`, `board`, `pen` or `nothing`.
    fn from_str(text: &str) -> Result<Self, String> {
        Self::ALL
            .into_iter()
            .find(|o| o.name() == text)
            .ok_or_else(|| {
                format!("unknown observation {text:?} (valid: board-and-pen, board, pen, nothing)")
            })
    }
}

/// What a robot run's `config.toml` does not hold, kept beside it in [`RobotSettings::FILE`]: how
/// the arm acts, what the skills see and, on the twin, whether it resets the board and how it
/// departs from a perfect arm. A resumed run and its evaluations keep them. Files from before the
/// observation and the noise read as the defaults (all seen, no noise), which those runs had.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RobotSettings {
    /// How actions move the pen.
    pub action_space: ActionSpace,
    /// Whether reset draws a new board (the twin only).
    pub reset_board: bool,
    /// What the skills see.
    #[serde(default)]
    pub observe: Observation,
    /// The twin's noise (the twin only).
    #[serde(default, skip_serializing_if = "TwinNoise::is_none")]
    pub twin_noise: TwinNoise,
}

impl RobotSettings {
    /// The file in a run directory.
    pub const FILE: &str = "robot.toml";

    /// The settings the run in `run` records; `None` for a run from before the file.
    pub fn read(run: &std::path::Path) -> Result<Option<Self>, UarmError> {
        let path = run.join(Self::FILE);
        let text = match std::fs::read_to_string(&path) {
            Ok(text) => text,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
            Err(e) => {
                return Err(UarmError::Io {
                    what: format!("reading {}", path.display()),
                    source: Box::new(e),
                });
            }
        };
        toml::from_str(&text)
            .map(Some)
            .map_err(|e| UarmError::Config(format!("{}: {}", path.display(), e.message())))
    }

    /// Writes them into the run in `run`, atomically.
    pub fn write(&self, run: &std::path::Path) -> Result<(), UarmError> {
        let text = toml::to_string(self).expect("plain fields serialise");
        crate::calibration::write_atomic(&run.join(Self::FILE), &text)
    }
}

/// Settings of the uArm environment.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct UarmConfig {
    /// The action space.
    pub action_space: ActionSpace,
    /// Steps per skill (not published; one press for absolute pushes, as many as the Cursor's
    /// for displacements).
    pub step_limit: usize,
    /// How long to wait for the tablet to log a tap after a press, seconds.
    pub tap_timeout_s: f64,
    /// Reset draws a new board and pen position. The twin only: the real tablet's boards are the
    /// app's. The paper's protocol resets neither board nor arm (SPEC §7.3, seed S.5), so an
    /// episode starts where the previous one ended; that is the default.
    pub reset_board: bool,
    /// What the skills see.
    pub observe: Observation,
}

impl Default for UarmConfig {
    fn default() -> Self {
        Self {
            action_space: ActionSpace::Absolute,
            step_limit: 1,
            tap_timeout_s: 2.0,
            reset_board: false,
            observe: Observation::BoardAndPen,
        }
    }
}

/// Normalised hover heights (z = 1 ≈ 10 cm above the screen).
const HOVER_ABSOLUTE: f64 = 0.2;
const HOVER_DISPLACEMENT: f64 = 0.3;

struct Hardware {
    arm: Swift,
    tablet: Box<dyn Tablet>,
    calibration: Calibration,
    /// Pen position over the screen, normalised.
    cursor: [f64; 2],
    /// The board side every environment has: the board the tablet last reported and the reset
    /// distribution with its stream (the twin's resets draw the pen's position after the board).
    board: BoardState,
    seq: u64,
}

/// The arm and the tablet as an [`Environment`]. Clones share the hardware (`spec().exclusive`):
/// a trainer runs their episodes one after another.
#[derive(Clone)]
pub struct UarmEnv {
    spec: EnvSpec,
    config: UarmConfig,
    hardware: Arc<Mutex<Hardware>>,
    steps: usize,
    /// The twin the hardware is, whose state the environment carries between episodes.
    twin: Option<Twin>,
}

/// What a run on the twin carries from one episode to the next ([`Environment::carried_state`]):
/// the environment's view (the pen over the screen, the last report and its board) and the twin.
#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct Carried {
    cursor: [f64; 2],
    seq: u64,
    board: SymbolicState,
    twin: TwinState,
}

impl UarmEnv {
    /// Connects the environment: attaches the servos, lifts the pen to hover height over the
    /// screen centre and reads the board.
    pub fn new(
        mut arm: Swift,
        mut tablet: Box<dyn Tablet>,
        calibration: Calibration,
        config: UarmConfig,
    ) -> Result<Self, UarmError> {
        if config.step_limit == 0
            || !config.tap_timeout_s.is_finite()
            || config.tap_timeout_s < 0.0
            || config.tap_timeout_s > 3600.0
        {
            return Err(UarmError::Config(
                "step_limit must be at least 1 and tap_timeout_s in [0, 3600] seconds".into(),
            ));
        }
        let game = crate::game();
        let name = config.action_space.env_name();
        let (low, high) = match config.action_space {
            ActionSpace::Absolute => (vec![0.0, 0.0], vec![1.0, 1.0]),
            ActionSpace::Displacement => (vec![-0.2, -0.2, -1.0], vec![0.2, 0.2, 1.0]),
        };
        let spec = EnvSpec {
            name: name.into(),
            game: game.kind(),
            board_size: 5,
            manipulator_dim: 2,
            state_low: vec![f32::NEG_INFINITY; 2],
            state_high: vec![f32::INFINITY; 2],
            symbolic_len: 25,
            obs_dim: 2 + 25 + 1,
            action_dim: low.len(),
            action_low: low,
            action_high: high,
            num_skills: game.num_moves(),
            step_limit: Some(config.step_limit),
            exclusive: true,
        };
        arm.attach()?;
        let centre = [0.5, 0.5];
        arm.move_to(calibration.to_arm(0.5, 0.5, HOVER_DISPLACEMENT))?;
        let report = tablet.latest(Duration::from_secs_f64(config.tap_timeout_s.max(1.0)))?;
        let mut board = BoardState::new(crate::game().kind(), 5, &EnvConfig::default())
            .expect("LightsOut 5×5 has boards of depth 1 to 5");
        board
            .set(report.board)
            .expect("every 5×5 pattern is a LightsOut board");
        let hardware = Hardware {
            arm,
            tablet,
            calibration,
            cursor: centre,
            board,
            seq: report.seq,
        };
        Ok(Self {
            spec,
            config,
            hardware: Arc::new(Mutex::new(hardware)),
            steps: 0,
            twin: None,
        })
    }

    /// Tells the environment that its arm and tablet are `twin`'s, so that it carries the twin's
    /// state with its own between episodes (a checkpoint keeps both; a resumed run goes on with
    /// the twin the stopped run left). On the real arm nothing is carried: the arm and the
    /// tablet keep their own state.
    pub fn on_twin(mut self, twin: Twin) -> Self {
        self.twin = Some(twin);
        self
    }

    fn lock(&self) -> MutexGuard<'_, Hardware> {
        self.hardware.lock().unwrap_or_else(|e| e.into_inner())
    }

    fn hover(&self) -> f64 {
        match self.config.action_space {
            ActionSpace::Absolute => HOVER_ABSOLUTE,
            ActionSpace::Displacement => HOVER_DISPLACEMENT,
        }
    }

    fn hardware_error(&self, e: UarmError) -> EnvError {
        EnvError::Hardware {
            env: self.spec.name.clone(),
            source: Box::new(e),
        }
    }

    /// Presses at the pen's position and waits for the tablet's report.
    fn press(&self, hw: &mut Hardware) -> Result<Push, UarmError> {
        let [x, y] = hw.cursor;
        hw.arm.move_to(hw.calibration.to_arm(x, y, 0.0))?;
        hw.arm.move_to(hw.calibration.to_arm(x, y, self.hover()))?;
        let report = hw
            .tablet
            .wait_for_report(hw.seq, Duration::from_secs_f64(self.config.tap_timeout_s))?;
        Ok(match report {
            Some(r) => {
                hw.seq = r.seq;
                let changed = r.board != hw.board.board();
                hw.board
                    .set(r.board)
                    .map_err(|e| UarmError::Tablet(e.to_string()))?;
                match r.game_move {
                    Some(m) if changed => Push::Move(m),
                    _ => Push::Miss,
                }
            }
            None => Push::Miss,
        })
    }

    fn act(&self, action: &[f32]) -> Result<Push, UarmError> {
        let mut guard = self.lock();
        let hw = &mut *guard;
        match self.config.action_space {
            ActionSpace::Absolute => {
                let (x, y) = (
                    action[0].clamp(0.0, 1.0) as f64,
                    action[1].clamp(0.0, 1.0) as f64,
                );
                hw.cursor = [x, y];
                hw.arm
                    .move_to(hw.calibration.to_arm(x, y, HOVER_ABSOLUTE))?;
                self.press(hw)
            }
            ActionSpace::Displacement => {
                let x = (hw.cursor[0] + action[0].clamp(-0.2, 0.2) as f64).clamp(0.0, 1.0);
                let y = (hw.cursor[1] + action[1].clamp(-0.2, 0.2) as f64).clamp(0.0, 1.0);
                hw.cursor = [x, y];
                hw.arm
                    .move_to(hw.calibration.to_arm(x, y, HOVER_DISPLACEMENT))?;
                if action[2] > 0.6 {
                    self.press(hw)
                } else {
                    Ok(Push::None)
                }
            }
        }
    }
}

impl Environment for UarmEnv {
    fn spec(&self) -> &EnvSpec {
        &self.spec
    }

    fn seed(&mut self, seed: u64) {
        self.lock().board.seed(seed);
    }

    fn reset(&mut self) -> Result<(), EnvError> {
        self.steps = 0;
        if !self.config.reset_board {
            return Ok(());
        }
        let mut hw = self.lock();
        let before = hw.board.board();
        hw.board.reset()?;
        let board = hw.board.board();
        let rng = hw.board.rng();
        let cursor = [rng.random::<f64>(), rng.random::<f64>()];
        let result = (|| {
            if let Err(e) = hw.tablet.set_board(board) {
                let _ = hw.board.set(before); // the tablet still shows it
                return Err(e);
            }
            hw.seq = hw.tablet.latest(Duration::ZERO)?.seq;
            let target = hw.calibration.to_arm(cursor[0], cursor[1], self.hover());
            hw.arm.move_to(target)?;
            hw.cursor = cursor;
            Ok(())
        })();
        drop(hw);
        result.map_err(|e| self.hardware_error(e))
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
        let push = match self.act(action) {
            Ok(push) => push,
            Err(e) => {
                // Leave the arm safe: lift the pen to hover height where it is, if the line allows.
                let mut hw = self.lock();
                let [x, y] = hw.cursor;
                let safe = hw.calibration.to_arm(x, y, self.hover());
                let _ = hw.arm.move_to(safe);
                return Err(self.hardware_error(e));
            }
        };
        self.steps += 1;
        let truncated = self.spec.step_limit.is_some_and(|l| self.steps >= l);
        Ok(StepOutcome { push, truncated })
    }

    fn observe(&self, out: &mut [f32]) {
        let hw = self.lock();
        out[0] = hw.cursor[0] as f32;
        out[1] = hw.cursor[1] as f32;
        self.spec.observe_board(hw.board.board(), self.steps, out);
        let observe = self.config.observe;
        if !observe.pen() {
            out[..2].fill(0.0);
        }
        if !observe.board() {
            out[2..2 + self.spec.symbolic_len].fill(0.0);
        }
    }

    fn board(&self) -> SymbolicState {
        self.lock().board.board()
    }

    fn set_board(&mut self, board: SymbolicState) -> Result<(), EnvError> {
        let mut hw = self.lock();
        let before = hw.board.board();
        hw.board.set(board)?;
        if let Err(e) = hw.tablet.set_board(board) {
            let _ = hw.board.set(before); // the tablet still shows it
            return Err(EnvError::Unsupported {
                env: self.spec.name.clone(),
                what: e.to_string(),
            });
        }
        if let Ok(r) = hw.tablet.latest(Duration::ZERO) {
            hw.seq = r.seq;
        }
        Ok(())
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
        if state.len() != 2 || state.iter().any(|v| !(0.0..=1.0).contains(v)) {
            return Err(invalid(format!(
                "a pen position is 2 values in [0, 1], got {state:?}"
            )));
        }
        let mut hw = self.lock();
        let target = hw
            .calibration
            .to_arm(state[0] as f64, state[1] as f64, self.hover());
        hw.arm.move_to(target).map_err(|e| self.hardware_error(e))?;
        hw.cursor = [state[0] as f64, state[1] as f64];
        Ok(())
    }

    fn scene(&self) -> Scene {
        let hw = self.lock();
        let fields = Layout::Grid { n: 5 }
            .fields()
            .into_iter()
            .enumerate()
            .map(|(d, rect)| FieldView {
                rect,
                lit: Some(hw.board.board().get(d)),
                label: None,
                height: 0.0,
            })
            .collect();
        Scene {
            title: self.spec.name.clone(),
            extent: [0.0, 0.0, 1.0, 1.0],
            fields,
            pivots: Vec::new(),
            shapes: vec![Shape::Marker { at: hw.cursor }],
        }
    }

    fn end_effector(&self) -> [f64; 2] {
        self.lock().cursor
    }

    fn box_clone(&self) -> Box<dyn Environment> {
        Box::new(self.clone())
    }

    fn carried_state(&self) -> Option<String> {
        let twin = self.twin.as_ref()?;
        let hw = self.lock();
        let carried = Carried {
            cursor: hw.cursor,
            seq: hw.seq,
            board: hw.board.board(),
            twin: twin.state(),
        };
        Some(serde_json::to_string(&carried).expect("plain fields serialise"))
    }

    fn restore_carried_state(&mut self, state: &str) -> Result<(), EnvError> {
        let invalid = |reason: String| EnvError::InvalidState {
            env: self.spec.name.clone(),
            reason,
        };
        let Some(twin) = &self.twin else {
            return Err(EnvError::Unsupported {
                env: self.spec.name.clone(),
                what: "restoring a state carried between episodes on the real arm".into(),
            });
        };
        let carried: Carried = serde_json::from_str(state)
            .map_err(|e| invalid(format!("a carried state that does not read: {e}")))?;
        if !carried.cursor.iter().all(|v| (0.0..=1.0).contains(v)) {
            return Err(invalid(format!(
                "a pen position is 2 values in [0, 1], got {:?}",
                carried.cursor
            )));
        }
        if !crate::game().is_valid(carried.board) {
            return Err(invalid("not a LightsOut 5×5 board".into()));
        }
        // The environment's board is the one the newest report it received showed: where that
        // is the twin's newest report, it is the twin's board (issue 82: a board that disagreed
        // was taken). Behind it (a late report), the twin's board may have moved on.
        if carried.seq == carried.twin.seq() && carried.board != carried.twin.board() {
            return Err(invalid(
                "the environment's board is not the twin's, though it received the twin's newest \
                 report"
                    .into(),
            ));
        }
        twin.restore(&carried.twin)
            .map_err(|e| invalid(e.to_string()))?;
        let mut hw = self.lock();
        hw.board.set(carried.board)?;
        hw.cursor = carried.cursor;
        hw.seq = carried.seq;
        Ok(())
    }
}
