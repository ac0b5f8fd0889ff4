//! Planning with a trained run: `seads solve`, `evaluate` (protocols, resuming, action noise, bounds) and `plot`.

use crate::common::*;

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

/// A learner without a forward model of its own (DIAYN) is planned with one fitted to its frozen
/// skills: refused without it, fitted reproducibly, evaluated under its own name, reported in its
/// own row, and never replaced under the evaluations that used it.
#[test]
fn a_diayn_run_plans_with_a_model_fitted_to_its_skills() {
    let dir = tempfile::tempdir().unwrap();
    let run = dir.path().join("diayn");
    seads_ok(&[
        "train",
        "--env",
        "lightsout-cursor",
        "--algorithm",
        "diayn",
        "--env-steps",
        "300",
        "--out",
        s(&run),
        "--quiet",
    ]);
    let evaluate = |run: &std::path::Path, fitted: bool| {
        let mut args = vec![
            "evaluate",
            "--run",
            s(run),
            "--boards",
            "2",
            "--max-expanded",
            "2000",
            "--replan",
            "--json",
        ];
        if fitted {
            args.push("--fitted-model");
        }
        args.iter().map(|a| a.to_string()).collect::<Vec<_>>()
    };
    let args = evaluate(&run, false);
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    check_bad_input(&args, "seads fit-model");
    let fitted_args = evaluate(&run, true);
    let fitted_args: Vec<&str> = fitted_args.iter().map(String::as_str).collect();
    check_bad_input(&fitted_args, "has no fitted model");
    // Two copies fitted alike are fitted to the bit: every choice flows from the seed.
    let copy = dir.path().join("copy");
    copy_dir(&run, &copy);
    let fit = |run: &std::path::Path| {
        json(&[
            "fit-model",
            "--run",
            s(run),
            "--episodes",
            "200",
            "--updates",
            "30",
            "--json",
        ])
    };
    let record = fit(&run);
    assert_eq!(record["num_skills"], 25);
    assert_eq!(record["quality"]["held_out"], 20);
    assert_eq!(record["settings"]["seed"], 1);
    fit(&copy);
    let weights = |run: &std::path::Path| {
        std::fs::read(run.join("fitted-model/forward_model.safetensors")).unwrap()
    };
    assert_eq!(weights(&run), weights(&copy));
    check_bad_input(
        &["fit-model", "--run", s(&run), "--episodes", "200"],
        "--refit",
    );
    check_bad_input(
        &["fit-model", "--run", s(&run), "--episodes", "9"],
        "--episodes",
    );
    let summary = json(&fitted_args);
    assert_eq!(
        summary["success_rate"].as_object().map(|m| m.len()),
        Some(5),
        "{summary}"
    );
    let stem = "evaluation-replan-boards-2-expanded-2000-fitted-model";
    assert!(run.join(format!("{stem}.json")).is_file());
    assert!(run.join(format!("{stem}-tasks.jsonl")).is_file());
    // A model that evaluations planned with is not replaced under them.
    check_bad_input(
        &[
            "fit-model",
            "--run",
            s(&run),
            "--episodes",
            "200",
            "--refit",
        ],
        &format!("{stem}.json"),
    );
    let out = dir.path().join("report");
    seads_ok(&["report", s(&run), "--out", s(&out), "--copy-runs"]);
    let md = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(
        md.contains("| re-planning | boards-2, expanded-2000, fitted-model | 1 |"),
        "{md}"
    );
    // The fit's quality, as the record says it.
    let right = 100.0 * record["quality"]["mode_accuracy"].as_f64().unwrap();
    assert!(
        md.contains("## Forward models fitted to the skills"),
        "{md}"
    );
    assert!(md.contains(&format!("| 1 | {right:.1} ± 0.0 % |")), "{md}");
    let copied: Vec<_> = walkdir::WalkDir::new(out.join("runs"))
        .into_iter()
        .map(|e| e.unwrap().into_path())
        .filter(|p| p.ends_with("fitted-model/fit.json"))
        .collect();
    assert_eq!(
        copied.len(),
        1,
        "the fit's record comes along, not its weights"
    );
    assert!(
        !copied[0]
            .with_file_name("forward_model.safetensors")
            .exists()
    );
}

/// A run whose skill model is the mixture (issue 80; `[seads.skill_model] kind = "mixture"`)
/// trains, checkpoints the mixture's weights, resumes and plans: its agent solves tasks with the
/// mixture's successors and likelihoods. Components belong to that kind only.
#[test]
fn a_run_with_the_mixture_model_trains_resumes_and_plans() {
    let dir = tempfile::tempdir().unwrap();
    let config = tiny_config(dir.path());
    let text = std::fs::read_to_string(&config)
        .unwrap()
        .replace("kind = \"forward\"", "kind = \"mixture\"\ncomponents = 3");
    assert!(text.contains("kind = \"mixture\""));
    std::fs::write(&config, &text).unwrap();
    let run = dir.path().join("run");
    seads_ok(&["train", "--config", s(&config), "--out", s(&run), "--quiet"]);
    let saved = std::fs::read_to_string(run.join("config.toml")).unwrap();
    assert!(saved.contains("kind = \"mixture\"") && saved.contains("components = 3"));
    let checkpoints: Vec<_> = std::fs::read_dir(run.join("checkpoints"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_dir())
        .collect();
    assert!(!checkpoints.is_empty());
    assert!(
        checkpoints
            .iter()
            .all(|c| c.join("mixture_model.safetensors").is_file()
                && !c.join("forward_model.safetensors").exists()),
        "{checkpoints:?}"
    );
    seads_ok(&[
        "train",
        "--resume",
        s(&run),
        "--env-steps",
        "900",
        "--quiet",
    ]);
    let evaluation = evaluate_two_boards_of_depths_1_2(s(&run));
    assert_eq!(
        evaluation["success_rate"].as_object().unwrap().len(),
        2,
        "{evaluation}"
    );
    let tasks = std::fs::read_to_string(run.join(format!("{TWO_BOARDS}-tasks.jsonl"))).unwrap();
    assert_eq!(tasks.lines().count(), 4, "two boards of each depth");
    // `components` with the paper's model is refused in one line.
    let wrong = text.replace("kind = \"mixture\"", "kind = \"forward\"");
    std::fs::write(&config, wrong).unwrap();
    check_bad_input(
        &[
            "train",
            "--config",
            s(&config),
            "--out",
            s(&dir.path().join("x")),
        ],
        "components belongs to kind = \"mixture\"",
    );
}
