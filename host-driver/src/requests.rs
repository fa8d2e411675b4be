//! What a client of pend asks for (events version 4, docs/events.md): the lines it writes, read
//! by its writer thread between writes, never waiting for them. A client that writes nothing
//! reads what a version-2 client knows (and the greeting's version); one that writes a
//! `subscribe` line naming `head` reads `head` lines too. Anything else it writes is ignored.

use std::io::Read;
use std::os::fd::AsFd;
use std::os::unix::net::UnixStream;

use nix::poll::{PollFd, PollFlags, PollTimeout, poll};

use crate::wire::ClientLine;

/// The longest line a client may write: a longer one is skipped up to its newline, so a client
/// writing without end costs a bounded buffer.
const MAX_LINE: usize = 1024;

/// Reads per call at most, so a client writing without end cannot keep its writer from writing.
const MAX_READS: usize = 8;

/// A client's requests so far, and the line it is writing.
#[derive(Debug, Default)]
pub struct Requests {
    partial: Vec<u8>,
    /// The line being written is too long: skipped up to its newline.
    skipping: bool,
    head: bool,
    /// The client shut its writing side: it will ask for nothing more, but may still read.
    done_asking: bool,
}

impl Requests {
    /// Whether the client asked for `head` lines.
    pub fn head(&self) -> bool {
        self.head
    }

    /// Takes bytes the client wrote, a line at a time.
    pub fn take(&mut self, bytes: &[u8]) {
        for &b in bytes {
            if b == b'\n' {
                if !self.skipping {
                    self.line();
                }
                self.partial.clear();
                self.skipping = false;
            } else if !self.skipping {
                if self.partial.len() >= MAX_LINE {
                    self.partial.clear();
                    self.skipping = true;
                } else {
                    self.partial.push(b);
                }
            }
        }
    }

    fn line(&mut self) {
        let asked = std::str::from_utf8(&self.partial)
            .ok()
            .and_then(|text| serde_json::from_str::<ClientLine>(text.trim()).ok());
        if asked.is_some_and(|l| l.wants_head()) {
            self.head = true;
        }
    }

    /// Takes what the client has written, without waiting for more; whether it left (closed
    /// its socket, or the socket failed). A client that only shut its writing side (`socat -
    /// UNIX-CONNECT:… </dev/null`, `shutdown(SHUT_WR)`) has not left: it is served until a
    /// write to it fails.
    pub fn read(&mut self, stream: &UnixStream) -> bool {
        let mut buf = [0u8; 512];
        for _ in 0..MAX_READS {
            // Once its writing side is shut the socket is always readable (at its end): then
            // only a hang-up, which the kernel reports whatever is asked, says it left.
            let wanted = if self.done_asking {
                PollFlags::empty()
            } else {
                PollFlags::POLLIN
            };
            let mut fds = [PollFd::new(stream.as_fd(), wanted)];
            if poll(&mut fds, PollTimeout::ZERO).is_err() {
                return false;
            }
            let events = fds[0].revents().unwrap_or(PollFlags::empty());
            // POLLHUP: both directions shut, so it closed its socket (a write would fail).
            if events.intersects(PollFlags::POLLHUP | PollFlags::POLLERR | PollFlags::POLLNVAL) {
                return true;
            }
            if !events.contains(PollFlags::POLLIN) {
                return false;
            }
            match (&*stream).read(&mut buf) {
                Ok(0) => {
                    self.done_asking = true;
                    return false;
                }
                Ok(n) => self.take(&buf[..n]),
                Err(e) => {
                    return !matches!(
                        e.kind(),
                        std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut | std::io::ErrorKind::Interrupted
                    );
                }
            }
        }
        false
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_subscribe_line_naming_head_asks_for_head_lines() {
        let mut r = Requests::default();
        // Split anywhere, other lines and unknown names around it.
        r.take(b"hello\n{\"type\":\"subscribe\",\"lines\":[\"sparkles\"]}\n{\"type\":\"subsc");
        assert!(!r.head());
        r.take(b"ribe\",\"lines\":[\"sparkles\",\"head\"]}");
        assert!(!r.head(), "not before its newline");
        r.take(b"\n");
        assert!(r.head());
    }

    #[test]
    fn other_lines_ask_for_nothing() {
        for line in [
            "{\"type\":\"subscribe\",\"lines\":[]}\n",
            "{\"type\":\"subscribe\",\"lines\":\"head\"}\n",
            "{\"type\":\"unsubscribe\",\"lines\":[\"head\"]}\n",
            "{\"lines\":[\"head\"]}\n",
            "head\n",
        ] {
            let mut r = Requests::default();
            r.take(line.as_bytes());
            assert!(!r.head(), "{line}");
        }
    }

    #[test]
    fn an_overlong_line_is_skipped_to_its_newline() {
        let mut r = Requests::default();
        let ask = ClientLine::subscribe_head().to_text();
        // The request inside a line too long to keep: ignored, and the buffer stays bounded.
        let long = format!("{}{}", "x".repeat(MAX_LINE), ask);
        r.take(long.as_bytes());
        assert!(!r.head());
        assert!(r.partial.len() <= MAX_LINE);
        // The next line is read again.
        r.take(ask.as_bytes());
        assert!(r.head());
    }
}
