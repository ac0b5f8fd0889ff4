//! Criterion benches of seads-skillmodel, one module per hot path.

use criterion::criterion_main;

mod planner;
mod relabel;

criterion_main!(planner::benches, relabel::benches);
