//! The report's interval estimates against rliable 1.2 on committed studies
//! (`data/reference/rliable/intervals.json`, made by `scripts/reference/rliable_intervals.py`):
//! the IQM, the mean, the probability of improvement and the run score distribution exactly, the
//! bootstrap intervals within bootstrap error (measured on our own bootstrap over several
//! streams); and the report takes the same runs' values.

use std::path::{Path, PathBuf};

use seads_study::report::intervals::{
    Interval, bootstrap, improvement_interval, iqm, mean, probability_of_improvement, share_above,
};
use serde_json::Value;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn reference() -> Value {
    let path = root().join("data/reference/rliable/intervals.json");
    let text = std::fs::read_to_string(&path).expect("the rliable reference");
    serde_json::from_str(&text).expect("JSON")
}

fn numbers(v: &Value) -> Vec<f64> {
    v.as_array()
        .expect("an array")
        .iter()
        .map(|x| x.as_f64().expect("a number"))
        .collect()
}

fn close(ours: f64, theirs: f64, tolerance: f64, what: &str) {
    assert!(
        (ours - theirs).abs() <= tolerance,
        "{what}: ours {ours}, rliable's {theirs} (tolerance {tolerance})"
    );
}

/// Streams of our own bootstrap that measure its error: an interval's ends vary from stream to
/// stream (most where a resampled statistic has an atom near the 2.5 % or 97.5 % point, e.g. a
/// probability of improvement of 1 in 2.6 % of the resamples).
const STREAMS: usize = 8;

/// Checks that rliable's interval `theirs` lies within bootstrap error of ours: each end within
/// the range of that end over [`STREAMS`] of our bootstraps (`interval(key)` for key 0, 1, …),
/// widened by `step`, the statistic's spacing on these runs.
fn within_bootstrap_error(
    interval: impl Fn(usize) -> Interval,
    theirs: &[f64],
    step: f64,
    what: &str,
) {
    let ours: Vec<Interval> = (0..STREAMS).map(interval).collect();
    for (end, their, pick) in [
        (
            "low",
            theirs[0],
            (|i: &Interval| i.low) as fn(&Interval) -> f64,
        ),
        ("high", theirs[1], |i: &Interval| i.high),
    ] {
        let ends: Vec<f64> = ours.iter().map(pick).collect();
        let (lo, hi) = (
            ends.iter().copied().fold(f64::INFINITY, f64::min),
            ends.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        );
        assert!(
            lo - step <= their && their <= hi + step,
            "{what} {end}: rliable's {their}, ours {lo} to {hi} over {STREAMS} streams (± {step})"
        );
    }
}

/// The spacing of a mean of `values`' resamples: the least gap between two distinct values over
/// their count (a resample's mean moves by at least that when one draw changes).
fn mean_step(values: &[f64]) -> f64 {
    let mut sorted = values.to_vec();
    sorted.sort_by(f64::total_cmp);
    let gap = sorted
        .windows(2)
        .map(|w| w[1] - w[0])
        .filter(|g| *g > 1e-12)
        .fold(f64::INFINITY, f64::min);
    if gap.is_finite() {
        gap / values.len() as f64 + 1e-9
    } else {
        1e-9
    }
}

#[test]
fn estimates_and_intervals_match_rliable_on_committed_studies() {
    let reference = reference();
    let cells = reference["cells"].as_array().expect("cells");
    let taus = numbers(&reference["taus"]);
    assert!(cells.len() >= 20, "{} cells", cells.len());
    let mut improvements = 0;
    for cell in cells {
        let what = format!("{} {} {}", cell["study"], cell["env"], cell["variant"]);
        let values = numbers(&cell["values"]);
        let step = mean_step(&values);
        let q = bootstrap(&values, iqm, &format!("iqm {what}")).expect("an IQM");
        close(
            q.estimate,
            cell["iqm"].as_f64().unwrap(),
            1e-12,
            &format!("{what} IQM"),
        );
        within_bootstrap_error(
            |k| bootstrap(&values, iqm, &format!("iqm {what} {k}")).unwrap(),
            &numbers(&cell["iqm_ci"]),
            step,
            &format!("{what} IQM"),
        );
        let m = bootstrap(&values, |v| Some(mean(v)), &format!("mean {what}")).expect("a mean");
        close(
            m.estimate,
            cell["mean"].as_f64().unwrap(),
            1e-12,
            &format!("{what} mean"),
        );
        within_bootstrap_error(
            |k| bootstrap(&values, |v| Some(mean(v)), &format!("mean {what} {k}")).unwrap(),
            &numbers(&cell["mean_ci"]),
            step,
            &format!("{what} mean"),
        );
        for tau in &taus {
            let theirs = cell["profile"][tau.to_string().as_str()]
                .as_f64()
                .or_else(|| cell["profile"][format!("{tau:.1}").as_str()].as_f64())
                .expect("a profile point");
            close(
                share_above(&values, *tau),
                theirs,
                1e-12,
                &format!("{what} τ {tau}"),
            );
        }
        if let Some(theirs) = cell.get("improvement").and_then(Value::as_f64) {
            improvements += 1;
            let against = numbers(&cell["reference_values"]);
            close(
                probability_of_improvement(&values, &against).unwrap(),
                theirs,
                1e-12,
                &format!("{what} P(improvement)"),
            );
            // Its resamples move in steps of half a pair (a tie).
            let step = 0.5 / (values.len() * against.len()) as f64 + 1e-9;
            within_bootstrap_error(
                |k| improvement_interval(&values, &against, &format!("poi {what} {k}")).unwrap(),
                &numbers(&cell["improvement_ci"]),
                step,
                &format!("{what} P(improvement)"),
            );
        }
    }
    assert!(improvements >= 15, "{improvements} comparisons");
}

/// The report takes the same runs' values: its `intervals.csv` of the committed ten-seed study
/// holds rliable's IQM and mean of each cell's final coverage.
#[test]
fn the_report_of_a_committed_study_gives_rliables_estimates() {
    let reference = reference();
    let out = tempfile::tempdir().expect("a temporary folder");
    let sweep = root().join("docs/results/table1-ten/runs/table1-lightsout-ten");
    let options = seads_study::report::ReportOptions {
        inputs: vec![sweep],
        reference: None,
        copy_runs: false,
        repository: None,
    };
    seads_study::report::write_report(&options, out.path()).expect("the report");
    let csv = std::fs::read_to_string(out.path().join("intervals.csv")).expect("intervals.csv");
    let mut checked = 0;
    for cell in reference["cells"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|c| c["study"] == "table1-ten")
    {
        let (env, variant) = (
            cell["env"].as_str().unwrap(),
            cell["variant"].as_str().unwrap(),
        );
        let line = csv
            .lines()
            .find(|l| l.starts_with(&format!("{env},{variant},coverage,")))
            .unwrap_or_else(|| panic!("no coverage row of {env} {variant} in\n{csv}"));
        let fields: Vec<&str> = line.split(',').collect();
        let number = |i: usize| fields[i].parse::<f64>().expect("a number");
        assert_eq!(number(3) as usize, numbers(&cell["values"]).len());
        close(
            number(4),
            cell["iqm"].as_f64().unwrap(),
            1e-6,
            "the report's IQM",
        );
        close(
            number(7),
            cell["mean"].as_f64().unwrap(),
            1e-6,
            "the report's mean",
        );
        checked += 1;
    }
    assert_eq!(checked, 7, "the study's seven variants");
}
