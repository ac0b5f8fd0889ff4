//! Random actions in an environment: what they press, and the last frame as a small SVG drawn
//! from the environment's [`Scene`] (the `seads render` command draws the same scene with more
//! care).
//!
//! ```sh
//! cargo run -p seads-embodiment --example rollout                          # lightsout-cursor
//! cargo run -p seads-embodiment --example rollout -- tileswap-reacher frame.svg
//! ```
#![allow(clippy::print_stdout)] // an example prints

use std::fmt::Write as _;

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use seads_embodiment::{EnvConfig, EnvError, Push, Scene, Shape, make_env};

/// Runs 200 random steps; returns the number of game moves they made and the last frame.
fn run(name: &str) -> Result<(usize, Scene), EnvError> {
    let mut env = make_env(name, &EnvConfig::default())?;
    let spec = env.spec().clone();
    println!(
        "{name}: observation = {} manipulator values + {} board bits + 1 step counter; {} action values; K = {}",
        spec.manipulator_dim, spec.symbolic_len, spec.action_dim, spec.num_skills
    );
    env.seed(1);
    env.reset()?;
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let mut moves = 0;
    for t in 0..200 {
        let action: Vec<f32> = spec
            .action_low
            .iter()
            .zip(&spec.action_high)
            .map(|(&lo, &hi)| rng.random_range(lo..=hi))
            .collect();
        let outcome = env.step(&action)?;
        if let Push::Move(m) = outcome.push {
            moves += 1;
            println!("  step {t:>3}: move {m}");
        }
        if outcome.done() {
            // A skill ends with a move or at its step limit; the board stays, the counter restarts.
            env.reset_step_counter();
        }
    }
    Ok((moves, env.scene()))
}

/// The scene as SVG: fields (lit ones yellow), pivots and the manipulator.
fn svg(scene: &Scene) -> String {
    let [u0, v0, u1, v1] = scene.extent;
    let (w, h) = (u1 - u0, v1 - v0);
    let mut out = format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" viewBox=\"{u0} {v0} {w} {h}\" width=\"400\" height=\"{}\">\n",
        400.0 * h / w
    );
    for f in &scene.fields {
        let [a, b, c, d] = f.rect;
        let fill = if f.lit == Some(true) {
            "#f5be28"
        } else {
            "#464650"
        };
        let _ = writeln!(
            out,
            "<rect x=\"{a}\" y=\"{b}\" width=\"{}\" height=\"{}\" fill=\"{fill}\"/>",
            c - a,
            d - b
        );
    }
    let r = w / 100.0;
    for p in &scene.pivots {
        let _ = writeln!(
            out,
            "<circle cx=\"{}\" cy=\"{}\" r=\"{r}\" fill=\"gray\"/>",
            p[0], p[1]
        );
    }
    for shape in &scene.shapes {
        match shape {
            Shape::Marker { at } => {
                let _ = writeln!(
                    out,
                    "<circle cx=\"{}\" cy=\"{}\" r=\"{}\" fill=\"red\"/>",
                    at[0],
                    at[1],
                    2.0 * r
                );
            }
            Shape::Segment { from, to } => {
                let _ = writeln!(
                    out,
                    "<line x1=\"{}\" y1=\"{}\" x2=\"{}\" y2=\"{}\" stroke=\"steelblue\" stroke-width=\"{r}\"/>",
                    from[0], from[1], to[0], to[1]
                );
            }
            _ => {}
        }
    }
    out + "</svg>\n"
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let name = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "lightsout-cursor".into());
    let (moves, scene) = run(&name)?;
    let path = std::env::args().nth(2).unwrap_or_else(|| {
        std::env::temp_dir()
            .join("seads-frame.svg")
            .display()
            .to_string()
    });
    std::fs::write(&path, svg(&scene))?;
    println!("{moves} moves in 200 random steps; last frame: {path}");
    Ok(())
}

#[test]
fn runs() {
    for name in ["lightsout-cursor", "tileswap-reacher"] {
        let (_, scene) = run(name).unwrap();
        assert!(svg(&scene).contains("<rect"));
    }
}
