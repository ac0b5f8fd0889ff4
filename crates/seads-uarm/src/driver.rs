//! The uArm Swift Pro driver over a line transport: sequence numbers, acknowledgements with a
//! timeout, recovery from garbled and unexpected lines.

use std::io::{BufRead, BufReader, Write};
use std::time::{Duration, Instant};

use crate::UarmError;
use crate::protocol::{Reply, command_line, move_to, next_id, parse_position, parse_reply};

/// A line-oriented connection to an arm: the serial port, or the simulated twin.
pub trait Transport: Send {
    /// Sends one line (the newline is added).
    fn write_line(&mut self, line: &str) -> Result<(), UarmError>;
    /// The next received line, or `None` if none arrived within `timeout`.
    fn read_line(&mut self, timeout: Duration) -> Result<Option<String>, UarmError>;
}

/// The USB serial port of a real arm (115200 baud, 8N1).
pub struct SerialTransport {
    reader: BufReader<Box<dyn serialport::SerialPort>>,
    name: String,
}

impl SerialTransport {
    /// Opens `port` (e.g. `/dev/ttyACM0`).
    pub fn open(port: &str) -> Result<Self, UarmError> {
        let serial = serialport::new(port, 115_200)
            .timeout(Duration::from_millis(50))
            .open()
            .map_err(|e| UarmError::Io {
                what: format!("opening serial port {port}"),
                source: Box::new(e),
            })?;
        Ok(Self {
            reader: BufReader::new(serial),
            name: port.to_owned(),
        })
    }
}

impl Transport for SerialTransport {
    fn write_line(&mut self, line: &str) -> Result<(), UarmError> {
        let port = self.reader.get_mut();
        port.write_all(format!("{line}\n").as_bytes())
            .and_then(|()| port.flush())
            .map_err(|e| match e.kind() {
                std::io::ErrorKind::BrokenPipe | std::io::ErrorKind::NotConnected => {
                    UarmError::Disconnected
                }
                _ => UarmError::Io {
                    what: self.name.clone(),
                    source: Box::new(e),
                },
            })
    }

    fn read_line(&mut self, timeout: Duration) -> Result<Option<String>, UarmError> {
        let deadline = Instant::now() + timeout;
        let mut line = Vec::new();
        loop {
            let mut byte = Vec::new();
            match self.reader.read_until(b'\n', &mut byte) {
                Ok(0) => return Err(UarmError::Disconnected),
                Ok(_) => {
                    line.extend_from_slice(&byte);
                    if line.ends_with(b"\n") {
                        return Ok(Some(String::from_utf8_lossy(&line).trim_end().to_owned()));
                    }
                }
                Err(e) if e.kind() == std::io::ErrorKind::TimedOut => {
                    line.extend_from_slice(&byte);
                    if Instant::now() >= deadline {
                        return Ok(None);
                    }
                }
                Err(e) => {
                    return Err(UarmError::Io {
                        what: self.name.clone(),
                        source: Box::new(e),
                    });
                }
            }
        }
    }
}

/// Driver settings. `Default`: the SDK's speed of 1000 mm/min, 5 s per acknowledgement.
#[derive(Debug, Clone, PartialEq)]
pub struct DriverConfig {
    /// Speed of moves, mm/min.
    pub speed: f64,
    /// How long to wait for a command's acknowledgement.
    pub ack_timeout: Duration,
    /// How long to wait for a move to arrive (position within `arrival_mm`).
    pub move_timeout: Duration,
    /// Arrival tolerance, mm.
    pub arrival_mm: f64,
}

impl Default for DriverConfig {
    fn default() -> Self {
        Self {
            speed: 1000.0,
            ack_timeout: Duration::from_secs(5),
            move_timeout: Duration::from_secs(10),
            arrival_mm: 1.0,
        }
    }
}

/// A uArm Swift Pro.
pub struct Swift {
    transport: Box<dyn Transport>,
    id: u16,
    config: DriverConfig,
    /// Garbled or unexpected lines skipped so far (diagnostics).
    skipped: usize,
}

impl Swift {
    /// A driver over `transport`.
    pub fn new(transport: Box<dyn Transport>, config: DriverConfig) -> Self {
        Self {
            transport,
            id: 0,
            config,
            skipped: 0,
        }
    }

    /// Garbled, stale or asynchronous lines skipped so far.
    pub fn skipped_lines(&self) -> usize {
        self.skipped
    }

    /// Sends `command` and waits for its acknowledgement; returns the reply's payload. Lines
    /// that are not the reply to this command (garbled, asynchronous, replies to earlier commands
    /// that timed out) are skipped.
    pub fn command(&mut self, command: &str) -> Result<String, UarmError> {
        self.id = next_id(self.id);
        let id = self.id;
        self.transport.write_line(&command_line(id, command))?;
        let deadline = Instant::now() + self.config.ack_timeout;
        loop {
            let left = deadline.saturating_duration_since(Instant::now());
            let Some(line) = self.transport.read_line(left)? else {
                return Err(UarmError::Timeout {
                    command: command.to_owned(),
                    seconds: self.config.ack_timeout.as_secs_f64(),
                });
            };
            match parse_reply(&line) {
                Reply::Ok { id: got, payload } if got == id => return Ok(payload),
                Reply::Error { id: got, code } if got == id => {
                    return Err(UarmError::CommandFailed {
                        command: command.to_owned(),
                        code,
                    });
                }
                _ => self.skipped += 1,
            }
        }
    }

    /// Attaches all servos (needed before moving).
    pub fn attach(&mut self) -> Result<(), UarmError> {
        self.command("M17").map(|_| ())
    }

    /// Detaches all servos: the arm can be moved by hand.
    pub fn detach(&mut self) -> Result<(), UarmError> {
        self.command("M2019").map(|_| ())
    }

    /// The current position, mm.
    pub fn position(&mut self) -> Result<[f64; 3], UarmError> {
        let payload = self.command("P2220")?;
        parse_position(&payload)
            .ok_or_else(|| UarmError::Protocol(format!("cannot read a position from {payload:?}")))
    }

    /// Moves to `target` (mm) and waits until the arm is there.
    pub fn move_to(&mut self, target: [f64; 3]) -> Result<(), UarmError> {
        if target.iter().any(|v| !v.is_finite()) {
            return Err(UarmError::Protocol(format!(
                "refusing to move to a non-finite target {target:?}"
            )));
        }
        self.command(&move_to(target, self.config.speed))?;
        let deadline = Instant::now() + self.config.move_timeout;
        loop {
            let p = self.position()?;
            let distance = ((p[0] - target[0]).powi(2)
                + (p[1] - target[1]).powi(2)
                + (p[2] - target[2]).powi(2))
            .sqrt();
            if distance <= self.config.arrival_mm {
                return Ok(());
            }
            if Instant::now() > deadline {
                return Err(UarmError::Timeout {
                    command: format!("move to {target:?} (stuck at {p:?})"),
                    seconds: self.config.move_timeout.as_secs_f64(),
                });
            }
            std::thread::sleep(Duration::from_millis(20));
        }
    }
}
