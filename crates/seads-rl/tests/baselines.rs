//! The task-reward baselines, flat SAC (SPEC §5.1) and two-level HAC (SPEC §5.2): the update
//! schedule by hand, determinism, exact resume through a run directory, task success on the
//! SEADS protocol's boards, and the presets against the seed's settings.

use seads_planner::TaskSet;
use seads_rl::store::read_metrics_as;
use seads_rl::{
    BaselineConfig, Hac, HacConfig, Learner, Run, TaskMetrics, TaskSac, TrainConfig, task_success,
    updates_due,
};

/// A small baseline run on LightsOutCursor: 8 environments, one update per epoch once 32
/// transitions are stored.
fn small(seed: u64, steps: u64) -> TrainConfig {
    small_of("sac", seed, steps)
}

fn small_of(algorithm: &str, seed: u64, steps: u64) -> TrainConfig {
    let mut config = TrainConfig::preset_for("lightsout-cursor", algorithm).unwrap();
    config.seed = seed;
    config.env_steps = steps;
    config.sac.hidden = vec![32, 32];
    config.sac.batch_size = 32;
    if config.is::<BaselineConfig>() {
        config
            .edit(|s: &mut BaselineConfig| s.eval_boards = 2)
            .unwrap();
    }
    config.eval_every = 20;
    config.checkpoint_every = 20;
    config.portable_numerics = true;
    // Subgoals of 7 steps in episodes of 10·S: checkpoints fall inside subgoal attempts.
    if config.is::<HacConfig>() {
        config
            .edit(|hac: &mut HacConfig| (hac.eval_boards, hac.subgoal_horizon) = (2, 7))
            .unwrap();
    }
    config
}

/// A metrics line without its wall-clock fields.
type Numbers = (u64, u64, Vec<f64>, u64, u32, u32);

/// The metrics without the wall-clock fields.
fn numbers(metrics: &[TaskMetrics]) -> Vec<Numbers> {
    metrics
        .iter()
        .map(|m| {
            (
                m.epoch,
                m.env_steps,
                m.success.clone(),
                m.train_solved.to_bits(),
                m.critic_loss.to_bits(),
                m.actor_loss.to_bits(),
            )
        })
        .collect()
}

#[test]
fn the_update_schedule_follows_n_per_epoch() {
    let over =
        |n: f64, epochs: u64| -> Vec<usize> { (0..epochs).map(|e| updates_due(e, n)).collect() };
    assert_eq!(over(1.0, 4), [1, 1, 1, 1]);
    assert_eq!(over(2.0, 3), [2, 2, 2]);
    // N < 1: one update every 1/N epochs (SPEC §5.1: 16 samples per update for N = 0.5, 32 for
    // N = 0.25 with 8 samples per epoch).
    assert_eq!(over(0.5, 6), [0, 1, 0, 1, 0, 1]);
    assert_eq!(over(0.25, 8), [0, 0, 0, 1, 0, 0, 0, 1]);
}

/// The numbers of a whole run of `config`.
fn whole_run<L: Learner<Metrics = TaskMetrics>>(config: TrainConfig) -> Vec<Numbers> {
    let dir = tempfile::tempdir().unwrap();
    let mut run = Run::<L>::create(dir.path(), config).unwrap();
    while !run.finished() {
        run.step().unwrap();
    }
    numbers(&read_metrics_as::<TaskMetrics>(dir.path()).unwrap())
}

/// Two runs of one seed are the same run, bit for bit; another seed is another run.
fn a_seed_gives_the_same_run<L: Learner<Metrics = TaskMetrics>>(algorithm: &str) {
    let a = whole_run::<L>(small_of(algorithm, 4, 480));
    assert_eq!(
        a.len(),
        4,
        "evaluations at epochs 1, 20, 40 and 60 (the last)"
    );
    assert_eq!(a, whole_run::<L>(small_of(algorithm, 4, 480)));
    assert_ne!(a, whole_run::<L>(small_of(algorithm, 5, 480)));
}

#[test]
fn a_seed_gives_the_same_sac_run() {
    a_seed_gives_the_same_run::<TaskSac>("sac");
}

#[test]
fn a_seed_gives_the_same_hac_run() {
    a_seed_gives_the_same_run::<Hac>("hac");
}

/// A run stopped after its epoch-40 checkpoint and resumed in a new process state (a fresh
/// `Run`) ends exactly as the uninterrupted run: the replay buffers, the streams, the open
/// episodes (replayed from their seeds and actions) and HAC's subgoals are all restored.
fn a_resumed_run_is_the_uninterrupted_run<L: Learner<Metrics = TaskMetrics>>(algorithm: &str) {
    let config = || small_of(algorithm, 6, 800);
    let whole = whole_run::<L>(config());
    let parted = tempfile::tempdir().unwrap();
    let mut run = Run::<L>::create(parted.path(), config()).unwrap();
    // Past the checkpoint at epoch 40: epochs 41–52 are lost and redone.
    for _ in 0..52 {
        run.step().unwrap();
    }
    drop(run);
    let mut run = Run::<L>::resume(parted.path()).unwrap();
    assert_eq!(run.trainer().epoch(), 40);
    while !run.finished() {
        run.step().unwrap();
    }
    assert_eq!(
        numbers(&read_metrics_as::<TaskMetrics>(parted.path()).unwrap()),
        whole
    );
}

#[test]
fn a_resumed_sac_run_is_the_uninterrupted_run() {
    a_resumed_run_is_the_uninterrupted_run::<TaskSac>("sac");
}

#[test]
fn a_resumed_hac_run_is_the_uninterrupted_run() {
    a_resumed_run_is_the_uninterrupted_run::<Hac>("hac");
}

/// Task success runs the SEADS protocol's test boards: every depth 1–5, the requested number of
/// boards each, and a solved task took at most T_lim = 10·S steps.
#[test]
fn task_success_covers_every_depth() {
    let config = small(1, 800);
    let agent = TaskSac::new(config.clone()).unwrap();
    let mut ended = Vec::new();
    let results = task_success(
        &config,
        &mut agent.policy(),
        &TaskSet::standard(3),
        |depth, seed, board, solved| ended.push((depth, seed, board, solved)),
    )
    .unwrap();
    assert_eq!(
        results.iter().map(|r| r.depth).collect::<Vec<_>>(),
        [1, 2, 3, 4, 5]
    );
    // Each task's board has the depth it is counted under (the GF(2) solver's, independent of
    // the task environment), and the tallies are those of the tasks as they ended.
    let game = seads_games::LightsOut::new(5).unwrap();
    for r in &results {
        let tasks: Vec<_> = ended.iter().filter(|t| t.0 == r.depth).collect();
        assert_eq!((r.tasks, tasks.len()), (3, 3));
        for &&(depth, _, board, _) in &tasks {
            assert_eq!(game.solver().depth(board).unwrap(), depth);
        }
        let solved = tasks.iter().filter(|t| t.3).count();
        assert_eq!((r.solved, r.solution_steps.len()), (solved, solved));
        assert!(
            r.solution_steps
                .iter()
                .all(|&s| (1..=10 * r.depth).contains(&s))
        );
    }
}

/// The shipped presets carry SPEC §5.1's settings: 3 × 512 units, batch 256, a replay buffer of
/// 10⁶, 8 samples per epoch, and the seed's best (N, α) per environment.
#[test]
fn presets_carry_the_seeds_best_settings() {
    let best = [
        ("lightsout-cursor", 1.0, 0.1),
        ("tileswap-cursor", 1.0, 0.1),
        ("lightsout-reacher", 0.5, 0.001),
        ("tileswap-reacher", 0.25, 0.001),
        ("lightsout-jaco", 0.5, 0.0001),
        ("tileswap-jaco", 0.5, 0.0001),
    ];
    assert_eq!(
        TrainConfig::preset_envs("sac").len(),
        12,
        "and LightsOut3DJaco, sliding-cursor and -reacher, and the three -reacher3"
    );
    for (env, n, alpha) in best {
        let c = TrainConfig::preset_for(env, "sac").unwrap();
        c.validate().unwrap();
        assert_eq!(c.algorithm(), "sac");
        assert_eq!(c.env, env);
        assert_eq!(c.sac.hidden, [512, 512, 512]);
        assert_eq!(
            (c.sac.batch_size, c.sac.lr, c.sac.gamma, c.sac.tau),
            (256, 3e-4, 0.99, 0.005)
        );
        assert_eq!(
            (
                c.section::<BaselineConfig>().unwrap().updates_per_epoch,
                c.sac.alpha
            ),
            (n, alpha),
            "{env}"
        );
        assert_eq!(
            (
                c.section::<BaselineConfig>().unwrap().replay_capacity,
                c.section::<BaselineConfig>().unwrap().samples_per_epoch
            ),
            (1_000_000, 8)
        );
        let budget = if env.ends_with("cursor") {
            500_000
        } else {
            10_000_000
        };
        assert_eq!(c.env_steps, budget);
    }
}

/// A config.toml states its algorithm and holds that algorithm's section only, defaults
/// included, and reads back equal.
#[test]
fn configs_round_trip_through_toml() {
    let sac = TrainConfig::preset_for("tileswap-cursor", "sac").unwrap();
    let text = sac.to_toml();
    assert!(
        text.contains("[sac_baseline]") && text.contains("updates_per_epoch = 1.0"),
        "{text}"
    );
    assert!(
        !text.contains("[seads") && !text.contains("[hac]"),
        "{text}"
    );
    assert_eq!(TrainConfig::from_toml(&text).unwrap(), sac);
    let seads = TrainConfig::preset("tileswap-cursor").unwrap();
    let text = seads.to_toml();
    assert!(
        text.contains("[seads]") && text.contains("[seads.relabel]"),
        "{text}"
    );
    assert!(
        !text.contains("baseline") && !text.contains("[hac]"),
        "{text}"
    );
    // Every config states its algorithm, SEADS's too.
    assert!(text.contains("algorithm = \"seads\""), "{text}");
    assert_eq!(TrainConfig::from_toml(&text).unwrap(), seads);
}

/// The HAC presets carry SPEC §5.2's settings: 2 × 512 units for both levels, lr 3·10⁻⁴,
/// τ 0.005, γ 0.99, and the seed's best (τ_RB, α_low, α_high) per environment.
#[test]
fn hac_presets_carry_the_seeds_best_settings() {
    let best = [
        ("lightsout-cursor", 0.1, 0.1, 0.001),
        ("tileswap-cursor", 0.5, 0.5, 0.001),
        ("lightsout-reacher", 0.1, 0.0001, 0.0001),
        ("tileswap-reacher", 0.1, 0.0001, 0.0001),
        ("lightsout-jaco", 0.1, 0.001, 0.001),
        ("tileswap-jaco", 0.1, 0.0001, 0.001),
    ];
    // The paper's seven, the sliding puzzle's two with its TileSwap counterparts' settings, and
    // the three-link arm's three with the two-link Reacher's.
    assert_eq!(TrainConfig::preset_envs("hac").len(), 12);
    for (sliding, tileswap) in [
        ("sliding-cursor", "tileswap-cursor"),
        ("sliding-reacher", "tileswap-reacher"),
        ("lightsout-reacher3", "lightsout-reacher"),
        ("tileswap-reacher3", "tileswap-reacher"),
        ("sliding-reacher3", "tileswap-reacher"),
    ] {
        let a = TrainConfig::preset_for(sliding, "hac").unwrap();
        let b = TrainConfig::preset_for(tileswap, "hac").unwrap();
        assert_eq!(
            (a.section::<HacConfig>().unwrap().temperature, a.sac.alpha),
            (b.section::<HacConfig>().unwrap().temperature, b.sac.alpha)
        );
    }
    for (env, temperature, alpha_low, alpha_high) in best {
        let c = TrainConfig::preset_for(env, "hac").unwrap();
        c.validate().unwrap();
        assert_eq!((c.algorithm(), c.env.as_str()), ("hac", env));
        assert_eq!(c.sac.hidden, [512, 512]);
        assert_eq!((c.sac.lr, c.sac.gamma, c.sac.tau), (3e-4, 0.99, 0.005));
        assert_eq!(
            (
                c.section::<HacConfig>().unwrap().temperature,
                c.sac.alpha,
                c.section::<HacConfig>().unwrap().alpha_high
            ),
            (temperature, alpha_low, alpha_high),
            "{env}"
        );
        // A subgoal gets the steps of one skill: T_max = 10 (Cursor) or 50.
        let horizon = if env.ends_with("cursor") { 10 } else { 50 };
        assert_eq!(c.section::<HacConfig>().unwrap().subgoal_horizon, horizon);
        let sac = TrainConfig::preset_for(env, "sac").unwrap();
        assert_eq!(
            c.section::<HacConfig>().unwrap().training(),
            sac.section::<BaselineConfig>().unwrap(),
            "{env}: N and the buffer as for SAC"
        );
        assert_eq!(c.env_steps, sac.env_steps);
    }
}

/// A HAC config.toml names all of `[hac]`, defaults included, and reads back equal.
#[test]
fn hac_configs_round_trip_through_toml() {
    let mut hac = TrainConfig::preset_for("lightsout-cursor", "hac").unwrap();
    hac.learner = seads_rl::LearnerConfig::of(&HacConfig::default()).unwrap();
    let text = hac.to_toml();
    assert!(
        text.contains("[hac]") && text.contains("replay_capacity = 1000000"),
        "{text}"
    );
    assert!(
        !text.contains("baseline") && !text.contains("[seads"),
        "{text}"
    );
    assert_eq!(TrainConfig::from_toml(&text).unwrap(), hac);
}

/// Bad values and settings of another algorithm are refused with a message naming them.
#[test]
fn bad_baseline_settings_are_refused() {
    let refused = |text: &str, needle: &str| {
        let e = TrainConfig::from_toml(text).unwrap_err().to_string();
        assert!(e.contains(needle), "{text:?}: {e}");
    };
    refused(
        "algorithm = \"ppo\"",
        "unknown learner \"ppo\" (one of diayn, hac, sac, seads)",
    );
    refused(
        "algorithm = \"hac\"\n[hac]\ntemperature = 0.0",
        "hac.temperature",
    );
    refused(
        "algorithm = \"hac\"\n[hac]\ntemperature = -1.0",
        "hac.temperature",
    );
    refused(
        "algorithm = \"hac\"\n[hac]\nsubgoal_horizon = 0",
        "hac.subgoal_horizon",
    );
    refused(
        "algorithm = \"sac\"\n[sac_baseline]\nupdates_per_epoch = 0.0",
        "sac_baseline.updates_per_epoch must be positive",
    );
    refused(
        "algorithm = \"hac\"\n[hac]\neval_boards = 0",
        "hac.eval_boards",
    );
    refused(
        "algorithm = \"sac\"\n[seads]\nnum_skills = 30",
        "[seads] is the section of algorithm \"seads\", not of this run's \"sac\"",
    );
    refused(
        "algorithm = \"hac\"\n[seads.relabel]\nsac_p = 0.0",
        "[seads] is the section of algorithm \"seads\", not of this run's \"hac\"",
    );
    refused("[hac]\ntemperature = 0.5", "[hac] is the section");
    refused(
        "algorithm = \"sac\"\n[hac]\ntemperature = 0.5",
        "[hac] is the section of algorithm \"hac\", not of this run's \"sac\"",
    );
    refused(
        "[sac_baseline]\nsamples_per_epoch = 4",
        "[sac_baseline] is the section",
    );
    // SAC's steps per epoch are each learner's own (`sac_baseline.updates_per_epoch`).
    refused(
        "algorithm = \"sac\"\n[sac]\nupdates_per_epoch = 4",
        "unknown field `updates_per_epoch`",
    );
    // The flat layout of older files is read no more (`seads migrate` rewrites it).
    refused(
        "algorithm = \"sac\"\n[baseline]\nupdates_per_epoch = 0.5",
        "unknown field `baseline`",
    );
    refused(
        "algorithm = \"sac\"\nnum_skills = 30",
        "unknown field `num_skills`",
    );
    refused(
        "algorithm = \"hac\"\n[relabel]\nsac_p = 0.0",
        "unknown field `relabel`",
    );
}

/// HAC's task success runs the protocol as SAC's does: every depth, the requested boards, and a
/// solved task within T_lim.
#[test]
fn hac_task_success_covers_every_depth() {
    let config = small_of("hac", 1, 800);
    let agent = Hac::new(config.clone()).unwrap();
    let results = task_success(
        &config,
        &mut agent.policy(),
        &TaskSet::standard(3),
        |_, _, _, _| {},
    )
    .unwrap();
    assert_eq!(results.len(), 5);
    for r in &results {
        assert_eq!(r.tasks, 3);
        assert!(r.solution_steps.iter().all(|&s| s <= 10 * r.depth));
    }
}

/// HAC's high level on a toy problem: on a board z ∈ {0,1}⁴ it proposes a subgoal, and a
/// subgoal is reachable when one move (one flipped bit) away. Rewarded 1 for a reachable
/// subgoal (the attempt succeeds) and 0 otherwise (a tested subgoal that is missed), the discrete
/// SAC with the RelaxedBernoulli policy learns to propose a reachable subgoal on (almost) every
/// board, where a random subgoal is reachable on a quarter of the proposals.
#[test]
fn hacs_high_level_learns_to_propose_reachable_subgoals() {
    use rand::{RngExt, SeedableRng};
    use seads_rl::{Sac, SacConfig, TransitionBatch};
    const D: usize = 4;
    let config = SacConfig {
        hidden: vec![64, 64],
        alpha: 0.01,
        lr: 1e-3,
        batch_size: 64,
        ..SacConfig::default()
    };
    let mut high = Sac::relaxed_bernoulli(D, D, 0.1, &config, tch::Device::Cpu, 3);
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
    let bits = |board: usize| -> Vec<f32> { (0..D).map(|d| ((board >> d) & 1) as f32).collect() };
    let reachable = |board: usize, subgoal: &[f32]| {
        let flipped = (0..D).filter(|&d| (subgoal[d] > 0.5) != ((board >> d) & 1 == 1));
        flipped.count() == 1
    };
    let share = |high: &Sac| {
        let hits = (0..1 << D).filter(|&b| reachable(b, &high.act(&bits(b), None)));
        hits.count() as f64 / (1 << D) as f64
    };
    let mut replay: Vec<(Vec<f32>, Vec<f32>, f32)> = Vec::new();
    let before = share(&high);
    for _ in 0..1000 {
        for _ in 0..8 {
            let board = rng.random_range(0..1 << D);
            let subgoal = high.act(&bits(board), Some(&mut rng));
            let reward = f32::from(u8::from(reachable(board, &subgoal)));
            replay.push((bits(board), subgoal, reward));
        }
        let mut batch = TransitionBatch::default();
        for _ in 0..config.batch_size {
            let (obs, action, reward) = &replay[rng.random_range(0..replay.len())];
            batch.obs.extend(obs);
            batch.actions.extend(action);
            batch.rewards.push(*reward);
            batch.next_obs.extend(obs);
            batch.dones.push(1.0);
        }
        high.update(&batch, &mut rng);
    }
    // A factorised policy cannot spread over the four reachable subgoals of a board, so the
    // fixed entropy bonus may leave one board's mode between two of them.
    assert!(before < 0.5, "the untrained policy: {before}");
    let after = share(&high);
    assert!(after >= 0.9, "reachable on {after} of the boards");
}

/// A checkpoint written by a run of another environment is refused on resume and on loading its
/// policy, with both environments named.
#[test]
fn a_checkpoint_of_another_environment_is_refused_naming_both() {
    let train = |config: TrainConfig| {
        let dir = tempfile::tempdir().unwrap();
        let mut run = Run::<TaskSac>::create(dir.path(), config).unwrap();
        while !run.finished() {
            run.step().unwrap();
        }
        dir
    };
    let lightsout = train(small(1, 160));
    let mut config = small(1, 160);
    config.env = "tileswap-cursor".into();
    let tileswap = train(config.clone());
    // The tileswap run's checkpoints replaced by the lightsout run's.
    let checkpoints = tileswap.path().join("checkpoints");
    std::fs::remove_dir_all(&checkpoints).unwrap();
    std::fs::create_dir(&checkpoints).unwrap();
    for entry in std::fs::read_dir(lightsout.path().join("checkpoints")).unwrap() {
        let entry = entry.unwrap();
        let to = checkpoints.join(entry.file_name());
        if entry.file_type().unwrap().is_dir() {
            std::fs::create_dir(&to).unwrap();
            for file in std::fs::read_dir(entry.path()).unwrap() {
                let file = file.unwrap();
                std::fs::copy(file.path(), to.join(file.file_name())).unwrap();
            }
        } else {
            std::fs::copy(entry.path(), &to).unwrap();
        }
    }
    let chain = |e: &dyn std::error::Error| {
        let mut text = e.to_string();
        let mut source = e.source();
        while let Some(s) = source {
            text += &format!(": {s}");
            source = s.source();
        }
        text
    };
    let e = Run::<TaskSac>::resume(tileswap.path())
        .err()
        .expect("refused");
    let text = chain(&e);
    assert!(
        text.contains("a sac run on lightsout-cursor, not a sac run on tileswap-cursor"),
        "{text}"
    );
    let latest = seads_rl::store::latest_checkpoint(tileswap.path())
        .unwrap()
        .unwrap();
    let e = seads_rl::load_policy(&config, &latest)
        .err()
        .expect("refused");
    assert!(
        chain(&e).contains("on lightsout-cursor, not"),
        "{}",
        chain(&e)
    );
}

/// One evaluation protocol: a baseline's policy evaluation and a SEADS planning evaluation of the
/// same task set play the same boards, beyond the authors' 20 seeds too (30 boards per depth).
#[test]
fn policy_and_planning_evaluations_play_the_same_boards() {
    /// Zero actions: the boards, not the outcomes, are compared.
    struct Still(usize);
    impl seads_rl::TaskPolicy for Still {
        fn act(&mut self, _: &[f32]) -> Vec<f32> {
            vec![0.0; self.0]
        }
    }
    impl seads_embodiment::SkillPolicy for Still {
        fn num_skills(&self) -> usize {
            25
        }
        fn act(&self, _: &[f32], _: &[usize], actions: &mut [f32]) {
            actions.fill(0.0);
        }
    }
    let config = small(1, 100);
    let spec = seads_embodiment::make_env(&config.env, &config.env_config)
        .unwrap()
        .spec()
        .clone();
    let still = Still(spec.action_dim);
    let tasks = TaskSet {
        depths: vec![1, 4],
        ..TaskSet::standard(30)
    };
    let mut policy_boards = Vec::new();
    task_success(
        &config,
        &mut Still(spec.action_dim),
        &tasks,
        |depth, seed, board, _| {
            policy_boards.push((depth, seed, board));
        },
    )
    .unwrap();
    let game = seads_games::LightsOut::new(5).unwrap();
    let evaluation = seads_planner::Evaluation {
        env: config.env.clone(),
        env_config: config.env_config.clone(),
        tasks: tasks.clone(),
        solve: seads_planner::SolveConfig::default(),
        action_noise: None,
    };
    let mut planning_boards = Vec::new();
    seads_planner::evaluate(
        &evaluation,
        &still,
        &mut seads_games::GameSuccessor::new(&game),
        |task| planning_boards.push((task.depth, task.seed, task.board)),
    )
    .unwrap();
    assert_eq!(policy_boards.len(), 60);
    assert_eq!(policy_boards, planning_boards);
    // The authors' seeds come first, and every board has its depth.
    assert_eq!(policy_boards[0].1, seads_planner::EVALUATION_SEEDS[0]);
    let solver = seads_games::Gf2Solver::new(&game);
    for (depth, _, board) in &policy_boards {
        assert_eq!(solver.depth(*board).unwrap(), *depth);
    }
}
