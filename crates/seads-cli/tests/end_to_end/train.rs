//! `seads train` and `seads run`: run directories, resuming, bad input, devices, kernels, one writer, damaged checkpoints, and the golden run.

use crate::common::*;

#[test]
fn train_writes_a_run_directory_and_resumes() {
    let dir = tempfile::tempdir().unwrap();
    let run = dir.path().join("run");
    let config = tiny_config(dir.path());
    let out = seads_ok(&[
        "train",
        "--config",
        config.to_str().unwrap(),
        "--out",
        run.to_str().unwrap(),
        "--seed",
        "3",
        "--quiet",
    ]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains("coverage") && stdout.contains("time per phase"),
        "{stdout}"
    );
    let saved = std::fs::read_to_string(run.join("config.toml")).unwrap();
    assert!(saved.contains("seed = 3") && saved.contains("env_steps = 600"));
    let metrics = std::fs::read_to_string(run.join("metrics.jsonl")).unwrap();
    let last: serde_json::Value = serde_json::from_str(metrics.lines().last().unwrap()).unwrap();
    for key in ["epoch", "env_steps", "skill_coverage", "wall_s"] {
        assert!(last.get(key).is_some(), "metrics have {key}");
    }
    assert!(last["env_steps"].as_u64().unwrap() >= 600);
    assert!(run.join("checkpoints/latest").exists());
    // Resuming a finished run has nothing left to do but succeeds.
    seads_ok(&["train", "--resume", run.to_str().unwrap(), "--quiet"]);
    // Each training process names its code and processor, from where it started; a resume that
    // raises the budget adds a line from the checkpoint's epoch, one with nothing to do does not.
    seads_ok(&[
        "train",
        "--resume",
        run.to_str().unwrap(),
        "--env-steps",
        "900",
        "--quiet",
    ]);
    let provenance: Vec<serde_json::Value> = std::fs::read_to_string(run.join("provenance.jsonl"))
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(provenance.len(), 2, "{provenance:?}");
    assert_eq!(
        (
            provenance[0]["epoch"].as_u64(),
            provenance[0]["env_steps"].as_u64()
        ),
        (Some(0), Some(0))
    );
    assert_eq!(provenance[1]["epoch"], last["epoch"]);
    assert_eq!(provenance[1]["env_steps"], last["env_steps"]);
    // The commit the binary was built from: this checkout's HEAD (vergen's stand-in outside git).
    let head = std::process::Command::new("git")
        .args(["rev-parse", "HEAD"])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .ok()
        .filter(|o| o.status.success())
        .map_or("VERGEN_IDEMPOTENT_OUTPUT".to_owned(), |o| {
            String::from_utf8_lossy(&o.stdout).trim().to_owned()
        });
    for line in &provenance {
        assert_eq!(line["commit"], head.as_str());
        assert_eq!(line["portable_numerics"], true);
        assert!(line["logical_cpus"].as_u64().unwrap() >= 1);
    }
    // The same directory cannot be trained into twice.
    check_bad_input(
        &[
            "train",
            "--config",
            config.to_str().unwrap(),
            "--out",
            run.to_str().unwrap(),
        ],
        "already holds a run",
    );
}

#[test]
fn train_rejects_bad_input() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("x");
    check_bad_input(
        &[
            "train",
            "--env",
            "lightsout-robot",
            "--out",
            out.to_str().unwrap(),
        ],
        "valid environments",
    );
    let bad = dir.path().join("bad.toml");
    std::fs::write(&bad, "env = \"lightsout-cursor\"\n[sac]\nalpha = -1.0\n").unwrap();
    check_bad_input(
        &[
            "train",
            "--config",
            bad.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ],
        "sac.alpha",
    );
    std::fs::write(&bad, "env = \"lightsout-cursor\"\nlearning_rate = 3\n").unwrap();
    check_bad_input(
        &[
            "train",
            "--config",
            bad.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ],
        "unknown field",
    );
    // A run that is not there is the user's to fix: exit 2, naming what is missing.
    check_bad_input(
        &[
            "train",
            "--resume",
            dir.path().join("nothing").to_str().unwrap(),
        ],
        "config.toml",
    );
}

/// A budget of no step is refused before a directory is made (issue 82: such a run had no
/// checkpoint and never finished), and `seads run` on an existing run refuses an environment or
/// seed that is not the run's instead of silently resuming the run it found there.
#[test]
fn run_and_train_refuse_what_they_would_ignore() {
    let dir = tempfile::tempdir().unwrap();
    let config = tiny_config(dir.path());
    let new = dir.path().join("new");
    check_bad_input(
        &[
            "train",
            "--config",
            s(&config),
            "--env-steps",
            "0",
            "--out",
            s(&new),
        ],
        "env_steps must be at least 1",
    );
    check_bad_input(
        &["run", "--out", s(&new), "--env-steps", "0"],
        "env_steps must be at least 1",
    );
    assert!(!new.exists(), "no run directory made");
    let run = dir.path().join("run");
    copy_tiny_run(&run);
    let before = data_snapshot(&run);
    check_bad_input(
        &["run", "--out", s(&run), "--env", "tileswap-cursor"],
        "is a run of env lightsout-cursor, not tileswap-cursor",
    );
    check_bad_input(
        &["run", "--out", s(&run), "--seed", "7"],
        "is a run of seed 1, not 7",
    );
    check_bad_input(
        &["run", "--out", s(&run), "--env-steps", "10"],
        "a budget can only be raised",
    );
    assert_eq!(data_snapshot(&run), before, "the run is untouched");
}

/// A device that is not there, or not a device, is one line of bad input from every command
/// that runs networks, and nothing is written: this binary has no CUDA (no `cuda` feature),
/// GPU or not.
#[test]
fn devices_that_are_not_there_are_refused_before_anything_is_written() {
    // Its own copy of the shared run, which other tests write evaluations into meanwhile.
    let dir = tempfile::tempdir().unwrap();
    let run = dir.path().join("run");
    copy_tiny_run(&run);
    let run = run.to_str().unwrap();
    let out = dir.path().join("new");
    let out = out.to_str().unwrap();
    let before = std::fs::read_dir(run).unwrap().count();
    let no_cuda = "needs a CUDA build of seads";
    for device in ["cuda", "cuda:0", "cuda:3"] {
        check_bad_input(
            &[
                "train",
                "--env",
                "lightsout-cursor",
                "--out",
                out,
                "--device",
                device,
            ],
            no_cuda,
        );
        check_bad_input(&["train", "--resume", run, "--device", device], no_cuda);
        check_bad_input(&["evaluate", "--run", run, "--device", device], no_cuda);
        check_bad_input(
            &[
                "solve",
                "--run",
                run,
                "--board",
                "0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,1",
                "--device",
                device,
            ],
            no_cuda,
        );
        check_bad_input(
            &["plan-bench", "--depths", "1", "--device", device],
            no_cuda,
        );
    }
    for bad in ["gpu", "cuda:", "cuda:-1", "cuda:1.5", "CUDA 0"] {
        check_bad_input(
            &["evaluate", "--run", run, "--device", bad],
            "not one of cpu, cuda, cuda:N",
        );
        check_bad_input(
            &["sweep", "run", out, "--device", bad],
            "not one of cpu, cuda, cuda:N",
        );
        check_bad_input(
            &["sweep", "slurm", out, "--device", bad],
            "not one of cpu, cuda, cuda:N",
        );
    }
    // A device in a config file is checked as on the command line.
    let config = dir.path().join("gpu.toml");
    std::fs::write(&config, "env = \"lightsout-cursor\"\ndevice = \"cuda:1\"\n").unwrap();
    check_bad_input(
        &["train", "--config", config.to_str().unwrap(), "--out", out],
        no_cuda,
    );
    std::fs::write(&config, "env = \"lightsout-cursor\"\ndevice = \"tpu\"\n").unwrap();
    check_bad_input(
        &["train", "--config", config.to_str().unwrap(), "--out", out],
        "not one of cpu, cuda, cuda:N",
    );
    assert!(
        !std::path::Path::new(out).exists(),
        "a refused command wrote {out}"
    );
    assert_eq!(
        std::fs::read_dir(run).unwrap().count(),
        before,
        "a refused command wrote into the run"
    );
    // The CPU is always there, and a run's provenance says where it trained.
    let provenance =
        std::fs::read_to_string(std::path::Path::new(run).join("provenance.jsonl")).unwrap();
    assert!(
        provenance.lines().all(|l| l.contains("\"device\":\"cpu\"")),
        "{provenance}"
    );
}

/// The run's `portable_numerics` decides libtorch's kernels, not the environment the binary
/// inherits: a portable run gives the same numbers whatever MKL_CBWR says, and a fast run is
/// another run.
#[test]
fn the_run_decides_the_kernels() {
    let dir = tempfile::tempdir().unwrap();
    let portable = tiny_config(dir.path());
    let fast = dir.path().join("fast.toml");
    std::fs::write(
        &fast,
        std::fs::read_to_string(&portable)
            .unwrap()
            .replace("portable_numerics = true", "portable_numerics = false"),
    )
    .unwrap();
    let losses = |config: &std::path::Path, mkl: &str, name: &str| -> Vec<String> {
        let out = dir.path().join(name);
        // Long enough (~60 epochs) for the kernels' last-bit differences to show.
        let status = seads_command()
            .args(["train", "--quiet", "--env-steps", "3000", "--config"])
            .arg(config)
            .arg("--out")
            .arg(&out)
            .env("MKL_CBWR", mkl)
            .output()
            .unwrap()
            .status;
        assert!(status.success());
        std::fs::read_to_string(out.join("metrics.jsonl"))
            .unwrap()
            .lines()
            .map(|l| {
                let v: serde_json::Value = serde_json::from_str(l).unwrap();
                format!("{} {}", v["critic_loss"], v["skill_model_loss"])
            })
            .collect()
    };
    let a = losses(&portable, "AUTO", "a");
    assert_eq!(a, losses(&portable, "COMPATIBLE", "b"));
    assert_ne!(a, losses(&fast, "COMPATIBLE", "c"));
}

/// Training commands run with libgomp's short spin (`GOMP_SPINCOUNT=1000`, see `main.rs`) unless
/// the user chose a wait policy: read from the running process's environment.
#[cfg(target_os = "linux")]
#[test]
fn training_runs_with_a_short_openmp_spin() {
    let dir = tempfile::tempdir().unwrap();
    let spin_of = |user: Option<(&str, &str)>, out: &str| -> Option<String> {
        let mut command = seads_command();
        command
            .args(["train", "--env", "lightsout-cursor", "--quiet", "--out"])
            .arg(dir.path().join(out))
            .env_remove("GOMP_SPINCOUNT")
            .env_remove("OMP_WAIT_POLICY")
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::null());
        if let Some((name, value)) = user {
            command.env(name, value);
        }
        let mut child = command.spawn().unwrap();
        let environ = format!("/proc/{}/environ", child.id());
        let mut seen = None;
        for _ in 0..300 {
            let text = std::fs::read(&environ).unwrap_or_default();
            seen = text
                .split(|&b| b == 0)
                .find_map(|v| v.strip_prefix(b"GOMP_SPINCOUNT="))
                .map(|v| String::from_utf8_lossy(v).into_owned());
            if seen.is_some() || child.try_wait().unwrap().is_some() {
                break;
            }
            std::thread::sleep(std::time::Duration::from_millis(10));
        }
        let _ = child.kill();
        let _ = child.wait();
        seen
    };
    assert_eq!(spin_of(None, "a").as_deref(), Some("1000"));
    assert_eq!(
        spin_of(Some(("GOMP_SPINCOUNT", "7")), "b").as_deref(),
        Some("7")
    );
    assert_eq!(spin_of(Some(("OMP_WAIT_POLICY", "active")), "c"), None);
}

/// A checkpoint whose weights have other shapes than its config says is a malformed input:
/// exit 2 and one line, libtorch's C++ stack trace cut off.
#[test]
fn a_checkpoint_of_other_shapes_is_one_line_of_bad_input() {
    let dir = tempfile::tempdir().unwrap();
    let run = dir.path().join("run");
    copy_tiny_run(&run);
    let latest = std::fs::read_to_string(run.join("checkpoints/latest")).unwrap();
    let weights = run
        .join("checkpoints")
        .join(latest.trim())
        .join("forward_model.safetensors");
    // The same tensor names, each of shape [1, 1] (safetensors: a little-endian header length,
    // the JSON header, the data).
    let bytes = std::fs::read(&weights).unwrap();
    let length = u64::from_le_bytes(bytes[..8].try_into().unwrap()) as usize;
    let header: serde_json::Map<String, serde_json::Value> =
        serde_json::from_slice(&bytes[8..8 + length]).unwrap();
    let mut shrunk = serde_json::Map::new();
    let names: Vec<&String> = header.keys().filter(|k| *k != "__metadata__").collect();
    for (i, name) in names.iter().enumerate() {
        shrunk.insert(
            (*name).clone(),
            serde_json::json!({"dtype": "F32", "shape": [1, 1], "data_offsets": [4 * i, 4 * i + 4]}),
        );
    }
    let text = serde_json::to_vec(&shrunk).unwrap();
    let mut file = (text.len() as u64).to_le_bytes().to_vec();
    file.extend(&text);
    file.extend(vec![0u8; 4 * names.len()]);
    std::fs::write(&weights, file).unwrap();
    check_bad_input(
        &["evaluate", "--run", s(&run), "--boards", "1", "--quiet"],
        "forward_model",
    );
}

/// A checkpoint whose network file has one damaged tensor (a shape that merely broadcasts, a
/// scalar, NaN, an infinity, float64) is refused by every command that loads it, in one line of
/// bad input naming the file and the tensor (issue 82: the binary loaded the broadcasting shapes
/// and NaN without a word and executed skills with them, and panicked on float64).
#[test]
fn a_checkpoint_with_a_damaged_tensor_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    for file in ["forward_model.safetensors", "sac_actor.safetensors"] {
        for damage in [
            TensorDamage::Broadcast,
            TensorDamage::Scalar,
            TensorDamage::NotANumber,
            TensorDamage::Infinite,
            TensorDamage::Float64,
        ] {
            let run = dir.path().join(format!("{file}-{damage:?}"));
            copy_tiny_run(&run);
            let latest = std::fs::read_to_string(run.join("checkpoints/latest")).unwrap();
            let path = run.join("checkpoints").join(latest.trim()).join(file);
            let tensor = damage_tensor(&path, damage);
            let board = "1,1,1,1,0,1,1,1,0,0,1,1,0,0,0,1,0,1,0,1,1,0,1,1,1";
            for args in [
                vec!["evaluate", "--run", s(&run), "--boards", "1", "--quiet"],
                vec!["solve", "--run", s(&run), "--board", board],
            ] {
                let out = seads(&args);
                let stderr = String::from_utf8_lossy(&out.stderr);
                assert_eq!(
                    out.status.code(),
                    Some(2),
                    "{file} {damage:?} {args:?}: {stderr}"
                );
                assert_eq!(stderr.lines().count(), 1, "{stderr}");
                assert!(
                    stderr.contains(file) && stderr.contains(&tensor),
                    "{file} {damage:?}: {stderr}"
                );
            }
        }
    }
}

/// A budget or seed beyond a TOML integer (2⁶³ and up) is refused before anything is written: a
/// finished run keeps its readable config (and still evaluates), a new run is not created.
#[test]
fn budgets_and_seeds_beyond_a_toml_integer_are_refused_before_writing() {
    let dir = tempfile::tempdir().unwrap();
    let run = dir.path().join("run");
    copy_tiny_run(&run);
    let config = std::fs::read(run.join("config.toml")).unwrap();
    let huge = "9223372036854775808";
    check_bad_input(
        &["train", "--resume", s(&run), "--env-steps", huge],
        "a TOML integer",
    );
    assert_eq!(std::fs::read(run.join("config.toml")).unwrap(), config);
    seads_ok(&[
        "evaluate",
        "--run",
        s(&run),
        "--depths",
        "1",
        "--boards",
        "1",
        "--quiet",
    ]);
    let out = dir.path().join("new");
    for option in ["--seed", "--env-steps"] {
        check_bad_input(
            &[
                "train",
                "--env",
                "lightsout-cursor",
                "--out",
                s(&out),
                option,
                huge,
            ],
            "a TOML integer",
        );
        assert!(!out.exists(), "{option}: nothing written");
    }
}

/// Two `train` processes started together on one new directory, with seeds 1 and 2: exactly one
/// trains and the other exits 2 in one line without writing, so the run's config is the winner's
/// (three tries). A directory that holds a run's metrics and checkpoints but no config.toml is
/// never trained over.
#[test]
fn one_writer_wins_a_new_run_and_a_damaged_run_is_not_trained_over() {
    let dir = tempfile::tempdir().unwrap();
    let config = tiny_config(dir.path());
    for attempt in 0..3 {
        let out = dir.path().join(format!("race-{attempt}"));
        let children: Vec<_> = ["1", "2"]
            .map(|seed| {
                let child = seads_command()
                    .args([
                        "train",
                        "--config",
                        s(&config),
                        "--out",
                        s(&out),
                        "--seed",
                        seed,
                    ])
                    .arg("--quiet")
                    .stdout(std::process::Stdio::null())
                    .stderr(std::process::Stdio::piped())
                    .spawn()
                    .unwrap();
                (seed, child)
            })
            .into_iter()
            .collect();
        let ended: Vec<_> = children
            .into_iter()
            .map(|(seed, child)| (seed, child.wait_with_output().unwrap()))
            .collect();
        let winners: Vec<&str> = ended
            .iter()
            .filter(|(_, o)| o.status.success())
            .map(|(seed, _)| *seed)
            .collect();
        assert_eq!(winners.len(), 1, "attempt {attempt}: {ended:?}");
        let (_, loser) = ended.iter().find(|(_, o)| !o.status.success()).unwrap();
        let stderr = String::from_utf8_lossy(&loser.stderr);
        assert_eq!(loser.status.code(), Some(2), "{stderr}");
        assert_eq!(stderr.lines().count(), 1, "{stderr}");
        assert!(
            stderr.contains("in use") || stderr.contains("already holds a run"),
            "{stderr}"
        );
        let written = std::fs::read_to_string(out.join("config.toml")).unwrap();
        assert!(
            written.contains(&format!("\nseed = {}\n", winners[0])),
            "attempt {attempt}: the config is the winner's (seed {})",
            winners[0]
        );
        let provenance = std::fs::read_to_string(out.join("provenance.jsonl")).unwrap();
        assert_eq!(provenance.lines().count(), 1, "one process trained it");
    }
    let damaged = dir.path().join("damaged");
    copy_tiny_run(&damaged);
    std::fs::remove_file(damaged.join("config.toml")).unwrap();
    let metrics = std::fs::read(damaged.join("metrics.jsonl")).unwrap();
    check_bad_input(
        &["train", "--config", s(&config), "--out", s(&damaged)],
        "no config.toml",
    );
    assert_eq!(
        std::fs::read(damaged.join("metrics.jsonl")).unwrap(),
        metrics
    );
    assert!(!damaged.join("config.toml").exists());
}

/// The golden run in CI (issue 45 item 6): its first 100 epochs (`data/golden/config.toml`,
/// portable numerics, evaluated every 10 epochs) trained again by this build give every metrics
/// line of `data/golden/first-100.jsonl` (clock fields left out), on any processor; a difference
/// is named by its first epoch and field. `SEADS_BLESS_GOLDEN=1` writes this build's lines there
/// instead (after a change that is meant to alter training). The file must also agree with the
/// full golden `data/golden/metrics.jsonl` (`cargo xtask golden`) where both have the epoch.
#[test]
fn the_golden_runs_first_100_epochs_repeat_line_for_line() {
    const CLOCK: [&str; 3] = ["wall_s", "steps_per_s", "timings"];
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let golden = root.join("data/golden");
    let strip = |text: &str| -> Vec<serde_json::Map<String, serde_json::Value>> {
        text.lines()
            .map(|l| {
                let mut line: serde_json::Map<_, _> = serde_json::from_str(l).unwrap();
                line.retain(|k, _| !CLOCK.contains(&k.as_str()));
                line
            })
            .collect()
    };
    let dir = tempfile::tempdir().unwrap();
    let config = std::fs::read_to_string(golden.join("config.toml"))
        .unwrap()
        .replace("env_steps = 22000", "env_steps = 5016");
    assert!(
        config.contains("env_steps = 5016"),
        "the golden's budget line"
    );
    let config_path = dir.path().join("config.toml");
    std::fs::write(&config_path, config).unwrap();
    let run = dir.path().join("run");
    seads_ok(&[
        "train",
        "--config",
        s(&config_path),
        "--out",
        s(&run),
        "--quiet",
    ]);
    let text = std::fs::read_to_string(run.join("metrics.jsonl")).unwrap();
    let ours = strip(&text);
    assert_eq!(
        ours.last().unwrap()["epoch"],
        100,
        "the budget ends at epoch 100"
    );
    let first_100 = golden.join("first-100.jsonl");
    if std::env::var_os("SEADS_BLESS_GOLDEN").is_some() {
        let lines: String = ours
            .iter()
            .map(|l| serde_json::to_string(l).unwrap() + "\n")
            .collect();
        std::fs::write(&first_100, lines).unwrap();
    }
    let expected = strip(&std::fs::read_to_string(&first_100).unwrap());
    let full = strip(&std::fs::read_to_string(golden.join("metrics.jsonl")).unwrap());
    for (name, reference) in [("first-100.jsonl", &expected), ("metrics.jsonl", &full)] {
        for (want, got) in reference.iter().zip(&ours) {
            let epoch = &want["epoch"];
            for (field, value) in want {
                assert_eq!(
                    got.get(field),
                    Some(value),
                    "data/golden/{name}: epoch {epoch} parts at field {field:?} \
                     (SEADS_BLESS_GOLDEN=1 records this build's run if the change is meant)"
                );
            }
        }
    }
    assert_eq!(expected.len(), ours.len(), "every epoch of first-100.jsonl");
}
