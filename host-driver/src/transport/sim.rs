//! The simulated pen in this process: the real firmware core producing the real report bytes
//! (pen-sim), decoded here exactly as bytes from a device are.
//!
//! It can be paced to the wall clock or run as fast as it is read, and unplugged and plugged
//! back (a [`SimPlug`]) to exercise reattachment.

use std::collections::VecDeque;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use pen_protocol::{MAX_PAYLOAD, Message, ReportId, Status};
use pen_sim::sim::MemoryStore;
use pen_sim::{Scenario, Simulation};

use super::{Transport, TransportError};

/// Plugs and unplugs a simulated device from another thread, and reads its clock there.
#[derive(Debug, Clone)]
pub struct SimPlug {
    plugged: Arc<AtomicBool>,
    clock: DeviceClock,
}

impl Default for SimPlug {
    fn default() -> Self {
        SimPlug {
            plugged: Arc::new(AtomicBool::new(true)),
            clock: DeviceClock::default(),
        }
    }
}

impl SimPlug {
    /// Whether the device is plugged in.
    pub fn is_plugged(&self) -> bool {
        self.plugged.load(Ordering::SeqCst)
    }

    /// Plugs it in or pulls it out.
    pub fn set(&self, plugged: bool) {
        self.plugged.store(plugged, Ordering::SeqCst)
    }

    /// The simulated device's clock, readable from any thread.
    pub fn clock(&self) -> DeviceClock {
        self.clock.clone()
    }
}

/// The simulated device's clock (µs since it was last opened), for measuring on the device's
/// time what a host does with its reports: a report with timestamp `t` is about something that
/// happened `now_us() - t` ago. Paced (speed > 0) it is the wall clock since the device opened
/// times the speed, as the transport releases each report at its device time; unpaced, the
/// simulation runs only as far as it is read, so the device's "now" is the device time of the
/// last report read.
#[derive(Debug, Clone, Default)]
pub struct DeviceClock(Arc<Mutex<ClockState>>);

#[derive(Debug, Default)]
struct ClockState {
    /// When the device was opened, and its speed.
    opened: Option<(Instant, f64)>,
    /// The device time of the last report read, µs.
    read_us: u64,
}

impl DeviceClock {
    fn state(&self) -> std::sync::MutexGuard<'_, ClockState> {
        self.0.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// The device's time now, µs; `None` before it was opened.
    pub fn now_us(&self) -> Option<u64> {
        let s = self.state();
        let (start, speed) = s.opened?;
        Some(if speed > 0.0 {
            (start.elapsed().as_secs_f64() * speed * 1e6) as u64
        } else {
            s.read_us
        })
    }

    /// Whether the clock follows the wall clock (a paced device).
    pub fn is_paced(&self) -> bool {
        self.state().opened.is_some_and(|(_, speed)| speed > 0.0)
    }

    fn opened(&self, start: Instant, speed: f64) {
        *self.state() = ClockState {
            opened: Some((start, speed)),
            read_us: 0,
        };
    }

    fn read(&self, t_us: u64) {
        let mut s = self.state();
        s.read_us = s.read_us.max(t_us);
    }
}

/// Two handles to the same clock are equal.
impl PartialEq for DeviceClock {
    fn eq(&self, other: &DeviceClock) -> bool {
        Arc::ptr_eq(&self.0, &other.0)
    }
}

/// How the simulated pen runs.
#[derive(Debug, Clone)]
pub struct SimOptions {
    /// The session, repeated.
    pub scenario: Scenario,
    /// Seeds the hand's tremor, the acoustics' noise and the switches' bounce.
    pub seed: u64,
    /// Device seconds per wall-clock second; 0 runs as fast as it is read.
    pub speed: f64,
    /// Keep a clone to unplug the device from another thread.
    pub plug: SimPlug,
}

/// The simulated pen as a transport.
pub struct SimTransport {
    sim: Simulation,
    /// Reports waiting for their release: when, their device time, their bytes.
    queue: VecDeque<(Instant, u64, Vec<u8>)>,
    start: Instant,
    speed: f64,
    plug: SimPlug,
    store: MemoryStore,
    name: String,
}

impl SimTransport {
    /// Starts the simulation; fails while unplugged.
    pub fn open(options: &SimOptions) -> Result<SimTransport, TransportError> {
        if !options.plug.is_plugged() {
            return Err(TransportError::NotFound("the simulated pen is unplugged".into()));
        }
        let start = Instant::now();
        options.plug.clock.opened(start, options.speed);
        Ok(SimTransport {
            sim: Simulation::looping(&options.scenario, options.seed),
            queue: VecDeque::new(),
            start,
            speed: options.speed,
            plug: options.plug.clone(),
            store: MemoryStore::default(),
            name: format!("sim {}", options.scenario.name),
        })
    }

    fn check_plug(&self) -> Result<(), TransportError> {
        if self.plug.is_plugged() {
            Ok(())
        } else {
            Err(TransportError::Disconnected("unplugged".into()))
        }
    }

    fn request(&mut self, m: &Message) -> Result<Message, TransportError> {
        self.check_plug()?;
        let mut bytes = [0u8; MAX_PAYLOAD];
        let n = m
            .encode(&mut bytes)
            .map_err(|e| TransportError::Unexpected(e.to_string()))?;
        let mut answer = [0u8; MAX_PAYLOAD];
        let engine = self.sim.engine();
        let store = &mut self.store;
        let (len, _action) = engine.lock(|e| e.borrow_mut().handle_request(&bytes[..n], &mut answer, store));
        let len = len.ok_or(TransportError::Timeout("request"))?;
        Ok(Message::decode(&answer[..len])?)
    }
}

impl Transport for SimTransport {
    fn describe(&self) -> String {
        self.name.clone()
    }

    fn read(&mut self, timeout: Duration) -> Result<Option<Message>, TransportError> {
        self.check_plug()?;
        let deadline = Instant::now() + timeout;
        loop {
            if let Some((release, _, _)) = self.queue.front() {
                // Each report is released when the wall clock reaches its device time.
                let now = Instant::now();
                if *release > deadline {
                    std::thread::sleep(deadline.saturating_duration_since(now));
                    return Ok(None);
                }
                std::thread::sleep(release.saturating_duration_since(now));
                let Some((_, t_us, bytes)) = self.queue.pop_front() else {
                    continue;
                };
                self.plug.clock.read(t_us);
                return Ok(Some(Message::decode(&bytes)?));
            }
            let record = self.sim.step();
            for sent in record.sent {
                let release = if self.speed > 0.0 {
                    self.start + Duration::from_secs_f64(sent.t_us as f64 * 1e-6 / self.speed)
                } else {
                    self.start
                };
                self.queue.push_back((release, sent.t_us, sent.bytes));
            }
        }
    }

    fn get_feature(&mut self, id: ReportId) -> Result<Message, TransportError> {
        self.request(&Message::GetFeature(pen_protocol::GetFeature { report: id }))
    }

    fn set_feature(&mut self, report: &Message) -> Result<Status, TransportError> {
        super::expect_status(self.request(report)?)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The device time a report is about (its burst), for the reports that carry one.
    fn timestamp(m: &Message) -> Option<u64> {
        match m {
            Message::Pen(r) => Some(u64::from(r.timestamp_us)),
            Message::Head(r) => Some(u64::from(r.timestamp_us)),
            _ => None,
        }
    }

    /// The clock is never behind a report read (a report is sent after its burst), restarts
    /// when the device is opened again, and is readable from a clone of the plug.
    #[test]
    fn the_device_clock_is_never_behind_a_report_read() {
        for speed in [0.0, 20.0] {
            let plug = SimPlug::default();
            let clock = plug.clone().clock();
            assert_eq!(clock.now_us(), None, "before the device is opened");
            let options = SimOptions {
                scenario: pen_sim::scenarios::by_name("viewer").expect("scenario"),
                seed: 1,
                speed,
                plug,
            };
            let mut t = SimTransport::open(&options).expect("open");
            assert_eq!(clock.is_paced(), speed > 0.0);
            let (mut reports, mut heads) = (0, 0);
            while reports < 40 {
                let Some(m) = t.read(Duration::from_secs(1)).expect("read") else {
                    continue;
                };
                heads += usize::from(matches!(m, Message::Head(_)));
                if let Some(ts) = timestamp(&m) {
                    reports += 1;
                    let now = clock.now_us().expect("opened");
                    assert!(now >= ts, "speed {speed}: clock {now} µs behind a report of {ts} µs");
                }
            }
            assert!(heads > 0, "the viewer's head reports are read too");
            let before = clock.now_us().expect("opened");
            let _again = SimTransport::open(&options).expect("reopen");
            assert!(clock.now_us().expect("opened") < before, "reopened: the clock restarts");
        }
    }
}
