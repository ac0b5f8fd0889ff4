//! The forward model's successors: the 8-bit screen gives float32's successors, untrained and
//! fitted, and the batched successor is the mode of the per-pair flip probabilities.

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use seads_games::{Successor, SymbolicState};
use seads_skillmodel::{ForwardModel, SkillModel, SkillModelConfig, SkillTransition, fit_to_game};
use tch::Device;

/// Successors of `states` with the 8-bit screen and in float32 alone.
fn both_ways(
    model: &mut ForwardModel,
    states: &[SymbolicState],
) -> (Vec<SymbolicState>, Vec<SymbolicState>) {
    let (mut screened, mut exact) = (Vec::new(), Vec::new());
    model.set_int8_screen(true);
    model.successors(states, &mut screened);
    model.set_int8_screen(false);
    model.successors(states, &mut exact);
    model.set_int8_screen(true);
    (screened, exact)
}

fn random_states(n: usize, seed: u64) -> Vec<SymbolicState> {
    use rand::RngExt;
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    (0..n)
        .map(|_| SymbolicState::from_u64(rng.random_range(0..1u64 << 25)))
        .collect()
}

/// An untrained model has many logits near 0: the screen must send those states to float32.
#[test]
fn the_int8_screen_gives_the_float_successors_of_an_untrained_model() {
    let mut model = ForwardModel::new(25, 25, &SkillModelConfig::default(), Device::Cpu, 11);
    let states = random_states(300, 1);
    let (screened, exact) = both_ways(&mut model, &states);
    assert_eq!(screened, exact);
    let (seen, redone) = model.screen_counts();
    assert_eq!(seen, 300 * 25);
    assert!(redone > 0, "an untrained model has logits within the bound");
    // A small batch goes straight to float32.
    let _ = both_ways(&mut model, &states[..100]);
    assert_eq!(model.screen_counts(), (seen, redone));
}

/// A model fitted to the LightsOut moves: the screen decides most states itself, and every
/// successor equals float32's, also after further training (the screen follows the weights).
#[test]
fn the_int8_screen_gives_the_float_successors_of_a_fitted_model() {
    let game = seads_games::LightsOut::new(5).unwrap();
    let config = SkillModelConfig {
        hidden: vec![128, 128],
        batch_size: 256,
        ..SkillModelConfig::default()
    };
    let mut model = fit_to_game(&game, &config, 400, 3);
    let states = random_states(2000, 2);
    let (screened, exact) = both_ways(&mut model, &states);
    assert_eq!(screened, exact);
    let (seen, redone) = model.screen_counts();
    assert_eq!(seen, 2000 * 25);
    assert!(
        redone < seen / 20,
        "{redone} of {seen} states computed again"
    );
    let batch: Vec<SkillTransition> = states
        .iter()
        .take(256)
        .map(|&z0| SkillTransition {
            z0,
            skill: 3,
            zt: z0,
        })
        .collect();
    for _ in 0..20 {
        model.train_step(&batch);
    }
    let (screened, exact) = both_ways(&mut model, &states);
    assert_eq!(screened, exact);
}

/// The batched successor agrees with the per-pair mode computed from `flip_logits`.
#[test]
fn successors_are_the_mode_of_the_model() {
    let mut model = ForwardModel::new(25, 25, &SkillModelConfig::default(), Device::Cpu, 4);
    let states: Vec<SymbolicState> = (0..7u64)
        .map(|i| SymbolicState::from_u64(i * 0x15_4321 % (1 << 25)))
        .collect();
    let mut out = Vec::new();
    model.successors(&states, &mut out);
    assert_eq!(out.len(), 7 * 25);
    for (i, &z) in states.iter().enumerate() {
        for k in 0..25 {
            let logits = Vec::<f32>::try_from(model.flip_logits(&[z], &[k]).view([-1])).unwrap();
            let mut expected = z;
            for (d, &x) in logits.iter().enumerate() {
                let p = 1.0 / (1.0 + (-x).exp());
                let alpha = if z.get(d) { 1.0 - p } else { p };
                expected.set(d, alpha > 0.5);
            }
            assert_eq!(out[i * 25 + k], expected, "state {i}, skill {k}");
        }
    }
}

/// A state's successors do not depend on the other states of its call: computed in pieces of
/// any size, or through the planner's memory of successors (which computes only the states it
/// has not seen, in calls of other compositions), they equal those of one call. An untrained
/// model has many logits near 0, where a different summation would show. Its hidden layers are
/// narrow: the screen's integer products (libtorch's `_int_mm`, a plain loop on an AMD EPYC) at
/// the default 256 × 256 made this test take minutes, and the width does not change how calls
/// are cut.
#[test]
fn successors_do_not_depend_on_how_states_are_batched() {
    use proptest::prelude::*;
    use proptest::test_runner::{Config, TestRunner};
    let config = SkillModelConfig {
        hidden: vec![64, 64],
        ..SkillModelConfig::default()
    };
    let mut model = ForwardModel::new(25, 25, &config, Device::Cpu, 5);
    // With the screen on whatever the processor, so that its cuts are among those tested.
    model.set_int8_screen(true);
    let states = random_states(3000, 3);
    let mut whole = Vec::new();
    model.successors(&states, &mut whole);
    let mut runner = TestRunner::new(Config {
        cases: 12,
        ..Config::default()
    });
    let cuts = proptest::collection::vec(1usize..1500, 1..12);
    let model = std::cell::RefCell::new(model);
    runner
        .run(&cuts, |cuts| {
            // Pieces of the given sizes, cycling, through the memory; every other piece again.
            let mut model = model.borrow_mut();
            let mut memo = seads_planner::Memo::new(&mut *model, 64 << 20);
            let (mut out, mut again) = (Vec::new(), Vec::new());
            let mut at = 0;
            for (i, &n) in cuts.iter().cycle().enumerate() {
                if at == states.len() {
                    break;
                }
                let piece = &states[at..(at + n).min(states.len())];
                memo.successors(piece, &mut out);
                if i % 2 == 1 {
                    memo.successors(piece, &mut again);
                    let start = at * 25;
                    prop_assert_eq!(
                        &again[again.len() - piece.len() * 25..],
                        &whole[start..start + piece.len() * 25]
                    );
                }
                at += piece.len();
            }
            prop_assert_eq!(&out, &whole);
            Ok(())
        })
        .unwrap();
}
