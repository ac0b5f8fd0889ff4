//! `seads migrate`: files of the older layouts (`older-layout/`, copies of committed files as
//! they were before the migration) become today's, as committed; today's readers refuse the
//! older ones; the committed data is all in today's layout.

use std::path::{Path, PathBuf};

use crate::common::*;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// Each file of `older-layout/` and the committed file it became.
fn fixtures() -> Vec<(&'static str, PathBuf)> {
    let results = root().join("docs/results");
    vec![
        (
            "hac/config.toml",
            results.join("baselines/runs/baselines/runs/lightsout-cursor/hac/seed-1/config.toml"),
        ),
        (
            "jaco/config.toml",
            results.join("arms-jaco/runs/arms-jaco/runs/lightsout-jaco/seads/seed-1/config.toml"),
        ),
        (
            "jaco-flat/config.toml",
            results.join("jaco/runs/arms/runs/lightsout-jaco/seads/seed-1/config.toml"),
        ),
        (
            "manifest.toml",
            results.join("table1/runs/table1/manifest.toml"),
        ),
        (
            "evaluation-replan.json",
            results.join(
                "table1/runs/table1/runs/lightsout-cursor/seads/seed-1/evaluation-replan.json",
            ),
        ),
    ]
}

#[test]
fn older_layouts_become_todays_as_committed() {
    let dir = tempfile::tempdir().unwrap();
    let old = dir.path().join("old");
    copy_dir(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/end_to_end/older-layout"),
        &old,
    );
    // Today's binary refuses them, pointing to the command.
    for run in ["jaco-flat", "jaco", "hac"] {
        let run = old.join(run);
        check_bad_input(
            &["evaluate", "--run", s(&run)],
            "`seads migrate` rewrites it",
        );
    }
    // --check lists them and changes nothing.
    let before = snapshot(&old);
    let out = seads(&["migrate", "--check", s(&old)]);
    assert_eq!(out.status.code(), Some(1));
    let listed = String::from_utf8_lossy(&out.stdout);
    for (file, _) in fixtures() {
        assert!(listed.contains(file), "{file} not in {listed}");
    }
    assert_eq!(snapshot(&old), before);
    // Migrated, each is the committed file byte for byte; a second run changes nothing.
    let out = seads_ok(&["migrate", s(&old)]);
    assert!(
        String::from_utf8_lossy(&out.stdout)
            .starts_with("migrated 3 run configuration(s), 1 manifest(s), 1 evaluation file(s), 0 episode table(s)"),
        "{}",
        String::from_utf8_lossy(&out.stdout)
    );
    for (file, committed) in fixtures() {
        assert_eq!(
            std::fs::read_to_string(old.join(file)).unwrap(),
            std::fs::read_to_string(&committed).unwrap(),
            "{file}"
        );
    }
    seads_ok(&["migrate", "--check", s(&old)]);
}

/// A file that cannot be migrated (a section of another algorithm holding other values than
/// its defaults) is bad input, and no file is rewritten, the good ones included.
#[test]
fn a_file_that_cannot_be_migrated_leaves_every_file_alone() {
    let dir = tempfile::tempdir().unwrap();
    copy_dir(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/end_to_end/older-layout"),
        dir.path(),
    );
    let bad = dir.path().join("zz-bad/config.toml");
    std::fs::create_dir_all(bad.parent().unwrap()).unwrap();
    std::fs::write(
        &bad,
        "algorithm = \"sac\"\nenv = \"lightsout-cursor\"\nnum_skills = 30\n",
    )
    .unwrap();
    let before = snapshot(dir.path());
    check_bad_input(
        &["migrate", s(dir.path())],
        "holds other values than its defaults",
    );
    assert_eq!(snapshot(dir.path()), before);
    check_bad_input(
        &["migrate", s(&dir.path().join("nowhere"))],
        "does not exist",
    );
}

/// Every committed run, manifest and evaluation is in today's layout.
#[test]
fn the_committed_data_is_in_todays_layout() {
    let root = root();
    let paths = [
        "docs/results",
        "experiments",
        "data",
        "crates/seads-py/tests/data",
    ]
    .map(|p| root.join(p));
    let args: Vec<&str> = std::iter::once("migrate")
        .chain(std::iter::once("--check"))
        .chain(paths.iter().map(|p| s(p)))
        .collect();
    let out = seads_ok(&args);
    assert!(
        String::from_utf8_lossy(&out.stdout).contains("are in today's layout"),
        "{}",
        String::from_utf8_lossy(&out.stdout)
    );
}
