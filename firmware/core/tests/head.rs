//! The tracked head in the engine: the slot schedule, the head report with its prediction, a
//! slot without a fix holding the pose, and the pen untouched by the head's slots.

use pen_core::head::{Schedule, mux_listen_us};
use pen_core::{Emitter, Engine, HeadSettings, Vec3};
use pen_protocol::*;

use crate::common::cycle_at;

const FIRMWARE: FirmwareVersion = FirmwareVersion {
    major: 1,
    minor: 2,
    patch: 3,
};

fn head_engine(prediction_ms: u8) -> Engine {
    let mut e = Engine::new(None, FIRMWARE, [7; 12]);
    e.set_head(Some(HeadSettings {
        schedule: Schedule { pen: 2, head: 1 },
        prediction_ms,
    }));
    e
}

#[test]
fn slots_follow_the_schedule_and_cover_the_workspace() {
    let mut e = head_engine(20);
    let s = e.settings();
    // The slowest flight the workspace allows, computed here from the speed of sound.
    let flight_us = 1500.0 / s.speed_m_s as f64 * 1000.0;
    let emitters: Vec<Emitter> = (0..6)
        .map(|_| {
            let slot = e.next_slot();
            assert!(
                slot.listen_us as f64 >= flight_us,
                "{slot:?} listens less than 1.5 m of flight"
            );
            assert!(slot.listen_us < slot.period_us);
            slot.emitter
        })
        .collect();
    use Emitter::*;
    assert_eq!(emitters, [Pen, Pen, Head, Pen, Pen, Head]);
    // The device tells the host the pen's rate: 2 of every 3 slots.
    let period = e.cycle_period_us() as f64;
    let expected = (2.0e6 / (3.0 * period)).round() as u16;
    assert_eq!(e.device_info().fix_rate_hz, expected);
    assert!(expected >= 150, "{expected}");
    // The chosen 5:2: five of every seven slots the pen's, the head at least 60 a second.
    e.set_head(Some(HeadSettings::default()));
    assert_eq!(HeadSettings::default().schedule, Schedule::CHOSEN);
    let pen_slots = (0..7).filter(|_| e.next_slot().emitter == Pen).count();
    assert_eq!(pen_slots, 5);
    let rate = e.device_info().fix_rate_hz as f64;
    assert!((rate - 5.0e6 / (7.0 * period)).abs() <= 0.5, "{rate}");
    assert!(2.0e6 / (7.0 * period) >= 60.0);
    // Without the head every cycle is the pen's, at the pen-only period.
    e.set_head(None);
    let slot = e.next_slot();
    assert_eq!((slot.emitter, slot.period_us), (Pen, 6_500));
    assert_eq!(mux_listen_us(343.2, 0), 4371);
}

#[test]
fn head_reports_predict_a_moving_head() {
    let prediction_ms = 30;
    let mut e = head_engine(prediction_ms);
    let period = 3 * e.cycle_period_us();
    // A head moving at 80 mm/s along x, 700 mm in front of the display's middle.
    let at = |t: u64| Vec3::new(150.0 + 80e-6 * t as f32, 170.0, 700.0);
    let mut last = None;
    for k in 1..200u64 {
        let t0 = k * period;
        let r = e.on_head_cycle(&cycle_at(&e, t0, at(t0)));
        assert!(r.fix.is_ok() || k == 1, "slot {k}: {:?}", r.fix);
        if let Some(h) = e.poll_head() {
            last = Some((t0, h));
        }
    }
    let (t0, h) = last.expect("head reports");
    assert!(!h.no_fix);
    assert_eq!(h.prediction_ms, prediction_ms);
    assert_eq!(h.timestamp_us, t0 as u32);
    assert!(h.quality.receivers_used >= 4);
    // Where the head is 30 ms after the burst, within the report's 0.1 mm units and the
    // rounding of the captures to whole ns.
    let truth = at(t0 + 30_000).to_array();
    for (got, want) in h.position.to_mm().into_iter().zip(truth) {
        assert!((got - want).abs() < 0.5, "{:?} vs {truth:?}", h.position.to_mm());
    }
    // Polled once only.
    assert_eq!(e.poll_head(), None);
    assert_eq!(e.head_counters().map(|c| c.fixes), Some(198));
}

#[test]
fn a_slot_without_a_fix_holds_the_pose_and_says_so() {
    let mut e = head_engine(0);
    let period = 3 * e.cycle_period_us();
    let p = Vec3::new(300.0, 170.0, 650.0);
    for k in 1..10u64 {
        e.on_head_cycle(&cycle_at(&e, k * period, p));
        e.poll_head();
    }
    let before = e.poll_head();
    assert_eq!(before, None);
    // The glasses turned away: two receivers hear nothing.
    let mut c = cycle_at(&e, 10 * period, p);
    c.arrival_ns[1] = None;
    c.arrival_ns[2] = None;
    let r = e.on_head_cycle(&c);
    assert!(r.fix.is_err());
    let h = e.poll_head().expect("a report every head slot");
    assert!(h.no_fix);
    assert_eq!(h.quality, Quality::NONE);
    for (got, want) in h.position.to_mm().into_iter().zip(p.to_array()) {
        assert!((got - want).abs() < 0.2, "held {:?}", h.position.to_mm());
    }
}

#[test]
fn head_slots_leave_the_pen_alone() {
    let mut e = head_engine(20);
    let period = e.cycle_period_us();
    let pen = Vec3::new(200.0, 100.0, 80.0);
    let head = Vec3::new(300.0, 170.0, 700.0);
    let mut pen_reports = Vec::new();
    for k in 0..30u64 {
        let t0 = k * period;
        let slot = e.next_slot();
        match slot.emitter {
            Emitter::Pen => {
                e.on_cycle(&cycle_at(&e, t0, pen));
            }
            Emitter::Head => {
                e.on_head_cycle(&cycle_at(&e, t0, head));
            }
        }
        pen_reports.extend(e.poll_report(t0 + slot.listen_us));
    }
    // A pen report per pen slot only, always the pen's position.
    assert_eq!(pen_reports.len(), 20);
    for r in pen_reports.iter().skip(1) {
        assert!(r.in_range);
        for (got, want) in r.position.to_mm().into_iter().zip(pen.to_array()) {
            assert!((got - want).abs() < 0.2, "{:?}", r.position.to_mm());
        }
    }
}

#[test]
fn head_tracking_starts_and_stops_by_command_where_the_glasses_are_fitted() {
    struct NoStore;
    impl pen_core::ConfigStore for NoStore {
        fn load(&mut self) -> Option<pen_core::Saved> {
            None
        }
        fn save(&mut self, _: &pen_core::Saved) -> Result<(), pen_core::StoreError> {
            Ok(())
        }
    }
    let on = Message::Command(Command::HeadOn).encode_vec();
    let off = Message::Command(Command::HeadOff).encode_vec();
    let mut e = Engine::new(None, FIRMWARE, [7; 12]);
    // The reference board has no glasses' emitter: not supported, and the pen keeps its cycle.
    let (status, _) = e.set_feature(&on, &mut NoStore);
    assert_eq!(status.code, StatusCode::Unsupported);
    assert_eq!(e.next_slot().period_us, 6_500);
    e.set_head_emitter_fitted(true);
    let (status, _) = e.set_feature(&on, &mut NoStore);
    assert_eq!(status.code, StatusCode::Ok);
    assert_eq!(e.head_settings(), Some(HeadSettings::default()));
    let heads = (0..7).filter(|_| e.next_slot().emitter == Emitter::Head).count();
    assert_eq!(heads, 2);
    let (status, _) = e.set_feature(&off, &mut NoStore);
    assert_eq!(status.code, StatusCode::Ok);
    assert_eq!(e.head_settings(), None);
    assert_eq!(e.next_slot().emitter, Emitter::Pen);
}

/// HeadOn, then SaveConfig: after a power cycle (a new engine from what the store loads) a base
/// station with the glasses' emitter tracks the head again; HeadOff saved: it does not. One
/// without the emitter never does.
#[test]
fn head_mode_saved_survives_a_power_cycle() {
    #[derive(Default)]
    struct RamStore(Option<pen_core::Saved>);
    impl pen_core::ConfigStore for RamStore {
        fn load(&mut self) -> Option<pen_core::Saved> {
            self.0
        }
        fn save(&mut self, saved: &pen_core::Saved) -> Result<(), pen_core::StoreError> {
            self.0 = Some(*saved);
            Ok(())
        }
    }
    let command = |c| Message::Command(c).encode_vec();
    use pen_core::ConfigStore;
    let boot = |store: &mut RamStore, fitted: bool| {
        let saved = store.load();
        let mut e = Engine::new(saved.map(|s| s.config), FIRMWARE, [7; 12]);
        e.set_head_emitter_fitted(fitted);
        e.resume_head(saved.is_some_and(|s| s.head));
        e
    };
    let mut store = RamStore::default();
    let mut e = boot(&mut store, true);
    assert_eq!(e.head_settings(), None, "nothing saved: the pen alone");
    e.set_feature(&command(Command::HeadOn), &mut store);
    // HeadOn alone is not saved.
    assert_eq!(boot(&mut store, true).head_settings(), None);
    let (status, _) = e.set_feature(&command(Command::SaveConfig), &mut store);
    assert_eq!(status.code, StatusCode::Ok);
    assert_eq!(store.0.map(|s| s.head), Some(true));
    let mut again = boot(&mut store, true);
    assert_eq!(again.head_settings(), Some(HeadSettings::default()));
    let heads = (0..7).filter(|_| again.next_slot().emitter == Emitter::Head).count();
    assert_eq!(heads, 2, "the 5:2 schedule runs from the start");
    assert_eq!(boot(&mut store, false).head_settings(), None, "no emitter: not started");
    again.set_feature(&command(Command::HeadOff), &mut store);
    again.set_feature(&command(Command::SaveConfig), &mut store);
    assert_eq!(boot(&mut store, true).head_settings(), None);
}

trait EncodeVec {
    fn encode_vec(&self) -> Vec<u8>;
}

impl EncodeVec for Message {
    fn encode_vec(&self) -> Vec<u8> {
        let mut buf = [0u8; MAX_PAYLOAD];
        let n = self.encode(&mut buf).expect("fits");
        buf[..n].to_vec()
    }
}
