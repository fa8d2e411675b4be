//! The serial link through serialport: framed reports in, framed requests out, resynchronising
//! after garbage (frames that fail COBS or the CRC are dropped and counted).

use std::collections::VecDeque;
use std::io::{ErrorKind, Read, Write};
use std::time::{Duration, Instant};

use pen_protocol::{FrameDecoder, GetFeature, MAX_FRAME, MAX_PAYLOAD, Message, ReportId, Status, encode_frame};
use serialport::SerialPort;

use super::{REQUEST_TIMEOUT, Transport, TransportError};

/// A base station's serial link (USB CDC-ACM, a UART bridge, or the simulated pen's
/// pseudo-terminal).
pub struct SerialTransport {
    port: Box<dyn SerialPort>,
    path: String,
    decoder: FrameDecoder,
    /// Input reports that arrived while waiting for an answer, or in the same read.
    inputs: VecDeque<Message>,
    /// Answers (feature reports, status) not yet claimed.
    answers: VecDeque<Message>,
    dropped: u64,
}

impl SerialTransport {
    /// Opens the port at `path`. The baud rate is irrelevant over USB and a pty; 115 200 for a
    /// UART bridge.
    pub fn open(path: &str) -> Result<SerialTransport, TransportError> {
        let port = serialport::new(path, 115_200)
            .timeout(Duration::from_millis(10))
            .open()
            .map_err(|e| match e.kind() {
                serialport::ErrorKind::NoDevice => TransportError::NotFound(format!("{path}: {e}")),
                serialport::ErrorKind::Io(ErrorKind::NotFound) => TransportError::NotFound(format!("{path}: {e}")),
                serialport::ErrorKind::Io(ErrorKind::PermissionDenied) => super::denied(path),
                _ => TransportError::Os(format!("cannot open {path}: {e}")),
            })?;
        Ok(SerialTransport {
            port,
            path: path.to_string(),
            decoder: FrameDecoder::new(),
            inputs: VecDeque::new(),
            answers: VecDeque::new(),
            dropped: 0,
        })
    }

    /// Reads what the port has within `timeout` and sorts the frames into inputs and answers.
    fn pump(&mut self, timeout: Duration) -> Result<(), TransportError> {
        let _ = self.port.set_timeout(timeout.max(Duration::from_millis(1)));
        let mut buf = [0u8; 1024];
        let n = match self.port.read(&mut buf) {
            Ok(0) => return Err(TransportError::Disconnected(format!("{}: end of file", self.path))),
            Ok(n) => n,
            Err(e) if e.kind() == ErrorKind::TimedOut || e.kind() == ErrorKind::WouldBlock => return Ok(()),
            Err(e) if e.kind() == ErrorKind::Interrupted => return Ok(()),
            Err(e) => return Err(TransportError::Disconnected(format!("{}: {e}", self.path))),
        };
        for &b in &buf[..n] {
            match self.decoder.push(b) {
                None => {}
                Some(Err(_)) => self.dropped += 1,
                Some(Ok(payload)) => match Message::decode(payload) {
                    Ok(m @ (Message::Pen(_) | Message::Tof(_) | Message::Head(_))) => self.inputs.push_back(m),
                    Ok(m) => self.answers.push_back(m),
                    // A frame that checks out but holds no valid report: a newer device, or a bug.
                    Err(_) => self.dropped += 1,
                },
            }
        }
        Ok(())
    }

    fn send(&mut self, m: &Message) -> Result<(), TransportError> {
        let mut payload = [0u8; MAX_PAYLOAD];
        let n = m
            .encode(&mut payload)
            .map_err(|e| TransportError::Unexpected(e.to_string()))?;
        let mut frame = [0u8; MAX_FRAME];
        let len = encode_frame(&payload[..n], &mut frame).map_err(|e| TransportError::Unexpected(e.to_string()))?;
        self.port
            .write_all(&frame[..len])
            .map_err(|e| TransportError::Disconnected(format!("{}: {e}", self.path)))
    }

    /// Waits for an answer that `wanted` accepts.
    fn answer(&mut self, what: &'static str, wanted: impl Fn(&Message) -> bool) -> Result<Message, TransportError> {
        let end = Instant::now() + REQUEST_TIMEOUT;
        loop {
            if let Some(i) = self.answers.iter().position(&wanted) {
                return Ok(self
                    .answers
                    .remove(i)
                    .unwrap_or_else(|| unreachable!("position is in range")));
            }
            let now = Instant::now();
            if now >= end {
                return Err(TransportError::Timeout(what));
            }
            self.pump(end - now)?;
        }
    }
}

impl Transport for SerialTransport {
    fn describe(&self) -> String {
        format!("serial {}", self.path)
    }

    fn read(&mut self, timeout: Duration) -> Result<Option<Message>, TransportError> {
        if let Some(m) = self.inputs.pop_front() {
            return Ok(Some(m));
        }
        self.pump(timeout)?;
        Ok(self.inputs.pop_front())
    }

    fn get_feature(&mut self, id: ReportId) -> Result<Message, TransportError> {
        self.answers.clear();
        self.send(&Message::GetFeature(GetFeature { report: id }))?;
        // A refused request is answered with a status report instead.
        let m = self.answer("get-feature", |m| m.id() == id || m.id() == ReportId::Status)?;
        match m {
            Message::Status(s) if id != ReportId::Status => Err(TransportError::Unexpected(s.to_string())),
            m => Ok(m),
        }
    }

    fn set_feature(&mut self, report: &Message) -> Result<Status, TransportError> {
        self.answers.clear();
        self.send(report)?;
        super::expect_status(self.answer("set-feature", |m| matches!(m, Message::Status(_)))?)
    }

    fn dropped(&self) -> u64 {
        self.dropped
    }
}

/// The serial devices of attached base stations (`/dev/ttyACM*` whose USB device is
/// 1209:0007), found through sysfs (Linux).
pub fn list() -> Vec<String> {
    let want = (
        format!("{:04x}", pen_protocol::USB_VID),
        format!("{:04x}", pen_protocol::USB_PID),
    );
    let Ok(entries) = std::fs::read_dir("/sys/class/tty") else {
        return Vec::new();
    };
    let mut out = Vec::new();
    for entry in entries.flatten() {
        let Ok(mut dir) = std::fs::canonicalize(entry.path().join("device")) else {
            continue;
        };
        // Walk up from the interface to the USB device, which has the IDs.
        for _ in 0..4 {
            let read = |f: &str| std::fs::read_to_string(dir.join(f)).map(|s| s.trim().to_string()).ok();
            if let (Some(v), Some(p)) = (read("idVendor"), read("idProduct")) {
                if (v, p) == want {
                    out.push(format!("/dev/{}", entry.file_name().to_string_lossy()));
                }
                break;
            }
            if !dir.pop() {
                break;
            }
        }
    }
    out.sort();
    out
}
