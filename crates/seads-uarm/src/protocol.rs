//! The uArm Swift Pro serial protocol (uArm-Python-SDK, `uarm/swift/protocol.py`):
//!
//! - ASCII lines at 115200 baud, terminated by `\n`.
//! - A command is sent as `#<id> <command>`, with a sequence number id cycling 1..=9999.
//! - Its reply is `$<id> ok …` (success; the payload follows `ok`) or `$<id> E<code>` (failure).
//! - Lines starting with `@` are asynchronous reports (`@3 X.. Y.. Z..` positions, `@5 V1`
//!   power); anything else is noise (a garbled line) and is skipped.
//!
//! Commands used here (units: mm, mm/min): `G0 X Y Z F` move to a Cartesian point,
//! `P2220` read the position (`$id ok X.. Y.. Z..`), `M17` attach all servos, `M2019` detach them
//! (the arm can then be moved by hand), `M2210 F T` buzzer.

/// A line received from the arm.
#[derive(Debug, Clone, PartialEq)]
pub enum Reply {
    /// `$<id> ok <payload>`.
    Ok {
        /// Sequence number of the command.
        id: u16,
        /// What follows `ok` (trimmed).
        payload: String,
    },
    /// `$<id> E<code>`.
    Error {
        /// Sequence number of the command.
        id: u16,
        /// The error code.
        code: u16,
    },
    /// An asynchronous report (`@…`).
    Report(String),
    /// Anything else.
    Garbled(String),
}

/// The line that sends `command` with sequence number `id`.
pub fn command_line(id: u16, command: &str) -> String {
    format!("#{id} {command}")
}

/// Parses one received line.
pub fn parse_reply(line: &str) -> Reply {
    let line = line.trim();
    if let Some(report) = line.strip_prefix('@') {
        return Reply::Report(report.to_owned());
    }
    let garbled = || Reply::Garbled(line.to_owned());
    let Some(rest) = line.strip_prefix('$') else {
        return garbled();
    };
    let (id, status) = rest.split_once(' ').unwrap_or((rest, ""));
    let Ok(id) = id.parse::<u16>() else {
        return garbled();
    };
    let status = status.trim();
    // By bytes, not characters: a garbled line holds multi-byte U+FFFD.
    if let Some((head, payload)) = status.split_at_checked(2)
        && head.eq_ignore_ascii_case("ok")
    {
        return Reply::Ok {
            id,
            payload: payload.trim().to_owned(),
        };
    }
    match status
        .strip_prefix('E')
        .and_then(|c| c.split_whitespace().next()?.parse().ok())
    {
        Some(code) => Reply::Error { id, code },
        None => garbled(),
    }
}

/// Reads `X… Y… Z…` (as in the reply to `P2220`) into millimetres.
pub fn parse_position(payload: &str) -> Option<[f64; 3]> {
    let mut xyz = [None; 3];
    for token in payload.split_whitespace() {
        let (axis, value) = token.split_at(token.char_indices().nth(1)?.0);
        let slot = match axis {
            "X" | "x" => 0,
            "Y" | "y" => 1,
            "Z" | "z" => 2,
            _ => continue,
        };
        xyz[slot] = Some(value.parse::<f64>().ok().filter(|v| v.is_finite())?);
    }
    Some([xyz[0]?, xyz[1]?, xyz[2]?])
}

/// `G0 X Y Z F`: move to (x, y, z) mm at `speed` mm/min.
pub fn move_to(p: [f64; 3], speed: f64) -> String {
    format!("G0 X{:.2} Y{:.2} Z{:.2} F{:.0}", p[0], p[1], p[2], speed)
}

/// The next sequence number after `id` (1..=9999, cycling).
pub fn next_id(id: u16) -> u16 {
    if id >= 9999 { 1 } else { id + 1 }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn replies_parse() {
        assert_eq!(
            parse_reply("$12 ok"),
            Reply::Ok {
                id: 12,
                payload: String::new()
            }
        );
        assert_eq!(
            parse_reply("$7 OK X150.00 Y0.00 Z150.00\r"),
            Reply::Ok {
                id: 7,
                payload: "X150.00 Y0.00 Z150.00".into()
            }
        );
        assert_eq!(parse_reply("$3 E22"), Reply::Error { id: 3, code: 22 });
        assert_eq!(
            parse_reply("@3 X1 Y2 Z3 R4"),
            Reply::Report("3 X1 Y2 Z3 R4".into())
        );
        for garbled in [
            "",
            "ok",
            "$x ok",
            "$5",
            "$5 maybe",
            "#5 G0",
            "\u{fffd}$5 ok",
            // Issue 13: a garbled status byte became U+FFFD and slicing two bytes panicked.
            "$12 \u{fffd}k",
            "$12 o\u{fffd}",
        ] {
            assert!(
                matches!(parse_reply(garbled), Reply::Garbled(_)),
                "{garbled:?}"
            );
        }
    }

    proptest::proptest! {
        /// Any bytes off the wire, decoded as the driver decodes them, parse without a panic;
        /// replies that do not start with `$`, `@` are garbled.
        #[test]
        fn any_bytes_parse_without_a_panic(bytes in proptest::collection::vec(proptest::num::u8::ANY, 0..40)) {
            let line = String::from_utf8_lossy(&bytes);
            let reply = parse_reply(&line);
            let trimmed = line.trim();
            if !trimmed.starts_with('$') && !trimmed.starts_with('@') {
                proptest::prop_assert!(matches!(reply, Reply::Garbled(_)));
            }
            let _ = parse_position(&line);
        }

        /// A dollar line with a garbled status never panics either (the case above rarely draws).
        #[test]
        fn dollar_lines_with_any_status_parse(id in 0u16..10000, bytes in proptest::collection::vec(proptest::num::u8::ANY, 0..12)) {
            let line = format!("${id} {}", String::from_utf8_lossy(&bytes));
            let _ = parse_reply(&line);
        }
    }

    #[test]
    fn positions_parse_and_reject_junk() {
        assert_eq!(
            parse_position("X150.00 Y-2.5 Z90"),
            Some([150.0, -2.5, 90.0])
        );
        assert_eq!(parse_position("X150 Y2"), None);
        assert_eq!(parse_position("X1 Y2 Zabc"), None);
        assert_eq!(parse_position("X1 Y2 Znan"), None);
    }

    #[test]
    fn commands_and_ids() {
        assert_eq!(
            command_line(4, &move_to([150.0, 0.0, 42.126], 1000.0)),
            "#4 G0 X150.00 Y0.00 Z42.13 F1000"
        );
        assert_eq!(next_id(9999), 1);
        assert_eq!(next_id(1), 2);
    }
}
