//! `data/*.csv` are what `cargo xtask gen-splits` writes today, and they hold the paper's numbers.

use seads_games::tables::{depth_counts_csv, split_counts_csv};

use crate::read;

/// Depth counts of the supplement's Table 2 (index = depth, 1..16).
const LIGHTSOUT5_DEPTHS: [u64; 15] = [
    25, 300, 2300, 12650, 53130, 176176, 467104, 982335, 1596279, 1935294, 1684446, 1004934,
    383670, 82614, 7350,
];
const TILESWAP_DEPTHS: [u64; 16] = [
    12, 88, 470, 1978, 6658, 18081, 38936, 65246, 83000, 76688, 48316, 18975, 4024, 382, 24, 1,
];

/// (train, test) per depth: depths 1–5 from the supplement's Table 3, the rest from SPEC §1.4.
const LIGHTSOUT5_SPLITS: [(u64, u64); 15] = [
    (7, 18),
    (99, 201),
    (785, 1515),
    (4200, 8450),
    (17849, 35281),
    (58697, 117479),
    (155662, 311442),
    (327524, 654811),
    (533511, 1062768),
    (644427, 1290867),
    (561112, 1123334),
    (335398, 669536),
    (128442, 255228),
    (27585, 55029),
    (2506, 4844),
];
const TILESWAP_SPLITS: [(u64, u64); 16] = [
    (7, 5),
    (31, 57),
    (179, 291),
    (683, 1295),
    (2237, 4421),
    (5996, 12085),
    (12982, 25954),
    (21714, 43532),
    (27869, 55131),
    (25567, 51121),
    (16184, 32132),
    (6253, 12722),
    (1345, 2679),
    (132, 250),
    (12, 12),
    (1, 0),
];

fn rows(csv: &str) -> Vec<Vec<String>> {
    csv.lines()
        .skip(1)
        .map(|l| l.split(',').map(str::to_owned).collect())
        .collect()
}

#[test]
fn data_files_are_up_to_date() {
    assert_eq!(
        read("data/depth_counts.csv"),
        depth_counts_csv(),
        "run `cargo xtask gen-splits`"
    );
    assert_eq!(
        read("data/split_counts.csv"),
        split_counts_csv(),
        "run `cargo xtask gen-splits`"
    );
}

#[test]
fn depth_counts_match_the_paper() {
    let csv = read("data/depth_counts.csv");
    let counts = |game: &str, size: &str| -> Vec<u64> {
        rows(&csv)
            .iter()
            .filter(|r| r[0] == game && r[1] == size)
            .map(|r| r[3].parse().unwrap())
            .collect()
    };
    let lo = counts("lightsout", "5");
    assert_eq!(lo[0], 1);
    assert_eq!(lo[1..], LIGHTSOUT5_DEPTHS);
    assert_eq!(lo.iter().sum::<u64>(), 1 << 23);
    let ts = counts("tileswap", "3");
    assert_eq!(ts[1..], TILESWAP_DEPTHS);
    assert_eq!(ts.iter().sum::<u64>(), 362880);
}

#[test]
fn split_counts_match_the_paper() {
    let csv = read("data/split_counts.csv");
    let splits = |game: &str| -> Vec<(u64, u64)> {
        let r: Vec<_> = rows(&csv).into_iter().filter(|r| r[0] == game).collect();
        r.chunks(2)
            .map(|pair| {
                assert_eq!(
                    (pair[0][2].as_str(), pair[1][2].as_str()),
                    ("train", "test")
                );
                (pair[0][3].parse().unwrap(), pair[1][3].parse().unwrap())
            })
            .collect()
    };
    assert_eq!(splits("lightsout"), LIGHTSOUT5_SPLITS);
    assert_eq!(splits("tileswap"), TILESWAP_SPLITS);
}
