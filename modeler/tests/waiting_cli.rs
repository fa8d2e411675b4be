//! `penmodel` with a pen that does not come (issue 19.3): it says what it waits for and why, and
//! a session stopped or failed before anything was modeled writes nothing and exits 1.

use std::io::Write;
use std::os::unix::net::UnixListener;
use std::path::Path;
use std::process::{Command, Output, Stdio};
use std::time::Duration;

use pen_host::wire::{Refused, SocketLine};

fn penmodel(dir: &Path, args: &[&str]) -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_penmodel"));
    c.current_dir(dir)
        .args(["--show", "headless"])
        .args(args)
        .env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY")
        .env("XDG_RUNTIME_DIR", dir)
        .env("HOME", dir)
        .env_remove("XDG_CONFIG_HOME")
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    c
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

#[test]
fn waiting_for_a_device_is_said_and_a_stop_writes_nothing() {
    let dir = tempfile::tempdir().expect("dir");
    let child = penmodel(dir.path(), &["--source", "serial:/dev/ttyDOESNOTEXIST", "--out", "run"])
        .env("PENSCAPE_NOTICE_SECS", "0.3")
        .spawn()
        .expect("penmodel starts");
    std::thread::sleep(Duration::from_millis(1500));
    let status = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .expect("kill");
    assert!(status.success(), "penmodel ended by itself");
    let out = child.wait_with_output().expect("penmodel exits");
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains(
            "penmodel: waiting for the base station on /dev/ttyDOESNOTEXIST: no device found: /dev/ttyDOESNOTEXIST: \
             No such file or directory; is it plugged in?"
        ),
        "{err}"
    );
    let still = err
        .matches("penmodel: still waiting for the base station on /dev/ttyDOESNOTEXIST (")
        .count();
    assert!((2..=5).contains(&still), "a notice every 0.3 s:\n{err}");
    assert!(
        err.trim_end()
            .ends_with("penmodel: stopped before anything was modeled: nothing written"),
        "{err}"
    );
    assert!(out.stdout.is_empty(), "no summary of nothing");
    assert!(
        !dir.path().join("run").exists(),
        "the --out folder it made is gone again"
    );
}

#[test]
fn without_pend_the_daemon_source_says_to_start_it_and_writes_nothing() {
    let dir = tempfile::tempdir().expect("dir");
    // A folder that was there stays, empty.
    std::fs::create_dir(dir.path().join("mine")).expect("folder");
    let out = penmodel(dir.path(), &["--source", "daemon", "--out", "mine"])
        .output()
        .expect("penmodel runs");
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{err}");
    let socket = dir.path().join("penscape/pend.sock");
    assert!(
        err.contains(&format!(
            "penmodel: the pen failed: pend is not running (nothing listens at {}): start it (`pend`",
            socket.display()
        )),
        "{err}"
    );
    assert!(err.contains("nothing modeled, nothing written"), "{err}");
    assert_eq!(err.matches("pend is not running").count(), 1, "said once: {err}");
    let left: Vec<_> = std::fs::read_dir(dir.path().join("mine"))
        .expect("still there")
        .collect();
    assert!(left.is_empty(), "nothing written: {left:?}");
}

#[test]
fn a_client_pend_refuses_is_told_why_and_writes_nothing() {
    let dir = tempfile::tempdir().expect("dir");
    let socket = dir.path().join("full.sock");
    let listener = UnixListener::bind(&socket).expect("bind");
    // pend with all its places taken: the refusal line, then the connection closes.
    let server = std::thread::spawn(move || {
        let (mut stream, _) = listener.accept().expect("accept");
        let reason = "pend serves at most 1 clients at once (pend --max-clients); try again when one has left";
        let line = SocketLine::Refused(Refused::new(1_000_000, reason.into())).to_text();
        stream.write_all(line.as_bytes()).expect("write");
    });
    let source = format!("daemon:{}", socket.display());
    let out = penmodel(dir.path(), &["--source", &source, "--out", "run"])
        .output()
        .expect("penmodel runs");
    server.join().expect("served");
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains(
            "penmodel: the pen failed: pend refused this client: pend serves at most 1 clients at once \
             (pend --max-clients); try again when one has left; nothing modeled, nothing written"
        ),
        "{err}"
    );
    assert!(!err.contains("pend socket: pend socket"), "{err}");
    assert!(!dir.path().join("run").exists());
}

#[test]
fn a_document_that_cannot_be_created_leaves_no_folder_behind() {
    let dir = tempfile::tempdir().expect("dir");
    let out = penmodel(
        dir.path(),
        &["--source", "sim", "--doc", "missing/d.json", "--out", "run"],
    )
    .output()
    .expect("penmodel runs");
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("cannot write missing/d.json"), "{err}");
    assert_eq!(err.matches("os error 2").count(), 1, "{err}");
    assert!(!dir.path().join("run").exists(), "the --out folder made for it is gone");
}
