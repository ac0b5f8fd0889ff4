//! The tablet's LightsOut board, read from the Android log (`adb logcat`).
//!
//! The LightsOut app logs one line per registered tap under the tag `SeadsLightsOut`:
//!
//! ```text
//! I/SeadsLightsOut( 4242): seq=17 board=0110010000100001000000000 move=12
//! ```
//!
//! - `seq`: number of taps registered since the app started (increasing by one per line);
//! - `board`: the 25 fields after the tap, row-major, `1` = light on;
//! - `move`: the pressed field `row·5 + col`, or `-` if the tap hit no field.
//!
//! The app logs the same line with `move=-` when it shows a new board. Only the text after the
//! tag and `): ` (or `: `) is read, so any `logcat -v` format that keeps the tag works. Lines
//! with the tag that do not parse are rejected (counted, never trusted).

use std::io::{BufRead, BufReader};
use std::process::{Child, Command, Stdio};
use std::sync::mpsc::{Receiver, RecvTimeoutError, channel};
use std::time::Duration;

use seads_games::{MoveId, SymbolicState};

use crate::UarmError;

/// The log tag of the LightsOut app.
pub const LOG_TAG: &str = "SeadsLightsOut";

/// One report of the app.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TabletReport {
    /// Taps registered so far.
    pub seq: u64,
    /// The board after the tap.
    pub board: SymbolicState,
    /// The pressed field, if the tap hit one.
    pub game_move: Option<MoveId>,
}

/// Parses a log line: `None` if it is not the app's, `Some(Err)` if it is but is malformed.
pub fn parse_log_line(line: &str) -> Option<Result<TabletReport, String>> {
    let start = line.find(LOG_TAG)? + LOG_TAG.len();
    let rest = &line[start..];
    let payload = rest.split_once(": ").map(|(_, p)| p)?;
    Some(parse_payload(payload.trim()))
}

fn parse_payload(payload: &str) -> Result<TabletReport, String> {
    let (mut seq, mut board, mut game_move) = (None, None, None);
    for field in payload.split_whitespace() {
        let (key, value) = field
            .split_once('=')
            .ok_or_else(|| format!("{field:?} is not key=value"))?;
        match key {
            "seq" => {
                seq = Some(
                    value
                        .parse::<u64>()
                        .map_err(|_| format!("seq={value:?} is not a number"))?,
                )
            }
            "board" => {
                if value.len() != 25 || !value.bytes().all(|b| b == b'0' || b == b'1') {
                    return Err(format!("board={value:?} is not 25 characters 0/1"));
                }
                board = Some(SymbolicState::from_bools(
                    &value.bytes().map(|b| b == b'1').collect::<Vec<_>>(),
                ));
            }
            "move" => {
                game_move = Some(match value {
                    "-" => None,
                    m => Some(
                        m.parse::<usize>()
                            .ok()
                            .filter(|&m| m < 25)
                            .ok_or_else(|| format!("move={m:?} is not a field 0..24 or -"))?,
                    ),
                })
            }
            other => return Err(format!("unknown field {other:?}")),
        }
    }
    Ok(TabletReport {
        seq: seq.ok_or("no seq=")?,
        board: board.ok_or("no board=")?,
        game_move: game_move.ok_or("no move=")?,
    })
}

/// The line the app logs for a report (used by the simulated tablet).
pub fn format_report(report: &TabletReport) -> String {
    let board: String = (0..25)
        .map(|d| if report.board.get(d) { '1' } else { '0' })
        .collect();
    let m = report.game_move.map_or("-".to_owned(), |m| m.to_string());
    format!(
        "I/{LOG_TAG}( 4242): seq={} board={board} move={m}",
        report.seq
    )
}

/// Where the board comes from: the real tablet over `adb logcat`, or the simulated one.
pub trait Tablet: Send {
    /// The latest report, waiting up to `timeout` for the first one.
    fn latest(&mut self, timeout: Duration) -> Result<TabletReport, UarmError>;
    /// Waits up to `timeout` for a report with `seq > after` (a registered tap).
    fn wait_for_report(
        &mut self,
        after: u64,
        timeout: Duration,
    ) -> Result<Option<TabletReport>, UarmError>;
    /// Shows `board` (only the simulated tablet can).
    fn set_board(&mut self, board: SymbolicState) -> Result<(), UarmError>;
}

/// The tablet read through `adb logcat` in a child process.
pub struct AdbTablet {
    child: Child,
    lines: Receiver<Result<TabletReport, String>>,
    latest: Option<TabletReport>,
    /// Malformed lines seen (rejected).
    pub rejected: usize,
}

impl AdbTablet {
    /// Starts `adb logcat` filtered to the app's tag (`adb` is the program to run).
    pub fn start(adb: &str) -> Result<Self, UarmError> {
        let mut child = Command::new(adb)
            .args(["logcat", "-v", "brief", "-s", &format!("{LOG_TAG}:I")])
            .stdout(Stdio::piped())
            .stderr(Stdio::null())
            .spawn()
            .map_err(|e| UarmError::Tablet(format!("cannot start `{adb} logcat`: {e}")))?;
        let stdout = child.stdout.take().expect("piped");
        let (tx, rx) = channel();
        std::thread::spawn(move || {
            for line in BufReader::new(stdout).lines().map_while(Result::ok) {
                if let Some(report) = parse_log_line(&line)
                    && tx.send(report).is_err()
                {
                    break;
                }
            }
        });
        Ok(Self {
            child,
            lines: rx,
            latest: None,
            rejected: 0,
        })
    }

    fn receive(&mut self, timeout: Duration) -> Result<Option<TabletReport>, UarmError> {
        loop {
            match self.lines.recv_timeout(timeout) {
                Ok(Ok(report)) => {
                    self.latest = Some(report);
                    return Ok(Some(report));
                }
                Ok(Err(_)) => self.rejected += 1,
                Err(RecvTimeoutError::Timeout) => return Ok(None),
                Err(RecvTimeoutError::Disconnected) => {
                    return Err(UarmError::Tablet(
                        "adb logcat ended (tablet disconnected?)".into(),
                    ));
                }
            }
        }
    }
}

impl Drop for AdbTablet {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

impl Tablet for AdbTablet {
    fn latest(&mut self, timeout: Duration) -> Result<TabletReport, UarmError> {
        while self.receive(Duration::ZERO)?.is_some() {}
        match self.latest {
            Some(report) => Ok(report),
            None => self.receive(timeout)?.ok_or_else(|| {
                UarmError::Tablet(format!(
                    "no {LOG_TAG} line from the tablet; is the app running?"
                ))
            }),
        }
    }

    fn wait_for_report(
        &mut self,
        after: u64,
        timeout: Duration,
    ) -> Result<Option<TabletReport>, UarmError> {
        let deadline = std::time::Instant::now() + timeout;
        loop {
            if let Some(latest) = self.latest.filter(|r| r.seq > after) {
                return Ok(Some(latest));
            }
            let left = deadline.saturating_duration_since(std::time::Instant::now());
            if self.receive(left)?.is_none() {
                return Ok(None);
            }
        }
    }

    fn set_board(&mut self, _board: SymbolicState) -> Result<(), UarmError> {
        Err(UarmError::Tablet(
            "the real tablet shows the app's boards; they cannot be set from here".into(),
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn app_lines_parse_in_any_logcat_format() {
        let board = "0110010000100001000000000";
        for line in [
            format!("I/SeadsLightsOut( 4242): seq=17 board={board} move=12"),
            format!(
                "11-22 20:15:03.123  1234  1234 I SeadsLightsOut: seq=17 board={board} move=12"
            ),
        ] {
            let r = parse_log_line(&line).unwrap().unwrap();
            assert_eq!((r.seq, r.game_move), (17, Some(12)));
            assert!(r.board.get(1) && r.board.get(2) && !r.board.get(0));
            assert_eq!(
                format!(
                    "{}",
                    parse_log_line(&format_report(&r)).unwrap().unwrap().seq
                ),
                "17"
            );
        }
        let miss = parse_log_line(&format!("I/SeadsLightsOut( 1): seq=3 board={board} move=-"))
            .unwrap()
            .unwrap();
        assert_eq!(miss.game_move, None);
        assert!(parse_log_line("I/ActivityManager( 99): Start proc").is_none());
    }

    #[test]
    fn malformed_app_lines_are_rejected() {
        for bad in [
            "I/SeadsLightsOut( 1): seq=3 board=0110 move=1",
            "I/SeadsLightsOut( 1): seq=3 board=0110010000100001000000002 move=1",
            "I/SeadsLightsOut( 1): seq=x board=0110010000100001000000000 move=1",
            "I/SeadsLightsOut( 1): seq=3 board=0110010000100001000000000 move=25",
            "I/SeadsLightsOut( 1): seq=3 board=0110010000100001000000000",
            "I/SeadsLightsOut( 1): seq=3 board=0110010000100001000000000 move=1 colour=red",
            "I/SeadsLightsOut( 1): garbage",
        ] {
            assert!(matches!(parse_log_line(bad), Some(Err(_))), "{bad}");
        }
    }
}
