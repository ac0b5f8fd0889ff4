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
    // The crates the project's shape names; more may join them, each described.
    for required in [
        "seads-games",
        "seads-embodiment",
        "seads-rl",
        "seads-skillmodel",
        "seads-planner",
        "seads-uarm",
        "seads-cli",
    ] {
        assert!(
            crates.iter().any(|c| c == required),
            "{required}: {crates:?}"
        );
    }
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

/// `cargo metadata` of the workspace, with the resolved dependency graph.
fn metadata() -> serde_json::Value {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let out = std::process::Command::new(cargo)
        .args(["metadata", "--format-version", "1", "--offline"])
        .current_dir(root())
        .output()
        .expect("run cargo metadata");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap()
}

/// Every package's name and its normal (not dev or build) dependencies, by package id.
fn normal_graph(meta: &serde_json::Value) -> Vec<(String, String, Vec<String>)> {
    let name_of = |id: &str| -> String {
        meta["packages"]
            .as_array()
            .unwrap()
            .iter()
            .find(|p| p["id"] == id)
            .map(|p| p["name"].as_str().unwrap().to_owned())
            .unwrap()
    };
    meta["resolve"]["nodes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|node| {
            let id = node["id"].as_str().unwrap().to_owned();
            let deps = node["deps"]
                .as_array()
                .unwrap()
                .iter()
                .filter(|d| {
                    d["dep_kinds"]
                        .as_array()
                        .unwrap()
                        .iter()
                        .any(|k| k["kind"].is_null())
                })
                .map(|d| d["pkg"].as_str().unwrap().to_owned())
                .collect();
            (name_of(&id), id, deps)
        })
        .collect()
}

/// Every package the dev profile names (`[profile.dev.package]`: what it compiles unoptimised)
/// is one the workspace builds: a dependency renamed or dropped would leave a stale line that
/// cargo only warns about, and its successor compiled optimised.
#[test]
fn the_dev_profile_names_only_packages_the_workspace_builds() {
    let manifest: toml::Table = toml::from_str(&read("Cargo.toml")).unwrap();
    let named = manifest["profile"]["dev"]["package"].as_table().unwrap();
    let meta = metadata();
    let built: std::collections::BTreeSet<&str> = meta["packages"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p["name"].as_str().unwrap())
        .collect();
    let stale: Vec<&String> = named
        .keys()
        .filter(|name| *name != "*" && !built.contains(name.as_str()))
        .collect();
    assert!(named.len() > 10, "{named:?}");
    assert!(
        stale.is_empty(),
        "Cargo.toml's [profile.dev.package] names {stale:?}, which nothing builds"
    );
}

/// The internal dependencies are the ones docs/ARCHITECTURE.md states, and only the crates it
/// names link libtorch (tch), counting dependencies of dependencies.
#[test]
fn crate_dependencies_point_one_way_and_only_five_crates_link_libtorch() {
    let meta = metadata();
    let graph = normal_graph(&meta);
    let expected: &[(&str, &[&str])] = &[
        ("seads-games", &[]),
        ("seads-weights", &[]),
        (
            "seads-run",
            &["seads-embodiment", "seads-games", "seads-planner"],
        ),
        ("seads-nn", &["seads-run", "seads-weights"]),
        ("seads-embodiment", &["seads-games"]),
        (
            "seads-skillmodel",
            &["seads-games", "seads-nn", "seads-run"],
        ),
        (
            "seads-rl",
            &[
                "seads-embodiment",
                "seads-games",
                "seads-nn",
                "seads-planner",
                "seads-run",
                "seads-skillmodel",
            ],
        ),
        ("seads-planner", &["seads-embodiment", "seads-games"]),
        (
            "seads-infer",
            &["seads-embodiment", "seads-games", "seads-weights"],
        ),
        ("seads-uarm", &["seads-embodiment", "seads-games"]),
        (
            "seads-py",
            &[
                "seads-embodiment",
                "seads-games",
                "seads-infer",
                "seads-planner",
            ],
        ),
        (
            "seads-study",
            &[
                "seads-embodiment",
                "seads-games",
                "seads-planner",
                "seads-run",
                "seads-uarm",
            ],
        ),
        (
            "seads-evaluation",
            &[
                "seads-embodiment",
                "seads-games",
                "seads-nn",
                "seads-planner",
                "seads-rl",
                "seads-run",
                "seads-skillmodel",
                "seads-study",
                "seads-uarm",
            ],
        ),
        (
            "seads-cli",
            &[
                "seads-embodiment",
                "seads-evaluation",
                "seads-games",
                "seads-nn",
                "seads-planner",
                "seads-rl",
                "seads-run",
                "seads-skillmodel",
                "seads-study",
                "seads-uarm",
            ],
        ),
    ];
    let by_id = |id: &String| graph.iter().find(|(_, i, _)| i == id).unwrap();
    for (name, internal) in expected {
        let (_, _, deps) = graph.iter().find(|(n, _, _)| n == name).unwrap();
        let mut found: Vec<&str> = deps
            .iter()
            .map(|d| by_id(d).0.as_str())
            .filter(|n| n.starts_with("seads-"))
            .collect();
        found.sort_unstable();
        assert_eq!(&found, internal, "internal dependencies of {name}");
    }
    let links_tch = |name: &str| {
        let start = graph.iter().find(|(n, _, _)| n == name).unwrap();
        let mut stack = vec![start.1.clone()];
        let mut seen = Vec::new();
        while let Some(id) = stack.pop() {
            if seen.contains(&id) {
                continue;
            }
            let node = by_id(&id);
            if node.0 == "tch" {
                return true;
            }
            stack.extend(node.2.iter().cloned());
            seen.push(id);
        }
        false
    };
    let linking: Vec<&str> = expected
        .iter()
        .map(|(n, _)| *n)
        .filter(|n| links_tch(n))
        .collect();
    assert_eq!(
        linking,
        [
            "seads-nn",
            "seads-skillmodel",
            "seads-rl",
            "seads-evaluation",
            "seads-cli"
        ]
    );
}

/// `cargo tree`'s lines for `args`, following the dependencies of kinds `edges`, each package
/// as `format` writes it (without the mark of one already listed).
fn cargo_tree(edges: &str, format: &str, args: &[&str]) -> Vec<String> {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let out = std::process::Command::new(cargo)
        .args(["tree", "--offline", "--locked", "-e", edges])
        .args(["--prefix", "none", "--format", format])
        .args(args)
        .current_dir(root())
        .output()
        .expect("run cargo tree");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout)
        .lines()
        .map(|l| l.trim_end_matches(" (*)").trim_end().to_owned())
        .collect()
}

/// The packages `cargo tree` lists for `args` (normal dependencies only), one name per entry.
fn tree(args: &[&str]) -> Vec<String> {
    cargo_tree("normal", "{p}", args)
        .iter()
        .filter_map(|l| l.split_whitespace().next().map(str::to_owned))
        .collect()
}

/// A user of the games, the planner, the robot, Cursor or Reacher downloads neither PyTorch nor
/// a physics engine: libtorch only behind `seads-nn`, rapier3d only behind `seads-embodiment`'s
/// default feature `jaco` (docs/ARCHITECTURE.md). A run's data (`seads-run`) and the reports
/// and sweeps that read it (`seads-study`) build without libtorch.
#[test]
fn light_crates_pull_in_neither_libtorch_nor_rapier() {
    for (args, heavy) in [
        (
            &["-p", "seads-games"][..],
            &["tch", "torch-sys", "rapier3d"][..],
        ),
        (&["-p", "seads-planner"], &["tch", "torch-sys", "rapier3d"]),
        (&["-p", "seads-infer"], &["tch", "torch-sys", "rapier3d"]),
        (&["-p", "seads-weights"], &["tch", "torch-sys", "rapier3d"]),
        (&["-p", "seads-uarm"], &["tch", "torch-sys", "rapier3d"]),
        // A run's data, and the reports and sweeps that read it: no libtorch (issue 78).
        (&["-p", "seads-run"], &["tch", "torch-sys", "rapier3d"]),
        (&["-p", "seads-study"], &["tch", "torch-sys"]),
        (
            &["-p", "seads-embodiment", "--no-default-features"],
            &["tch", "torch-sys", "rapier3d"],
        ),
        (&["-p", "seads-embodiment"], &["tch", "torch-sys"]),
        // The Python package: PyTorch's process must not get a second libtorch.
        (&["-p", "seads-py"], &["tch", "torch-sys"]),
    ] {
        let packages = tree(args);
        assert!(
            packages.len() > 3,
            "cargo tree {args:?} listed {packages:?}"
        );
        for h in heavy {
            assert!(
                !packages.iter().any(|p| p == h),
                "cargo tree {args:?} includes {h}"
            );
        }
    }
    // The feature is what brings rapier: the check above would pass vacuously otherwise.
    assert!(
        tree(&["-p", "seads-embodiment"])
            .iter()
            .any(|p| p == "rapier3d")
    );
}

/// The Python package's build (maturin builds `seads-py` alone) compiles every dependency with
/// the features the workspace's test build gives it, so that `cargo xtask ci` compiles each
/// once: cargo resolves features for the packages one build names, and the lines of
/// `crates/seads-py/Cargo.toml` that the code does not use exist to ask for the workspace's.
/// A dependency that differs here compiles a second time, with its dependents (282 s when
/// rapier3d's tree did).
#[test]
fn the_python_package_compiles_its_dependencies_as_the_workspace_does() {
    let with_features = |edges: &str, args: &[&str]| -> std::collections::BTreeSet<String> {
        cargo_tree(edges, "{p} {f}", args).into_iter().collect()
    };
    let workspace = with_features("normal,build,dev", &["--workspace"]);
    let python = with_features("normal,build", &["-p", "seads-py"]);
    assert!(python.len() > 50, "{python:?}");
    let differing: Vec<&String> = python.difference(&workspace).collect();
    assert!(
        differing.is_empty(),
        "seads-py alone builds these with other features than the workspace (package, \
         features): {differing:?}; add them to crates/seads-py/Cargo.toml's list"
    );
}

/// Every `.rs` file under `crates/`, with its text.
fn sources() -> Vec<(std::path::PathBuf, String)> {
    let mut out = Vec::new();
    let mut dirs = vec![root().join("crates")];
    while let Some(dir) = dirs.pop() {
        for entry in std::fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                dirs.push(path);
            } else if path.extension().is_some_and(|e| e == "rs") {
                let text = std::fs::read_to_string(&path).unwrap();
                out.push((path, text));
            }
        }
    }
    out
}

/// No test is `#[ignore]`d and no test asserts on the time a piece of work took: a test that
/// needs what a machine may lack is built only when switched on, and a wait ends on an event
/// (docs/ARCHITECTURE.md, "Tests and the clock").
#[test]
fn no_test_is_ignored_or_timed() {
    let ignored = ["#", "[ignore"].concat();
    let timed = ["elapsed()", " < "].concat();
    let mut checked = 0;
    for (path, text) in sources() {
        checked += 1;
        assert!(
            !text.contains(&ignored),
            "{} ignores a test",
            path.display()
        );
        let in_tests = path.components().any(|c| c.as_os_str() == "tests");
        let asserts_time = text.lines().collect::<Vec<_>>().windows(2).any(|w| {
            w[0].trim_start().starts_with("assert!(") && w[1].contains(&timed)
                || w[0].contains("assert!(") && w[0].contains(&timed)
        });
        assert!(
            !(in_tests && asserts_time),
            "{} asserts on wall time",
            path.display()
        );
    }
    assert!(checked > 100, "{checked} sources checked");
}

/// No code draws from libtorch's global generator: every random number comes from a stream of
/// the run's seed (docs/ARCHITECTURE.md, "Determinism").
#[test]
fn nothing_uses_libtorchs_global_generator() {
    let calls = [
        "manual_seed",
        "Tensor::rand",
        "Tensor::randn",
        "Tensor::randint",
        "Tensor::randperm",
        "rand_like",
        "randn_like",
        ".bernoulli",
        ".multinomial",
        ".normal_(",
        ".uniform_(",
        "dropout",
        "nn::init::",
    ];
    for (path, text) in sources() {
        for call in calls {
            assert!(
                !text.contains(call),
                "{} uses libtorch's generator ({call})",
                path.display()
            );
        }
    }
}

/// The Python bindings allow `unsafe_code` for pyo3's macros only: their own source has none.
#[test]
fn the_python_bindings_write_no_unsafe_code() {
    let sources = sources();
    let bindings: Vec<_> = sources
        .iter()
        .filter(|(path, _)| path.starts_with(root().join("crates/seads-py/src")))
        .collect();
    assert!(bindings.len() >= 4, "found the bindings' files");
    for (path, text) in bindings {
        assert!(
            !words(text).any(|w| w == "unsafe"),
            "{} has unsafe code",
            path.display()
        );
    }
}

/// Every registered environment has a shipped preset (laid together from the layers of
/// `configs/`: `every_preset_file_is_embedded_and_used` in seads-run).
#[test]
fn every_environment_has_a_preset() {
    let envs = seads_embodiment::env_names();
    assert!(
        envs.contains(&"lightsout-jaco"),
        "the Jaco environments are registered"
    );
    for env in envs {
        let preset = seads_run::TrainConfig::preset(env).unwrap();
        assert_eq!(preset.env, env);
    }
}

/// Paths that are outside the repository or made by set-up and runs, not committed.
fn generated(path: &str) -> bool {
    [
        "../",
        "/tmp",
        ".libtorch",
        ".venv",
        "target/",
        "runs/",
        "sweeps/",
        "logs/",
        "RUN/",
        "DIR/",
    ]
    .iter()
    .any(|p| path.starts_with(p))
}

/// The files and folders (with a trailing `/`) that a clean checkout of this working copy has:
/// what git tracks or would commit (untracked files it does not ignore), nothing that builds,
/// runs or set-up leave behind (an ignored `gpu/` once made a citation pass here and fail in CI).
/// Without git (a source archive), every file outside the [`generated`] places.
fn checkout_files() -> Vec<String> {
    let listed = std::process::Command::new("git")
        .args([
            "ls-files",
            "-z",
            "--cached",
            "--others",
            "--exclude-standard",
        ])
        .current_dir(root())
        .output()
        .ok()
        .filter(|o| o.status.success());
    let mut files: Vec<String> = match listed {
        Some(out) => String::from_utf8(out.stdout)
            .unwrap()
            .split('\0')
            .filter(|f| !f.is_empty() && root().join(f).is_file())
            .map(str::to_owned)
            .collect(),
        None => walk_files(),
    };
    let folders: Vec<String> = files
        .iter()
        .flat_map(|f| {
            f.match_indices('/')
                .map(|(i, _)| f[..=i].to_owned())
                .collect::<Vec<_>>()
        })
        .collect();
    files.extend(folders);
    files.sort();
    files.dedup();
    files
}

/// Every file below the root outside hidden folders and the [`generated`] places.
fn walk_files() -> Vec<String> {
    let mut files = Vec::new();
    let mut dirs = vec![root()];
    while let Some(dir) = dirs.pop() {
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            let name = path.file_name().unwrap().to_string_lossy().into_owned();
            if name.starts_with('.') && name != ".ci" && name != ".cargo" {
                continue;
            }
            let relative = path.strip_prefix(root()).unwrap().to_string_lossy();
            if path.is_dir() {
                if !generated(&format!("{relative}/")) {
                    dirs.push(path);
                }
            } else {
                files.push(relative.into_owned());
            }
        }
    }
    files
}

/// Every file path and test name that the two reference documents cite in backticks exists: a
/// path (with a `/`, or a file name with an extension) somewhere in the repository, a test name
/// (four or more words joined by `_`) as a `fn` in some Rust file or a `def` in a Python one.
#[test]
fn the_documents_cite_only_files_and_tests_that_exist() {
    let files = checkout_files();
    let rust: String = files
        .iter()
        .filter(|f| f.ends_with(".rs"))
        .map(|f| std::fs::read_to_string(root().join(f)).unwrap())
        .collect();
    // The Python package's tests (pytest) are cited by name too.
    let python: String = files
        .iter()
        .filter(|f| f.ends_with(".py"))
        .map(|f| std::fs::read_to_string(root().join(f)).unwrap())
        .collect();
    let extensions = [
        ".rs", ".toml", ".md", ".py", ".json", ".jsonl", ".csv", ".sh", ".gz",
    ];
    let mut missing = Vec::new();
    for doc in [
        "README.md",
        "docs/ARCHITECTURE.md",
        "docs/RESULTS.md",
        "docs/USAGE.md",
    ] {
        let text = read(doc);
        for cited in text.split('`').skip(1).step_by(2) {
            let cited = cited.trim();
            if cited.contains(' ')
                || cited.contains('*')
                || cited.contains('<')
                || cited.starts_with('~')
            {
                continue;
            }
            let is_test = cited.split('_').count() >= 4
                && cited
                    .chars()
                    .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '_');
            let is_path = (cited.contains('/') && !cited.contains("://"))
                || extensions.iter().any(|e| cited.ends_with(e));
            if is_test {
                if !rust.contains(&format!("fn {cited}("))
                    && !python.contains(&format!("def {cited}("))
                {
                    missing.push(format!("{doc}: test {cited}"));
                }
            } else if is_path && !generated(cited) {
                // A path relative to the root, or the end of one (`src/x.rs`, `report/`).
                let found = files
                    .iter()
                    .any(|f| f == cited || f.ends_with(&format!("/{cited}")));
                if !found {
                    missing.push(format!("{doc}: path {cited}"));
                }
            }
        }
    }
    assert!(
        missing.is_empty(),
        "cited but missing:\n{}",
        missing.join("\n")
    );
}

/// Every `.rs` file under `dir`, recursively.
fn rust_files(dir: &std::path::Path) -> Vec<std::path::PathBuf> {
    let mut files = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for entry in std::fs::read_dir(&d).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                stack.push(path);
            } else if path.extension().is_some_and(|e| e == "rs") {
                files.push(path);
            }
        }
    }
    files
}

/// The words of `text` that can be Rust identifiers.
fn words(text: &str) -> impl Iterator<Item = &str> {
    text.split(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
        .filter(|w| !w.is_empty())
}

/// The top-level modules of each crate that another module of the same crate uses (through
/// `crate::module::…`, `crate::{…}` or a name the crate root re-exports from a module), and the
/// cycles among them: `[crate, a, b, …, a]`.
fn module_cycles() -> Vec<Vec<String>> {
    let mut cycles = Vec::new();
    let mut crates: Vec<_> = std::fs::read_dir(root().join("crates"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    crates.sort();
    for krate in crates {
        let src = krate.join("src");
        let name = krate.file_name().unwrap().to_string_lossy().into_owned();
        // Module name → its files.
        let mut modules: std::collections::BTreeMap<String, Vec<std::path::PathBuf>> =
            Default::default();
        for entry in std::fs::read_dir(&src).unwrap() {
            let path = entry.unwrap().path();
            let stem = path.file_stem().unwrap().to_string_lossy().into_owned();
            if path.is_dir() {
                modules.entry(stem).or_default().extend(rust_files(&path));
            } else if path.extension().is_some_and(|e| e == "rs") && stem != "lib" && stem != "main"
            {
                modules.entry(stem).or_default().push(path);
            }
        }
        let root_file = ["lib.rs", "main.rs"]
            .iter()
            .map(|f| src.join(f))
            .find(|p| p.exists())
            .unwrap();
        // Names the crate root re-exports: `pub use module::{A, B};`.
        let mut exported: std::collections::BTreeMap<String, String> = Default::default();
        let root_text = std::fs::read_to_string(root_file).unwrap();
        for part in root_text.split("pub use ").skip(1) {
            let statement = part.split(';').next().unwrap();
            if let Some((module, names)) = statement.split_once("::") {
                for word in words(names) {
                    exported.insert(word.to_owned(), module.trim().to_owned());
                }
            }
        }
        let mut edges: std::collections::BTreeMap<String, std::collections::BTreeSet<String>> =
            Default::default();
        for (module, files) in &modules {
            let text: String = files
                .iter()
                .map(|f| std::fs::read_to_string(f).unwrap())
                .flat_map(|t| {
                    t.lines()
                        .map(|l| l.split("//").next().unwrap_or("").to_owned() + "\n")
                        .collect::<Vec<_>>()
                })
                .collect();
            let mut used = std::collections::BTreeSet::new();
            for part in text.split("crate::").skip(1) {
                let names: &str = if let Some(list) = part.strip_prefix('{') {
                    list.split('}').next().unwrap()
                } else {
                    part.split(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
                        .next()
                        .unwrap()
                };
                for word in words(names) {
                    if modules.contains_key(word) {
                        used.insert(word.to_owned());
                    } else if let Some(m) = exported.get(word) {
                        used.insert(m.clone());
                    }
                }
            }
            used.remove(module);
            edges.insert(module.clone(), used);
        }
        // Every simple cycle, found once from its smallest module.
        fn walk(
            edges: &std::collections::BTreeMap<String, std::collections::BTreeSet<String>>,
            start: &str,
            path: &mut Vec<String>,
            found: &mut Vec<Vec<String>>,
        ) {
            let last = path.last().unwrap().clone();
            for next in edges.get(&last).into_iter().flatten() {
                if next == start {
                    found.push(path.iter().cloned().chain([next.clone()]).collect());
                } else if next.as_str() > start && !path.contains(next) {
                    path.push(next.clone());
                    walk(edges, start, path, found);
                    path.pop();
                }
            }
        }
        for start in edges.keys() {
            let mut found = Vec::new();
            walk(&edges, start, &mut vec![start.clone()], &mut found);
            for cycle in found {
                cycles.push([name.clone()].into_iter().chain(cycle).collect());
            }
        }
    }
    cycles
}

/// The modules of a crate use one another one way (their tests included): no import cycle.
#[test]
fn modules_within_a_crate_use_one_another_one_way() {
    let found: Vec<String> = module_cycles().iter().map(|c| c.join(" → ")).collect();
    assert!(found.is_empty(), "import cycles: {found:?}");
}

/// The binary holds arguments, printing and wiring; the libraries below it do neither. Structural
/// rules, not sizes: no library crate depends on an argument parser (clap); every crate takes
/// the workspace's lints (or, the Python bindings, the same ones of its own), which make printing (`print_stdout`, `print_stderr`) and an
/// undocumented public item (`missing_docs`) a warning that CI's clippy and doc steps refuse; and
/// no library source lifts the printing lints (build scripts, examples, tests and benches may).
#[test]
fn libraries_neither_parse_arguments_nor_print() {
    let manifest = read("Cargo.toml");
    for lint in [
        "missing_docs = \"warn\"",
        "print_stdout = \"warn\"",
        "print_stderr = \"warn\"",
    ] {
        assert!(manifest.contains(lint), "the workspace's lints lack {lint}");
    }
    let mut libraries = 0;
    for entry in std::fs::read_dir(root().join("crates")).unwrap() {
        let dir = entry.unwrap().path();
        let name = dir.file_name().unwrap().to_string_lossy().into_owned();
        let Ok(cargo) = std::fs::read_to_string(dir.join("Cargo.toml")) else {
            continue;
        };
        let cargo: toml::Table = toml::from_str(&cargo).unwrap();
        // The workspace's lints, or (the Python bindings, which must allow unsafe FFI code) the
        // same printing and documentation lints of its own.
        let lints = cargo.get("lints");
        let lint = |group: &str, name: &str| {
            lints
                .and_then(|l| l.get(group))
                .and_then(|g| g.get(name))
                .and_then(toml::Value::as_str)
                == Some("warn")
        };
        let workspace = lints
            .and_then(|l| l.get("workspace"))
            .and_then(toml::Value::as_bool)
            == Some(true);
        assert!(
            workspace
                || (lint("rust", "missing_docs")
                    && lint("clippy", "print_stdout")
                    && lint("clippy", "print_stderr")),
            "{name} takes neither the workspace's lints nor the printing and documentation ones"
        );
        if name == "seads-cli" {
            continue;
        }
        libraries += 1;
        let dependencies = cargo.get("dependencies").and_then(toml::Value::as_table);
        assert!(
            dependencies.is_none_or(|d| !d.contains_key("clap")),
            "{name} parses arguments (clap): that is the binary's job"
        );
        for file in rust_files(&dir.join("src")) {
            let text = std::fs::read_to_string(&file).unwrap();
            assert!(
                !text.contains("allow(clippy::print_stdout")
                    && !text.contains("clippy::print_stderr"),
                "{} lifts the printing lints: libraries below the binary never print",
                file.display()
            );
        }
    }
    assert!(libraries >= 7, "{libraries} library crates found");
}

/// Games are an open set: a game is one type in seads-games, listed once in its registry, and
/// no source outside that crate names a concrete game's type or builds one by name. The one
/// exception is the real robot (seads-uarm), whose tablet shows the paper's LightsOut 5×5, and
/// the Jaco arm's physical boards, which name the games they model. Everything else reaches a
/// game through `GameKind` and the `BoardGame` trait.
#[test]
fn no_game_is_named_outside_the_games_crate() {
    let types = ["LightsOut", "TileSwap", "SlidingPuzzle", "Gf2Solver"];
    let mut offenders = Vec::new();
    let mut checked = 0;
    for entry in std::fs::read_dir(root().join("crates")).unwrap() {
        let dir = entry.unwrap().path();
        let name = dir.file_name().unwrap().to_string_lossy().into_owned();
        if name == "seads-games" || name == "seads-uarm" {
            continue;
        }
        for file in rust_files(&dir.join("src")) {
            let text = std::fs::read_to_string(&file).unwrap();
            checked += 1;
            // Code only, tests apart: the words may appear in comments, docs, text and tests.
            let code = code_only(text.split("#[cfg(test)]").next().unwrap_or(""));
            let jaco_boards = name == "seads-embodiment"
                && (file.ends_with("registry.rs")
                    || file.ends_with("jaco.rs")
                    || file.starts_with(dir.join("src/jaco")));
            for word in words(&code) {
                if types.contains(&word) && !jaco_boards {
                    offenders.push(format!("{} names {word}", file.display()));
                }
            }
            if text
                .split("#[cfg(test)]")
                .next()
                .unwrap_or("")
                .lines()
                .any(|l| {
                    l.split("//")
                        .next()
                        .unwrap_or("")
                        .contains("GameKind::named(\"")
                })
                && !jaco_boards
            {
                offenders.push(format!("{} builds a game by name", file.display()));
            }
        }
    }
    assert!(checked > 50, "{checked} source files checked");
    assert!(offenders.is_empty(), "{offenders:#?}");
}

/// `source` without its comments and the contents of its string literals (a rough Rust lexer:
/// enough for names in code).
fn code_only(source: &str) -> String {
    let mut out = String::with_capacity(source.len());
    let mut chars = source.chars().peekable();
    let mut in_string = false;
    while let Some(c) = chars.next() {
        if in_string {
            match c {
                '\\' => {
                    chars.next();
                }
                '"' => {
                    in_string = false;
                    out.push('"');
                }
                '\n' => out.push('\n'),
                _ => {}
            }
        } else if c == '/' && chars.peek() == Some(&'/') {
            for rest in chars.by_ref() {
                if rest == '\n' {
                    out.push('\n');
                    break;
                }
            }
        } else if c == '"' {
            in_string = true;
            out.push('"');
        } else if c == '\'' {
            // A char literal ('"', '\\') or a lifetime: keep it out of the string state.
            out.push(c);
            let mut lookahead = chars.clone();
            match (lookahead.next(), lookahead.next(), lookahead.next()) {
                (Some('\\'), Some(_), Some('\'')) => {
                    chars.next();
                    chars.next();
                    chars.next();
                }
                (Some(_), Some('\''), _) => {
                    chars.next();
                    chars.next();
                }
                _ => {}
            }
        } else {
            out.push(c);
        }
    }
    out
}

/// Manipulators likewise: no source outside seads-embodiment names the Cursor, the Reacher or
/// the Jaco (the robot's crate has its own arm); everything else reaches them through the
/// environment registry and the `Environment` trait.
#[test]
fn no_manipulator_is_named_outside_the_embodiment_crate() {
    let types = ["Cursor", "Reacher", "Reacher3", "Jaco", "JacoBoard"];
    let mut offenders = Vec::new();
    let mut checked = 0;
    for entry in std::fs::read_dir(root().join("crates")).unwrap() {
        let dir = entry.unwrap().path();
        if dir.ends_with("seads-embodiment") {
            continue;
        }
        for file in rust_files(&dir.join("src")) {
            let text = std::fs::read_to_string(&file).unwrap();
            checked += 1;
            let code = code_only(text.split("#[cfg(test)]").next().unwrap_or(""));
            for word in words(&code).filter(|w| types.contains(w)) {
                offenders.push(format!("{} names {word}", file.display()));
            }
        }
    }
    assert!(checked > 50, "{checked} source files checked");
    assert!(offenders.is_empty(), "{offenders:#?}");
}

/// The methods a block of code defines: the names after `fn` in the braces that follow the first
/// line containing `head` (the braces counted in code only).
fn methods_in_block(file: &str, head: &str) -> Vec<String> {
    let code = code_only(&read(file));
    let start = code
        .find(head)
        .unwrap_or_else(|| panic!("{file} has no {head:?}"));
    let body = &code[start..];
    let open = body.find('{').unwrap();
    let block = &body[open..closing_brace(body, open)];
    let words: Vec<&str> = words(block).collect();
    words
        .windows(2)
        .filter(|w| w[0] == "fn")
        .map(|w| w[1].to_owned())
        .collect()
}

/// A wrapped environment (action noise, filming) forwards every method of `Environment` to the
/// one it wraps, defaults included, in the one generic impl of `wrapper.rs`: a method added to
/// the trait (as the state carried between episodes was) cannot be dropped by a layer.
#[test]
fn the_wrapper_forwards_every_method_of_the_environment() {
    let trait_methods = methods_in_block(
        "crates/seads-embodiment/src/embodied.rs",
        "pub trait Environment",
    );
    let forwarded = methods_in_block(
        "crates/seads-embodiment/src/wrapper.rs",
        "impl<L: Layer> Environment for Wrapped<L>",
    );
    assert!(trait_methods.len() >= 15, "{trait_methods:?}");
    let missing: Vec<_> = trait_methods
        .iter()
        .filter(|m| !forwarded.contains(m))
        .collect();
    assert!(missing.is_empty(), "Wrapped does not forward {missing:?}");
}

/// The end of the braces that open at `open` in `code` (counted in code only).
fn closing_brace(code: &str, open: usize) -> usize {
    let mut depth = 0;
    for (i, c) in code[open..].char_indices() {
        match c {
            '{' => depth += 1,
            '}' => depth -= 1,
            _ => {}
        }
        if depth == 0 {
            return open + i;
        }
    }
    code.len()
}

/// No panic of ours reaches Python as pyo3's `PanicException`, a `BaseException` that `except
/// Exception` misses (issue 82): every method of a `#[pymethods]` block and every
/// `#[pyfunction]` of the bindings that can fail (returns `PyResult`) runs its body through
/// `guarded`, which turns a panic into a `RuntimeError` (the Python test
/// `test_a_panic_of_ours_is_a_runtime_error_that_except_exception_catches` shows it does).
/// The infallible ones are getters of a field or a size.
#[test]
fn every_fallible_python_method_guards_its_body() {
    let mut checked = Vec::new();
    let mut unguarded = Vec::new();
    for file in rust_files(&root().join("crates/seads-py/src")) {
        let code = code_only(&std::fs::read_to_string(&file).unwrap());
        // The blocks: a #[pymethods] impl's braces, or a #[pyfunction]'s item.
        let mut blocks = Vec::new();
        for (at, _) in code.match_indices("#[pymethods]") {
            let open = at + code[at..].find('{').unwrap();
            blocks.push((open, closing_brace(&code, open)));
        }
        for (at, _) in code.match_indices("#[pyfunction]") {
            let item = at + code[at..].find("fn ").unwrap();
            let open = item + code[item..].find('{').unwrap();
            blocks.push((at, closing_brace(&code, open)));
        }
        for (start, end) in blocks {
            let block = &code[start..end];
            for (at, _) in block.match_indices("fn ") {
                let name: String = block[at + 3..]
                    .chars()
                    .take_while(|c| c.is_alphanumeric() || *c == '_')
                    .collect();
                let open = at + block[at..].find('{').unwrap();
                let signature = &block[at..open];
                if !signature.contains("PyResult<") {
                    continue;
                }
                let body = &block[open..closing_brace(block, open)];
                checked.push(name.clone());
                if !body
                    .trim_start_matches('{')
                    .trim_start()
                    .starts_with("crate::guarded(")
                    && !body
                        .trim_start_matches('{')
                        .trim_start()
                        .starts_with("guarded(")
                {
                    unguarded.push(format!("{}: {name}", file.display()));
                }
            }
        }
    }
    assert!(checked.len() >= 25, "{checked:?}");
    assert!(unguarded.is_empty(), "not guarded: {unguarded:#?}");
}

/// RESULTS' summary is the table that `seads summary` computes from each study's claims.toml
/// and committed runs: a number typed into it, or data committed without regenerating it, fails
/// here (regenerate with `seads summary --write docs/RESULTS.md`). RESULTS stays a reference of
/// at most 300 lines.
#[test]
fn results_summary_is_generated_from_the_data() {
    use seads_study::report::summary::{replace_summary, summary_table};
    let document = read("docs/RESULTS.md");
    let table = summary_table(&root().join("docs/results")).unwrap();
    let generated = replace_summary(&document, &table).unwrap();
    assert!(
        generated == document,
        "docs/RESULTS.md's summary differs from the data: run `seads summary --write docs/RESULTS.md`"
    );
    let lines = document.lines().count();
    assert!(
        lines <= 300,
        "docs/RESULTS.md has {lines} lines, more than 300"
    );
}
