//! Environment steps with random actions, one bench per manipulator (resets included).

use criterion::{Criterion, Throughput, criterion_group};
use seads_embodiment::{EnvConfig, make_env, random_rollout};

fn env_step(c: &mut Criterion) {
    let mut group = c.benchmark_group("env_step");
    const STEPS: usize = 10_000;
    group.throughput(Throughput::Elements(STEPS as u64));
    for name in [
        "lightsout-cursor",
        "tileswap-cursor",
        "lightsout-reacher",
        "tileswap-reacher",
    ] {
        let mut env = make_env(name, &EnvConfig::default()).expect("registered");
        group.bench_function(name, |b| {
            b.iter(|| random_rollout(env.as_mut(), STEPS, 1).expect("finite actions"))
        });
    }
    group.sample_size(10);
    const JACO_STEPS: usize = 200;
    group.throughput(Throughput::Elements(JACO_STEPS as u64));
    for (label, substeps) in [
        ("lightsout-jaco", None),
        ("lightsout-jaco-10-substeps", Some(10)),
    ] {
        let mut config = EnvConfig::default();
        if let Some(n) = substeps {
            config
                .manipulator
                .insert("physics_substeps".into(), serde_json::Value::from(n));
        }
        let mut env = make_env("lightsout-jaco", &config).expect("registered");
        group.bench_function(label, |b| {
            b.iter(|| random_rollout(env.as_mut(), JACO_STEPS, 1).expect("finite actions"))
        });
    }
    group.finish();
}

criterion_group!(benches, env_step);
