//! The simulated base station: the real firmware core (`pen-core`'s engine and station loop)
//! driven through its hardware traits by the simulated world, on a virtual clock.
//!
//! [`Simulation::step`] runs one measurement cycle exactly as the board does — burst, switch
//! samples every tick, capture collection, reports — and returns what happened: the truth, what
//! the receivers heard, the engine's fix, and the report bytes the device sent. Runs are
//! deterministic for a given seed.

use std::cell::RefCell;
use std::rc::Rc;

use embassy_futures::block_on;
use embassy_sync::blocking_mutex::Mutex;
use embassy_sync::blocking_mutex::raw::NoopRawMutex;
use glam::DVec3;
use pen_core::{
    Clock, ConfigStore, CycleResult, Engine, Ranging, ReportSink, SharedEngine, Station, StoreError, Switches,
};
use pen_protocol::{Config, FirmwareVersion, MAX_RECEIVERS, PenReport, Report, TofReport};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

use crate::acoustics::{Acoustics, Heard};
use crate::hand::Hand;
use crate::rig::Rig;
use crate::script::Timeline;

/// The firmware version the simulated device reports.
pub const SIM_FIRMWARE: FirmwareVersion = FirmwareVersion {
    major: 0,
    minor: 1,
    patch: 0,
};
/// The simulated device's unique ID.
pub const SIM_UNIQUE_ID: [u8; 12] = *b"penscape-sim";

/// A complete simulated session: the world, the hand's script, the device's configuration.
#[derive(Debug, Clone)]
pub struct Scenario {
    /// Its name.
    pub name: String,
    /// The physical set-up.
    pub rig: Rig,
    /// The sound.
    pub acoustics: Acoustics,
    /// What the hand does.
    pub timeline: Timeline,
    /// The configuration the device runs.
    pub config: Config,
    /// The unique ID the device reports ([`SIM_UNIQUE_ID`] unless set otherwise): another
    /// one stands for another base station, whose calibration is not this one's.
    pub unique_id: [u8; 12],
}

impl Scenario {
    /// A scenario whose device is configured from the rig, at the air's starting temperature.
    pub fn new(name: &str, rig: Rig, acoustics: Acoustics, timeline: Timeline) -> Scenario {
        let config = rig.config(acoustics.air.base_c);
        Scenario {
            name: name.to_string(),
            rig,
            acoustics,
            timeline,
            config,
            unique_id: SIM_UNIQUE_ID,
        }
    }

    /// The same session on a base station reporting `unique_id`.
    pub fn with_unique_id(self, unique_id: [u8; 12]) -> Scenario {
        Scenario { unique_id, ..self }
    }
}

/// A report as the device sent it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Sent {
    /// Device time, µs.
    pub t_us: u64,
    /// The report's bytes, report ID first: what goes into a HID report or a serial frame.
    pub bytes: Vec<u8>,
}

/// One measurement cycle.
#[derive(Debug, Clone, PartialEq)]
pub struct CycleRecord {
    /// Device time of the burst, µs.
    pub t0_us: u64,
    /// Where the emitter really was, tracker frame, mm.
    pub truth_mm: DVec3,
    /// What the receivers heard.
    pub heard: Heard,
    /// The engine's fix (before smoothing) or why there was none.
    pub result: CycleResult,
    /// The pen report of this cycle (sent when the listening window closed).
    pub report: Option<PenReport>,
    /// The switches as the hand meant them at the end of the cycle.
    pub intended_switches: [bool; 3],
    /// Every report the device sent during the cycle, in order.
    pub sent: Vec<Sent>,
    /// The switch samples the station took during the cycle, one per tick, as bits (SW1 = 1,
    /// SW2 = 2, SW3 = 4): with the captures, everything the core was given.
    pub switch_samples: Vec<u8>,
}

/// Called at every tick with the device time and the reports sent since the last call; the
/// pseudo-terminal server uses it to keep real time and stream the reports.
pub type Pacer = Box<dyn FnMut(u64, &mut Vec<Sent>)>;

struct World {
    now_us: u64,
    rig: Rig,
    acoustics: Acoustics,
    hand: Hand,
    rng: ChaCha8Rng,
    heard: Option<(DVec3, Heard)>,
    sent: Vec<Sent>,
    samples: Vec<u8>,
    pacer: Option<Pacer>,
}

type Shared = Rc<RefCell<World>>;

struct SimRanging(Shared);
struct SimSwitches(Shared);
struct SimClock(Shared);
struct SimSink(Shared);

impl Ranging for SimRanging {
    fn fire(&mut self) {
        let mut w = self.0.borrow_mut();
        let w = &mut *w;
        let t_s = w.now_us as f64 * 1e-6;
        let emitter = w.hand.emitter(&w.rig, t_s);
        let heard = w.acoustics.hear(&w.rig, emitter, t_s, &mut w.rng);
        w.heard = Some((emitter, heard));
    }

    fn collect(&mut self) -> [Option<u32>; MAX_RECEIVERS] {
        self.0
            .borrow()
            .heard
            .map_or([None; MAX_RECEIVERS], |(_, h)| h.arrival_ns)
    }
}

impl Switches for SimSwitches {
    fn read(&mut self) -> [bool; 3] {
        let mut w = self.0.borrow_mut();
        let raw = w.hand.raw_switches(w.now_us as f64 * 1e-6);
        w.samples.push(raw[0] as u8 | (raw[1] as u8) << 1 | (raw[2] as u8) << 2);
        raw
    }
}

impl Clock for SimClock {
    fn now_us(&self) -> u64 {
        self.0.borrow().now_us
    }

    async fn wait_until(&mut self, t_us: u64) {
        let mut w = self.0.borrow_mut();
        let w = &mut *w;
        w.now_us = w.now_us.max(t_us);
        if let Some(pacer) = w.pacer.as_mut() {
            pacer(w.now_us, &mut w.sent);
        }
    }
}

impl SimSink {
    fn push<R: Report>(&mut self, report: &R) {
        let mut w = self.0.borrow_mut();
        let mut buf = vec![0u8; R::LEN];
        // The buffer has exactly the report's length.
        let _ = report.encode(&mut buf);
        let t_us = w.now_us;
        w.sent.push(Sent { t_us, bytes: buf });
    }
}

impl ReportSink for SimSink {
    async fn pen(&mut self, report: &PenReport) {
        self.push(report);
    }

    async fn tof(&mut self, report: &TofReport) {
        self.push(report);
    }
}

/// The simulated device's configuration storage: memory that lasts as long as the simulation.
#[derive(Debug, Default)]
pub struct MemoryStore {
    /// The saved configuration.
    pub saved: Option<Config>,
}

impl ConfigStore for MemoryStore {
    fn load(&mut self) -> Option<Config> {
        self.saved
    }

    fn save(&mut self, config: &Config) -> Result<(), StoreError> {
        self.saved = Some(*config);
        Ok(())
    }
}

/// The engine shared between the station and whoever sends it requests.
pub type SimEngine = Rc<SharedEngine<NoopRawMutex>>;

/// A simulated pen and base station.
pub struct Simulation {
    world: Shared,
    engine: SimEngine,
    station: Station<NoopRawMutex, SimEngine, SimRanging, SimSwitches, SimClock, SimSink>,
    scenario: Scenario,
}

impl Simulation {
    /// Starts `scenario` at device time 0 with randomness from `seed`.
    pub fn new(scenario: &Scenario, seed: u64) -> Simulation {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let hand = Hand::new(scenario.timeline.clone(), &mut rng);
        Simulation::with_hand(scenario, hand, rng)
    }

    /// As [`new`](Self::new), with the scenario repeating for as long as the simulation runs.
    pub fn looping(scenario: &Scenario, seed: u64) -> Simulation {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let hand = Hand::new(scenario.timeline.clone(), &mut rng).looping();
        Simulation::with_hand(scenario, hand, rng)
    }

    fn with_hand(scenario: &Scenario, hand: Hand, rng: ChaCha8Rng) -> Simulation {
        let world = Rc::new(RefCell::new(World {
            now_us: 0,
            rig: scenario.rig.clone(),
            acoustics: scenario.acoustics,
            hand,
            rng,
            heard: None,
            sent: Vec::new(),
            samples: Vec::new(),
            pacer: None,
        }));
        let engine: SimEngine = Rc::new(Mutex::new(RefCell::new(Engine::new(
            Some(scenario.config),
            SIM_FIRMWARE,
            scenario.unique_id,
        ))));
        let station = Station::new(
            engine.clone(),
            SimRanging(world.clone()),
            SimSwitches(world.clone()),
            SimClock(world.clone()),
            SimSink(world.clone()),
        );
        Simulation {
            world,
            engine,
            station,
            scenario: scenario.clone(),
        }
    }

    /// The scenario being run.
    pub fn scenario(&self) -> &Scenario {
        &self.scenario
    }

    /// The device's engine, for requests (configuration, feature reports).
    pub fn engine(&self) -> SimEngine {
        self.engine.clone()
    }

    /// Device time, µs.
    pub fn now_us(&self) -> u64 {
        self.world.borrow().now_us
    }

    /// Installs a pacer, called at every tick. It takes the reports as they are sent, so the
    /// records [`step`](Self::step) returns no longer list them.
    pub fn set_pacer(&mut self, pacer: Pacer) {
        self.world.borrow_mut().pacer = Some(pacer);
    }

    /// Runs one measurement cycle.
    pub fn step(&mut self) -> CycleRecord {
        let t0_us = self.now_us();
        let result = block_on(self.station.cycle());
        let mut w = self.world.borrow_mut();
        let (truth_mm, heard) = w.heard.unwrap_or_else(|| unreachable!("every cycle fires"));
        let sent = std::mem::take(&mut w.sent);
        let switch_samples = std::mem::take(&mut w.samples);
        // The cycle's own report is the first one sent at or after the listening window closed.
        let report = sent
            .iter()
            .filter(|s| s.t_us >= t0_us + pen_core::LISTEN_US)
            .find_map(|s| PenReport::decode(&s.bytes).ok());
        let intended_switches = w.hand.intended_switches(w.now_us as f64 * 1e-6);
        CycleRecord {
            t0_us,
            truth_mm,
            heard,
            result,
            report,
            intended_switches,
            sent,
            switch_samples,
        }
    }

    /// Runs cycles until device time reaches `seconds`.
    pub fn run_for(&mut self, seconds: f64) -> Vec<CycleRecord> {
        let end = (seconds * 1e6) as u64;
        let mut out = Vec::new();
        while self.now_us() < end {
            out.push(self.step());
        }
        out
    }
}
