//! Drives the simulated twin of the uArm Swift Pro and its LightsOut tablet: calibrates against
//! it, presses every field of the top row, and recovers from a garbled reply injected on the
//! wire. With a real arm, `Swift::open("/dev/ttyACM0")` and an `AdbTablet` replace the twin.
//!
//! ```sh
//! cargo run -p seads-uarm --example twin
//! ```
#![allow(clippy::print_stdout)] // an example prints

use seads_embodiment::{Environment, Push};
use seads_games::{BoardGame, LightsOut};
use seads_uarm::{
    ActionSpace, Calibration, CalibrationFile, DriverConfig, Faults, Swift, Twin, UarmConfig,
    UarmEnv, twin_screen_corners,
};

/// Calibrates and presses the five fields of the top row; returns the moves the tablet saw.
fn run() -> Result<Vec<usize>, Box<dyn std::error::Error>> {
    let twin = Twin::new(7);
    let mut arm = Swift::new(twin.transport(), DriverConfig::default());
    arm.detach()?;
    let mut corners = [[0.0; 3]; 4];
    for (corner, at) in corners.iter_mut().zip(twin_screen_corners()) {
        twin.move_by_hand(at);
        *corner = arm.position()?;
        println!(
            "corner at X {:.1} Y {:.1} Z {:.1} mm",
            corner[0], corner[1], corner[2]
        );
    }
    arm.attach()?;
    let calibration = Calibration::fit(CalibrationFile {
        corners,
        d_max_mm: 100.0,
    })?;
    // The fifth reply from now arrives garbled: the driver skips it and waits for a clean one.
    twin.inject(Faults {
        garble_at: Some(5),
        ..Faults::default()
    });
    let config = UarmConfig {
        action_space: ActionSpace::Absolute,
        step_limit: 1,
        tap_timeout_s: 0.0,
        reset_board: true,
        ..UarmConfig::default()
    };
    let mut env = UarmEnv::new(arm, twin.tablet(), calibration, config)?;
    env.seed(1);
    env.reset()?;
    let game = LightsOut::new(seads_uarm::BOARD_SIZE)?;
    println!("board {}", game.format(env.board()));
    let mut moves = Vec::new();
    for column in 0..5 {
        // Screen coordinates in [0, 1]²: the centre of field (row 0, column).
        let outcome = env.step(&[(column as f32 + 0.5) / 5.0, 0.1])?;
        if let Push::Move(m) = outcome.push {
            moves.push(m);
        }
        println!(
            "press column {column}: {:?} -> {}",
            outcome.push,
            game.format(env.board())
        );
        // One press is one skill: the step counter restarts for the next.
        env.reset_step_counter();
    }
    Ok(moves)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    run().map(|_| ())
}

#[test]
fn runs() {
    assert_eq!(run().unwrap(), [0, 1, 2, 3, 4]);
}
