//! The simulated twin: an arm that speaks the uArm protocol and a tablet running LightsOut, in
//! one in-process world, so that the driver, the calibration and the environment run end to end
//! without hardware — faults included.
//!
//! The arm moves instantly to commanded points; the pen cannot go below the screen (it rests on
//! the glass). When the pen comes within 0.5 mm of the screen inside its area, the tablet
//! registers a tap at that point (once per touch: the pen must lift by 1 mm before the next),
//! presses the LightsOut field under it and logs a report. A solved board stays on the screen
//! (the environment's reset shows a new one).

use std::collections::VecDeque;
use std::sync::{Arc, Mutex, MutexGuard};
use std::time::Duration;

use rand::seq::SliceRandom;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};
use seads_games::{BoardGame, LightsOut, SymbolicState};
use serde::{Deserialize, Serialize};

use seads_embodiment::Layout;

use crate::UarmError;
use crate::calibration::{Calibration, CalibrationFile};
use crate::driver::Transport;
use crate::tablet::{Tablet, TabletReport};

/// Faults the twin can inject, counted in commands received.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Faults {
    /// Never answer the n-th command (the driver times out).
    pub silent_at: Option<usize>,
    /// Send a garbled line and a stale reply before the answer to the n-th command.
    pub garble_at: Option<usize>,
    /// Answer the n-th command with a malformed position (for `P2220`) or an error code.
    pub bad_reply_at: Option<usize>,
    /// Drop the connection when the n-th command arrives.
    pub disconnect_at: Option<usize>,
}

/// How the twin departs from a perfect arm and tablet (both off by default). Its random draws
/// come from the twin's seed, on a stream of their own.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct TwinNoise {
    /// Standard deviation of where a tap lands on the screen around the commanded point, mm, on
    /// each screen axis (the pen's offset and the arm's repeatability).
    pub tap_sd_mm: f64,
    /// Probability that the tablet logs a tap too late for the press that made it: the press
    /// sees no report, and the report arrives at the next press (the tablet's latency).
    pub late_report_p: f64,
}

impl TwinNoise {
    /// Checks that both values are in range: a finite, non-negative deviation of at most 100 mm
    /// and a probability.
    pub fn check(&self) -> Result<(), UarmError> {
        if !(self.tap_sd_mm.is_finite() && (0.0..=100.0).contains(&self.tap_sd_mm)) {
            return Err(UarmError::Config(format!(
                "the twin's tap deviation must be 0 to 100 mm, not {}",
                self.tap_sd_mm
            )));
        }
        if !(0.0..=1.0).contains(&self.late_report_p) {
            return Err(UarmError::Config(format!(
                "the twin's late-report probability must be in [0, 1], not {}",
                self.late_report_p
            )));
        }
        Ok(())
    }

    /// Whether the twin is perfect.
    pub fn is_none(&self) -> bool {
        *self == Self::default()
    }
}

/// The stream of the noise's draws (the board's scrambles use stream 0).
const NOISE_STREAM: u64 = 1;

struct World {
    /// Pen tip position, arm coordinates (mm).
    pen: [f64; 3],
    attached: bool,
    connected: bool,
    touching: bool,
    commands: usize,
    faults: Faults,
    replies: VecDeque<String>,
    screen: Calibration,
    game: LightsOut,
    board: SymbolicState,
    seq: u64,
    last_move: Option<usize>,
    /// Every G0 target received (for tests: where the arm was sent).
    trail: Vec<[f64; 3]>,
    noise: TwinNoise,
    noise_rng: ChaCha8Rng,
    /// The screen's width and height, mm (the tap deviation's scale).
    screen_mm: [f64; 2],
    /// The last report whose timing was drawn (each tap's is drawn once).
    timed: u64,
    /// A report is late: the next wait receives it.
    late: bool,
}

/// What of the twin outlives an episode: the pen, the board and its log, and where the noise's
/// stream stands. A checkpoint keeps it ([`Twin::state`], [`Twin::restore`]), so that a resumed
/// run goes on with the twin it left, as the real arm stays where it was. Faults and the trail
/// are for tests and are not part of it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TwinState {
    pen: [f64; 3],
    touching: bool,
    board: SymbolicState,
    seq: u64,
    last_move: Option<usize>,
    timed: u64,
    late: bool,
    noise_rng: ChaCha8Rng,
}

impl TwinState {
    /// The board the twin's tablet shows.
    pub fn board(&self) -> SymbolicState {
        self.board
    }

    /// The number of the tablet's newest report.
    pub fn seq(&self) -> u64 {
        self.seq
    }
}

/// The shared simulated world; hand out its arm transport and its tablet.
#[derive(Clone)]
pub struct Twin {
    world: Arc<Mutex<World>>,
}

/// The twin's screen: a 217 × 136 mm display (a 10.1" tablet's usable area) lying in front of the
/// arm, slightly tilted.
pub fn twin_screen_corners() -> [[f64; 3]; 4] {
    [
        [160.0, 108.5, 5.0],
        [160.0, -108.5, 5.0],
        [296.0, -108.5, 12.0],
        [296.0, 108.5, 12.0],
    ]
}

impl Twin {
    /// A twin with a random board drawn from `seed`.
    pub fn new(seed: u64) -> Self {
        Self::with_noise(seed, TwinNoise::default()).expect("no noise is valid noise")
    }

    /// A twin with a random board drawn from `seed` whose taps and reports follow `noise`.
    pub fn with_noise(seed: u64, noise: TwinNoise) -> Result<Self, UarmError> {
        noise.check()?;
        let screen = Calibration::fit(CalibrationFile {
            corners: twin_screen_corners(),
            d_max_mm: 100.0,
        })
        .expect("the twin's screen is valid");
        let game = LightsOut::new(5).expect("5×5");
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let board = scramble(&game, &mut rng);
        let world = World {
            pen: [150.0, 0.0, 150.0],
            attached: true,
            connected: true,
            touching: false,
            commands: 0,
            faults: Faults::default(),
            replies: VecDeque::new(),
            screen,
            game,
            board,
            seq: 0,
            last_move: None,
            trail: Vec::new(),
            noise,
            noise_rng: {
                let mut rng = ChaCha8Rng::seed_from_u64(seed);
                rng.set_stream(NOISE_STREAM);
                rng
            },
            screen_mm: screen_size_mm(),
            timed: 0,
            late: false,
        };
        Ok(Self {
            world: Arc::new(Mutex::new(world)),
        })
    }

    fn lock(&self) -> MutexGuard<'_, World> {
        self.world.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// The arm's serial line.
    pub fn transport(&self) -> Box<dyn Transport> {
        Box::new(SimTransport { twin: self.clone() })
    }

    /// The tablet's log.
    pub fn tablet(&self) -> Box<dyn Tablet> {
        Box::new(SimTablet { twin: self.clone() })
    }

    /// Arms `faults` (command counts from now on).
    pub fn inject(&self, faults: Faults) {
        let mut w = self.lock();
        let now = w.commands;
        let shift = |n: Option<usize>| n.map(|n| now + n);
        w.faults = Faults {
            silent_at: shift(faults.silent_at),
            garble_at: shift(faults.garble_at),
            bad_reply_at: shift(faults.bad_reply_at),
            disconnect_at: shift(faults.disconnect_at),
        };
    }

    /// Reconnects after an injected disconnect.
    pub fn reconnect(&self) {
        self.lock().connected = true;
    }

    /// The pen tip, arm coordinates.
    pub fn pen(&self) -> [f64; 3] {
        self.lock().pen
    }

    /// The pen's height above the screen, mm.
    pub fn pen_height_mm(&self) -> f64 {
        let w = self.lock();
        w.screen.to_screen(w.pen)[2] * w.screen.file().d_max_mm
    }

    /// The board the tablet shows.
    pub fn board(&self) -> SymbolicState {
        self.lock().board
    }

    /// Every G0 target the arm received.
    pub fn trail(&self) -> Vec<[f64; 3]> {
        self.lock().trail.clone()
    }

    /// The state a resumed run needs to go on with this twin.
    pub fn state(&self) -> TwinState {
        let w = self.lock();
        TwinState {
            pen: w.pen,
            touching: w.touching,
            board: w.board,
            seq: w.seq,
            last_move: w.last_move,
            timed: w.timed,
            late: w.late,
            noise_rng: w.noise_rng.clone(),
        }
    }

    /// Puts the twin into `state` (from [`Twin::state`] of a twin of the same noise). A state no
    /// twin can be in (a pen off the numbers, a board that is not LightsOut's, a move that is
    /// not one, a report timed ahead of the log) is refused and changes nothing.
    pub fn restore(&self, state: &TwinState) -> Result<(), UarmError> {
        let mut w = self.lock();
        let bad = |what: &str| Err(UarmError::Config(format!("the twin's saved state: {what}")));
        // Within the arm's reach on every axis (issue 82: a pen at 1e308 mm was taken).
        let reach = crate::calibration::REACH_MM;
        if !state.pen.iter().all(|v| v.is_finite() && v.abs() <= reach) {
            return bad(&format!(
                "the pen's position {:?} lies beyond the arm's reach ({reach} mm on each axis)",
                state.pen
            ));
        }
        if !w.game.is_valid(state.board) {
            return bad("not a LightsOut 5×5 board");
        }
        if state.last_move.is_some_and(|m| m >= w.game.num_moves()) {
            return bad("a move LightsOut 5×5 does not have");
        }
        if state.timed > state.seq {
            return bad("a report timed after the newest");
        }
        w.pen = state.pen;
        w.touching = state.touching;
        w.board = state.board;
        w.seq = state.seq;
        w.last_move = state.last_move;
        w.timed = state.timed;
        w.late = state.late;
        w.noise_rng = state.noise_rng.clone();
        Ok(())
    }

    /// Moves the detached arm by hand (calibration: a person places the pen on a corner).
    pub fn move_by_hand(&self, to: [f64; 3]) {
        let mut w = self.lock();
        w.pen = to;
    }
}

/// The twin screen's width (top-left to top-right corner) and height (top-left to bottom-left),
/// mm.
fn screen_size_mm() -> [f64; 2] {
    let [a, b, _, d] = twin_screen_corners();
    let dist = |p: [f64; 3], q: [f64; 3]| {
        ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)).sqrt()
    };
    [dist(a, b), dist(a, d)]
}

/// A board 1–5 distinct moves from the goal, not the goal.
fn scramble(game: &LightsOut, rng: &mut ChaCha8Rng) -> SymbolicState {
    loop {
        let mut moves: Vec<usize> = (0..game.num_moves()).collect();
        moves.shuffle(rng);
        let depth = rng.random_range(1..=5);
        let board = game.apply_all(game.goal(), &moves[..depth]);
        if !game.is_goal(board) {
            return board;
        }
    }
}

impl World {
    fn answer(&mut self, line: &str) {
        let Some((id, command)) = line.strip_prefix('#').and_then(|l| l.split_once(' ')) else {
            return; // the firmware ignores lines without a sequence number
        };
        self.commands += 1;
        let n = self.commands;
        if self.faults.disconnect_at == Some(n) {
            self.connected = false;
            return;
        }
        if self.faults.silent_at == Some(n) {
            return;
        }
        if self.faults.garble_at == Some(n) {
            self.replies.push_back("\u{fffd}$#@!ok".into());
            self.replies.push_back("$9999 ok".into());
        }
        let bad = self.faults.bad_reply_at == Some(n);
        let reply = match command.split_whitespace().next().unwrap_or("") {
            "G0" if bad => format!("${id} E22"),
            "G0" => match parse_move(command) {
                Some(target) => {
                    self.trail.push(target);
                    if self.attached {
                        self.move_pen(target);
                        format!("${id} ok")
                    } else {
                        format!("${id} E21")
                    }
                }
                None => format!("${id} E20"),
            },
            "P2220" if bad => format!("${id} ok X1.0 Y?? Z3"),
            "P2220" => format!(
                "${id} ok X{:.2} Y{:.2} Z{:.2}",
                self.pen[0], self.pen[1], self.pen[2]
            ),
            "M17" => {
                self.attached = true;
                format!("${id} ok")
            }
            "M2019" => {
                self.attached = false;
                format!("${id} ok")
            }
            "M2210" | "M2400" | "P2234" | "P2201" | "P2202" | "P2203" | "P2204" | "P2205" => {
                format!("${id} ok")
            }
            _ => format!("${id} E20"),
        };
        self.replies.push_back(reply);
    }

    /// Moves the pen, stopping on the glass, and registers a tap when it touches the screen.
    fn move_pen(&mut self, target: [f64; 3]) {
        let d_max = self.screen.file().d_max_mm;
        let [x, y, h] = self.screen.to_screen(target);
        self.pen = if h < 0.0 {
            self.screen
                .to_arm(x.clamp(0.0, 1.0), y.clamp(0.0, 1.0), 0.0)
        } else {
            target
        };
        let height_mm = h.max(0.0) * d_max;
        let inside = (0.0..=1.0).contains(&x) && (0.0..=1.0).contains(&y);
        if inside && height_mm <= 0.5 && !self.touching {
            self.touching = true;
            // The tap lands where the noise puts it, on the screen.
            let (x, y) = self.tap_point(x, y);
            // The app's fields tile the screen as the Cursor's board does.
            let mv = Layout::Grid { n: 5 }
                .locate(x, y)
                .expect("a grid push always hits a field");
            self.board = self.game.apply(self.board, mv);
            self.seq += 1;
            self.last_move = Some(mv);
        } else if height_mm > 1.0 {
            self.touching = false;
        }
    }
}

impl World {
    /// Where a tap commanded at screen point (x, y) lands.
    fn tap_point(&mut self, x: f64, y: f64) -> (f64, f64) {
        let sd = self.noise.tap_sd_mm;
        if sd == 0.0 {
            return (x, y);
        }
        let normal = Normal::new(0.0, sd).expect("a checked deviation");
        let dx = normal.sample(&mut self.noise_rng) / self.screen_mm[0];
        let dy = normal.sample(&mut self.noise_rng) / self.screen_mm[1];
        ((x + dx).clamp(0.0, 1.0), (y + dy).clamp(0.0, 1.0))
    }

    /// Whether the newest report reaches a waiting press now. A tap's report is late with the
    /// noise's probability; a late report arrives at the next wait, with whatever the board
    /// became since (so a press that receives a late report also receives its own tap's).
    fn report_in_time(&mut self) -> bool {
        if self.late || self.seq == self.timed {
            self.late = false;
            self.timed = self.seq;
            return true;
        }
        self.timed = self.seq;
        let p = self.noise.late_report_p;
        self.late = p > 0.0 && self.noise_rng.random::<f64>() < p;
        !self.late
    }
}

fn parse_move(command: &str) -> Option<[f64; 3]> {
    let mut xyz = [None; 3];
    for token in command.split_whitespace().skip(1) {
        let (axis, value) = token.split_at(1);
        let v: f64 = value.parse().ok()?;
        match axis {
            "X" => xyz[0] = Some(v),
            "Y" => xyz[1] = Some(v),
            "Z" => xyz[2] = Some(v),
            "F" => {}
            _ => return None,
        }
    }
    Some([xyz[0]?, xyz[1]?, xyz[2]?])
}

/// The arm's end of the simulated serial line (instant replies, virtual time).
struct SimTransport {
    twin: Twin,
}

impl Transport for SimTransport {
    fn write_line(&mut self, line: &str) -> Result<(), UarmError> {
        let mut w = self.twin.lock();
        if !w.connected {
            return Err(UarmError::Disconnected);
        }
        w.answer(line);
        Ok(())
    }

    fn read_line(&mut self, _timeout: Duration) -> Result<Option<String>, UarmError> {
        let mut w = self.twin.lock();
        if !w.connected {
            return Err(UarmError::Disconnected);
        }
        Ok(w.replies.pop_front())
    }
}

/// The simulated tablet's log.
struct SimTablet {
    twin: Twin,
}

impl SimTablet {
    fn report(w: &World) -> TabletReport {
        TabletReport {
            seq: w.seq,
            board: w.board,
            game_move: w.last_move,
        }
    }
}

impl Tablet for SimTablet {
    fn latest(&mut self, _timeout: Duration) -> Result<TabletReport, UarmError> {
        Ok(Self::report(&self.twin.lock()))
    }

    fn wait_for_report(
        &mut self,
        after: u64,
        _timeout: Duration,
    ) -> Result<Option<TabletReport>, UarmError> {
        let mut w = self.twin.lock();
        Ok((w.seq > after && w.report_in_time()).then(|| Self::report(&w)))
    }

    fn set_board(&mut self, board: SymbolicState) -> Result<(), UarmError> {
        let mut w = self.twin.lock();
        if !w.game.is_valid(board) {
            return Err(UarmError::Tablet("not a LightsOut 5×5 board".into()));
        }
        w.board = board;
        w.seq += 1;
        w.last_move = None;
        // A late report of the board before is no longer news.
        w.late = false;
        w.timed = w.seq;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A saved pen beyond the arm's reach, or not finite, is refused and leaves the twin as it
    /// was (issue 82: a pen at [1e308, -1e308, 1e308] was taken); one within reach is restored.
    #[test]
    fn a_saved_pen_beyond_the_arms_reach_is_refused() {
        let twin = Twin::new(1);
        let before = twin.state();
        for pen in [
            [1e308, -1e308, 1e308],
            [f64::NAN, 0.0, 0.0],
            [0.0, 0.0, crate::calibration::REACH_MM + 1.0],
        ] {
            let mut state = before.clone();
            state.pen = pen;
            let err = twin.restore(&state).unwrap_err().to_string();
            assert!(err.contains("reach"), "{pen:?}: {err}");
            assert_eq!(twin.state().pen, before.pen);
        }
        let mut state = before.clone();
        state.pen = [200.0, -50.0, 30.0];
        twin.restore(&state).unwrap();
        assert_eq!(twin.state().pen, [200.0, -50.0, 30.0]);
    }
}
