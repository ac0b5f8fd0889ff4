//! Reports over any set of sweeps and runs: the paper's Table 1 with its Mann–Whitney tests,
//! interval estimates over runs (IQM, bootstrap confidence intervals, probability of
//! improvement, performance profiles), task success and lengths, failed tasks and the skills that deviated from the model's
//! predictions (each failed task's wrong moves too), where the training time went, coverage and
//! success curves and length box plots, written to `report.md`, CSV files and PNG + SVG figures
//! by [`write_report`].

mod curves;
mod deep;
mod failed_tasks;
mod failures;
mod figures;
pub mod intervals;
mod paper;
mod runs;
pub mod stats;
pub mod summary;
mod tables;
mod versions;
mod walltime;

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use crate::{Context as _, Result, StudyError};

pub use crate::run_data::data_files;
pub use versions::is_repository;

/// A CSV field, quoted when it holds a comma or a quote (RFC 4180).
fn csv_field(text: &str) -> String {
    if text.contains([',', '"', '\n']) {
        format!("\"{}\"", text.replace('"', "\"\""))
    } else {
        text.to_owned()
    }
}

/// What to report.
#[derive(Debug, Clone)]
pub struct ReportOptions {
    /// Sweep directories and run directories, in any mix; a run outside a sweep is its own
    /// variant, named by its directory.
    pub inputs: Vec<PathBuf>,
    /// The variant the others are tested against (`None`: the first sweep's reference).
    pub reference: Option<String>,
    /// Also copy what the report rests on into `OUT/runs/`: each finished, undamaged run's
    /// config, metrics and evaluation files (never checkpoints), with each sweep's index and
    /// manifest; a report of the copy names the runs it lacks.
    pub copy_runs: bool,
    /// The git repository whose commits count as known: the code-version table marks runs that
    /// trained on a commit it lacks (`None`: not checked).
    pub repository: Option<PathBuf>,
}

/// What a report holds, for the front end to tell.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ReportSummary {
    /// Finished runs in the tables.
    pub finished: usize,
    /// Groups (environment × variant).
    pub groups: usize,
    /// Runs left out because a file of theirs cannot be read (`report.md` lists them).
    pub damaged: usize,
    /// Figure files written (PNG and SVG).
    pub figures: usize,
    /// The report itself.
    pub report: PathBuf,
}

/// Writes the report of `options` into the folder `out`: `report.md`, the CSV tables and the
/// figures (and the runs' data with [`ReportOptions::copy_runs`]). An input that is not a sweep
/// or run, or a reference that is no variant, is [`StudyError::Invalid`].
pub fn write_report(options: &ReportOptions, out: &Path) -> Result<ReportSummary> {
    let collection = runs::collect(&options.inputs).map_err(StudyError::into_invalid)?;
    let reference = options.reference.clone().or(collection.reference.clone());
    let (groups, unfinished) = runs::group(&collection.runs).map_err(StudyError::into_invalid)?;
    if let Some(r) = &reference
        && options.reference.is_some()
        && !collection.runs.iter().any(|run| run.variant == *r)
    {
        return Err(StudyError::invalid(format!(
            "--reference {r:?} is not a variant of these runs"
        )));
    }
    if options.copy_runs {
        check_copies(&collection, out)?;
    }
    std::fs::create_dir_all(out).doing(|| format!("creating {}", out.display()))?;
    let write = |name: &str, text: &str| -> Result<()> {
        seads_run::store::write_atomic(&out.join(name), text.as_bytes())?;
        Ok(())
    };
    let cells = tables::coverage_cells(&groups, reference.as_deref());
    write("table1.csv", &tables::coverage_csv(&cells))?;
    let against_paper = paper::comparison(&cells, reference.as_deref())?;
    if let Some((_, csv)) = &against_paper {
        write("paper.csv", csv)?;
    }
    let over_training = curves::coverage_over_training(&groups, reference.as_deref());
    if let Some((_, csv)) = &over_training {
        write("coverage-over-training.csv", csv)?;
    }
    let intervals = tables::interval_tables(&groups, reference.as_deref());
    if let Some((_, csv)) = &intervals {
        write("intervals.csv", csv)?;
    }
    let (success_md, success_csv) = tables::success_tables(&groups);
    write("success.csv", &success_csv)?;
    let noise = tables::noise_tables(&groups);
    if let Some((_, csv)) = &noise {
        write("noise.csv", csv)?;
    }
    let deep = deep::deep_tables(&groups);
    if let Some((_, csv)) = &deep {
        write("deep-search.csv", csv)?;
    }
    let (length_md, length_csv) = tables::length_tables(&groups);
    write("lengths.csv", &length_csv)?;
    let (walltime_md, walltime_csv) = walltime::walltime_tables(&groups);
    write("walltime.csv", &walltime_csv)?;
    let known = |commit: &str| {
        options
            .repository
            .as_deref()
            .and_then(|repo| versions::has_commit(repo, commit))
    };
    let reported: Vec<&runs::RunData> = collection.runs.iter().collect();
    let (versions_md, versions_csv) = versions::version_tables(&reported, &known);
    write("versions.csv", &versions_csv)?;
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
    let mut figures = figures::coverage_figures(out, &groups, &k_of)?;
    figures.extend(figures::profile_figures(out, &groups, &k_of)?);
    figures.extend(figures::success_figures(out, &groups)?);
    figures.extend(figures::length_figures(out, &groups)?);

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
            "- unfinished: `{}` ({steps} of {} steps{})",
            run.dir.display(),
            run.config.env_steps,
            if run.busy { "; a task works on it" } else { "" }
        );
    }
    if not_started > 0 {
        let _ = writeln!(md, "- not started: {not_started} run(s)");
    }
    if collection.absent > 0 {
        let _ = writeln!(
            md,
            "- not here: {} run(s) of the sweep have no directory (a copy holds finished runs only)",
            collection.absent
        );
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
    if !unfinished.is_empty() || damaged > 0 || collection.absent > 0 {
        md.push('\n');
    }
    let _ = writeln!(md, "## Skill coverage at the end of training (Table 1)\n");
    md += &tables::coverage_markdown(&cells, reference.as_deref());
    let _ = writeln!(md, "\nAs CSV: `table1.csv`.\n");
    if let Some((paper_md, _)) = &against_paper {
        let _ = writeln!(md, "## Against the paper's Table 1\n");
        md += paper_md;
        let _ = writeln!(md, "\nAs CSV: `paper.csv`.\n");
    }
    if let Some((intervals_md, _)) = &intervals {
        let _ = writeln!(md, "## Interval estimates over runs\n");
        md += intervals_md;
        let _ = writeln!(
            md,
            "\nAs CSV: `intervals.csv`; the run score distributions (performance profiles) of \
             coverage are the figures `profile-<environment>`.\n"
        );
    }
    if let Some((curve_md, _)) = &over_training {
        let _ = writeln!(md, "## Skill coverage over training\n");
        md += curve_md;
        let _ = writeln!(md, "\nAs CSV: `coverage-over-training.csv`.\n");
    }
    let _ = writeln!(md, "## Task success at the end of training\n");
    md += &success_md;
    md += &evaluation_notes(&collection.runs);
    let _ = writeln!(md, "\nAs CSV: `success.csv`.\n");
    if let Some(fits) = tables::fit_table(&groups) {
        let _ = writeln!(md, "## Forward models fitted to the skills\n");
        md += &fits;
        md.push('\n');
    }
    if let Some(comparison) = tables::success_comparison(&groups, reference.as_deref()) {
        let _ = writeln!(md, "## SEADS against the baselines: task success\n");
        md += &comparison;
        md.push('\n');
    }
    if let Some((noise_md, _)) = &noise {
        let _ = writeln!(md, "## Task success under action noise\n");
        md += noise_md;
        let _ = writeln!(md, "\nAs CSV: `noise.csv`.\n");
    }
    if let Some((deep_md, _)) = &deep {
        let _ = writeln!(md, "## The deeper search (Fig. S.7)\n");
        md += deep_md;
        let _ = writeln!(md, "\nAs CSV: `deep-search.csv`.\n");
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
    let _ = writeln!(md, "## Code versions the runs trained on\n");
    md += &versions_md;
    let _ = writeln!(md, "\nAs CSV, per run: `versions.csv`.\n");
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
    if options.copy_runs {
        // A sweep's index and manifest come along, so that the copy is a sweep again.
        for (name, dir) in collection.sweeps.iter().zip(&collection.sweep_dirs) {
            let dest = out.join("runs").join(name);
            std::fs::create_dir_all(&dest).doing(|| format!("creating {}", dest.display()))?;
            for file in [crate::sweep::INDEX, crate::sweep::MANIFEST] {
                let bytes = std::fs::read(dir.join(file))
                    .doing(|| format!("reading {}", dir.join(file).display()))?;
                seads_run::store::write_atomic(&dest.join(file), &bytes)?;
            }
        }
        // What the tables rest on: finished, undamaged runs (the others resume where they are).
        for run in collection
            .runs
            .iter()
            .filter(|r| r.finished() && r.damage.is_empty())
        {
            crate::run_data::copy_data(&run.dir, &out.join("runs").join(&run.copy_to))?;
        }
        let _ = writeln!(
            md,
            "The data of every run (configuration, metrics, evaluations; no checkpoints) is in \
             `runs/`, sweeps with their index: `seads report runs/<sweep> --out …` reports it again.\n"
        );
    }
    write("report.md", &md)?;
    Ok(ReportSummary {
        finished,
        groups: groups.len(),
        damaged,
        figures: figures.len(),
        report: out.join("report.md"),
    })
}

/// Refuses, before anything is written, copies that would collide or land inside what they
/// copy: two runs with one destination under `runs/` (runs of the same name outside a sweep), or
/// a report folder inside a run or sweep it copies.
fn check_copies(collection: &runs::Collection, out: &Path) -> Result<()> {
    let mut taken: std::collections::BTreeMap<PathBuf, &Path> = Default::default();
    for run in collection
        .runs
        .iter()
        .filter(|r| r.finished() && r.damage.is_empty())
    {
        if let Some(other) = taken.insert(run.copy_to.clone(), &run.dir) {
            return Err(StudyError::invalid(format!(
                "{} and {} would both be copied to runs/{}: report them without --copy-runs, \
                 or rename one",
                other.display(),
                run.dir.display(),
                run.copy_to.display()
            )));
        }
    }
    // The report folder, or the nearest folder above it that exists, as a real path.
    let mut probe = out.to_path_buf();
    let target = loop {
        if let Ok(real) = std::fs::canonicalize(&probe) {
            break real;
        }
        match probe.parent() {
            Some(parent) if !parent.as_os_str().is_empty() => probe = parent.to_path_buf(),
            _ => break std::env::current_dir().unwrap_or_default(),
        }
    };
    let dirs = collection.runs.iter().map(|r| r.dir.as_path());
    for dir in dirs.chain(collection.sweep_dirs.iter().map(PathBuf::as_path)) {
        if let Ok(dir) = std::fs::canonicalize(dir)
            && target.starts_with(&dir)
        {
            return Err(StudyError::invalid(format!(
                "{} lies inside {}, which --copy-runs copies: write the report elsewhere",
                out.display(),
                dir.display()
            )));
        }
    }
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
