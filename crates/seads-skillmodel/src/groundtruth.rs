//! Forward models fitted to a game's true move table (skill k = move k): the planner's benches
//! and tests need a learned model whose mode is known.

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use seads_games::{BoardGame, Successor, SymbolicState};
use tch::Device;

use crate::{ForwardModel, SkillModel, SkillModelConfig, SkillTransition};

/// Fits a forward model to `game`'s moves from `steps` batches of random boards and moves.
pub fn fit_to_game(
    game: &dyn BoardGame,
    config: &SkillModelConfig,
    steps: usize,
    seed: u64,
) -> ForwardModel {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut model = ForwardModel::new(
        game.symbolic_len(),
        game.num_moves(),
        config,
        Device::Cpu,
        seed,
    );
    for _ in 0..steps {
        model.train_step(&move_transitions(game, config.batch_size, &mut rng));
    }
    model
}

/// `n` random boards of `game`, each with a move drawn uniformly and the board it leads to: the
/// executions of skills that are the game's moves (skill k = move k).
pub fn move_transitions(
    game: &dyn BoardGame,
    n: usize,
    rng: &mut ChaCha8Rng,
) -> Vec<SkillTransition> {
    (0..n)
        .map(|_| {
            let z0 = game.random_board(rng);
            let skill = rng.random_range(0..game.num_moves());
            SkillTransition {
                z0,
                skill,
                zt: game.apply(z0, skill),
            }
        })
        .collect()
}

/// Fraction of (random board, move) pairs whose predicted successor is exactly the true one.
pub fn agreement_with_game(
    model: &mut ForwardModel,
    game: &dyn BoardGame,
    boards: usize,
    seed: u64,
) -> f64 {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let states: Vec<SymbolicState> = (0..boards).map(|_| game.random_board(&mut rng)).collect();
    let mut out = Vec::new();
    model.successors(&states, &mut out);
    let k = game.num_moves();
    let correct = out
        .iter()
        .enumerate()
        .filter(|&(i, &next)| next == game.apply(states[i / k], i % k))
        .count();
    correct as f64 / out.len() as f64
}
