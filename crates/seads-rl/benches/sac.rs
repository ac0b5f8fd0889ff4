//! One SAC update at the sizes of `lightsout-cursor` (policy input 28 + 25) and `tileswap-cursor`
//! (policy input 96), 2-D action, hidden 256 × 256, batch 128, on one libtorch thread: the SAC
//! phase of an epoch is 16 of these.

use criterion::{Criterion, criterion_group};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use seads_rl::{Sac, SacConfig};
use tch::Device;

use crate::common;

fn sac_update(c: &mut Criterion) {
    tch::set_num_threads(1);
    for (env, input) in [("lightsout_cursor", 53), ("tileswap_cursor", 96)] {
        bench_update(c, env, input);
    }
}

fn bench_update(c: &mut Criterion, env: &str, input: usize) {
    let config = SacConfig::default();
    let mut sac = Sac::new(input, &[-1.0, -1.0], &[1.0, 1.0], &config, Device::Cpu, 1);
    let transitions = common::random_transitions(128, input, 2);
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    c.bench_function(&format!("sac_update_{env}_hidden256_batch128"), |b| {
        b.iter(|| sac.update(&transitions, &mut rng))
    });
}

criterion_group!(benches, sac_update);
