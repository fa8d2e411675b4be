//! A device session that survives unplugging: it reads samples, says when the device goes away,
//! keeps trying to reattach, and says when it is back. At each attach it reads the device's
//! information, so that whoever uses the session knows which base station it is (its unique ID)
//! before the first sample — a calibration is checked against it.

use std::time::{Duration, Instant};

use pen_protocol::{DeviceInfo, Message, ReportId, TofReport};

use crate::sample::{Sample, Sampler, now_us};
use crate::source::Source;
use crate::transport::{Transport, TransportError};

/// How often to try to reattach: a device that returns is back within this much (plus its
/// enumeration).
pub const RETRY_EVERY: Duration = Duration::from_millis(200);

/// What a device session produced.
#[derive(Debug, Clone, PartialEq)]
pub enum DeviceEvent {
    /// The device was attached (or reattached).
    Found(String),
    /// The device went away; the session keeps trying to reattach.
    Lost(String),
    /// A pen report, and the reports lost just before it.
    Sample(Sample, u64),
    /// A time-of-flight diagnostics report.
    Tof(TofReport),
}

/// A reattaching session on a [`Source`].
pub struct Device {
    source: Source,
    transport: Option<Box<dyn Transport>>,
    sampler: Sampler,
    next_try: Instant,
    last_error: Option<String>,
    info: Result<DeviceInfo, String>,
}

impl Device {
    /// A session on `source`; nothing is opened until [`next`](Self::next).
    pub fn new(source: Source) -> Device {
        Device {
            source,
            transport: None,
            sampler: Sampler::new(),
            next_try: Instant::now(),
            last_error: None,
            info: Err("not attached".into()),
        }
    }

    #[allow(missing_docs)]
    pub fn source(&self) -> &Source {
        &self.source
    }

    /// The open transport, for requests; `None` while detached.
    pub fn transport(&mut self) -> Option<&mut (dyn Transport + 'static)> {
        self.transport.as_deref_mut()
    }

    /// Reports received and lost since the last attach.
    pub fn counts(&self) -> (u64, u64) {
        (self.sampler.received(), self.sampler.lost())
    }

    /// Why the last attempt to attach failed, if it did.
    pub fn last_error(&self) -> Option<&str> {
        self.last_error.as_deref()
    }

    /// The attached device's information (read at each attach), or why it could not be read.
    pub fn info(&self) -> Result<&DeviceInfo, &str> {
        self.info.as_ref().map_err(String::as_str)
    }

    /// Lets the device go without its having gone away (it is refused, say), and tries to
    /// reattach only after `retry_in`: a different device may have taken its place by then.
    pub fn detach(&mut self, retry_in: Duration) {
        self.transport = None;
        self.info = Err("not attached".into());
        self.next_try = Instant::now() + retry_in;
    }

    /// Waits at most `timeout` for the next thing to happen.
    pub fn next(&mut self, timeout: Duration) -> Option<DeviceEvent> {
        let Some(transport) = self.transport.as_mut() else {
            let now = Instant::now();
            if now < self.next_try {
                std::thread::sleep((self.next_try - now).min(timeout));
                return None;
            }
            self.next_try = now + RETRY_EVERY;
            return match self.source.open() {
                Ok(mut t) => {
                    let name = t.describe();
                    self.info = match t.get_feature(ReportId::DeviceInfo) {
                        Ok(Message::DeviceInfo(info)) => Ok(info),
                        Ok(other) => Err(format!("it answered with a {} report", other.id())),
                        Err(e) => Err(e.to_string()),
                    };
                    self.transport = Some(t);
                    self.sampler = Sampler::new();
                    self.last_error = None;
                    Some(DeviceEvent::Found(name))
                }
                Err(e) => {
                    self.last_error = Some(e.to_string());
                    None
                }
            };
        };
        match transport.read(timeout) {
            Ok(Some(Message::Pen(report))) => {
                let (sample, lost) = self.sampler.sample(&report, now_us());
                Some(DeviceEvent::Sample(sample, lost))
            }
            Ok(Some(Message::Tof(t))) => Some(DeviceEvent::Tof(t)),
            Ok(_) => None,
            Err(TransportError::Disconnected(why)) => {
                self.transport = None;
                self.info = Err("not attached".into());
                self.next_try = Instant::now();
                Some(DeviceEvent::Lost(why))
            }
            Err(e) => {
                // A bad report is dropped; the device is still there.
                self.last_error = Some(e.to_string());
                None
            }
        }
    }
}
