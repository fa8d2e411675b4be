//! The engine: cycles to reports, switches, configuration requests, serial requests.

use pen_core::{Action, ConfigStore, Cycle, Engine, NoFix, Saved, StoreError, Vec3, default_config};
use pen_protocol::*;

use crate::common::cycle_at;

const FIRMWARE: FirmwareVersion = FirmwareVersion {
    major: 1,
    minor: 2,
    patch: 3,
};
const PERIOD_US: u64 = 6_500;

/// A store in RAM that can be told to fail.
#[derive(Default)]
struct RamStore {
    saved: Option<Saved>,
    fail: bool,
}

impl ConfigStore for RamStore {
    fn load(&mut self) -> Option<Saved> {
        self.saved
    }
    fn save(&mut self, saved: &Saved) -> Result<(), StoreError> {
        if self.fail {
            return Err(StoreError::Flash);
        }
        self.saved = Some(*saved);
        Ok(())
    }
}

fn engine() -> Engine {
    Engine::new(None, FIRMWARE, [7; 12])
}

fn encode(m: &Message) -> Vec<u8> {
    let mut buf = [0u8; MAX_PAYLOAD];
    let n = m.encode(&mut buf).expect("fits");
    buf[..n].to_vec()
}

/// Runs `n` cycles with the pen at `p`; returns the reports.
fn run(e: &mut Engine, from: u64, n: u64, p: Vec3) -> Vec<PenReport> {
    let mut out = Vec::new();
    for k in 0..n {
        let t0 = from + k * PERIOD_US;
        e.on_cycle(&cycle_at(e, t0, p));
        out.extend(e.poll_report(t0 + 5_000));
    }
    out
}

#[test]
fn cycles_become_reports() {
    let mut e = engine();
    let p = Vec3::new(300.0, 170.0, 80.0);
    let first = e.on_cycle(&cycle_at(&e, 0, p));
    // The first fix after a gap waits for the next one to confirm it.
    assert_eq!(first.fix, Err(NoFix::Acquiring));
    let r0 = e.poll_report(5_000).expect("a report after every cycle");
    assert!(!r0.in_range);
    assert_eq!(r0.quality, Quality::NONE);
    assert_eq!(e.poll_report(5_500), None, "nothing more until the next cycle");
    let reports = run(&mut e, PERIOD_US, 20, p);
    assert_eq!(reports.len(), 20);
    for (i, r) in reports.iter().enumerate() {
        assert!(r.in_range);
        assert_eq!(r.seq, i as u16 + 1);
        assert_eq!(r.timestamp_us as u64, (i as u64 + 1) * PERIOD_US);
        assert_eq!(r.quality.receivers_used, 4);
        let got = Vec3::from_array(r.position.to_mm());
        assert!((got - p).length() < 0.1, "{got:?}");
    }
    assert_eq!(e.counters().cycles, 21);
    assert_eq!(e.counters().gated, 1);
    assert_eq!(e.counters().reports, 21);
}

/// Reports for cycles from `from` with the arrivals `spoil` leaves; the tip at `tip`.
fn run_spoiled(e: &mut Engine, from: u64, n: u64, p: Vec3, tip: bool, spoil: impl Fn(&mut Cycle)) -> Vec<PenReport> {
    let mut out = Vec::new();
    for k in 0..n {
        let t0 = from + k * PERIOD_US;
        e.on_switches(t0, [tip, false, false]);
        let mut c = cycle_at(e, t0, p);
        spoil(&mut c);
        e.on_cycle(&c);
        out.extend(e.poll_report(t0 + 5_000));
    }
    out
}

#[test]
fn a_cycle_without_a_fix_keeps_the_pen_in_range_for_100_ms() {
    let mut e = engine();
    let p = Vec3::new(300.0, 170.0, 80.0);
    run(&mut e, 0, 3, p);
    // Cycles that cannot fix (two receivers silent): the pen stays in range at its last
    // position, with no quality (nothing fresh), for 100 ms after the last fix at 13 ms …
    let lost = run_spoiled(&mut e, 3 * PERIOD_US, 30, p, false, |c| {
        c.arrival_ns[0] = None;
        c.arrival_ns[2] = None;
    });
    assert_eq!(e.counters().too_few, 30);
    let last_fix_us = 2 * PERIOD_US;
    for (k, r) in lost.iter().enumerate() {
        let now = (3 + k as u64) * PERIOD_US + 5_000;
        assert_eq!(r.in_range, now - last_fix_us <= 100_000, "at {now} µs");
        assert_eq!(r.quality.receivers_used, 0);
        assert!(
            (Vec3::from_array(r.position.to_mm()) - p).length() < 0.1,
            "held position"
        );
    }
    // … and out of range after it: a pen taken away.
    assert!(lost.iter().filter(|r| r.in_range).count() >= 13);
    assert!(!lost.last().expect("reports").in_range);
}

#[test]
fn a_pressed_tip_is_always_in_range_once_the_pen_was_seen() {
    let mut e = engine();
    let p = Vec3::new(200.0, 100.0, 6.0);
    // Before any fix there is no position to hold: the tip alone does not bring it in range.
    let before = run_spoiled(&mut e, 0, 3, p, true, |c| c.arrival_ns = [None; MAX_RECEIVERS]);
    assert!(before.iter().all(|r| r.sw1 && !r.in_range));
    run_spoiled(&mut e, 3 * PERIOD_US, 5, p, true, |_| {});
    // A stroke with every other cycle spoiled by two late echoes among the four receivers
    // (gated or inconsistent), and then a second of no fix at all: Tip never comes without
    // In Range, so the OS never sees the stroke break.
    let stroke = run_spoiled(&mut e, 8 * PERIOD_US, 200, p, true, |c| {
        if (c.t0_us / PERIOD_US).is_multiple_of(2) || c.t0_us > 60 * PERIOD_US {
            for a in c.arrival_ns.iter_mut().take(2).flatten() {
                *a += 300_000;
            }
        }
    });
    assert!(e.counters().inconsistent + e.counters().gated > 150);
    assert!(stroke.iter().all(|r| r.sw1 && r.in_range));
    // The tip lifted: the hold runs out 100 ms after the last fix.
    let lifted = run_spoiled(&mut e, 208 * PERIOD_US, 2, p, false, |c| {
        c.arrival_ns = [None; MAX_RECEIVERS]
    });
    assert!(lifted.iter().all(|r| !r.sw1 && !r.in_range));
}

#[test]
fn a_click_between_reports_is_reported() {
    let mut e = engine();
    e.on_switches(100, [false; 3]);
    // SW2 pressed and released (after the debounce time) before the next report.
    e.on_switches(1_000, [false, true, false]);
    e.on_switches(7_000, [false, false, false]);
    let r1 = e.poll_report(7_500).expect("the press is due");
    assert!(r1.sw2);
    let r2 = e.poll_report(8_000).expect("the release is due");
    assert!(!r2.sw2);
    assert_eq!(e.poll_report(8_500), None);
    assert_eq!(r2.seq, r1.seq + 1);
}

#[test]
fn the_tip_rests_on_the_display_while_pressed() {
    let mut e = engine();
    // The emitter 6 mm above the surface: the tip is on it.
    let p = Vec3::new(200.0, 100.0, 6.0);
    e.on_switches(0, [true, false, false]);
    let reports = run(&mut e, 0, 10, p);
    let last = reports.last().expect("reports");
    assert!(last.sw1 && last.in_range);
    assert_eq!(last.position.z, 0);
    assert!((last.position.to_mm()[0] - 200.0).abs() < 0.2);
    // Released, the height comes back.
    e.on_switches(20 * PERIOD_US, [false; 3]);
    let reports = run(&mut e, 21 * PERIOD_US, 10, p);
    assert!((reports.last().expect("reports").position.to_mm()[2] - 6.0).abs() < 0.2);
}

#[test]
fn display_frame_reports() {
    let mut e = engine();
    let mut config = default_config();
    // The display frame 100 mm to the right of the tracker frame.
    config.display = Some(DisplayPose {
        rotation: [1.0, 0.0, 0.0, 0.0],
        translation_mm: [-100.0, 0.0, 0.0],
        scale: 1.0,
        size_mm: [0.0; 2],
    });
    config.report_display_frame = true;
    let mut store = RamStore::default();
    assert_eq!(
        e.set_feature(&encode(&Message::Config(config)), &mut store).0.code,
        StatusCode::Ok
    );
    let reports = run(&mut e, 0, 10, Vec3::new(300.0, 170.0, 50.0));
    let r = reports.last().expect("reports");
    assert!(r.display_frame);
    let mm = r.position.to_mm();
    assert!(
        (mm[0] - 200.0).abs() < 0.2 && (mm[1] - 170.0).abs() < 0.2 && (mm[2] - 50.0).abs() < 0.2,
        "{mm:?}"
    );
}

#[test]
fn report_rate_above_the_cycle_rate_repeats_fixes() {
    let mut e = engine();
    let mut config = default_config();
    config.report_rate_hz = 1000;
    e.set_feature(&encode(&Message::Config(config)), &mut RamStore::default());
    assert_eq!(e.cycle_period_us(), 6_500);
    assert_eq!(e.device_info().fix_rate_hz, 154);
    e.on_cycle(&cycle_at(&e, 0, Vec3::new(1.0, 2.0, 3.0)));
    let mut times = Vec::new();
    for t in (5_000..11_500).step_by(500) {
        if let Some(r) = e.poll_report(t) {
            times.push((t, r.timestamp_us));
        }
    }
    // After the cycle's report, one per millisecond, all from the same fix.
    assert_eq!(
        times.iter().map(|t| t.0).collect::<Vec<_>>(),
        [5_000, 6_000, 7_000, 8_000, 9_000, 10_000, 11_000]
    );
    assert!(times.iter().all(|t| t.1 == 0));
}

#[test]
fn time_of_flight_reports_stream_when_asked() {
    let mut e = engine();
    assert_eq!(e.tof_report(), None);
    let mut config = default_config();
    config.stream_tof = true;
    config.transducer_delay_us[1] = 25.0;
    e.set_feature(&encode(&Message::Config(config)), &mut RamStore::default());
    let p = Vec3::new(300.0, 170.0, 80.0);
    run(&mut e, 0, 2, p);
    let tof = e.tof_report().expect("streaming");
    assert_eq!(tof.receiver_count, 4);
    assert_eq!(tof.used_mask, 0b1111);
    let s = e.settings();
    for i in 0..4 {
        // Delay subtracted: the flight time alone.
        let expected = (p - s.receivers[i]).length() as f64 / (s.speed_m_s as f64 * 1e-6);
        assert!((tof.tof_ns[i] as f64 - expected).abs() <= 1.0, "receiver {i}");
    }
    assert_eq!(tof.tof_ns[4], NO_ARRIVAL);
}

#[test]
fn configuration_is_validated_and_nonsense_keeps_the_old_one() {
    let mut e = engine();
    let mut store = RamStore::default();
    let mut good = default_config();
    good.temperature_c = 25.0;
    let (status, action) = e.set_feature(&encode(&Message::Config(good)), &mut store);
    assert_eq!((status, action), (Status::ok(ReportId::Config as u8), None));
    assert_eq!(e.config().temperature_c, 25.0);

    let mut bad = good;
    bad.receivers_mm[3] = bad.receivers_mm[0];
    let (status, _) = e.set_feature(&encode(&Message::Config(bad)), &mut store);
    assert_eq!(status.code, StatusCode::Degenerate);
    assert_eq!(status.config_field(), Some(ConfigField::Receiver(3)));
    assert_eq!(e.config(), &good, "the old configuration stays");

    // The status report says the same.
    let mut out = [0u8; 64];
    let n = e.get_feature(ReportId::Status as u8, &mut out).expect("status");
    assert_eq!(Status::decode(&out[..n]), Ok(status));

    let mut bytes = encode(&Message::Config(good));
    bytes.truncate(100);
    assert_eq!(e.set_feature(&bytes, &mut store).0.code, StatusCode::Malformed);
    assert_eq!(
        e.set_feature(&[0x42, 1, 2], &mut store).0.code,
        StatusCode::UnknownReport
    );
    let info = encode(&Message::DeviceInfo(e.device_info()));
    assert_eq!(e.set_feature(&info, &mut store).0.code, StatusCode::ReadOnly);
    assert_eq!(e.config(), &good);
}

#[test]
fn commands() {
    let mut e = engine();
    let mut store = RamStore::default();
    let mut c = default_config();
    c.debounce_ms = 9;
    e.set_feature(&encode(&Message::Config(c)), &mut store);
    let save = encode(&Message::Command(Command::SaveConfig));
    assert_eq!(e.set_feature(&save, &mut store).0.code, StatusCode::Ok);
    assert_eq!(store.saved, Some(Saved::config(c)));
    store.fail = true;
    assert_eq!(e.set_feature(&save, &mut store).0.code, StatusCode::StorageFailed);
    let defaults = encode(&Message::Command(Command::LoadDefaults));
    assert_eq!(
        e.set_feature(&defaults, &mut store).0,
        Status::ok(ReportId::Command as u8)
    );
    assert_eq!(e.config(), &default_config());
    let boot = encode(&Message::Command(Command::EnterBootloader));
    assert_eq!(e.set_feature(&boot, &mut store).1, Some(Action::EnterBootloader));
}

#[test]
fn serial_requests() {
    let mut e = engine();
    let mut store = RamStore::default();
    let mut out = [0u8; MAX_PAYLOAD];
    let get = |id| encode(&Message::GetFeature(GetFeature { report: id }));

    let (n, _) = e.handle_request(&get(ReportId::DeviceInfo), &mut out, &mut store);
    let info = DeviceInfo::decode(&out[..n.expect("answer")]).expect("device info");
    assert_eq!(
        (info.firmware, info.unique_id, info.receiver_count),
        (FIRMWARE, [7; 12], 4)
    );
    assert_eq!(info.protocol, PROTOCOL_VERSION);
    assert_eq!(info.fix_rate_hz, 154);

    let (n, _) = e.handle_request(&get(ReportId::Config), &mut out, &mut store);
    assert_eq!(Config::decode(&out[..n.expect("answer")]), Ok(default_config()));

    let mut c = default_config();
    c.report_rate_hz = 100;
    let (n, _) = e.handle_request(&encode(&Message::Config(c)), &mut out, &mut store);
    assert_eq!(
        Status::decode(&out[..n.expect("answer")]),
        Ok(Status::ok(ReportId::Config as u8))
    );
    assert_eq!(e.cycle_period_us(), 10_000);

    // A get-feature request for a report that cannot be read.
    let (n, _) = e.handle_request(&[0x80, 0x06], &mut out, &mut store);
    let s = Status::decode(&out[..n.expect("answer")]).expect("status");
    assert_eq!((s.request, s.code), (0x80, StatusCode::UnknownReport));
    // Garbage that framed correctly but is no request.
    let (n, _) = e.handle_request(&[0x01, 0x02], &mut out, &mut store);
    assert_eq!(
        Status::decode(&out[..n.expect("answer")]).map(|s| s.code),
        Ok(StatusCode::Malformed)
    );
}

#[test]
fn an_invalid_stored_configuration_falls_back_to_the_defaults() {
    let mut bad = default_config();
    bad.receiver_count = 2;
    let e = Engine::new(Some(bad), FIRMWARE, [0; 12]);
    assert_eq!(e.config(), &default_config());
}

/// An engine started with a calibration for a 600 × 340 mm display (the display frame is the
/// tracker frame: the default pose).
fn calibrated() -> Engine {
    let mut config = default_config();
    if let Some(d) = config.display.as_mut() {
        d.size_mm = [600.0, 340.0];
    }
    Engine::new(Some(config), FIRMWARE, [7; 12])
}

#[test]
fn the_os_pen_is_where_the_pen_is_on_the_display() {
    let mut e = calibrated();
    assert_eq!(e.os_extent(), Some([6000, 3400]));
    // 300 mm from the left edge, 170 mm up from the bottom (v up): X 300 mm, Y 170 mm down.
    let hover = run(&mut e, 0, 3, Vec3::new(300.0, 100.0, 80.0));
    let os = e.os_report(hover.last().expect("reports"));
    assert!(os.in_range && !os.tip, "{os:?}");
    assert_eq!((os.x, os.y), (3000, 2400));
    // Tip down: Tip and In Range together.
    e.on_switches(3 * PERIOD_US, [true, false, false]);
    let down = run(&mut e, 3 * PERIOD_US, 10, Vec3::new(150.0, 255.0, 6.0));
    let os = e.os_report(down.last().expect("reports"));
    assert!(os.in_range && os.tip, "{os:?}");
    assert!(
        (os.x as i32 - 1500).abs() <= 2 && (os.y as i32 - 850).abs() <= 2,
        "{os:?}"
    );
    // Off the display by more than 20 mm: out of range for the OS, never Tip without it.
    let off = run(&mut e, 13 * PERIOD_US, 40, Vec3::new(700.0, 200.0, 6.0));
    let os = e.os_report(off.last().expect("reports"));
    assert!(!os.in_range && !os.tip, "{os:?}");
    // Within 20 mm of an edge: in range, clamped to it.
    let edge = run(&mut e, 53 * PERIOD_US, 40, Vec3::new(610.0, -10.0, 6.0));
    let os = e.os_report(edge.last().expect("reports"));
    assert!(os.in_range, "{os:?}");
    assert_eq!((os.x, os.y), (6000, 3400));
}

#[test]
fn before_a_calibration_the_os_pen_is_never_in_range() {
    let mut e = engine();
    assert_eq!(e.os_extent(), None);
    e.on_switches(0, [true, false, true]);
    for r in run(&mut e, 0, 10, Vec3::new(300.0, 170.0, 6.0)) {
        let os = e.os_report(&r);
        assert!(!os.in_range && !os.tip, "{os:?}");
        assert!(os.secondary_barrel, "the barrels are reported whatever the range");
    }
}

#[test]
fn a_new_display_size_saved_restarts_the_device() {
    let mut e = calibrated();
    let mut store = RamStore::default();
    let save = encode(&Message::Command(Command::SaveConfig));
    // The size the descriptor was built with: saved, no restart.
    assert_eq!(e.set_feature(&save, &mut store).1, None);
    // Another size: the OS pen is out of range until the restart, which saving it asks for.
    let mut config = *e.config();
    if let Some(d) = config.display.as_mut() {
        d.size_mm = [520.0, 290.0];
    }
    let (status, _) = e.set_feature(&encode(&Message::Config(config)), &mut store);
    assert_eq!(status, Status::ok(ReportId::Config as u8));
    let reports = run(&mut e, 0, 3, Vec3::new(300.0, 100.0, 80.0));
    assert!(!e.os_report(reports.last().expect("reports")).in_range);
    assert_eq!(e.set_feature(&save, &mut store).1, Some(Action::Restart));
    // After the restart the engine starts from the saved configuration: in range again.
    let mut e = Engine::new(store.load().map(|s| s.config), FIRMWARE, [7; 12]);
    assert_eq!(e.os_extent(), Some([5200, 2900]));
    let reports = run(&mut e, 0, 3, Vec3::new(300.0, 100.0, 80.0));
    assert!(e.os_report(reports.last().expect("reports")).in_range);
}

#[test]
fn arrivals_after_the_listening_window_are_none_so_no_fix_lies_beyond_hearing() {
    // A pen 3 m in front of the display: every capture consistent, but each after the window
    // (at most LISTEN_US of flight, about 1.7 m): before, these solved to a fix 3 m away.
    let mut e = engine();
    let far = Vec3::new(200.0, 150.0, 3_000.0);
    let c = cycle_at(&e, 0, far);
    let window_ns = e.listen_us() * 1000;
    assert!(c.arrival_ns.iter().flatten().all(|&a| u64::from(a) > window_ns));
    // Not solved at all (with them taken as ranges the solver found the far fix, which the
    // tracking gate then held as its first, `Acquiring`).
    assert_eq!(e.on_cycle(&c).fix.err(), Some(NoFix::TooFewRanges));
    // The same pen within reach is fixed once the gate has seen it twice.
    let near = Vec3::new(200.0, 150.0, 300.0);
    let results: Vec<_> = (1..4)
        .map(|k| e.on_cycle(&cycle_at(&e, k * PERIOD_US, near)).fix)
        .collect();
    let fix = results[2].expect("a fix within reach");
    assert!((fix.position - near).length() < 5.0, "{:?}", fix.position);
}
