//! Trains SEADS from a preset and writes the joint relabellings of chosen epochs as JSON Lines:
//! the clipped log-posteriors, the labels in and the labels out. The input of the label-tie study
//! (`scripts/analysis/label_ties.py` solves the same problems with SciPy).
//!
//! ```sh
//! cargo run --release -p seads-rl --example relabel_dump -- \
//!     --env lightsout-cursor --skills 30 --seed 1 --env-steps 250000 --every 250 --out dump.jsonl
//! ```
//!
//! Each line: `{"epoch", "batch" ("skill_model" | "sac"), "k", "labels", "relabelled", "clipped"}`,
//! `clipped` row-major, `k` values per chosen episode.
#![allow(clippy::print_stdout, clippy::print_stderr)] // an example prints

use std::io::Write;
use std::path::PathBuf;
use std::sync::{Arc, Mutex};

use anyhow::{Context, Result, bail};
use seads_rl::{RelabelBatch, TrainConfig, Trainer};

struct Args {
    env: String,
    skills: Option<usize>,
    seed: u64,
    env_steps: u64,
    every: u64,
    out: PathBuf,
}

fn parse() -> Result<Args> {
    let mut args = Args {
        env: "lightsout-cursor".into(),
        skills: None,
        seed: 1,
        env_steps: 250_000,
        every: 250,
        out: PathBuf::from("relabel-dump.jsonl"),
    };
    let mut it = std::env::args().skip(1);
    while let Some(flag) = it.next() {
        let value = it.next().with_context(|| format!("{flag} needs a value"))?;
        match flag.as_str() {
            "--env" => args.env = value,
            "--skills" => args.skills = Some(value.parse()?),
            "--seed" => args.seed = value.parse()?,
            "--env-steps" => args.env_steps = value.parse()?,
            "--every" => args.every = value.parse()?,
            "--out" => args.out = value.into(),
            _ => bail!("unknown option {flag}"),
        }
    }
    if args.every == 0 {
        bail!("--every must be at least 1");
    }
    Ok(args)
}

fn main() -> Result<()> {
    let args = parse()?;
    let mut config = TrainConfig::preset(&args.env)?;
    config.seed = args.seed;
    config.env_steps = args.env_steps;
    if args.skills.is_some() {
        config
            .edit(|s: &mut seads_rl::SeadsConfig| s.num_skills = args.skills)
            .unwrap();
    }
    let mut trainer = Trainer::new(config)?;
    // The observer runs on the calling thread of `run_epoch`; it records only chosen epochs.
    let epoch = Arc::new(Mutex::new(0u64));
    let lines: Arc<Mutex<Vec<String>>> = Arc::default();
    {
        let (epoch, lines, every) = (Arc::clone(&epoch), Arc::clone(&lines), args.every);
        trainer.observe_relabelling(Box::new(move |r| {
            let e = *epoch.lock().expect("epoch lock");
            if e == 0 || e % every != 0 {
                return;
            }
            let batch = match r.batch {
                RelabelBatch::SkillModel => "skill_model",
                RelabelBatch::Sac => "sac",
            };
            let line = serde_json::json!({
                "epoch": e,
                "batch": batch,
                "k": r.k,
                "labels": r.labels,
                "relabelled": r.relabelled,
                "clipped": r.clipped,
            });
            lines.lock().expect("lines lock").push(line.to_string());
        }));
    }
    let mut file = std::io::BufWriter::new(
        std::fs::File::create(&args.out)
            .with_context(|| format!("creating {}", args.out.display()))?,
    );
    while !trainer.finished() {
        *epoch.lock().expect("epoch lock") = trainer.epoch();
        trainer.run_epoch()?;
        for line in lines.lock().expect("lines lock").drain(..) {
            writeln!(file, "{line}")?;
        }
        if trainer.epoch() % 500 == 0 {
            eprintln!(
                "epoch {} steps {} coverage {:.2}",
                trainer.epoch(),
                trainer.env_steps(),
                trainer.skill_coverage()?
            );
        }
    }
    file.flush()?;
    Ok(())
}
