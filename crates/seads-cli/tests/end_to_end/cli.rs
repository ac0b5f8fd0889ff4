//! End-to-end tests of the `seads` binary.

use crate::common::*;

#[test]
fn depths_json() {
    let v = json(&["games", "depths", "--game", "tileswap", "--json"]);
    assert_eq!(v["game"], "tileswap");
    assert_eq!(v["size"], 3);
    let counts: Vec<u64> = serde_json::from_value(v["counts"].clone()).unwrap();
    assert_eq!(counts.len(), 17);
    assert_eq!(counts[..4], [1, 12, 88, 470]);
    let v = json(&[
        "games",
        "depths",
        "--game",
        "lightsout",
        "--size",
        "4",
        "--json",
    ]);
    assert_eq!(
        v["counts"]
            .as_array()
            .unwrap()
            .iter()
            .map(|c| c.as_u64().unwrap())
            .sum::<u64>(),
        1 << 12
    );
}

#[test]
fn split_json() {
    let v = json(&["games", "split", "--game", "lightsout", "--json"]);
    assert_eq!(v["train"], serde_json::json!([7, 99, 785, 4200, 17849]));
    assert_eq!(v["test"], serde_json::json!([18, 201, 1515, 8450, 35281]));
    let v = json(&[
        "games",
        "split",
        "--game",
        "tileswap",
        "--max-depth",
        "2",
        "--json",
    ]);
    assert_eq!(v["train"], serde_json::json!([7, 31]));
}

/// A depth beyond the game's farthest board is one line of bad input, found before the table is
/// allocated (issue 82: `--max-depth 18446744073709551615` panicked with "capacity overflow" and
/// `--max-depth 100000000` grew to 4.5 GB without a word); the farthest depth itself is fine.
#[test]
fn a_split_beyond_the_farthest_board_is_refused() {
    for depth in ["18446744073709551615", "100000000", "10"] {
        check_bad_input(
            &[
                "games",
                "split",
                "--game",
                "lightsout",
                "--size",
                "3",
                "--max-depth",
                depth,
            ],
            "the farthest is 9 moves from the goal",
        );
    }
    let v = json(&[
        "games",
        "split",
        "--game",
        "lightsout",
        "--size",
        "3",
        "--max-depth",
        "9",
        "--json",
    ]);
    let boards: u64 = ["train", "test"]
        .iter()
        .flat_map(|s| v[s].as_array().unwrap().iter().map(|n| n.as_u64().unwrap()))
        .sum();
    assert_eq!(boards, 511, "every 3×3 board but the goal");
}

#[test]
fn solve_json_and_table() {
    let board = "1,1,0,0,0,1,0,0,0,0,0,0,1,0,0,0,1,1,1,0,0,0,1,0,0";
    let v = json(&[
        "games",
        "solve",
        "--game",
        "lightsout",
        "--board",
        board,
        "--json",
    ]);
    assert_eq!(v["moves"], serde_json::json!([0, 17]));
    assert_eq!(v["depth"], 2);
    let v = json(&[
        "games",
        "solve",
        "--game",
        "tileswap",
        "--board",
        "3,1,2,0,4,5,6,7,8",
        "--json",
    ]);
    assert_eq!(v["moves"], serde_json::json!([0]));
    let out = seads(&[
        "games",
        "solve",
        "--game",
        "tileswap",
        "--board",
        "0,1,2,3,4,5,6,7,8",
    ]);
    assert!(String::from_utf8_lossy(&out.stdout).contains("already solved"));
}

#[test]
fn bad_boards_get_one_line_and_exit_code_2() {
    check_bad_input(
        &["games", "solve", "--game", "lightsout", "--board", "1,0,1"],
        "has 25 fields, got 3",
    );
    let two = format!("2{}", ",0".repeat(24));
    check_bad_input(
        &["games", "solve", "--game", "lightsout", "--board", &two],
        "0 or 1",
    );
    check_bad_input(
        &[
            "games",
            "solve",
            "--game",
            "tileswap",
            "--board",
            "0,1,2,3,4,5,6,7,7",
        ],
        "exactly once",
    );
    check_bad_input(
        &[
            "games",
            "solve",
            "--game",
            "tileswap",
            "--board",
            "0,1,2,3,a,5,6,7,8",
        ],
        "field 4",
    );
    let corner = format!("1{}", ",0".repeat(24));
    check_bad_input(
        &["games", "solve", "--game", "lightsout", "--board", &corner],
        "cannot be solved",
    );
    check_bad_input(
        &["games", "depths", "--game", "lightsout", "--size", "7"],
        "infeasible",
    );
    check_bad_input(
        &["games", "depths", "--game", "tileswap", "--size", "4"],
        "size 4",
    );
}

#[test]
fn usage_errors_are_one_line_with_exit_code_2() {
    check_bad_input(&["games", "depths", "--game", "chess"], "unknown game");
    check_bad_input(&["trian"], "unrecognized subcommand 'trian'");
    // A message that lists what is missing keeps the list on its line.
    check_bad_input(
        &["evaluate"],
        "required arguments were not provided: --run <RUN>",
    );
    check_bad_input(&["evaluate", "--run", "r", "--boards", "x"], "--boards");
    // Help is not an error.
    let out = seads(&["evaluate", "--help"]);
    assert_eq!(out.status.code(), Some(0));
    assert!(String::from_utf8_lossy(&out.stdout).contains("--replan"));
}

#[test]
fn envs_json_lists_every_environment() {
    let v = json(&["envs", "--json"]);
    let names: Vec<&str> = v
        .as_array()
        .unwrap()
        .iter()
        .map(|e| e["name"].as_str().unwrap())
        .collect();
    assert_eq!(
        names,
        [
            "lightsout-cursor",
            "tileswap-cursor",
            "sliding-cursor",
            "lightsout-reacher",
            "tileswap-reacher",
            "sliding-reacher",
            "lightsout-reacher3",
            "tileswap-reacher3",
            "sliding-reacher3",
            "lightsout-jaco",
            "tileswap-jaco",
            "lightsout3d-jaco"
        ]
    );
    let obs_dim = |name: &str| v[names.iter().position(|&n| n == name).unwrap()]["obs_dim"].clone();
    assert_eq!(obs_dim("lightsout-cursor"), 28);
    assert_eq!(obs_dim("tileswap-jaco"), 124);
    // The 8-puzzle under the Cursor: its position (2), 81 one-hot bits, the time left.
    assert_eq!(obs_dim("sliding-cursor"), 84);
    assert_eq!(v[2]["title"], "SlidingCursor");
    // The three-link arm: its joint angles and velocities (6), 25 lights, the time left.
    assert_eq!(obs_dim("lightsout-reacher3"), 32);
    assert_eq!(v[6]["title"], "LightsOutReacher3");
}

#[test]
fn render_writes_png_and_svg() {
    let dir = tempfile::tempdir().unwrap();
    for (env, file) in [("tileswap-cursor", "a.png"), ("lightsout-reacher", "b.svg")] {
        let out = dir.path().join(file);
        seads_ok(&[
            "render",
            "--env",
            env,
            "--seed",
            "2",
            "--out",
            out.to_str().unwrap(),
        ]);
        let bytes = std::fs::read(&out).unwrap();
        if file.ends_with(".png") {
            assert_eq!(&bytes[1..4], b"PNG");
        } else {
            let text = String::from_utf8(bytes).unwrap();
            assert!(text.contains("<svg") && text.contains("lightsout-reacher"));
        }
    }
    // LightsOut3DJaco's raised and recessed fields get a side view under the top view.
    let png_height = |path: &std::path::Path| {
        let bytes = std::fs::read(path).unwrap();
        u32::from_be_bytes(bytes[20..24].try_into().unwrap())
    };
    let (flat, stairs) = (dir.path().join("flat.png"), dir.path().join("stairs.png"));
    seads_ok(&["render", "--env", "lightsout-jaco", "--out", s(&flat)]);
    seads_ok(&["render", "--env", "lightsout3d-jaco", "--out", s(&stairs)]);
    assert_eq!((png_height(&flat), png_height(&stairs)), (640, 880));
    let svg = dir.path().join("stairs.svg");
    seads_ok(&["render", "--env", "lightsout3d-jaco", "--out", s(&svg)]);
    assert!(std::fs::read_to_string(&svg).unwrap().contains("side view"));
    check_bad_input(
        &["render", "--env", "lightsout-robot", "--out", "x.png"],
        "valid environments: lightsout-cursor",
    );
    check_bad_input(
        &[
            "render",
            "--env",
            "lightsout-cursor",
            "--board-size",
            "6",
            "--out",
            "x.png",
        ],
        "odd sizes",
    );
}

#[test]
fn env_bench_reports_steps_per_second() {
    let v = json(&[
        "env-bench",
        "--env",
        "tileswap-reacher",
        "--steps",
        "20000",
        "--threads",
        "2",
        "--json",
    ]);
    assert_eq!(v["env"], "tileswap-reacher");
    assert_eq!(v["steps"], 20000);
    assert!(v["steps_per_sec"].as_f64().unwrap() > 0.0);
    check_bad_input(
        &["env-bench", "--env", "lightsout-cursor", "--threads", "0"],
        "at least 1",
    );
    // Threads beyond the machine are refused before any is spawned (issue 82: 10⁸ grew to
    // 12.7 GB).
    for huge in ["100000000", "18446744073709551615"] {
        check_bad_input(
            &[
                "env-bench",
                "--env",
                "lightsout-reacher3",
                "--threads",
                huge,
            ],
            "more than this machine can run",
        );
    }
    // A manipulator's options are its own: the Cursor has none, the Jaco's must fit its type.
    check_bad_input(
        &[
            "env-bench",
            "--env",
            "lightsout-cursor",
            "--manipulator",
            "physics_substeps=25",
        ],
        "unknown field `physics_substeps`",
    );
    for bad in [
        "physics_substeps=-1",
        "physics_substeps=0",
        "physics_substeps=nan",
    ] {
        check_bad_input(
            &["env-bench", "--env", "lightsout-jaco", "--manipulator", bad],
            "invalid manipulator options",
        );
    }
    check_bad_input(
        &[
            "env-bench",
            "--env",
            "lightsout-jaco",
            "--manipulator",
            "physics_substeps",
        ],
        "KEY=VALUE",
    );
    let v = json(&[
        "env-bench",
        "--env",
        "lightsout-jaco",
        "--manipulator",
        "physics_substeps=5",
        "--steps",
        "20",
        "--json",
    ]);
    assert_eq!(v["steps"], 20);
}

/// A tiny training configuration (small networks, small budget) written into `dir`.
fn tiny_config(dir: &std::path::Path) -> std::path::PathBuf {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../configs/lightsout-cursor.toml"
    ))
    .unwrap()
    .replace("env_steps = 500000", "env_steps = 600")
    .replace("hidden = [256, 256]", "hidden = [32, 32]")
    .replace("sampled_episodes = 256", "sampled_episodes = 32")
    .replace("recent_episodes = 256", "recent_episodes = 16")
    .replace("eval_every = 100", "eval_every = 5")
    .replace("checkpoint_every = 100", "checkpoint_every = 5")
    .replace("eval_seeds = 20", "eval_seeds = 1")
    // Tests run side by side: SAC taking a second thread would oversubscribe the cores.
    .replace("sac_threads_alone = 2", "sac_threads_alone = 0")
    .replace("portable_numerics = false", "portable_numerics = true");
    let path = dir.join("tiny.toml");
    std::fs::write(&path, text).unwrap();
    path
}

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

/// A copy of the shared tiny run at `to`, for a test that writes into it.
fn copy_tiny_run(to: &std::path::Path) {
    copy_dir(&tiny_run().join("run"), to);
}

/// The stem of the files [`evaluate_two_boards_of_depths_1_2`] writes: named by every part of
/// its protocol that departs from the standard one.
const TWO_BOARDS: &str = "evaluation-replan-depths-1-2-boards-2-expanded-2000";

/// `seads evaluate --json` of `run` with re-planning on 2 boards of depths 1 and 2 (searches
/// bounded by 2,000 states); it writes [`TWO_BOARDS`]`*` into the run.
fn evaluate_two_boards_of_depths_1_2(run: &str) -> serde_json::Value {
    serde_json::from_slice(&evaluate_two_boards_of_depths_1_2_output(run).stdout).unwrap()
}

/// What [`evaluate_two_boards_of_depths_1_2`] prints, standard error included.
fn evaluate_two_boards_of_depths_1_2_output(run: &str) -> std::process::Output {
    seads_ok(&[
        "evaluate",
        "--run",
        run,
        "--depths",
        "1-2",
        "--boards",
        "2",
        "--max-expanded",
        "2000",
        "--replan",
        "--json",
    ])
}

/// One tiny trained run shared by the planning tests.
fn tiny_run() -> &'static std::path::Path {
    static RUN: std::sync::OnceLock<tempfile::TempDir> = std::sync::OnceLock::new();
    RUN.get_or_init(|| {
        let dir = tempfile::tempdir().unwrap();
        let config = tiny_config(dir.path());
        let run = dir.path().join("run");
        seads_ok(&[
            "train",
            "--config",
            config.to_str().unwrap(),
            "--out",
            run.to_str().unwrap(),
            "--quiet",
        ]);
        dir
    })
    .path()
}

#[test]
fn solve_evaluate_and_plot_a_trained_run() {
    let run = tiny_run().join("run");
    let run = run.to_str().unwrap();
    let board = "1,1,0,0,0,1,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0";
    let v = json(&[
        "solve",
        "--run",
        run,
        "--board",
        board,
        "--replan",
        "--max-expanded",
        "2000",
        "--json",
    ]);
    assert_eq!(v["board"], board);
    // The same solution as an animation: the start, a frame per manipulator step, the last held.
    let dir = tempfile::tempdir().unwrap();
    let gif_path = dir.path().join("solution.gif");
    let animated = json(&[
        "solve",
        "--run",
        run,
        "--board",
        board,
        "--replan",
        "--max-expanded",
        "2000",
        "--json",
        "--render",
        s(&gif_path),
    ]);
    let steps = animated["manipulator_steps"].as_u64().unwrap() as usize;
    let mut decoder = gif::DecodeOptions::new()
        .read_info(std::fs::File::open(&gif_path).unwrap())
        .unwrap();
    let mut frames = 0;
    while decoder.read_next_frame().unwrap().is_some() {
        frames += 1;
    }
    assert_eq!(frames, 1 + steps + 9, "{animated}");
    // Every skill as a clip: from each start, its first scene, a frame per step, the end twice.
    let skills_gif = dir.path().join("skills.gif");
    let out = seads_ok(&[
        "plot",
        "--run",
        run,
        "--animate",
        s(&skills_gif),
        "--starts",
        "2",
    ]);
    let mut decoder = gif::DecodeOptions::new()
        .read_info(std::fs::File::open(&skills_gif).unwrap())
        .unwrap();
    let mut clips = 0;
    while decoder.read_next_frame().unwrap().is_some() {
        clips += 1;
    }
    let k = 25;
    assert!(clips >= k * 2 * 4, "{clips} frames");
    assert!(String::from_utf8_lossy(&out.stdout).contains(&format!("({clips} frames)")));
    check_bad_input(&["plot", "--run", run, "--animate", "skills.png"], ".gif");
    // An output that cannot be written is refused before the work, in one line naming it (issue
    // 82: `--render /dev/null` and `--render nodir/x.gif` failed only after the whole solve, and
    // `--render` wrote into the agent's run): a special file, a folder that is not there, the run
    // itself, a format that is not drawn.
    let missing = dir.path().join("nodir/x.gif");
    let inside = std::path::Path::new(run).join("solution.gif");
    let text = dir.path().join("solution.txt");
    for (out, why) in [
        ("/dev/null", "a special file"),
        (s(&missing), "does not exist"),
        (s(&inside), "lies inside"),
        (s(&text), "the output must be a ."),
    ] {
        check_bad_input(
            &["solve", "--run", run, "--board", board, "--render", out],
            why,
        );
        check_bad_input(&["plot", "--run", run, "--animate", out], why);
    }
    assert!(!inside.exists() && !missing.exists());
    // More clips than an animation holds: the frames it holds are said, never cut silently.
    let many = dir.path().join("many.gif");
    let out = seads_ok(&[
        "plot",
        "--run",
        run,
        "--animate",
        s(&many),
        "--starts",
        "20",
    ]);
    let said = String::from_utf8_lossy(&out.stdout);
    let mut decoder = gif::DecodeOptions::new()
        .read_info(std::fs::File::open(&many).unwrap())
        .unwrap();
    let mut held = 0;
    while decoder.read_next_frame().unwrap().is_some() {
        held += 1;
    }
    assert!(
        said.contains(&format!("({held} of ")) && said.contains("left out"),
        "{held}: {said}"
    );
    check_bad_input(&["plot", "--run", run], "--out");
    assert!(
        !std::fs::read_dir(dir.path())
            .unwrap()
            .any(|e| { e.unwrap().file_name().to_string_lossy().contains("tmp") })
    );
    for key in [
        "solved",
        "plan_found",
        "executed",
        "skill_steps",
        "manipulator_steps",
        "planning_s",
    ] {
        assert!(v.get(key).is_some(), "solve reports {key}");
    }
    let v = evaluate_two_boards_of_depths_1_2(run);
    for key in [
        "success_rate",
        "plan_found",
        "planning_s",
        "solution_steps",
        "skill_steps",
    ] {
        assert_eq!(
            v[key].as_object().unwrap().len(),
            2,
            "{key} has depths 1 and 2"
        );
    }
    let rate = v["success_rate"]["1"].as_f64().unwrap();
    assert!((0.0..=1.0).contains(&rate));
    // One line per task, with what every skill did against the model's prediction: with
    // re-planning, each deviation of a solved task cost one more search.
    let tasks =
        std::fs::read_to_string(tiny_run().join(format!("run/{TWO_BOARDS}-tasks.jsonl"))).unwrap();
    let tasks: Vec<serde_json::Value> = tasks
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(tasks.len(), 4, "2 boards x depths 1 and 2");
    for task in &tasks {
        let deviations = task["deviations"].as_array().unwrap();
        for d in deviations {
            assert_ne!(d["predicted"], d["reached"], "{task}");
        }
        if task["solved"] == true {
            assert_eq!(
                task["plans"].as_u64().unwrap(),
                1 + deviations.len() as u64,
                "{task}"
            );
        }
        assert_eq!(task["board"].as_str().unwrap().split(',').count(), 25);
    }
    let figures = tiny_run().join("figures");
    seads_ok(&[
        "plot",
        "--run",
        run,
        "--out",
        figures.to_str().unwrap(),
        "--boards",
        "1",
        "--max-expanded",
        "2000",
    ]);
    for name in ["coverage", "success", "trajectories", "pushes"] {
        assert_eq!(
            &std::fs::read(figures.join(format!("{name}.png"))).unwrap()[1..4],
            b"PNG"
        );
        assert!(
            std::fs::read_to_string(figures.join(format!("{name}.svg")))
                .unwrap()
                .contains("<svg")
        );
    }
}

#[test]
fn planning_commands_reject_bad_input() {
    let run = tiny_run().join("run");
    let run = run.to_str().unwrap();
    check_bad_input(
        &["solve", "--run", run, "--board", "1,0"],
        "has 25 fields, got 2",
    );
    check_bad_input(&["evaluate", "--run", run, "--depths", "five"], "--depths");
    check_bad_input(&["evaluate", "--run", run, "--depths", "0-2"], "--depths");
    check_bad_input(
        &["solve", "--run", "/nonexistent/run", "--board", "0,0"],
        "loading run /nonexistent/run",
    );
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

#[test]
fn record_and_replay_round_trip() {
    let dir = tempfile::tempdir().unwrap();
    for env in ["tileswap-cursor", "lightsout-reacher"] {
        let rec = dir.path().join(format!("{env}.jsonl"));
        let re = dir.path().join(format!("{env}.re.jsonl"));
        seads_ok(&[
            "record",
            "--env",
            env,
            "--episodes",
            "2",
            "--steps",
            "50",
            "--seed",
            "4",
            "--out",
            rec.to_str().unwrap(),
        ]);
        let out = seads_ok(&[
            "replay",
            "--env",
            env,
            "--input",
            rec.to_str().unwrap(),
            "--out",
            re.to_str().unwrap(),
            "--compare",
        ]);
        assert!(String::from_utf8_lossy(&out.stdout).contains("0 board and 0 move mismatches"));
        assert_eq!(
            std::fs::read_to_string(&rec).unwrap(),
            std::fs::read_to_string(&re).unwrap()
        );
        let first: serde_json::Value = serde_json::from_str(
            std::fs::read_to_string(&rec)
                .unwrap()
                .lines()
                .next()
                .unwrap(),
        )
        .unwrap();
        assert_eq!(first["steps"].as_array().unwrap().len(), 50);
        assert!(first["steps"][0].get("move").is_some());
    }
}

#[test]
fn replay_reports_bad_lines_with_their_number() {
    let dir = tempfile::tempdir().unwrap();
    let good = dir.path().join("good.jsonl");
    let out = seads(&[
        "record",
        "--env",
        "lightsout-cursor",
        "--episodes",
        "1",
        "--steps",
        "3",
        "--out",
        good.to_str().unwrap(),
    ]);
    assert!(out.status.success());
    let line = std::fs::read_to_string(&good).unwrap();
    let line = line.trim();
    // A replay that fails leaves its output as it was: never half-written.
    let out_file = dir.path().join("out.jsonl");
    std::fs::write(&out_file, "an earlier replay\n").unwrap();
    let cases = [
        (format!("{line}\n{{not json\n"), ":2: not an episode"),
        (
            format!(
                "{line}\n\n{}\n",
                line.replace("\"initial_obs\":[", "\"initial_obs\":[0.5,")
            ),
            ":3: initial_obs has 28 values",
        ),
        (
            line.replace("lightsout-cursor", "tileswap-cursor"),
            ":1: the episode is of environment \"tileswap-cursor\"",
        ),
    ];
    for (content, needle) in cases {
        let input = dir.path().join("bad.jsonl");
        std::fs::write(&input, content).unwrap();
        check_bad_input(
            &[
                "replay",
                "--env",
                "lightsout-cursor",
                "--input",
                input.to_str().unwrap(),
                "--out",
                out_file.to_str().unwrap(),
            ],
            needle,
        );
        assert_eq!(
            std::fs::read_to_string(&out_file).unwrap(),
            "an earlier replay\n",
            "{needle}"
        );
    }
    check_bad_input(
        &[
            "replay",
            "--env",
            "chess-robot",
            "--input",
            good.to_str().unwrap(),
            "--out",
            out_file.to_str().unwrap(),
        ],
        "valid environments",
    );
    let jaco = dir.path().join("jaco.jsonl");
    seads_ok(&[
        "record",
        "--env",
        "lightsout-jaco",
        "--episodes",
        "1",
        "--steps",
        "1",
        "--out",
        jaco.to_str().unwrap(),
    ]);
    check_bad_input(
        &[
            "replay",
            "--env",
            "lightsout-jaco",
            "--input",
            jaco.to_str().unwrap(),
            "--out",
            out_file.to_str().unwrap(),
        ],
        "not supported",
    );
    // An output that is the input (issue 32: it left the input empty), through another path too.
    let before = std::fs::read(&good).unwrap();
    let same = dir.path().join(".").join("good.jsonl");
    for out in [&good, &same] {
        check_bad_input(
            &[
                "replay",
                "--env",
                "lightsout-cursor",
                "--input",
                good.to_str().unwrap(),
                "--out",
                out.to_str().unwrap(),
            ],
            "never overwrites its input",
        );
    }
    assert_eq!(std::fs::read(&good).unwrap(), before, "the input is intact");
}

#[test]
fn uarm_twin_calibrates_and_trains() {
    let dir = tempfile::tempdir().unwrap();
    let cal = dir.path().join("cal.toml");
    seads_ok(&[
        "uarm",
        "calibrate",
        "--port",
        "sim",
        "--out",
        cal.to_str().unwrap(),
    ]);
    assert!(
        std::fs::read_to_string(&cal)
            .unwrap()
            .contains("corners = [[160.0, 108.5, 5.0]")
    );
    let run = dir.path().join("run");
    let out = seads_ok(&[
        "uarm",
        "train",
        "--port",
        "sim:3",
        "--calibration",
        cal.to_str().unwrap(),
        "--env-steps",
        "12",
        "--boards",
        "1",
        "--max-expanded",
        "2000",
        "--out",
        run.to_str().unwrap(),
        "--quiet",
    ]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("of 5 boards with re-planning"), "{stdout}");
    assert!(
        std::fs::read_to_string(run.join("config.toml"))
            .unwrap()
            .contains("uarm-lightsout-absolute")
    );
    // The preset unless asked otherwise (the pen seen only:
    // `a_new_robot_run_sees_what_its_action_space_needs`), recorded for a resume.
    assert_eq!(
        std::fs::read_to_string(run.join("robot.toml")).unwrap(),
        "action_space = \"absolute\"\nreset_board = false\nobserve = \"pen\"\n"
    );
    // A robot run has figures and a report too: what its directory holds. Its success figure
    // shows the evaluation of the protocol asked for (issue 82): the standard one was not made,
    // so there is none, and said so.
    let figures = dir.path().join("figures");
    let out = seads_ok(&["plot", "--run", s(&run), "--out", s(&figures)]);
    let said = String::from_utf8_lossy(&out.stderr);
    assert!(said.contains("no evaluation of epoch"), "{said}");
    assert!(!figures.join("success.png").exists());
    // Success as `uarm train` measured it; the skills as the twin executes them.
    let limits = ["--boards", "1", "--max-expanded", "2000"];
    seads_ok(
        &[
            &["plot", "--run", s(&run), "--out", s(&figures)][..],
            &limits,
        ]
        .concat(),
    );
    for f in ["coverage", "success", "trajectories", "pushes"] {
        assert!(figures.join(format!("{f}.png")).is_file(), "{f}");
    }
    const RESULTS: &str = "evaluation-replan-boards-1-expanded-2000.json";
    let evaluation: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(run.join(RESULTS)).unwrap()).unwrap();
    let tasks: u64 = evaluation["results"]
        .as_array()
        .unwrap()
        .iter()
        .map(|d| d["tasks"].as_u64().unwrap())
        .sum();
    assert_eq!(tasks, 5, "{evaluation}");
    assert_eq!(evaluation["protocol"]["tasks"]["boards"], 1, "{evaluation}");
    let report = dir.path().join("report");
    seads_ok(&["report", s(&run), "--out", s(&report), "--copy-runs"]);
    let md = std::fs::read_to_string(report.join("report.md")).unwrap();
    assert!(md.contains("uarm-lightsout-absolute (of 25)"), "{md}");
    for f in [
        "config.toml",
        "robot.toml",
        "metrics.jsonl",
        "provenance.jsonl",
        RESULTS,
    ] {
        assert!(report.join("runs/run").join(f).is_file(), "{f}");
    }
    // Planning commands name a robot run as such (issue 82: "unknown environment").
    let board = "1,1,1,1,0,1,1,1,0,0,1,1,0,0,0,1,0,1,0,1,1,0,1,1,1";
    for args in [
        vec!["solve", "--run", s(&run), "--board", board],
        vec!["evaluate", "--run", s(&run), "--boards", "1"],
    ] {
        check_bad_input(&args, "is a robot run (uarm-lightsout-absolute)");
    }
    // The report takes the run's one evaluation of another protocol, and names it.
    assert!(
        md.contains("| re-planning | boards-1, expanded-2000 | 1 |"),
        "{md}"
    );
}

/// A resumed robot run acts as it was trained: resuming a displacement run without
/// `--action-space` is not an absolute-push run refused as foreign.
#[test]
fn a_resumed_robot_run_keeps_its_action_space() {
    let dir = tempfile::tempdir().unwrap();
    let run = dir.path().join("run");
    let train = |extra: &[&str]| {
        let mut args = vec![
            "uarm",
            "train",
            "--port",
            "sim:2",
            "--env-steps",
            "12",
            "--boards",
            "1",
            "--max-expanded",
            "2000",
            "--out",
            s(&run),
            "--quiet",
        ];
        args.extend_from_slice(extra);
        seads_ok(&args)
    };
    train(&["--action-space", "displacement", "--reset-board"]);
    let out = train(&["--resume"]);
    assert!(
        String::from_utf8_lossy(&out.stdout).contains("of 5 boards with re-planning"),
        "{out:?}"
    );
    let settings = std::fs::read_to_string(run.join("robot.toml")).unwrap();
    assert!(settings.contains("displacement") && settings.contains("reset_board = true"));
    assert!(
        std::fs::read_to_string(run.join("config.toml"))
            .unwrap()
            .contains("uarm-lightsout-displacement")
    );
    // An earlier checkpoint evaluated on its own, beside the final evaluation (issue 32: it
    // took the final evaluation's file).
    let (last, earlier) = add_an_earlier_checkpoint(&run);
    const RESULTS: &str = "evaluation-replan-boards-1-expanded-2000.json";
    let final_evaluation = std::fs::read_to_string(run.join(RESULTS)).unwrap();
    let evaluate = |extra: &[&str]| {
        let mut args = vec![
            "uarm",
            "evaluate",
            "--port",
            "sim:2",
            "--run",
            s(&run),
            "--boards",
            "1",
            "--max-expanded",
            "2000",
            "--quiet",
        ];
        args.extend_from_slice(extra);
        args.iter().map(|a| a.to_string()).collect::<Vec<_>>()
    };
    let args = evaluate(&["--checkpoint", &earlier.to_string()]);
    seads_ok(&args.iter().map(String::as_str).collect::<Vec<_>>());
    let record: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(run.join(format!(
            "evaluation-replan-boards-1-expanded-2000-epoch-{earlier:06}.json"
        )))
        .unwrap(),
    )
    .unwrap();
    assert_eq!(record["checkpoint"]["epoch"], earlier, "{record}");
    assert_eq!(
        std::fs::read_to_string(run.join(RESULTS)).unwrap(),
        final_evaluation,
        "the final evaluation is untouched"
    );
    let final_record: serde_json::Value = serde_json::from_str(&final_evaluation).unwrap();
    assert_eq!(final_record["checkpoint"]["epoch"], last, "{final_record}");
    let args = evaluate(&["--checkpoint", "999999"]);
    check_bad_input(
        &args.iter().map(String::as_str).collect::<Vec<_>>(),
        "no checkpoint of epoch 999999",
    );
}

#[test]
fn a_vic_run_is_plotted_and_reported_without_planning() {
    let dir = tempfile::tempdir().unwrap();
    let config = tiny_config(dir.path());
    let text = std::fs::read_to_string(&config).unwrap().replace(
        "[seads.skill_model]\nkind = \"forward\"",
        "[seads.skill_model]\nkind = \"vic\"",
    );
    assert!(text.contains("kind = \"vic\""));
    std::fs::write(&config, text).unwrap();
    let run = dir.path().join("vic");
    seads_ok(&["train", "--config", s(&config), "--out", s(&run), "--quiet"]);
    let figures = dir.path().join("figures");
    let out = seads_ok(&["plot", "--run", s(&run), "--out", s(&figures)]);
    assert!(String::from_utf8_lossy(&out.stderr).contains("cannot plan"));
    for f in ["coverage.png", "trajectories.png", "pushes.svg"] {
        assert!(figures.join(f).is_file(), "{f}");
    }
    assert!(!figures.join("success.png").exists());
    let report = dir.path().join("report");
    seads_ok(&["report", s(&run), "--out", s(&report)]);
    assert!(
        std::fs::read_to_string(report.join("report.md"))
            .unwrap()
            .contains("| vic |")
    );
}

#[test]
fn uarm_rejects_bad_input() {
    let dir = tempfile::tempdir().unwrap();
    let cal = dir.path().join("cal.toml");
    std::fs::write(&cal, "corners = [[0.0, 0.0, 0.0], [100.0, 0.0, 0.0], [200.0, 0.0, 0.0], [300.0, 0.0, 0.0]]\nd_max_mm = 100.0\n").unwrap();
    let run = dir.path().join("run");
    check_bad_input(
        &[
            "uarm",
            "train",
            "--port",
            "sim",
            "--calibration",
            cal.to_str().unwrap(),
            "--out",
            run.to_str().unwrap(),
        ],
        "line",
    );
    // Issue 32: absurd sizes (a height scale of 1e300 mm) and no test boards.
    std::fs::write(
        &cal,
        "corners = [[180.0, -60.0, 20.0], [180.0, 60.0, 20.0], [300.0, 60.0, 20.0], [300.0, -60.0, 20.0]]\nd_max_mm = 1e300\n",
    )
    .unwrap();
    for (extra, needle) in [
        (["--calibration", cal.to_str().unwrap()], "reach"),
        (["--boards", "0"], "--boards"),
    ] {
        let mut args = vec![
            "uarm",
            "train",
            "--port",
            "sim",
            "--out",
            run.to_str().unwrap(),
        ];
        args.extend(extra);
        check_bad_input(&args, needle);
    }
    assert!(!run.exists(), "a refused command writes nothing");
    // Issue 13: `sim:abc` became seed 0, and every port starting with `sim` the twin.
    check_bad_input(
        &[
            "uarm",
            "train",
            "--port",
            "sim:abc",
            "--out",
            run.to_str().unwrap(),
        ],
        "sim:SEED",
    );
    // A real arm: it needs a calibration, which the twin does not.
    check_bad_input(
        &[
            "uarm",
            "train",
            "--port",
            "simulated-arm",
            "--out",
            run.to_str().unwrap(),
        ],
        "needs --calibration",
    );
    let out = seads(&[
        "uarm",
        "train",
        "--port",
        "/dev/does-not-exist",
        "--calibration",
        cal.to_str().unwrap(),
        "--out",
        run.to_str().unwrap(),
    ]);
    assert!(!out.status.success());
    let missing = seads(&[
        "uarm",
        "calibrate",
        "--port",
        "/dev/does-not-exist",
        "--out",
        cal.to_str().unwrap(),
    ]);
    assert_eq!(missing.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&missing.stderr).contains("/dev/does-not-exist"));
    check_bad_input(
        &[
            "uarm",
            "train",
            "--port",
            "/dev/ttyACM9",
            "--out",
            run.to_str().unwrap(),
        ],
        "needs --calibration",
    );
    // Only the twin's board can be set.
    check_bad_input(
        &[
            "uarm",
            "train",
            "--port",
            "/dev/ttyACM9",
            "--calibration",
            cal.to_str().unwrap(),
            "--reset-board",
            "--out",
            run.to_str().unwrap(),
        ],
        "needs the twin",
    );
    // And only the twin's noise.
    check_bad_input(
        &[
            "uarm",
            "train",
            "--port",
            "/dev/ttyACM9",
            "--calibration",
            cal.to_str().unwrap(),
            "--tap-sd-mm",
            "2",
            "--out",
            run.to_str().unwrap(),
        ],
        "need the twin",
    );
    for (option, needle) in [
        ("--late-reports=1.5", "probability"),
        ("--tap-sd-mm=-1", "--tap-sd-mm"),
        ("--tap-sd-mm=101", "tap deviation"),
        ("--alpha=0", "--alpha"),
        ("--updates-per-epoch=0", "--updates-per-epoch"),
        ("--observe=eyes", "board-and-pen"),
    ] {
        check_bad_input(
            &["uarm", "train", option, "--out", run.to_str().unwrap()],
            needle,
        );
    }
    assert!(!run.exists(), "a refused command writes nothing");
}

/// What a new robot run's skills see unless told: the pen only with absolute pushes (the preset
/// that the twin's ablations chose), the board and the pen with displacements (the Cursor's).
#[test]
fn a_new_robot_run_sees_what_its_action_space_needs() {
    for (space, observe) in [("absolute", "pen"), ("displacement", "board-and-pen")] {
        let dir = tempfile::tempdir().unwrap();
        let run = dir.path().join("run");
        seads_ok(&[
            "uarm",
            "train",
            "--port",
            "sim:2",
            "--action-space",
            space,
            "--env-steps",
            "8",
            "--boards",
            "1",
            "--max-expanded",
            "1000",
            "--quiet",
            "--out",
            s(&run),
        ]);
        let robot = std::fs::read_to_string(run.join("robot.toml")).unwrap();
        assert!(
            robot.contains(&format!("observe = \"{observe}\"\n")),
            "{space}: {robot}"
        );
    }
}

/// The settings an ablation of the robot changes are recorded with the run, and a resume keeps
/// them whatever its options say.
#[test]
fn a_robot_run_records_its_ablation_settings() {
    let dir = tempfile::tempdir().unwrap();
    let run = dir.path().join("run");
    let train = |extra: &[&str]| {
        let mut args = vec!["uarm", "train", "--port", "sim:2", "--boards", "1"];
        args.extend(["--out", s(&run), "--quiet", "--max-expanded", "1000"]);
        args.extend(extra);
        seads_ok(&args)
    };
    train(&[
        "--env-steps",
        "8",
        "--observe",
        "pen",
        "--tap-sd-mm",
        "5",
        "--late-reports",
        "0.25",
        "--updates-per-epoch",
        "3",
        "--episodes-per-epoch",
        "2",
        "--alpha",
        "0.05",
    ]);
    let robot = || std::fs::read_to_string(run.join("robot.toml")).unwrap();
    assert_eq!(
        robot(),
        "action_space = \"absolute\"\nreset_board = false\nobserve = \"pen\"\n\n\
         [twin_noise]\ntap_sd_mm = 5.0\nlate_report_p = 0.25\n"
    );
    let config = std::fs::read_to_string(run.join("config.toml")).unwrap();
    for line in [
        "episodes_per_epoch = 2",
        "updates_per_epoch = 3",
        "alpha = 0.05",
    ] {
        assert!(config.contains(line), "{line}: {config}");
    }
    let recorded = robot();
    train(&["--resume", "--env-steps", "12", "--observe", "nothing"]);
    assert_eq!(robot(), recorded, "a resume keeps the run's settings");
    assert_eq!(
        std::fs::read_to_string(run.join("config.toml")).unwrap(),
        config.replace("env_steps = 8", "env_steps = 12")
    );
    // Training options belong to a new run.
    check_bad_input(
        &[
            "uarm",
            "train",
            "--resume",
            "--alpha",
            "0.2",
            "--out",
            s(&run),
        ],
        "--alpha",
    );
}

/// A robot evaluation on the noisy twin from the command line: `uarm evaluate` plays the tasks
/// that the evaluation at the end of `uarm train` played (both on a fresh twin of the port's
/// seed), a stopped one resumes from its journal (saying so) to the same tasks and results, and a
/// journal the twin does not repeat is one line of bad input. (This tiny agent finds no plan, so
/// no skill runs: that a replay puts the twin where the whole evaluation left it is
/// `a_stopped_twin_evaluation_resumes_to_the_whole_one` in `seads-study`.)
#[test]
fn a_robot_evaluation_is_the_same_whole_resumed_or_after_training() {
    let dir = tempfile::tempdir().unwrap();
    let run = dir.path().join("run");
    let limits = ["--port", "sim:3", "--boards", "2", "--max-expanded", "2000"];
    let mut args = vec!["uarm", "train", "--env-steps", "16", "--tap-sd-mm", "8"];
    args.extend(limits);
    args.extend(["--out", s(&run), "--quiet"]);
    seads_ok(&args);
    // The files of this protocol (2 boards, 2,000 states).
    const TASKS: &str = "evaluation-replan-boards-2-expanded-2000-tasks.jsonl";
    const RESULTS: &str = "evaluation-replan-boards-2-expanded-2000.json";
    let tasks = |run: &std::path::Path| std::fs::read_to_string(run.join(TASKS)).unwrap();
    // The results without the search times, which differ between machines.
    let results = |run: &std::path::Path| {
        let text = std::fs::read_to_string(run.join(RESULTS)).unwrap();
        let mut v: serde_json::Value = serde_json::from_str(&text).unwrap();
        for r in v["results"].as_array_mut().unwrap() {
            r.as_object_mut().unwrap().remove("planning_s");
        }
        v
    };
    let whole = tasks(&run);
    let lines: Vec<serde_json::Value> = whole
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(lines.len(), 10, "{whole}");
    assert!(
        lines
            .iter()
            .all(|l| l["reached"].is_string() && l["solution_depth"].is_u64())
    );
    let evaluate = |run: &std::path::Path| {
        let mut args = vec!["uarm", "evaluate", "--run", s(run)];
        args.extend(limits);
        seads(&args)
    };
    let copy = |name: &str| {
        let to = dir.path().join(name);
        copy_dir(&run, &to);
        std::fs::remove_file(to.join(TASKS)).unwrap();
        std::fs::remove_file(to.join(RESULTS)).unwrap();
        to
    };
    let again = copy("again");
    assert!(evaluate(&again).status.success());
    assert_eq!(
        tasks(&again),
        whole,
        "uarm evaluate plays what uarm train's evaluation played"
    );
    assert_eq!(results(&again), results(&run));
    // Stopped after five tasks: the journal holds them under the evaluation's header.
    let record = results(&run);
    let header = serde_json::json!({"evaluation": {
        "protocol": record["protocol"], "checkpoint": record["checkpoint"], "twin": 3}});
    // As this binary writes it: each task with its search time and the binary that solved it.
    let journal = |lines: &[serde_json::Value]| {
        let mut text = format!("{header}\n");
        for l in lines {
            let mut l = l.clone();
            l["planning_s"] = 0.0.into();
            l["by"] = record["evaluated_by"][0].clone();
            text += &format!("{l}\n");
        }
        text
    };
    let resumed = copy("resumed");
    std::fs::write(
        resumed.join(format!("{TASKS}.partial")),
        journal(&lines[..5]),
    )
    .unwrap();
    let out = evaluate(&resumed);
    assert!(out.status.success());
    let note = String::from_utf8_lossy(&out.stderr);
    assert!(
        note.contains("resuming a robot evaluation: 5 of 10 tasks finished before"),
        "{note}"
    );
    assert_eq!(tasks(&resumed), whole);
    assert_eq!(results(&resumed), record);
    assert!(!resumed.join(format!("{TASKS}.partial")).exists());
    // A journal whose boards the twin does not reach: nothing is evaluated over it.
    let mut wrong = lines[..5].to_vec();
    let reached = wrong[4]["reached"].as_str().unwrap().to_owned();
    let flipped = if reached.starts_with('0') { "1" } else { "0" };
    wrong[4]["reached"] = format!("{flipped}{}", &reached[1..]).into();
    let wrong_run = copy("wrong");
    std::fs::write(wrong_run.join(format!("{TASKS}.partial")), journal(&wrong)).unwrap();
    let out = evaluate(&wrong_run);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    let errors: Vec<&str> = err.lines().filter(|l| l.starts_with("error")).collect();
    assert!(
        errors.len() == 1 && errors[0].contains("does not repeat"),
        "{err}"
    );
    assert!(!wrong_run.join(TASKS).exists());
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

/// A numeric option's refusal of a negative, NaN or infinite value ends the process with exit
/// code 2 and one `error` line, never a panic (issue 13: `--timeout=-1` and `--timeout nan`
/// panicked). That clap refuses every such value of every numeric option is checked in-process
/// by the binary's own test, `every_numeric_option_refuses_negative_nan_and_infinite_values`.
#[test]
fn numeric_options_reject_negative_nan_and_infinite_values() {
    let commands: [&[&str]; 4] = [
        &["evaluate", "--timeout=-1"],
        &["solve", "--timeout=nan"],
        &["render", "--spacing=inf"],
        &["uarm", "train", "--late-reports=-inf"],
    ];
    for args in commands {
        let out = seads(args);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "seads {args:?}: {stderr}");
        assert!(
            stderr.starts_with("error")
                && stderr.lines().count() == 1
                && !stderr.contains("panicked"),
            "seads {args:?}: {stderr}"
        );
    }
}

/// Output into a closed pipe (`seads … | head`) ends the process quietly, as for other Unix
/// tools, instead of a panic.
#[test]
fn a_closed_output_pipe_is_not_a_panic() {
    use std::os::unix::process::ExitStatusExt;
    let (reader, writer) = std::io::pipe().unwrap();
    drop(reader);
    let out = seads_command()
        .args(["games", "depths", "--game", "tileswap"])
        .stdout(writer)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert_eq!(
        out.status.signal(),
        Some(13),
        "killed by SIGPIPE: {:?}",
        out.status
    );
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

/// Output errors end with a message, not a panic (issue 32: `seads envs > /dev/full` panicked).
#[test]
fn a_full_stdout_is_an_error_message_not_a_panic() {
    let full = std::fs::File::options()
        .write(true)
        .open("/dev/full")
        .unwrap();
    let output = seads_command().arg("envs").stdout(full).output().unwrap();
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("writing to standard output"), "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert_eq!(stderr.trim().lines().count(), 1, "{stderr}");
}

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

/// What a process did with a command line: its exit code, or `None` if it was still working
/// after `patience` (then it is killed), and its stderr.
fn run_for(args: &[String], patience: std::time::Duration) -> (Option<i32>, String) {
    use std::io::Read as _;
    use std::os::unix::process::ExitStatusExt;
    let mut child = seads_command()
        .args(args)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let start = std::time::Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break Some(status);
        }
        if start.elapsed() > patience {
            let _ = child.kill();
            let _ = child.wait();
            break None;
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    };
    let mut stderr = String::new();
    let _ = child.stderr.take().unwrap().read_to_string(&mut stderr);
    if let Some(status) = status {
        assert_eq!(status.signal(), None, "{args:?} died of a signal: {stderr}");
    }
    (status.and_then(|s| s.code()), stderr)
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig::with_cases(40))]
    /// Any value of a numeric option (negative, zero, NaN, infinite, huge, past 64 bits, not a
    /// number) ends in success, an error or bad input with a message, never a panic, an abort
    /// or a memory kill; a command that accepts a huge value may still be working at the end.
    #[test]
    fn numeric_options_never_panic(
        option in 0usize..14,
        value in proptest::sample::select(vec![
            "0", "1", "-1", "nan", "inf", "-inf", "1e300", "1e-300", "4294967297",
            "9223372036854775807", "18446744073709551615", "18446744073709551616", "abc", "",
        ]),
    ) {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("out");
        let out = out.to_str().unwrap();
        let run = tiny_run().join("run");
        let run = run.to_str().unwrap();
        let board = vec!["0"; 25].join(",");
        let templates: [&[&str]; 14] = [
            &["record", "--env", "lightsout-cursor", "--episodes", "1", "--steps", "V", "--out", out],
            &["record", "--env", "lightsout-cursor", "--episodes", "V", "--steps", "1", "--out", out],
            &["env-bench", "--env", "lightsout-cursor", "--steps", "V", "--threads", "1"],
            &["env-bench", "--env", "lightsout-cursor", "--steps", "10", "--threads", "V"],
            &["render", "--env", "lightsout-cursor", "--board-size", "V", "--out", "x.png"],
            &["render", "--env", "lightsout-cursor", "--spacing", "V", "--out", "x.png"],
            &["evaluate", "--run", run, "--boards", "V", "--quiet", "--timeout", "1"],
            &["solve", "--run", run, "--board", &board, "--timeout", "V"],
            &["uarm", "calibrate", "--port", "sim", "--d-max-mm", "V", "--out", out],
            &["evaluate", "--run", run, "--boards", "1", "--quiet", "--max-expanded", "V"],
            &["evaluate", "--run", run, "--boards", "1", "--quiet", "--memory-limit", "V"],
            &["plan-bench", "--depths", "1", "--boards", "1", "--threads", "V"],
            &["train", "--env", "lightsout-cursor", "--out", out, "--quiet", "--env-steps", "V"],
            &["train", "--env", "lightsout-cursor", "--out", out, "--quiet", "--env-steps", "1", "--seed", "V"],
        ];
        let args: Vec<String> = templates[option]
            .iter()
            .map(|a| if *a == "V" { value.to_owned() } else { (*a).to_owned() })
            .map(|a| if a == "x.png" { format!("{out}.png") } else { a })
            .collect();
        let (code, stderr) = run_for(&args, std::time::Duration::from_secs(3));
        proptest::prop_assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
        proptest::prop_assert!(matches!(code, None | Some(0..=2)), "{args:?}: {code:?} {stderr}");
        if code == Some(2) {
            proptest::prop_assert_eq!(stderr.trim().lines().count(), 1, "{:?}: {}", args, stderr);
        }
    }
}

/// Evaluations are keyed by their whole protocol (issue 82): one with other limits never
/// replaces another's file, a file of another protocol found under an evaluation's name (as an
/// older binary named them) is moved to its own name rather than overwritten, and a plot shows
/// only an evaluation of the protocol it is asked for, never one with other limits.
#[test]
fn an_evaluation_of_another_protocol_never_replaces_or_stands_in_for_another() {
    let dir = tempfile::tempdir().unwrap();
    let run = dir.path().join("run");
    copy_tiny_run(&run);
    let evaluate = |extra: &[&str]| {
        let base = [
            "evaluate",
            "--run",
            s(&run),
            "--boards",
            "1",
            "--replan",
            "--quiet",
        ];
        seads_ok(&[&base[..], extra].concat());
    };
    const ROOMY: &str = "evaluation-replan-boards-1-expanded-2000";
    const CRIPPLED: &str = "evaluation-replan-boards-1-expanded-1-timeout-0.5s";
    evaluate(&["--max-expanded", "2000"]);
    let roomy = std::fs::read(run.join(format!("{ROOMY}.json"))).unwrap();
    evaluate(&["--max-expanded", "1", "--timeout", "0.5"]);
    assert_eq!(
        std::fs::read(run.join(format!("{ROOMY}.json"))).unwrap(),
        roomy,
        "untouched"
    );
    let crippled: serde_json::Value =
        serde_json::from_slice(&std::fs::read(run.join(format!("{CRIPPLED}.json"))).unwrap())
            .unwrap();
    assert_eq!(crippled["protocol"]["limits"]["max_expanded"], 1);
    // A plot with the roomy limits shows the roomy evaluation, and one with the crippled limits
    // the crippled one: each reuses its own, neither is evaluated again.
    for limits in [
        &["--max-expanded", "2000"][..],
        &["--max-expanded", "1", "--timeout", "0.5"],
    ] {
        let out = dir.path().join("figures");
        let args = ["plot", "--run", s(&run), "--out", s(&out), "--boards", "1"];
        seads_ok(&[&args[..], limits].concat());
    }
    assert_eq!(
        std::fs::read(run.join(format!("{ROOMY}.json"))).unwrap(),
        roomy
    );
    // The crippled record found where the roomy one goes (as an older binary, which named files
    // by fewer parts of the protocol, left it): it moves to its own name, tasks and all.
    let older = dir.path().join("older");
    copy_tiny_run(&older);
    let crippled_text = std::fs::read(run.join(format!("{CRIPPLED}.json"))).unwrap();
    let crippled_tasks = std::fs::read(run.join(format!("{CRIPPLED}-tasks.jsonl"))).unwrap();
    std::fs::write(older.join(format!("{ROOMY}.json")), &crippled_text).unwrap();
    std::fs::write(older.join(format!("{ROOMY}-tasks.jsonl")), &crippled_tasks).unwrap();
    let base = [
        "evaluate",
        "--run",
        s(&older),
        "--boards",
        "1",
        "--replan",
        "--quiet",
    ];
    seads_ok(&[&base[..], &["--max-expanded", "2000"]].concat());
    assert_eq!(
        std::fs::read(older.join(format!("{CRIPPLED}.json"))).unwrap(),
        crippled_text
    );
    assert_eq!(
        std::fs::read(older.join(format!("{CRIPPLED}-tasks.jsonl"))).unwrap(),
        crippled_tasks
    );
    let now: serde_json::Value =
        serde_json::from_slice(&std::fs::read(older.join(format!("{ROOMY}.json"))).unwrap())
            .unwrap();
    assert_eq!(now["protocol"]["limits"]["max_expanded"], 2000, "{now}");
    // Where the moved record's own name is taken too, nothing is moved or lost: bad input.
    std::fs::write(older.join(format!("{ROOMY}.json")), &crippled_text).unwrap();
    let before = data_snapshot(&older);
    check_bad_input(
        &[&base[..], &["--max-expanded", "2000"]].concat(),
        "holds an evaluation of another protocol",
    );
    assert_eq!(data_snapshot(&older), before);
}

/// `seads evaluate --search both-ends --memory-limit GIB` records both in its protocol and solves
/// as many of the tiny agent's boards as breadth-first search does; an unknown search is bad
/// input.
#[test]
fn an_evaluation_records_its_search_and_memory_bound() {
    let dir = tempfile::tempdir().unwrap();
    let run = dir.path().join("run");
    copy_tiny_run(&run);
    let evaluate = |extra: &[&str], file: &str| -> serde_json::Value {
        let mut args = vec!["evaluate", "--run", s(&run), "--boards", "3", "--replan"];
        args.extend(["--max-expanded", "20000", "--json"]);
        args.extend(extra);
        seads_ok(&args);
        serde_json::from_slice(&std::fs::read(run.join(file)).unwrap()).unwrap()
    };
    let breadth = evaluate(&[], "evaluation-replan-boards-3-expanded-20000.json");
    let limits = &breadth["protocol"]["limits"];
    assert!(
        limits.get("search").is_none() && limits.get("memory_limit_mib").is_none(),
        "{limits}"
    );
    let both = evaluate(
        &["--search", "both-ends", "--memory-limit", "16"],
        "evaluation-replan-boards-3-expanded-20000-both-ends-memory-16384mib.json",
    );
    let limits = &both["protocol"]["limits"];
    assert_eq!(limits["search"], "both-ends", "{limits}");
    assert_eq!(limits["memory_limit_mib"], 16384, "{limits}");
    let outcomes = |record: &serde_json::Value| -> Vec<(u64, u64)> {
        let results = record["results"].as_array().unwrap().iter();
        results
            .map(|d| {
                (
                    d["solved"].as_u64().unwrap(),
                    d["plan_found"].as_u64().unwrap(),
                )
            })
            .collect()
    };
    assert_eq!(outcomes(&both), outcomes(&breadth));
    check_bad_input(
        &["evaluate", "--run", s(&run), "--search", "sideways"],
        "breadth, both-ends",
    );
}

/// `seads evaluate --action-noise STD` plays the same tasks with noisy actions, into files of
/// their own that record the noise; the same seed gives the same outcome; a negative or
/// non-finite deviation is bad input.
#[test]
fn an_evaluation_under_action_noise_has_files_of_its_own_and_repeats() {
    let dir = tempfile::tempdir().unwrap();
    let run = dir.path().join("run");
    copy_tiny_run(&run);
    let args = |noise: &str| -> Vec<String> {
        let mut a: Vec<String> = [
            "evaluate",
            "--run",
            s(&run),
            "--boards",
            "2",
            "--depths",
            "1-2",
            "--replan",
            "--max-expanded",
            "500",
            "--json",
        ]
        .iter()
        .map(|x| (*x).to_owned())
        .collect();
        if !noise.is_empty() {
            a.extend(["--action-noise".to_owned(), noise.to_owned()]);
        }
        a
    };
    let call = |noise: &str| {
        let a = args(noise);
        let refs: Vec<&str> = a.iter().map(String::as_str).collect();
        seads_ok(&refs)
    };
    call("");
    call("0.05");
    let plain = run.join("evaluation-replan-depths-1-2-boards-2-expanded-500.json");
    let noisy = run.join("evaluation-replan-depths-1-2-boards-2-expanded-500-noise-0.05.json");
    let record: serde_json::Value =
        serde_json::from_slice(&std::fs::read(&noisy).unwrap()).unwrap();
    assert_eq!(record["protocol"]["action_noise"], 0.05, "{record}");
    let plain_record: serde_json::Value =
        serde_json::from_slice(&std::fs::read(&plain).unwrap()).unwrap();
    assert!(plain_record["protocol"].get("action_noise").is_none());
    let tasks = |path: &std::path::Path| -> Vec<serde_json::Value> {
        std::fs::read_to_string(path)
            .unwrap()
            .lines()
            .map(|l| serde_json::from_str(l).unwrap())
            .collect()
    };
    let noisy_tasks =
        run.join("evaluation-replan-depths-1-2-boards-2-expanded-500-noise-0.05-tasks.jsonl");
    let first = tasks(&noisy_tasks);
    call("0.05");
    assert_eq!(tasks(&noisy_tasks), first, "the same seeds, the same noise");
    for bad in ["-0.1", "nan", "inf"] {
        let a = args(bad);
        let refs: Vec<&str> = a.iter().map(String::as_str).collect();
        let out = seads(&refs);
        assert_eq!(out.status.code(), Some(2), "{bad}");
    }
}

/// Outputs are written only as regular files: `record --out` refuses a FIFO, a symbolic link and a
/// file inside the run it records, leaving each as it was (exit 2, one line); a run directory
/// named with 100 `é` or with bytes that are not UTF-8 is evaluated like any other.
#[test]
fn outputs_replace_only_regular_files_and_any_run_name_works() {
    let dir = tempfile::tempdir().unwrap();
    let run = dir.path().join("run");
    copy_tiny_run(&run);
    let fifo = dir.path().join("fifo");
    let made = std::process::Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap();
    assert!(made.success());
    let target = dir.path().join("target.jsonl");
    let link = dir.path().join("link.jsonl");
    std::os::unix::fs::symlink(&target, &link).unwrap();
    let record = |out: &std::path::Path, policy: &str, why: &str| {
        check_bad_input(
            &[
                "record",
                "--env",
                "lightsout-cursor",
                "--policy",
                policy,
                "--episodes",
                "1",
                "--steps",
                "2",
                "--out",
                s(out),
            ],
            why,
        );
    };
    record(&fifo, "random", "a special file");
    record(&link, "random", "a symbolic link");
    let config = run.join("config.toml");
    let before = std::fs::read(&config).unwrap();
    record(&config, s(&run), "inside");
    use std::os::unix::fs::FileTypeExt as _;
    assert!(
        std::fs::symlink_metadata(&fifo)
            .unwrap()
            .file_type()
            .is_fifo()
    );
    assert!(
        std::fs::symlink_metadata(&link)
            .unwrap()
            .file_type()
            .is_symlink()
    );
    assert!(!target.exists(), "nothing written through the link");
    assert_eq!(std::fs::read(&config).unwrap(), before);
    let accented = dir.path().join("é".repeat(100));
    let raw = dir
        .path()
        .join(<std::ffi::OsStr as std::os::unix::ffi::OsStrExt>::from_bytes(b"run-\xff\xfe"));
    for name in [accented, raw] {
        copy_dir(&run, &name);
        let out = seads_command()
            .args([
                "evaluate", "--depths", "1", "--boards", "1", "--quiet", "--run",
            ])
            .arg(&name)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}: {}",
            name.display(),
            String::from_utf8_lossy(&out.stderr)
        );
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

/// Copies the run's last checkpoint under the epoch before it, which stands in for an earlier
/// checkpoint (a run keeps only its last); returns the last epoch and the earlier one.
fn add_an_earlier_checkpoint(run: &std::path::Path) -> (u64, u64) {
    let (last, _) = seads_rl::store::checkpoints(run).unwrap().pop().unwrap();
    let earlier = last - 1;
    let status = std::process::Command::new("cp")
        .arg("-r")
        .arg(run.join(format!("checkpoints/epoch-{last:06}")))
        .arg(run.join(format!("checkpoints/epoch-{earlier:06}")))
        .status()
        .unwrap();
    assert!(status.success());
    (last, earlier)
}

/// `seads plot --checkpoint` of an earlier checkpoint evaluates it once: the next plot reuses
/// the evaluation saved under the epoch's name (it looked for the final evaluation's file and
/// evaluated the checkpoint anew each time, minutes on an arm), and the figures of the checkpoint
/// say its epoch.
#[test]
fn a_plot_of_an_earlier_checkpoint_reuses_its_evaluation_and_names_its_epoch() {
    let dir = tempfile::tempdir().unwrap();
    let run = dir.path().join("run");
    copy_tiny_run(&run);
    let (_, earlier) = add_an_earlier_checkpoint(&run);
    let epoch = earlier.to_string();
    let plot = |out: &str| {
        let figures = dir.path().join(out);
        seads_ok(&[
            "plot",
            "--run",
            s(&run),
            "--out",
            s(&figures),
            "--checkpoint",
            &epoch,
            "--boards",
            "1",
            "--max-expanded",
            "2000",
        ]);
        figures
    };
    plot("first");
    // Named by the protocol (1 board, 2,000 states) and the epoch.
    let stem = format!("evaluation-replan-boards-1-expanded-2000-epoch-{earlier:06}");
    let record: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(run.join(format!("{stem}.json"))).unwrap())
            .unwrap();
    assert_eq!(record["checkpoint"]["epoch"], earlier, "{record}");
    // A planted line stands in for the tasks the evaluation wrote: evaluating again rewrites them.
    let tasks = run.join(format!("{stem}-tasks.jsonl"));
    std::fs::write(&tasks, "planted\n").unwrap();
    let figures = plot("second");
    assert_eq!(std::fs::read_to_string(&tasks).unwrap(), "planted\n");
    for name in ["success", "trajectories", "pushes"] {
        let svg = std::fs::read_to_string(figures.join(format!("{name}.svg"))).unwrap();
        assert!(svg.contains(&format!("epoch {earlier})")), "{name}");
    }
}

/// An evaluation with no board, or with more tasks than one evaluation may have, is refused
/// before anything is trained or written, by `run` and `plot` as by `evaluate`.
#[test]
fn evaluations_of_no_board_or_too_many_are_refused_up_front() {
    let dir = tempfile::tempdir().unwrap();
    let run = dir.path().join("run");
    copy_tiny_run(&run);
    let before: Vec<_> = std::fs::read_dir(&run).unwrap().collect();
    let figures = dir.path().join("figures");
    check_bad_input(
        &[
            "plot",
            "--run",
            s(&run),
            "--out",
            s(&figures),
            "--boards",
            "0",
        ],
        "at least 1 board",
    );
    assert!(!figures.exists());
    assert_eq!(std::fs::read_dir(&run).unwrap().count(), before.len());
    let demo = dir.path().join("demo");
    for (boards, why) in [("0", "at least 1 board"), ("2000000", "more than the")] {
        check_bad_input(
            &[
                "run",
                "--out",
                s(&demo),
                "--boards",
                boards,
                "--env-steps",
                "100",
            ],
            why,
        );
        assert!(!demo.exists(), "--boards {boards}: nothing written");
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

/// An evaluation plays the agent as it was trained: a `config.toml` whose environment settings
/// were edited since the checkpoint is refused in one line, as resuming refuses it, and nothing
/// is written; the budget may differ.
#[test]
fn an_evaluation_refuses_a_config_edited_since_the_checkpoint() {
    let dir = tempfile::tempdir().unwrap();
    let run = dir.path().join("run");
    copy_tiny_run(&run);
    let path = run.join("config.toml");
    let original = std::fs::read_to_string(&path).unwrap();
    assert!(original.contains("max_solution_depth = 5"), "{original}");
    std::fs::write(
        &path,
        original.replace("max_solution_depth = 5", "max_solution_depth = 3"),
    )
    .unwrap();
    let before: Vec<_> = std::fs::read_dir(&run).unwrap().collect();
    check_bad_input(
        &[
            "evaluate",
            "--run",
            s(&run),
            "--depths",
            "1",
            "--boards",
            "1",
        ],
        "`env_config.max_solution_depth` is 3, was 5",
    );
    assert_eq!(std::fs::read_dir(&run).unwrap().count(), before.len());
    std::fs::write(
        &path,
        original.replace("env_steps = 600", "env_steps = 900"),
    )
    .unwrap();
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

/// A stopped evaluation resumes: the tasks its `.partial` file holds under the same protocol and
/// checkpoint are counted as written there (a planted outcome shows it), a torn last line is
/// dropped, the other tasks are solved, and the file is gone at the end; the record names the
/// binary of the planted tasks and this one (none where a planted task names none). A `.partial`
/// of another protocol is ignored.
#[test]
fn a_stopped_evaluation_resumes_from_its_finished_tasks() {
    let dir = tempfile::tempdir().unwrap();
    let evaluate = |run: &std::path::Path| evaluate_two_boards_of_depths_1_2(s(run));
    let tasks_file = format!("{TWO_BOARDS}-tasks.jsonl");
    let tasks_file = tasks_file.as_str();
    let lines = |run: &std::path::Path| -> Vec<serde_json::Value> {
        std::fs::read_to_string(run.join(tasks_file))
            .unwrap()
            .lines()
            .map(|l| {
                let mut v: serde_json::Value = serde_json::from_str(l).unwrap();
                v.as_object_mut().unwrap().remove("planning_s");
                v
            })
            .collect()
    };
    let whole = dir.path().join("whole");
    copy_tiny_run(&whole);
    let reference = evaluate(&whole);
    let whole_lines = lines(&whole);
    assert_eq!(whole_lines.len(), 4);
    assert!(!whole.join(format!("{tasks_file}.partial")).exists());
    let record: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(whole.join(format!("{TWO_BOARDS}.json"))).unwrap(),
    )
    .unwrap();
    let header = |protocol: &serde_json::Value| serde_json::json!({"evaluation": {"protocol": protocol, "checkpoint": record["checkpoint"]}});
    let first_two: Vec<String> = std::fs::read_to_string(whole.join(tasks_file))
        .unwrap()
        .lines()
        .take(2)
        .map(str::to_owned)
        .collect();
    // The first task planted as solved in 7 steps: a resumed evaluation counts it so.
    let mut planted: serde_json::Value = serde_json::from_str(&first_two[0]).unwrap();
    for (key, value) in [
        ("solved", serde_json::json!(true)),
        ("plan_found", serde_json::json!(true)),
        ("manipulator_steps", serde_json::json!(7)),
        ("skill_steps", serde_json::json!([7])),
        ("failure", serde_json::Value::Null),
        ("planning_s", serde_json::json!(0.5)),
    ] {
        planted[key] = value;
    }
    // Solved by another binary, which the journal names beside the task.
    let earlier = serde_json::json!({"seads": "0.1.0", "commit": "0123abc", "dirty": false});
    planted["by"] = earlier.clone();
    let resumed = dir.path().join("resumed");
    copy_tiny_run(&resumed);
    // A `.partial` line also holds the task's search time (the tasks file does not).
    let mut second: serde_json::Value = serde_json::from_str(&first_two[1]).unwrap();
    second["planning_s"] = serde_json::json!(0.25);
    second["by"] = earlier.clone();
    let partial = format!(
        "{}\n{planted}\n{second}\n{{\"depth\": 2, \"se",
        header(&record["protocol"])
    );
    std::fs::write(resumed.join(format!("{tasks_file}.partial")), partial).unwrap();
    let out = evaluate_two_boards_of_depths_1_2_output(s(&resumed));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let note = String::from_utf8_lossy(&out.stderr);
    assert!(
        note.contains("resuming an evaluation: 2 of 4 tasks finished before"),
        "{note}"
    );
    // The whole evaluation's lines, the first as planted (without what only the journal keeps).
    let mut planted_first = whole_lines.clone();
    planted_first[0] = planted.clone();
    planted_first[0]
        .as_object_mut()
        .unwrap()
        .remove("planning_s");
    planted_first[0].as_object_mut().unwrap().remove("by");
    assert_eq!(lines(&resumed), planted_first);
    // The record names both binaries, the one that began first first; a whole evaluation names
    // this one alone.
    let this = &record["evaluated_by"][0];
    assert_eq!(
        record["evaluated_by"].as_array().unwrap().len(),
        1,
        "{record}"
    );
    let version = String::from_utf8(seads_ok(&["--version"]).stdout).unwrap();
    assert!(
        version.contains(this["commit"].as_str().unwrap()),
        "{version} {this}"
    );
    let resumed_record: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(resumed.join(format!("{TWO_BOARDS}.json"))).unwrap(),
    )
    .unwrap();
    assert_eq!(
        resumed_record["evaluated_by"],
        serde_json::json!([earlier, this])
    );
    // A task from before that names no binary (a journal of older code): the record cannot name
    // every binary, so it names none.
    let unnamed = dir.path().join("unnamed");
    copy_tiny_run(&unnamed);
    let mut anonymous = second.clone();
    anonymous.as_object_mut().unwrap().remove("by");
    let partial = format!("{}\n{planted}\n{anonymous}\n", header(&record["protocol"]));
    std::fs::write(unnamed.join(format!("{tasks_file}.partial")), partial).unwrap();
    evaluate(&unnamed);
    let unnamed_record: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(unnamed.join(format!("{TWO_BOARDS}.json"))).unwrap(),
    )
    .unwrap();
    assert!(
        unnamed_record.get("evaluated_by").is_none(),
        "{unnamed_record}"
    );
    let second = f64::from(u8::from(whole_lines[1]["solved"] == true));
    assert_eq!(
        v["success_rate"]["1"].as_f64().unwrap(),
        (1.0 + second) / 2.0,
        "{v}"
    );
    assert_eq!(v["success_rate"]["2"], reference["success_rate"]["2"]);
    assert!(!resumed.join(format!("{tasks_file}.partial")).exists());
    // Another protocol's file is not this evaluation's: everything is solved anew.
    let other = dir.path().join("other");
    copy_tiny_run(&other);
    let mut protocol = record["protocol"].clone();
    protocol["tasks"]["boards"] = 3.into();
    let partial = format!("{}\n{planted}\n", header(&protocol));
    std::fs::write(other.join(format!("{tasks_file}.partial")), partial).unwrap();
    let v = evaluate(&other);
    assert_eq!(lines(&other), whole_lines);
    assert_eq!(v["success_rate"], reference["success_rate"]);
    // A damaged line in the middle costs its own task only, and is said (issue 82: it threw
    // every finished task away without a word): the planted task before it and the one after it
    // stand, and the damaged one is solved again.
    let damaged = dir.path().join("damaged");
    copy_tiny_run(&damaged);
    let whole_tasks = std::fs::read_to_string(whole.join(tasks_file)).unwrap();
    let mut third: serde_json::Value =
        serde_json::from_str(whole_tasks.lines().nth(2).unwrap()).unwrap();
    third["planning_s"] = serde_json::json!(0.125);
    third["by"] = earlier.clone();
    let partial = format!(
        "{}\n{planted}\n{{\"depth\": 1, garbage\n{third}\n",
        header(&record["protocol"])
    );
    std::fs::write(damaged.join(format!("{tasks_file}.partial")), partial).unwrap();
    let out = evaluate_two_boards_of_depths_1_2_output(s(&damaged));
    let note = String::from_utf8_lossy(&out.stderr);
    assert!(
        note.contains("resuming an evaluation: 2 of 4 tasks finished before"),
        "{note}"
    );
    assert!(
        note.contains("1 damaged line(s) in the journal of a stopped evaluation were left out"),
        "{note}"
    );
    assert_eq!(lines(&damaged), planted_first);
    assert!(!damaged.join(format!("{tasks_file}.partial")).exists());
}
