//! Criterion benches of seads-rl, one module per hot path.

use criterion::criterion_main;

#[path = "../tests/common/mod.rs"]
mod common;
mod sac;

criterion_main!(sac::benches);
