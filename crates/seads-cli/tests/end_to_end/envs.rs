//! The environments' commands: `seads envs`, `render`, `env-bench`, `record` and `replay`.

use crate::common::*;

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
