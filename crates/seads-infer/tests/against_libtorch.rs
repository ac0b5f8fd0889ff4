//! The light agent against the libtorch one on the same checkpoint (a LightsOutCursor run trained
//! here, 64-wide networks): the same actions (deterministic and sampled with the same stream)
//! and successor log-probabilities within 1e-5, the same successors, the same plans on 100 boards
//! and the same evaluation, task for task.

use std::path::Path;
use std::sync::LazyLock;

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use seads_embodiment::{EnvConfig, SkillPolicy, make_env};
use seads_games::{BoardGame, LightsOut, Successor, SymbolicState};
use seads_planner::{Evaluation, PlannerConfig, SolveConfig, TaskSet, bfs_plan, evaluate};

/// A tiny trained run, made once for every test.
static RUN: LazyLock<tempfile::TempDir> = LazyLock::new(|| {
    let dir = tempfile::tempdir().unwrap();
    let mut config = seads_rl::TrainConfig::preset("lightsout-cursor").unwrap();
    config.env_steps = 6000;
    config.sac.hidden = vec![64, 64];
    config
        .edit(|s: &mut seads_rl::SeadsConfig| {
            s.skill_model.hidden = vec![64, 64];
            (s.sampled_episodes, s.recent_episodes) = (64, 32);
        })
        .unwrap();
    config.eval_every = 50;
    config.checkpoint_every = 50;
    config
        .edit(|s: &mut seads_rl::SeadsConfig| s.eval_seeds = 2)
        .unwrap();
    config.sac_threads_alone = 0;
    config.portable_numerics = true;
    let run_dir = dir.path().join("run");
    let mut run = seads_rl::Run::<seads_rl::Trainer>::create(&run_dir, config).unwrap();
    while !run.finished() {
        run.step().unwrap();
    }
    drop(run);
    dir
});

fn run() -> &'static Path {
    static PATH: LazyLock<std::path::PathBuf> = LazyLock::new(|| RUN.path().join("run"));
    &PATH
}

fn both() -> (seads_infer::Agent, seads_rl::Agent) {
    let light = seads_infer::Agent::load(run(), None).unwrap();
    let torch = seads_rl::Agent::load(run(), None).unwrap();
    assert_eq!(light.epoch, torch.epoch);
    (light, torch)
}

/// Observations the skills meet: boards and cursor positions of training resets.
fn observations(n: usize) -> Vec<f32> {
    let mut env = make_env("lightsout-cursor", &EnvConfig::default()).unwrap();
    let mut obs = Vec::new();
    for seed in 0..n as u64 {
        env.seed(seed);
        env.reset().unwrap();
        obs.extend(env.observation());
    }
    obs
}

#[test]
fn actions_match_libtorchs() {
    let (light, torch) = both();
    let k = light.policy.num_skills();
    assert_eq!(k, torch.policy.num_skills());
    let n = 40;
    let obs_one = observations(n);
    let obs_dim = obs_one.len() / n;
    // Every skill from every observation.
    let mut obs = Vec::new();
    let mut skills = Vec::new();
    for i in 0..n {
        for skill in 0..k {
            obs.extend_from_slice(&obs_one[i * obs_dim..(i + 1) * obs_dim]);
            skills.push(skill);
        }
    }
    let mut expected = vec![0.0; skills.len() * 3];
    torch.policy.act(&obs, &skills, &mut expected);
    let mut got = vec![0.0; expected.len()];
    light.policy.act(&obs, &skills, &mut got);
    let worst = |a: &[f32], b: &[f32]| {
        a.iter()
            .zip(b)
            .map(|(x, y)| (x - y).abs())
            .fold(0.0, f32::max)
    };
    assert!(
        worst(&got, &expected) <= 1e-5,
        "deterministic: {}",
        worst(&got, &expected)
    );
    let sampled_torch =
        torch
            .policy
            .actions(&obs, &skills, Some(&mut ChaCha8Rng::seed_from_u64(9)));
    let sampled = light
        .policy
        .actions(&obs, &skills, Some(&mut ChaCha8Rng::seed_from_u64(9)))
        .unwrap();
    assert!(
        worst(&sampled, &sampled_torch) <= 1e-5,
        "sampled: {}",
        worst(&sampled, &sampled_torch)
    );
    assert!(worst(&sampled, &got) > 1e-3, "a sample is not the mean");
}

/// Random boards (reachable or not): the same successors under every skill, and the same
/// log-probabilities of each successor and of the board staying as it is.
#[test]
fn successors_and_their_probabilities_match_libtorchs() {
    let (mut light, torch) = both();
    let mut torch_model = torch.model.unwrap();
    same_successors_and_probabilities(&mut light.model, &mut *torch_model, 300, 3);
}

/// `n` random boards (seeded by `seed`): both models give the same successors under every skill,
/// and the same log-probabilities (within 1e-5) of each successor and of the board staying.
fn same_successors_and_probabilities(
    light: &mut dyn Successor,
    torch: &mut dyn Successor,
    n: usize,
    seed: u64,
) {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let states: Vec<SymbolicState> = (0..n)
        .map(|_| {
            let bits: Vec<bool> = (0..25)
                .map(|_| rand::RngExt::random::<bool>(&mut rng))
                .collect();
            SymbolicState::from_bools(&bits)
        })
        .collect();
    let (mut a, mut b) = (Vec::new(), Vec::new());
    light.successors(&states, &mut a);
    torch.successors(&states, &mut b);
    assert_eq!(a, b);
    let k = light.num_skills();
    let steps: Vec<(SymbolicState, usize, SymbolicState)> = states
        .iter()
        .enumerate()
        .flat_map(|(i, &z)| [(z, i % k, a[i * k + i % k]), (z, (i + 1) % k, z)])
        .collect();
    let la = light.log_likelihoods(&steps).unwrap();
    let lb = torch.log_likelihoods(&steps).unwrap();
    assert_eq!(la.len(), lb.len());
    for (x, y) in la.iter().zip(&lb) {
        assert!((x - y).abs() <= 1e-5 * y.abs().max(1.0), "{x} against {y}");
    }
}

/// 100 test boards of depths 1–5: breadth-first search with either model gives the same plan.
#[test]
fn plans_match_libtorchs_on_a_hundred_boards() {
    let (mut light, torch) = both();
    let mut torch_model = torch.model.unwrap();
    let game = LightsOut::new(5).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    // The agent lacks moves, so most searches run to the bound: 2,000 expansions (of 25
    // successors each, up to 5·10⁶ successors in all) keep the test short; 27 boards still find
    // a plan.
    let config = PlannerConfig {
        max_expanded: Some(2_000),
        ..PlannerConfig::default()
    };
    let mut found = 0;
    for i in 0..100 {
        let moves: Vec<usize> = (0..1 + i % 5)
            .map(|_| rand::RngExt::random_range(&mut rng, 0..25))
            .collect();
        let board = game.apply_all(game.goal(), &moves);
        if game.is_goal(board) {
            continue;
        }
        let a = bfs_plan(&mut light.model, board, game.goal(), &config);
        let b = bfs_plan(&mut *torch_model, board, game.goal(), &config);
        // The same plan after as many expansions; its log-probability to float32 rounding.
        // Of the (state, skill) successors the search saw, a logit within rounding of 0 may
        // decide one differently (one in 10⁴ at most).
        let strip = |p: &Result<seads_planner::Plan, seads_planner::PlanError>| {
            p.clone().map(|p| (p.skills, p.predicted, p.expanded))
        };
        assert_eq!(strip(&a), strip(&b), "board {i}");
        if let (Ok(a), Ok(b)) = (&a, &b) {
            // Weighed by both models or, with nothing to choose, by neither.
            match (a.log_likelihood, b.log_likelihood) {
                (Some(x), Some(y)) => assert!(
                    (x - y).abs() <= 1e-5 * y.abs().max(1.0),
                    "board {i}: {x} against {y}"
                ),
                (x, y) => assert_eq!(x, y, "board {i}"),
            }
            let apart = a.discovered.abs_diff(b.discovered) as f64;
            assert!(
                apart <= 1e-4 * b.discovered as f64,
                "board {i}: {a:?} against {b:?}"
            );
        }
        found += usize::from(a.is_ok());
    }
    assert!(found > 10, "{found} plans");
}

/// The protocol's tasks with re-planning: the same outcome, task for task.
#[test]
fn an_evaluation_matches_libtorchs_task_for_task() {
    let (mut light, torch) = both();
    let mut torch_model = torch.model.unwrap();
    let evaluation = Evaluation {
        env: "lightsout-cursor".into(),
        env_config: EnvConfig::default(),
        tasks: TaskSet::standard(4),
        solve: SolveConfig {
            replan: true,
            planner: PlannerConfig {
                // As above: a failing task searches up to ten times to the bound.
                max_expanded: Some(5_000),
                ..PlannerConfig::default()
            },
            ..SolveConfig::default()
        },
        action_noise: None,
    };
    let outcomes = |policy: &dyn SkillPolicy, model: &mut dyn Successor| {
        let mut tasks = Vec::new();
        evaluate(&evaluation, policy, model, |t| {
            tasks.push((
                t.depth,
                t.seed,
                t.outcome.solved,
                t.outcome.executed.clone(),
            ))
        })
        .unwrap();
        tasks
    };
    let light_tasks = outcomes(&light.policy, &mut light.model);
    let torch_tasks = outcomes(&torch.policy, &mut *torch_model);
    assert_eq!(light_tasks.len(), 20);
    assert_eq!(light_tasks, torch_tasks);
}

/// A missing or damaged run, a checkpoint that is not there and questions the agent cannot
/// answer are errors that say why, never panics.
#[test]
fn bad_runs_and_questions_are_errors() {
    use seads_infer::{Agent, InferError};
    let dir = tempfile::tempdir().unwrap();
    assert!(matches!(
        Agent::load(&dir.path().join("none"), None),
        Err(InferError::Io { .. } | InferError::Missing(_))
    ));
    assert!(matches!(
        Agent::load(run(), Some(999_999)),
        Err(InferError::Missing(_))
    ));
    // A copy whose forward model is cut short.
    let copy = dir.path().join("copy");
    let latest = seads_infer::checkpoint_dir(run(), None).unwrap();
    let target = copy.join("checkpoints").join(latest.file_name().unwrap());
    std::fs::create_dir_all(&target).unwrap();
    for entry in std::fs::read_dir(&latest).unwrap() {
        let entry = entry.unwrap();
        std::fs::copy(entry.path(), target.join(entry.file_name())).unwrap();
    }
    let model = target.join(seads_infer::MODEL_FILE);
    let bytes = std::fs::read(&model).unwrap();
    std::fs::write(&model, &bytes[..bytes.len() / 2]).unwrap();
    let err = Agent::load(&copy, None).unwrap_err();
    assert!(matches!(err, InferError::Damaged { .. }), "{err}");
    assert!(err.to_string().contains("forward_model"), "{err}");
    std::fs::write(&model, b"not a safetensors file").unwrap();
    assert!(matches!(
        Agent::load(&copy, None),
        Err(InferError::Damaged { .. })
    ));
    // Questions.
    let light = Agent::load(run(), None).unwrap();
    let obs = observations(1);
    let none = None::<&mut ChaCha8Rng>;
    assert!(light.policy.actions(&obs, &[0], none).is_ok());
    for (obs, skills, what) in [
        (obs.clone(), vec![25], "skill 25"),
        (obs[1..].to_vec(), vec![0], "observation values"),
        ([&[f32::NAN], &obs[1..]].concat(), vec![0], "NaN"),
    ] {
        let err = light
            .policy
            .actions(&obs, &skills, None::<&mut ChaCha8Rng>)
            .unwrap_err();
        assert!(matches!(err, InferError::Input(_)), "{what}: {err}");
        assert!(err.to_string().contains(what), "{what}: {err}");
    }
}

/// A tiny run whose skill model is the mixture (issue 80), made once.
static MIXTURE_RUN: LazyLock<tempfile::TempDir> = LazyLock::new(|| {
    let dir = tempfile::tempdir().unwrap();
    let mut config = seads_rl::TrainConfig::preset("lightsout-cursor").unwrap();
    config.env_steps = 3000;
    config.sac.hidden = vec![32, 32];
    config
        .edit(|s: &mut seads_rl::SeadsConfig| {
            s.skill_model.kind = seads_skillmodel::SkillModelKind::Mixture;
            s.skill_model.components = Some(3);
            s.skill_model.hidden = vec![32, 32];
            (s.sampled_episodes, s.recent_episodes) = (32, 16);
            s.eval_seeds = 1;
        })
        .unwrap();
    config.eval_every = 50;
    config.checkpoint_every = 50;
    config.sac_threads_alone = 0;
    config.portable_numerics = true;
    let run_dir = dir.path().join("run");
    let mut run = seads_rl::Run::<seads_rl::Trainer>::create(&run_dir, config).unwrap();
    while !run.finished() {
        run.step().unwrap();
    }
    drop(run);
    dir
});

/// The mixture model in plain Rust against libtorch's on the same checkpoint: the same
/// successors of random boards under every skill, and the same log-probabilities within 1e-5.
#[test]
fn the_mixture_models_successors_and_probabilities_match_libtorchs() {
    let run = MIXTURE_RUN.path().join("run");
    let mut light = seads_infer::Agent::load(&run, None).unwrap();
    let torch = seads_rl::Agent::load(&run, None).unwrap();
    assert!(matches!(light.model, seads_infer::Model::Mixture(_)));
    let mut torch_model = torch.model.unwrap();
    same_successors_and_probabilities(&mut light.model, &mut *torch_model, 200, 5);
}
