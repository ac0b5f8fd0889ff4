//! Breadth-first planning with a learned forward model (fitted to the LightsOut 5×5 move table)
//! on test boards of solution depth 5, 7 and 9, one libtorch thread, with the successor
//! function's 8-bit screen (the default) and in float32 alone (`_float32`; the same plans). The
//! model has hidden layers of 64; `seads plan-bench --hidden 256,256 [--float32]` measures the
//! paper's size. `cargo test` runs each bench once as a smoke test, depth 9 left out: the same
//! code as depth 7, and about 40 s of a debug build.

use criterion::{Criterion, criterion_group};
use rand::SeedableRng;
use seads_games::{BoardDataset, BoardGame, LightsOut, Split};
use seads_planner::{PlannerConfig, bfs_plan};
use seads_skillmodel::{SkillModelConfig, agreement_with_game, fit_to_game};

fn planner(c: &mut Criterion) {
    tch::set_num_threads(1);
    let game = LightsOut::new(5).expect("5×5");
    let config = SkillModelConfig {
        hidden: vec![64, 64],
        batch_size: 256,
        ..SkillModelConfig::default()
    };
    let mut model = fit_to_game(&game, &config, 1500, 1);
    assert!(
        agreement_with_game(&mut model, &game, 1000, 2) > 0.999,
        "the bench model reproduces the move table"
    );
    // `cargo bench` passes `--bench`; `cargo test` (each bench once) does not.
    let measuring = std::env::args().any(|a| a == "--bench");
    let depths: &[usize] = if measuring { &[5, 7, 9] } else { &[5, 7] };
    let boards = BoardDataset::build(&game, depths[depths.len() - 1]).expect("enumerable");
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
    let mut group = c.benchmark_group("bfs_plan_learned_lightsout");
    group.sample_size(10);
    for &depth in depths {
        let board = boards
            .sample(depth, Split::Test, &mut rng)
            .expect("boards of this depth");
        for (suffix, screen) in [("", true), ("_float32", false)] {
            model.set_int8_screen(screen);
            group.bench_function(format!("depth_{depth}{suffix}"), |b| {
                b.iter(|| {
                    let plan = bfs_plan(&mut model, board, game.goal(), &PlannerConfig::default())
                        .expect("a plan");
                    assert_eq!(plan.skills.len(), depth);
                })
            });
        }
    }
    group.finish();
}

criterion_group!(benches, planner);
