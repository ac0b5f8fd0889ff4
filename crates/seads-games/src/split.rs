//! The CRC32 train/test split of boards (SPEC §1.4).

use std::fmt::Write as _;

/// Which part of the board data set a board belongs to.
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, serde::Serialize, serde::Deserialize,
)]
#[serde(rename_all = "lowercase")]
pub enum Split {
    /// Boards used for training (CRC32 mod 3 = 0).
    Train,
    /// Boards held out for validation and evaluation (CRC32 mod 3 ≠ 0).
    Test,
}

impl Split {
    /// Both splits, train first.
    pub const ALL: [Split; 2] = [Split::Train, Split::Test];

    /// The lower-case name.
    pub fn name(self) -> &'static str {
        match self {
            Split::Train => "train",
            Split::Test => "test",
        }
    }
}

impl std::fmt::Display for Split {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for Split {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "train" => Ok(Split::Train),
            "test" => Ok(Split::Test),
            other => Err(format!("unknown split {other:?} (valid: train, test)")),
        }
    }
}

/// The canonical board string: decimal values joined by "," with no spaces.
pub fn board_string(values: &[u8]) -> String {
    let mut s = String::with_capacity(values.len() * 2);
    for (i, v) in values.iter().enumerate() {
        if i > 0 {
            s.push(',');
        }
        write!(s, "{v}").expect("writing to a String cannot fail");
    }
    s
}

/// The split of a board given by its canonical values: train iff CRC-32 of the board string is
/// divisible by 3. The spaced variant "1, 0, …" printed in the paper's supplement is typography
/// only; the unspaced string reproduces its split table (SPEC §1.4).
///
/// ```
/// use seads_games::{Split, split_of};
/// // CRC-32 of "0,1,2,3,4,5,6,7,8" (the solved TileSwap board) is 0 mod 3 (Python's zlib.crc32).
/// assert_eq!(split_of(&[0, 1, 2, 3, 4, 5, 6, 7, 8]), Split::Train);
/// // The dark 5×5 LightsOut board's CRC-32 is 2510077351, 1 mod 3.
/// assert_eq!(split_of(&[0; 25]), Split::Test);
/// ```
pub fn split_of(values: &[u8]) -> Split {
    if crc32fast::hash(board_string(values).as_bytes()).is_multiple_of(3) {
        Split::Train
    } else {
        Split::Test
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn crc(s: &str) -> u32 {
        crc32fast::hash(s.as_bytes())
    }

    #[test]
    fn spec_test_vectors() {
        let zeros = board_string(&[0; 25]);
        assert_eq!(zeros.len(), 49);
        assert_eq!(crc(&zeros), 2510077351);
        assert_eq!(split_of(&[0; 25]), Split::Test);
        assert_eq!(crc("0,1,2,3,4,5,6,7,8"), 4019828199);
        assert_eq!(split_of(&[0, 1, 2, 3, 4, 5, 6, 7, 8]), Split::Train);
        assert_eq!(crc("1,0,2,3,4,5,6,7,8"), 3519325516);
        assert_eq!(split_of(&[1, 0, 2, 3, 4, 5, 6, 7, 8]), Split::Test);
        assert_eq!(crc("3,1,2,0,4,5,6,7,8"), 635537506);
        let mut after_move_0 = [0u8; 25];
        for d in [0, 1, 5] {
            after_move_0[d] = 1;
        }
        assert_eq!(crc(&board_string(&after_move_0)), 1026855544);
        let mut after_move_12 = [0u8; 25];
        for d in [7, 11, 12, 13, 17] {
            after_move_12[d] = 1;
        }
        assert_eq!(crc(&board_string(&after_move_12)), 3012366364);
        assert_eq!(split_of(&after_move_12), Split::Test);
    }
}
