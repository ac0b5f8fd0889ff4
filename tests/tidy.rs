//! The repository keeps its promises: the architecture doc names every crate, the README's two
//! commands are the ones CI runs.

use crate::{read, root};

#[test]
fn architecture_doc_names_every_crate() {
    let doc = read("docs/ARCHITECTURE.md");
    let mut crates: Vec<String> = std::fs::read_dir(root().join("crates"))
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    crates.sort();
    assert_eq!(crates.len(), 7, "{crates:?}");
    for name in crates {
        assert!(
            doc.contains(&format!("`{name}`")),
            "docs/ARCHITECTURE.md does not describe crate {name}"
        );
    }
}

#[test]
fn readme_starts_with_the_two_commands_and_ci_runs_the_second() {
    let readme = read("README.md");
    let commands: Vec<&str> = readme
        .lines()
        .filter(|l| l.starts_with("cargo xtask "))
        .take(2)
        .collect();
    assert_eq!(
        commands,
        ["cargo xtask run", "cargo xtask ci"],
        "README's set-up commands"
    );
    let ci = read(".ci/run");
    assert!(
        ci.lines().any(|l| l.trim() == "exec cargo xtask ci"),
        ".ci/run must run `cargo xtask ci`"
    );
}
