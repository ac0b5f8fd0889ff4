//! Criterion benches of seads-games, one module per hot path.

use criterion::criterion_main;

mod bfs;

criterion_main!(bfs::benches);
