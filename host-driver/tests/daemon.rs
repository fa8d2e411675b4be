//! The daemon: many clients at 1 kHz while one stops reading; a lagging client's loss marked
//! where it happened with its state brought up to date; a client joining mid-stroke told the pen
//! is down; clients beyond the limit refused; a clean stop on SIGTERM.

use std::io::{BufRead, BufReader};
use std::os::unix::fs::PermissionsExt;
use std::os::unix::net::UnixStream;
use std::path::PathBuf;
use std::process::{Command, Stdio};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use glam::DVec3;
use pen_host::calibration::{Calibration, DisplaySize};
use pen_host::client::{Line, parse_line};
use pen_host::daemon::{self, Hub};
use pen_host::events::{DisplayPoint, EventDetector, EventKind, PenEvent, PenState};
use pen_host::pipeline::Pipeline;
use pen_host::sample::Sample;
use pen_host::source::Source;
use pen_host::transport::sim::SimOptions;
use pen_protocol::Quality;

/// A socket path in a directory pend creates (as it does its default's), inside a temporary
/// directory removed with the returned guard: a test leaves nothing in /tmp behind.
fn socket_path(name: &str) -> (tempfile::TempDir, PathBuf) {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join(name).join("pend.sock");
    (dir, path)
}

/// What a client saw.
#[derive(Default, Debug)]
struct Seen {
    motions: u64,
    missed: u64,
    gaps: u64,
    latencies_us: Vec<u64>,
    /// What broke the stream's promises: a down without its up, time going backwards, a gap in
    /// the reports with no `missed` notice at it, a notice where no report is missing.
    broken: Vec<String>,
}

/// Checks one event against the client's view of the pen, and updates it: every down has its
/// up, proximity alternates, times never go backwards.
fn follow(view: &mut PenState, last_t: &mut u64, e: &PenEvent) -> Result<(), String> {
    let ok = match &e.kind {
        EventKind::ProximityIn => !view.in_range,
        EventKind::ProximityOut => view.in_range,
        EventKind::TipDown => !view.sw[0],
        EventKind::TipUp => view.sw[0],
        EventKind::ButtonDown { button } => !view.sw[usize::from(*button) - 1],
        EventKind::ButtonUp { button } => view.sw[usize::from(*button) - 1],
        _ => true,
    };
    let before = *last_t;
    *last_t = e.t_us;
    view.apply(e);
    if !ok {
        return Err(format!("{} out of turn at t {}", e.kind.name(), e.t_us));
    }
    if e.t_us < before {
        return Err(format!("{} at t {} after t {before}", e.kind.name(), e.t_us));
    }
    Ok(())
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
    let (mut view, mut last_t, mut notice) = (PenState::default(), 0u64, false);
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
            Ok(Line::Event(e)) => {
                if let Err(why) = follow(&mut view, &mut last_t, &e) {
                    seen.broken.push(why);
                }
                match e.kind {
                    EventKind::Motion => {
                        seen.motions += 1;
                        seen.latencies_us.push(received.saturating_sub(e.t_us));
                        let seq = e.seq.map(|s| s.0).unwrap_or(0);
                        let jumped = last_seq.is_some_and(|l| seq != l.wrapping_add(1));
                        if jumped {
                            seen.gaps += 1;
                        }
                        // The held pen makes one motion per report and nothing else, so a
                        // notice comes exactly where the reports jump.
                        if jumped != notice {
                            seen.broken.push(format!(
                                "seq {last_seq:?} then {seq} with{} a missed notice between",
                                if notice { "" } else { "out" }
                            ));
                        }
                        notice = false;
                        last_seq = Some(seq);
                    }
                    EventKind::Missed { count } => {
                        seen.missed += count;
                        notice = true;
                    }
                    _ => {}
                }
            }
            Ok(Line::Hello { .. }) => {}
            Err(e) => panic!("bad line from pend: {e}"),
        }
    }
    seen
}

#[test]
fn sixteen_clients_at_1_khz_while_one_stops_reading() {
    let (_dir, path) = socket_path("fanout");
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
        assert!(s.broken.is_empty(), "client {i}: {:?}", s.broken);
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
    // It reads on past the notice: the queued events before the gap, the notice at the gap,
    // then the events after it, in order.
    let resumed = read_client(slow, 2 * daemon::DEFAULT_QUEUE as u64, false, Instant::now() + GUARD);
    assert!(
        resumed.missed > 0 && resumed.gaps > 0,
        "the slow client was told it missed {missed} events: {resumed:?}"
    );
    assert!(resumed.broken.is_empty(), "the slow client: {:?}", resumed.broken);
    stop.store(true, Ordering::Relaxed);
}

#[test]
fn sigterm_stops_pend_cleanly() {
    let (_dir, path) = socket_path("sigterm");
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

/// A pen driven sample by sample through the real event detector, each event published with
/// its own time (1 µs apart) so a client's stream says exactly which events it got.
struct Pen {
    detector: EventDetector,
    seq: u16,
    next_t: u64,
    /// The pen's state after each event published, by the event's time.
    states: Vec<(u64, PenState)>,
    state: PenState,
}

impl Pen {
    fn new() -> Pen {
        Pen {
            detector: EventDetector::new(),
            seq: 0,
            next_t: 1_000_000,
            states: Vec::new(),
            state: PenState::default(),
        }
    }

    fn publish(&mut self, hub: &Hub, mut events: Vec<PenEvent>) {
        for e in &mut events {
            e.t_us = self.next_t;
            self.next_t += 1;
            self.state.apply(e);
            self.states.push((e.t_us, self.state.clone()));
            hub.publish(e);
        }
    }

    fn sample(&mut self, hub: &Hub, in_range: bool, sw: [bool; 3]) {
        self.seq = self.seq.wrapping_add(1);
        let s = Sample {
            seq: self.seq,
            device_us: u64::from(self.seq) * 1000,
            host_us: 0,
            sw,
            in_range,
            display_frame: true,
            position_mm: DVec3::new(100.0, 50.0, 0.0),
            quality: Quality::NONE,
        };
        let point = DisplayPoint {
            u_mm: 100.0 + f64::from(self.seq % 100),
            v_mm: 50.0,
            h_mm: 0.0,
            u_px: 400.0,
            v_px: 200.0,
        };
        let mut events = Vec::new();
        self.detector.on_sample(&s, point, &mut events);
        self.publish(hub, events);
    }

    fn found(&mut self, hub: &Hub, device: &str) {
        let mut events = Vec::new();
        self.detector.on_device_found(0, device, &mut events);
        self.publish(hub, events);
    }

    fn lost(&mut self, hub: &Hub) {
        let mut events = Vec::new();
        self.detector.on_device_lost(0, "unplugged", &mut events);
        self.publish(hub, events);
    }

    /// The state after the event at `t_us`.
    fn state_at(&self, t_us: u64) -> &PenState {
        let i = self.states.partition_point(|(t, _)| *t < t_us);
        &self.states[i].1
    }
}

/// Reads lines until `done` says so, or the guard passes; returns the greeting's device and the
/// events.
fn read_events(stream: UnixStream, mut done: impl FnMut(&PenEvent) -> bool) -> (Option<Option<String>>, Vec<PenEvent>) {
    let _ = stream.set_read_timeout(Some(Duration::from_millis(200)));
    let until = Instant::now() + GUARD;
    let mut reader = BufReader::new(stream);
    let (mut hello, mut events) = (None, Vec::new());
    let mut line = String::new();
    while Instant::now() < until {
        line.clear();
        match reader.read_line(&mut line) {
            Ok(0) => break,
            Ok(_) => {}
            Err(_) => continue,
        }
        match parse_line(line.trim_end()) {
            Ok(Line::Hello { device }) => hello = Some(device),
            Ok(Line::Event(e)) => {
                let stop = done(&e);
                events.push(e);
                if stop {
                    break;
                }
            }
            Err(e) => panic!("bad line from pend: {e}"),
        }
    }
    (hello, events)
}

fn names(events: &[PenEvent]) -> Vec<&'static str> {
    events.iter().map(|e| e.kind.name()).collect()
}

/// Issue 22 item 6: a client that stalls mid-stroke while the tip is lifted and put down again
/// and the device is lost and found. Its `missed` notice must come exactly at the gap (the
/// events before it are all it got before the loss, none older follow it), its times never go
/// backwards, and the events after the notice bring it to the pen's state, so it never sees two
/// `tip_down` without a `tip_up`.
#[test]
fn a_lagging_client_sees_its_loss_where_it_happened_and_the_state_after_it() {
    const QUEUE: usize = 32;
    let hub = Arc::new(Hub::default());
    let (ours, theirs) = UnixStream::pair().expect("socket pair");
    assert!(hub.connect(ours, QUEUE));
    let mut pen = Pen::new();
    pen.found(&hub, "sim");
    // Mid-stroke, the client not reading: its socket buffer and queue fill, then it misses.
    let down = [true, false, false];
    let mut filled = 0;
    while hub.counts().1 == 0 {
        pen.sample(&hub, true, down);
        filled += 1;
        assert!(filled < 1_000_000, "the client's queue never filled");
    }
    // The first miss can come while the writer thread still has room in the socket to drain the
    // queue into; the gap below must fall where the writer is blocked. It is once publications
    // spaced by pauses long enough for a writer to run are all missed.
    let (mut missed_in_a_row, until) = (0, Instant::now() + GUARD);
    while missed_in_a_row < 20 {
        assert!(Instant::now() < until, "the client's writer never blocked");
        let before = hub.counts();
        std::thread::sleep(Duration::from_millis(2));
        pen.sample(&hub, true, down);
        let after = hub.counts();
        if after.0 == before.0 && after.1 == before.1 + 1 {
            missed_in_a_row += 1;
        } else {
            missed_in_a_row = 0;
        }
    }
    // All lost to it while it does not read: the tip lifted and put down again, SW3 pressed, the
    // device lost and found, the pen back with the tip down and SW2 pressed.
    let gap_from = pen.next_t;
    pen.sample(&hub, true, [false, false, false]);
    pen.sample(&hub, true, [true, false, false]);
    pen.sample(&hub, true, [true, false, true]);
    pen.lost(&hub);
    pen.found(&hub, "sim");
    pen.sample(&hub, true, [true, true, false]);
    let gap_to = pen.next_t;

    // The client reads again, while the pen goes on (paced, not timed: each publication
    // offers the notice again until its queue has room).
    let caught_up = Arc::new(AtomicBool::new(false));
    let flag = caught_up.clone();
    let reader = std::thread::spawn(move || {
        let mut notice = false;
        read_events(theirs, |e| {
            notice |= matches!(e.kind, EventKind::Missed { .. });
            // Earlier gaps may close while the writer still drains; the one that matters ends
            // at or after the lost device.
            let done = notice && e.seq.is_some() && e.t_us >= gap_to;
            if done {
                flag.store(true, Ordering::Relaxed);
            }
            done
        })
    });
    let until = Instant::now() + GUARD;
    while !caught_up.load(Ordering::Relaxed) && Instant::now() < until {
        pen.sample(&hub, true, [true, true, false]);
        std::thread::sleep(Duration::from_millis(1));
    }
    let (hello, events) = reader.join().expect("reader");
    assert_eq!(hello, Some(None), "greeted before any device");

    // The stream: every down paired, times in order.
    let (mut view, mut last_t) = (PenState::default(), 0);
    for e in &events {
        follow(&mut view, &mut last_t, e).unwrap_or_else(|why| panic!("{why}: {:?}", names(&events)));
    }
    // Each notice sits exactly at its gap: the real event before it and the first after it are
    // `count` + 1 apart, and between them come only events pend made up (no `seq`).
    let notices: Vec<usize> = (0..events.len())
        .filter(|&i| matches!(events[i].kind, EventKind::Missed { .. }))
        .collect();
    assert!(!notices.is_empty(), "{:?}", names(&events));
    let mut counted = 0;
    let mut covered = false;
    for &i in &notices {
        let EventKind::Missed { count } = events[i].kind else {
            unreachable!()
        };
        counted += count;
        let before = events[..i]
            .iter()
            .rev()
            .find(|e| e.seq.is_some())
            .expect("an event before the gap");
        let after_at = i + events[i..]
            .iter()
            .position(|e| e.seq.is_some())
            .expect("an event after the gap");
        let after = &events[after_at];
        assert_eq!(after.t_us - before.t_us - 1, count, "notice {i} marks its gap");
        assert_eq!(events[i].t_us, after.t_us, "the notice at the gap's end");
        // What came between is the difference between the state the client saw and the pen's.
        let mut caught = pen.state_at(before.t_us).clone();
        for e in &events[i + 1..after_at] {
            assert_eq!((e.seq, e.t_us), (None, after.t_us), "made up at the gap: {e:?}");
            caught.apply(e);
        }
        let now = pen.state_at(after.t_us - 1);
        assert_eq!(
            (caught.in_range, caught.sw, &caught.device, caught.attachments),
            (now.in_range, now.sw, &now.device, now.attachments),
            "resynchronised at notice {i}"
        );
        if before.t_us < gap_from && after.t_us >= gap_to {
            covered = true;
            // The tip never came up for this client before the device was lost: pend says the
            // device went, releases and takes the pen out of range, then the new device, the
            // pen, its tip and SW2.
            assert_eq!(
                names(&events[i + 1..after_at]),
                [
                    "device_lost",
                    "tip_up",
                    "proximity_out",
                    "device_found",
                    "proximity_in",
                    "tip_down",
                    "button_down"
                ]
            );
        }
    }
    assert!(covered, "one gap spans the lifted tip and the lost device");
    assert_eq!(counted, hub.counts().1, "every event missed is counted in a notice");
}

/// Issue 19 item 7: a client that joins mid-stroke is told the pen is in range with the tip
/// and SW3 down before the next motion, so it sees the stroke's `tip_up` paired.
#[test]
fn a_client_joining_mid_stroke_is_told_the_pen_is_down() {
    let hub = Arc::new(Hub::default());
    let mut pen = Pen::new();
    pen.found(&hub, "sim");
    pen.sample(&hub, true, [false; 3]);
    pen.sample(&hub, true, [true, false, true]);
    pen.sample(&hub, true, [true, false, true]);
    let joined_at = pen.next_t - 1;
    let (ours, theirs) = UnixStream::pair().expect("socket pair");
    assert!(hub.connect(ours, daemon::DEFAULT_QUEUE));
    pen.sample(&hub, true, [true, false, true]);
    pen.sample(&hub, true, [false, false, false]);
    let (hello, events) = read_events(theirs, |e| e.kind == EventKind::ButtonUp { button: 3 });
    assert_eq!(hello, Some(Some("sim".to_string())));
    assert_eq!(
        names(&events),
        [
            "proximity_in",
            "tip_down",
            "button_down",
            "motion",
            "tip_up",
            "button_up"
        ]
    );
    // Made up from the state, at the time of the last event that made it, with its position.
    for e in &events[..3] {
        assert_eq!((e.seq, e.t_us), (None, joined_at), "{e:?}");
        assert!(e.point.is_some());
    }
    assert_eq!(events[1].sw, Some([true, false, false]));
    assert_eq!(events[2].sw, Some([true, false, true]));
    let (mut view, mut last_t) = (PenState::default(), 0);
    for e in &events {
        follow(&mut view, &mut last_t, e).expect("paired");
    }
}

/// The first line on a new connection to pend.
fn first_line(path: &std::path::Path) -> (UnixStream, String) {
    let stream = UnixStream::connect(path).expect("connect");
    stream.set_read_timeout(Some(GUARD)).expect("timeout");
    let mut reader = BufReader::new(stream.try_clone().expect("clone"));
    let mut line = String::new();
    reader.read_line(&mut line).expect("a line");
    (stream, line)
}

fn threads(pid: u32) -> usize {
    let status = std::fs::read_to_string(format!("/proc/{pid}/status")).expect("status");
    status
        .lines()
        .find_map(|l| l.strip_prefix("Threads:"))
        .and_then(|n| n.trim().parse().ok())
        .expect("Threads:")
}

/// Issue 22 item 9: pend serves at most `--max-clients` at once; one more reads a `refused`
/// line saying why and is closed, costing no thread; a place is freed when a client leaves.
#[test]
fn clients_beyond_the_limit_are_refused_and_cost_no_thread() {
    let (_dir, path) = socket_path("limit");
    let mut pend = Command::new(env!("CARGO_BIN_EXE_pend"))
        .args(["--sim", "hold", "--max-clients", "4", "--socket"])
        .arg(&path)
        .stderr(Stdio::null())
        .spawn()
        .expect("pend starts");
    let end = Instant::now() + GUARD;
    while UnixStream::connect(&path).is_err() {
        assert!(Instant::now() < end, "pend did not listen");
        std::thread::sleep(Duration::from_millis(20));
    }
    // Threads settle to pend's own once the probe above is gone: main and acceptor, since the
    // simulated pen's device threads are each client's own (issue 42: a session per client;
    // before, main, acceptor and one shared device thread, and a writer per client).
    let wait_threads = |want: usize| {
        let end = Instant::now() + GUARD;
        while threads(pend.id()) != want {
            assert!(Instant::now() < end, "threads {} not {want}", threads(pend.id()));
            std::thread::sleep(Duration::from_millis(20));
        }
    };
    wait_threads(2);
    let mut served: Vec<UnixStream> = (0..4)
        .map(|_| {
            let (s, line) = first_line(&path);
            assert!(line.contains(r#""type":"hello""#), "{line}");
            s
        })
        .collect();
    assert_eq!(threads(pend.id()), 2 + 2 * 4, "a writer and a session per client");
    for _ in 0..50 {
        let (stream, line) = first_line(&path);
        match parse_line(line.trim_end()) {
            Err(pen_host::client::ClientError::Io(e)) => {
                assert_eq!(e.kind(), std::io::ErrorKind::ConnectionRefused);
                assert!(e.to_string().contains("at most 4 clients"), "{e}");
            }
            other => panic!("{line}: {other:?}"),
        }
        let mut rest = String::new();
        let n = BufReader::new(stream).read_line(&mut rest).expect("closed");
        assert_eq!(n, 0, "closed after the refusal: {rest}");
    }
    assert_eq!(threads(pend.id()), 2 + 2 * 4, "refused clients cost no thread");
    // One leaves: its writer and its session end and its place is taken by the next.
    drop(served.pop());
    wait_threads(2 + 2 * 3);
    let (_, line) = first_line(&path);
    assert!(line.contains(r#""type":"hello""#), "{line}");
    let _ = pend.kill();
    let _ = pend.wait();
    let _ = std::fs::remove_file(&path);
}

/// Issue 47 item 9: a client's queue is bounded by bytes as well as by events. A stalled client
/// offered 1,000 lines of 8 KiB (device names; 8 MB in all, fewer events than its queue's 1024)
/// holds at most the queue's byte budget, beside what its socket and writer have in flight; the
/// rest it misses. Counted by events only, all 1,000 were queued. Its queue is freed when it
/// leaves.
#[test]
fn a_stalled_clients_queue_is_bounded_by_bytes_and_freed_when_it_leaves() {
    let hub = Arc::new(Hub::default());
    let (ours, theirs) = UnixStream::pair().expect("socket pair");
    assert!(hub.connect(ours, daemon::DEFAULT_QUEUE));
    let budget = daemon::DEFAULT_QUEUE * daemon::LINE_BYTES;
    let name = "n".repeat(8 * 1024);
    for i in 0..1000u64 {
        let kind = if i % 2 == 0 {
            EventKind::DeviceFound { device: name.clone() }
        } else {
            EventKind::DeviceLost { reason: name.clone() }
        };
        hub.publish(&PenEvent {
            kind,
            t_us: 1_000_000 + i,
            point: None,
            sw: None,
            seq: None,
        });
        assert!(
            hub.queued_bytes() <= budget,
            "after {i} lines: {} bytes queued, more than the {budget} budget",
            hub.queued_bytes()
        );
    }
    let (delivered, missed) = hub.counts();
    // What is not queued is in the socket (a few hundred KB) or the writer's batch (64 KiB).
    assert!(
        delivered * 8 * 1024 <= 4 * 1024 * 1024,
        "{delivered} lines of 8 KiB taken for a client that never reads"
    );
    assert_eq!(delivered + missed, 1000);

    drop(theirs);
    let until = Instant::now() + GUARD;
    while hub.clients() > 0 {
        assert!(Instant::now() < until, "the client that left kept its place");
        std::thread::sleep(Duration::from_millis(10));
    }
    assert_eq!(hub.queued_bytes(), 0, "its queue freed");
}

/// Issue 47 item 11: a client that shuts its writing side (as `socat - UNIX-CONNECT:… </dev/null`
/// does) but reads on is served: reading 0 bytes from it means it asks for nothing more, not that
/// it left. pend dropped it within milliseconds. A client that closes its socket while the pen is
/// quiet still frees its place.
#[test]
fn a_half_closed_client_is_served_and_a_closed_one_leaves() {
    const MOTIONS: usize = 200;
    let hub = Arc::new(Hub::default());
    let (ours, theirs) = UnixStream::pair().expect("socket pair");
    theirs
        .shutdown(std::net::Shutdown::Write)
        .expect("shut its writing side");
    assert!(hub.connect(ours, daemon::DEFAULT_QUEUE));
    let reader = std::thread::spawn(move || {
        let mut motions = 0;
        read_events(theirs, |e| {
            motions += usize::from(e.kind == EventKind::Motion);
            motions == MOTIONS
        })
    });
    let mut pen = Pen::new();
    // More than a writer's batch (64 lines): however the threads are scheduled, the writer
    // looks at the client's side between batches, before the last motions are written.
    for _ in 0..MOTIONS {
        pen.sample(&hub, true, [false, false, false]);
    }
    let (hello, events) = reader.join().expect("reader");
    assert_eq!(hello, Some(None), "greeted");
    let motions = events.iter().filter(|e| e.kind == EventKind::Motion).count();
    assert_eq!(
        motions,
        MOTIONS,
        "every motion read by the half-closed client: {:?}",
        names(&events)
    );
    assert_eq!(hub.counts().1, 0, "none missed");

    // Closed whole, with no event to write: it leaves at its writer's next look (the first
    // client closed too, when its reader ended).
    let (ours, theirs) = UnixStream::pair().expect("socket pair");
    assert!(hub.connect(ours, daemon::DEFAULT_QUEUE));
    drop(theirs);
    let until = Instant::now() + GUARD;
    while hub.clients() > 0 {
        assert!(Instant::now() < until, "a closed client kept its place");
        std::thread::sleep(Duration::from_millis(10));
    }
}

/// Issue 47 item 11: SIGHUP reloads the calibration and says so; pend serves on with it. It
/// used to end pend (the default action), leaving its socket behind.
#[test]
fn sighup_reloads_the_calibration_and_pend_serves_on() {
    let (dir, path) = socket_path("sighup");
    let file = dir.path().join("calibration.toml");
    let identity = Calibration::identity(DisplaySize::REFERENCE);
    identity.save(&file).expect("save");
    let mut pend = Command::new(env!("CARGO_BIN_EXE_pend"))
        .args(["--sim", "hold", "--calibration"])
        .arg(&file)
        .arg("--socket")
        .arg(&path)
        .stderr(Stdio::piped())
        .spawn()
        .expect("pend starts");
    let (tx, log) = std::sync::mpsc::channel();
    let stderr = pend.stderr.take().expect("stderr");
    std::thread::spawn(move || {
        for line in BufReader::new(stderr).lines().map_while(Result::ok) {
            let _ = tx.send(line);
        }
    });
    let end = Instant::now() + GUARD;
    let stream = loop {
        if let Ok(s) = UnixStream::connect(&path) {
            break s;
        }
        assert!(Instant::now() < end, "pend did not listen");
        std::thread::sleep(Duration::from_millis(20));
    };
    stream
        .set_read_timeout(Some(Duration::from_millis(200)))
        .expect("timeout");
    let mut reader = BufReader::new(stream);
    let mut next_u = || loop {
        assert!(Instant::now() < end, "no motion within {GUARD:?}");
        let mut line = String::new();
        match reader.read_line(&mut line) {
            Ok(0) => panic!("pend closed the socket"),
            Ok(_) => {}
            Err(_) => continue,
        }
        if let Ok(Line::Event(e)) = parse_line(line.trim_end())
            && e.kind == EventKind::Motion
        {
            return e.point.expect("a motion's point").u_mm;
        }
    };
    let before = next_u();

    let mut moved = identity.clone();
    moved.transform.translation_mm.x += 100.0;
    moved.save(&file).expect("save");
    let status = Command::new("kill")
        .args(["-HUP", &pend.id().to_string()])
        .status()
        .expect("kill");
    assert!(status.success());
    let reloaded = loop {
        assert!(Instant::now() < end, "no reload said within {GUARD:?}");
        if let Some(code) = pend.try_wait().expect("wait") {
            panic!("pend ended at SIGHUP: {code}");
        }
        match log.recv_timeout(Duration::from_millis(100)) {
            Ok(line) if line.contains("SIGHUP") => break line,
            _ => {}
        }
    };
    assert!(
        reloaded.contains("reloaded") && reloaded.contains("calibration.toml"),
        "{reloaded}"
    );
    // A file without fit targets has no RMS to show (issue 47 item 11: it showed "-0.00 mm").
    assert!(
        reloaded.contains("no fit targets") && !reloaded.contains("-0.00"),
        "{reloaded}"
    );
    // The events after it are mapped by the new file: 100 mm further along u.
    let after = loop {
        let u = next_u();
        if (u - before - 100.0).abs() < 10.0 {
            break u;
        }
    };
    assert!(after > before + 90.0);
    assert!(path.exists(), "its socket stays");
    let status = Command::new("kill")
        .args(["-TERM", &pend.id().to_string()])
        .status()
        .expect("kill");
    assert!(status.success());
    assert_eq!(pend.wait().expect("exits").code(), Some(0));
}

/// Issue 42: `pend --source sim` serves each client the scripted session from its start. A
/// modeler that connected 1.5 s after another joined the one session mid-stroke; now its first
/// report is at the scenario's start on the device's clock, as the first client's was, and the
/// two sessions are the same script, so their first motions are at the same points.
#[test]
fn each_client_of_the_simulated_pen_gets_the_session_from_its_start() {
    let (_dir, path) = socket_path("sessions");
    let mut pend = Command::new(env!("CARGO_BIN_EXE_pend"))
        .args(["--source", "sim", "--speed", "1", "--socket"])
        .arg(&path)
        .stderr(Stdio::piped())
        .spawn()
        .expect("pend starts");
    let stderr = pend.stderr.take().expect("stderr");
    let (tx, log) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        for line in BufReader::new(stderr).lines().map_while(Result::ok) {
            let _ = tx.send(line);
        }
    });
    let end = Instant::now() + GUARD;
    let connect = || loop {
        if let Ok(s) = UnixStream::connect(&path) {
            break s;
        }
        assert!(Instant::now() < end, "pend did not listen");
        std::thread::sleep(Duration::from_millis(20));
    };
    let device_us = |e: &PenEvent| e.seq.map(|(_, d)| d);
    let first = connect();
    let started = Instant::now();
    // The first client reads for 1.5 s of the session.
    let (_, a) = read_events(first.try_clone().expect("clone"), |_| {
        started.elapsed() > Duration::from_millis(1500)
    });
    let a_first = a.iter().find_map(device_us).expect("reports");
    let a_last = a.iter().rev().find_map(device_us).expect("reports");
    assert!(
        a_last > a_first + 1_000_000,
        "the first session ran on: {a_first}..{a_last} µs"
    );
    // The second joins now: its session starts afresh, not where the first one is.
    let (_, b) = read_events(connect(), {
        let mut n = 0;
        move |e| {
            n += usize::from(e.kind == EventKind::Motion);
            n >= 20
        }
    });
    let b_first = b.iter().find_map(device_us).expect("reports");
    assert!(
        b_first < a_first + 300_000,
        "the second client's first report at {b_first} µs, the first's at {a_first} µs, and it was at {a_last} µs"
    );
    let motions = |events: &[PenEvent]| -> Vec<(i64, i64)> {
        events
            .iter()
            .filter(|e| e.kind == EventKind::Motion)
            .filter_map(|e| e.point)
            .map(|p| ((p.u_mm * 10.0).round() as i64, (p.v_mm * 10.0).round() as i64))
            .take(10)
            .collect()
    };
    assert_eq!(motions(&a), motions(&b), "the same script from the same start");
    drop(first);
    let _ = Command::new("kill").args(["-TERM", &pend.id().to_string()]).status();
    assert_eq!(pend.wait().expect("exits").code(), Some(0));
    // pend has ended: its stderr closes, and the reader's channel with it.
    let log: Vec<String> = log.iter().collect();
    let log = log.join("\n");
    assert!(log.contains("a session of its own"), "{log}");
    assert!(log.contains("stopped; 2 sessions"), "{log}");
}
