//! What several test modules share: pend started on a socket and stopped however a test ends.

use std::os::unix::net::UnixStream;
use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// A hang guard only: a loaded machine is slow, never this slow.
pub const GUARD: Duration = Duration::from_secs(60);

/// The pend binary running; killed when the test ends, however it ends.
pub struct Pend(pub Child);

impl Drop for Pend {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// Starts pend with `args` on `socket` and waits until it listens there.
pub fn start_pend(socket: &Path, args: &[&str]) -> Pend {
    let child = Command::new(env!("CARGO_BIN_EXE_pend"))
        .args(args)
        .arg("--socket")
        .arg(socket)
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .expect("pend starts");
    let end = Instant::now() + GUARD;
    while UnixStream::connect(socket).is_err() {
        assert!(Instant::now() < end, "pend did not listen");
        std::thread::sleep(Duration::from_millis(20));
    }
    Pend(child)
}
