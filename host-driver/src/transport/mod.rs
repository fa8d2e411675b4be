//! Transports: one interface over the ways a base station reaches the host — USB HID through
//! hidapi ([`hid`]), the serial link through serialport ([`serial`]), and, with the cargo
//! feature `sim`, the simulated pen in this process (`sim`).

pub mod hid;
pub mod serial;
#[cfg(feature = "sim")]
pub mod sim;

use std::time::Duration;

use pen_protocol::{DecodeError, Message, ReportId, Status};
use thiserror::Error;

/// The status a set-feature request is answered with; any other report is unexpected.
pub fn expect_status(answer: Message) -> Result<Status, TransportError> {
    match answer {
        Message::Status(s) => Ok(s),
        other => Err(TransportError::Unexpected(format!(
            "{:?} report instead of the status",
            other.id()
        ))),
    }
}

/// Why a transport call failed.
#[derive(Debug, Error)]
pub enum TransportError {
    /// The device is gone (unplugged, the port closed); the caller reattaches.
    #[error("device disconnected: {0}")]
    Disconnected(String),
    /// No device matched.
    #[error("no device found: {0}")]
    NotFound(String),
    /// The device did not answer a request in time.
    #[error("no answer from the device to the {0} request")]
    Timeout(&'static str),
    /// The device sent bytes that are not a valid report.
    #[error("invalid report from the device: {0}")]
    Protocol(#[from] DecodeError),
    /// The device answered with something other than what was asked.
    #[error("unexpected answer from the device: {0}")]
    Unexpected(String),
    /// The operating system refused (a busy port, an I/O error).
    #[error("{0}")]
    Os(String),
    /// This user may not open the device's file; `fix` says how to allow it ([`denied`]).
    #[error("cannot open {path}: {why}; {fix}")]
    Denied {
        /// The device's file.
        path: String,
        /// The OS's words.
        why: String,
        /// What to do.
        fix: String,
    },
}

/// The udev rules that give the base station's devices to the `plugdev` group.
pub const UDEV_RULES: &str = "host-driver/udev/70-penscape.rules";

/// Permission to open `path` was denied: the error, with what to do. A file of group `root` has
/// no rule giving it to a group yet (the udev rules do, for the base station); any other group
/// (`plugdev`, `dialout`) is one to join.
pub fn denied(path: &str) -> TransportError {
    use std::os::unix::fs::MetadataExt;
    let group = std::fs::metadata(path)
        .ok()
        .and_then(|m| {
            nix::unistd::Group::from_gid(nix::unistd::Gid::from_raw(m.gid()))
                .ok()
                .flatten()
        })
        .map(|g| g.name);
    let rules = format!(
        "install the udev rules ({UDEV_RULES}: sudo cp {UDEV_RULES} /etc/udev/rules.d/ && sudo udevadm control \
         --reload && sudo udevadm trigger), which give the base station to group plugdev"
    );
    let fix = match group.as_deref() {
        Some(g) if g != "root" => format!(
            "{path} belongs to group {g}: join it (sudo usermod -aG {g} $USER, then log in again); for the base \
             station, {rules}"
        ),
        _ => format!("{rules}; join that group (sudo usermod -aG plugdev $USER, then log in again) and replug it"),
    };
    TransportError::Denied {
        path: path.to_string(),
        why: nix::errno::Errno::EACCES.desc().to_string(),
        fix,
    }
}

/// A connection to one base station.
pub trait Transport {
    /// Which device, for messages (`hid /dev/hidraw3`, `serial /dev/ttyACM0`, `sim`).
    fn describe(&self) -> String;

    /// The next input report (pen or time-of-flight), waiting at most `timeout`; `None` if none
    /// came. Invalid reports are skipped and counted, not returned.
    fn read(&mut self, timeout: Duration) -> Result<Option<Message>, TransportError>;

    /// Reads a feature report.
    fn get_feature(&mut self, id: ReportId) -> Result<Message, TransportError>;

    /// Writes a feature report (a configuration or a command) and returns the device's status.
    fn set_feature(&mut self, report: &Message) -> Result<Status, TransportError>;

    /// Invalid reports or frames received and dropped so far.
    fn dropped(&self) -> u64 {
        0
    }
}

/// How long a request waits for its answer.
pub const REQUEST_TIMEOUT: Duration = Duration::from_millis(500);
