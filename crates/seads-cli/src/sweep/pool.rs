//! `seads sweep run`: every run of a sweep that is not done, on this machine, by a few workers.
//! Each run is a child process (`seads sweep task`), because libtorch's thread count and
//! kernels are per process; its output goes to the run's `task.log`. The children die with
//! the parent, so killing `seads sweep run` and starting it again resumes every run.

use std::path::Path;
use std::process::{Command, Stdio};
use std::sync::Mutex;
use std::time::Duration;

use anyhow::{Context, Result, bail};
use seads_rl::ComputeDevice;

use super::index::Sweep;
use super::state::{LOG, Status, TAKEN_EXIT, note_population_log, status};
use seads_study::sweep::overview::tally;

/// What a worker reports for a run: whether its task succeeded, or `None` when another task
/// had taken or finished the run by the time a worker came to it.
struct Finished {
    index: usize,
    ok: Option<bool>,
}

/// How a sweep's runs are spread over this machine.
pub struct Workers {
    /// Tasks at once.
    pub workers: usize,
    /// Cores they share.
    pub cores: usize,
    /// Runs trained together in one task, at most (`None`: one run per task).
    pub population: Option<usize>,
}

/// Runs the sweep in `dir` (only the runs of `seeds`, if given) with parallel tasks sharing the
/// cores, their networks on `device`.
pub fn run_sweep(
    dir: &Path,
    seeds: Option<&[u64]>,
    Workers {
        workers,
        cores,
        population,
    }: Workers,
    device: ComputeDevice,
    quiet: bool,
) -> Result<()> {
    let sweep = Sweep::load(dir).map_err(crate::bad_input)?;
    let chosen = sweep.runs_of_seeds(seeds).map_err(crate::study_error)?;
    let mut todo = Vec::new();
    let mut skipped_running = 0;
    let mut copied = 0;
    for &i in &chosen {
        let run = sweep.run_dir(dir, i)?;
        match status(&run)?.0 {
            Status::Done => {}
            Status::Copied => copied += 1,
            Status::Running => skipped_running += 1,
            Status::Damaged => {
                eprintln!(
                    "seads: {}: damaged, left alone: {}",
                    run.display(),
                    super::state::damage(&run).unwrap_or_default()
                );
            }
            Status::Failed | Status::Pending => {
                if sweep.ensure_run_dir(dir, i)?.1 {
                    eprintln!("seads: {}: was deleted; planned again", run.display());
                }
                todo.push(i);
            }
        }
    }
    // Runs already begun resume before new ones start (a restarted sweep finishes what it had
    // begun first).
    let run_dirs: Vec<_> = sweep.runs.iter().map(|r| dir.join(&r.dir)).collect();
    let todo = seads_study::sweep::begun_first(&run_dirs, &todo);
    let listed = todo.len();
    let todo: Vec<Vec<usize>> = match population {
        Some(k) => seads_study::sweep::populations(dir, &sweep, &todo, k)?,
        None => todo.into_iter().map(|i| vec![i]).collect(),
    };
    let workers = workers.max(1);
    let per_task = (cores / workers).max(1);
    let of_seeds = seeds.map_or(String::new(), |_| {
        format!(", {} with the chosen seeds", chosen.len())
    });
    let of_copied = if copied > 0 {
        format!(", {copied} copied in without checkpoints (reported as they are)")
    } else {
        String::new()
    };
    outln!(
        "sweep {:?}: {} runs{of_seeds}, {listed} to train or resume{}, {skipped_running} running elsewhere{of_copied}; {workers} worker(s) × {per_task} core(s)",
        sweep.name,
        sweep.runs.len(),
        population.map_or(String::new(), |_| format!(
            " in {} population(s)",
            todo.len()
        )),
    );
    let total: u64 = chosen
        .iter()
        .map(|&i| {
            let run = dir.join(&sweep.runs[i].dir);
            seads_rl::load_config(&run).map_or(0, |c| c.env_steps)
        })
        .sum();
    let template = "{elapsed_precise} [{bar:30}] {percent}% of all steps, eta {eta} {msg}";
    let bar = crate::progress_bar(total, quiet, template);
    let exe = std::env::current_exe().context("locating the seads binary")?;
    let queue = Mutex::new(todo.into_iter());
    let finished = Mutex::new(Vec::<Finished>::new());
    let mut failures = Vec::new();
    std::thread::scope(|scope| -> Result<()> {
        let mut handles = Vec::new();
        for _ in 0..workers {
            handles.push(scope.spawn(|| -> Result<()> {
                loop {
                    let next = queue.lock().expect("queue lock").next();
                    let Some(mut members) = next else {
                        return Ok(());
                    };
                    // Another `sweep run` (or a Slurm task) may have taken or finished a run
                    // since this one listed it: leave it to that one.
                    let mut free = Vec::new();
                    for index in members.drain(..) {
                        let run = dir.join(&sweep.runs[index].dir);
                        if matches!(
                            status(&run)?.0,
                            Status::Running | Status::Done | Status::Copied | Status::Damaged
                        ) {
                            let mut finished = finished.lock().expect("finished lock");
                            finished.push(Finished { index, ok: None });
                        } else {
                            free.push(index);
                        }
                    }
                    let Some(&index) = free.first() else { continue };
                    let run = dir.join(&sweep.runs[index].dir);
                    let list: Vec<String> = free.iter().map(usize::to_string).collect();
                    // A population's output goes to its first member's log.
                    let others: Vec<_> = free[1..]
                        .iter()
                        .map(|&o| dir.join(&sweep.runs[o].dir))
                        .collect();
                    note_population_log(&others, &list.join(","), &run.join(LOG))?;
                    let log = std::fs::OpenOptions::new()
                        .create(true)
                        .append(true)
                        .open(run.join(LOG))
                        .with_context(|| format!("opening {}", run.join(LOG).display()))?;
                    let exit = Command::new(&exe)
                        .args(["sweep", "task"])
                        .arg(dir)
                        .args(["--index", &list.join(",")])
                        .args(["--cores", &per_task.to_string(), "--child"])
                        .args(["--device", &device.to_string()])
                        // The same binary, whose build `sweep run` has already checked.
                        .arg("--allow-dirty")
                        .stdin(Stdio::null())
                        .stdout(log.try_clone()?)
                        .stderr(log)
                        .status()
                        .with_context(|| format!("starting the task of {}", run.display()))?;
                    let ok = match exit.code() {
                        Some(code) if code == i32::from(TAKEN_EXIT) => None,
                        _ => Some(exit.success()),
                    };
                    let mut finished = finished.lock().expect("finished lock");
                    for &index in &free {
                        // A failed population: each member's task.json says how it ended.
                        let ok = match ok {
                            Some(false) if free.len() > 1 => Some(matches!(
                                status(&dir.join(&sweep.runs[index].dir))?.0,
                                Status::Done
                            )),
                            other => other,
                        };
                        finished.push(Finished { index, ok });
                    }
                }
            }));
        }
        // The bar follows the runs' own files until every worker has finished.
        while handles.iter().any(|h| !h.is_finished()) {
            let (position, message) = tally(dir, &sweep, &chosen);
            bar.set_position(position);
            bar.set_message(message);
            std::thread::sleep(Duration::from_millis(if quiet { 5000 } else { 1000 }));
        }
        for handle in handles {
            handle.join().expect("a worker panicked")?;
        }
        Ok(())
    })?;
    bar.finish_and_clear();
    for f in finished.into_inner().expect("finished lock") {
        let run = dir.join(&sweep.runs[f.index].dir);
        match f.ok {
            None => outln!(
                "elsewhere {} (taken by another task meanwhile)",
                run.display()
            ),
            Some(true) => outln!("done    {}", run.display()),
            Some(false) => {
                outln!(
                    "failed  {} (see {})",
                    run.display(),
                    run.join(LOG).display()
                );
                failures.push(run);
            }
        }
    }
    if !failures.is_empty() {
        bail!(
            "{} run(s) failed; `seads sweep status {}` lists them, their task.log says why",
            failures.len(),
            dir.display()
        );
    }
    match seeds {
        None => outln!("sweep {:?} complete", sweep.name),
        Some(_) => outln!("sweep {:?}: the chosen seeds are complete", sweep.name),
    }
    Ok(())
}
