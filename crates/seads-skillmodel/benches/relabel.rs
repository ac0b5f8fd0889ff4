//! Relabelling one SEADS forward-model batch: 512 episodes, K = 25 labels (SPEC §3.6), by the
//! transportation solver, and as the reference's square problem with the port of SciPy's solver
//! (the solver this project used before), on the same scores.

use criterion::{Criterion, criterion_group};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use seads_skillmodel::relabel_assignment;

fn relabel(c: &mut Criterion) {
    let mut group = c.benchmark_group("relabel");
    for (n, k) in [(512usize, 25usize), (512, 12), (160, 25)] {
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        let floor = -2.0 * (k as f32).ln();
        let clipped: Vec<f32> = (0..n * k)
            .map(|_| (-rng.random::<f32>() * 10.0).max(floor))
            .collect();
        let labels: Vec<usize> = (0..n).map(|_| rng.random_range(0..k)).collect();
        group.bench_function(format!("transport_n{n}_k{k}"), |b| {
            b.iter(|| relabel_assignment(&clipped, k, &labels))
        });
        group.bench_function(format!("square_n{n}_k{k}"), |b| {
            b.iter(|| {
                let mut cost = vec![0.0f64; n * n];
                for (i, &label) in labels.iter().enumerate() {
                    for j in 0..n {
                        cost[i * n + j] = -f64::from(clipped[j * k + label]);
                    }
                }
                lsap::solve(n, n, &cost, false).unwrap()
            })
        });
    }
    group.finish();
}

criterion_group!(benches, relabel);
