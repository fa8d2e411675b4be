//! The simulated pen on a pseudo-terminal: host programs open it with serialport exactly like
//! the base station's USB serial link, and get the same framed reports, in real time.
//!
//! The simulation runs on the device's clock, paced to the wall clock (or faster, by a factor).
//! At every tick the reports sent so far are framed and written, and any requests the host
//! wrote (get-feature, configuration, commands) are answered by the engine, as the firmware's
//! serial task answers them.

use std::cell::RefCell;
use std::io::{Read, Write};
use std::path::{Path, PathBuf};
use std::rc::Rc;
use std::time::{Duration, Instant};

use pen_protocol::{FrameDecoder, MAX_FRAME, MAX_PAYLOAD, encode_frame};
use serialport::{SerialPort, TTYPort};
use thiserror::Error;

use pen_sim::sim::{MemoryStore, Scenario, Sent, Simulation};

/// Bytes the host may leave unread before new reports are dropped rather than queued: a host
/// that stops reading should find fresh reports when it resumes, as with real hardware.
const MAX_BACKLOG: u32 = 4096;

/// Why the pseudo-terminal could not be served.
#[derive(Debug, Error)]
pub enum PtyError {
    /// Creating the pseudo-terminal pair failed.
    #[error("cannot create a pseudo-terminal: {0}")]
    Open(serialport::Error),
    /// The pseudo-terminal has no device path.
    #[error("the pseudo-terminal has no device path")]
    NoPath,
    /// The symbolic link could not be made.
    #[error("cannot link {link} to the pseudo-terminal: {source}")]
    Link {
        /// The link's path.
        link: PathBuf,
        /// Why.
        source: std::io::Error,
    },
}

// Not `#[from]`: that would make the error its source too, and a chain (`{:#}`) would say it
// twice.
impl From<serialport::Error> for PtyError {
    fn from(e: serialport::Error) -> PtyError {
        PtyError::Open(e)
    }
}

/// How to serve.
#[derive(Debug, Clone)]
pub struct ServeOptions {
    /// The session to play, repeated for as long as the server runs.
    pub scenario: Scenario,
    /// Randomness.
    pub seed: u64,
    /// Also make this symbolic link to the device (replaced if it exists), for a stable path.
    pub link: Option<PathBuf>,
    /// Device seconds per wall-clock second; 0 runs as fast as the host reads.
    pub speed: f64,
}

/// What the server has done.
#[derive(Debug, Default, Clone, Copy)]
pub struct ServeCounters {
    /// Frames written.
    pub frames: u64,
    /// Frames dropped because the host was not reading.
    pub dropped: u64,
    /// Requests answered.
    pub requests: u64,
    /// Frames from the host that failed COBS or the CRC.
    pub bad_frames: u64,
}

/// A pseudo-terminal pair whose other end a host opens by its path.
pub struct PtyDevice {
    master: TTYPort,
    path: PathBuf,
}

impl PtyDevice {
    /// Creates the pair and, if asked, the symbolic link.
    pub fn open(link: Option<&Path>) -> Result<PtyDevice, PtyError> {
        let (mut master, slave) = TTYPort::pair()?;
        let path = PathBuf::from(slave.name().ok_or(PtyError::NoPath)?);
        // The host opens the slave side itself; keeping it open here would queue reports for
        // nobody and hand a late host stale ones.
        drop(slave);
        master.set_timeout(Duration::ZERO)?;
        if let Some(link) = link {
            let tmp = link.with_extension("new");
            let _ = std::fs::remove_file(&tmp);
            std::os::unix::fs::symlink(&path, &tmp)
                .and_then(|()| std::fs::rename(&tmp, link))
                .map_err(|source| PtyError::Link {
                    link: link.to_path_buf(),
                    source,
                })?;
        }
        Ok(PtyDevice { master, path })
    }

    /// The device path a host opens (`/dev/pts/N`).
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Writes a framed report unless the host has left too much unread; returns whether it
    /// was written.
    fn write_frame(&mut self, payload: &[u8]) -> bool {
        if self.master.bytes_to_write().unwrap_or(0) > MAX_BACKLOG {
            return false;
        }
        let mut frame = [0u8; MAX_FRAME];
        let Ok(n) = encode_frame(payload, &mut frame) else {
            return false;
        };
        self.master.write_all(&frame[..n]).is_ok()
    }

    /// Bytes the host has written, if any.
    fn read_available(&mut self, buf: &mut [u8]) -> usize {
        match self.master.bytes_to_read() {
            Ok(n) if n > 0 => self.master.read(buf).unwrap_or(0),
            _ => 0,
        }
    }
}

/// Serves until the process is killed. `started` is called once with the device path, before
/// the first report; `status` every ten device seconds with the counters.
pub fn serve(
    options: &ServeOptions,
    started: impl FnOnce(&Path),
    mut status: impl FnMut(ServeCounters),
) -> Result<(), PtyError> {
    let device = Rc::new(RefCell::new(PtyDevice::open(options.link.as_deref())?));
    started(device.borrow().path());
    let mut sim = Simulation::looping(&options.scenario, options.seed);
    let engine = sim.engine();
    let counters = Rc::new(RefCell::new(ServeCounters::default()));
    let (dev, count) = (device.clone(), counters.clone());
    let mut decoder = FrameDecoder::new();
    let mut store = MemoryStore::default();
    let start = Instant::now();
    let speed = options.speed;
    sim.set_pacer(Box::new(move |t_us: u64, sent: &mut Vec<Sent>| {
        if speed > 0.0 {
            let due = start + Duration::from_secs_f64(t_us as f64 * 1e-6 / speed);
            if let Some(wait) = due.checked_duration_since(Instant::now()) {
                std::thread::sleep(wait);
            }
        }
        let mut dev = dev.borrow_mut();
        let mut c = count.borrow_mut();
        for s in sent.drain(..) {
            if dev.write_frame(&s.bytes) {
                c.frames += 1;
            } else {
                c.dropped += 1;
            }
        }
        let mut buf = [0u8; 512];
        let n = dev.read_available(&mut buf);
        for &b in &buf[..n] {
            match decoder.push(b) {
                None => {}
                Some(Err(_)) => c.bad_frames += 1,
                Some(Ok(request)) => {
                    let mut answer = [0u8; MAX_PAYLOAD];
                    let (len, _action) =
                        engine.lock(|e| e.borrow_mut().handle_request(request, &mut answer, &mut store));
                    c.requests += 1;
                    if let Some(len) = len
                        && !dev.write_frame(&answer[..len])
                    {
                        c.dropped += 1;
                    }
                }
            }
        }
    }));
    let mut next_status = 10_000_000;
    loop {
        sim.step();
        if sim.now_us() >= next_status {
            next_status += 10_000_000;
            status(*counters.borrow());
        }
    }
}
