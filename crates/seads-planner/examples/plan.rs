//! Plan on a LightsOut board with the true game's successor function, then execute the plan in
//! `lightsout-cursor` with a scripted skill policy (skill k moves the cursor to field k and
//! pushes), once planning a single time and once re-planning after every skill.
//!
//! ```sh
//! cargo run -p seads-planner --example plan
//! ```
#![allow(clippy::print_stdout)] // an example prints

use seads_embodiment::{EnvConfig, SkillPolicy, make_env};
use seads_games::{BoardGame, GameSuccessor, LightsOut, Split};
use seads_planner::{SolveConfig, solve};

/// Skill k drives the cursor to the centre of field k (row k / 5, column k % 5) and pushes there.
struct ScriptedCursor;

impl SkillPolicy for ScriptedCursor {
    fn num_skills(&self) -> usize {
        25
    }

    fn act(&self, observations: &[f32], skills: &[usize], actions: &mut [f32]) {
        let width = observations.len() / skills.len();
        for ((obs, &k), action) in observations
            .chunks(width)
            .zip(skills)
            .zip(actions.chunks_mut(3))
        {
            let target = [(k % 5) as f32 * 0.2 + 0.1, (k / 5) as f32 * 0.2 + 0.1];
            let d = [target[0] - obs[0], target[1] - obs[1]];
            // Push on the step that lands on the target.
            let push = if d[0].abs() <= 0.2 && d[1].abs() <= 0.2 {
                1.0
            } else {
                -1.0
            };
            action.copy_from_slice(&[d[0].clamp(-0.2, 0.2), d[1].clamp(-0.2, 0.2), push]);
        }
    }
}

fn run() -> Result<Vec<bool>, Box<dyn std::error::Error>> {
    let game = LightsOut::new(5)?;
    let config = EnvConfig {
        reset_split: Split::Test,
        max_solution_depth: 4,
        random_solution_depth: false,
        ..EnvConfig::default()
    };
    let mut solved = Vec::new();
    for replan in [false, true] {
        let mut env = make_env("lightsout-cursor", &config)?;
        env.seed(11);
        env.reset()?;
        println!("board {}", game.format(env.board()));
        let outcome = solve(
            env.as_mut(),
            &ScriptedCursor,
            &mut GameSuccessor::new(&game),
            game.goal(),
            &SolveConfig {
                replan,
                ..SolveConfig::default()
            },
        )?;
        println!(
            "  {}: plan {:?}, executed {:?}, {} manipulator steps, solved: {}",
            if replan { "re-planning" } else { "plan once" },
            outcome.first_plan,
            outcome.executed,
            outcome.manipulator_steps,
            outcome.solved
        );
        solved.push(outcome.solved);
    }
    Ok(solved)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    run().map(|_| ())
}

#[test]
fn runs() {
    assert_eq!(run().unwrap(), [true, true]);
}
