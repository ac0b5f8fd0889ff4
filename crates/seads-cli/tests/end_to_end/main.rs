//! End-to-end tests of the `seads` binary, in one test binary (each test binary links libtorch,
//! so one link instead of six): the commands and their bad input (`cli`), crash consistency
//! (`crash`), populations (`population`), sweeps (`sweep`), the Slurm path (`slurm`) and the
//! baselines (`baseline`). `common` runs the binary and checks its exit.

mod common;

mod baseline;
mod cli;
mod crash;
mod population;
mod slurm;
mod sweep;
