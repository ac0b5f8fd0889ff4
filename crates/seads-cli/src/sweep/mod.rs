//! `seads sweep`: studies over many seeds and variants — plan them from a manifest, run them on
//! this machine or as a Slurm job array, and see where each run stands.

mod pool;
pub(crate) mod task;
pub(crate) mod train;

use std::path::PathBuf;
use std::time::Duration;

use anyhow::{Context, Result, anyhow};
use clap::{Args, Subcommand};

pub use index::Sweep;
pub use manifest::Manifest;
pub use state::TAKEN_EXIT;

use crate::BadInput;
use seads_rl::ComputeDevice;
use seads_study::sweep::{Overview, index, manifest, slurm, state};

/// `seads sweep …`.
#[derive(Debug, Subcommand)]
pub enum SweepCommand {
    /// Expand a study manifest (experiments/*.toml) into one run directory per environment ×
    /// variant × seed, each with its full config.toml, plus the sweep's index. Planning the same
    /// manifest again changes nothing.
    Plan(PlanArgs),
    /// Train and evaluate every run of a sweep that is not done, on this machine: killed runs
    /// resume (those already begun before any new one starts), new runs start, failed ones are
    /// tried again. Stop it at any time; running it again loses nothing.
    Run(RunArgs),
    /// Train and evaluate one run of a sweep (what each Slurm array task runs); resumes a run
    /// that a killed or re-queued task left.
    Task(TaskArgs),
    /// Write an sbatch script for a Slurm job array (one task per run) and a dependent job that
    /// writes the report; with --submit, submit both.
    Slurm(SlurmArgs),
    /// Done / running / failed / pending per run and in total, read from the run directories.
    Status(StatusArgs),
    /// Lay a sweep out again from its committed copy (`seads report --copy-runs`, e.g.
    /// docs/results/STUDY/runs/SWEEP) on this machine: planned again from its manifest, the
    /// committed runs laid in as copied; `seads sweep run` then trains the rest.
    Restore(RestoreArgs),
}

/// Arguments of `seads sweep plan`.
#[derive(Debug, Args)]
pub struct PlanArgs {
    /// The study manifest (see experiments/).
    manifest: PathBuf,
    /// The sweep directory to create.
    #[arg(long)]
    out: PathBuf,
}

/// A count that must be at least 1 (workers, cores): 0 is a one-line usage error.
fn at_least_one(option: &str, value: u64) -> Result<usize> {
    if value == 0 {
        return Err(BadInput(anyhow!("{option} must be at least 1")).into());
    }
    Ok(usize::try_from(value).unwrap_or(usize::MAX))
}

/// A count of threads or processes on this machine (workers, cores): at least 1 and at most
/// [`crate::max_threads`], said in one line otherwise.
fn thread_count(option: &str, value: u64) -> Result<usize> {
    let value = at_least_one(option, value)?;
    crate::check_threads(option, value)?;
    Ok(value)
}

fn cores() -> usize {
    std::thread::available_parallelism().map_or(1, |n| n.get())
}

/// Arguments of `seads sweep run`.
#[derive(Debug, Args)]
pub struct RunArgs {
    /// The sweep directory (from `seads sweep plan`).
    dir: PathBuf,
    /// Runs trained at once. Each gets an equal share of the cores (a run trains on two threads,
    /// so the default gives each two cores; --workers 2 on two cores gives each one).
    #[arg(long)]
    workers: Option<u64>,
    /// Cores to share among the workers (default: all of this machine's).
    #[arg(long)]
    cores: Option<u64>,
    /// Only the runs of these seeds, a list (1,2,3) or a range (1-3): finish a few seeds of every
    /// variant before starting more.
    #[arg(long, value_parser = crate::numbers::NumberList::parse)]
    seeds: Option<crate::numbers::NumberList>,
    /// Where each run's networks train and evaluate: cpu, cuda (the first GPU) or cuda:N. The
    /// workers share the device.
    #[arg(long, default_value = "cpu")]
    device: ComputeDevice,
    /// Train up to K compatible runs (same environment and network shapes) as one population in
    /// one process per worker: their epochs side by side on the worker's cores, each run
    /// written, resumed and evaluated as if trained alone, with the same metrics on the CPU. With
    /// a GPU device, SEADS members' SAC steps run there on stacked weights, all at once.
    #[arg(long, value_name = "K")]
    population: Option<u64>,
    /// Train even though this binary was built from a working tree with uncommitted changes
    /// (refused by default, so that a study's runs come from committed code; such runs say
    /// `dirty: true` in their provenance and the report marks them). The environment variable
    /// SEADS_ALLOW_DIRTY=1 (or true, yes, on) does the same.
    #[arg(long)]
    allow_dirty: bool,
    /// Train with this binary although the sweep was planned by a binary of another commit
    /// (refused by default, so that a cell's runs never mix code versions).
    #[arg(long)]
    allow_other_commit: bool,
    /// No progress bar.
    #[arg(long)]
    quiet: bool,
}

/// Arguments of `seads sweep task`.
#[derive(Debug, Args)]
pub struct TaskArgs {
    /// The sweep directory.
    dir: PathBuf,
    /// Index of the run in the sweep (0-based; a Slurm array task passes $SLURM_ARRAY_TASK_ID),
    /// or a list of runs (0,5,10) to train as one population.
    #[arg(long, value_parser = crate::numbers::NumberList::parse)]
    index: crate::numbers::NumberList,
    /// Cores of this task; its libtorch threads follow them (Slurm: $SLURM_CPUS_PER_TASK).
    #[arg(long, default_value_t = 2)]
    cores: u64,
    /// Where the run's networks train and evaluate: cpu, cuda or cuda:N.
    #[arg(long, default_value = "cpu")]
    device: ComputeDevice,
    /// How long to wait for another task that holds one of the runs (a re-queued Slurm task
    /// waits for the one it replaces to let go) before giving up: exit 3 for one run, exit 2
    /// for a population.
    #[arg(long, value_name = "SECONDS", default_value_t = state::PATIENCE.as_secs())]
    wait: u64,
    /// Train even though this binary was built from a working tree with uncommitted changes
    /// (refused by default; see `seads sweep run --allow-dirty`; or SEADS_ALLOW_DIRTY=1).
    #[arg(long)]
    allow_dirty: bool,
    /// Train with this binary although the sweep was planned by a binary of another commit
    /// (refused by default; see `seads sweep run --allow-other-commit`).
    #[arg(long)]
    allow_other_commit: bool,
    /// Started by `seads sweep run`: die with the parent, and if another task holds the run,
    /// exit with status 3 (taken elsewhere) after two seconds.
    #[arg(long, hide = true)]
    child: bool,
}

/// Arguments of `seads sweep slurm`.
#[derive(Debug, Args)]
pub struct SlurmArgs {
    /// The sweep directory.
    dir: PathBuf,
    /// Slurm partition of the jobs.
    #[arg(long)]
    partition: Option<String>,
    /// Time limit per task, in Slurm's format (a task that hits it is resumed when re-queued).
    #[arg(long, default_value = "04:00:00")]
    time: String,
    /// Memory per task, in Slurm's format (8G, 8000M; default: the cluster's). A task holds its
    /// run's buffers and networks and, while it evaluates, each search's own bound
    /// (`--memory-limit`, 4 GiB unless the study says otherwise) and half as much again of
    /// remembered successors.
    #[arg(long, value_name = "SIZE")]
    mem: Option<String>,
    /// Cores per task; the task's libtorch threads follow them.
    #[arg(long, default_value_t = 2)]
    cpus_per_task: u64,
    /// At most this many tasks at once (the array's %M throttle).
    #[arg(long)]
    max_parallel: Option<u64>,
    /// Where each task's networks train and evaluate: cpu, or cuda for the GPU Slurm gives the
    /// task (the script then asks for one GPU per task, `--gres=gpu:1`).
    #[arg(long, default_value = "cpu")]
    device: ComputeDevice,
    /// The seads binary the tasks run (default: this one; it must be reachable from the nodes).
    #[arg(long)]
    seads: Option<PathBuf>,
    /// One array task per population of up to K compatible runs (see `seads sweep run
    /// --population`) instead of one per run.
    #[arg(long, value_name = "K")]
    population: Option<u64>,
    /// Submit the array and the report job with sbatch, and print their job ids.
    #[arg(long)]
    submit: bool,
    /// Let the tasks train with a binary built from a working tree with uncommitted changes
    /// (refused by default; see `seads sweep run --allow-dirty`; or SEADS_ALLOW_DIRTY=1).
    #[arg(long)]
    allow_dirty: bool,
    /// Let the tasks train although the sweep was planned by a binary of another commit
    /// (refused by default; see `seads sweep run --allow-other-commit`).
    #[arg(long)]
    allow_other_commit: bool,
}

/// Arguments of `seads sweep status`.
#[derive(Debug, Args)]
pub struct StatusArgs {
    /// The sweep directory.
    dir: PathBuf,
    /// Print JSON.
    #[arg(long)]
    json: bool,
}

/// Arguments of `seads sweep restore`.
#[derive(Debug, Args)]
pub struct RestoreArgs {
    /// The committed sweep (its sweep.json, manifest.toml and finished runs' data).
    committed: PathBuf,
    /// The sweep directory to create (it must not exist).
    #[arg(long)]
    out: PathBuf,
    /// Plan it with this binary although the sweep was planned by another commit (its runs
    /// would then mix code versions).
    #[arg(long)]
    allow_other_commit: bool,
}

/// Runs `seads sweep restore`.
fn restore(args: RestoreArgs) -> Result<()> {
    let restored = seads_study::sweep::restore(
        &args.committed,
        &args.out,
        crate::build().commit,
        args.allow_other_commit,
    )
    .map_err(crate::study_error)?;
    outln!(
        "laid out {}: {} runs, {} copied in from {} (no checkpoints), {} to train",
        args.out.display(),
        restored.runs,
        restored.copied,
        args.committed.display(),
        restored.runs - restored.copied
    );
    for dir in &restored.departures {
        outln!(
            "  {dir}: trained with another configuration than today's plan (kept as it trained)"
        );
    }
    Ok(())
}

/// Runs `seads sweep …`.
pub fn run(command: SweepCommand) -> Result<()> {
    match command {
        SweepCommand::Plan(args) => plan(args),
        SweepCommand::Restore(args) => restore(args),
        SweepCommand::Run(args) => {
            crate::build()
                .allows_study(allow_dirty(args.allow_dirty)?)
                .map_err(crate::study_error)?;
            allows_commit(&args.dir, args.allow_other_commit)?;
            let cores = match args.cores {
                Some(c) => thread_count("--cores", c)?,
                None => cores(),
            };
            let workers = match args.workers {
                Some(w) => thread_count("--workers", w)?,
                None => (cores / 2).max(1),
            };
            let population = args
                .population
                .map(|k| at_least_one("--population", k))
                .transpose()?;
            pool::run_sweep(
                &args.dir,
                args.seeds.as_ref().map(|s| s.0.as_slice()),
                pool::Workers {
                    workers,
                    cores,
                    population,
                },
                crate::usable_device(args.device)?,
                args.quiet,
            )
        }
        SweepCommand::Task(args) => {
            crate::build()
                .allows_study(allow_dirty(args.allow_dirty)?)
                .map_err(crate::study_error)?;
            allows_commit(&args.dir, args.allow_other_commit)?;
            // `seads sweep run` looked at the run an instant ago and found it free: if another
            // task holds it now, it took it meanwhile, and the child leaves it to that one.
            let patience = if args.child {
                die_with_parent();
                Duration::from_secs(2)
            } else {
                Duration::from_secs(args.wait)
            };
            let cores = thread_count("--cores", args.cores)?;
            let device = crate::usable_device(args.device)?;
            // The task's threads: rayon's (environments, the planner) as libtorch's.
            rayon::ThreadPoolBuilder::new()
                .num_threads(cores)
                .build_global()
                .context("starting the task's threads")?;
            let indices: Vec<usize> = args.index.0.iter().map(|&i| i as usize).collect();
            let result = task::run_task(&args.dir, &indices, cores, device, patience);
            // Run by hand, a population whose member another task holds is the user's to fix.
            match result {
                Err(e) if !args.child && indices.len() > 1 && is_taken(&e) => {
                    Err(BadInput(e.context("a member belongs to another population's task")).into())
                }
                other => other,
            }
        }
        SweepCommand::Slurm(args) => slurm(args),
        SweepCommand::Status(args) => status(args),
    }
}

fn plan(args: PlanArgs) -> Result<()> {
    let text = std::fs::read_to_string(&args.manifest)
        .map_err(|e| BadInput(anyhow!("reading {}: {e}", args.manifest.display())))?;
    let manifest =
        Manifest::parse(&text, &args.manifest.display().to_string()).map_err(crate::bad_input)?;
    let planned = Sweep::plan(&manifest, &text, &args.out, Some(crate::build().commit))
        .map_err(crate::bad_input)?;
    if planned.created == 0 {
        outln!(
            "sweep {:?} in {} is already planned ({} runs); nothing changed",
            manifest.name,
            args.out.display(),
            planned.runs
        );
    } else {
        outln!(
            "planned sweep {:?}: {} runs ({} new) in {}",
            manifest.name,
            planned.runs,
            planned.created,
            args.out.display()
        );
        outln!(
            "next: seads sweep run {}   or   seads sweep slurm {} --submit",
            args.out.display(),
            args.out.display()
        );
    }
    Ok(())
}

fn slurm(args: SlurmArgs) -> Result<()> {
    let dir = std::fs::canonicalize(&args.dir).map_err(|_| {
        BadInput(anyhow!(
            "sweep directory {} does not exist",
            args.dir.display()
        ))
    })?;
    let sweep = Sweep::load(&dir).map_err(crate::bad_input)?;
    let populations = match args.population {
        Some(k) => {
            let all: Vec<usize> = (0..sweep.runs.len()).collect();
            let k = at_least_one("--population", k)?;
            Some(seads_study::sweep::populations(&dir, &sweep, &all, k)?)
        }
        None => None,
    };
    let tasks = populations.as_ref().map_or(sweep.runs.len(), Vec::len);
    let seads = match args.seads {
        Some(path) => std::fs::canonicalize(&path)
            .map_err(|_| BadInput(anyhow!("--seads {} does not exist", path.display())))?,
        None => std::env::current_exe().context("locating the seads binary")?,
    };
    let options = slurm::SlurmOptions {
        partition: args.partition,
        time: args.time,
        mem: args.mem,
        cpus_per_task: at_least_one("--cpus-per-task", args.cpus_per_task)?,
        max_parallel: args
            .max_parallel
            .map(|m| at_least_one("--max-parallel", m))
            .transpose()?,
        seads,
        device: args.device,
        populations,
        allow_dirty: allow_dirty(args.allow_dirty)?,
        allow_other_commit: args.allow_other_commit,
    };
    let (array, report) =
        slurm::write_scripts(&dir, &sweep, &options).map_err(crate::study_error)?;
    outln!("wrote {} and {}", array.display(), report.display());
    if args.submit {
        let (array_id, report_id) = slurm::submit(&array, &report)?;
        outln!("submitted job array {array_id} ({tasks} tasks) and report job {report_id}");
        outln!("follow with: seads sweep status {}", dir.display());
    } else {
        outln!(
            "submit with: sbatch {}, then sbatch --dependency=afterany:<array id> {}",
            array.display(),
            report.display()
        );
    }
    Ok(())
}

fn status(args: StatusArgs) -> Result<()> {
    let sweep = Sweep::load(&args.dir).map_err(crate::bad_input)?;
    let overview = Overview::read(&args.dir, &sweep)?;
    if args.json {
        outln!("{}", serde_json::to_string(&overview)?);
    } else {
        outln!("{}", overview.table());
    }
    Ok(())
}

/// Refuses to train the runs of the sweep in `dir` with this binary if another commit planned
/// the sweep, unless `allow_other` (bad input, naming both commits); a sweep that cannot be read
/// is left to the command, which says why.
fn allows_commit(dir: &std::path::Path, allow_other: bool) -> Result<()> {
    match Sweep::load(dir) {
        Ok(sweep) => sweep
            .allows_commit(crate::build().commit, allow_other)
            .map_err(crate::study_error),
        Err(_) => Ok(()),
    }
}

/// The environment variable that allows a study to train with a binary built from a working tree
/// with uncommitted changes, as `--allow-dirty` does.
const ALLOW_DIRTY_VAR: &str = "SEADS_ALLOW_DIRTY";

/// Whether a study may train with a dirty binary: `--allow-dirty` (`flag`), or
/// [`ALLOW_DIRTY_VAR`] set to a true value; a value that is no boolean is bad input naming the
/// variable.
fn allow_dirty(flag: bool) -> Result<bool> {
    // The variable is checked even beside the flag: a bad value is never silently ignored.
    let variable = crate::env_flag(ALLOW_DIRTY_VAR)?;
    Ok(flag || variable)
}

/// Whether `e` says that another task holds a run.
pub fn is_taken(e: &anyhow::Error) -> bool {
    e.chain().any(|c| {
        matches!(
            c.downcast_ref::<seads_study::StudyError>(),
            Some(seads_study::StudyError::Taken(_))
        )
    })
}

/// A task started by `seads sweep run` is killed when that process dies, however it dies, so
/// that a killed sweep leaves no orphan training on.
fn die_with_parent() {
    #[cfg(target_os = "linux")]
    #[allow(unsafe_code)]
    // SAFETY: prctl(PR_SET_PDEATHSIG) only sets a flag of this process; the arguments are valid
    // constants. Called before any other thread is started.
    unsafe {
        libc::prctl(libc::PR_SET_PDEATHSIG, libc::SIGKILL);
    }
    // The parent may have died before the flag was set.
    #[cfg(unix)]
    if std::os::unix::process::parent_id() == 1 {
        std::process::exit(1);
    }
}
