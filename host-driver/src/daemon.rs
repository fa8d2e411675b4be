//! `pend`: one process owns the device and serves its events to any number of clients on a Unix
//! domain socket, as JSON lines (docs/events.md).
//!
//! The device is read on its own thread and every event is encoded once and offered to each
//! client's bounded queue. A client that does not keep up loses events from its own queue only —
//! counted, and announced to it with a `missed` event as soon as it reads again — and never slows
//! the device reader or the other clients, each of which has its own writer thread.

use std::io::{BufWriter, Write};
use std::os::unix::net::{UnixListener, UnixStream};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::mpsc::{Receiver, SyncSender, TrySendError, sync_channel};
use std::sync::{Arc, Mutex};
use std::time::Duration;

use crate::events::{EventKind, PenEvent};
use crate::pipeline::Pipeline;
use crate::sample::now_us;
use crate::socket::{self, SocketError};

use crate::wire::{self, Hello, SocketLine};

/// Events a client may have queued before it starts missing them: about a second at 1 kHz.
pub const DEFAULT_QUEUE: usize = 1024;

/// The default socket: `$XDG_RUNTIME_DIR/penscape/pend.sock`, or `/tmp/penscape-UID/pend.sock`.
pub fn default_socket() -> PathBuf {
    socket::default_path()
}

struct Client {
    queue: SyncSender<Arc<str>>,
    missed: Arc<AtomicU64>,
}

/// The clients and the device's state, shared by the device thread and the acceptor.
#[derive(Default)]
pub struct Hub {
    clients: Mutex<Vec<Client>>,
    device: Mutex<Option<String>>,
    delivered: AtomicU64,
    missed: AtomicU64,
}

impl Hub {
    /// Offers one event to every client.
    pub fn publish(&self, event: &PenEvent) {
        match &event.kind {
            EventKind::DeviceFound { device } => *lock(&self.device) = Some(device.clone()),
            EventKind::DeviceLost { .. } => *lock(&self.device) = None,
            _ => {}
        }
        let line: Arc<str> = Arc::from(wire::line(event));
        let mut clients = lock(&self.clients);
        clients.retain(|c| match c.queue.try_send(line.clone()) {
            Ok(()) => {
                self.delivered.fetch_add(1, Ordering::Relaxed);
                true
            }
            Err(TrySendError::Full(_)) => {
                c.missed.fetch_add(1, Ordering::Relaxed);
                self.missed.fetch_add(1, Ordering::Relaxed);
                true
            }
            Err(TrySendError::Disconnected(_)) => false,
        });
    }

    /// Clients connected.
    pub fn clients(&self) -> usize {
        lock(&self.clients).len()
    }

    /// Events queued for clients, and events clients missed, since the start.
    pub fn counts(&self) -> (u64, u64) {
        (
            self.delivered.load(Ordering::Relaxed),
            self.missed.load(Ordering::Relaxed),
        )
    }

    /// Serves a connected client: greets it, then writes events to it from its own thread, its
    /// queue holding at most `queue_len`.
    pub fn connect(&self, stream: UnixStream, queue_len: usize) {
        let (tx, rx) = sync_channel(queue_len.max(1));
        let missed = Arc::new(AtomicU64::new(0));
        let device = lock(&self.device).clone();
        let hello = SocketLine::Hello(Hello::new(now_us(), device)).to_text();
        let client_missed = missed.clone();
        std::thread::spawn(move || write_client(stream, rx, client_missed, &hello));
        lock(&self.clients).push(Client { queue: tx, missed });
    }
}

/// A poisoned lock only means another thread panicked mid-update of a list we can still use.
fn lock<T>(m: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|e| e.into_inner())
}

/// A client's writer: its queue to its socket, announcing what it missed.
fn write_client(stream: UnixStream, rx: Receiver<Arc<str>>, missed: Arc<AtomicU64>, hello: &str) {
    let mut out = BufWriter::new(stream);
    if out.write_all(hello.as_bytes()).and_then(|()| out.flush()).is_err() {
        return;
    }
    while let Ok(line) = rx.recv() {
        let lost = missed.swap(0, Ordering::Relaxed);
        if lost > 0 {
            let notice = wire::line(&PenEvent::missed(lost, now_us()));
            if out.write_all(notice.as_bytes()).is_err() {
                return;
            }
        }
        // Flush only when nothing else is waiting: a burst goes out in one write.
        let result = out.write_all(line.as_bytes()).and_then(|()| match rx.try_recv() {
            Ok(next) => out.write_all(next.as_bytes()).and_then(|()| out.flush()),
            Err(_) => out.flush(),
        });
        if result.is_err() {
            return;
        }
    }
}

/// Binds the socket at `path`, owner-only from the start, replacing only a dead socket
/// (`socket` says what is checked). At the default path the directory is pend's own and must be
/// private to this user.
pub fn bind(path: &Path) -> Result<UnixListener, SocketError> {
    socket::bind(path, path == default_socket())
}

/// Accepts clients until `stop` is set.
pub fn accept(listener: UnixListener, hub: Arc<Hub>, queue_len: usize, stop: Arc<AtomicBool>) {
    if listener.set_nonblocking(true).is_err() {
        return;
    }
    while !stop.load(Ordering::Relaxed) {
        match listener.accept() {
            Ok((stream, _)) => {
                // Writes block: a client that stops reading blocks only its own writer.
                if stream.set_nonblocking(false).is_ok() {
                    hub.connect(stream, queue_len);
                }
            }
            Err(_) => std::thread::sleep(Duration::from_millis(20)),
        }
    }
}

/// Reads the device and publishes its events until `stop` is set.
pub fn run_device(mut pipeline: Pipeline, hub: Arc<Hub>, stop: Arc<AtomicBool>, log: impl Fn(&str)) {
    let mut events = Vec::new();
    while !stop.load(Ordering::Relaxed) {
        events.clear();
        pipeline.poll(Duration::from_millis(50), &mut events);
        for e in &events {
            match &e.kind {
                EventKind::DeviceFound { device } => log(&format!("attached {device}")),
                EventKind::DeviceLost { reason } => log(&format!("device lost ({reason}); waiting for it")),
                _ => {}
            }
            hub.publish(e);
        }
    }
}
