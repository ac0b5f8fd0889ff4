//! Task mode (SPEC §5.1) against independent sources: the games' own board data sets for the
//! depths, hand-counted time limits, and a scripted cursor that solves the board.

use seads_embodiment::{EnvConfig, EnvError, TaskEnv, make_env};
use seads_games::{BoardDataset, LightsOut, Split, TileSwap};

fn task(name: &str, config: &EnvConfig) -> TaskEnv {
    TaskEnv::new(make_env(name, config).unwrap(), config.max_solution_depth).unwrap()
}

/// Training episodes: S ~ U{1..5} from the train split, T_lim = 10·S on the Cursor, 50·S on the
/// Reacher; the depth is the data set's, which enumerates the boards by itself.
#[test]
fn training_episodes_draw_every_depth_and_scale_the_time_limit() {
    let lightsout = BoardDataset::build(&LightsOut::new(5).unwrap(), 5).unwrap();
    let tileswap = BoardDataset::build(&TileSwap::new(), 5).unwrap();
    for (name, data, per_depth) in [
        ("lightsout-cursor", &lightsout, 10),
        ("tileswap-cursor", &tileswap, 10),
        ("lightsout-reacher", &lightsout, 50),
    ] {
        let mut env = task(name, &EnvConfig::default());
        let mut counts = [0usize; 6];
        for seed in 0..300 {
            env.seed(seed);
            let depth = env.reset().unwrap();
            assert!(
                data.boards(depth, Split::Train)
                    .contains(&env.env().board()),
                "{name}, seed {seed}: a train board of depth {depth}"
            );
            assert_eq!(env.limit(), per_depth * depth, "{name}");
            assert_eq!(env.env().spec().step_limit, Some(env.limit()));
            counts[depth] += 1;
        }
        // 300 draws of U{1..5}: each depth 60 times in expectation; below 30 or above 90 has a
        // probability under 1e-5 per depth.
        assert_eq!(counts[0], 0);
        for (depth, &n) in counts.iter().enumerate().skip(1) {
            assert!(
                (30..=90).contains(&n),
                "{name}: depth {depth} drawn {n} times"
            );
        }
    }
}

/// Evaluation episodes: a fixed depth on the test split, as in the SEADS protocol.
#[test]
fn evaluation_episodes_have_the_fixed_depth_and_test_boards() {
    let data = BoardDataset::build(&LightsOut::new(5).unwrap(), 5).unwrap();
    for depth in 1..=5 {
        let config = EnvConfig {
            reset_split: Split::Test,
            max_solution_depth: depth,
            random_solution_depth: false,
            ..EnvConfig::default()
        };
        let mut env = task("lightsout-cursor", &config);
        for seed in 0..20 {
            env.seed(seed);
            assert_eq!(env.reset().unwrap(), depth);
            assert!(data.boards(depth, Split::Test).contains(&env.env().board()));
            assert_eq!(env.limit(), 10 * depth);
        }
    }
}

/// Doing nothing: reward 0 on every step, the episode ends exactly at T_lim, the time left in the
/// observation counts down to 0, and a further step is an error until the next reset.
#[test]
fn an_unsolved_episode_ends_at_the_time_limit() {
    let mut env = task("lightsout-cursor", &EnvConfig::default());
    env.seed(3);
    let depth = env.reset().unwrap();
    let obs_dim = env.spec().obs_dim;
    let mut obs = vec![0.0; obs_dim];
    env.observe(&mut obs);
    assert_eq!(obs[obs_dim - 1], 1.0);
    for t in 1..=10 * depth {
        let step = env.step(&[0.0, 0.0, -1.0]).unwrap();
        assert_eq!((step.reward, step.solved), (0.0, false));
        assert_eq!(step.done, t == 10 * depth, "step {t}");
        env.observe(&mut obs);
        assert!((obs[obs_dim - 1] - (1.0 - t as f32 / (10 * depth) as f32)).abs() < 1e-6);
    }
    assert!(matches!(
        env.step(&[0.0, 0.0, -1.0]),
        Err(EnvError::EpisodeOver { .. })
    ));
    env.reset().unwrap();
    assert!(env.step(&[0.0, 0.0, -1.0]).is_ok());
}

/// A cursor that presses the one field of a depth-1 board: reward 1 on the pressing step, which
/// ends the episode.
#[test]
fn solving_the_board_pays_one_and_ends_the_episode() {
    let game = LightsOut::new(5).unwrap();
    let config = EnvConfig {
        max_solution_depth: 1,
        random_solution_depth: false,
        ..EnvConfig::default()
    };
    let mut env = task("lightsout-cursor", &config);
    for seed in 0..5 {
        env.seed(seed);
        assert_eq!(env.reset().unwrap(), 1);
        let board = env.env().board();
        let mv = (0..25)
            .find(|&m| {
                seads_games::BoardGame::apply(&game, board, m)
                    == seads_games::BoardGame::goal(&game)
            })
            .unwrap();
        let target = [((mv % 5) as f32 + 0.5) / 5.0, ((mv / 5) as f32 + 0.5) / 5.0];
        let mut rewards = Vec::new();
        loop {
            let obs = env.env().observation();
            let (dx, dy) = (target[0] - obs[0], target[1] - obs[1]);
            let arrived = dx.abs() < 1e-3 && dy.abs() < 1e-3;
            let push = if arrived { 1.0 } else { -1.0 };
            let step = env
                .step(&[dx.clamp(-0.2, 0.2), dy.clamp(-0.2, 0.2), push])
                .unwrap();
            rewards.push(step.reward);
            if step.done {
                assert!(step.solved, "seed {seed}: solved within 10 steps");
                break;
            }
        }
        assert_eq!(rewards.last(), Some(&1.0));
        assert_eq!(rewards.iter().sum::<f32>(), 1.0);
    }
}

/// The deepest tasks: 5×5 LightsOut boards of depth 15 (its largest), TileSwap boards of depth 10,
/// and 7×7 boards of four random presses. The depth a reset reports is the one breadth-first
/// search finds (the games' enumerations; 7×7 by the layers of a search from the goal), with no
/// map of every board built first (that took minutes and half a gigabyte at depth 10).
#[test]
fn the_deepest_tasks_report_the_breadth_first_depth() {
    let lightsout = seads_games::enumerate(&LightsOut::new(5).unwrap(), None).unwrap();
    let tileswap = seads_games::enumerate(&TileSwap::new(), None).unwrap();
    for (name, depth, e, size) in [
        ("lightsout-cursor", 15, &lightsout, 5),
        ("tileswap-cursor", 10, &tileswap, 3),
    ] {
        let config = EnvConfig {
            reset_split: Split::Test,
            max_solution_depth: depth,
            random_solution_depth: false,
            ..EnvConfig::default()
        };
        let mut env = task(name, &config);
        let layer: std::collections::BTreeSet<u32> = e.layer(depth).iter().copied().collect();
        for seed in 0..10 {
            env.seed(seed);
            assert_eq!(env.reset().unwrap(), depth, "{name}");
            let board = env.env().board();
            let index = if size == 5 {
                seads_games::Enumerable::index_of(&LightsOut::new(5).unwrap(), board)
            } else {
                seads_games::Enumerable::index_of(&TileSwap::new(), board)
            };
            assert!(
                layer.contains(&index),
                "{name}: a board of the depth-{depth} layer"
            );
        }
    }
    // 7×7: boards made by 4 distinct presses; their true depth by breadth-first search from the
    // goal, layer by layer.
    let game = LightsOut::new(7).unwrap();
    let mut layers = vec![std::collections::BTreeSet::from([
        seads_games::BoardGame::goal(&game),
    ])];
    let mut seen = layers[0].clone();
    for _ in 0..4 {
        let mut next = std::collections::BTreeSet::new();
        for &b in layers.last().unwrap() {
            for mv in 0..49 {
                let after = seads_games::BoardGame::apply(&game, b, mv);
                if seen.insert(after) {
                    next.insert(after);
                }
            }
        }
        layers.push(next);
    }
    let config = EnvConfig {
        board_size: Some(7),
        max_solution_depth: 4,
        random_solution_depth: false,
        ..EnvConfig::default()
    };
    let mut env = task("lightsout-cursor", &config);
    for seed in 0..10 {
        env.seed(seed);
        let depth = env.reset().unwrap();
        assert!(
            layers[depth].contains(&env.env().board()),
            "7×7 seed {seed}"
        );
    }
}
