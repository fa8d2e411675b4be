//! A client of `pend`: connects to its socket and reads events.

use std::io::{BufRead, BufReader};
use std::os::unix::net::UnixStream;
use std::path::Path;

use serde_json::Value;

use crate::events::{DisplayPoint, EventKind, PenEvent};

/// Why an event line could not be read.
#[derive(Debug, thiserror::Error)]
pub enum ClientError {
    /// The socket failed.
    #[error("pend socket: {0}")]
    Io(#[from] std::io::Error),
    /// A line is not an event.
    #[error("bad event line {line:?}: {why}")]
    Bad {
        /// The line.
        line: String,
        /// What is wrong.
        why: String,
    },
}

/// A line from pend: the greeting, or an event.
#[derive(Debug, Clone, PartialEq)]
pub enum Line {
    /// The first line: whether a device is attached, and which.
    Hello {
        /// The device, if attached.
        device: Option<String>,
    },
    /// An event.
    Event(PenEvent),
}

/// Parses one JSON line (docs/events.md).
pub fn parse_line(line: &str) -> Result<Line, ClientError> {
    let bad = |why: &str| ClientError::Bad {
        line: line.to_string(),
        why: why.to_string(),
    };
    let v: Value = serde_json::from_str(line).map_err(|e| bad(&e.to_string()))?;
    let kind = v.get("type").and_then(Value::as_str).ok_or_else(|| bad("no type"))?;
    let t = v.get("t").and_then(Value::as_f64).ok_or_else(|| bad("no t"))?;
    let t_us = (t * 1e6).round() as u64;
    let num = |k: &str| v.get(k).and_then(Value::as_f64);
    let button = || {
        v.get("button")
            .and_then(Value::as_u64)
            .map(|b| b as u8)
            .ok_or_else(|| bad("no button"))
    };
    let text = |k: &str| v.get(k).and_then(Value::as_str).unwrap_or("").to_string();
    let kind = match kind {
        "hello" => {
            return Ok(Line::Hello {
                device: v.get("device").and_then(Value::as_str).map(str::to_string),
            });
        }
        "proximity_in" => EventKind::ProximityIn,
        "proximity_out" => EventKind::ProximityOut,
        "tip_down" => EventKind::TipDown,
        "tip_up" => EventKind::TipUp,
        "button_down" => EventKind::ButtonDown { button: button()? },
        "button_up" => EventKind::ButtonUp { button: button()? },
        "motion" => EventKind::Motion,
        "device_lost" => EventKind::DeviceLost { reason: text("reason") },
        "device_found" => EventKind::DeviceFound { device: text("device") },
        "missed" => EventKind::Missed {
            count: v.get("count").and_then(Value::as_u64).ok_or_else(|| bad("no count"))?,
        },
        other => return Err(bad(&format!("unknown type {other:?}"))),
    };
    let point = match (num("u_mm"), num("v_mm"), num("h_mm")) {
        (Some(u_mm), Some(v_mm), Some(h_mm)) => Some(DisplayPoint {
            u_mm,
            v_mm,
            h_mm,
            u_px: num("u_px").unwrap_or(0.0),
            v_px: num("v_px").unwrap_or(0.0),
        }),
        _ => None,
    };
    let sw = v.get("sw").and_then(Value::as_array).and_then(|a| {
        let b: Vec<bool> = a.iter().filter_map(Value::as_bool).collect();
        <[bool; 3]>::try_from(b).ok()
    });
    let seq = match (
        v.get("seq").and_then(Value::as_u64),
        v.get("device_us").and_then(Value::as_u64),
    ) {
        (Some(s), Some(d)) => Some((s as u16, d)),
        _ => None,
    };
    Ok(Line::Event(PenEvent {
        kind,
        t_us,
        point,
        sw,
        seq,
    }))
}

/// A connection to pend.
pub struct Client {
    reader: BufReader<UnixStream>,
    line: String,
}

impl Client {
    /// Connects to the socket at `path`.
    pub fn connect(path: &Path) -> Result<Client, ClientError> {
        Ok(Client {
            reader: BufReader::new(UnixStream::connect(path)?),
            line: String::new(),
        })
    }

    /// The next line; `None` when pend closed the connection.
    pub fn next_line(&mut self) -> Option<Result<Line, ClientError>> {
        self.line.clear();
        match self.reader.read_line(&mut self.line) {
            Ok(0) => None,
            Ok(_) => Some(parse_line(self.line.trim_end())),
            Err(e) => Some(Err(e.into())),
        }
    }
}
