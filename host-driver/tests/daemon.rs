//! The daemon: many clients at 1 kHz while one stops reading, and a clean stop on SIGTERM.

use std::io::{BufRead, BufReader};
use std::os::unix::fs::PermissionsExt;
use std::os::unix::net::UnixStream;
use std::path::PathBuf;
use std::process::{Command, Stdio};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use pen_host::calibration::{Calibration, DisplaySize};
use pen_host::client::{Line, parse_line};
use pen_host::daemon::{self, Hub};
use pen_host::events::EventKind;
use pen_host::pipeline::Pipeline;
use pen_host::source::Source;
use pen_host::transport::sim::SimOptions;

fn socket_path(name: &str) -> PathBuf {
    std::env::temp_dir().join(format!("pend-test-{}-{name}/pend.sock", std::process::id()))
}

/// What a client saw.
#[derive(Default, Debug)]
struct Seen {
    motions: u64,
    missed: u64,
    gaps: u64,
    latencies_us: Vec<u64>,
}

/// A hang guard only: a loaded machine is slow, never this slow.
const GUARD: Duration = Duration::from_secs(60);

/// Reads until `enough` motion events (or a `missed` notice, if `until_missed`) have come, or
/// `until` passes.
fn read_client(stream: UnixStream, enough: u64, until_missed: bool, until: Instant) -> Seen {
    let _ = stream.set_read_timeout(Some(Duration::from_millis(200)));
    let mut reader = BufReader::new(stream);
    let mut seen = Seen::default();
    let mut last_seq: Option<u16> = None;
    let mut line = String::new();
    while seen.motions < enough && !(until_missed && seen.missed > 0) && Instant::now() < until {
        line.clear();
        match reader.read_line(&mut line) {
            Ok(0) => break,
            Ok(_) => {}
            Err(_) => continue,
        }
        let received = pen_host::sample::now_us();
        match parse_line(line.trim_end()) {
            Ok(Line::Event(e)) => match e.kind {
                EventKind::Motion => {
                    seen.motions += 1;
                    seen.latencies_us.push(received.saturating_sub(e.t_us));
                    let seq = e.seq.map(|s| s.0).unwrap_or(0);
                    if last_seq.is_some_and(|l| seq != l.wrapping_add(1)) {
                        seen.gaps += 1;
                    }
                    last_seq = Some(seq);
                }
                EventKind::Missed { count } => seen.missed += count,
                _ => {}
            },
            Ok(Line::Hello { .. }) => {}
            Err(e) => panic!("bad line from pend: {e}"),
        }
    }
    seen
}

#[test]
fn sixteen_clients_at_1_khz_while_one_stops_reading() {
    let path = socket_path("fanout");
    let listener = daemon::bind(&path).expect("bind");
    let mode = std::fs::metadata(&path).expect("socket").permissions().mode() & 0o777;
    assert_eq!(mode, 0o600, "the socket is the user's alone");
    let stop = Arc::new(AtomicBool::new(false));
    let hub = Arc::new(Hub::default());
    let (h, s) = (hub.clone(), stop.clone());
    std::thread::spawn(move || daemon::accept(listener, h, daemon::DEFAULT_QUEUE, s));

    // The clients connect first: 15 that read and one that never does.
    let clients: Vec<UnixStream> = (0..16).map(|_| UnixStream::connect(&path).expect("connect")).collect();
    while hub.clients() < 16 {
        std::thread::sleep(Duration::from_millis(10));
    }
    // A pen held still, reporting every millisecond.
    let mut scenario = pen_sim::scenarios::by_name("hold").expect("scenario");
    scenario.config.report_rate_hz = 1000;
    let (h, s) = (hub.clone(), stop.clone());
    std::thread::spawn(move || {
        let source = Source::Sim(SimOptions {
            scenario,
            seed: 2,
            speed: 1.0,
            plug: Default::default(),
        });
        daemon::run_device(
            Pipeline::new(source, Calibration::identity(DisplaySize::REFERENCE)),
            h,
            s,
            |_| {},
        )
    });
    // Counted, not timed: each reader takes 3000 motion events (3 s of the pen at 1 kHz, more
    // than the slow client's queue holds). The rate is measured by the pend_load example.
    const MOTIONS: u64 = 3000;
    let until = Instant::now() + GUARD;
    let mut streams = clients.into_iter();
    let slow = streams.next().expect("the slow client");
    let readers: Vec<_> = streams
        .map(|c| std::thread::spawn(move || read_client(c, MOTIONS, false, until)))
        .collect();
    let seen: Vec<Seen> = readers.into_iter().map(|r| r.join().expect("reader")).collect();

    for (i, s) in seen.iter().enumerate() {
        // Every motion event, none missed, none skipped.
        assert_eq!(s.motions, MOTIONS, "client {i} within {GUARD:?}");
        assert_eq!((s.missed, s.gaps), (0, 0), "client {i}");
    }
    let mut lat: Vec<u64> = seen.iter().flat_map(|s| s.latencies_us.iter().copied()).collect();
    lat.sort_unstable();
    eprintln!(
        "15 clients: {} events; latency from report arrival to client p50 {} µs, p99 {} µs, max {} µs",
        lat.len(),
        lat[lat.len() / 2],
        lat[lat.len() * 99 / 100],
        lat[lat.len() - 1]
    );
    // The slow client missed events, and is told so when it reads again.
    let (_, missed) = hub.counts();
    assert!(missed > 0, "the slow client's queue overflowed");
    let resumed = read_client(slow, u64::MAX, true, Instant::now() + GUARD);
    assert!(
        resumed.missed > 0,
        "the slow client was told it missed {missed} events: {resumed:?}"
    );
    stop.store(true, Ordering::Relaxed);
}

#[test]
fn sigterm_stops_pend_cleanly() {
    let path = socket_path("sigterm");
    let mut pend = Command::new(env!("CARGO_BIN_EXE_pend"))
        .args(["--sim", "hold", "--socket"])
        .arg(&path)
        .stderr(Stdio::null())
        .spawn()
        .expect("pend starts");
    let end = Instant::now() + Duration::from_secs(5);
    let stream = loop {
        if let Ok(s) = UnixStream::connect(&path) {
            break s;
        }
        assert!(Instant::now() < end, "pend did not listen");
        std::thread::sleep(Duration::from_millis(20));
    };
    let seen = read_client(stream, 20, false, Instant::now() + GUARD);
    assert_eq!(seen.motions, 20, "events flow: {seen:?}");
    let status = Command::new("kill")
        .args(["-TERM", &pend.id().to_string()])
        .status()
        .expect("kill");
    assert!(status.success());
    let code = pend.wait().expect("pend exits");
    assert_eq!(code.code(), Some(0), "exit status 0 on SIGTERM");
    assert!(!path.exists(), "socket removed");
}
