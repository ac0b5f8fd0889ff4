//! The skill models learn what they should, and relabelling is optimal.

use proptest::prelude::*;
use seads_games::{BoardGame, LightsOut, SymbolicState, TileSwap};
use seads_skillmodel::BuildSkillModel as _;
use seads_skillmodel::{
    OPTIMISER_FILES, SkillModelConfig, SkillModelError, SkillModelKind, SkillTransition,
    relabel_assignment,
};
use tch::Device;

/// Every permutation of 0..n (Heap's algorithm).
fn permutations(n: usize) -> Vec<Vec<usize>> {
    fn heap(k: usize, a: &mut Vec<usize>, out: &mut Vec<Vec<usize>>) {
        if k <= 1 {
            out.push(a.clone());
            return;
        }
        for i in 0..k {
            heap(k - 1, a, out);
            a.swap(if k.is_multiple_of(2) { i } else { 0 }, k - 1);
        }
    }
    let mut out = Vec::new();
    heap(n, &mut (0..n).collect(), &mut out);
    out
}

proptest! {
    /// The assignment is optimal (brute force over all permutations of the slots) and keeps the
    /// multiset of labels.
    #[test]
    fn assignment_is_optimal(
        n in 1usize..=6,
        k in 2usize..=5,
        seed_costs in proptest::collection::vec(-8.0f32..0.0, 36 * 5),
        seed_labels in proptest::collection::vec(0usize..5, 6),
    ) {
        let labels: Vec<usize> = seed_labels[..n].iter().map(|&l| l % k).collect();
        let clipped = &seed_costs[..n * k];
        let new = relabel_assignment(clipped, k, &labels);
        let total = |assigned: &[usize]| -> f32 { assigned.iter().enumerate().map(|(j, &l)| clipped[j * k + l]).sum() };
        let best = permutations(n)
            .into_iter()
            .map(|p| total(&p.iter().map(|&slot| labels[slot]).collect::<Vec<_>>()))
            .fold(f32::NEG_INFINITY, f32::max);
        prop_assert!((total(&new) - best).abs() < 1e-4, "{} vs {}", total(&new), best);
        let (mut a, mut b) = (labels.clone(), new.clone());
        a.sort_unstable();
        b.sort_unstable();
        prop_assert_eq!(a, b);
    }
}

/// The reference's square problem (n × n, slot i carries `labels[i]`), solved with the port of
/// SciPy's `linear_sum_assignment`: its optimal total score.
fn square_optimum(clipped: &[f32], k: usize, labels: &[usize]) -> f64 {
    let n = labels.len();
    let mut cost = vec![0.0f64; n * n];
    for (i, &label) in labels.iter().enumerate() {
        for j in 0..n {
            cost[i * n + j] = -f64::from(clipped[j * k + label]);
        }
    }
    let (rows, cols) = lsap::solve(n, n, &cost, false).unwrap();
    -rows
        .iter()
        .zip(&cols)
        .map(|(&i, &j)| cost[i * n + j])
        .sum::<f64>()
}

proptest! {
    /// On problems of the training loop's shape (many episodes, few distinct labels, scores
    /// clipped to [−2 log K, 0] with ties), relabelling reaches the optimum of the square problem
    /// the reference solves, and keeps the multiset of labels.
    #[test]
    fn assignment_matches_the_square_problem(
        n in 1usize..=80,
        k in 2usize..=30,
        raw in proptest::collection::vec(0u8..=40, 80 * 30),
        raw_labels in proptest::collection::vec(0usize..30, 80),
    ) {
        let floor = -2.0 * (k as f32).ln();
        // Coarse values make ties common; the clip makes many episodes score the floor.
        let clipped: Vec<f32> = raw[..n * k].iter().map(|&v| (-(v as f32) / 4.0).max(floor)).collect();
        let labels: Vec<usize> = raw_labels[..n].iter().map(|&l| l % k).collect();
        let new = relabel_assignment(&clipped, k, &labels);
        let total: f64 = new.iter().enumerate().map(|(j, &l)| f64::from(clipped[j * k + l])).sum();
        let best = square_optimum(&clipped, k, &labels);
        prop_assert!((total - best).abs() <= 1e-6 * (1.0 + best.abs()), "{total} vs {best}");
        let (mut a, mut b) = (labels.clone(), new.clone());
        a.sort_unstable();
        b.sort_unstable();
        prop_assert_eq!(a, b);
    }
}

/// The label-tie study's relabelling problems, dumped from real LightsOutCursor training with
/// K = 25 and K = 30 (`docs/results/label-ties/`, made by the `relabel_dump` example of
/// seads-rl). On each, relabelling reaches the optimum of the reference's square problem
/// (SciPy's algorithm, ported), and the episodes it gives a label at the clip floor get the
/// same multiset of labels as SciPy's solution gives them: ties do not push them towards other
/// label indices than the reference's.
#[test]
fn tied_episodes_get_the_labels_scipy_gives_them_on_real_training_problems() {
    use std::io::BufRead;
    #[derive(serde::Deserialize)]
    struct Problem {
        k: usize,
        labels: Vec<usize>,
        relabelled: Vec<usize>,
        clipped: Vec<f32>,
    }
    let dir =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../docs/results/label-ties");
    let mut problems = 0;
    for name in ["k25.jsonl.gz", "k30.jsonl.gz"] {
        let file = std::fs::File::open(dir.join(name)).unwrap();
        for line in std::io::BufReader::new(flate2::read::GzDecoder::new(file)).lines() {
            let p: Problem = serde_json::from_str(&line.unwrap()).unwrap();
            let (k, n) = (p.k, p.labels.len());
            let ours = relabel_assignment(&p.clipped, k, &p.labels);
            assert_eq!(
                ours, p.relabelled,
                "the solver no longer gives the dumped labels"
            );
            // The square problem as the reference states it: slot i carries labels[i].
            let mut cost = vec![0.0f64; n * n];
            for (i, &label) in p.labels.iter().enumerate() {
                for j in 0..n {
                    cost[i * n + j] = -f64::from(p.clipped[j * k + label]);
                }
            }
            let (rows, cols) = lsap::solve(n, n, &cost, false).unwrap();
            let mut scipy = vec![0; n];
            for (&i, &j) in rows.iter().zip(&cols) {
                scipy[j] = p.labels[i];
            }
            let total = |labels: &[usize]| -> f64 {
                labels
                    .iter()
                    .enumerate()
                    .map(|(j, &l)| f64::from(p.clipped[j * k + l]))
                    .sum()
            };
            assert!((total(&ours) - total(&scipy)).abs() < 1e-6, "not optimal");
            let floor = p.clipped.iter().copied().fold(f32::INFINITY, f32::min);
            let tied = |labels: &[usize]| -> Vec<usize> {
                let mut t: Vec<usize> = labels
                    .iter()
                    .enumerate()
                    .filter(|&(j, &l)| p.clipped[j * k + l] == floor)
                    .map(|(_, &l)| l)
                    .collect();
                t.sort_unstable();
                t
            };
            assert!(
                !tied(&ours).is_empty(),
                "a problem without ties tests nothing"
            );
            assert_eq!(tied(&ours), tied(&scipy));
            problems += 1;
        }
    }
    assert_eq!(problems, 40);
}

/// Synthetic data of the ground-truth game: skill k performs move k (LightsOut 5×5 flip masks).
fn lightsout_data(n: usize, seed: u64) -> Vec<SkillTransition> {
    let game = LightsOut::new(5).unwrap();
    let mut state = seed;
    let mut next = || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        state >> 33
    };
    (0..n)
        .map(|_| {
            let z0 = SymbolicState::from_u64(next() & ((1 << 25) - 1));
            let skill = (next() % 25) as usize;
            SkillTransition {
                z0,
                skill,
                zt: game.apply(z0, skill),
            }
        })
        .collect()
}

#[test]
fn forward_model_learns_the_lightsout_flip_table() {
    let config = SkillModelConfig::default();
    let mut model = config.build(25, 25, Device::Cpu, 1);
    let data = lightsout_data(4000, 7);
    for epoch in 0..1500 {
        let start = (epoch * 32) % (data.len() - 32);
        model.train_step(&data[start..start + 32]);
    }
    // The true skill is the most likely explanation of held-out transitions.
    let test = lightsout_data(200, 99);
    let pairs: Vec<(SymbolicState, SymbolicState)> = test.iter().map(|t| (t.z0, t.zt)).collect();
    let scores = model.scores(&pairs);
    let correct = test
        .iter()
        .enumerate()
        .filter(|(i, t)| {
            let row = &scores[i * 25..(i + 1) * 25];
            let best = (0..25).fold(0, |b, k| if row[k] > row[b] { k } else { b });
            best == t.skill
        })
        .count();
    assert!(
        correct >= 195,
        "{correct}/200 held-out transitions attributed to the right skill"
    );
    // And it predicts the successor with high likelihood: log q(z_T | z_0, k*) close to 0.
    let mean_true: f32 = test
        .iter()
        .enumerate()
        .map(|(i, t)| scores[i * 25 + t.skill])
        .sum::<f32>()
        / 200.0;
    assert!(
        mean_true > -1.0,
        "mean log-likelihood of the true skill {mean_true}"
    );
}

#[test]
fn discriminator_learns_which_swap_happened() {
    let config = SkillModelConfig {
        kind: SkillModelKind::Vic,
        ..SkillModelConfig::default()
    };
    let game = TileSwap::new();
    let mut model = config.build(81, 12, Device::Cpu, 2);
    let data: Vec<SkillTransition> = (0..600)
        .map(|i| {
            let z0 = game.apply_all(
                game.goal(),
                &[(i * 7) % 12, (i * 5 + 3) % 12, (i * 11 + 1) % 12],
            );
            let skill = i % 12;
            SkillTransition {
                z0,
                skill,
                zt: game.apply(z0, skill),
            }
        })
        .collect();
    for step in 0..600 {
        let start = (step * 32) % (data.len() - 32);
        model.train_step(&data[start..start + 32]);
    }
    let pairs: Vec<_> = data.iter().take(120).map(|t| (t.z0, t.zt)).collect();
    let scores = model.scores(&pairs);
    let correct = data.iter().take(120).enumerate().filter(|(i, t)| {
        let row = &scores[i * 12..(i + 1) * 12];
        (0..12).fold(0, |b, k| if row[k] > row[b] { k } else { b }) == t.skill
    });
    assert!(correct.count() >= 115);
}

#[test]
fn checkpoints_round_trip_and_bad_files_are_errors() {
    let dir = tempfile::tempdir().unwrap();
    let config = SkillModelConfig::default();
    let mut model = config.build(25, 25, Device::Cpu, 3);
    model.train_step(&lightsout_data(32, 1));
    model.save(dir.path()).unwrap();
    let mut other = config.build(25, 25, Device::Cpu, 4);
    let pairs = [(SymbolicState::from_u64(5), SymbolicState::from_u64(7))];
    assert_ne!(model.scores(&pairs), other.scores(&pairs));
    other.load(dir.path(), true).unwrap();
    assert_eq!(model.scores(&pairs), other.scores(&pairs));
    // The optimiser state came along: one more identical step gives identical models.
    let batch = lightsout_data(32, 2);
    model.train_step(&batch);
    other.train_step(&batch);
    assert_eq!(model.scores(&pairs), other.scores(&pairs));
    std::fs::write(
        dir.path().join("forward_model.safetensors"),
        b"not a checkpoint",
    )
    .unwrap();
    assert!(matches!(
        other.load(dir.path(), true),
        Err(SkillModelError::Checkpoint { path, .. }) if path.ends_with("forward_model.safetensors")
    ));
    let mut wrong_shape = config.build(81, 12, Device::Cpu, 5);
    model.save(dir.path()).unwrap();
    assert!(matches!(
        wrong_shape.load(dir.path(), true),
        Err(SkillModelError::Checkpoint { .. })
    ));
    // The optimiser files are the ones the trainer lists as resume-only.
    assert!(dir.path().join(OPTIMISER_FILES[0]).exists());
    let vic = SkillModelConfig {
        kind: SkillModelKind::Vic,
        ..SkillModelConfig::default()
    }
    .build(25, 25, Device::Cpu, 3);
    let vic_dir = tempfile::tempdir().unwrap();
    vic.save(vic_dir.path()).unwrap();
    assert!(vic_dir.path().join(OPTIMISER_FILES[1]).exists());
    // Resuming needs the optimiser state (a fresh one would change the run); evaluating does not.
    std::fs::remove_file(dir.path().join("forward_model_adam.safetensors")).unwrap();
    other.load(dir.path(), false).unwrap();
    let err = other.load(dir.path(), true).unwrap_err();
    assert!(err.to_string().contains("forward_model_adam"), "{err}");
}

/// A model fitted to the LightsOut move table predicts every successor exactly, so BFS on it
/// finds the same shortest plans as on the real rules.
#[test]
fn fitted_model_reproduces_the_move_table() {
    let game = LightsOut::new(5).unwrap();
    let config = SkillModelConfig {
        batch_size: 256,
        ..SkillModelConfig::default()
    };
    let mut model = seads_skillmodel::fit_to_game(&game, &config, 600, 1);
    let agreement = seads_skillmodel::agreement_with_game(&mut model, &game, 400, 2);
    assert!(agreement > 0.999, "{agreement}");
}

/// Where one skill from one board has two outcomes that each change two bits together (half the
/// time bits 0 and 1, half the time bits 2 and 3: a stochastic skill's two slides), the mixture
/// model learns both outcomes whole: each gets about half the probability and its most likely
/// successor is one of them. The paper's per-bit model learns each of the four bits at one half,
/// and no outcome keeps most of the probability mass.
#[test]
fn the_mixture_model_keeps_two_outcomes_of_one_skill_whole() {
    use seads_games::Successor as _;
    let z0 = SymbolicState::from_u64(0b1_0000);
    let (a, b) = (
        SymbolicState::from_u64(0b1_0011),
        SymbolicState::from_u64(0b1_1100),
    );
    let batch: Vec<SkillTransition> = (0..32)
        .map(|i| SkillTransition {
            z0,
            skill: 0,
            zt: if i % 2 == 0 { a } else { b },
        })
        .collect();
    let mixture = SkillModelConfig {
        kind: SkillModelKind::Mixture,
        hidden: vec![16, 16],
        lr: 1e-2,
        ..SkillModelConfig::default()
    };
    let paper = SkillModelConfig {
        kind: SkillModelKind::Forward,
        ..mixture.clone()
    };
    let (d, k) = (6, 2);
    let mut ours = seads_skillmodel::MixtureModel::new(d, k, &mixture, Device::Cpu, 5);
    let mut theirs = paper.build(d, k, Device::Cpu, 5);
    for _ in 0..300 {
        seads_skillmodel::SkillModel::train_step(&mut ours, &batch);
        theirs.train_step(&batch);
    }
    let probability = |scores: Vec<f32>| scores.iter().map(|s| f64::from(*s).exp()).sum::<f64>();
    let ours_ab = probability(
        ours.log_likelihoods(&[(z0, 0, a), (z0, 0, b)])
            .expect("skill 0 exists"),
    );
    let theirs_ab = probability(vec![
        theirs.scores(&[(z0, a)])[0],
        theirs.scores(&[(z0, b)])[0],
    ]);
    assert!(
        ours_ab > 0.95,
        "the mixture gives the two outcomes {ours_ab}"
    );
    assert!(theirs_ab < 0.2, "the per-bit model gives them {theirs_ab}");
    let mut next = Vec::new();
    ours.successors(&[z0], &mut next);
    assert!(
        next[0] == a || next[0] == b,
        "successor {:#b}",
        next[0].low_u64()
    );
}
