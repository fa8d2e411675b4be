//! The simulated pen in this process: the real firmware core producing the real report bytes
//! (pen-sim), decoded here exactly as bytes from a device are.
//!
//! It can be paced to the wall clock or run as fast as it is read, and unplugged and plugged
//! back (a [`SimPlug`]) to exercise reattachment.

use std::collections::VecDeque;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use pen_protocol::{MAX_PAYLOAD, Message, ReportId, Status};
use pen_sim::sim::MemoryStore;
use pen_sim::{Scenario, Simulation};

use super::{Transport, TransportError};

/// Plugs and unplugs a simulated device from another thread.
#[derive(Debug, Clone)]
pub struct SimPlug(Arc<AtomicBool>);

impl Default for SimPlug {
    fn default() -> Self {
        SimPlug(Arc::new(AtomicBool::new(true)))
    }
}

impl SimPlug {
    /// Whether the device is plugged in.
    pub fn is_plugged(&self) -> bool {
        self.0.load(Ordering::SeqCst)
    }

    /// Plugs it in or pulls it out.
    pub fn set(&self, plugged: bool) {
        self.0.store(plugged, Ordering::SeqCst)
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
    queue: VecDeque<(Instant, Vec<u8>)>,
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
        Ok(SimTransport {
            sim: Simulation::looping(&options.scenario, options.seed),
            queue: VecDeque::new(),
            start: Instant::now(),
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
            if let Some((release, _)) = self.queue.front() {
                // Each report is released when the wall clock reaches its device time.
                let now = Instant::now();
                if *release > deadline {
                    std::thread::sleep(deadline.saturating_duration_since(now));
                    return Ok(None);
                }
                std::thread::sleep(release.saturating_duration_since(now));
                let Some((_, bytes)) = self.queue.pop_front() else {
                    continue;
                };
                return Ok(Some(Message::decode(&bytes)?));
            }
            let record = self.sim.step();
            for sent in record.sent {
                let release = if self.speed > 0.0 {
                    self.start + Duration::from_secs_f64(sent.t_us as f64 * 1e-6 / self.speed)
                } else {
                    self.start
                };
                self.queue.push_back((release, sent.bytes));
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
