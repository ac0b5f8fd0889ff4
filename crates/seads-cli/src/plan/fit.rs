//! `seads fit-model`: fits SEADS's forward model to any trained learner's frozen skills, so that
//! they can be planned with (`seads evaluate --fitted-model`).

use std::path::PathBuf;

use anyhow::{Result, bail};
use clap::Args;
use seads_rl::{ComputeDevice, FitProgress};
use seads_run::fitted::{FitRecord, FitSettings, read_fit_record};

use super::load_agent;
use crate::BadInput;

/// Arguments of `seads fit-model`.
#[derive(Debug, Args)]
pub struct FitModelArgs {
    /// Run directory of a trained skill learner (SEADS, VIC, DIAYN, …).
    #[arg(long)]
    run: PathBuf,
    /// Fit to the skills of the checkpoint of this epoch instead of the latest.
    #[arg(long)]
    checkpoint: Option<u64>,
    /// Skill executions to learn from, each from a fresh training board with a skill drawn
    /// uniformly, executed deterministically; one in ten is held out to measure the fit.
    #[arg(long, default_value_t = FitSettings::standard(0).episodes as u64,
          value_parser = clap::value_parser!(u64).range(FitSettings::HELD_OUT_EVERY as u64..=100_000_000))]
    episodes: u64,
    /// Gradient steps, each on a batch of the environment's SEADS preset (`[seads.skill_model]`).
    #[arg(long, default_value_t = FitSettings::standard(0).updates as u64,
          value_parser = clap::value_parser!(u64).range(1..=100_000_000))]
    updates: u64,
    /// Seed of the boards, skills, initial weights and batches (default: the run's seed).
    #[arg(long)]
    seed: Option<u64>,
    /// Replace the run's fitted model (refused while evaluations planned with it are there).
    #[arg(long)]
    refit: bool,
    /// Where the networks run: cpu, cuda or cuda:N.
    #[arg(long, default_value = "cpu")]
    device: ComputeDevice,
    /// No progress bar.
    #[arg(long)]
    quiet: bool,
    /// Print the fit's record as JSON (implies --quiet).
    #[arg(long)]
    json: bool,
}

/// `seads fit-model`.
pub fn fit_model(args: FitModelArgs) -> Result<()> {
    let _lock = crate::lock_run(&args.run)?;
    if let Some(record) = read_fit_record(&args.run).map_err(|e| BadInput(e.into()))? {
        if !args.refit {
            bail!(BadInput(anyhow::anyhow!(
                "{} already has a model fitted to the skills of epoch {}; --refit replaces it",
                args.run.display(),
                record.checkpoint.epoch
            )));
        }
        let planned_with = fitted_evaluations(&args.run)?;
        if !planned_with.is_empty() {
            bail!(BadInput(anyhow::anyhow!(
                "{}: {} planned with the fitted model there; move them away before refitting",
                args.run.display(),
                planned_with.join(", ")
            )));
        }
    }
    // The skills execute on rayon's threads, each network on one libtorch thread.
    seads_rl::set_threads(1);
    let agent = load_agent(&args.run, args.checkpoint, args.device)?;
    let settings = FitSettings {
        episodes: usize::try_from(args.episodes)?,
        updates: usize::try_from(args.updates)?,
        seed: args.seed.unwrap_or(agent.config.seed),
    };
    let quiet = args.quiet || args.json;
    let bar = crate::progress_bar(
        settings.episodes as u64,
        quiet,
        "{prefix} {wide_bar} {pos}/{len}",
    );
    bar.set_prefix("executing skills");
    let by = seads_study::provenance::this_binary()
        .into_iter()
        .cloned()
        .collect();
    let record = seads_rl::fit_model(&agent, &args.run, &settings, by, |p| match p {
        FitProgress::Collecting { done, .. } => bar.set_position(done as u64),
        FitProgress::Training { done, total } => {
            if bar.length() != Some(total as u64) {
                bar.set_prefix("fitting the model");
                bar.set_length(total as u64);
            }
            bar.set_position(done as u64);
        }
    })?;
    bar.finish_and_clear();
    if args.json {
        outln!("{}", serde_json::to_string(&record)?);
    } else {
        let q = &record.quality;
        outln!(
            "{}: a forward model fitted to the {} skills of epoch {} ({} executions, {} steps): \
             on {} held-out executions, log-likelihood {:.3} nats, the most likely successor right \
             {:.1} %; {:.1} % of executions changed the board",
            args.run.display(),
            record.num_skills,
            record.checkpoint.epoch,
            settings.episodes,
            settings.updates,
            q.held_out,
            q.log_likelihood,
            100.0 * q.mode_accuracy,
            100.0 * q.changed
        );
    }
    Ok(())
}

/// [`seads_rl::fit_model`], the record naming this binary as the one that fitted.
pub fn fit_naming_this_binary(
    agent: &seads_rl::Agent,
    run: &std::path::Path,
    settings: &FitSettings,
    progress: impl FnMut(FitProgress),
) -> Result<FitRecord> {
    let by = seads_study::provenance::this_binary()
        .into_iter()
        .cloned()
        .collect();
    Ok(seads_rl::fit_model(agent, run, settings, by, progress)?)
}

/// The run's evaluation files that planned with its fitted model (their results or their
/// journals), by name.
fn fitted_evaluations(run: &std::path::Path) -> Result<Vec<String>> {
    let mut names: Vec<String> = std::fs::read_dir(run)?
        .filter_map(|e| e.ok()?.file_name().into_string().ok())
        .filter(|n| n.starts_with("evaluation-") && n.contains("-fitted-model"))
        .collect();
    names.sort();
    Ok(names)
}
