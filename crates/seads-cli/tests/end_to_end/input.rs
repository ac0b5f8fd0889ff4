//! Bad input and output streams across commands: usage errors and numeric options (one line, exit 2, never a panic), closed or full pipes, and outputs that replace only regular files.

use crate::common::*;

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
