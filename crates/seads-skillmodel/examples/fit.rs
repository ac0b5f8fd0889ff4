//! Fits the symbolic forward model q(z_T | z_0, k) to the true LightsOut moves (skill k = move k)
//! and measures how often its mode — what the planner uses — is the true successor.
//!
//! ```sh
//! cargo run --release -p seads-skillmodel --example fit            # 3×3 board, small network
//! cargo run --release -p seads-skillmodel --example fit -- 5 256   # the paper's 5×5, hidden 256
//! ```
#![allow(clippy::print_stdout)] // an example prints

use seads_games::LightsOut;
use seads_skillmodel::{SkillModelConfig, agreement_with_game, fit_to_game};

/// Fits a model to LightsOut N×N with two hidden layers of `hidden`; returns the agreement.
fn run(n: usize, hidden: i64, steps: usize) -> Result<f64, Box<dyn std::error::Error>> {
    tch::set_num_threads(1);
    let game = LightsOut::new(n)?;
    let config = SkillModelConfig {
        hidden: vec![hidden, hidden],
        batch_size: 256,
        ..SkillModelConfig::default()
    };
    let mut model = fit_to_game(&game, &config, steps, 1);
    let agreement = agreement_with_game(&mut model, &game, 1000, 2);
    println!(
        "LightsOut {n}×{n}, hidden {hidden}: after {steps} Adam steps the mode is the true successor for {:.1} % of (board, skill) pairs",
        100.0 * agreement
    );
    Ok(agreement)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1).map(|a| a.parse::<i64>());
    let n = args.next().transpose()?.unwrap_or(3) as usize;
    let hidden = args.next().transpose()?.unwrap_or(64);
    run(n, hidden, 1500).map(|_| ())
}

#[test]
fn runs() {
    assert!(run(3, 32, 400).unwrap() > 0.9);
}
