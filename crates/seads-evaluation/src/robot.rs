//! Task success of a robot run (`seads uarm train` and `seads uarm evaluate`): the agent solves
//! LightsOut 5×5 boards with re-planning on the arm or its twin.

use std::collections::BTreeMap;
use std::path::Path;

use seads_embodiment::{Environment as _, SkillPolicy, execute_skill};
use seads_games::BoardGame;
use seads_games::Successor;
use seads_planner::{
    CheckpointId, DepthResult, EvaluationRecord, Memo, Protocol, SearchLimits, SolveConfig,
    TaskRecord, solve,
};
use seads_rl::Agent;
use seads_uarm::UarmEnv;

use seads_study::StudyError;
use seads_study::evaluation::journal::Place;
use seads_study::evaluation::{checkpoint_of, save_evaluation, task_line};

use crate::Result;

/// A robot evaluation: re-planning on the tasks of depth 1–5 with `boards` boards per depth,
/// each search bounded by `limits`, on the twin of `twin_seed` or on the real arm (`None`).
///
/// The twin's board is set to each task's board, the boards a Cursor evaluation plays; the real
/// tablet's boards are whatever the app shows. Results are keyed by the board's solution depth
/// and saved as `evaluation-replan.json` (or `evaluation-replan-epoch-<EPOCH>.json` for an
/// earlier checkpoint), with one line per task in the tasks file beside it.
///
/// A stopped evaluation resumes from the tasks its journal holds (`journal.rs`). On the
/// twin it replays their executed skills, so that the twin's pen and noise stand where the
/// whole evaluation would have left them, and checks that each replay reaches the board the
/// journal says: the resumed evaluation is the whole one. The real arm cannot replay: it goes on
/// from the board it shows.
#[derive(Debug, Clone, Copy)]
pub struct RobotEvaluation {
    /// The twin's seed, or `None` for the real arm.
    pub twin_seed: Option<u64>,
    /// Boards per depth.
    pub boards: usize,
    /// Search limits.
    pub limits: SearchLimits,
}

impl RobotEvaluation {
    fn protocol(&self) -> Protocol {
        Protocol::planning(true, self.boards, self.limits)
    }

    /// What, besides protocol and checkpoint, decides the outcome: which twin plays it.
    fn header(&self) -> [(&'static str, serde_json::Value); 1] {
        [("twin", self.twin_seed.into())]
    }

    /// What a stopped evaluation of `checkpoint` in `run` left: the tasks it finished, and its
    /// damaged journal lines.
    pub fn finished_before(&self, run: &Path, checkpoint: &Path) -> Result<seads_study::Resumed> {
        let (id, named) = checkpoint_of(run, checkpoint)?;
        Ok(Place::new(run, &self.protocol(), &id, named, &self.header()).finished_before()?)
    }

    /// Evaluates the robot run in `run` at `checkpoint` in `env`, calling `each` after every
    /// task (replayed ones too).
    pub fn run(
        &self,
        run: &Path,
        checkpoint: &Path,
        mut env: UarmEnv,
        each: impl FnMut(),
    ) -> Result<EvaluationRecord> {
        // The robot's agent runs on the CPU, wherever it trained.
        let config = seads_rl::TrainConfig {
            device: seads_rl::ComputeDevice::Cpu,
            ..seads_run::load_config(run)?
        };
        let mut agent = Agent::load_for(config, env.spec().clone(), checkpoint)?;
        let (policy, model) = agent.parts()?;
        let checkpoint = checkpoint_of(run, checkpoint)?;
        self.play(run, checkpoint, &mut env, policy, model, each)
    }

    /// [`run`](Self::run)'s tasks, played by `policy` and planned with `model`, for the
    /// checkpoint `id` (`named` by its epoch unless it is the run's latest).
    fn play(
        &self,
        run: &Path,
        (id, named): (CheckpointId, Option<u64>),
        env: &mut UarmEnv,
        policy: &dyn SkillPolicy,
        model: &mut dyn Successor,
        mut each: impl FnMut(),
    ) -> Result<EvaluationRecord> {
        let game = seads_uarm::game();
        let protocol = self.protocol();
        let solve_config = SolveConfig {
            replan: true,
            planner: self.limits.planner(),
            ..SolveConfig::default()
        };
        seads_study::evaluation::keep_another_protocols(run, &protocol, named)?;
        let mut journal = Place::new(run, &protocol, &id, named, &self.header()).open()?;
        let mut results: BTreeMap<usize, DepthResult> = BTreeMap::new();
        let mut lines = String::new();
        let mut model = Memo::new(model, solve_config.planner.memo_bytes());
        let seeds = protocol.tasks.seeds();
        for &depth in &protocol.tasks.depths {
            for (done, &seed) in seeds.iter().enumerate() {
                if self.twin_seed.is_some() {
                    let board = protocol
                        .tasks
                        .board(game.kind(), game.size(), depth, seed)
                        .map_err(env_error)?;
                    env.set_board(board).map_err(env_error)?;
                }
                let line = if let Some((summary, line)) = journal.earlier(depth, seed) {
                    if self.twin_seed.is_some() {
                        replay(env, policy, &game, line)?;
                    }
                    let d = line["solution_depth"].as_u64().unwrap_or(0) as usize;
                    results
                        .entry(d)
                        .or_insert_with(|| DepthResult::new(d))
                        .count(summary);
                    line.clone()
                } else {
                    let board = env.board();
                    let d = game.solution_depth(board).and_then(Result::ok).unwrap_or(0);
                    let outcome = solve(env, policy, &mut model, game.goal(), &solve_config)
                        .map_err(env_error)?;
                    results
                        .entry(d)
                        .or_insert_with(|| DepthResult::new(d))
                        .record(&outcome);
                    let task = TaskRecord {
                        depth,
                        seed,
                        board,
                        done: done + 1,
                        outcome: &outcome,
                    };
                    let mut line = task_line(&game, &task);
                    line["solution_depth"] = d.into();
                    line["reached"] = game.format(env.board()).into();
                    journal.append(&line, outcome.planning_s);
                    line
                };
                lines += &line.to_string();
                lines.push('\n');
                each();
            }
        }
        let record = EvaluationRecord {
            checkpoint: Some(id),
            protocol: Some(protocol),
            evaluated_by: journal.evaluated_by(),
            results: results.into_values().collect(),
        };
        journal.finish(|| save_evaluation(run, &record, named, Some(&lines)))?;
        Ok(record)
    }
}

/// A failure of the arm or the tablet is the run's, not the user's input.
fn env_error(e: seads_embodiment::EnvError) -> StudyError {
    StudyError::Run(seads_run::RunError::Env(e))
}

/// Executes again the skills a finished task's `line` executed and checks that they reach the
/// board it reached.
fn replay(
    env: &mut UarmEnv,
    policy: &dyn SkillPolicy,
    game: &dyn BoardGame,
    line: &serde_json::Value,
) -> Result<()> {
    let task = format!("task {}/{}", line["depth"], line["seed"]);
    let executed: Vec<usize> = serde_json::from_value(line["executed"].clone()).map_err(|e| {
        StudyError::invalid(format!(
            "the stopped evaluation's {task} has no skills: {e}"
        ))
    })?;
    for skill in executed {
        execute_skill(env, policy, skill).map_err(env_error)?;
    }
    let reached = game.format(env.board());
    if line["reached"].as_str() != Some(reached.as_str()) {
        return Err(StudyError::invalid(format!(
            "the twin does not repeat the stopped evaluation's {task} (it reached {reached}, the \
             journal says {}): remove the evaluation's .partial file to evaluate afresh",
            line["reached"]
        ))
        .into());
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use seads_embodiment::Layout;
    use seads_games::GameSuccessor;
    use seads_uarm::{
        ActionSpace, Calibration, CalibrationFile, DriverConfig, Swift, Twin, TwinNoise,
        UarmConfig, twin_screen_corners,
    };

    /// Skill k presses the centre of field k.
    struct Tapper;

    impl SkillPolicy for Tapper {
        fn num_skills(&self) -> usize {
            25
        }

        fn act(&self, _observations: &[f32], skills: &[usize], actions: &mut [f32]) {
            for (&k, action) in skills.iter().zip(actions.chunks_mut(2)) {
                action.copy_from_slice(&centre(k));
            }
        }
    }

    fn centre(k: usize) -> [f32; 2] {
        let centres = (0..25).map(|i| ((i % 5) as f64 + 0.5, (i / 5) as f64 + 0.5));
        let (u, v) = centres
            .map(|(u, v)| (u / 5.0, v / 5.0))
            .find(|&(u, v)| Layout::Grid { n: 5 }.locate(u, v) == Some(k))
            .unwrap();
        [u as f32, v as f32]
    }

    /// A fresh twin whose taps scatter with a deviation of 12 mm (fields are 27 mm high), calibrated
    /// as a person would, one press per skill.
    fn twin_env() -> UarmEnv {
        let noise = TwinNoise {
            tap_sd_mm: 12.0,
            late_report_p: 0.0,
        };
        let twin = Twin::with_noise(5, noise).unwrap();
        let mut arm = Swift::new(twin.transport(), DriverConfig::default());
        arm.detach().unwrap();
        let mut corners = [[0.0; 3]; 4];
        for (corner, at) in corners.iter_mut().zip(twin_screen_corners()) {
            twin.move_by_hand(at);
            *corner = arm.position().unwrap();
        }
        arm.attach().unwrap();
        let calibration = Calibration::fit(CalibrationFile {
            corners,
            d_max_mm: 100.0,
        })
        .unwrap();
        let config = UarmConfig {
            action_space: ActionSpace::Absolute,
            step_limit: 1,
            tap_timeout_s: 0.0,
            reset_board: false,
            ..UarmConfig::default()
        };
        UarmEnv::new(arm, twin.tablet(), calibration, config).unwrap()
    }

    const EVALUATION: RobotEvaluation = RobotEvaluation {
        twin_seed: Some(5),
        boards: 4,
        limits: SearchLimits {
            timeout_s: None,
            max_expanded: Some(1 << 20),
            plan: seads_planner::PlanChoice::MostLikely,
            search: seads_planner::Search::Breadth,
            memory_limit_mib: None,
        },
    };

    const CHECKPOINT: CheckpointId = CheckpointId {
        epoch: 10,
        env_steps: Some(40),
    };

    /// The record (without search times) and tasks file of an evaluation in `run` with the
    /// game's own rules as the model, on a fresh twin.
    fn evaluate(run: &Path) -> (serde_json::Value, String) {
        let game = seads_uarm::game();
        let mut model = GameSuccessor::new(&game);
        let record = EVALUATION
            .play(
                run,
                (CHECKPOINT, None),
                &mut twin_env(),
                &Tapper,
                &mut model,
                || {},
            )
            .unwrap();
        let mut record: serde_json::Value = serde_json::from_str(&record.to_json()).unwrap();
        for r in record["results"].as_array_mut().unwrap() {
            r.as_object_mut().unwrap().remove("planning_s");
        }
        let tasks = EVALUATION.protocol().tasks_file(None);
        (record, std::fs::read_to_string(run.join(tasks)).unwrap())
    }

    /// An evaluation stopped after any task resumes to the whole one: the tasks it finished are
    /// replayed on the fresh twin, whose noise then draws what it drew in the whole evaluation.
    #[test]
    fn a_stopped_twin_evaluation_resumes_to_the_whole_one() {
        let whole = tempfile::tempdir().unwrap();
        let (record, tasks) = evaluate(whole.path());
        let lines: Vec<serde_json::Value> = tasks
            .lines()
            .map(|l| serde_json::from_str(l).unwrap())
            .collect();
        assert_eq!(lines.len(), 20);
        // The noise sends taps onto other fields: what a task does depends on the twin's draws.
        let deviated = lines
            .iter()
            .filter(|l| l["deviations"] != serde_json::json!([]));
        assert!(deviated.count() >= 3, "{tasks}");
        let header = serde_json::json!({"evaluation": {
            "protocol": record["protocol"], "checkpoint": CHECKPOINT, "twin": 5}});
        let partial = format!("{}.partial", EVALUATION.protocol().tasks_file(None));
        for stop in [1, 6, 13] {
            let dir = tempfile::tempdir().unwrap();
            let mut journal = format!("{header}\n");
            for line in &lines[..stop] {
                let mut line = line.clone();
                line["planning_s"] = 0.5.into();
                journal += &format!("{line}\n");
            }
            std::fs::write(dir.path().join(&partial), journal).unwrap();
            let (resumed, resumed_tasks) = evaluate(dir.path());
            assert_eq!(resumed_tasks, tasks, "stopped after {stop}");
            assert_eq!(resumed, record, "stopped after {stop}");
            assert!(!dir.path().join(&partial).exists());
        }
    }
}
