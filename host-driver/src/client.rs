//! A client of `pend`: connects to its socket, asks for `head` lines (events version 4), and
//! reads events.

use std::io::{BufRead, BufReader, Write};
use std::os::unix::net::UnixStream;
use std::path::Path;

use crate::events::PenEvent;
use crate::wire::{ClientLine, SocketLine};

/// Why an event line could not be read.
#[derive(Debug, thiserror::Error)]
#[allow(missing_docs)]
pub enum ClientError {
    /// The socket failed.
    #[error("pend socket: {0}")]
    Io(std::io::Error),
    /// A line is not an event.
    #[error("bad event line {line:?}: {why}")]
    Bad { line: String, why: String },
}

// Not `#[from]`: that would make the error its source too, and a chain (`{:#}`) would say it
// twice.
impl From<std::io::Error> for ClientError {
    fn from(e: std::io::Error) -> ClientError {
        ClientError::Io(e)
    }
}

/// A line from pend: the greeting, or an event.
#[derive(Debug, Clone, PartialEq)]
#[allow(missing_docs)]
pub enum Line {
    /// The first line: whether a device is attached, and which.
    Hello {
        /// The device, if attached.
        device: Option<String>,
    },
    Event(PenEvent),
}

/// Parses one JSON line (docs/events.md): a line that is not JSON, lacks a key its `type`
/// needs, or has one of the wrong type or range is an error saying which. pend's refusal is a
/// `ConnectionRefused` I/O error with its reason.
pub fn parse_line(line: &str) -> Result<Line, ClientError> {
    let bad = |why: String| ClientError::Bad {
        line: line.to_string(),
        why,
    };
    let wire: SocketLine = serde_json::from_str(line).map_err(|e| bad(e.to_string()))?;
    let device = match &wire {
        SocketLine::Hello(h) => Some(h.device.clone()),
        // Not a bad line but a closed door: an I/O error of the connection's kind, so a caller
        // that stops on socket errors stops here too, with pend's reason.
        SocketLine::Refused(r) => {
            return Err(ClientError::Io(std::io::Error::new(
                std::io::ErrorKind::ConnectionRefused,
                format!("pend refused this client: {}", r.reason),
            )));
        }
        _ => None,
    };
    match wire.into_event().map_err(|e| bad(e.to_string()))? {
        Some(event) => Ok(Line::Event(event)),
        None => Ok(Line::Hello {
            device: device.flatten(),
        }),
    }
}

/// A connection to pend.
pub struct Client {
    reader: BufReader<UnixStream>,
    line: String,
}

impl Client {
    /// Connects to the socket at `path` and asks for `head` lines, which this client reads.
    pub fn connect(path: &Path) -> Result<Client, ClientError> {
        let stream = UnixStream::connect(path)?;
        // Unanswered: a pend that refused the client has closed its end, and the refusal's
        // reason is what the client should read next, not a failed write; an older pend
        // ignores what clients write (and sends every line anyway).
        let _ = (&stream).write_all(ClientLine::subscribe_head().to_text().as_bytes());
        Ok(Client {
            reader: BufReader::new(stream),
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::events::EventKind;

    fn why(line: &str) -> String {
        match parse_line(line) {
            Err(ClientError::Bad { why, .. }) => why,
            other => panic!("{line}: {other:?}"),
        }
    }

    #[test]
    fn good_lines_read() {
        let hello = parse_line(r#"{"type":"hello","t":1.5,"events":1,"connected":false,"device":null}"#);
        assert_eq!(hello.ok(), Some(Line::Hello { device: None }));
        let Ok(Line::Event(e)) = parse_line(
            r#"{"type":"button_up","t":2.000001,"u_mm":1,"v_mm":2,"h_mm":3,"u_px":4,"v_px":5,"button":3,"sw":[true,false,false],"seq":7,"device_us":9,"later":"ignored"}"#,
        ) else {
            panic!("a button event")
        };
        assert_eq!(e.kind, EventKind::ButtonUp { button: 3 });
        assert_eq!(
            (e.t_us, e.seq, e.sw),
            (2_000_001, Some((7, 9)), Some([true, false, false]))
        );
        assert_eq!(e.point.map(|p| p.v_px), Some(5.0));
    }

    #[test]
    fn a_refusal_is_a_refused_connection_with_the_reason() {
        let line = r#"{"type":"refused","t":1.5,"reason":"pend serves at most 64 clients at once"}"#;
        match parse_line(line) {
            Err(ClientError::Io(e)) => {
                assert_eq!(e.kind(), std::io::ErrorKind::ConnectionRefused);
                assert!(e.to_string().contains("at most 64 clients"), "{e}");
            }
            other => panic!("{other:?}"),
        }
        assert!(why(r#"{"type":"refused","t":1}"#).contains("missing field `reason`"));
    }

    #[test]
    fn malformed_lines_are_errors_not_defaults() {
        let cases = [
            ("not json", "expected ident"),
            (r#"{"t":1}"#, "missing field `type`"),
            (r#"{"type":"wobble","t":1}"#, "unknown variant `wobble`"),
            (r#"{"type":"motion"}"#, "missing field `t`"),
            (r#"{"type":"motion","t":"now"}"#, "invalid type"),
            (r#"{"type":"motion","t":-1}"#, "not a time"),
            (r#"{"type":"motion","t":1,"u_mm":1,"v_mm":2,"h_mm":3}"#, "u_px"),
            (r#"{"type":"motion","t":1,"seq":70000,"device_us":1}"#, "70000"),
            (r#"{"type":"motion","t":1,"seq":7}"#, "seq and device_us"),
            (r#"{"type":"motion","t":1,"sw":[true,false]}"#, "invalid length 2"),
            (r#"{"type":"button_down","t":1}"#, "missing field `button`"),
            (r#"{"type":"button_down","t":1,"button":1}"#, "button 1 is not 2 or 3"),
            (r#"{"type":"button_down","t":1,"button":258}"#, "258"),
            (r#"{"type":"device_lost","t":1}"#, "missing field `reason`"),
            (r#"{"type":"missed","t":1,"count":-2}"#, "-2"),
            (r#"{"type":"hello","t":1,"events":1}"#, "missing field `connected`"),
        ];
        for (line, expected) in cases {
            let why = why(line);
            assert!(why.contains(expected), "{line}: {why}");
        }
    }
}
