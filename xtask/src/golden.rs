//! `cargo xtask golden`: does this processor give the committed golden run?
//!
//! The golden (`data/golden/`) is the first 300 epochs of the demo's configuration with portable
//! numerics, evaluated every 10 epochs, as one processor trained it (its `provenance.jsonl`
//! names it). The command builds the release binary, trains the same configuration, and compares
//! every metrics line up to epoch 300 field by field, clock fields left out. It names the first
//! line and field that differ, so that a processor that parts from the golden shows when. It
//! then compares the fingerprint of the floating-point primitives a run uses (the seads-rl
//! example `numerics_fingerprint`) with the golden's, to show which. CI checks the first 100
//! epochs (`data/golden/first-100.jsonl`, the seads-cli test
//! `the_golden_runs_first_100_epochs_repeat_line_for_line`); this command checks all 300.

use std::path::Path;

use anyhow::{Context, Result, bail};
use serde_json::Value;

use crate::step;

/// The last epoch compared.
const EPOCHS: u64 = 300;

/// Fields that measure the clock, not the run.
const CLOCK: [&str; 3] = ["wall_s", "steps_per_s", "timings"];

/// Trains the golden configuration and compares it with the golden (`record`: writes the new
/// run as the golden instead).
pub fn run(root: &Path, record: bool) -> Result<()> {
    let golden = root.join("data/golden");
    step(
        "cargo",
        &["build", "--release", "--quiet", "-p", "seads-cli"],
    )?;
    let out = root.join("target/golden-run");
    if out.exists() {
        std::fs::remove_dir_all(&out).with_context(|| format!("removing {}", out.display()))?;
    }
    let seads = root.join("target/release/seads");
    let config = golden.join("config.toml");
    step(
        seads.to_str().context("a UTF-8 path")?,
        &[
            "train",
            "--config",
            config.to_str().context("a UTF-8 path")?,
            "--out",
            out.to_str().context("a UTF-8 path")?,
            "--quiet",
        ],
    )?;
    let this = processor(&out)?;
    let fingerprint = fingerprint(root)?;
    if record {
        for file in ["metrics.jsonl", "provenance.jsonl"] {
            std::fs::copy(out.join(file), golden.join(file))
                .with_context(|| format!("copying {file} into {}", golden.display()))?;
        }
        let path = golden.join("fingerprint.json");
        std::fs::write(&path, serde_json::to_string_pretty(&fingerprint)? + "\n")
            .with_context(|| format!("writing {}", path.display()))?;
        println!("golden: recorded on {this}");
        return Ok(());
    }
    let path = golden.join("fingerprint.json");
    let text =
        std::fs::read_to_string(&path).with_context(|| format!("reading {}", path.display()))?;
    let theirs: Value = serde_json::from_str(&text)?;
    let parted = parted_primitives(&fingerprint, &theirs);
    if parted.is_empty() {
        println!("golden: every primitive of the fingerprint equals the golden's");
    } else {
        println!(
            "golden: primitives that differ from the golden's: {}",
            parted.join(", ")
        );
    }
    let ours = lines(&out.join("metrics.jsonl"))?;
    let theirs = lines(&golden.join("metrics.jsonl"))?;
    let golden_processor = processor(&golden)?;
    match first_difference(&ours, &theirs) {
        None => {
            println!(
                "golden: {} metrics lines up to epoch {EPOCHS} equal the golden's ({golden_processor}) on {this}",
                theirs.len()
            );
            Ok(())
        }
        Some(difference) => bail!(
            "golden: this processor ({this}) parts from the golden ({golden_processor}): {difference}"
        ),
    }
}

/// The fingerprint of this machine's floating-point primitives (a JSON object: name → CRC).
fn fingerprint(root: &Path) -> Result<Value> {
    let args = [
        "run",
        "--release",
        "--quiet",
        "-p",
        "seads-rl",
        "--example",
        "numerics_fingerprint",
    ];
    eprintln!("xtask: $ cargo {}", args.join(" "));
    let output = std::process::Command::new("cargo")
        .args(args)
        .current_dir(root)
        .output()
        .context("could not start cargo")?;
    if !output.status.success() {
        bail!(
            "the fingerprint failed: {}",
            String::from_utf8_lossy(&output.stderr)
        );
    }
    serde_json::from_slice(&output.stdout).context("the fingerprint's JSON")
}

/// The primitives whose fingerprints differ (or that only one side has).
fn parted_primitives(ours: &Value, theirs: &Value) -> Vec<String> {
    let empty = serde_json::Map::new();
    let (a, b) = (
        ours.as_object().unwrap_or(&empty),
        theirs.as_object().unwrap_or(&empty),
    );
    let mut names: Vec<&String> = a.keys().chain(b.keys()).collect();
    names.sort();
    names.dedup();
    names
        .into_iter()
        .filter(|n| a.get(n.as_str()) != b.get(n.as_str()))
        .cloned()
        .collect()
}

/// The metrics lines of a run up to [`EPOCHS`], without their clock fields.
fn lines(path: &Path) -> Result<Vec<Value>> {
    metrics_without_clock(path, EPOCHS)
}

/// The metrics lines of `path` up to epoch `last`, without their clock fields.
pub fn metrics_without_clock(path: &Path, last: u64) -> Result<Vec<Value>> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    let mut out = Vec::new();
    for line in text.lines() {
        let mut value: Value = serde_json::from_str(line)
            .with_context(|| format!("a metrics line of {}", path.display()))?;
        if value["epoch"].as_u64().is_some_and(|e| e > last) {
            break;
        }
        if let Some(object) = value.as_object_mut() {
            for field in CLOCK {
                object.remove(field);
            }
        }
        out.push(value);
    }
    Ok(out)
}

/// The first line and field in which `ours` differs from `theirs`, in words.
fn first_difference(ours: &[Value], theirs: &[Value]) -> Option<String> {
    for (a, b) in ours.iter().zip(theirs) {
        if a != b {
            let fields = a.as_object().into_iter().flatten();
            let field = fields
                .filter(|(k, v)| b.get(k.as_str()) != Some(v))
                .map(|(k, v)| format!("{k} {v} (golden {})", b[k.as_str()]))
                .collect::<Vec<_>>()
                .join(", ");
            return Some(format!("first at epoch {}: {field}", b["epoch"]));
        }
    }
    (ours.len() != theirs.len()).then(|| {
        format!(
            "{} metrics lines, the golden has {}",
            ours.len(),
            theirs.len()
        )
    })
}

/// The processor of a run's first training process (`provenance.jsonl`).
fn processor(dir: &Path) -> Result<String> {
    let path = dir.join("provenance.jsonl");
    let text =
        std::fs::read_to_string(&path).with_context(|| format!("reading {}", path.display()))?;
    let first: Value = serde_json::from_str(text.lines().next().unwrap_or_default())
        .with_context(|| format!("reading {}", path.display()))?;
    Ok(format!(
        "{} {}, AVX-512 {}",
        first["cpu_vendor"].as_str().unwrap_or("?"),
        first["cpu_model"].as_str().unwrap_or("?"),
        first["avx512"]
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_first_difference_names_its_epoch_and_field() {
        let line = |epoch: u64, coverage: f64| serde_json::json!({"epoch": epoch, "skill_coverage": coverage, "env_steps": 10});
        let golden = [line(10, 1.0), line(20, 2.0)];
        assert_eq!(first_difference(&golden, &golden), None);
        let parted = [line(10, 1.0), line(20, 2.5)];
        assert_eq!(
            first_difference(&parted, &golden).unwrap(),
            "first at epoch 20: skill_coverage 2.5 (golden 2.0)"
        );
        assert!(
            first_difference(&golden[..1], &golden)
                .unwrap()
                .contains("1 metrics lines")
        );
    }
}
