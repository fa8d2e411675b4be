//! The serial transport on a real pseudo-terminal, through serialport: garbage on the line never
//! yields a wrong sample, and the simulated pen's pty server answers requests.

use std::collections::HashMap;
use std::io::Write;
use std::time::{Duration, Instant};

use pen_host::transport::Transport;
use pen_host::transport::serial::SerialTransport;
use pen_protocol::{MAX_FRAME, Message, PenReport, ReportId, StatusCode, encode_frame};
use pen_sim::Simulation;
use rand::{RngExt, SeedableRng};
use serialport::{SerialPort, TTYPort};

#[test]
fn garbage_on_the_line_never_yields_a_wrong_sample() {
    let (mut master, slave) = TTYPort::pair().expect("a pty pair");
    let path = slave.name().expect("the pty's path");
    drop(slave);
    master.set_timeout(Duration::from_secs(1)).expect("timeout");
    // Opened before anything is written: opening sets the line up and may discard what waits
    // in it (a frame written first was lost when the open came late on a loaded machine).
    let mut port = SerialTransport::open(&path).expect("the pty opens as a serial port");

    // The device side: a simulation's report bytes, framed, with garbage between the frames.
    let scenario = pen_sim::scenarios::by_name("hand-sweep").expect("scenario");
    let writer = std::thread::spawn(move || {
        let mut sim = Simulation::new(&scenario, 9);
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1);
        let mut sent: HashMap<u16, PenReport> = HashMap::new();
        let mut garbage_bytes = 0;
        while sent.len() < 600 {
            for s in sim.step().sent {
                let Ok(Message::Pen(p)) = Message::decode(&s.bytes) else {
                    continue;
                };
                let mut frame = [0u8; MAX_FRAME];
                let n = encode_frame(&s.bytes, &mut frame).expect("fits");
                // Random bytes, zeros among them, and sometimes the tail of a frame cut short.
                let mut junk: Vec<u8> = (0..rng.random_range(0..24)).map(|_| rng.random()).collect();
                if rng.random_bool(0.2) {
                    junk.extend_from_slice(&frame[1..rng.random_range(2..n)]);
                }
                garbage_bytes += junk.len();
                master.write_all(&junk).expect("write");
                master.write_all(&frame[..n]).expect("write");
                sent.insert(p.seq, p);
            }
            std::thread::sleep(Duration::from_micros(500));
        }
        // The master goes back with the results: closing it hangs the line up, and a hangup
        // discards what the reader has not read yet.
        (sent, garbage_bytes, master)
    });

    let mut received = Vec::new();
    // Until the writer is done and the line has been quiet for 2 s: a loaded machine (the
    // simulation runs unoptimised beside other tests) only makes it slower, never wrong. The
    // cap only keeps a broken reader from hanging the run.
    let cap = Instant::now() + Duration::from_secs(300);
    let mut last_heard = Instant::now();
    while received.len() < 600 && Instant::now() < cap {
        if let Ok(Some(Message::Pen(p))) = port.read(Duration::from_millis(100)) {
            received.push(p);
            last_heard = Instant::now();
        } else if writer.is_finished() && last_heard.elapsed() > Duration::from_secs(2) {
            break;
        }
    }
    let (sent, garbage_bytes, _master) = writer.join().expect("writer");
    assert!(garbage_bytes > 5000, "garbage was injected ({garbage_bytes} bytes)");
    assert!(
        port.dropped() > 100,
        "garbage frames were seen and dropped: {}",
        port.dropped()
    );
    // Every sample is exactly a report that was sent; and every frame sent came through.
    for p in &received {
        assert_eq!(sent.get(&p.seq), Some(p), "a sample that was not sent");
    }
    assert_eq!(received.len(), 600, "every intact frame arrives");
}

#[test]
fn the_pty_server_answers_through_the_serial_transport() {
    let (tx, rx) = std::sync::mpsc::channel();
    // The server runs for the rest of the test process.
    std::thread::spawn(move || {
        let options = pen_hil::pty::ServeOptions {
            scenario: pen_sim::scenarios::by_name("hold").expect("scenario"),
            seed: 1,
            link: None,
            speed: 1.0,
        };
        let _ = pen_hil::pty::serve(&options, |path| tx.send(path.to_path_buf()).unwrap_or(()), |_| {});
    });
    let path = rx.recv_timeout(Duration::from_secs(5)).expect("the server's path");
    let mut port = SerialTransport::open(&path.to_string_lossy()).expect("open");
    let Message::DeviceInfo(info) = port.get_feature(ReportId::DeviceInfo).expect("device information") else {
        panic!("not the device information");
    };
    assert_eq!(info.receiver_count, 4);
    let cycle_us = 1e6 / f64::from(info.fix_rate_hz);
    let Message::Config(mut config) = port.get_feature(ReportId::Config).expect("configuration") else {
        panic!("not a configuration");
    };
    config.report_rate_hz = 1000;
    assert_eq!(
        port.set_feature(&Message::Config(config)).expect("status").code,
        StatusCode::Ok
    );
    // Now reports come every millisecond of the device's clock. Read on that clock, not the
    // wall's: a loaded machine runs the simulation late, never at another rate.
    let mut stamps = Vec::new();
    let cap = Instant::now() + Duration::from_secs(60);
    while stamps.len() < 300 && Instant::now() < cap {
        if let Ok(Some(Message::Pen(p))) = port.read(Duration::from_millis(50)) {
            stamps.push((p.seq, p.timestamp_us));
        }
    }
    // A report carries the time of its fix, and fixes come at the acoustic cycle's rate (about
    // 150 a second) while reports repeat the latest at 1 kHz: so count the reports between the
    // first reports of two fixes far apart, each sent within a report period of its fix. The
    // first 100 reports may predate the change.
    let fresh: Vec<(u16, u32)> = stamps
        .windows(2)
        .skip(100)
        .filter(|w| w[1].1 != w[0].1)
        .map(|w| w[1])
        .collect();
    assert!(fresh.len() >= 10, "fixes among the reports: {fresh:?}");
    let (first, last) = (fresh[0], fresh[fresh.len() - 1]);
    let reports = f64::from(last.0.wrapping_sub(first.0));
    let span_us = f64::from(last.1.wrapping_sub(first.1));
    // Each cycle's fix is reported, then the latest repeated a report period (1 ms) after each
    // report until the next fix: ⌈cycle / 1 ms⌉ reports a cycle (docs/firmware.md, Reports).
    let expected = span_us / cycle_us * (cycle_us / 1000.0).ceil();
    assert!(
        (reports - expected).abs() <= 2.0,
        "{reports} reports over {:.1} ms of the device's clock, {expected:.1} expected",
        span_us / 1000.0
    );
    config.receiver_count = 2;
    let refused = port.set_feature(&Message::Config(config)).expect("status");
    assert_eq!(refused.code, StatusCode::OutOfRange);
}
