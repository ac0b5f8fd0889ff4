//! Criterion benches of seads-skillmodel, one module per hot path.

use criterion::criterion_main;

mod planner;

criterion_main!(planner::benches);
