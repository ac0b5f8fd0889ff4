//! `cargo xtask population-bench`: throughput of populations against the same runs one by one.
//!
//! For each population size K it plans two identical sweeps of K LightsOutCursor runs (seeds
//! 1…K, the preset's settings, a budget of `--steps` each, no evaluation by planning) and trains
//! one with `seads sweep task --index 0,…,K-1` (one population), the other run by run with
//! `seads sweep task --index i`, one after the other, with the same binary. Each side's summed
//! environment steps over its wall time is its throughput. It also says whether every member's
//! metrics equal its solo run's (clock fields left out): on the CPU they must.
//!
//! On a GPU machine, `--device cuda` trains the populations there while the solo runs stay on
//! the CPU with `--solo-cores` cores (1: the "one run on one CPU core"). The xtask binary
//! needs no cargo: with `--seads PATH` it runs a prebuilt seads (the GPU check carries both).

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

use anyhow::{Context, Result, bail};
use serde_json::{Value, json};

/// Options of the benchmark.
struct Options {
    sizes: Vec<usize>,
    steps: u64,
    cores: usize,
    solo_cores: usize,
    device: String,
    seads: Option<PathBuf>,
    out: PathBuf,
}

const USAGE: &str = "\
cargo xtask population-bench [--sizes 2,8] [--steps 20000] [--cores N] [--solo-cores N]
                             [--device cpu|cuda] [--seads PATH] [--out DIR]

Trains populations of K LightsOutCursor runs (seeds 1..K) against the same runs one by one and
writes DIR/population-bench.json (default DIR: target/population-bench). --cores: the cores of
a population and, by default, of each solo run (default: all); --solo-cores: the solo runs';
--device: where the populations' networks run; --seads: a prebuilt binary (default: build the
release binary).";

fn parse(args: &[String], root: &Path) -> Result<Options> {
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let mut options = Options {
        sizes: vec![2, 8],
        steps: 20_000,
        cores,
        solo_cores: 0,
        device: "cpu".into(),
        seads: None,
        out: root.join("target/population-bench"),
    };
    let mut args = args.iter();
    while let Some(flag) = args.next() {
        if flag == "--help" || flag == "-h" {
            println!("{USAGE}");
            std::process::exit(0);
        }
        let value = args
            .next()
            .with_context(|| format!("{flag} needs a value\n\n{USAGE}"))?;
        let number = |v: &str| -> Result<usize> {
            match v.parse::<usize>() {
                Ok(n) if n > 0 => Ok(n),
                _ => bail!("{flag} wants whole numbers above 0, got {v:?}"),
            }
        };
        match flag.as_str() {
            "--sizes" => {
                options.sizes = value.split(',').map(number).collect::<Result<_>>()?;
            }
            "--steps" => options.steps = number(value)? as u64,
            "--cores" => options.cores = number(value)?,
            "--solo-cores" => options.solo_cores = number(value)?,
            "--device" => options.device = value.clone(),
            "--seads" => options.seads = Some(PathBuf::from(value)),
            "--out" => options.out = PathBuf::from(value),
            other => bail!("unknown option {other:?}\n\n{USAGE}"),
        }
    }
    if options.solo_cores == 0 {
        options.solo_cores = options.cores;
    }
    Ok(options)
}

/// Runs the benchmark with the command-line `args`.
pub fn run(root: &Path, args: &[String]) -> Result<()> {
    let options = parse(args, root)?;
    let seads = match &options.seads {
        Some(path) => path.clone(),
        None => {
            crate::step(
                "cargo",
                &["build", "--release", "--quiet", "-p", "seads-cli"],
            )?;
            root.join("target/release/seads")
        }
    };
    if options.out.exists() {
        std::fs::remove_dir_all(&options.out)
            .with_context(|| format!("removing {}", options.out.display()))?;
    }
    std::fs::create_dir_all(&options.out)
        .with_context(|| format!("creating {}", options.out.display()))?;
    let mut rows = Vec::new();
    for &k in &options.sizes {
        let solo = plan(&seads, &options, k, "solo")?;
        let population = plan(&seads, &options, k, "population")?;
        let mut solo_wall = 0.0;
        for i in 0..k {
            solo_wall += task(&seads, &solo, &i.to_string(), options.solo_cores, "cpu")?;
        }
        let list: Vec<String> = (0..k).map(|i| i.to_string()).collect();
        let population_wall = task(
            &seads,
            &population,
            &list.join(","),
            options.cores,
            &options.device,
        )?;
        let (solo_steps, solo_metrics) = finals(&solo, k)?;
        let (population_steps, population_metrics) = finals(&population, k)?;
        let row = json!({
            "runs": k,
            "budget_per_run": options.steps,
            "cores": options.cores,
            "solo_cores": options.solo_cores,
            "device": options.device,
            "solo_steps": solo_steps,
            "solo_wall_s": solo_wall,
            "solo_steps_per_s": solo_steps as f64 / solo_wall,
            "population_steps": population_steps,
            "population_wall_s": population_wall,
            "population_steps_per_s": population_steps as f64 / population_wall,
            "ratio": (population_steps as f64 / population_wall) / (solo_steps as f64 / solo_wall),
            "members_equal_solo_runs": solo_metrics == population_metrics,
            "final_coverage": population_metrics.iter().map(|m| m.last().and_then(|l| l.get("skill_coverage").cloned())).collect::<Vec<_>>(),
        });
        println!(
            "population of {k}: {:.0} steps/s in {:.0} s; one by one: {:.0} steps/s in {:.0} s; ratio {:.2}; members equal solo runs: {}",
            row["population_steps_per_s"].as_f64().unwrap_or(0.0),
            population_wall,
            row["solo_steps_per_s"].as_f64().unwrap_or(0.0),
            solo_wall,
            row["ratio"].as_f64().unwrap_or(0.0),
            row["members_equal_solo_runs"]
        );
        rows.push(row);
    }
    let first = options.sizes.first().copied().unwrap_or(0);
    let cpu = processor(&options.out.join(format!("solo-{first}")));
    let report = json!({"cpu": cpu, "seads": seads.display().to_string(), "rows": rows});
    let path = options.out.join("population-bench.json");
    std::fs::write(&path, serde_json::to_string_pretty(&report)? + "\n")
        .with_context(|| format!("writing {}", path.display()))?;
    println!("wrote {}", path.display());
    Ok(())
}

/// Plans a sweep of `k` runs into `out/<name>-<k>`; returns its directory.
fn plan(seads: &Path, options: &Options, k: usize, name: &str) -> Result<PathBuf> {
    let dir = options.out.join(format!("{name}-{k}"));
    let manifest = options.out.join(format!("{name}-{k}.toml"));
    let text = format!(
        "name = \"population-bench\"\nenvironments = [\"lightsout-cursor\"]\nseeds = [{}]\n\n\
         [overrides]\nenv_steps = {}\n\n[evaluation]\nevery = 0\nlast = false\n\n\
         [[variant]]\nname = \"seads\"\n",
        (1..=k)
            .map(|s| s.to_string())
            .collect::<Vec<_>>()
            .join(", "),
        options.steps
    );
    std::fs::write(&manifest, text).with_context(|| format!("writing {}", manifest.display()))?;
    let status = Command::new(seads)
        .args(["sweep", "plan"])
        .arg(&manifest)
        .arg("--out")
        .arg(&dir)
        .stdout(std::process::Stdio::null())
        .status()
        .with_context(|| format!("running {}", seads.display()))?;
    if !status.success() {
        bail!("planning {} failed", dir.display());
    }
    Ok(dir)
}

/// Runs `seads sweep task DIR --index INDICES`; returns its wall time in seconds.
fn task(seads: &Path, dir: &Path, indices: &str, cores: usize, device: &str) -> Result<f64> {
    eprintln!("xtask: training runs {indices} of {}", dir.display());
    let start = Instant::now();
    let output = Command::new(seads)
        .args(["sweep", "task"])
        .arg(dir)
        .args(["--index", indices, "--cores", &cores.to_string()])
        .args(["--device", device])
        // A speed measurement, not a study: a developer's build may have uncommitted changes
        // (its runs' provenance says so).
        .arg("--allow-dirty")
        .output()
        .with_context(|| format!("running {}", seads.display()))?;
    let wall = start.elapsed().as_secs_f64();
    if !output.status.success() {
        bail!(
            "training runs {indices} of {} failed: {}",
            dir.display(),
            String::from_utf8_lossy(&output.stderr)
        );
    }
    Ok(wall)
}

/// The summed final environment steps of the sweep's `k` runs, and each run's metrics without
/// their clock fields.
fn finals(dir: &Path, k: usize) -> Result<(u64, Vec<Vec<Value>>)> {
    let mut steps = 0;
    let mut all = Vec::new();
    for seed in 1..=k {
        let path = dir.join(format!(
            "runs/lightsout-cursor/seads/seed-{seed}/metrics.jsonl"
        ));
        let lines = crate::golden::metrics_without_clock(&path, u64::MAX)?;
        steps += lines
            .last()
            .and_then(|l| l.get("env_steps"))
            .and_then(Value::as_u64)
            .unwrap_or(0);
        all.push(lines);
    }
    Ok((steps, all))
}

/// The processor that trained the first run of the sweep in `dir`, as its provenance names it.
fn processor(dir: &Path) -> String {
    let path = dir.join("runs/lightsout-cursor/seads/seed-1/provenance.jsonl");
    std::fs::read_to_string(path)
        .ok()
        .and_then(|t| serde_json::from_str::<Value>(t.lines().next()?).ok())
        .and_then(|line| line["cpu_model"].as_str().map(str::to_owned))
        .unwrap_or_else(|| "unknown".into())
}
