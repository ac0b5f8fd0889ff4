//! Populations with stacked SAC agents, on the CPU: a member follows its solo run to rounding,
//! a killed population resumes exactly, a member's checkpoint resumes as a single run, and
//! members whose stacked steps would not fit are refused.

use std::path::Path;

use seads_rl::{
    ComputeDevice, EpochStats, Members, Metrics, Run, StackedPopulation, TrainConfig, Trainer,
    raise_budget, read_metrics,
};

mod common;

/// A small LightsOutCursor configuration of 2500 steps, seed `seed`, evaluated and checkpointed
/// every 4 epochs, with 32-wide networks.
fn small(seed: u64) -> TrainConfig {
    let mut config = common::small(seed, 2500);
    config.sac.hidden = vec![32, 32];
    config
        .edit(|s: &mut seads_rl::SeadsConfig| s.skill_model.hidden = vec![32, 32])
        .unwrap();
    (config.eval_every, config.checkpoint_every) = (4, 4);
    config
}

/// Three members: different seeds, and one with another learning rate and α.
fn configs() -> Vec<TrainConfig> {
    let mut configs: Vec<TrainConfig> = (1..=3).map(small).collect();
    configs[2].sac.lr = 1e-3;
    configs[2].sac.alpha = 0.05;
    configs
}

/// New runs `root/m0`, `root/m1`, … of `configs`, stacked on the CPU.
fn stacked(root: &Path, configs: &[TrainConfig]) -> Result<StackedPopulation, seads_rl::RlError> {
    let members = configs
        .iter()
        .enumerate()
        .map(|(i, c)| Run::create(&root.join(format!("m{i}")), c.clone()).unwrap())
        .collect();
    StackedPopulation::new(members, 2, ComputeDevice::Cpu)
}

fn population(root: &Path, configs: &[TrainConfig]) -> StackedPopulation {
    stacked(root, configs).unwrap()
}

/// Each epoch's statistics of every member, until all have finished.
fn train(population: &mut StackedPopulation) -> Vec<Vec<EpochStats>> {
    let mut stats = vec![Vec::new(); population.members().len()];
    while !population.finished() {
        for (i, event) in population.step().unwrap().into_iter().enumerate() {
            stats[i].extend(event.map(|e| e.stats));
        }
    }
    stats
}

/// A metrics line without its clock fields, as bits.
fn unclocked(m: &Metrics) -> Vec<u64> {
    vec![
        m.epoch,
        m.env_steps,
        m.skill_coverage.to_bits(),
        m.mean_reward.to_bits().into(),
        m.changed.to_bits().into(),
        m.skill_model_loss.to_bits().into(),
        m.critic_loss.to_bits().into(),
        m.actor_loss.to_bits().into(),
    ]
}

fn metrics(dir: &Path) -> Vec<Vec<u64>> {
    read_metrics(dir).unwrap().iter().map(unclocked).collect()
}

#[test]
fn stacked_members_follow_their_solo_runs_and_resume_exactly() {
    let tmp = tempfile::tempdir().unwrap();
    let configs = configs();
    let mut whole = population(&tmp.path().join("whole"), &configs);
    let stacked = train(&mut whole);

    // The same runs alone: equal until the first SAC steps, whose losses agree to rounding.
    for (i, config) in configs.iter().enumerate() {
        let mut solo =
            Run::<Trainer>::create(&tmp.path().join(format!("solo{i}")), config.clone()).unwrap();
        let mut alone = Vec::new();
        while !solo.finished() && alone.len() < stacked[i].len() {
            alone.push(solo.step().unwrap().stats);
        }
        let first = alone.iter().position(|s| s.updated).expect("updates start");
        for (a, b) in alone.iter().zip(&stacked[i]).take(first + 1) {
            assert_eq!(
                (a.epoch, a.env_steps, a.updated),
                (b.epoch, b.env_steps, b.updated)
            );
            assert_eq!(a.skill_model_loss.to_bits(), b.skill_model_loss.to_bits());
        }
        let (a, b) = (&alone[first].sac, &stacked[i][first].sac);
        for (x, y) in [(a.critic, b.critic), (a.actor, b.actor), (a.q, b.q)] {
            assert!(
                (x - y).abs() <= 1e-4 * (1.0 + x.abs()),
                "member {i}: {x} against {y}"
            );
        }
    }

    // Killed two epochs after its checkpoint at epoch 8 (nothing written back), then resumed.
    let root = tmp.path().join("killed");
    let mut killed = population(&root, &configs);
    for _ in 0..10 {
        killed.step().unwrap();
    }
    drop(killed);
    let members = (0..3)
        .map(|i| Run::<Trainer>::resume(&root.join(format!("m{i}"))).unwrap())
        .collect();
    let mut resumed = StackedPopulation::new(members, 1, ComputeDevice::Cpu).unwrap();
    train(&mut resumed);
    for i in 0..3 {
        let name = format!("m{i}");
        let (a, b) = (
            metrics(&tmp.path().join("whole").join(&name)),
            metrics(&root.join(&name)),
        );
        assert!(a.len() >= 3, "{a:?}");
        assert_eq!(a, b, "member {i} after the resume");
    }

    // A member's checkpoint resumes as a single run.
    let dir = tmp.path().join("whole").join("m0");
    raise_budget(&dir, 3000).unwrap();
    let mut single = Run::<Trainer>::resume(&dir).unwrap();
    assert!(!single.finished());
    while !single.finished() {
        single.step().unwrap();
    }
    assert!(read_metrics(&dir).unwrap().last().unwrap().env_steps >= 3000);
}

#[test]
fn members_whose_stacked_steps_differ_in_shape_are_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let mut configs = configs();
    configs[1].sac.batch_size = 64;
    let Err(e) = stacked(&tmp.path().join("batch"), &configs) else {
        panic!("a population of two batch sizes was stacked");
    };
    assert!(
        e.to_string()
            .contains("sac.batch_size differs (64 against 128)"),
        "{e}"
    );
    configs[1] = small(2);
    configs[1].sac.hidden = vec![16, 16];
    let Err(e) = stacked(&tmp.path().join("shape"), &configs) else {
        panic!("networks of two shapes were stacked");
    };
    assert!(e.to_string().contains("sac.hidden differs"), "{e}");
}
