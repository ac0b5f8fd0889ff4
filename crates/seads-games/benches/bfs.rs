//! Full breadth-first enumeration of LightsOut 5×5 (2^23 boards) and TileSwap 3×3 (9! boards).

use criterion::{Criterion, criterion_group};
use seads_games::{LightsOut, TileSwap, enumerate};
use std::hint::black_box;

fn bfs(c: &mut Criterion) {
    let mut group = c.benchmark_group("bfs");
    group.sample_size(10);
    let lightsout = LightsOut::new(5).expect("5×5");
    group.bench_function("lightsout_5x5_all_depths", |b| {
        b.iter(|| black_box(enumerate(&lightsout, None).expect("enumerable")).total())
    });
    let tileswap = TileSwap::new();
    group.bench_function("tileswap_3x3_all_depths", |b| {
        b.iter(|| black_box(enumerate(&tileswap, None).expect("enumerable")).total())
    });
    group.finish();
}

criterion_group!(benches, bfs);
