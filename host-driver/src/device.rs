//! A device session that survives unplugging: it reads samples, says when the device goes away,
//! keeps trying to reattach, and says when it is back. While it cannot attach it says so — what
//! it waits for, why the last try failed and what to do — at once and then every
//! [`notice_every`], not at every retry: every tool (pend, penctl, penmodel) shows these same
//! words. At each attach it reads the device's
//! information, so that whoever uses the session knows which base station it is (its unique ID)
//! before the first sample — a calibration is checked against it.

use std::time::{Duration, Instant};

use pen_protocol::{DeviceInfo, Message, ReportId, TofReport, USB_PID, USB_VID};

use crate::head::{HeadSample, HeadSampler};
use crate::sample::{Sample, Sampler, now_us};
use crate::source::Source;
use crate::transport::{Transport, TransportError};

/// How often to try to reattach: a device that returns is back within this much (plus its
/// enumeration).
pub const RETRY_EVERY: Duration = Duration::from_millis(200);

/// How often a session that cannot attach says so: often enough that nobody waits in silence,
/// seldom enough to read (it retries every [`RETRY_EVERY`]).
pub const NOTICE_EVERY: Duration = Duration::from_secs(5);

/// The environment variable that sets [`notice_every`] in seconds (0.1 to 3600; tests use a
/// short one).
pub const NOTICE_ENV: &str = "PENSCAPE_NOTICE_SECS";

/// How often a session that cannot attach says so: [`NOTICE_EVERY`], or [`NOTICE_ENV`] when it
/// holds a number of seconds in range (anything else is ignored).
pub fn notice_every() -> Duration {
    std::env::var(NOTICE_ENV)
        .ok()
        .and_then(|s| s.trim().parse::<f64>().ok())
        .filter(|s| (0.1..=3600.0).contains(s))
        .map(Duration::from_secs_f64)
        .unwrap_or(NOTICE_EVERY)
}

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
    /// A head report (protocol 2.1, the tracked glasses).
    Head(HeadSample),
    /// The device cannot be attached yet: what is awaited, why the last try failed, and what
    /// to do. Said at the first failed try (after a [`Lost`](Self::Lost), which says it waits,
    /// only after [`notice_every`]) and then every [`notice_every`] while it lasts.
    Waiting(String),
}

/// A reattaching session on a [`Source`].
pub struct Device {
    source: Source,
    transport: Option<Box<dyn Transport>>,
    sampler: Sampler,
    head_sampler: HeadSampler,
    next_try: Instant,
    last_error: Option<String>,
    /// Reports the transport returned as invalid since the last attach.
    invalid: u64,
    info: Result<DeviceInfo, String>,
    /// Since when the session has been without a device.
    waiting_since: Instant,
    next_notice: Instant,
    notice_every: Duration,
    /// The session has said it waits (a notice, or the loss).
    said_waiting: bool,
}

impl Device {
    /// A session on `source`; nothing is opened until [`next`](Self::next).
    pub fn new(source: Source) -> Device {
        Device {
            source,
            transport: None,
            sampler: Sampler::new(),
            head_sampler: HeadSampler::new(),
            next_try: Instant::now(),
            last_error: None,
            invalid: 0,
            info: Err("not attached".into()),
            waiting_since: Instant::now(),
            next_notice: Instant::now(),
            notice_every: notice_every(),
            said_waiting: false,
        }
    }

    /// The same session saying that it waits every `every` instead of [`notice_every`].
    pub fn with_notice_every(mut self, every: Duration) -> Device {
        self.notice_every = every;
        self
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

    /// Invalid reports or frames received and dropped since the last attach: what the
    /// transport counted (serial frames failing COBS or the CRC, or holding no valid report)
    /// and reports it refused (HID).
    pub fn dropped(&self) -> u64 {
        self.invalid + self.transport.as_ref().map_or(0, |t| t.dropped())
    }

    /// Why the last attempt to attach failed, if it did, with what to do.
    pub fn last_error(&self) -> Option<&str> {
        self.last_error.as_deref()
    }

    /// Why an attempt to attach failed, with what to do when the error does not say it already.
    fn why_not_attached(&self, e: &TransportError) -> String {
        match (e, &self.source) {
            (TransportError::NotFound(_), Source::Hid(_) | Source::Serial(_)) => {
                format!("{e}; is it plugged in? (`penctl list` lists the base stations attached)")
            }
            // Denied says how to get access; the rest are the OS's or the device's words.
            _ => e.to_string(),
        }
    }

    /// What the session waits for, in words: "the base station on /dev/ttyACM0".
    pub fn awaited(&self) -> String {
        match &self.source {
            Source::Hid(None) => format!("a base station on USB (HID {USB_VID:04x}:{USB_PID:04x})"),
            Source::Hid(Some(path)) => format!("the base station at {path}"),
            Source::Serial(path) => format!("the base station on {path}"),
            #[cfg(feature = "sim")]
            Source::Sim(_) => "the simulated pen".into(),
        }
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
                    self.head_sampler = HeadSampler::new();
                    self.last_error = None;
                    self.invalid = 0;
                    Some(DeviceEvent::Found(name))
                }
                Err(e) => {
                    let why = self.why_not_attached(&e);
                    self.last_error = Some(why.clone());
                    if now < self.next_notice {
                        return None;
                    }
                    self.next_notice = now + self.notice_every;
                    let waited = now.duration_since(self.waiting_since).as_secs();
                    let what = self.awaited();
                    let said = std::mem::replace(&mut self.said_waiting, true);
                    Some(DeviceEvent::Waiting(if said {
                        format!("still waiting for {what} ({waited} s): {why}")
                    } else {
                        format!("waiting for {what}: {why}")
                    }))
                }
            };
        };
        match transport.read(timeout) {
            Ok(Some(Message::Pen(report))) => {
                let (sample, lost) = self.sampler.sample(&report, now_us());
                Some(DeviceEvent::Sample(sample, lost))
            }
            Ok(Some(Message::Tof(t))) => Some(DeviceEvent::Tof(t)),
            Ok(Some(Message::Head(h))) => Some(DeviceEvent::Head(self.head_sampler.sample(&h, now_us()))),
            Ok(_) => None,
            Err(TransportError::Disconnected(why)) => {
                self.transport = None;
                self.info = Err("not attached".into());
                self.next_try = Instant::now();
                // The loss says the session waits; the notices follow if it lasts.
                self.waiting_since = Instant::now();
                self.next_notice = self.waiting_since + self.notice_every;
                self.said_waiting = true;
                Some(DeviceEvent::Lost(why))
            }
            Err(e) => {
                // A bad report is dropped and counted; the device is still there.
                self.last_error = Some(e.to_string());
                self.invalid += 1;
                None
            }
        }
    }
}
