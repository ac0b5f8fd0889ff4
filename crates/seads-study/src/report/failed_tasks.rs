//! Every failed task of the runs' final evaluation with re-planning, one row each: which skills
//! left another board than the forward model predicted, told as game moves (the move the model
//! predicted, the move the skill made), how often, and after how many manipulator steps.
//! Re-planning from the board a skill left often picks the same skill again, so one wrong skill
//! can spend a task's whole budget.

use std::fmt::Write as _;

use crate::{Context as _, Result};
use seads_games::{BoardGame, MoveId};

use super::csv_field;
use super::failures::{TaskLine, read_tasks};
use super::runs::Group;
use crate::run_game;

/// The rows shown in report.md; `failed-tasks.csv` has them all.
const SHOWN: usize = 40;

/// What a skill did to the board, or what the model said it would do.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Effect {
    /// One game move.
    Move(MoveId),
    /// The board stayed as it was.
    Nothing,
    /// A board that no single move reaches.
    Other,
}

impl std::fmt::Display for Effect {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Effect::Move(m) => write!(f, "move {m}"),
            Effect::Nothing => f.write_str("nothing"),
            Effect::Other => f.write_str("no single move"),
        }
    }
}

/// The effect that takes `before` to `after` in `game` (boards as the per-task file writes them).
fn effect(game: &dyn BoardGame, before: &str, after: &str) -> Result<Effect> {
    let parse = |text: &str| {
        game.parse(text)
            .doing(|| format!("board {text:?} in a per-task file"))
    };
    let (before, after) = (parse(before)?, parse(after)?);
    if before == after {
        return Ok(Effect::Nothing);
    }
    Ok((0..game.num_moves())
        .find(|&m| game.apply(before, m) == after)
        .map_or(Effect::Other, Effect::Move))
}

/// One kind of deviation in a task: a skill, the predicted and the made effect, how often, and
/// the manipulator steps of each time (empty for files without `skill_steps`).
#[derive(Debug, PartialEq)]
struct Repeat {
    skill: usize,
    predicted: Effect,
    made: Effect,
    times: usize,
    steps: Vec<usize>,
}

impl Repeat {
    /// "×10, 50 steps" or "×10, steps: median 1, 1–7" (the count alone where steps are unknown
    /// for some of the times).
    fn count(&self) -> String {
        let times = self.times;
        if self.steps.len() != times {
            return format!("×{times}");
        }
        let (lo, hi) = (self.steps.iter().min(), self.steps.iter().max());
        let (Some(&lo), Some(&hi)) = (lo, hi) else {
            return format!("×{times}");
        };
        let unit = |n: usize| if n == 1 { "step" } else { "steps" };
        if lo == hi {
            return format!("×{times}, {lo} {}", unit(lo));
        }
        let values: Vec<f64> = self.steps.iter().map(|&s| s as f64).collect();
        let median = super::stats::median(&values).unwrap_or(f64::NAN);
        format!("×{times}, steps: median {median}, {lo}–{hi}")
    }
}

/// One failed task.
#[derive(Debug, PartialEq)]
struct FailedTask {
    depth: usize,
    /// Why it failed, in words.
    outcome: &'static str,
    /// Skills executed.
    executed: usize,
    /// Its deviations, grouped, in the order first seen.
    repeats: Vec<Repeat>,
}

impl FailedTask {
    /// The failed task of `line`, or `None` if it was solved.
    fn of(game: &dyn BoardGame, line: &TaskLine) -> Result<Option<Self>> {
        if line.solved {
            return Ok(None);
        }
        let outcome = match (line.plan_found, line.timed_out) {
            (false, true) => "no plan (search timed out)",
            (false, false) => "no plan",
            (true, _) => "goal not reached",
        };
        let mut repeats: Vec<Repeat> = Vec::new();
        for d in &line.deviations {
            let predicted = effect(game, &d.before, &d.predicted)?;
            let made = effect(game, &d.before, &d.reached)?;
            let steps = line.skill_steps.get(d.step).copied();
            match repeats
                .iter_mut()
                .find(|r| r.skill == d.skill && r.predicted == predicted && r.made == made)
            {
                Some(r) => {
                    r.times += 1;
                    r.steps.extend(steps);
                }
                None => repeats.push(Repeat {
                    skill: d.skill,
                    predicted,
                    made,
                    times: 1,
                    steps: steps.into_iter().collect(),
                }),
            }
        }
        Ok(Some(Self {
            depth: line.depth,
            outcome,
            executed: line.executed.len(),
            repeats,
        }))
    }

    /// "skill 0: model move 7, made move 11 (×6, steps: median 4, 3–9); …", or "–".
    fn deviations(&self) -> String {
        if self.repeats.is_empty() {
            return "–".to_owned();
        }
        self.repeats
            .iter()
            .map(|r| {
                format!(
                    "skill {}: model {}, made {} ({})",
                    r.skill,
                    r.predicted,
                    r.made,
                    r.count()
                )
            })
            .collect::<Vec<_>>()
            .join("; ")
    }
}

/// The markdown table (without heading; at most [`SHOWN`] rows) and `failed-tasks.csv`, or
/// `None` if no run has a failed task in its per-task file.
pub fn failed_task_tables(groups: &[Group<'_>]) -> Result<Option<(String, String)>> {
    let mut rows: Vec<[String; 7]> = Vec::new();
    for g in groups {
        let mut tasks = Vec::new();
        for run in &g.runs {
            if let Some(lines) = read_tasks(run)? {
                tasks.push((run, lines));
            }
        }
        // The runs of a group share their environment's options, so its game too.
        let Some((first, _)) = tasks.first() else {
            continue;
        };
        let game = run_game(&first.config)?;
        for (run, lines) in &tasks {
            for line in lines {
                if let Some(task) = FailedTask::of(game.as_ref(), line)
                    .doing(|| format!("reading the per-task file of {}", run.dir.display()))?
                {
                    rows.push([
                        g.env.clone(),
                        g.variant.clone(),
                        run.config.seed.to_string(),
                        task.depth.to_string(),
                        task.outcome.to_owned(),
                        task.executed.to_string(),
                        task.deviations(),
                    ]);
                }
            }
        }
    }
    if rows.is_empty() {
        return Ok(None);
    }
    let mut md = String::from(
        "| environment | variant | seed | depth | outcome | skills executed | deviations: skill, the model's move, the move made (times, manipulator steps) |\n\
         |---|---|---|---|---|---|---|\n",
    );
    let mut csv = String::from("env,variant,seed,depth,outcome,executed,deviations\n");
    for row in &rows {
        let fields: Vec<String> = row.iter().map(|c| csv_field(c)).collect();
        let _ = writeln!(csv, "{}", fields.join(","));
    }
    for row in rows.iter().take(SHOWN) {
        let _ = writeln!(md, "| {} |", row.join(" | "));
    }
    if rows.len() > SHOWN {
        let _ = writeln!(md, "\n{} more in `failed-tasks.csv`.", rows.len() - SHOWN);
    }
    md += "\nEvery failed task of the per-task files, with each way a skill left another board \
           than the forward model predicted: \"move m\" is the game's move m (LightsOut: the \
           field m, row by row from the top left; TileSwap: its swap m), \"nothing\" a skill \
           that left the board as it was, \"no single move\" a board no one move reaches, \
           and \"steps\" how many manipulator steps the skill ran each time (their median and \
           range). \
           Re-planning searches again from the board reached, so a wrong skill may be chosen \
           again and again.\n";
    Ok(Some((md, csv)))
}

#[cfg(test)]
mod tests {
    use seads_games::GameKind;
    fn game(name: &str) -> Box<dyn seads_games::BoardGame> {
        GameKind::named(name).unwrap().build(3).unwrap()
    }

    use super::*;

    fn line(text: &str) -> TaskLine {
        serde_json::from_str(text).unwrap()
    }

    /// LightsOut 3×3 by hand: pressing field 4 (the centre) toggles fields 1, 3, 4, 5, 7; pressing
    /// field 0 toggles 0, 1, 3. Skill 2's first kind of deviation ran 7 and 1 steps (median 4).
    #[test]
    fn deviations_are_told_as_moves_and_grouped_by_skill_and_effect() {
        let game = game("lightsout");
        let empty = "0,0,0,0,0,0,0,0,0";
        let centre = "0,1,0,1,1,1,0,1,0";
        let corner = "1,1,0,1,0,0,0,0,0";
        let two = "1,0,0,1,0,0,0,0,1";
        let text = format!(
            r#"{{"depth":3,"solved":false,"plan_found":true,"timed_out":false,"executed":[2,5,2,2],
            "skill_steps":[7,50,1,12],
            "deviations":[
              {{"step":0,"skill":2,"before":"{empty}","predicted":"{centre}","reached":"{corner}"}},
              {{"step":1,"skill":5,"before":"{empty}","predicted":"{corner}","reached":"{empty}"}},
              {{"step":2,"skill":2,"before":"{empty}","predicted":"{centre}","reached":"{corner}"}},
              {{"step":3,"skill":2,"before":"{empty}","predicted":"{two}","reached":"{corner}"}}]}}"#
        );
        let task = FailedTask::of(game.as_ref(), &line(&text))
            .unwrap()
            .unwrap();
        let expected = vec![
            Repeat {
                skill: 2,
                predicted: Effect::Move(4),
                made: Effect::Move(0),
                times: 2,
                steps: vec![7, 1],
            },
            Repeat {
                skill: 5,
                predicted: Effect::Move(0),
                made: Effect::Nothing,
                times: 1,
                steps: vec![50],
            },
            Repeat {
                skill: 2,
                predicted: Effect::Other,
                made: Effect::Move(0),
                times: 1,
                steps: vec![12],
            },
        ];
        assert_eq!(task.repeats, expected);
        assert_eq!(task.executed, 4);
        assert_eq!(task.outcome, "goal not reached");
        assert_eq!(
            task.deviations(),
            "skill 2: model move 4, made move 0 (×2, steps: median 4, 1–7); \
             skill 5: model move 0, made nothing (×1, 50 steps); \
             skill 2: model no single move, made move 0 (×1, 12 steps)"
        );
    }

    /// A file written before `skill_steps` existed, or one whose deviation points past it, gives
    /// the counts without steps, and one step reads in the singular.
    #[test]
    fn steps_are_left_out_where_the_file_does_not_have_them() {
        let game = game("tileswap");
        let (goal, swapped) = ("0,1,2,3,4,5,6,7,8", "1,0,2,3,4,5,6,7,8");
        let task = |steps: &str| {
            let text = format!(
                r#"{{"depth":1,"solved":false,"plan_found":true,"timed_out":false,"executed":[3,3],{steps}
                "deviations":[{{"step":1,"skill":3,"before":"{goal}","predicted":"{goal}","reached":"{swapped}"}}]}}"#
            );
            FailedTask::of(game.as_ref(), &line(&text))
                .unwrap()
                .unwrap()
                .deviations()
        };
        assert_eq!(task(""), "skill 3: model nothing, made move 6 (×1)");
        assert_eq!(
            task(r#""skill_steps":[4],"#),
            "skill 3: model nothing, made move 6 (×1)"
        );
        assert_eq!(
            task(r#""skill_steps":[4,1],"#),
            "skill 3: model nothing, made move 6 (×1, 1 step)"
        );
    }

    #[test]
    fn solved_tasks_are_skipped_and_a_broken_board_is_an_error() {
        let game = game("tileswap");
        let solved = r#"{"depth":1,"solved":true,"plan_found":true,"timed_out":false,"executed":[0],"deviations":[]}"#;
        assert!(
            FailedTask::of(game.as_ref(), &line(solved))
                .unwrap()
                .is_none()
        );
        let unplanned = r#"{"depth":5,"solved":false,"plan_found":false,"timed_out":true,"executed":[],"deviations":[]}"#;
        let task = FailedTask::of(game.as_ref(), &line(unplanned))
            .unwrap()
            .unwrap();
        assert_eq!(task.outcome, "no plan (search timed out)");
        assert_eq!(task.deviations(), "–");
        let broken = r#"{"depth":1,"solved":false,"plan_found":true,"timed_out":false,"executed":[0],
            "deviations":[{"step":0,"skill":0,"before":"1,0,2,3,4,5,6,7,8","predicted":"NaN","reached":"0,1,2,3,4,5,6,7,8"}]}"#;
        let err = FailedTask::of(game.as_ref(), &line(broken)).unwrap_err();
        assert!(format!("{err:#}").contains("\"NaN\""), "{err:#}");
    }

    /// TileSwap: swapping back the two tiles of move 6 (cells 0 and 1) is move 6 again.
    #[test]
    fn tileswap_effects_are_its_swaps() {
        let game = game("tileswap");
        let goal = "0,1,2,3,4,5,6,7,8";
        assert_eq!(
            effect(game.as_ref(), goal, "1,0,2,3,4,5,6,7,8").unwrap(),
            Effect::Move(6)
        );
        assert_eq!(
            effect(game.as_ref(), goal, "1,2,0,3,4,5,6,7,8").unwrap(),
            Effect::Other
        );
    }
}
