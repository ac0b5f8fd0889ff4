//! TensorBoard event files beside `metrics.jsonl`: every metrics line of a run is also an event
//! in `events.out.tfevents.seads`, its numbers as scalars at the line's environment step, so
//! that `tensorboard --logdir <sweep>` shows every run of a sweep, named by its directory
//! (environment, variant, seed).
//!
//! This module makes the bytes; the store writes them ([`crate::store::append_metrics`],
//! [`crate::store::write_metrics`], [`crate::store::write_events`]).
//!
//! The file is TensorFlow's record format: per record its length (u64, little-endian), the
//! masked CRC-32C of those 8 bytes, the bytes of an `Event` protocol buffer, and their masked
//! CRC-32C. The first event names the format (`file_version`), each later one holds a
//! `Summary` of simple values. The file follows the metrics: a line appended is an event
//! appended, metrics rewritten (a resume that drops lines) rewrite it, so it is never more than
//! a view of `metrics.jsonl`, which stays the run's record. A line's numbers are its top-level
//! numeric fields (`skill_coverage`, `mean_reward`, losses, `steps_per_s`, …), nested ones under
//! their table's name (`timings/collect`); the step is its `env_steps`, the event's wall time
//! its `wall_s`, the seconds since the run started (TensorBoard's relative time).

use serde::Serialize;

/// The event file of a run directory (TensorBoard reads files whose name holds `tfevents`).
pub const EVENTS: &str = "events.out.tfevents.seads";

/// The format the first event names.
const FILE_VERSION: &str = "brain.Event:2";

/// The fields of a metrics line that are the event's step and time, not scalars.
const NOT_SCALARS: [&str; 3] = ["epoch", "env_steps", "wall_s"];

/// tensorflow/core/util/event.proto's `Event` (the two members of its `what` one-of used here).
#[derive(Clone, PartialEq, prost::Message)]
struct Event {
    #[prost(double, tag = "1")]
    wall_time: f64,
    #[prost(int64, tag = "2")]
    step: i64,
    #[prost(string, optional, tag = "3")]
    file_version: Option<String>,
    #[prost(message, optional, tag = "5")]
    summary: Option<Summary>,
}

/// tensorflow/core/framework/summary.proto's `Summary`.
#[derive(Clone, PartialEq, prost::Message)]
struct Summary {
    #[prost(message, repeated, tag = "1")]
    value: Vec<SummaryValue>,
}

/// `Summary.Value`, a scalar (`simple_value`).
#[derive(Clone, PartialEq, prost::Message)]
struct SummaryValue {
    #[prost(string, tag = "1")]
    tag: String,
    #[prost(float, optional, tag = "2")]
    simple_value: Option<f32>,
}

/// CRC-32C as TensorFlow's records mask it (rotated right by 15 bits, plus a constant).
fn masked_crc(bytes: &[u8]) -> u32 {
    const CASTAGNOLI: crc::Crc<u32> = crc::Crc::<u32>::new(&crc::CRC_32_ISCSI);
    let crc = CASTAGNOLI.checksum(bytes);
    crc.rotate_right(15).wrapping_add(0xa282_ead8)
}

/// One record: length, its masked CRC, the data, its masked CRC.
fn record(data: &[u8]) -> Vec<u8> {
    let length = (data.len() as u64).to_le_bytes();
    let mut out = Vec::with_capacity(data.len() + 16);
    out.extend_from_slice(&length);
    out.extend_from_slice(&masked_crc(&length).to_le_bytes());
    out.extend_from_slice(data);
    out.extend_from_slice(&masked_crc(data).to_le_bytes());
    out
}

/// The record that opens an event file.
fn header() -> Vec<u8> {
    let event = Event {
        file_version: Some(FILE_VERSION.to_owned()),
        ..Event::default()
    };
    record(&prost::Message::encode_to_vec(&event))
}

/// The numbers of a JSON value as (tag, value), nested tables under their name.
fn scalars(prefix: &str, value: &serde_json::Value, out: &mut Vec<SummaryValue>) {
    match value {
        serde_json::Value::Number(n) => {
            if let Some(v) = n.as_f64() {
                out.push(SummaryValue {
                    tag: prefix.to_owned(),
                    simple_value: Some(v as f32),
                });
            }
        }
        serde_json::Value::Object(fields) => {
            for (name, field) in fields {
                let tag = if prefix.is_empty() {
                    name.clone()
                } else {
                    format!("{prefix}/{name}")
                };
                if !(prefix.is_empty() && NOT_SCALARS.contains(&name.as_str())) {
                    scalars(&tag, field, out);
                }
            }
        }
        _ => {}
    }
}

/// The record of one metrics line.
fn line_record<M: Serialize>(line: &M) -> Result<Vec<u8>, serde_json::Error> {
    let json = serde_json::to_value(line)?;
    let mut value = Vec::new();
    scalars("", &json, &mut value);
    let step = json["env_steps"].as_u64().unwrap_or(0);
    let event = Event {
        wall_time: json["wall_s"].as_f64().unwrap_or(0.0),
        step: i64::try_from(step).unwrap_or(i64::MAX),
        file_version: None,
        summary: Some(Summary { value }),
    };
    Ok(record(&prost::Message::encode_to_vec(&event)))
}

/// The bytes to append to a run's event file for one metrics line: its event, after the
/// file's opening record where the file is `new`.
pub fn event<M: Serialize>(line: &M, new: bool) -> Result<Vec<u8>, serde_json::Error> {
    let mut bytes = if new { header() } else { Vec::new() };
    bytes.extend(line_record(line)?);
    Ok(bytes)
}

/// A whole event file holding the events of exactly `lines`.
pub fn events<M: Serialize>(lines: &[M]) -> Result<Vec<u8>, serde_json::Error> {
    let mut bytes = header();
    for line in lines {
        bytes.extend(line_record(line)?);
    }
    Ok(bytes)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// CRC-32C's published check value (of "123456789": 0xE3069283, RFC 3720's Castagnoli
    /// polynomial), masked as TensorFlow masks it, by hand: rotated right 15 bits, plus
    /// 0xa282ead8.
    #[test]
    fn records_carry_tensorflows_masked_crc32c() {
        let crc: u32 = 0xE306_9283;
        // Spelled out, not by `rotate_right` as the code does it.
        #[allow(clippy::manual_rotate)]
        let masked = ((crc >> 15) | (crc << 17)).wrapping_add(0xa282_ead8);
        assert_eq!(masked_crc(b"123456789"), masked);
        let r = record(b"abc");
        assert_eq!(&r[..8], &3u64.to_le_bytes());
        assert_eq!(&r[12..15], b"abc");
        assert_eq!(r.len(), 3 + 16);
    }

    /// A line's numbers become scalars, nested ones under their table's name, step and time
    /// excluded, and anything not a number left out.
    #[test]
    fn a_lines_numbers_are_its_scalars() {
        let line = serde_json::json!({
            "epoch": 5, "env_steps": 600, "wall_s": 1.5, "skill_coverage": 2.25,
            "mean_success": null, "timings": {"collect": 0.5}, "note": "x"
        });
        let mut out = Vec::new();
        scalars("", &line, &mut out);
        let tags: Vec<(&str, f32)> = out
            .iter()
            .map(|v| (v.tag.as_str(), v.simple_value.unwrap()))
            .collect();
        assert_eq!(tags, [("skill_coverage", 2.25), ("timings/collect", 0.5)]);
    }
}
