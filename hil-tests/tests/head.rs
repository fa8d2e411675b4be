//! The tracked head through the whole firmware core: a seated viewer's glasses multiplexed with
//! the pen on one base station, judged from the report bytes against the simulated truth.

use glam::DVec3;
use pen_core::Emitter;
use pen_protocol::{HeadReport, Message};
use pen_sim::{CycleRecord, Simulation, scenarios};

const SECONDS: f64 = 20.0;

fn run(name: &str) -> (pen_sim::Scenario, Simulation, Vec<CycleRecord>) {
    let s = scenarios::by_name(name).unwrap_or_else(|| panic!("scenario {name}"));
    let mut sim = Simulation::looping(&s, 7);
    let records = sim.run_for(SECONDS);
    (s, sim, records)
}

/// Pen fixes per second and their RMS error, from the pen's cycles.
fn pen_figures(records: &[CycleRecord]) -> (f64, f64) {
    let errors: Vec<f64> = records
        .iter()
        .filter(|r| r.emitter == Emitter::Pen)
        .filter_map(|r| {
            let f = r.result.fix.ok()?;
            Some((DVec3::new(f.position.x as f64, f.position.y as f64, f.position.z as f64) - r.truth_mm).length())
        })
        .collect();
    let rms = (errors.iter().map(|e| e * e).sum::<f64>() / errors.len() as f64).sqrt();
    (errors.len() as f64 / SECONDS, rms)
}

#[test]
fn the_head_is_tracked_and_the_pen_keeps_its_rate_and_accuracy() {
    let (_, _, alone) = run("hand-sweep");
    let (s, sim, with_head) = run("viewer");
    let viewer = sim.viewer().expect("the viewer scenario has a viewer");
    let (rate_alone, rms_alone) = pen_figures(&alone);
    let (rate, rms) = pen_figures(&with_head);
    assert!(rate >= 150.0, "pen {rate:.1} fixes/s with the head");
    assert!(
        (rms / rms_alone - 1.0).abs() <= 0.05,
        "pen RMS {rms:.3} mm against {rms_alone:.3} alone"
    );
    assert!(rate >= 0.95 * rate_alone, "{rate:.1} against {rate_alone:.1}");

    // The head reports, decoded from the bytes the device sent.
    let reports: Vec<(u64, HeadReport)> = with_head
        .iter()
        .flat_map(|r| &r.sent)
        .filter_map(|sent| match Message::decode(&sent.bytes) {
            Ok(Message::Head(h)) => Some((sent.t_us, h)),
            _ => None,
        })
        .collect();
    let fixed: Vec<&(u64, HeadReport)> = reports.iter().filter(|(_, h)| !h.no_fix).collect();
    assert!(
        fixed.len() as f64 / SECONDS >= 60.0,
        "{} head fixes in {SECONDS} s",
        fixed.len()
    );
    // Against where the head is when the prediction says, computed from the viewer.
    let mut sq = 0.0;
    for (_, h) in &fixed {
        let t_s = (h.timestamp_us as f64 + h.prediction_ms as f64 * 1000.0) * 1e-6;
        let truth = viewer.emitter(&s.rig, t_s);
        let [x, y, z] = h.position.to_mm();
        sq += (DVec3::new(x as f64, y as f64, z as f64) - truth).length_squared();
    }
    let head_rms = (sq / fixed.len() as f64).sqrt();
    assert!(head_rms <= 3.0, "head RMS {head_rms:.2} mm");
    // One report per head slot, counted without gaps; a no-fix report holds the pose before it.
    assert_eq!(
        reports.len(),
        with_head.iter().filter(|r| r.emitter == Emitter::Head).count()
    );
    for pair in reports.windows(2) {
        let (a, b) = (pair[0].1, pair[1].1);
        assert_eq!(b.seq, a.seq.wrapping_add(1));
        if b.no_fix {
            assert_eq!(b.position, a.position);
            assert_eq!(b.quality.receivers_used, 0);
        }
    }
}

#[test]
fn the_head_shadows_receivers_when_leaning_in() {
    let (s, sim, records) = run("viewer");
    let viewer = sim.viewer().expect("viewer");
    // The receivers the head shadows hear nothing in the head's slots.
    let mut shadowed_slots = 0;
    for r in records.iter().filter(|r| r.emitter == Emitter::Head) {
        let mask = viewer.shadowed(&s.rig, r.t0_us as f64 * 1e-6);
        for i in 0..s.rig.receivers_mm.len() {
            if mask & (1 << i) != 0 {
                shadowed_slots += 1;
                assert_eq!(r.heard.arrival_ns[i], None, "receiver {i} heard through the head");
            }
        }
    }
    assert!(shadowed_slots > 0, "the viewer never shadowed a receiver");
}

#[test]
fn head_reports_cross_the_serial_link_beside_the_pen() {
    use std::io::Write;
    use std::time::{Duration, Instant};

    use pen_host::transport::Transport;
    use pen_host::transport::serial::SerialTransport;
    use pen_protocol::{MAX_FRAME, encode_frame};
    use serialport::{SerialPort, TTYPort};

    let (mut master, slave) = TTYPort::pair().expect("a pty pair");
    let path = slave.name().expect("the pty's path");
    drop(slave);
    master.set_timeout(Duration::from_secs(1)).expect("timeout");
    let mut port = SerialTransport::open(&path).expect("the pty opens as a serial port");
    // The device side: every report the simulated base station sends, framed, in order.
    let writer = std::thread::spawn(move || {
        let scenario = scenarios::by_name("viewer").expect("scenario");
        let mut sim = Simulation::new(&scenario, 3);
        let mut sent = Vec::new();
        while sent.iter().filter(|m| matches!(m, Message::Head(_))).count() < 100 {
            for s in sim.step().sent {
                let mut frame = [0u8; MAX_FRAME];
                let n = encode_frame(&s.bytes, &mut frame).expect("fits");
                master.write_all(&frame[..n]).expect("write");
                sent.push(Message::decode(&s.bytes).expect("the device's bytes decode"));
            }
            std::thread::sleep(Duration::from_micros(300));
        }
        // The master is handed back, not dropped: closing it hangs the line up, and what the
        // reader has not read yet would be lost with it.
        (sent, master)
    });
    let mut received = Vec::new();
    let cap = Instant::now() + Duration::from_secs(300);
    let mut last_heard = Instant::now();
    while Instant::now() < cap {
        if let Ok(Some(m)) = port.read(Duration::from_millis(100)) {
            received.push(m);
            last_heard = Instant::now();
        } else if writer.is_finished() && last_heard.elapsed() > Duration::from_secs(2) {
            break;
        }
    }
    let (sent, _master) = writer.join().expect("writer");
    // Every input report arrives, in order, the head's among the pen's.
    let first_difference = received.iter().zip(&sent).position(|(a, b)| a != b);
    assert_eq!(
        (received.len(), first_difference),
        (sent.len(), None),
        "received {} of {} reports; first difference at {first_difference:?}",
        received.len(),
        sent.len()
    );
    assert_eq!(port.dropped(), 0);
}

#[test]
fn the_rooms_tail_reaches_a_slot_only_past_its_start() {
    use pen_sim::acoustics::Acoustics;
    use rand::SeedableRng;

    let rig = pen_sim::rig::Rig::reference();
    let acoustics = Acoustics {
        reverb_rate: 1.0,
        ..Acoustics::clean()
    };
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
    // An emitter at the workspace's far end, 1.3–1.4 m from the receivers.
    let previous = DVec3::new(300.0, 170.0, 1300.0);
    let c_mm_per_us = acoustics.air.speed_m_s(0.0) * 1e-3;
    let (mut reached_short, mut reached_long) = (0, 0);
    for _ in 0..200 {
        // After a 4.42 ms slot, some tails of a 1.5 ms die-away cross into the next slot; after
        // the pen-only 6.5 ms cycle none can (the longest: the farthest receiver plus 515 mm).
        for (slot_us, reached) in [(4_420.0, &mut reached_short), (6_500.0, &mut reached_long)] {
            let tails = acoustics.tails(&rig, previous, 0.0, slot_us, &mut rng);
            for (i, t) in tails.iter().enumerate() {
                if let Some(t) = t {
                    *reached += 1;
                    let latest = ((previous - rig.receivers_mm[i]).length() + acoustics.reverb_tail_mm) / c_mm_per_us
                        + rig.delays_us[i]
                        - slot_us;
                    assert!(*t > 0.0 && *t <= latest + 1e-9, "receiver {i}: {t} µs");
                }
            }
        }
    }
    assert!(reached_short > 0, "no tail crossed a 4.42 ms slot");
    assert_eq!(reached_long, 0, "a tail crossed the 6.5 ms cycle");
}
