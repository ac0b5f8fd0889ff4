//! Criterion benches of seads-rl, one module per hot path.

use criterion::criterion_main;

mod sac;

criterion_main!(sac::benches);
