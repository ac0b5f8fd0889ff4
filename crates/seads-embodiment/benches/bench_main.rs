//! Criterion benches of seads-embodiment, one module per hot path.

use criterion::criterion_main;

mod env_step;

criterion_main!(env_step::benches);
