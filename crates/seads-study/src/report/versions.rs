//! Which code versions trained a study's runs: each run's distinct (commit, dirty) pairs from its
//! `provenance.jsonl`, counted per version, with the runs that trained from a dirty working tree,
//! from a commit the repository lacks, or without any provenance marked; and which binaries made
//! the evaluations the report's tables take (`evaluated_by` of the evaluation files).

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;
use std::process::{Command, Stdio};

use super::csv_field;
use super::runs::RunData;
use crate::provenance::{PROVENANCE, Provenance};

/// One code version: a commit and whether the binary's tree had uncommitted changes.
#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord)]
struct Version {
    commit: String,
    dirty: bool,
}

impl Version {
    /// The commit, marked `(dirty)` if the tree had uncommitted changes.
    fn named(&self) -> String {
        if self.dirty {
            format!("{} (dirty)", self.commit)
        } else {
            self.commit.clone()
        }
    }
}

/// A commit as read from a file, made safe to print in a table cell or a CSV field: letters,
/// digits, `.`, `-` and `_` are kept, anything else (a backtick, `|`, a comma, a line break) is
/// shown as `?`, and at most 64 characters are kept. A forged provenance line can thus neither
/// add a row nor break one.
fn shown(commit: &str) -> String {
    let mut out: String = commit
        .chars()
        .take(64)
        .map(|c| {
            if c.is_ascii_alphanumeric() || "._-".contains(c) {
                c
            } else {
                '?'
            }
        })
        .collect();
    if commit.chars().count() > 64 {
        out.push_str("...");
    }
    out
}

/// Whether `dir` is inside a git repository; `None` where git cannot be run.
pub fn is_repository(dir: &Path) -> Option<bool> {
    let inside = Command::new("git")
        .arg("-C")
        .arg(dir)
        .args(["rev-parse", "--is-inside-work-tree"])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .ok()?;
    Some(inside.success())
}

/// Whether the git repository at `repository` has `commit`, a full commit hash (40 hexadecimal
/// digits, or 64 in a SHA-256 repository, as provenance records it); `None` where git cannot say
/// (no git, no repository). Anything else is no commit of the repository: neither an abbreviated
/// hash nor a name that git would resolve (`HEAD`, a branch, `X~1`) counts.
pub fn has_commit(repository: &Path, commit: &str) -> Option<bool> {
    if ![40, 64].contains(&commit.len()) || !commit.chars().all(|c| c.is_ascii_hexdigit()) {
        return Some(false);
    }
    if !is_repository(repository)? {
        return None;
    }
    let found = Command::new("git")
        .arg("-C")
        .arg(repository)
        .args(["cat-file", "-e", &format!("{commit}^{{commit}}")])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .ok()?;
    Some(found.success())
}

/// A run's code versions in the order they first trained it; `Err` with the reason where its
/// provenance is missing or cannot be read.
fn run_versions(run: &RunData) -> Result<Vec<Version>, String> {
    let path = run.dir.join(PROVENANCE);
    if !path.is_file() {
        return Err("no provenance".to_owned());
    }
    let (lines, _) = seads_run::store::read_json_lines::<Provenance>(&path)
        .map_err(|e| format!("provenance unreadable: {e}"))?;
    let mut seen: Vec<Version> = Vec::new();
    for line in lines {
        let v = Version {
            commit: shown(&line.commit),
            dirty: line.dirty,
        };
        if !seen.contains(&v) {
            seen.push(v);
        }
    }
    if seen.is_empty() {
        return Err("no provenance".to_owned());
    }
    Ok(seen)
}

/// The code-version table (markdown: one row per version with its run count, then the marked
/// runs) and its CSV (one row per run), for `runs`; `known` says whether the repository has a
/// commit (`None`: not checked).
pub fn version_tables(runs: &[&RunData], known: &dyn Fn(&str) -> Option<bool>) -> (String, String) {
    let mut counts: BTreeMap<Version, usize> = BTreeMap::new();
    let mut known_cache: BTreeMap<String, Option<bool>> = BTreeMap::new();
    let mut is_known = |commit: &str| {
        *known_cache
            .entry(commit.to_owned())
            .or_insert_with(|| known(commit))
    };
    let mut marked: Vec<(String, String)> = Vec::new();
    let mut csv = String::from("env,variant,run,commits,dirty,not_in_repository,evaluated_by\n");
    let mut evaluations: BTreeMap<Version, usize> = BTreeMap::new();
    let mut unnamed = 0;
    for run in runs {
        let name = run.dir.display().to_string();
        let evaluators: Vec<Version> = run
            .evaluated_by
            .named
            .iter()
            .map(|e| Version {
                commit: shown(&e.commit),
                dirty: e.dirty,
            })
            .collect();
        unnamed += usize::from(run.evaluated_by.unnamed > 0);
        let evaluated_by: Vec<String> = evaluators.iter().map(Version::named).collect();
        let evaluated_by = csv_field(&evaluated_by.join(";"));
        for v in evaluators {
            *evaluations.entry(v).or_default() += 1;
        }
        match run_versions(run) {
            Ok(versions) => {
                let dirty = versions.iter().any(|v| v.dirty);
                let missing: Vec<&str> = versions
                    .iter()
                    .filter(|v| is_known(&v.commit) == Some(false))
                    .map(|v| v.commit.as_str())
                    .collect();
                let mut why = Vec::new();
                if dirty {
                    why.push("trained from a working tree with uncommitted changes".to_owned());
                }
                if !missing.is_empty() {
                    why.push(format!(
                        "commit not in the repository: {}",
                        missing.join(", ")
                    ));
                }
                if !why.is_empty() {
                    marked.push((name.clone(), why.join("; ")));
                }
                let commits: Vec<&str> = versions.iter().map(|v| v.commit.as_str()).collect();
                let _ = writeln!(
                    csv,
                    "{},{},{},{},{dirty},{},{evaluated_by}",
                    csv_field(&run.config.env),
                    csv_field(&run.variant),
                    csv_field(&name),
                    commits.join(";"),
                    !missing.is_empty()
                );
                for v in versions {
                    *counts.entry(v).or_default() += 1;
                }
            }
            Err(why) => {
                let _ = writeln!(
                    csv,
                    "{},{},{},,,,{evaluated_by}",
                    csv_field(&run.config.env),
                    csv_field(&run.variant),
                    csv_field(&name)
                );
                marked.push((name, why));
            }
        }
    }
    let mut md =
        String::from("| commit | working tree | in the repository | runs |\n|---|---|---|---|\n");
    for (v, n) in &counts {
        let in_repo = match is_known(&v.commit) {
            Some(true) => "yes",
            Some(false) => "**no**",
            None => "not checked",
        };
        let tree = if v.dirty {
            "**uncommitted changes**"
        } else {
            "clean"
        };
        let _ = writeln!(md, "| `{}` | {tree} | {in_repo} | {n} |", v.commit);
    }
    if counts.is_empty() {
        md += "| – | – | – | 0 |\n";
    }
    let clean = counts.len() == 1
        && marked.is_empty()
        && counts
            .keys()
            .all(|v| !v.dirty && is_known(&v.commit) != Some(false));
    md.push('\n');
    if clean {
        md += "Every run trained on this one clean commit.\n";
    } else {
        let _ = writeln!(
            md,
            "{} code version(s) over {} run(s); a run that trained in several processes counts \
             once per version.",
            counts.len(),
            runs.len()
        );
        for (run, why) in &marked {
            let _ = writeln!(md, "- `{run}`: {why}");
        }
    }
    if !evaluations.is_empty() {
        let by: Vec<String> = evaluations
            .iter()
            .map(|(v, n)| format!("`{}` ({n} run(s))", v.named()))
            .collect();
        let _ = writeln!(
            md,
            "\nThe evaluations the tables take were made by the binaries of {}.",
            by.join(", ")
        );
    }
    if unnamed > 0 {
        let _ = writeln!(
            md,
            "\nSome evaluation files of {unnamed} run(s) name no binary (written before evaluation \
             files did, or resumed from one that did not)."
        );
    }
    (md, csv)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::provenance::Build;
    use crate::report::runs::bare_run;

    /// Four runs, written by hand: one trained in two processes on the clean commit `aaa1`, one on
    /// `aaa1` from a dirty tree, one on `bbb2` (which the repository lacks), one without
    /// provenance. Counted per version, and every run but the first marked with why.
    #[test]
    fn versions_are_counted_and_doubtful_runs_marked() {
        let tmp = tempfile::tempdir().unwrap();
        let mut runs = Vec::new();
        let lines: [&[(&str, bool)]; 4] = [
            &[("aaa1", false), ("aaa1", false)],
            &[("aaa1", true)],
            &[("bbb2", false)],
            &[],
        ];
        for (i, versions) in lines.iter().enumerate() {
            let mut run = bare_run(i as u32 + 1);
            run.dir = tmp.path().join(format!("seed-{}", i + 1));
            std::fs::create_dir_all(&run.dir).unwrap();
            for &(commit, dirty) in versions.iter() {
                let build = Build {
                    version: "0.1.0",
                    commit,
                    dirty,
                };
                Provenance::here(0, 0, false, Default::default(), &build)
                    .append(&run.dir)
                    .unwrap();
            }
            runs.push(run);
        }
        let refs: Vec<&RunData> = runs.iter().collect();
        let known = |commit: &str| Some(commit == "aaa1");
        let (md, csv) = version_tables(&refs, &known);
        assert!(md.contains("| `aaa1` | clean | yes | 1 |"), "{md}");
        assert!(
            md.contains("| `aaa1` | **uncommitted changes** | yes | 1 |"),
            "{md}"
        );
        assert!(md.contains("| `bbb2` | clean | **no** | 1 |"), "{md}");
        let marked: Vec<&str> = md.lines().filter(|l| l.starts_with("- `")).collect();
        assert_eq!(marked.len(), 3, "{md}");
        assert!(marked[0].contains("seed-2") && marked[0].contains("uncommitted changes"));
        assert!(marked[1].contains("seed-3") && marked[1].contains("not in the repository: bbb2"));
        assert!(marked[2].contains("seed-4") && marked[2].contains("no provenance"));
        assert!(!md.contains("Every run trained on this one clean commit"));
        let rows: Vec<&str> = csv.lines().skip(1).collect();
        assert_eq!(rows.len(), 4);
        assert!(rows[0].ends_with(",aaa1,false,false,"), "{}", rows[0]);
        assert!(rows[1].ends_with(",aaa1,true,false,"), "{}", rows[1]);
        assert!(rows[2].ends_with(",bbb2,false,true,"), "{}", rows[2]);
        assert!(rows[3].ends_with(",,,,"), "{}", rows[3]);
        // Evaluations name their binaries: two runs by `ccc3`, one of them resumed by a dirty
        // `ddd4`; a run with an evaluation that names none is counted apart.
        let evaluator = |commit: &str, dirty| seads_planner::Evaluator {
            seads: "0.1.0".into(),
            commit: commit.into(),
            dirty,
        };
        runs[0].evaluated_by.add(vec![evaluator("ccc3", false)]);
        runs[1]
            .evaluated_by
            .add(vec![evaluator("ccc3", false), evaluator("ddd4", true)]);
        runs[2].evaluated_by.add(Vec::new());
        let refs: Vec<&RunData> = runs.iter().collect();
        let (md, csv) = version_tables(&refs, &known);
        let rows: Vec<&str> = csv.lines().skip(1).collect();
        assert!(rows[0].ends_with(",aaa1,false,false,ccc3"), "{}", rows[0]);
        assert!(
            rows[1].ends_with(",true,false,ccc3;ddd4 (dirty)"),
            "{}",
            rows[1]
        );
        assert!(rows[2].ends_with(",bbb2,false,true,"), "{}", rows[2]);
        assert!(
            md.contains(
                "The evaluations the tables take were made by the binaries of `ccc3` (2 run(s)), \
                 `ddd4 (dirty)` (1 run(s)).\n"
            ),
            "{md}"
        );
        assert!(
            md.contains("Some evaluation files of 1 run(s) name no binary"),
            "{md}"
        );
        // A run whose files name a binary and none: it counts among the runs naming none too.
        runs[0].evaluated_by.add(Vec::new());
        let refs: Vec<&RunData> = runs.iter().collect();
        let (md, _) = version_tables(&refs, &known);
        assert!(
            md.contains("Some evaluation files of 2 run(s) name no binary"),
            "{md}"
        );
        // One clean known commit for every run: said in one sentence.
        let (md, _) = version_tables(&refs[..1], &known);
        assert!(
            md.contains("Every run trained on this one clean commit."),
            "{md}"
        );
    }

    /// A provenance line whose commit holds a backtick, `|`, a comma or a line break forges no
    /// row of the markdown table and no field of the CSV (issue 82).
    #[test]
    fn a_forged_commit_adds_no_row() {
        let tmp = tempfile::tempdir().unwrap();
        let mut run = bare_run(1);
        run.dir = tmp.path().join("seed-1");
        std::fs::create_dir_all(&run.dir).unwrap();
        let forged = "aaa1` | clean | yes | 99 |\n| `bbb2,x";
        let build = Build {
            version: "0.1.0",
            commit: forged,
            dirty: false,
        };
        Provenance::here(0, 0, false, Default::default(), &build)
            .append(&run.dir)
            .unwrap();
        run.evaluated_by.add(vec![seads_planner::Evaluator {
            seads: "0.1.0".into(),
            commit: "ccc3,\n,x".into(),
            dirty: false,
        }]);
        let (md, csv) = version_tables(&[&run], &|_| Some(false));
        let rows: Vec<&str> = md.lines().filter(|l| l.starts_with('|')).collect();
        assert_eq!(rows.len(), 3, "header, rule and one version: {md}");
        assert!(!md.contains("| 99 |"), "{md}");
        assert!(rows[2].ends_with("| clean | **no** | 1 |"), "{md}");
        let lines: Vec<&str> = csv.lines().collect();
        assert_eq!(lines.len(), 2, "{csv}");
        let fields = lines[1].split(',').count();
        assert_eq!(fields, lines[0].split(',').count(), "{csv}");
        assert_eq!(shown("ab\n|`,"), "ab????");
        assert_eq!(shown(&"a".repeat(70)), format!("{}...", "a".repeat(64)));
    }

    /// A name git would resolve (a branch named in hexadecimal digits, an abbreviated hash, a
    /// relative name) is no commit of the repository; only full hashes are looked up (issue 82:
    /// `git cat-file -e X^{commit}` resolved them).
    #[test]
    fn only_full_hashes_are_commits_of_the_repository() {
        let tmp = tempfile::tempdir().unwrap();
        let git = |args: &[&str]| {
            let out = std::process::Command::new("git")
                .arg("-C")
                .arg(tmp.path())
                .args([
                    "-c",
                    "user.name=t",
                    "-c",
                    "user.email=t@t",
                    "-c",
                    "init.defaultBranch=main",
                ])
                .args(args)
                .output()
                .expect("git runs");
            assert!(out.status.success(), "git {args:?}: {out:?}");
            String::from_utf8(out.stdout).unwrap().trim().to_owned()
        };
        git(&["init", "--quiet"]);
        git(&["commit", "--quiet", "--allow-empty", "-m", "one"]);
        git(&["branch", "beef"]);
        let head = git(&["rev-parse", "HEAD"]);
        assert_eq!(has_commit(tmp.path(), &head), Some(true));
        for name in ["beef", &head[..7], "HEAD", "main", "HEAD~0"] {
            assert_eq!(has_commit(tmp.path(), name), Some(false), "{name}");
        }
        assert_eq!(is_repository(tmp.path()), Some(true));
        let plain = tempfile::tempdir().unwrap();
        assert_eq!(is_repository(plain.path()), Some(false));
        assert_eq!(is_repository(&plain.path().join("missing")), Some(false));
    }

    /// A commit the repository has, one it lacks, and a name that is no commit.
    #[test]
    fn commits_are_looked_up_in_the_repository() {
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
        let head = std::process::Command::new("git")
            .arg("-C")
            .arg(&root)
            .args(["rev-parse", "HEAD"])
            .output();
        let Some(head) = head.ok().filter(|o| o.status.success()) else {
            // A source tree without git (a crates.io package): nothing to look up.
            assert_eq!(has_commit(&root, "0123abcd"), None);
            return;
        };
        let head = String::from_utf8(head.stdout).unwrap();
        assert_eq!(has_commit(&root, head.trim()), Some(true));
        assert_eq!(has_commit(&root, &"0".repeat(40)), Some(false));
        assert_eq!(has_commit(&root, "not-a-commit; rm -rf /"), Some(false));
    }
}
