//! `pend`: one process owns the device and serves its events to a bounded number of clients on
//! a Unix domain socket, as JSON lines (docs/events.md).
//!
//! The device is read on its own thread and every event is encoded once and offered to each
//! client's bounded queue. A client that does not keep up loses events from its own queue only,
//! and never slows the device reader or the other clients, each of which has its own writer
//! thread. The loss is marked where it happened: the events before it stay queued, and once
//! there is room again the `missed` notice goes into the queue at the gap, followed by the
//! events that bring the client from the state it last saw to the pen's state now, so its
//! downs and ups stay paired. A client that joins gets the greeting and then the same kind of
//! events for the state it joins in (a pen already down gives it `tip_down`).
//!
//! Clients are bounded (`--max-clients`, 64 by default): one more is sent a `refused` line
//! saying why, and closed, instead of costing a thread.
//!
//! The simulated pen is served otherwise ([`Sessions`]): each client gets a session of its own,
//! from the scenario's start, on a device thread of its own that ends when the client leaves,
//! so a modeler that connects late never joins a scripted stroke half drawn.
//!
//! `head` lines go only to clients that asked for them (events version 4: a `subscribe` line
//! the client writes, which its writer reads between writes, [`crate::requests`]), so a client
//! built for version 2 reads only the lines it knows.

use std::collections::VecDeque;
use std::io::{BufWriter, Write};
use std::net::Shutdown;
use std::os::unix::net::UnixStream;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Condvar, Mutex};
use std::time::Duration;

use crate::calibration::Calibration;
use crate::events::{EventKind, PenEvent, PenState};
use crate::pipeline::Pipeline;
use crate::requests::Requests;
use crate::sample::now_us;
use crate::socket::{self, SocketError};

use crate::wire::{self, Hello, Refused, SocketLine};

/// Events a client may have queued before it starts missing them: about a second at 1 kHz.
pub const DEFAULT_QUEUE: usize = 1024;

/// The longest queue a client may have (`pend --queue`): 16 s at 1 kHz. Beyond it one stalled
/// client could hold as much memory as it likes; with [`LINE_BYTES`] a queue holds at most
/// 8 MiB of lines.
pub const MAX_QUEUE: usize = 16 * 1024;

/// Bytes of lines a queue holds per event of its length: a motion line is about 300 bytes, so
/// a queue is bounded by its length in events; a long line (a device's name, a loss's reason)
/// takes its size from the same budget, so the bytes are bounded too.
pub const LINE_BYTES: usize = 512;

/// Clients served at once. Each costs a writer thread and, while it lags, up to its queue of
/// lines (about 300 KB at 1024); 64 is far more than the programs one pen feeds, and small
/// enough that a runaway script opening connections cannot exhaust threads or memory.
pub const DEFAULT_MAX_CLIENTS: usize = 64;

/// A writer only moves lines from its queue to its socket: a small stack suffices, and many
/// clients then reserve little address space.
const WRITER_STACK: usize = 64 * 1024;

/// Lines a writer takes from its queue per write: enough to send a burst in one system call,
/// few enough that the lines in flight stay small beside the queue.
const BATCH: usize = 64;

/// Bytes a writer takes per batch at most: lines in flight stay small beside the queue however
/// long they are.
const BATCH_BYTES: usize = 64 * 1024;

/// A queue that held more than this at its fullest is handed back to the system when its client
/// leaves (see [`Leaving`]).
const TRIM_AFTER: usize = 1024 * 1024;

/// How long a writer waits for events before checking that its client is still there, so a
/// client that leaves while the pen is quiet frees its place.
const IDLE_CHECK: Duration = Duration::from_secs(1);

/// How often a writer with nothing to write looks for its client's request during
/// [`ASK_WINDOW`] after it connected: a client asks right after connecting, and the pen may be
/// quiet then (with the pen moving the writer looks after every write).
const ASK_CHECK: Duration = Duration::from_millis(20);

/// See [`ASK_CHECK`]; later an idle writer looks every [`IDLE_CHECK`].
const ASK_WINDOW: Duration = Duration::from_secs(2);

/// The default socket: `$XDG_RUNTIME_DIR/penscape/pend.sock`, or `/tmp/penscape-UID/pend.sock`.
pub fn default_socket() -> PathBuf {
    socket::default_path()
}

/// One client's lines, shared by the publisher (which appends) and its writer (which takes).
struct Queue {
    state: Mutex<QueueState>,
    wake: Condvar,
}

struct QueueState {
    lines: VecDeque<Arc<str>>,
    /// The bytes of `lines`.
    bytes: usize,
    /// The most bytes `lines` held.
    peak: usize,
    /// The writer has stopped: the client left or its socket failed.
    gone: bool,
    /// The writer is waiting for lines: only then is it worth a wake-up.
    waiting: bool,
    /// The client asked for `head` lines.
    head: bool,
}

/// Events a lagging client has lost since the last one queued for it.
struct Gap {
    /// The state its queued events leave it in.
    seen: PenState,
    count: u64,
}

struct Client {
    queue: Arc<Queue>,
    /// At most this many lines…
    capacity: usize,
    /// …and this many bytes of them.
    capacity_bytes: usize,
    gap: Option<Gap>,
}

impl QueueState {
    /// Whether `n` more lines of `bytes` fit beside those queued, within `c`'s bounds. An empty
    /// queue takes them whatever their size, or a tiny queue or a long line never would be.
    fn fits(&self, c: &Client, n: usize, bytes: usize) -> bool {
        self.lines.is_empty() || (self.lines.len() + n <= c.capacity && self.bytes + bytes <= c.capacity_bytes)
    }

    fn push(&mut self, line: Arc<str>) {
        self.bytes += line.len();
        self.peak = self.peak.max(self.bytes);
        self.lines.push_back(line);
    }
}

struct Inner {
    clients: Vec<Client>,
    /// The pen's state after the events published so far.
    state: PenState,
    /// The last event's time: when `state` was last known to hold.
    last_t_us: u64,
}

/// The clients and the pen's state, shared by the device thread and the acceptor.
pub struct Hub {
    inner: Mutex<Inner>,
    max_clients: usize,
    delivered: AtomicU64,
    missed: AtomicU64,
    refused: AtomicU64,
}

impl Default for Hub {
    fn default() -> Hub {
        Hub::new(DEFAULT_MAX_CLIENTS)
    }
}

impl Hub {
    /// A hub serving at most `max_clients` at once (at least one).
    pub fn new(max_clients: usize) -> Hub {
        Hub {
            inner: Mutex::new(Inner {
                clients: Vec::new(),
                state: PenState::default(),
                last_t_us: 0,
            }),
            max_clients: max_clients.max(1),
            delivered: AtomicU64::new(0),
            missed: AtomicU64::new(0),
            refused: AtomicU64::new(0),
        }
    }

    /// Offers one event to every client.
    pub fn publish(&self, event: &PenEvent) {
        let line: Arc<str> = Arc::from(wire::line(event));
        let mut inner = lock(&self.inner);
        let Inner {
            clients,
            state,
            last_t_us,
        } = &mut *inner;
        let mut resync = Vec::new();
        let head = matches!(event.kind, EventKind::Head(_));
        clients.retain_mut(|c| {
            let mut q = lock(&c.queue.state);
            if q.gone {
                return false;
            }
            // Not asked for: not sent, and not missed either (events version 4).
            if head && !q.head {
                return true;
            }
            let queued = match c.gap.take() {
                None if q.fits(c, 1, line.len()) => {
                    q.push(line.clone());
                    true
                }
                // The queue is full: the gap starts here, after what the client will read.
                None => {
                    c.gap = Some(Gap {
                        seen: state.clone(),
                        count: 1,
                    });
                    false
                }
                // Not even the notice and this event fit: still in the gap, and cheaply so,
                // since a lagging client meets this for every event until it reads.
                Some(mut gap) if !q.fits(c, 2, line.len()) => {
                    gap.count += 1;
                    c.gap = Some(gap);
                    false
                }
                Some(mut gap) => {
                    // The notice and the catch-up go in at the gap, before this event, and at
                    // its time, so the client's times never go backwards.
                    resync.clear();
                    resync.push(PenEvent::missed(gap.count, event.t_us));
                    gap.seen.resync(state, event.t_us, &mut resync);
                    let lines: Vec<Arc<str>> = resync.iter().map(|e| Arc::from(wire::line(e))).collect();
                    let bytes = lines.iter().map(|l| l.len()).sum::<usize>() + line.len();
                    if q.fits(c, lines.len() + 1, bytes) {
                        lines.into_iter().for_each(|l| q.push(l));
                        q.push(line.clone());
                        true
                    } else {
                        gap.count += 1;
                        c.gap = Some(gap);
                        false
                    }
                }
            };
            if queued {
                self.delivered.fetch_add(1, Ordering::Relaxed);
                if q.waiting {
                    c.queue.wake.notify_one();
                }
            } else {
                self.missed.fetch_add(1, Ordering::Relaxed);
            }
            true
        });
        state.apply(event);
        *last_t_us = event.t_us;
    }

    /// Clients connected.
    pub fn clients(&self) -> usize {
        let mut inner = lock(&self.inner);
        inner.clients.retain(|c| !lock(&c.queue.state).gone);
        inner.clients.len()
    }

    /// The most clients served at once.
    pub fn max_clients(&self) -> usize {
        self.max_clients
    }

    /// Events queued for clients, and events clients missed, since the start.
    pub fn counts(&self) -> (u64, u64) {
        (
            self.delivered.load(Ordering::Relaxed),
            self.missed.load(Ordering::Relaxed),
        )
    }

    /// Bytes of lines queued for clients now.
    pub fn queued_bytes(&self) -> usize {
        let inner = lock(&self.inner);
        inner.clients.iter().map(|c| lock(&c.queue.state).bytes).sum()
    }

    /// Clients turned away because `max_clients` were connected, since the start.
    pub fn refused(&self) -> u64 {
        self.refused.load(Ordering::Relaxed)
    }

    /// Serves a connected client from its own writer thread, its queue holding at most
    /// `queue_len` events (at most [`MAX_QUEUE`]) and `queue_len` × [`LINE_BYTES`] bytes of
    /// lines: the greeting, the events of the pen's current state, then every event. When `max_clients` are connected it is sent a `refused` line and closed instead;
    /// the result says whether it was taken.
    pub fn connect(&self, stream: UnixStream, queue_len: usize) -> bool {
        let mut inner = lock(&self.inner);
        inner.clients.retain(|c| !lock(&c.queue.state).gone);
        if inner.clients.len() >= self.max_clients {
            drop(inner);
            self.refuse(stream);
            return false;
        }
        // Greeting and state are taken under the lock that publishing holds, so no event falls
        // between them and the first one queued.
        let mut first = QueueState {
            lines: VecDeque::new(),
            bytes: 0,
            peak: 0,
            gone: false,
            waiting: false,
            head: false,
        };
        first.push(Arc::from(
            SocketLine::Hello(Hello::new(now_us(), inner.state.device.clone())).to_text(),
        ));
        let mut join = Vec::new();
        inner.state.greeted().resync(&inner.state, inner.last_t_us, &mut join);
        join.iter().for_each(|e| first.push(Arc::from(wire::line(e))));
        let queue = Arc::new(Queue {
            state: Mutex::new(first),
            wake: Condvar::new(),
        });
        let writer = queue.clone();
        let spawned = std::thread::Builder::new()
            .name("pend-client".into())
            .stack_size(WRITER_STACK)
            .spawn(move || write_client(stream, &writer));
        // Without a thread the stream was dropped with the closure: the client sees the
        // connection close, and pend goes on serving the others.
        if spawned.is_err() {
            return false;
        }
        let capacity = queue_len.clamp(1, MAX_QUEUE);
        inner.clients.push(Client {
            queue,
            capacity,
            capacity_bytes: capacity * LINE_BYTES,
            gap: None,
        });
        true
    }

    /// Tells a client there is no room for it, and closes it.
    fn refuse(&self, stream: UnixStream) {
        self.refused.fetch_add(1, Ordering::Relaxed);
        let reason = format!(
            "pend serves at most {} clients at once (pend --max-clients); try again when one has left",
            self.max_clients
        );
        let line = SocketLine::Refused(Refused::new(now_us(), reason)).to_text();
        // A new socket's buffer takes one line; the timeout only keeps a strange one from
        // holding up the acceptor.
        let _ = stream.set_write_timeout(Some(Duration::from_millis(100)));
        let _ = (&stream).write_all(line.as_bytes());
        let _ = stream.shutdown(Shutdown::Both);
    }
}

/// A poisoned lock only means another thread panicked mid-update of a list we can still use.
fn lock<T>(m: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|e| e.into_inner())
}

/// Marks the queue's writer gone however it ends (an error, the client leaving, a panic), so
/// the hub drops the client and frees its place.
struct Leaving<'a>(&'a Queue);

impl Drop for Leaving<'_> {
    fn drop(&mut self) {
        let mut q = lock(&self.0.state);
        q.gone = true;
        q.lines = VecDeque::new();
        q.bytes = 0;
        let peak = std::mem::take(&mut q.peak);
        drop(q);
        // The lines were many small allocations made on the device thread, in its own malloc
        // arena, which glibc does not shrink on free: a full queue's memory stayed with pend
        // after its client left (70 of 188 MB, measured) until it is trimmed.
        if peak > TRIM_AFTER {
            trim_heap();
        }
    }
}

/// Gives the allocator's free memory back to the system.
#[cfg(all(target_os = "linux", target_env = "gnu"))]
fn trim_heap() {
    // SAFETY: malloc_trim takes no pointers and only releases free memory of the allocator's
    // own arenas; it is thread-safe (it locks each arena).
    #[allow(unsafe_code)]
    unsafe {
        libc::malloc_trim(0);
    }
}

/// Other allocators return large frees themselves.
#[cfg(not(all(target_os = "linux", target_env = "gnu")))]
fn trim_heap() {}

/// A client's writer: its queue to its socket, a batch per write; between writes, what the
/// client asks for.
fn write_client(stream: UnixStream, queue: &Queue) {
    let _leaving = Leaving(queue);
    // Reads only take the client's requests and see whether it is still there, after a poll
    // said there is something; the receive timeout leaves writes blocking, so a client that
    // stops reading blocks only this thread.
    if stream.set_read_timeout(Some(Duration::from_millis(1))).is_err() {
        return;
    }
    let connected = std::time::Instant::now();
    let mut requests = Requests::default();
    let mut out = BufWriter::with_capacity(16 * 1024, &stream);
    let mut batch: Vec<Arc<str>> = Vec::with_capacity(BATCH);
    loop {
        {
            let mut q = lock(&queue.state);
            while q.lines.is_empty() {
                q.waiting = true;
                let check = if !q.head && connected.elapsed() < ASK_WINDOW {
                    ASK_CHECK
                } else {
                    IDLE_CHECK
                };
                let (guard, wait) = queue.wake.wait_timeout(q, check).unwrap_or_else(|e| e.into_inner());
                q = guard;
                q.waiting = false;
                if wait.timed_out() && q.lines.is_empty() {
                    drop(q);
                    if requests.read(&stream) {
                        return;
                    }
                    q = lock(&queue.state);
                    q.head |= requests.head();
                }
            }
            let mut bytes = 0;
            while batch.len() < BATCH && bytes < BATCH_BYTES {
                let Some(line) = q.lines.pop_front() else { break };
                bytes += line.len();
                batch.push(line);
            }
            q.bytes -= bytes;
            // A queue that filled keeps its buffer's size once drained: give it back.
            if q.lines.is_empty() && q.lines.capacity() > 4 * BATCH {
                q.lines.shrink_to(BATCH);
            }
        }
        for line in batch.drain(..) {
            if out.write_all(line.as_bytes()).is_err() {
                return;
            }
        }
        if out.flush().is_err() {
            return;
        }
        // Once it asked there is nothing more to ask for: no more reads while the pen moves.
        if !requests.head() {
            if requests.read(&stream) {
                return;
            }
            if requests.head() {
                lock(&queue.state).head = true;
            }
        }
    }
}

/// Binds the socket at `path`, owner-only from the start, replacing only a dead socket
/// (`socket` says what is checked). At the default path the directory is pend's own and must be
/// private to this user.
pub fn bind(path: &Path) -> Result<socket::Bound, SocketError> {
    socket::bind(path, path == default_socket())
}

/// Accepts clients until `stop` is set; the socket's lock is held until then.
pub fn accept(bound: socket::Bound, hub: Arc<Hub>, queue_len: usize, stop: Arc<AtomicBool>) {
    accept_each(&bound, &stop, |stream| {
        hub.connect(stream, queue_len);
    });
}

/// Polls `bound`'s listener until `stop` is set, handing each client's stream, made blocking, to
/// `each`. Writes block: a client that stops reading blocks only its own writer.
fn accept_each(bound: &socket::Bound, stop: &AtomicBool, mut each: impl FnMut(UnixStream)) {
    let listener = &bound.listener;
    if listener.set_nonblocking(true).is_err() {
        return;
    }
    while !stop.load(Ordering::Relaxed) {
        match listener.accept() {
            Ok((stream, _)) => {
                if stream.set_nonblocking(false).is_ok() {
                    each(stream);
                }
            }
            Err(_) => std::thread::sleep(Duration::from_millis(20)),
        }
    }
}

/// Reads the device and publishes its events until `stop` is set.
pub fn run_device(pipeline: Pipeline, hub: Arc<Hub>, stop: Arc<AtomicBool>, log: impl Fn(&str)) {
    run_device_with(pipeline, hub, stop, log, |_| {})
}

/// [`run_device`], with `each` called with every event after it is published (the virtual
/// tablet follows them so).
pub fn run_device_with(
    pipeline: Pipeline,
    hub: Arc<Hub>,
    stop: Arc<AtomicBool>,
    log: impl Fn(&str),
    each: impl FnMut(&PenEvent),
) {
    let (_none, reloads) = std::sync::mpsc::channel();
    run_device_reloading(pipeline, hub, stop, log, each, &reloads)
}

/// [`run_device_with`], taking each calibration sent on `reloads` between polls (pend's SIGHUP)
/// and logging whether it was taken.
pub fn run_device_reloading(
    mut pipeline: Pipeline,
    hub: Arc<Hub>,
    stop: Arc<AtomicBool>,
    log: impl Fn(&str),
    mut each: impl FnMut(&PenEvent),
    reloads: &std::sync::mpsc::Receiver<(Calibration, String)>,
) {
    let mut events = Vec::new();
    while !stop.load(Ordering::Relaxed) {
        while let Ok((calibration, what)) = reloads.try_recv() {
            match pipeline.set_calibration(calibration) {
                Ok(()) => log(&format!("SIGHUP: reloaded: {what}")),
                Err(e) => log(&format!("SIGHUP: kept the calibration in use, not {what}: {e}")),
            }
        }
        poll_logged(&mut pipeline, &mut events, true, &log);
        for e in &events {
            hub.publish(e);
            each(e);
        }
    }
}

/// One poll of `pipeline` into `events` (cleared first): the pipeline's notice logged, and each
/// device loss (and, with `found`, each attach) in the order they came.
fn poll_logged(pipeline: &mut Pipeline, events: &mut Vec<PenEvent>, found: bool, log: &impl Fn(&str)) {
    events.clear();
    pipeline.poll(Duration::from_millis(50), events);
    if let Some(notice) = pipeline.take_notice() {
        log(&notice);
    }
    for e in events.iter() {
        match &e.kind {
            EventKind::DeviceFound { device } if found => log(&format!("attached {device}")),
            EventKind::DeviceLost { reason } => log(&format!("device lost ({reason}); waiting for it")),
            _ => {}
        }
    }
}

/// The calibration the simulated pen's sessions take ([`run_session`]): set again at SIGHUP,
/// numbered so that each session takes each one once.
pub struct CurrentCalibration {
    inner: Mutex<(u64, Calibration, String)>,
}

impl CurrentCalibration {
    /// `calibration`, described by `what`, as the first.
    pub fn new(calibration: Calibration, what: String) -> CurrentCalibration {
        CurrentCalibration {
            inner: Mutex::new((0, calibration, what)),
        }
    }

    /// Replaces the calibration: running sessions take it between polls, new ones start with it.
    pub fn set(&self, calibration: Calibration, what: String) {
        let mut inner = lock(&self.inner);
        let n = inner.0 + 1;
        *inner = (n, calibration, what);
    }

    /// The calibration now, its number and what it is.
    pub fn get(&self) -> (u64, Calibration, String) {
        lock(&self.inner).clone()
    }
}

/// The simulated pen's clients (`pend --source sim`), each served by a session of its own from
/// the scenario's start: a hub with that client alone, fed by its own device thread.
pub struct Sessions {
    /// Only refuses: a client beyond the limit is told so by it.
    gate: Hub,
    live: Mutex<Vec<Arc<Hub>>>,
    started: AtomicU64,
    /// Events delivered and missed in sessions that have ended.
    ended: Mutex<(u64, u64)>,
}

impl Sessions {
    /// At most `max_clients` sessions at once (at least one).
    pub fn new(max_clients: usize) -> Sessions {
        Sessions {
            gate: Hub::new(max_clients),
            live: Mutex::new(Vec::new()),
            started: AtomicU64::new(0),
            ended: Mutex::new((0, 0)),
        }
    }

    /// Sessions whose client is still connected.
    pub fn clients(&self) -> usize {
        let mut live = lock(&self.live);
        let mut ended = lock(&self.ended);
        live.retain(|hub| {
            let here = hub.clients() > 0;
            if !here {
                let (d, m) = hub.counts();
                ended.0 += d;
                ended.1 += m;
            }
            here
        });
        live.len()
    }

    /// Sessions started so far.
    pub fn started(&self) -> u64 {
        self.started.load(Ordering::Relaxed)
    }

    /// Events delivered and missed, over every session.
    pub fn counts(&self) -> (u64, u64) {
        let live = lock(&self.live);
        let ended = lock(&self.ended);
        live.iter().fold(*ended, |(d, m), hub| {
            let (hd, hm) = hub.counts();
            (d + hd, m + hm)
        })
    }

    /// Clients refused because `max_clients` sessions were running.
    pub fn refused(&self) -> u64 {
        self.gate.refused()
    }

    /// The most sessions at once.
    pub fn max_clients(&self) -> usize {
        self.gate.max_clients()
    }

    /// Takes a connected client: refused beyond the limit, else given a hub of its own (the
    /// greeting queued), which is returned with the session's number (from 1).
    fn take(&self, stream: UnixStream, queue_len: usize) -> Option<(Arc<Hub>, u64)> {
        if self.clients() >= self.gate.max_clients() {
            self.gate.refuse(stream);
            return None;
        }
        let hub = Arc::new(Hub::new(1));
        if !hub.connect(stream, queue_len) {
            return None;
        }
        lock(&self.live).push(hub.clone());
        Some((hub, self.started.fetch_add(1, Ordering::Relaxed) + 1))
    }
}

/// Accepts clients until `stop` is set, each served by a session of its own: `start(hub, n)`
/// is called with the client's hub (the client connected to it) and the session's number, and
/// must return at once — it starts the session's device thread, which runs [`run_session`].
pub fn accept_sessions(
    bound: socket::Bound,
    sessions: Arc<Sessions>,
    queue_len: usize,
    stop: Arc<AtomicBool>,
    mut start: impl FnMut(Arc<Hub>, u64),
) {
    accept_each(&bound, &stop, |stream| {
        if let Some((hub, n)) = sessions.take(stream, queue_len) {
            start(hub, n);
        }
    });
}

/// One client's session: reads `pipeline` (opened for it, so the simulated pen starts its
/// scenario) and publishes its events to `hub` until its client has left or `stop` is set,
/// taking each newer calibration from `current` between polls.
pub fn run_session(
    mut pipeline: Pipeline,
    hub: Arc<Hub>,
    stop: Arc<AtomicBool>,
    current: &CurrentCalibration,
    taken: u64,
    log: impl Fn(&str),
) {
    let mut taken = taken;
    let mut events = Vec::new();
    while !stop.load(Ordering::Relaxed) && hub.clients() > 0 {
        let (n, calibration, what) = current.get();
        if n != taken {
            taken = n;
            if let Err(e) = pipeline.set_calibration(calibration) {
                log(&format!("SIGHUP: kept the calibration in use, not {what}: {e}"));
            }
        }
        poll_logged(&mut pipeline, &mut events, false, &log);
        for e in &events {
            hub.publish(e);
        }
    }
}

/// Opens `pipeline`'s device once, before any client, and says what pend would serve: that it
/// attached (the device's name), or why it is refused (a calibration for another base station).
/// Gives up after `within`.
pub fn probe(mut pipeline: Pipeline, within: Duration, log: impl Fn(&str)) {
    let end = std::time::Instant::now() + within;
    let mut events = Vec::new();
    while std::time::Instant::now() < end {
        poll_logged(&mut pipeline, &mut events, true, &log);
        if events.iter().any(|e| matches!(e.kind, EventKind::DeviceFound { .. })) || pipeline.refused().is_some() {
            return;
        }
    }
}
