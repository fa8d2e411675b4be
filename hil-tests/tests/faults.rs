//! Faults on purpose on the serial link (issue 17): the simulated pen's real report bytes,
//! framed as the base station frames them, damaged on the way — bytes dropped, duplicated,
//! bit-flipped, runs of bytes cut out of the stream, at rates up to 1e-3 a byte — and read by
//! the host's serial transport from a real pseudo-terminal.
//!
//! Expectations, checked against what was sent:
//! - no wrong sample: every report read is one that was sent (whole report, so seq and
//!   timestamp too), in the order sent;
//! - resync within one frame: every frame whose bytes (its two delimiters included) were not
//!   touched arrives — a fault spoils at most the frames it hits;
//! - counted drops: the host's sequence-gap count is exactly the reports that did not arrive,
//!   and the damaged frames it saw are counted as dropped (at least one per lost run, at most
//!   two per fault: a flip to 0x00 splits a frame in two).

use std::collections::BTreeSet;
use std::io::Write;
use std::sync::OnceLock;
use std::time::{Duration, Instant};

use pen_host::sample::Sampler;
use pen_host::transport::Transport;
use pen_host::transport::serial::SerialTransport;
use pen_protocol::{MAX_FRAME, Message, encode_frame};
use pen_sim::Simulation;
use rand::{RngExt, SeedableRng};
use serialport::{SerialPort, TTYPort};

/// Frames of real traffic per run (about 65 s of the device's clock): at 1e-3 a byte, some 300
/// faults.
const FRAMES: usize = 10_000;

/// Frames at each end left intact, so that the first and last reports anchor the gap count.
const CLEAN_ENDS: usize = 5;

/// The modeling session's report payloads, as the firmware core sent them (computed once).
fn traffic() -> &'static [Vec<u8>] {
    static TRAFFIC: OnceLock<Vec<Vec<u8>>> = OnceLock::new();
    TRAFFIC.get_or_init(|| {
        let scenario = pen_sim::scenarios::by_name("modeling-session").expect("scenario");
        let mut sim = Simulation::new(&scenario, 17);
        let mut out = Vec::new();
        while out.len() < FRAMES {
            out.extend(sim.step().sent.into_iter().map(|s| s.bytes));
        }
        out.truncate(FRAMES);
        out
    })
}

#[derive(Clone, Copy, Debug)]
enum Fault {
    Drop,
    Duplicate,
    Flip,
    /// A run of 1–64 bytes lost (the line cut mid-frame and back).
    Cut,
}

/// The framed stream with faults at `rate` a byte, and which frames they touched.
fn damage(frames: &[Vec<u8>], fault: Fault, rate: f64, seed: u64) -> (Vec<u8>, BTreeSet<usize>, usize) {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let mut out = Vec::new();
    let mut touched = BTreeSet::new();
    let mut faults = 0;
    // A cut under way: bytes still to lose.
    let mut cutting = 0usize;
    for (i, payload) in frames.iter().enumerate() {
        let mut frame = [0u8; MAX_FRAME];
        let n = encode_frame(payload, &mut frame).expect("fits");
        let clean = i < CLEAN_ENDS || i + CLEAN_ENDS >= frames.len();
        for &b in &frame[..n] {
            if cutting > 0 && !clean {
                cutting -= 1;
                touched.insert(i);
                continue;
            }
            if clean || !rng.random_bool(rate) {
                out.push(b);
                continue;
            }
            faults += 1;
            touched.insert(i);
            match fault {
                Fault::Drop => {}
                Fault::Duplicate => out.extend([b, b]),
                Fault::Flip => out.push(b ^ (1 << rng.random_range(0..8))),
                Fault::Cut => cutting = rng.random_range(0..64),
            }
        }
    }
    (out, touched, faults)
}

/// Writes `bytes` into a pseudo-terminal and reads them with the host's serial transport until
/// the last frame's report arrives; returns the reports read and the frames the transport
/// dropped.
fn through_the_pty(bytes: Vec<u8>, last: &Message) -> (Vec<Message>, u64) {
    let (mut master, slave) = TTYPort::pair().expect("a pty pair");
    let path = slave.name().expect("the pty's path");
    drop(slave);
    master.set_timeout(Duration::from_secs(5)).expect("timeout");
    // Opened before anything is written: opening sets the line up and may discard what waits.
    let mut port = SerialTransport::open(&path).expect("the pty opens as a serial port");
    let writer = std::thread::spawn(move || {
        for chunk in bytes.chunks(512) {
            master.write_all(chunk).expect("write");
        }
        // Kept open until the reader is done: closing hangs the line up and may discard what
        // it has not read yet.
        master
    });
    let mut received = Vec::new();
    // A hang guard only: the last frame is intact and always arrives.
    let cap = Instant::now() + Duration::from_secs(120);
    while received.last() != Some(last) {
        assert!(Instant::now() < cap, "the last frame never arrived");
        if let Some(m) = port.read(Duration::from_millis(100)).expect("the pty stays open") {
            received.push(m);
        }
    }
    drop(writer.join().expect("writer"));
    (received, port.dropped())
}

fn check(fault: Fault, rate: f64, seed: u64) {
    let frames = traffic();
    let sent: Vec<Message> = frames
        .iter()
        .map(|b| Message::decode(b).expect("the firmware's own report"))
        .collect();
    let (bytes, touched, faults) = damage(frames, fault, rate, seed);
    let (received, dropped) = through_the_pty(bytes, &sent[sent.len() - 1]);
    let what = format!(
        "{fault:?} at {rate:e} ({faults} faults, {} frames touched)",
        touched.len()
    );
    assert!(faults > 0, "{what}: no fault injected");

    // No wrong sample: each report read is the next sent one equal to it, whole.
    let mut arrived = BTreeSet::new();
    let mut next = 0;
    for m in &received {
        let k = sent[next..]
            .iter()
            .position(|s| s == m)
            .unwrap_or_else(|| panic!("{what}: {m:?} was not sent (or came out of order)"));
        arrived.insert(next + k);
        next += k + 1;
    }
    // Resync within one frame: every untouched frame arrived.
    let missing: Vec<usize> = (0..sent.len())
        .filter(|i| !touched.contains(i) && !arrived.contains(i))
        .collect();
    assert!(missing.is_empty(), "{what}: intact frames lost: {missing:?}");
    // Counted drops: the gaps in the sequence are the reports lost, no more, no fewer.
    let mut sampler = Sampler::new();
    let mut gaps = 0;
    for m in &received {
        if let Message::Pen(p) = m {
            gaps += sampler.sample(p, 0).1;
        }
    }
    let lost = (sent.len() - arrived.len()) as u64;
    assert_eq!(gaps, lost, "{what}: sequence gaps against reports lost");
    if lost > 0 {
        assert!(dropped >= 1, "{what}: {lost} lost, no damaged frame counted");
    }
    assert!(dropped <= 2 * faults as u64, "{what}: {dropped} frames dropped");
    eprintln!("{what}: {lost} reports lost, {dropped} damaged frames dropped");
}

#[test]
fn dropped_bytes_never_give_a_wrong_sample() {
    check(Fault::Drop, 1e-3, 1);
    check(Fault::Drop, 1e-4, 2);
}

#[test]
fn duplicated_bytes_never_give_a_wrong_sample() {
    check(Fault::Duplicate, 1e-3, 3);
}

#[test]
fn flipped_bits_never_give_a_wrong_sample() {
    check(Fault::Flip, 1e-3, 4);
    check(Fault::Flip, 1e-4, 5);
}

#[test]
fn a_stream_cut_mid_frame_resyncs_at_the_next_frame() {
    check(Fault::Cut, 1e-3, 6);
}

/// Kills the simulated pen's process when dropped: the pty's device side closes, as a base
/// station's serial device does when its cable is pulled.
struct PenSim(std::process::Child);

impl Drop for PenSim {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// `pen-sim serve --pty` playing `draw-figures` in real time, its device linked at `link`
/// (replaced atomically, as udev's stable names are).
fn plug_in(link: &std::path::Path) -> PenSim {
    use std::io::BufRead;
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_pen-sim"))
        .args(["serve", "--pty", "--scenario", "draw-figures", "--link"])
        .arg(link)
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::null())
        .spawn()
        .expect("pen-sim starts");
    let mut first = String::new();
    std::io::BufReader::new(child.stdout.take().expect("stdout"))
        .read_line(&mut first)
        .expect("the device path");
    PenSim(child)
}

/// The device unplugged mid-stroke and plugged back, through pend's daemon code (the hub, its
/// socket, the device thread reattaching `serial:LINK`, as `pend` runs them) and a client on the
/// socket. Expectations: the client is told the device is lost, with the stroke ended (tip up,
/// then out of range) at once; when the device is back it is told so, and the first motion comes
/// from the device's first second (the device's clock restarts at 0 when it is plugged in;
/// pend tries to reattach every 200 ms, so this holds with room on a loaded machine).
#[test]
fn a_device_unplugged_mid_stroke_ends_the_stroke_and_resumes_within_a_second() {
    use std::io::{BufRead, BufReader};
    use std::os::unix::net::UnixStream;
    use std::sync::Arc;
    use std::sync::atomic::AtomicBool;

    use pen_host::calibration::{Calibration, DisplaySize};
    use pen_host::client::{Line, parse_line};
    use pen_host::daemon::{self, Hub};
    use pen_host::events::{EventKind, PenEvent};
    use pen_host::pipeline::Pipeline;
    use pen_host::source::Source;

    let dir = tempfile_dir();
    let link = dir.join("pen-tty");
    let socket = dir.join("pend.sock");
    let mut pen = plug_in(&link);

    let listener = daemon::bind(&socket).expect("bind");
    let stop = Arc::new(AtomicBool::new(false));
    let hub = Arc::new(Hub::default());
    let (h, s) = (hub.clone(), stop.clone());
    std::thread::spawn(move || daemon::accept(listener, h, daemon::DEFAULT_QUEUE, s));
    let (h, s) = (hub.clone(), stop.clone());
    let source = Source::Serial(link.to_string_lossy().into_owned());
    std::thread::spawn(move || {
        let pipeline = Pipeline::new(source, Calibration::identity(DisplaySize::REFERENCE));
        daemon::run_device(pipeline, h, s, |_| {})
    });

    let stream = UnixStream::connect(&socket).expect("connect");
    stream.set_read_timeout(Some(Duration::from_secs(60))).expect("timeout");
    let mut reader = BufReader::new(stream);
    let mut next = || -> PenEvent {
        loop {
            let mut line = String::new();
            let n = reader.read_line(&mut line).expect("a line within the hang guard");
            assert!(n > 0, "pend closed the socket");
            if let Line::Event(e) = parse_line(line.trim_end()).expect("a line pend wrote") {
                return e;
            }
        }
    };
    // Mid-stroke: the tip down and moving.
    let cap = Instant::now() + Duration::from_secs(120);
    while next().kind != EventKind::TipDown {
        assert!(Instant::now() < cap, "no stroke within the hang guard");
    }
    let mut moving = 0;
    while moving < 5 {
        let e = next();
        if e.kind == EventKind::Motion && e.sw == Some([true, false, false]) {
            moving += 1;
        }
    }

    drop(pen); // unplugged
    // The reports read before the loss still come, then the loss, then the switches released
    // and the pen out of range, at once.
    while !matches!(next().kind, EventKind::DeviceLost { .. }) {}
    let mut released = Vec::new();
    let out = loop {
        let e = next();
        match e.kind {
            EventKind::TipUp | EventKind::ButtonUp { .. } => released.push(e),
            _ => break e,
        }
    };
    assert!(
        released.first().is_some_and(|e| e.kind == EventKind::TipUp),
        "the stroke ended by the loss: {released:?}"
    );
    assert_eq!(out.kind, EventKind::ProximityOut, "{out:?}");
    assert_eq!(out.sw, Some([false; 3]), "every switch released");

    pen = plug_in(&link); // plugged back
    let found = next();
    assert!(matches!(found.kind, EventKind::DeviceFound { .. }), "{found:?}");
    let first = loop {
        let e = next();
        if let Some((_, device_us)) = e.seq {
            break device_us;
        }
    };
    eprintln!("first report after the replug: {first} µs on the device's clock");
    assert!(first <= 1_000_000, "resumed {first} µs into the device's run");
    stop.store(true, std::sync::atomic::Ordering::Relaxed);
    drop(pen);
    let _ = std::fs::remove_dir_all(&dir);
}

/// A scratch folder of this test process.
fn tempfile_dir() -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("pen-hil-faults-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("scratch folder");
    dir
}
