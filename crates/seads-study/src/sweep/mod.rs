//! Sweeps: a [`Manifest`] (environments × variants × seeds, a variant being overrides of the
//! environment's preset) expands into a [`Sweep`] planned on disk, `sweep.json` and one run
//! directory per run with its validated `config.toml`. Where a run stands is read from its
//! directory alone ([`status`]), so that every machine of a cluster tells the same; a Slurm job
//! array runs it ([`slurm`]).

pub mod index;
pub mod manifest;
pub mod overview;
pub mod population;
pub mod restore;
pub mod slurm;
pub mod state;
pub mod task;

pub use crate::error::Taken;
pub use index::{INDEX, MANIFEST, Planned, Sweep, SweepRun};
pub use manifest::{EvaluationPlan, Manifest, PlannedRun};
pub use overview::{Overview, RunStatus};
pub use population::populations;
pub use restore::{Restored, restore};
pub use state::{
    Claim, LOG, Missing, Outcome, PATIENCE, RECORD, Record, Status, TAKEN_EXIT, begun_first,
    check_outputs, damage, is_claimed, status,
};
pub use task::{Task, Work};
