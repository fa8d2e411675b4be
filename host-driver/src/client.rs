//! A client of `pend`: connects to its socket, checks that it is served by its own user (or
//! root), asks for `head` lines (events version 4), and reads events.

use std::io::{BufRead, BufReader, Write};
use std::os::unix::net::UnixStream;
use std::path::Path;

use nix::sys::socket::getsockopt;
use nix::sys::socket::sockopt::PeerCredentials;

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

/// Whether a client of user `own_uid` may take the events of a server run by `server_uid`: its
/// own user's pend, or a system-wide one run by root. Anyone else may have put a socket where
/// pend's belongs (a shared folder), and would see what the client sends and feed it false pen
/// events.
pub fn trusted_server(server_uid: u32, own_uid: u32) -> bool {
    server_uid == own_uid || server_uid == 0
}

/// Refuses a server that [`trusted_server`] does not trust, by the kernel's word for who it is
/// (`SO_PEERCRED`: the credentials of the process that bound the socket, which it cannot fake).
fn check_server(stream: &UnixStream, path: &Path) -> Result<(), ClientError> {
    let creds = getsockopt(stream, PeerCredentials)?;
    let (server, own) = (creds.uid(), nix::unistd::getuid().as_raw());
    if trusted_server(server, own) {
        return Ok(());
    }
    Err(ClientError::Io(std::io::Error::new(
        std::io::ErrorKind::PermissionDenied,
        format!(
            "{} is served by a process of user {server} (PID {}), not by you (user {own}) or root; \
             not reading it: another user may have put a socket there (pend --socket in a folder of your own)",
            path.display(),
            creds.pid()
        ),
    )))
}

impl From<nix::errno::Errno> for ClientError {
    fn from(e: nix::errno::Errno) -> ClientError {
        ClientError::Io(std::io::Error::from(e))
    }
}

/// A connection to pend.
pub struct Client {
    reader: BufReader<UnixStream>,
    line: String,
}

impl Client {
    /// Connects to the socket at `path`, refuses it unless it is served by this user or root
    /// (an error of kind `PermissionDenied` naming the server's user), and asks for `head`
    /// lines, which this client reads.
    pub fn connect(path: &Path) -> Result<Client, ClientError> {
        let stream = UnixStream::connect(path)?;
        // Before a byte is written: the request is nobody else's business either.
        check_server(&stream, path)?;
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
    fn only_the_clients_own_user_or_root_may_serve_it() {
        assert!(trusted_server(1000, 1000));
        assert!(trusted_server(0, 1000), "a system-wide pend");
        assert!(trusted_server(0, 0));
        assert!(!trusted_server(1001, 1000), "another user");
        assert!(!trusted_server(1000, 0), "root trusts only root");
        assert!(!trusted_server(65534, 1000));
    }

    /// The real check on a real socket: served by this process, so by this user.
    #[test]
    fn a_socket_served_by_the_clients_own_user_is_taken() {
        let tmp = tempfile::tempdir().expect("tempdir");
        let path = tmp.path().join("pend.sock");
        let listener = std::os::unix::net::UnixListener::bind(&path).expect("bind");
        let client = Client::connect(&path).expect("our own server is trusted");
        let (served, _) = listener.accept().expect("accept");
        let creds = getsockopt(&served, PeerCredentials).expect("peer");
        assert_eq!(creds.uid(), nix::unistd::getuid().as_raw());
        drop(client);
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
