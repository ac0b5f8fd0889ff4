//! `seads uarm` on the twin: calibration, training, resuming, ablation settings and evaluation.

use crate::common::*;

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
