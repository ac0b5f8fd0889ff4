//! `seads games`: depths, the train/test split, the optimal solver, and bad boards.

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
