//! SAC learns a toy task; SEADS trains, is deterministic, checkpoints and resumes; bad
//! configurations are rejected.

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use seads_rl::store::{checkpoints, latest_checkpoint};
use seads_rl::{
    RlError, Run, Sac, SacConfig, SeadsConfig, TrainConfig, Trainer, TransitionBatch, read_metrics,
};
use tch::Device;

mod common;

/// A one-step task: observe s ∈ [−1, 1], act a ∈ [−1, 1], reward −(a − s)², then the episode
/// ends. SAC must learn a ≈ s.
#[test]
fn sac_learns_to_track_a_target() {
    let config = SacConfig {
        hidden: vec![64, 64],
        alpha: 0.01,
        lr: 1e-3,
        ..SacConfig::default()
    };
    let mut sac = Sac::new(1, &[-1.0], &[1.0], &config, Device::Cpu, 3);
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    for _ in 0..1500 {
        let obs: Vec<f32> = (0..64).map(|_| rng.random_range(-1.0..1.0)).collect();
        let actions = sac.act(&obs, Some(&mut rng));
        let rewards = obs
            .iter()
            .zip(&actions)
            .map(|(s, a)| -(a - s) * (a - s))
            .collect();
        let batch = TransitionBatch {
            next_obs: obs.clone(),
            obs,
            actions,
            rewards,
            dones: vec![1.0; 64],
        };
        sac.update(&batch, &mut rng);
    }
    let test = [-0.8f32, -0.3, 0.0, 0.4, 0.9];
    let actions = sac.act(&test, None);
    for (s, a) in test.iter().zip(&actions) {
        assert!((s - a).abs() < 0.1, "state {s}: action {a}");
    }
}

/// SAC updates give the same bits with one libtorch thread as with two or eight, at the presets' network
/// and batch sizes (the trainer widens SAC to two threads part-way through an epoch, at a moment
/// that depends on timing, so this keeps runs reproducible).
#[test]
fn sac_updates_do_not_depend_on_the_thread_count() {
    let input = 96;
    let transitions = common::random_transitions(128, input, 2);
    let run = |threads: i32| {
        let transitions = &transitions;
        // libtorch's thread count is per thread: each run has a thread of its own.
        std::thread::scope(|scope| {
            scope
                .spawn(move || {
                    tch::set_num_threads(threads);
                    let mut sac = Sac::new(
                        input,
                        &[-1.0, -1.0],
                        &[1.0, 1.0],
                        &SacConfig::default(),
                        Device::Cpu,
                        1,
                    );
                    let mut rng = ChaCha8Rng::seed_from_u64(3);
                    let losses: Vec<[u32; 3]> = (0..20)
                        .map(|_| {
                            let l = sac.update(transitions, &mut rng);
                            [l.critic.to_bits(), l.actor.to_bits(), l.q.to_bits()]
                        })
                        .collect();
                    (losses, sac.act(&transitions.obs, None))
                })
                .join()
                .expect("SAC thread")
        })
    };
    // Two: the trainer's switch; eight: a task given 8 cores or more (`TrainConfig::use_cores`).
    let one = run(1);
    for threads in [2, 8] {
        let other = run(threads);
        assert_eq!(one.0, other.0, "losses with {threads} threads");
        assert_eq!(
            one.1, other.1,
            "deterministic actions after the updates, {threads} threads"
        );
    }
}

/// A few epochs of LightsOutCursor (small networks, CI-sized): updates start once the buffer
/// holds enough episodes, the forward model starts to explain the moves, and the deterministic
/// skills, which push nowhere at initialisation, start making game moves. (Learning all 25 skills
/// takes ~10⁴–10⁵ steps: see `seads train` and the README's results.)
#[test]
fn lightsout_cursor_smoke() {
    let mut trainer = Trainer::new(common::small(7, 4000)).unwrap();
    let first = trainer.skill_coverage().unwrap();
    let mut updated = false;
    let mut losses = Vec::new();
    let mut steps_before_last_epoch = 0;
    while !trainer.finished() {
        steps_before_last_epoch = trainer.env_steps();
        let stats = trainer.run_epoch().unwrap();
        updated |= stats.updated;
        if stats.updated {
            losses.push(stats.skill_model_loss);
        }
    }
    assert!(updated);
    let early: f32 = losses[..5].iter().sum::<f32>() / 5.0;
    let late: f32 = losses[losses.len() - 5..].iter().sum::<f32>() / 5.0;
    assert!(late < early, "forward-model loss falls: {early} -> {late}");
    let coverage = trainer.skill_coverage().unwrap();
    assert_eq!(first, 0.0, "untrained skills do not push");
    assert!(
        coverage > 0.0,
        "skills start making moves: coverage {first} -> {coverage}"
    );
    // The budget stops training at the first epoch that reaches it, not one epoch later.
    assert!(
        steps_before_last_epoch < 4000 && trainer.env_steps() >= 4000,
        "{steps_before_last_epoch} steps before the last epoch, {} after",
        trainer.env_steps()
    );
}

/// The same seed gives the same run (metrics bit for bit), whether or not SAC takes a second
/// libtorch thread part-way through its epochs; another seed gives another run. SAC is 128 wide:
/// with the portable kernels a 64-wide one's bits depend on the thread count
/// (`examples/thread_count_bits.rs`), so whether it widened, which timing decides, would show.
#[test]
fn same_seed_same_run() {
    let run = |seed, sac_threads_alone| {
        let mut config = TrainConfig {
            sac_threads_alone,
            ..common::small(seed, 1200)
        };
        config.sac.hidden = vec![128, 128];
        let mut trainer = Trainer::new(config).unwrap();
        let mut trace = Vec::new();
        while !trainer.finished() {
            let s = trainer.run_epoch().unwrap();
            trace.push((
                s.env_steps,
                s.mean_reward.to_bits(),
                s.skill_model_loss.to_bits(),
                s.sac.critic.to_bits(),
            ));
        }
        trace.push((trainer.skill_coverage().unwrap().to_bits(), 0, 0, 0));
        trace
    };
    let first = run(3, 0);
    assert!(first.iter().any(|t| t.3 != 0), "SAC updated");
    assert_eq!(first, run(3, 0));
    assert_eq!(first, run(3, 2));
    assert_ne!(first, run(4, 0));
}

/// No silent defaults on resume: a `config.toml` edited after a checkpoint (a seed, a learning
/// rate) is refused, naming the field; raising the budget is allowed; an emptied one names no
/// environment and is refused rather than trained as a preset.
#[test]
fn resume_refuses_a_config_edited_since_its_checkpoint() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("run");
    let mut run = Run::<Trainer>::create(&path, common::small(12, 2500)).unwrap();
    while run.trainer().epoch() < 10 {
        run.step().unwrap();
    }
    drop(run);
    let original = std::fs::read_to_string(path.join("config.toml")).unwrap();
    for (from, to, field) in [
        ("seed = 12", "seed = 13", "`seed` is 13, was 12"),
        (
            "lr = 0.0003",
            "lr = 0.0005",
            "`sac.lr` is 0.0005, was 0.0003",
        ),
    ] {
        assert!(original.contains(from), "{original}");
        std::fs::write(path.join("config.toml"), original.replacen(from, to, 1)).unwrap();
        let err = Run::<Trainer>::resume(&path).err().expect("refused");
        assert!(err.to_string().contains(field), "{err}");
    }
    std::fs::write(path.join("config.toml"), "").unwrap();
    let err = Run::<Trainer>::resume(&path).err().expect("refused");
    assert!(err.to_string().contains("names no `env`"), "{err}");
    std::fs::write(path.join("config.toml"), &original).unwrap();
    seads_rl::raise_budget(&path, 3000).unwrap();
    let resumed = Run::<Trainer>::resume(&path).unwrap();
    assert_eq!(resumed.trainer().epoch(), 10);
}

/// A killed run resumes from its last checkpoint: the state is restored exactly, evaluations
/// logged after the checkpoint are dropped, and training continues to the budget.
#[test]
fn resume_continues_from_the_last_checkpoint() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("run");
    let mut run = Run::<Trainer>::create(&path, common::small(11, 2500)).unwrap();
    let mut at_checkpoint = None;
    for _ in 0..25 {
        let event = run.step().unwrap();
        if event.checkpoint.is_some() {
            at_checkpoint = Some((run.trainer().epoch(), run.trainer().env_steps()));
        }
    }
    // "Kill" after epoch 25: the latest checkpoint is epoch 20; the epoch-1/10/20 evaluations stay.
    let (epoch, steps) = at_checkpoint.unwrap();
    assert_eq!(epoch, 20);
    assert_eq!(
        latest_checkpoint(&path).unwrap().unwrap(),
        path.join("checkpoints/epoch-000020")
    );
    drop(run);
    // Creating again in the same directory is refused.
    assert!(matches!(
        Run::<Trainer>::create(&path, common::small(11, 2500)),
        Err(RlError::Run(seads_rl::RunError::Config(m))) if m.contains("already holds a run")
    ));
    let mut resumed = Run::<Trainer>::resume(&path).unwrap();
    assert_eq!(
        (resumed.trainer().epoch(), resumed.trainer().env_steps()),
        (epoch, steps)
    );
    assert!(read_metrics(&path).unwrap().iter().all(|m| m.epoch <= 20));
    while !resumed.finished() {
        resumed.step().unwrap();
    }
    let metrics = read_metrics(&path).unwrap();
    assert!(metrics.last().unwrap().env_steps >= 2500);
    let epochs: Vec<u64> = metrics.iter().map(|m| m.epoch).collect();
    assert!(
        epochs.windows(2).all(|w| w[0] < w[1]),
        "metrics epochs increase: {epochs:?}"
    );
    // Older checkpoints keep only what evaluation needs.
    let all = checkpoints(&path).unwrap();
    assert!(all.len() >= 3);
    assert!(!all[0].1.join("episodes.safetensors").exists());
    assert!(all[0].1.join("sac_actor.safetensors").exists());
    assert!(all.last().unwrap().1.join("episodes.safetensors").exists());
}

/// A checkpoint holds the updates already prepared for the next epoch (the skill model steps
/// ahead of SAC): a trainer restored from it takes the same SAC steps on the same relabelled
/// batch as the one that saved it.
#[test]
fn a_checkpoint_keeps_the_prepared_updates() {
    let dir = tempfile::tempdir().unwrap();
    let mut trainer = Trainer::new(common::small(5, 100_000)).unwrap();
    for _ in 0..4 {
        trainer.run_epoch().unwrap();
    }
    trainer.save(dir.path()).unwrap();
    assert!(dir.path().join("prepared.safetensors").exists());
    let mut restored = Trainer::new(common::small(5, 100_000)).unwrap();
    restored.load(dir.path()).unwrap();
    let (a, b) = (trainer.run_epoch().unwrap(), restored.run_epoch().unwrap());
    assert!(a.updated && b.updated);
    assert_eq!(a.mean_reward.to_bits(), b.mean_reward.to_bits());
    assert_eq!(a.skill_model_loss.to_bits(), b.skill_model_loss.to_bits());
    assert_eq!(a.sac.critic.to_bits(), b.sac.critic.to_bits());
    assert_eq!(a.sac.actor.to_bits(), b.sac.actor.to_bits());

    std::fs::write(dir.path().join("prepared.safetensors"), b"garbage").unwrap();
    let err = restored
        .load(dir.path())
        .expect_err("corrupt prepared updates");
    assert!(err.to_string().contains("prepared.safetensors"), "{err}");
}

/// An error and its sources, as the CLI prints them.
fn chain(err: impl std::error::Error + Send + Sync + 'static) -> String {
    format!("{:#}", anyhow::Error::from(err))
}

/// A corrupt latest checkpoint is passed over for the one before it (resuming says so); when no
/// checkpoint can be loaded, resuming is an error that names the file, never a panic.
#[test]
fn corrupt_checkpoints_are_errors_not_panics() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("run");
    let mut run = Run::<Trainer>::create(&path, common::small(2, 4000)).unwrap();
    while !run.finished() {
        run.step().unwrap();
    }
    drop(run);
    let all = checkpoints(&path).unwrap();
    let (latest, before) = (&all[all.len() - 1].1, &all[all.len() - 2].1);
    let episodes = latest.join("episodes.safetensors");
    let intact = std::fs::read(&episodes).unwrap();
    std::fs::write(&episodes, b"garbage").unwrap();
    let resumed = Run::<Trainer>::resume(&path).unwrap();
    assert!(
        resumed.repairs()[0].contains("episodes.safetensors"),
        "{:?}",
        resumed.repairs()
    );
    assert_eq!(
        resumed.trainer().epoch(),
        all[all.len() - 2].0,
        "resumed from the checkpoint before"
    );
    drop(resumed);
    std::fs::write(before.join("episodes.safetensors"), b"garbage").unwrap();
    let err = Run::<Trainer>::resume(&path)
        .err()
        .expect("no loadable checkpoint is an error");
    let text = chain(err);
    assert!(text.contains("episodes.safetensors"), "{text}");
    // Well-formed tensors whose episode table gives the second episode a negative length.
    std::fs::write(&episodes, &intact).unwrap();
    let mut tensors = tch::Tensor::read_safetensors(&episodes).unwrap();
    let lengths = &mut tensors.iter_mut().find(|(n, _)| n == "lengths").unwrap().1;
    let _ = lengths.get(1).fill_(-1);
    tch::Tensor::write_safetensors(&tensors, &episodes).unwrap();
    let err = Run::<Trainer>::resume(&path)
        .err()
        .expect("a negative episode length is an error");
    let text = chain(err);
    assert!(text.contains("episode table"), "{text}");
    // A missing optimiser state is an error on resume (a fresh optimiser would change the run).
    std::fs::write(&episodes, &intact).unwrap();
    std::fs::remove_file(latest.join("sac_critic_adam.safetensors")).unwrap();
    std::fs::remove_dir_all(before).unwrap();
    let err = Run::<Trainer>::resume(&path)
        .err()
        .expect("a missing optimiser state");
    let text = chain(err);
    assert!(text.contains("sac_critic_adam"), "{text}");
    std::fs::remove_dir_all(latest).unwrap();
    assert!(
        matches!(
            Run::<Trainer>::resume(&path),
            Err(RlError::NoCheckpoint { .. })
        ),
        "checkpoints were written, none that resuming can load is left"
    );
    // Without its checkpoints folder (a run copied without checkpoints), resuming refuses
    // instead of training again over the metrics, which stay as they were.
    let metrics = std::fs::read(path.join("metrics.jsonl")).unwrap();
    std::fs::remove_dir_all(path.join("checkpoints")).unwrap();
    let err = Run::<Trainer>::resume(&path)
        .err()
        .expect("a run with metrics and no checkpoints folder");
    assert!(
        matches!(err, RlError::CheckpointsMissing { lines, .. } if lines > 0),
        "{err}"
    );
    assert_eq!(std::fs::read(path.join("metrics.jsonl")).unwrap(), metrics);
    assert!(!path.join("checkpoints").exists());
}

/// The same run killed after a checkpoint and resumed equals the run that was never killed, in
/// every evaluation (the case: seed 5, an evaluation and a checkpoint every 20 epochs,
/// scaled down). Before environments were seeded per epoch, the resumed run collected other
/// episodes.
#[test]
fn a_resumed_run_equals_the_uninterrupted_run() {
    let dir = tempfile::tempdir().unwrap();
    let config = TrainConfig {
        eval_every: 5,
        checkpoint_every: 5,
        ..common::small(5, 2500)
    };
    let strip = |path: &std::path::Path| -> Vec<(u64, u64, u64, u32, u32, u32)> {
        read_metrics(path)
            .unwrap()
            .iter()
            .map(|m| {
                (
                    m.epoch,
                    m.env_steps,
                    m.skill_coverage.to_bits(),
                    m.mean_reward.to_bits(),
                    m.skill_model_loss.to_bits(),
                    m.critic_loss.to_bits(),
                )
            })
            .collect()
    };
    let whole = dir.path().join("whole");
    let mut run = Run::<Trainer>::create(&whole, config.clone()).unwrap();
    while !run.finished() {
        run.step().unwrap();
    }
    let killed = dir.path().join("killed");
    let mut run = Run::<Trainer>::create(&killed, config).unwrap();
    for _ in 0..13 {
        run.step().unwrap();
    }
    drop(run); // killed at epoch 13, after its epoch-10 checkpoint
    let mut run = Run::<Trainer>::resume(&killed).unwrap();
    assert_eq!(run.trainer().epoch(), 10);
    while !run.finished() {
        run.step().unwrap();
    }
    assert!(strip(&whole).len() > 5);
    assert_eq!(strip(&killed), strip(&whole));
}

#[test]
fn bad_configurations_are_rejected_with_a_reason() {
    type Edit = fn(&mut TrainConfig);
    let cases: [(&str, Edit); 8] = [
        ("unknown environment", |c| c.env = "lightsout-robot".into()),
        ("sac.hidden", |c| c.sac.hidden = vec![64, -1]),
        ("sac.alpha", |c| c.sac.alpha = 0.0),
        ("sac.gamma", |c| c.sac.gamma = 1.5),
        ("skill_model.lr", |c| {
            c.edit(|s: &mut SeadsConfig| s.skill_model.lr = -1.0)
                .unwrap()
        }),
        ("relabel.sac_p", |c| {
            c.edit(|s: &mut SeadsConfig| s.relabel.sac_p = 2.0).unwrap()
        }),
        ("episodes_per_epoch", |c| {
            c.edit(|s: &mut SeadsConfig| s.episodes_per_epoch = 0)
                .unwrap()
        }),
        ("buffer_capacity", |c| {
            c.edit(|s: &mut SeadsConfig| s.sampled_episodes = s.buffer_capacity + 1)
                .unwrap()
        }),
    ];
    for (needle, edit) in cases {
        let mut config = TrainConfig::default();
        edit(&mut config);
        let err = config
            .validate()
            .err()
            .unwrap_or_else(|| panic!("{needle} accepted"));
        assert!(err.to_string().contains(needle), "{needle}: {err}");
    }
    assert!(
        matches!(
            TrainConfig::from_toml("env = \"lightsout-cursor\"\nalpha = 0.1"),
            Err(seads_rl::RunError::Config(m)) if m.contains("unknown field")
        ),
        "unknown fields are errors"
    );
}

#[test]
fn presets_parse_and_round_trip() {
    for (env, config) in TrainConfig::presets_of("seads") {
        let config = config.unwrap();
        assert_eq!(config.env, env);
        assert_eq!(TrainConfig::from_toml(&config.to_toml()).unwrap(), config);
        // The robot's presets are the Cursor's (seed S.5).
        let expected_alpha = if env.contains("cursor") || env.starts_with("uarm-") {
            0.1
        } else {
            0.01
        };
        assert_eq!(config.sac.alpha, expected_alpha, "{env}");
    }
    // `TrainConfig::default` is documented as the LightsOutCursor preset (issue 13: its thread
    // settings differed).
    assert_eq!(
        TrainConfig::default(),
        TrainConfig::preset("lightsout-cursor").unwrap()
    );
}

/// Every run configuration committed with a study (and the test data's) is in today's layout
/// (`seads migrate` rewrote the older ones): it loads alone and as its run directory is read,
/// states its algorithm, holds that algorithm's section only, and reads back as it was.
#[test]
fn every_committed_run_config_loads() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let files: Vec<std::path::PathBuf> = ["docs/results", "data", "crates/seads-py/tests/data"]
        .iter()
        .flat_map(|dir| walkdir::WalkDir::new(root.join(dir)))
        .map(|entry| entry.unwrap().into_path())
        .filter(|path| path.file_name().is_some_and(|n| n == "config.toml"))
        .collect();
    assert!(
        files.len() > 200,
        "found only {} config.toml files",
        files.len()
    );
    for path in &files {
        let text = std::fs::read_to_string(path).unwrap();
        let config =
            TrainConfig::from_toml(&text).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let stated: toml::Table = text.parse().unwrap();
        assert_eq!(
            stated.get("algorithm").and_then(|a| a.as_str()),
            Some(config.algorithm()),
            "{}",
            path.display()
        );
        let sections: Vec<&String> = stated
            .iter()
            .filter(|(key, value)| {
                value.is_table() && !["env_config", "sac"].contains(&key.as_str())
            })
            .map(|(key, _)| key)
            .collect();
        assert_eq!(
            sections,
            [seads_rl::section_name(config.algorithm()).unwrap()],
            "{}",
            path.display()
        );
        seads_rl::learners::check(&config).unwrap();
        assert_eq!(TrainConfig::from_toml(&config.to_toml()).unwrap(), config);
        // As a run directory is read (the file laid over its preset): every command that opens
        // the run, `seads report` among them.
        let dir = path.parent().unwrap();
        let loaded = seads_rl::load_config(dir).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(loaded, config, "{}", path.display());
    }
}
