//! Trains SEADS for a few epochs into a run directory and reads its metrics back — what
//! `seads train` does, from code.
//!
//! ```sh
//! cargo run --release -p seads-rl --example train              # 3000 steps into a temporary folder
//! cargo run --release -p seads-rl --example train -- 20000 runs/example
//! ```
#![allow(clippy::print_stdout)] // an example prints

use std::path::Path;

use seads_rl::{RlError, Run, TrainConfig, Trainer, read_metrics};

/// Trains a small agent for `steps` environment steps into `dir`; returns the final coverage.
fn run(steps: u64, dir: &Path) -> Result<f64, RlError> {
    let mut config = TrainConfig::preset("lightsout-cursor")?;
    config.env_steps = steps;
    config.sac.hidden = vec![64, 64];
    (config.eval_every, config.checkpoint_every) = (10, 10);
    config.edit(|seads: &mut seads_rl::SeadsConfig| {
        seads.skill_model.hidden = vec![64, 64];
        seads.eval_seeds = 4;
    })?;
    let mut run = Run::<Trainer>::create(dir, config)?;
    while !run.finished() {
        let event = run.step()?;
        if let Some(m) = event.metrics {
            println!(
                "epoch {:>4}  steps {:>6}  coverage {:>5.2}/25  reward {:>5.2}",
                m.epoch, m.env_steps, m.skill_coverage, m.mean_reward
            );
        }
    }
    let metrics = read_metrics(dir)?;
    println!(
        "{} evaluations in {}/metrics.jsonl",
        metrics.len(),
        dir.display()
    );
    Ok(metrics.last().map_or(0.0, |m| m.skill_coverage))
}

fn main() -> Result<(), RlError> {
    let mut args = std::env::args().skip(1);
    let steps = args.next().and_then(|s| s.parse().ok()).unwrap_or(3000);
    let dir = match args.next() {
        Some(dir) => dir.into(),
        None => std::env::temp_dir().join(format!("seads-example-{}", std::process::id())),
    };
    run(steps, &dir).map(|_| ())
}

#[test]
fn runs() {
    let dir = std::env::temp_dir().join(format!("seads-example-test-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let coverage = run(600, &dir).unwrap();
    assert!((0.0..=25.0).contains(&coverage));
    assert!(dir.join("checkpoints/latest").is_file());
    std::fs::remove_dir_all(&dir).unwrap();
}
