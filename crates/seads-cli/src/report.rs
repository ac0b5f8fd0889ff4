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

/// Arguments of `seads summary`.
#[derive(Debug, clap::Args)]
pub struct SummaryArgs {
    /// The folder of committed studies; each study with a claims.toml beside its runs gives
    /// rows of the table.
    #[arg(long, default_value = "docs/results", value_name = "DIR")]
    results: PathBuf,
    /// Write the table into this document, between its summary markers (RESULTS.md), instead
    /// of printing it.
    #[arg(long, value_name = "FILE", conflicts_with = "check")]
    write: Option<PathBuf>,
    /// Exit 1 when this document's summary differs from the table the data give.
    #[arg(long, value_name = "FILE")]
    check: Option<PathBuf>,
}

/// Runs `seads summary`: RESULTS' summary table from the studies' claims and committed runs.
pub fn summary(args: SummaryArgs) -> Result<()> {
    use seads_study::report::summary::{replace_summary, summary_table};
    if !args.results.is_dir() {
        return Err(crate::bad_input(anyhow::anyhow!(
            "--results {} is not a folder of studies",
            args.results.display()
        ))
        .into());
    }
    let table = summary_table(&args.results).map_err(crate::study_error)?;
    let Some(document) = args.write.as_ref().or(args.check.as_ref()) else {
        outln!("{table}");
        return Ok(());
    };
    let text = std::fs::read_to_string(document)
        .map_err(|e| crate::bad_input(anyhow::anyhow!("reading {}: {e}", document.display())))?;
    let updated = replace_summary(&text, &table)
        .map_err(|e| crate::bad_input(anyhow::anyhow!("{}: {e}", document.display())))?;
    if args.check.is_some() {
        if updated != text {
            anyhow::bail!(
                "{}: its summary differs from the data; run `seads summary --write {}`",
                document.display(),
                document.display()
            );
        }
        outln!("{}: the summary matches the data", document.display());
    } else {
        seads_run::store::write_atomic(document, updated.as_bytes())?;
        outln!("wrote the summary into {}", document.display());
    }
    Ok(())
}
