//! Studies of SEADS runs: many runs of environments × variants × seeds, planned, run, tracked
//! and reported as the paper's tables and figures.
//!
//! - [`sweep`]: a [`Manifest`](sweep::Manifest) (TOML) expands into a planned
//!   [`Sweep`](sweep::Sweep) on disk, one run directory per run; [`sweep::status`] reads where a
//!   run stands from its directory alone; [`sweep::slurm`] writes a Slurm job array for it.
//! - [`evaluation`] (and its [`journal`](evaluation::journal)): the files an evaluation of a run writes, named by its protocol
//!   and checkpoint, its journal while it runs, and the evaluations over training (running one is
//!   `seads-evaluation`'s).
//! - [`report`]: Table 1 with the one-sided Mann–Whitney test (exact p too), task success,
//!   solution lengths, failure analysis, wall time and figures, from sweeps and runs.
//! - [`figures`]: the figures of one run: coverage, success, skill trajectories and pushes.
//! - [`provenance`]: which code on which processor trained which part of a run.
//!
//! It reads run directories through `seads-run` and links no libtorch. The `seads` command
//! (`seads sweep`, `seads report`) is the front end; this crate never prints.
//!
//! ```
//! use seads_study::sweep::{Manifest, Sweep};
//!
//! let manifest = Manifest::parse(
//!     r#"
//!     name = "two-seeds"
//!     environments = ["lightsout-cursor"]
//!     seeds = [1, 2]
//!     [[variant]]
//!     name = "seads"
//!     "#,
//!     "example",
//! )?;
//! let runs = manifest.expand()?;
//! assert_eq!(runs.len(), 2);
//! assert_eq!(runs[1].rel_dir(), "runs/lightsout-cursor/seads/seed-2");
//!
//! let dir = tempfile::tempdir()?;
//! let planned = Sweep::plan(&manifest, "…", dir.path(), None)?;
//! assert_eq!((planned.runs, planned.created), (2, 2));
//! let status = seads_study::sweep::status(&dir.path().join(runs[0].rel_dir()))?;
//! assert_eq!(status.0, seads_study::sweep::Status::Pending);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub mod animation;
pub mod draw;
mod error;
pub mod evaluation;
pub mod figures;
pub mod provenance;
pub mod recording;
pub mod report;
pub mod run_data;
pub mod sweep;

pub use error::{BoxError, Context, Result, StudyError};
pub use evaluation::journal::Resumed;

/// The number of skills K of a run: its learner's `num_skills` (SEADS's, DIAYN's: any learner's
/// section that states one), else its environment's (for a robot run, whose environment is not
/// in the registry, one per field of the tablet's LightsOut 5×5). An environment that is neither
/// is [`StudyError::Environment`].
pub fn run_skills(config: &seads_run::TrainConfig) -> Result<usize> {
    if let Some(k) = config.learner.stated_num_skills() {
        return Ok(k);
    }
    if seads_uarm::ActionSpace::of_env(&config.env).is_some() {
        return Ok(seads_uarm::BOARD_SIZE * seads_uarm::BOARD_SIZE);
    }
    let env = seads_embodiment::make_env(&config.env, &config.env_config)
        .map_err(StudyError::Environment)?;
    Ok(env.spec().num_skills)
}

/// The board game a run plays: its environment's, or the robot's LightsOut 5×5. An environment
/// that is neither is [`StudyError::Environment`].
pub fn run_game(config: &seads_run::TrainConfig) -> Result<Box<dyn seads_games::BoardGame>> {
    if seads_uarm::ActionSpace::of_env(&config.env).is_some() {
        return Ok(Box::new(seads_uarm::game()));
    }
    let env = seads_embodiment::make_env(&config.env, &config.env_config)
        .map_err(StudyError::Environment)?;
    env.spec()
        .game
        .build(env.spec().board_size)
        .doing(|| format!("building the game of {}", config.env))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// K is the learner's own where its section states one, whichever learner it is, else the
    /// environment's (25 moves on LightsOut 5×5, 12 swaps on TileSwap 3×3).
    #[test]
    fn a_runs_skills_are_its_learners_or_its_environments() {
        let preset = |env: &str, algorithm: &str, k: Option<i64>| {
            let mut table: toml::Table = seads_run::TrainConfig::preset_for(env, algorithm)
                .unwrap()
                .to_toml()
                .parse()
                .unwrap();
            if let (Some(k), Some(toml::Value::Table(section))) = (k, table.get_mut(algorithm)) {
                section.insert("num_skills".into(), toml::Value::Integer(k));
            }
            seads_run::TrainConfig::from_table(table).unwrap()
        };
        assert_eq!(
            run_skills(&preset("lightsout-cursor", "seads", Some(30))).unwrap(),
            30
        );
        assert_eq!(
            run_skills(&preset("lightsout-cursor", "diayn", Some(7))).unwrap(),
            7
        );
        assert_eq!(
            run_skills(&preset("lightsout-cursor", "diayn", None)).unwrap(),
            25
        );
        assert_eq!(
            run_skills(&preset("tileswap-cursor", "seads", None)).unwrap(),
            12
        );
    }
}
