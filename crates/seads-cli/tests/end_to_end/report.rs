//! `seads report` of single runs: damaged and unreadable runs, copies, CSVs and repositories.

use crate::common::*;

/// A repository the user names must exist and be one (issue 82: `--repository /nonexistent`
/// said "not checked" and exited 0); nothing is written.
#[test]
fn a_report_refuses_a_repository_that_is_not_one() {
    let dir = tempfile::tempdir().unwrap();
    let run = dir.path().join("run");
    copy_tiny_run(&run);
    let plain = dir.path().join("plain");
    std::fs::create_dir(&plain).unwrap();
    let out = dir.path().join("report");
    for repository in [dir.path().join("nonexistent"), plain] {
        check_bad_input(
            &[
                "report",
                s(&run),
                "--out",
                s(&out),
                "--repository",
                s(&repository),
            ],
            "is not a git repository",
        );
        assert!(!out.exists(), "nothing written");
    }
}

/// Reports never hide damage (issue 32): a run whose metrics start with a garbage line, or whose
/// evaluation file is garbage, or whose configuration cannot be read, is listed as damaged with
/// why and left out of the tables, not counted as "not started" or dropped without a word.
#[test]
fn a_report_lists_damaged_runs_with_why() {
    let dir = tempfile::tempdir().unwrap();
    let copy = |name: &str| {
        let to = dir.path().join(name);
        copy_tiny_run(&to);
        to
    };
    let (good, metrics, evaluation, config) = (
        copy("good"),
        copy("metrics"),
        copy("evaluation"),
        copy("config"),
    );
    let text = std::fs::read_to_string(metrics.join("metrics.jsonl")).unwrap();
    std::fs::write(metrics.join("metrics.jsonl"), format!("garbage\n{text}")).unwrap();
    std::fs::write(evaluation.join("evaluation-replan.json"), "{ not json").unwrap();
    std::fs::write(config.join("config.toml"), "env = 3").unwrap();
    let out = dir.path().join("report");
    let s = |p: &std::path::Path| p.to_str().unwrap().to_owned();
    let output = seads(&[
        "report",
        &s(&good),
        &s(&metrics),
        &s(&evaluation),
        &s(&config),
        "--out",
        &s(&out),
    ]);
    assert!(output.status.success(), "{output:?}");
    let md = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(
        md.contains("1 finished, 0 unfinished and 3 damaged"),
        "{md}"
    );
    for (run, why) in [
        (&metrics, "metrics.jsonl"),
        (&evaluation, "evaluation-replan.json"),
        (&config, "config.toml"),
    ] {
        let line = md
            .lines()
            .find(|l| l.starts_with("- damaged") && l.contains(&s(run)))
            .unwrap_or_else(|| panic!("{} is not listed as damaged:\n{md}", run.display()));
        assert!(line.contains(why), "{line}");
    }
    assert!(md.contains("| good |"), "{md}");
    assert!(
        !md.contains("| metrics |"),
        "a damaged run is in no table: {md}"
    );
}

/// A run named three times (twice, and through `./`) is one run of the report; a file given as a
/// run is said to be a file.
#[test]
fn a_run_given_twice_is_reported_once() {
    let dir = tempfile::tempdir().unwrap();
    let base = dir.path().join("base");
    copy_tiny_run(&base);
    let again = dir.path().join(".").join("base");
    let report = dir.path().join("report");
    seads_ok(&["report", s(&base), s(&base), s(&again), "--out", s(&report)]);
    let md = std::fs::read_to_string(report.join("report.md")).unwrap();
    assert!(md.contains("from 1 run(s): 1 finished"), "{md}");
    let file = base.join("config.toml");
    check_bad_input(
        &["report", s(&file), "--out", s(&dir.path().join("r2"))],
        "is a file",
    );
}

/// A run directory whose name holds a comma and a quote (`a,"b`) is its own variant in the
/// report; every CSV the report writes reads back with one field per column in every row.
#[test]
fn report_csvs_quote_names_with_commas() {
    let dir = tempfile::tempdir().unwrap();
    let odd = dir.path().join("a,\"b");
    copy_tiny_run(&odd);
    let report = dir.path().join("report");
    seads_ok(&["report", s(&odd), "--out", s(&report)]);
    let mut checked = 0;
    for entry in std::fs::read_dir(&report).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_none_or(|e| e != "csv") {
            continue;
        }
        let mut reader = csv::Reader::from_path(&path).unwrap();
        let columns = reader.headers().unwrap().len();
        let (mut rows, mut named) = (0, 0);
        for record in reader.records() {
            let record = record.unwrap_or_else(|e| panic!("{}: {e}", path.display()));
            assert_eq!(record.len(), columns, "{}: {record:?}", path.display());
            rows += 1;
            named += usize::from(record.iter().any(|f| f.contains("a,\"b")));
        }
        assert_eq!(named, rows, "{}: every row names the run", path.display());
        checked += usize::from(rows > 0);
    }
    assert!(checked >= 3, "{checked} CSV files with rows");
}

/// A run that is not there, a file or a link loop given as a run, a folder given as `--config`,
/// and a run whose `config.toml` is garbage or was edited since its checkpoint are the user's
/// input to fix: exit 2 and one line, whatever the command.
#[test]
fn runs_that_cannot_be_read_are_bad_input() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("missing");
    let file = dir.path().join("file");
    std::fs::write(&file, "not a run").unwrap();
    let looped = dir.path().join("loop");
    std::os::unix::fs::symlink(&looped, &looped).unwrap();
    for run in [&missing, &file, &looped] {
        check_bad_input(&["evaluate", "--run", s(run)], "loading run");
        check_bad_input(&["train", "--resume", s(run)], "loading run");
        check_bad_input(
            &["plot", "--run", s(run), "--out", s(&dir.path().join("f"))],
            "loading run",
        );
    }
    check_bad_input(
        &["train", "--config", s(dir.path()), "--out", s(&missing)],
        "reading",
    );
    let run = dir.path().join("run");
    copy_tiny_run(&run);
    let config = std::fs::read_to_string(run.join("config.toml")).unwrap();
    std::fs::write(run.join("config.toml"), "env = [").unwrap();
    check_bad_input(&["train", "--resume", s(&run)], "loading run");
    std::fs::write(
        run.join("config.toml"),
        config.replace("max_solution_depth = 5", "max_solution_depth = 4"),
    )
    .unwrap();
    check_bad_input(&["train", "--resume", s(&run)], "max_solution_depth");
}

/// `report --copy-runs` refuses, before writing anything, two runs that would be copied to one
/// place (both named `lo1`) and a report folder inside a run it copies; a run given as `..` is
/// copied under its own name.
#[test]
fn report_copies_never_collide_or_land_inside_a_run() {
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = (dir.path().join("a/lo1"), dir.path().join("b/lo1"));
    copy_tiny_run(&a);
    copy_tiny_run(&b);
    let out = dir.path().join("r");
    check_bad_input(
        &["report", s(&a), s(&b), "--out", s(&out), "--copy-runs"],
        "would both be copied to runs/lo1",
    );
    assert!(!out.exists());
    let inside = a.join("report");
    check_bad_input(
        &["report", s(&a), "--out", s(&inside), "--copy-runs"],
        "lies inside",
    );
    assert!(!inside.exists());
    let up = dir.path().join("up");
    let done = seads_command()
        .current_dir(a.join("checkpoints"))
        .args(["report", "..", "--out", s(&up), "--copy-runs"])
        .output()
        .unwrap();
    assert!(
        done.status.success(),
        "{}",
        String::from_utf8_lossy(&done.stderr)
    );
    assert!(up.join("runs/lo1/metrics.jsonl").is_file());
    assert!(
        !up.join("metrics.jsonl").exists(),
        "nothing copied into the report's top"
    );
}

/// Metrics with a repeated or an out-of-order epoch are damage: resuming refuses the run in one
/// line (exit 2) and a report leaves it out as damaged, never taking it as progress.
#[test]
fn repeated_or_out_of_order_epochs_are_damage() {
    let dir = tempfile::tempdir().unwrap();
    for (name, reorder) in [("repeated", false), ("reversed", true)] {
        let run = dir.path().join(name);
        copy_tiny_run(&run);
        let text = std::fs::read_to_string(run.join("metrics.jsonl")).unwrap();
        let mut lines: Vec<&str> = text.lines().collect();
        if reorder {
            let n = lines.len();
            lines.swap(n - 1, n - 2);
        } else {
            lines.push(lines[lines.len() - 1]);
        }
        std::fs::write(run.join("metrics.jsonl"), lines.join("\n") + "\n").unwrap();
        check_bad_input(
            &["train", "--resume", s(&run), "--env-steps", "900"],
            "after epoch",
        );
        let report = dir.path().join(format!("report-{name}"));
        let out = seads(&["report", s(&run), "--out", s(&report)]);
        let md = std::fs::read_to_string(report.join("report.md")).unwrap_or_default();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(
            md.contains("damaged") || stderr.contains("after epoch"),
            "{name}: {stderr}\n{md}"
        );
        assert!(!md.contains("1 finished"), "{name}: {md}");
    }
}

/// A damaged JSON Lines file of a run is named as what it is, with its line, not as a checkpoint
/// that cannot be loaded.
#[test]
fn a_garbage_evaluation_file_is_named_as_such() {
    let dir = tempfile::tempdir().unwrap();
    let run = dir.path().join("run");
    copy_tiny_run(&run);
    std::fs::write(run.join("evaluation-over-training.jsonl"), "garbage\n").unwrap();
    let out = seads(&[
        "evaluate",
        "--run",
        s(&run),
        "--checkpoints",
        "all",
        "--boards",
        "1",
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(
        stderr.contains("cannot read") && stderr.contains("evaluation-over-training.jsonl:1"),
        "{stderr}"
    );
    assert!(!stderr.contains("cannot load checkpoint"), "{stderr}");
}

/// `seads summary` writes the table between a document's markers and checks it: the committed
/// RESULTS matches its data; a document that was edited by hand fails the check (exit 1); a
/// folder that is not there, or a document without the markers, is one line of bad input and
/// the document is left as it was.
#[test]
fn the_summary_is_checked_written_and_refused_as_it_should_be() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let results = root.join("docs/results");
    let committed = root.join("docs/RESULTS.md");
    seads_ok(&[
        "summary",
        "--results",
        s(&results),
        "--check",
        s(&committed),
    ]);
    let dir = tempfile::tempdir().unwrap();
    let edited = dir.path().join("RESULTS.md");
    let text = std::fs::read_to_string(&committed).unwrap();
    let first_row = text.find("| LightsOutCursor").unwrap();
    let mut typed = text.clone();
    typed.insert_str(first_row, "| a row typed by hand | 1 | 2 | 3 | x |\n");
    std::fs::write(&edited, &typed).unwrap();
    let out = seads(&["summary", "--results", s(&results), "--check", s(&edited)]);
    assert_eq!(out.status.code(), Some(1), "{out:?}");
    seads_ok(&["summary", "--results", s(&results), "--write", s(&edited)]);
    assert_eq!(std::fs::read_to_string(&edited).unwrap(), text);
    check_bad_input(
        &["summary", "--results", s(&dir.path().join("none"))],
        "is not a folder of studies",
    );
    let bare = dir.path().join("bare.md");
    std::fs::write(&bare, "# no markers\n").unwrap();
    check_bad_input(
        &["summary", "--results", s(&results), "--write", s(&bare)],
        "lacks the lines",
    );
    assert_eq!(std::fs::read_to_string(&bare).unwrap(), "# no markers\n");
}
