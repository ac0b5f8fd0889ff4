//! `seads report`: tables, tests and figures over any set of sweeps and runs — the paper's
//! Table 1 with its Mann–Whitney tests, task success and lengths, failed tasks and the skills
//! that deviated from the model's predictions (each failed task's wrong moves too), where the
//! training time went, coverage and success curves and length box plots — written to
//! `report.md`, CSV files and PNG + SVG figures.

mod curves;
mod failed_tasks;
mod failures;
mod figures;
mod runs;
mod stats;
mod tables;
mod walltime;

use std::fmt::Write as _;
use std::path::PathBuf;

use anyhow::{Context, Result, anyhow};
use clap::Args;

use crate::BadInput;

/// A CSV field, quoted when it holds a comma or a quote (RFC 4180).
fn csv_field(text: &str) -> String {
    if text.contains([',', '"', '\n']) {
        format!("\"{}\"", text.replace('"', "\"\""))
    } else {
        text.to_owned()
    }
}

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
    /// Also copy what the report rests on into REPORT_DIR/runs/: each run's config.toml,
    /// metrics.jsonl and evaluation files (never checkpoints), so that the folder can be
    /// committed as data and reported again from itself.
    #[arg(long)]
    copy_runs: bool,
}

/// Runs `seads report`.
pub fn report(args: ReportArgs) -> Result<()> {
    let inputs: Vec<&std::path::Path> = args.inputs.iter().map(PathBuf::as_path).collect();
    crate::refuse_overwriting_input(&args.out, &inputs)?;
    let collection = runs::collect(&args.inputs).map_err(BadInput)?;
    let reference = args.reference.clone().or(collection.reference.clone());
    let (groups, unfinished) = runs::group(&collection.runs).map_err(BadInput)?;
    if let Some(r) = &reference
        && args.reference.is_some()
        && !collection.runs.iter().any(|run| run.variant == *r)
    {
        return Err(BadInput(anyhow!("--reference {r:?} is not a variant of these runs")).into());
    }
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("creating {}", args.out.display()))?;
    let write = |name: &str, text: &str| -> Result<()> {
        seads_rl::write_atomic(&args.out.join(name), text.as_bytes())?;
        Ok(())
    };
    let cells = tables::coverage_cells(&groups, reference.as_deref());
    write("table1.csv", &tables::coverage_csv(&cells))?;
    let over_training = curves::coverage_over_training(&groups, reference.as_deref());
    if let Some((_, csv)) = &over_training {
        write("coverage-over-training.csv", csv)?;
    }
    let (success_md, success_csv) = tables::success_tables(&groups);
    write("success.csv", &success_csv)?;
    let (length_md, length_csv) = tables::length_tables(&groups);
    write("lengths.csv", &length_csv)?;
    let (walltime_md, walltime_csv) = walltime::walltime_tables(&groups);
    write("walltime.csv", &walltime_csv)?;
    let failures = failures::failure_tables(&groups)?;
    if let Some((_, failures_csv, deviations_csv)) = &failures {
        write("failures.csv", failures_csv)?;
        write("deviations.csv", deviations_csv)?;
    }
    let failed_tasks = failed_tasks::failed_task_tables(&groups)?;
    if let Some((_, csv)) = &failed_tasks {
        write("failed-tasks.csv", csv)?;
    }
    let k_of = |g: &runs::Group<'_>| tables::skills(g.runs[0]);
    let mut figures = figures::coverage_figures(&args.out, &groups, &k_of)?;
    figures.extend(figures::success_figures(&args.out, &groups)?);
    figures.extend(figures::length_figures(&args.out, &groups)?);

    let mut md = String::new();
    let title = if collection.sweeps.is_empty() {
        "runs".to_owned()
    } else {
        collection.sweeps.join(", ")
    };
    let _ = writeln!(md, "# Report: {title}\n");
    let damaged = collection
        .runs
        .iter()
        .filter(|r| !r.damage.is_empty())
        .count()
        + collection.unreadable.len();
    let finished = groups.iter().map(|g| g.runs.len()).sum::<usize>();
    let _ = writeln!(
        md,
        "Written by `seads report` from {} run(s): {finished} finished, {} unfinished and {damaged} \
         damaged (left out of every table and figure).\n",
        collection.runs.len() + collection.unreadable.len(),
        unfinished.len(),
    );
    let mut not_started = 0;
    for run in &unfinished {
        let steps = run.env_steps();
        if steps == 0 {
            not_started += 1;
            continue;
        }
        let _ = writeln!(
            md,
            "- unfinished: `{}` ({steps} of {} steps)",
            run.dir.display(),
            run.config.env_steps
        );
    }
    if not_started > 0 {
        let _ = writeln!(md, "- not started: {not_started} run(s)");
    }
    for run in collection.runs.iter().filter(|r| !r.damage.is_empty()) {
        let _ = writeln!(
            md,
            "- damaged, left out of every table: `{}`: {}",
            run.dir.display(),
            run.damage.join("; ")
        );
    }
    for (dir, why) in &collection.unreadable {
        let _ = writeln!(
            md,
            "- damaged, left out of every table: `{}`: {why}",
            dir.display()
        );
    }
    if !unfinished.is_empty() || damaged > 0 {
        md.push('\n');
    }
    let _ = writeln!(md, "## Skill coverage at the end of training (Table 1)\n");
    md += &tables::coverage_markdown(&cells, reference.as_deref());
    let _ = writeln!(md, "\nAs CSV: `table1.csv`.\n");
    if let Some((curve_md, _)) = &over_training {
        let _ = writeln!(md, "## Skill coverage over training\n");
        md += curve_md;
        let _ = writeln!(md, "\nAs CSV: `coverage-over-training.csv`.\n");
    }
    let _ = writeln!(md, "## Task success at the end of training\n");
    md += &success_md;
    md += &evaluation_notes(&collection.runs);
    let _ = writeln!(md, "\nAs CSV: `success.csv`.\n");
    if let Some(comparison) = tables::success_comparison(&groups, reference.as_deref()) {
        let _ = writeln!(md, "## SEADS against the baselines: task success\n");
        md += &comparison;
        md.push('\n');
    }
    let _ = writeln!(md, "## Skill and solution length\n");
    md += &length_md;
    let _ = writeln!(md, "\nAs CSV: `lengths.csv`.\n");
    if let Some((failures_md, _, _)) = &failures {
        let _ = writeln!(md, "## Failed tasks and deviations (re-planning)\n");
        md += failures_md;
        let _ = writeln!(
            md,
            "\nAs CSV: `failures.csv`, and per skill `deviations.csv`.\n"
        );
    }
    if let Some((failed_md, _)) = &failed_tasks {
        let _ = writeln!(md, "## The failed tasks, one by one (re-planning)\n");
        md += failed_md;
        let _ = writeln!(md, "\nAs CSV: `failed-tasks.csv`.\n");
    }
    let _ = writeln!(md, "## Where the training time went\n");
    md += &walltime_md;
    let _ = writeln!(md, "\nAs CSV, per run: `walltime.csv`.\n");
    let _ = writeln!(md, "## Figures\n");
    if let Some(note) = figures::success_note(&groups) {
        let _ = writeln!(md, "{note}\n");
    }
    for f in figures
        .iter()
        .filter(|f| f.extension().is_some_and(|e| e == "png"))
    {
        let name = f
            .file_name()
            .map_or(String::new(), |n| n.to_string_lossy().into_owned());
        let _ = writeln!(md, "![{name}]({name})\n");
    }
    if args.copy_runs {
        // A sweep's index and manifest come along, so that the copy is a sweep again.
        for (name, dir) in collection.sweeps.iter().zip(&collection.sweep_dirs) {
            let dest = args.out.join("runs").join(name);
            std::fs::create_dir_all(&dest)
                .with_context(|| format!("creating {}", dest.display()))?;
            for file in [crate::sweep::INDEX, crate::sweep::MANIFEST] {
                let bytes = std::fs::read(dir.join(file))
                    .with_context(|| format!("reading {}", dir.join(file).display()))?;
                seads_rl::write_atomic(&dest.join(file), &bytes)?;
            }
        }
        for run in &collection.runs {
            let dest = args.out.join("runs").join(&run.copy_to);
            std::fs::create_dir_all(&dest)
                .with_context(|| format!("creating {}", dest.display()))?;
            for file in runs::data_files(&run.dir)? {
                let bytes =
                    std::fs::read(&file).with_context(|| format!("reading {}", file.display()))?;
                let name = file.file_name().expect("a file has a name");
                seads_rl::write_atomic(&dest.join(name), &bytes)?;
            }
        }
        let _ = writeln!(
            md,
            "The data of every run (configuration, metrics, evaluations; no checkpoints) is in \
             `runs/`, sweeps with their index: `seads report runs/<sweep> --out …` reports it again.\n"
        );
    }
    write("report.md", &md)?;
    if damaged > 0 {
        eprintln!("seads: {damaged} damaged run(s) left out; report.md lists them with why");
    }
    outln!(
        "report of {finished} finished run(s) in {} groups: {} (and {} figure files)",
        groups.len(),
        args.out.join("report.md").display(),
        figures.len()
    );
    Ok(())
}

/// Which evaluation files the end-of-training tables left out (they evaluated an earlier
/// checkpoint) or took without knowing their checkpoint (older files), as Markdown lines.
fn evaluation_notes(runs: &[runs::RunData]) -> String {
    let mut md = String::new();
    for run in runs {
        for note in &run.evaluation_notes {
            let _ = writeln!(md, "- `{}`: {note}", run.dir.display());
        }
    }
    let unrecorded: usize = runs.iter().map(|r| r.unrecorded_evaluations).sum();
    if unrecorded > 0 {
        let _ = writeln!(
            md,
            "- {unrecorded} evaluation file(s) do not record which checkpoint they evaluated \
             (written before evaluations did): taken as the end of training"
        );
    }
    if !md.is_empty() {
        md.insert(0, '\n');
    }
    md
}

#[cfg(test)]
mod tests {
    use super::csv_field;

    #[test]
    fn csv_fields_are_quoted_only_when_they_must_be() {
        assert_eq!(csv_field("a, \"b\""), "\"a, \"\"b\"\"\"");
        assert_eq!(csv_field("AMD EPYC 9554"), "AMD EPYC 9554");
        assert_eq!(csv_field("a\nb"), "\"a\nb\"");
    }
}
