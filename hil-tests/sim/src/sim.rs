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
    Clock, ConfigStore, CycleResult, Emitter, Engine, HeadSettings, Ranging, ReportSink, Saved, SharedEngine, Station,
    StoreError, Switches,
};
use pen_protocol::{Config, FirmwareVersion, HeadReport, MAX_RECEIVERS, OsPenReport, PenReport, Report, TofReport};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

use crate::acoustics::{Acoustics, Heard};
use crate::hand::Hand;
use crate::rig::Rig;
use crate::script::Timeline;
use crate::viewer::Viewer;

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
    /// A viewer wears the tracked glasses and the device schedules their emitter with these
    /// settings; `None`: the pen alone.
    pub head: Option<HeadSettings>,
    /// Device time at which the glasses are switched on (as a HeadOn from the host would),
    /// s; 0: tracked from the start.
    pub head_from_s: f64,
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
            head: None,
            head_from_s: 0.0,
        }
    }

    /// The same session with a seated viewer wearing the tracked glasses, the device
    /// multiplexing their emitter with the pen's by `head`.
    pub fn with_head(self, head: HeadSettings) -> Scenario {
        Scenario {
            head: Some(head),
            ..self
        }
    }

    /// The same session with the glasses switched on only at `from_s` seconds of device time:
    /// until then the device tracks the pen alone.
    pub fn with_head_from(self, head: HeadSettings, from_s: f64) -> Scenario {
        Scenario {
            head: Some(head),
            head_from_s: from_s.max(0.0),
            ..self
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
    /// The emitter the burst came from (the pen's unless the head is tracked).
    pub emitter: Emitter,
    /// Where the emitter really was, tracker frame, mm.
    pub truth_mm: DVec3,
    /// What the receivers heard.
    pub heard: Heard,
    /// The engine's fix (before smoothing) or why there was none.
    pub result: CycleResult,
    /// The pen report of this cycle (sent when the listening window closed).
    pub report: Option<PenReport>,
    /// The head report of this cycle (head slots only).
    pub head_report: Option<HeadReport>,
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
    viewer: Option<Viewer>,
    emitter: Emitter,
    /// Device time the station collected the arrivals: the slot's listening window closed.
    collected_at: Option<u64>,
    rng: ChaCha8Rng,
    heard: Option<(DVec3, Heard)>,
    sent: Vec<Sent>,
    samples: Vec<u8>,
    pacer: Option<Pacer>,
    /// Send the OS pen report after each pen report, as the USB HID sink does.
    os_pen: bool,
    /// The listening window of the slot being fired, µs.
    listen_us: u64,
    /// The previous burst: when, and from where (for the room's reverberation).
    previous: Option<(u64, DVec3)>,
}

type Shared = Rc<RefCell<World>>;

struct SimRanging(Shared);
struct SimSwitches(Shared);
struct SimClock(Shared);
struct SimSink(Shared);

impl Ranging for SimRanging {
    fn set_emitter(&mut self, emitter: Emitter) {
        self.0.borrow_mut().emitter = emitter;
    }

    fn fire(&mut self) {
        let mut w = self.0.borrow_mut();
        let w = &mut *w;
        let t_s = w.now_us as f64 * 1e-6;
        w.collected_at = None;
        let tails = match w.previous {
            Some((t0, at)) => w
                .acoustics
                .tails(&w.rig, at, t_s, w.now_us.saturating_sub(t0) as f64, &mut w.rng),
            None => [None; MAX_RECEIVERS],
        };
        let listen = w.listen_us;
        let (emitter, blocked) = match (w.emitter, &w.viewer) {
            (Emitter::Head, Some(viewer)) => (viewer.emitter(&w.rig, t_s), viewer.shadowed(&w.rig, t_s)),
            // Glasses scheduled but nobody wears them: the burst drives no emitter.
            (Emitter::Head, None) => (w.hand.emitter(&w.rig, t_s), u8::MAX),
            (Emitter::Pen, _) => (w.hand.emitter(&w.rig, t_s), 0),
        };
        let heard = w
            .acoustics
            .hear_slot(&w.rig, emitter, t_s, listen, blocked, tails, &mut w.rng);
        w.previous = (blocked != u8::MAX).then_some((w.now_us, emitter));
        w.heard = Some((emitter, heard));
    }

    fn collect(&mut self) -> [Option<u32>; MAX_RECEIVERS] {
        let mut w = self.0.borrow_mut();
        w.collected_at = Some(w.now_us);
        w.heard.map_or([None; MAX_RECEIVERS], |(_, h)| h.arrival_ns)
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

    async fn head(&mut self, report: &HeadReport) {
        self.push(report);
    }

    async fn os_pen(&mut self, report: &OsPenReport) {
        if self.0.borrow().os_pen {
            self.push(report);
        }
    }
}

/// The simulated device's configuration storage: memory that lasts as long as the simulation.
#[derive(Debug, Default)]
pub struct MemoryStore {
    /// The saved configuration and head mode.
    pub saved: Option<Saved>,
}

impl ConfigStore for MemoryStore {
    fn load(&mut self) -> Option<Saved> {
        self.saved
    }

    fn save(&mut self, saved: &Saved) -> Result<(), StoreError> {
        self.saved = Some(*saved);
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
    /// The glasses' settings until they are switched on ([`Scenario::head_from_s`]).
    head_pending: Option<HeadSettings>,
}

impl Simulation {
    /// Starts `scenario` at device time 0 with randomness from `seed`.
    pub fn new(scenario: &Scenario, seed: u64) -> Simulation {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let hand = Hand::new(scenario.timeline.clone(), &mut rng);
        Simulation::with_hand(scenario, hand, rng)
    }

    /// The viewer wearing the glasses, when the scenario has one.
    pub fn viewer(&self) -> Option<Viewer> {
        self.world.borrow().viewer.clone()
    }

    /// As [`new`](Self::new), with the scenario repeating for as long as the simulation runs.
    pub fn looping(scenario: &Scenario, seed: u64) -> Simulation {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let hand = Hand::new(scenario.timeline.clone(), &mut rng).looping();
        Simulation::with_hand(scenario, hand, rng)
    }

    fn with_hand(scenario: &Scenario, hand: Hand, mut rng: ChaCha8Rng) -> Simulation {
        // The viewer sits in front of the display; the reference display is 600 × 340 mm.
        let size = scenario
            .config
            .display
            .map(|d| d.size_mm)
            .filter(|s| s[0] > 0.0)
            .unwrap_or([600.0, 340.0]);
        let viewer = scenario
            .head
            .map(|_| Viewer::seated(size[0] as f64, size[1] as f64, &mut rng));
        let world = Rc::new(RefCell::new(World {
            now_us: 0,
            rig: scenario.rig.clone(),
            acoustics: scenario.acoustics,
            hand,
            viewer,
            emitter: Emitter::Pen,
            collected_at: None,
            listen_us: pen_core::LISTEN_US,
            previous: None,
            rng,
            heard: None,
            sent: Vec::new(),
            samples: Vec::new(),
            pacer: None,
            os_pen: false,
        }));
        let mut device = Engine::new(Some(scenario.config), SIM_FIRMWARE, scenario.unique_id);
        // A viewer wears the glasses: their emitter is fitted, and tracked from the start unless
        // they are switched on later (see `step`).
        device.set_head_emitter_fitted(scenario.head.is_some());
        device.set_head(scenario.head.filter(|_| scenario.head_from_s <= 0.0));
        let engine: SimEngine = Rc::new(Mutex::new(RefCell::new(device)));
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
            head_pending: scenario.head.filter(|_| scenario.head_from_s > 0.0),
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

    /// Sends the OS pen report (`0x07`) after every pen report from now on, as the base
    /// station does on USB HID; the serial link's byte stream, the default, has none.
    pub fn send_os_pen(&mut self) {
        self.world.borrow_mut().os_pen = true;
    }

    /// Runs one measurement cycle.
    pub fn step(&mut self) -> CycleRecord {
        let t0_us = self.now_us();
        if let Some(head) = self.head_pending
            && t0_us as f64 >= self.scenario.head_from_s * 1e6
        {
            // The glasses switched on: from this cycle the device multiplexes their emitter.
            self.head_pending = None;
            self.engine.lock(|e| e.borrow_mut().set_head(Some(head)));
        }
        // The world hears within the slot's listening window, which the engine knows (it is
        // the pen-only cycle's unless the head is tracked).
        let listen = self.engine.lock(|e| {
            let e = e.borrow();
            match e.head_settings() {
                Some(_) => e.cycle_period_us() - pen_core::head::MUX_GUARD_US,
                None => pen_core::LISTEN_US,
            }
        });
        self.world.borrow_mut().listen_us = listen;
        let result = block_on(self.station.cycle());
        let mut w = self.world.borrow_mut();
        let (truth_mm, heard) = w.heard.unwrap_or_else(|| unreachable!("every cycle fires"));
        let sent = std::mem::take(&mut w.sent);
        let switch_samples = std::mem::take(&mut w.samples);
        let collected = w.collected_at.unwrap_or(t0_us + pen_core::LISTEN_US);
        // The cycle's own report is the first one sent at or after the listening window closed.
        let report = sent
            .iter()
            .filter(|s| s.t_us >= collected)
            .find_map(|s| PenReport::decode(&s.bytes).ok());
        let head_report = sent.iter().find_map(|s| HeadReport::decode(&s.bytes).ok());
        let intended_switches = w.hand.intended_switches(w.now_us as f64 * 1e-6);
        CycleRecord {
            t0_us,
            emitter: w.emitter,
            truth_mm,
            heard,
            result,
            report,
            head_report,
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
