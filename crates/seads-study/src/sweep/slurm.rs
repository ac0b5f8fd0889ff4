//! `seads sweep slurm`: the sweep as one Slurm job array (a task per run, `%M` throttle, each
//! task `seads sweep task DIR --index $SLURM_ARRAY_TASK_ID`, re-queueable) and a dependent job
//! that writes the report once every task has ended. Slurm schedules; we only write the
//! scripts and, with `--submit`, hand them to `sbatch`.

use std::path::{Path, PathBuf};
use std::process::Command;

use seads_run::ComputeDevice;

use crate::error::fail;
use crate::{Context as _, Result};

use super::index::Sweep;

/// Where the scripts go, inside the sweep directory.
pub const SLURM_DIR: &str = "slurm";

/// Options of the job array.
#[derive(Debug, Clone)]
pub struct SlurmOptions {
    /// Partition (`--partition`), if any.
    pub partition: Option<String>,
    /// Time limit per task (`--time`, Slurm's format).
    pub time: String,
    /// Memory per task (`--mem`, Slurm's format: a number with an optional unit K, M, G or T);
    /// `None`: the cluster's default.
    pub mem: Option<String>,
    /// Cores per task; the task's libtorch threads follow them.
    pub cpus_per_task: usize,
    /// At most this many tasks at once (`%M`), if any.
    pub max_parallel: Option<usize>,
    /// The `seads` binary the tasks run (it must be reachable from the compute nodes).
    pub seads: PathBuf,
    /// Where the tasks' networks run. For a GPU each task asks for one (`--gres=gpu:1`), which
    /// Slurm makes its `cuda:0`.
    pub device: ComputeDevice,
    /// The runs as populations (`--population K`), one array task each; `None`: a task per run.
    pub populations: Option<Vec<Vec<usize>>>,
    /// Whether the tasks may train with a binary built from a working tree with uncommitted
    /// changes (`sweep task --allow-dirty`).
    pub allow_dirty: bool,
    /// Pass `--allow-other-commit` to the tasks.
    pub allow_other_commit: bool,
}

/// A word for bash, single-quoted.
fn quote(text: &str) -> String {
    format!("'{}'", text.replace('\'', r"'\''"))
}

/// The job array script and the report script, as text.
pub fn scripts(dir: &Path, sweep: &Sweep, options: &SlurmOptions) -> (String, String) {
    let d = dir.display().to_string();
    let seads = quote(&options.seads.display().to_string());
    let logs = format!("{d}/{SLURM_DIR}/logs");
    let throttle = options
        .max_parallel
        .map_or(String::new(), |m| format!("%{m}"));
    let partition = options
        .partition
        .as_ref()
        .map_or(String::new(), |p| format!("#SBATCH --partition={p}\n"));
    let mem = options
        .mem
        .as_ref()
        .map_or(String::new(), |m| format!("#SBATCH --mem={m}\n"));
    let (gres, device) = match options.device {
        ComputeDevice::Cpu => (String::new(), String::new()),
        ComputeDevice::Cuda(_) => (
            "#SBATCH --gres=gpu:1\n".to_owned(),
            " --device cuda:0".to_owned(),
        ),
    };
    // With populations, array task i trains the runs listed in the script's i-th word.
    let (last, members, index) = match &options.populations {
        None => (
            sweep.runs.len().saturating_sub(1),
            String::new(),
            "\"$SLURM_ARRAY_TASK_ID\"".to_owned(),
        ),
        Some(groups) => {
            let words: Vec<String> = groups
                .iter()
                .map(|g| g.iter().map(usize::to_string).collect::<Vec<_>>().join(","))
                .collect();
            (
                groups.len().saturating_sub(1),
                format!("POPULATIONS=({})\n", words.join(" ")),
                "\"${POPULATIONS[$SLURM_ARRAY_TASK_ID]}\"".to_owned(),
            )
        }
    };
    let array = format!(
        "#!/bin/bash\n\
         # One task per {unit} of sweep {name:?}; written by `seads sweep slurm`.\n\
         # A task resumes its run when it is re-queued or submitted again.\n\
         #SBATCH --job-name=seads-{name}\n\
         #SBATCH --array=0-{last}{throttle}\n\
         #SBATCH --cpus-per-task={cpus}\n\
         #SBATCH --time={time}\n\
         {mem}\
         {partition}\
         {gres}\
         #SBATCH --output=\"{logs}/task-%a.out\"\n\
         #SBATCH --requeue\n\
         {members}\
         exec {seads} sweep task {dir} --index {index} --cores \"${{SLURM_CPUS_PER_TASK:-{cpus}}}\"{device}{dirty}\n",
        name = sweep.name,
        dirty = match (options.allow_dirty, options.allow_other_commit) {
            (true, true) => " --allow-dirty --allow-other-commit",
            (true, false) => " --allow-dirty",
            (false, true) => " --allow-other-commit",
            (false, false) => "",
        },
        unit = if options.populations.is_some() {
            "population of runs"
        } else {
            "run"
        },
        cpus = options.cpus_per_task,
        time = options.time,
        dir = quote(&d),
    );
    let report = format!(
        "#!/bin/bash\n\
         # The report of sweep {name:?}, once every task has ended; written by `seads sweep slurm`.\n\
         #SBATCH --job-name=seads-{name}-report\n\
         #SBATCH --cpus-per-task=1\n\
         #SBATCH --time={time}\n\
         {partition}\
         #SBATCH --output=\"{logs}/report.out\"\n\
         {seads} sweep status {dir}\n\
         exec {seads} report {dir} --out {out}\n",
        name = sweep.name,
        time = options.time,
        dir = quote(&d),
        out = quote(&format!("{d}/report")),
    );
    (array, report)
}

/// Refuses what the scripts could not hold safely ([`crate::StudyError::Invalid`], before
/// anything is written): a newline would end an `#SBATCH` line and start a command, `%` is
/// expanded by Slurm in `--output`, and the values of `#SBATCH` lines are one word each.
pub fn check_options(dir: &Path, options: &SlurmOptions) -> Result<()> {
    let word = |name: &str, value: &str| -> Result<()> {
        if value.is_empty()
            || value
                .chars()
                .any(|c| c.is_whitespace() || "%\"'\\".contains(c))
        {
            return Err(crate::StudyError::invalid(format!(
                "{name} {value:?} must be one word without spaces, quotes or %"
            )));
        }
        Ok(())
    };
    word("--time", &options.time)?;
    if let Some(partition) = &options.partition {
        word("--partition", partition)?;
    }
    if let Some(mem) = &options.mem {
        let digits = mem.trim_end_matches(['K', 'M', 'G', 'T']);
        let unit = mem.len() - digits.len();
        if digits.is_empty() || !digits.chars().all(|c| c.is_ascii_digit()) || unit > 1 {
            return Err(crate::StudyError::invalid(format!(
                "--mem {mem:?} must be a number with an optional unit K, M, G or T (8G, 8000M)"
            )));
        }
    }
    for (name, path) in [("the sweep directory", dir), ("--seads", &options.seads)] {
        let text = path.to_string_lossy();
        if text.chars().any(|c| c.is_control() || c == '%' || c == '"') {
            return Err(crate::StudyError::invalid(format!(
                "{name} {text:?} holds a newline, a quote or %, which a Slurm script cannot hold"
            )));
        }
    }
    Ok(())
}

/// Writes the scripts into `dir/slurm/`; returns their paths.
pub fn write_scripts(
    dir: &Path,
    sweep: &Sweep,
    options: &SlurmOptions,
) -> Result<(PathBuf, PathBuf)> {
    check_options(dir, options)?;
    let (array, report) = scripts(dir, sweep, options);
    let folder = dir.join(SLURM_DIR);
    std::fs::create_dir_all(folder.join("logs"))
        .doing(|| format!("creating {}", folder.display()))?;
    let paths = (folder.join("array.sbatch"), folder.join("report.sbatch"));
    seads_run::store::write_atomic(&paths.0, array.as_bytes())?;
    seads_run::store::write_atomic(&paths.1, report.as_bytes())?;
    Ok(paths)
}

/// `sbatch --parsable [extra] script`: the job id.
fn sbatch(script: &Path, extra: &[String]) -> Result<String> {
    let output = Command::new("sbatch")
        .arg("--parsable")
        .args(extra)
        .arg(script)
        .output()
        .doing(|| "running sbatch (is Slurm installed and SLURM_CONF set?)".to_owned())?;
    if !output.status.success() {
        fail!(
            "sbatch {} failed: {}",
            script.display(),
            String::from_utf8_lossy(&output.stderr).trim()
        );
    }
    let text = String::from_utf8_lossy(&output.stdout);
    // `--parsable` prints "id" or "id;cluster".
    let id = text.trim().split(';').next().unwrap_or("").to_owned();
    if id.is_empty() {
        fail!("sbatch printed no job id");
    }
    Ok(id)
}

/// Submits the array, then the report job after it (`afterany`: the report is written even
/// when tasks failed, and shows them). Returns both job ids.
pub fn submit(array: &Path, report: &Path) -> Result<(String, String)> {
    let array_id = sbatch(array, &[])?;
    let report_id = sbatch(report, &[format!("--dependency=afterany:{array_id}")])?;
    Ok((array_id, report_id))
}
