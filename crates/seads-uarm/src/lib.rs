//! The real robot of SEADS (SPEC §7): a uArm Swift Pro pressing LightsOut on an Android tablet.
//!
//! - [`protocol`]: the uArm's G-code line protocol (documented there).
//! - [`Swift`]: the driver over a [`Transport`] — the serial port ([`SerialTransport`]) or the
//!   simulated twin — with acknowledgements, timeouts and recovery from garbled lines.
//! - [`Calibration`]: from four measured screen corners to arm coordinates.
//! - [`Tablet`]: the board, read from the app's log lines over `adb logcat` ([`AdbTablet`]; the
//!   line format is documented in [`tablet`]).
//! - [`UarmEnv`]: both action spaces as a `seads_embodiment::Environment`.
//! - [`Twin`]: an in-process arm and tablet, so that everything but the wire runs in tests,
//!   including timeouts, disconnects and malformed replies.
//!
//! Architecture invariant: the only crate that opens a serial port.
//!
//! # Example: calibrate against the twin and press a field
//!
//! ```
//! use seads_embodiment::Environment;
//! use seads_uarm::{
//!     ActionSpace, Calibration, CalibrationFile, DriverConfig, Swift, Twin, UarmConfig, UarmEnv,
//!     twin_screen_corners,
//! };
//!
//! let twin = Twin::new(3); // an arm and a tablet in this process, seeded
//! let mut arm = Swift::new(twin.transport(), DriverConfig::default());
//! // Calibration: the pen is put on the four screen corners by hand and each is read back.
//! arm.detach()?;
//! let mut corners = [[0.0; 3]; 4];
//! for (corner, at) in corners.iter_mut().zip(twin_screen_corners()) {
//!     twin.move_by_hand(at);
//!     *corner = arm.position()?;
//! }
//! arm.attach()?;
//! let calibration = Calibration::fit(CalibrationFile { corners, d_max_mm: 100.0 })?;
//! // The environment: an absolute push at (x, y) on the screen, one step per skill.
//! let config = UarmConfig {
//!     action_space: ActionSpace::Absolute,
//!     step_limit: 1,
//!     tap_timeout_s: 0.0,
//!     reset_board: true,
//!     ..UarmConfig::default()
//! };
//! let mut env = UarmEnv::new(arm, twin.tablet(), calibration, config)?;
//! env.seed(1);
//! env.reset()?;
//! let before = env.board();
//! let outcome = env.step(&[0.5, 0.5])?; // the centre of the screen: field 12
//! assert!(outcome.moved());
//! assert_ne!(env.board(), before);
//! assert_eq!(twin.board(), env.board()); // the tablet agrees
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! `cargo run -p seads-uarm --example twin` drives the twin through a calibration and a few
//! presses, with a fault injected on the wire.

mod calibration;
mod driver;
mod env;
pub mod protocol;
pub mod tablet;
mod twin;

pub use calibration::{Calibration, CalibrationFile};

/// Side of the LightsOut board the robot plays (on the tablet); its K is the game's 25 moves.
pub const BOARD_SIZE: usize = 5;

/// The game the robot plays: the tablet's LightsOut 5×5.
pub fn game() -> seads_games::LightsOut {
    seads_games::LightsOut::new(BOARD_SIZE).expect("LightsOut 5×5 exists")
}
pub use driver::{DriverConfig, SerialTransport, Swift, Transport};
pub use env::{ActionSpace, Observation, RobotSettings, UarmConfig, UarmEnv};
pub use tablet::{AdbTablet, Tablet, TabletReport};
pub use twin::{Faults, Twin, TwinNoise, TwinState, twin_screen_corners};

/// What can go wrong with the robot.
#[derive(Debug, thiserror::Error)]
pub enum UarmError {
    /// Opening, reading or writing a file or the serial port failed.
    #[error("{what}")]
    Io {
        /// The file or port, and what was done with it.
        what: String,
        /// What went wrong.
        #[source]
        source: Box<dyn std::error::Error + Send + Sync>,
    },
    /// The arm did not acknowledge a command in time.
    #[error("the arm did not answer `{command}` within {seconds:.1} s")]
    Timeout {
        /// The command.
        command: String,
        /// The time waited.
        seconds: f64,
    },
    /// The serial line is gone.
    #[error("the arm is disconnected")]
    Disconnected,
    /// The arm answered with an error code.
    #[error("the arm refused `{command}` with error E{code}")]
    CommandFailed {
        /// The command.
        command: String,
        /// The error code.
        code: u16,
    },
    /// An answer that does not fit the protocol.
    #[error("protocol error: {0}")]
    Protocol(String),
    /// An environment setting that cannot be used.
    #[error("invalid uArm setting: {0}")]
    Config(String),
    /// A calibration that cannot be used.
    #[error("calibration: {0}")]
    Calibration(String),
    /// The tablet's board cannot be read or set.
    #[error("tablet: {0}")]
    Tablet(String),
}
