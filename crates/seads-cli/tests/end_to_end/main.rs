//! End-to-end tests of the `seads` binary, in one test binary (each test binary links libtorch,
//! so one link instead of many): one file per command group (`games`, `envs`, `train`, `plan`,
//! `uarm`, `report`) and bad input across them (`input`), crash consistency
//! (`crash`), `seads migrate` (`migrate`), populations (`population`), sweeps (`sweep`), the Slurm path (`slurm`, built only
//! with `SEADS_TEST_SLURM=1`: it needs Slurm) and the baselines (`baseline`). `common` runs the
//! binary and checks its exit and waits on events.

mod common;

mod baseline;
mod crash;
mod envs;
mod games;
mod input;
mod migrate;
mod plan;
mod population;
mod report;
#[cfg(seads_test_slurm)]
mod slurm;
mod sweep;
mod train;
mod uarm;
