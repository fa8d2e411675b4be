//! The measurement loop over fake hardware with a virtual clock: what it fires, samples and
//! sends, and when.

use core::cell::RefCell;
use std::rc::Rc;

use embassy_futures::block_on;
use embassy_sync::blocking_mutex::Mutex;
use embassy_sync::blocking_mutex::raw::NoopRawMutex;
use pen_core::{Clock, Engine, LISTEN_US, Ranging, ReportSink, SharedEngine, Station, Switches, TICK_US, Vec3};
use pen_protocol::{FirmwareVersion, MAX_RECEIVERS, PenReport, TofReport};

#[derive(Default)]
struct World {
    now_us: u64,
    fired_at: Vec<u64>,
    /// The receiver count the station gave the front end before each burst.
    armed: Vec<usize>,
    collected_at: Vec<u64>,
    sampled_at: Vec<u64>,
    sent: Vec<(u64, Result<PenReport, TofReport>)>,
}

type Shared = Rc<RefCell<World>>;

struct FakeRanging {
    world: Shared,
    receivers: Vec<Vec3>,
    speed_m_s: f32,
    pen: Vec3,
}

impl Ranging for FakeRanging {
    fn set_receivers(&mut self, count: usize) {
        self.world.borrow_mut().armed.push(count);
    }
    fn fire(&mut self) {
        let mut w = self.world.borrow_mut();
        let t = w.now_us;
        w.fired_at.push(t);
    }
    fn collect(&mut self) -> [Option<u32>; MAX_RECEIVERS] {
        let mut w = self.world.borrow_mut();
        let t = w.now_us;
        w.collected_at.push(t);
        let mut out = [None; MAX_RECEIVERS];
        for (slot, r) in out.iter_mut().zip(&self.receivers) {
            *slot = Some(((self.pen - *r).length() / (self.speed_m_s * 1e-6)).round() as u32);
        }
        out
    }
}

struct FakeSwitches(Shared);

impl Switches for FakeSwitches {
    fn read(&mut self) -> [bool; 3] {
        let mut w = self.0.borrow_mut();
        let t = w.now_us;
        w.sampled_at.push(t);
        // SW1 held from 20 ms to 40 ms.
        [(20_000..40_000).contains(&t), false, false]
    }
}

struct VirtualClock(Shared);

impl Clock for VirtualClock {
    fn now_us(&self) -> u64 {
        self.0.borrow().now_us
    }
    async fn wait_until(&mut self, t_us: u64) {
        let mut w = self.0.borrow_mut();
        w.now_us = w.now_us.max(t_us);
    }
}

struct Sink(Shared);

impl ReportSink for Sink {
    async fn pen(&mut self, report: &PenReport) {
        let mut w = self.0.borrow_mut();
        let t = w.now_us;
        w.sent.push((t, Ok(*report)));
    }
    async fn tof(&mut self, report: &TofReport) {
        let mut w = self.0.borrow_mut();
        let t = w.now_us;
        w.sent.push((t, Err(*report)));
    }
}

/// A configuration store that keeps nothing (the test saves nothing).
struct NoStore;

impl pen_core::ConfigStore for NoStore {
    fn load(&mut self) -> Option<pen_core::Saved> {
        None
    }
    fn save(&mut self, _: &pen_core::Saved) -> Result<(), pen_core::StoreError> {
        Err(pen_core::StoreError::Flash)
    }
}

#[test]
fn cycles_fire_sample_collect_and_report_on_time() {
    let world: Shared = Rc::default();
    let mut config = pen_core::default_config();
    config.stream_tof = true;
    let engine: SharedEngine<NoopRawMutex> = Mutex::new(RefCell::new(Engine::new(
        Some(config),
        FirmwareVersion {
            major: 0,
            minor: 1,
            patch: 0,
        },
        [0; 12],
    )));
    let (receivers, speed, period) = engine.lock(|e| {
        let e = e.borrow();
        (
            e.settings().receivers[..e.settings().count].to_vec(),
            e.settings().speed_m_s,
            e.cycle_period_us(),
        )
    });
    let pen = Vec3::new(250.0, 150.0, 40.0);
    let mut station = Station::new(
        &engine,
        FakeRanging {
            world: world.clone(),
            receivers,
            speed_m_s: speed,
            pen,
        },
        FakeSwitches(world.clone()),
        VirtualClock(world.clone()),
        Sink(world.clone()),
    );
    let results: Vec<_> = (0..10).map(|_| block_on(station.cycle())).collect();
    // A configuration with three receivers applies from the next burst.
    let mut three = config;
    three.receiver_count = 3;
    three.receivers_mm[3] = [0.0; 3];
    three.transducer_delay_us[3] = 0.0;
    let mut bytes = [0u8; pen_protocol::MAX_PAYLOAD];
    let n = pen_protocol::Report::encode(&three, &mut bytes).expect("fits");
    let mut store = NoStore;
    let (status, _) = engine.lock(|e| e.borrow_mut().set_feature(&bytes[..n], &mut store));
    assert_eq!(status, pen_protocol::Status::ok(pen_protocol::ReportId::Config as u8));
    block_on(station.cycle());
    assert_eq!(world.borrow().armed, [[4; 10].as_slice(), &[3]].concat());
    let results = &results[..];

    let w = world.borrow();
    assert_eq!(w.now_us, 11 * period, "each cycle lasts one period");
    assert_eq!(w.fired_at, (0..11).map(|k| k * period).collect::<Vec<_>>());
    assert_eq!(
        w.collected_at,
        w.fired_at.iter().map(|t| t + LISTEN_US).collect::<Vec<_>>()
    );
    // Switches every tick.
    assert!(w.sampled_at.windows(2).all(|p| p[1] - p[0] <= TICK_US));
    // After the first (acquiring) cycle every fix is on the pen.
    for r in &results[1..] {
        let fix = r.fix.expect("fix");
        assert!((fix.position - pen).length() < 0.05);
    }
    // One pen report per cycle when the listening window closes, then its time-of-flight
    // report; plus one for each SW1 edge between cycles.
    let pens: Vec<_> = w.sent.iter().filter_map(|(t, r)| r.ok().map(|r| (*t, r))).collect();
    let tofs = w.sent.iter().filter(|(_, r)| r.is_err()).count();
    assert_eq!(tofs, 11);
    assert_eq!(pens.len(), 13);
    let edges: Vec<_> = pens
        .windows(2)
        .filter(|p| p[0].1.sw1 != p[1].1.sw1)
        .map(|p| p[1].0)
        .collect();
    let first_tick_from = |t: u64| w.sampled_at.iter().copied().find(|&s| s >= t).expect("sampled");
    assert_eq!(
        edges,
        [first_tick_from(20_000), first_tick_from(40_000)],
        "SW1 reported at the first tick after it changed"
    );
    assert!(pens.windows(2).all(|p| p[1].1.seq == p[0].1.seq.wrapping_add(1)));
}

#[test]
fn a_suspended_host_wakes_on_a_new_press_only() {
    use pen_core::WakeOnPress;
    let mut wake = WakeOnPress::default();
    // Suspended with the pen standing on its tip: no wakeup however long it stands.
    wake.suspended();
    assert!((0..100).all(|_| !wake.sample(true)));
    // Lifted and pressed: one wakeup, at the press.
    assert!(!wake.sample(false));
    assert!(wake.sample(true));
    assert!(!wake.sample(true), "held: no second wakeup");
    // A new suspend forgets the release seen in the last one.
    assert!(!wake.sample(false));
    wake.suspended();
    assert!(!wake.sample(true));
}
