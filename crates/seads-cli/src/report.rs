//! `seads report`: tables, tests and figures over any set of sweeps and runs
//! ([`seads_study::report`]), written to `report.md`, CSV files and PNG + SVG figures.

use std::path::PathBuf;

use anyhow::Result;
use clap::Args;
use seads_study::report::{ReportOptions, write_report};

/// Arguments of `seads report`.
#[derive(Debug, Args)]
pub struct ReportArgs {
    /// Sweep directories (from `seads sweep plan`) and run directories, in any mix. A run outside
    /// a sweep is its own variant, named by its directory.
    #[arg(required = true)]
    inputs: Vec<PathBuf>,
    /// Folder for report.md, the CSV tables and the figures.
    #[arg(long)]
    out: PathBuf,
    /// The variant the others are tested against (default: the first sweep's reference).
    #[arg(long)]
    reference: Option<String>,
    /// Also copy what the report rests on into REPORT_DIR/runs/: each finished, undamaged run's
    /// config.toml, metrics.jsonl and evaluation files (never checkpoints; unfinished runs stay
    /// where they resume), so that the folder can be committed as data and reported again from
    /// itself.
    #[arg(long)]
    copy_runs: bool,
    /// The git repository whose commits count as known: the report's code-version table marks
    /// runs that trained on a commit it lacks (default: the current directory's repository).
    #[arg(long, value_name = "DIR")]
    repository: Option<PathBuf>,
}

/// Runs `seads report`.
pub fn report(args: ReportArgs) -> Result<()> {
    let inputs: Vec<&std::path::Path> = args.inputs.iter().map(PathBuf::as_path).collect();
    crate::paths::refuse_overwriting_input(&args.out, &inputs)?;
    // A repository the user names must be one: a report would otherwise say "not checked" for
    // every commit, as if no repository had been asked for.
    if let Some(repository) = &args.repository {
        match seads_study::report::is_repository(repository) {
            Some(true) => {}
            Some(false) => {
                return Err(crate::bad_input(anyhow::anyhow!(
                    "--repository {} is not a git repository",
                    repository.display()
                ))
                .into());
            }
            None => {
                return Err(crate::bad_input(anyhow::anyhow!(
                    "--repository {}: git could not be run to look up commits",
                    repository.display()
                ))
                .into());
            }
        }
    }
    let options = ReportOptions {
        inputs: args.inputs.clone(),
        reference: args.reference.clone(),
        copy_runs: args.copy_runs,
        repository: Some(
            args.repository
                .clone()
                .unwrap_or_else(|| PathBuf::from(".")),
        ),
    };
    let summary = write_report(&options, &args.out).map_err(crate::study_error)?;
    if summary.damaged > 0 {
        eprintln!(
            "seads: {} damaged run(s) left out; report.md lists them with why",
            summary.damaged
        );
    }
    outln!(
        "report of {} finished run(s) in {} groups: {} (and {} figure files)",
        summary.finished,
        summary.groups,
        summary.report.display(),
        summary.figures
    );
    Ok(())
}
