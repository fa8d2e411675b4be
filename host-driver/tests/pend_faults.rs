//! Faults on purpose against pend (issue 17), the real daemon binary on its real socket: clients
//! that never read, that send garbage or a 100 MB line, 2,000 connections opened and dropped as
//! fast as they go; a second pend on the same socket; the socket a killed pend left behind.
//!
//! Expectations: pend stays up; a client that reads meanwhile loses nothing (every report's
//! motion, in sequence, no `missed`); pend's memory stays within its bound (below); the second
//! pend refuses, naming the socket and saying another pend has it; a stale socket is replaced and
//! served.

use std::io::{BufRead, BufReader, Write};
use std::os::unix::net::UnixStream;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use crate::common::{GUARD, Pend, start_pend};

use pen_host::client::{Line, parse_line};
use pen_host::daemon::{DEFAULT_MAX_CLIENTS, DEFAULT_QUEUE};
use pen_host::events::EventKind;

fn socket_path(name: &str) -> (tempfile::TempDir, PathBuf) {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join(format!("{name}.sock"));
    (dir, path)
}

/// A line of `/proc/PID/status` in its unit (kB for memory).
fn status(pid: u32, key: &str) -> u64 {
    let text = std::fs::read_to_string(format!("/proc/{pid}/status")).expect("pend is alive");
    text.lines()
        .find_map(|l| l.strip_prefix(key))
        .and_then(|v| v.trim().trim_end_matches(" kB").parse().ok())
        .unwrap_or_else(|| panic!("{key} in /proc/{pid}/status"))
}

/// What a reading client saw.
#[derive(Debug, Default)]
struct Seen {
    motions: u64,
    /// Reports skipped between consecutive motions (the held pen makes one motion a report).
    gaps: u64,
    missed: u64,
}

/// Reads pend's lines until `stop` is set and at least `at_least` motions came.
fn read_all(stream: UnixStream, stop: &AtomicBool, at_least: u64) -> Seen {
    stream
        .set_read_timeout(Some(Duration::from_millis(200)))
        .expect("timeout");
    let mut reader = BufReader::new(stream);
    let mut seen = Seen::default();
    let mut last_seq: Option<u16> = None;
    let mut line = String::new();
    let end = Instant::now() + 4 * GUARD;
    while !(stop.load(Ordering::Relaxed) && seen.motions >= at_least) && Instant::now() < end {
        line.clear();
        match reader.read_line(&mut line) {
            Ok(0) => break,
            Ok(_) => {}
            Err(_) => continue,
        }
        match parse_line(line.trim_end()).expect("a line pend wrote") {
            Line::Event(e) => match e.kind {
                EventKind::Motion => {
                    seen.motions += 1;
                    let seq = e.seq.expect("a motion's report").0;
                    if last_seq.is_some_and(|l| seq != l.wrapping_add(1)) {
                        seen.gaps += 1;
                    }
                    last_seq = Some(seq);
                }
                EventKind::Missed { count } => seen.missed += count,
                _ => {}
            },
            Line::Hello { .. } => {}
        }
    }
    seen
}

/// Writes `total` bytes of `fill` in 1 MB pieces until pend stops taking them for 2 s; returns
/// the bytes it took.
fn flood(mut stream: UnixStream, total: usize, fill: impl Fn(usize) -> Vec<u8>) -> usize {
    stream.set_write_timeout(Some(Duration::from_secs(2))).expect("timeout");
    let mut sent = 0;
    while sent < total {
        let piece = fill(sent);
        match stream.write(&piece) {
            Ok(0) | Err(_) => break,
            Ok(n) => sent += n,
        }
    }
    sent
}

/// pend's own memory bound, from its documented limits: `max_clients` queues of `DEFAULT_QUEUE`
/// lines of at most 512 bytes each (a motion line is about 300), their writer threads' 64 KB
/// stacks, and 8 MB of slack for the allocator's per-thread arenas and the simulated pen.
fn memory_bound_kb() -> u64 {
    let per_client = DEFAULT_QUEUE * 512 + 64 * 1024;
    ((DEFAULT_MAX_CLIENTS * per_client) / 1024 + 8 * 1024) as u64
}

#[test]
fn pend_outlives_bad_clients_in_bounded_memory_and_live_clients_lose_nothing() {
    let (_dir, path) = socket_path("abuse");
    let pend = start_pend(&path, &["--source", "sim:hold"]);
    let pid = pend.0.id();

    let stop = Arc::new(AtomicBool::new(false));
    let live = {
        let stream = UnixStream::connect(&path).expect("connect");
        let stop = stop.clone();
        std::thread::spawn(move || read_all(stream, &stop, 200))
    };
    std::thread::sleep(Duration::from_millis(300));
    let rss_start = status(pid, "VmRSS:");

    // Ten clients that never read: their queues fill and they miss events, alone.
    let idle: Vec<UnixStream> = (0..10).map(|_| UnixStream::connect(&path).expect("connect")).collect();
    // Garbage, newlines among it, then a 100 MB line: pend reads nothing a client writes but
    // to see that it left, so what it cannot take waits in the client's socket, not in pend.
    let garbage = {
        let s = UnixStream::connect(&path).expect("connect");
        std::thread::spawn(move || {
            flood(s, 4 << 20, |at| {
                (0..1 << 20)
                    .map(|i: usize| (i.wrapping_mul(2_654_435_761).wrapping_add(at) >> 7) as u8)
                    .collect()
            })
        })
    };
    let long_line = {
        let s = UnixStream::connect(&path).expect("connect");
        std::thread::spawn(move || flood(s, 100 << 20, |_| vec![b'x'; 1 << 20]))
    };
    // 2,000 connections opened and dropped at once, as fast as they go; beyond the limit pend
    // refuses them.
    let mut opened = 0;
    for _ in 0..2000 {
        if UnixStream::connect(&path).is_ok() {
            opened += 1;
        }
    }
    let garbage_taken = garbage.join().expect("garbage writer");
    let line_taken = long_line.join().expect("long-line writer");

    // Pend is up and serves a new client, and the writers of the dropped ones have ended:
    // pend's own two threads, and a writer and a session for the live client and each idle
    // one (issue 42: the simulated pen's clients each have a session of their own; before,
    // pend's three threads with one shared device thread, and a writer per client).
    let (s, _) = first_line(&path);
    drop(s);
    let end = Instant::now() + GUARD;
    let threads = || status(pid, "Threads:");
    while threads() > 2 + 2 * (1 + 10) {
        assert!(
            Instant::now() < end,
            "{} threads left after the connections closed",
            threads()
        );
        std::thread::sleep(Duration::from_millis(50));
    }
    let rss_end = status(pid, "VmRSS:");
    let rss_peak = status(pid, "VmHWM:");
    stop.store(true, Ordering::Relaxed);
    let seen = live.join().expect("live reader");
    drop(idle);

    eprintln!(
        "pend VmRSS {rss_start} kB before, {rss_end} kB after, peak {rss_peak} kB (bound {} kB); \
         {opened} of 2000 connections opened; garbage taken {garbage_taken} B, long line {line_taken} B; \
         live client {} motions",
        memory_bound_kb(),
        seen.motions
    );
    assert!(pend_alive(&pend), "pend stays up");
    assert_eq!(opened, 2000, "every connection was accepted or refused, none failed");
    assert!(
        line_taken < 100 << 20,
        "pend does not swallow a 100 MB line: {line_taken} B"
    );
    assert!(rss_peak <= memory_bound_kb(), "peak {rss_peak} kB over the bound");
    assert!(seen.motions >= 200, "{seen:?}");
    assert_eq!(
        (seen.gaps, seen.missed),
        (0, 0),
        "the live client lost nothing: {seen:?}"
    );
}

fn pend_alive(pend: &Pend) -> bool {
    std::fs::read_to_string(format!("/proc/{}/status", pend.0.id())).is_ok_and(|s| !s.contains("State:\tZ"))
}

/// The first line on a new connection.
fn first_line(path: &Path) -> (UnixStream, String) {
    let stream = UnixStream::connect(path).expect("connect");
    stream.set_read_timeout(Some(GUARD)).expect("timeout");
    let mut line = String::new();
    BufReader::new(stream.try_clone().expect("clone"))
        .read_line(&mut line)
        .expect("a line");
    (stream, line)
}

#[test]
fn a_second_pend_refuses_and_a_killed_pends_socket_is_replaced() {
    let (_dir, path) = socket_path("second");
    let mut first = start_pend(&path, &["--source", "sim:hold"]);
    let (client, hello) = first_line(&path);
    assert!(hello.contains(r#""type":"hello""#), "{hello}");

    // A second pend on the same socket gives up at once, naming it; the first goes on serving.
    let out = Command::new(env!("CARGO_BIN_EXE_pend"))
        .args(["--source", "sim:hold", "--socket"])
        .arg(&path)
        .stdin(Stdio::null())
        .output()
        .expect("the second pend runs");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("in use by another pend"), "{stderr}");
    assert!(stderr.contains(&*path.to_string_lossy()), "{stderr}");
    let stop = AtomicBool::new(true);
    let seen = read_all(client, &stop, 20);
    assert!(
        seen.motions >= 20 && seen.gaps == 0,
        "the first pend still serves: {seen:?}"
    );

    // Killed, pend leaves its socket; the next one replaces it and serves.
    first.0.kill().expect("SIGKILL");
    first.0.wait().expect("reaped");
    assert!(path.exists(), "a killed pend leaves its socket behind");
    assert!(UnixStream::connect(&path).is_err(), "and nobody answers on it");
    let _next = start_pend(&path, &["--source", "sim:hold"]);
    let (_, hello) = first_line(&path);
    assert!(hello.contains(r#""type":"hello""#), "{hello}");
}

/// Issue 47 item 9: `--queue` has a maximum. Above it pend refuses as a usage error naming the
/// maximum, before it serves anything; before, any length was taken, and one stalled client
/// grew pend by tens of MB a second.
#[test]
fn a_queue_above_the_maximum_is_a_usage_error_naming_it() {
    use pen_host::daemon::MAX_QUEUE;
    let (_dir, path) = socket_path("queue");
    let too_long = (MAX_QUEUE + 1).to_string();
    let mut child = Command::new(env!("CARGO_BIN_EXE_pend"))
        .args(["--source", "sim:hold", "--queue", &too_long, "--socket"])
        .arg(&path)
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("pend starts");
    let end = Instant::now() + GUARD;
    let status = loop {
        if let Some(status) = child.try_wait().expect("wait") {
            break status;
        }
        if Instant::now() > end {
            let _ = child.kill();
            let _ = child.wait();
            panic!("pend took --queue {too_long} and ran");
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    let mut err = String::new();
    std::io::Read::read_to_string(&mut child.stderr.take().expect("stderr"), &mut err).expect("stderr");
    assert_eq!(status.code(), Some(2), "a usage error: {err}");
    assert!(err.contains(&MAX_QUEUE.to_string()), "names the maximum: {err}");
    assert!(!path.exists(), "nothing served");
    // The maximum itself is taken.
    let _pend = start_pend(&path, &["--source", "sim:hold", "--queue", &MAX_QUEUE.to_string()]);
}
