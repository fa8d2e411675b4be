//! Waiting for a base station that is not there, or not this user's to open: pend and penctl
//! say what they wait for and why, with what to do — at once and then every few seconds, not at
//! every retry (issue 19.3). The real binaries, their stderr and exit status.

use std::io::{BufRead, BufReader};
use std::os::unix::fs::PermissionsExt;
use std::path::Path;
use std::process::{Child, Command, ExitStatus, Output, Stdio};
use std::sync::mpsc;
use std::time::{Duration, Instant};

/// Runs `cmd` until its stderr has shown `n` lines containing `pat` (at most 30 s: a loaded
/// machine may start it slowly; the tests count notices, they do not time them), keeps it
/// running `then` longer, stops it with SIGTERM and returns its exit status and all its
/// stderr.
fn run_until(mut cmd: Command, pat: &str, n: usize, then: Duration) -> (ExitStatus, String) {
    let mut child: Child = cmd
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the program starts");
    let err = child.stderr.take().expect("stderr piped");
    let (tx, rx) = mpsc::channel();
    let reader = std::thread::spawn(move || {
        for line in BufReader::new(err).lines() {
            let Ok(line) = line else { break };
            if tx.send(line).is_err() {
                break;
            }
        }
    });
    let deadline = Instant::now() + Duration::from_secs(30);
    let mut lines = Vec::new();
    while lines_with_in(&lines, pat) < n {
        let left = deadline.saturating_duration_since(Instant::now());
        match rx.recv_timeout(left) {
            Ok(line) => lines.push(line),
            Err(_) => break,
        }
    }
    std::thread::sleep(then);
    let status = Command::new("kill")
        .args(["-TERM", &child.id().to_string()])
        .status()
        .expect("kill");
    assert!(status.success(), "still running");
    let exit = child.wait().expect("it exits");
    reader.join().expect("reader joined");
    lines.extend(rx.try_iter());
    (exit, lines.join("\n"))
}

fn lines_with_in(lines: &[String], pat: &str) -> usize {
    lines.iter().filter(|l| l.contains(pat)).count()
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

fn lines_with(text: &str, pat: &str) -> usize {
    text.lines().filter(|l| l.contains(pat)).count()
}

fn penctl(home: &Path, args: &[&str]) -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_penctl"));
    c.args(args).env("HOME", home).env_remove("XDG_CONFIG_HOME");
    c
}

#[test]
fn penctl_monitor_says_what_it_waits_for_every_few_seconds_not_every_retry() {
    let home = tempfile::tempdir().expect("home");
    let args = ["monitor", "--serial", "/dev/ttyDOESNOTEXIST"];
    // The default interval (5 s): one notice, then none for the next 1.5 s, while it retries
    // every 200 ms.
    let mut default = penctl(home.path(), &args);
    default.env_remove("PENSCAPE_NOTICE_SECS");
    // A short interval: the notice repeats, with the time waited.
    let mut short = penctl(home.path(), &args);
    short.env("PENSCAPE_NOTICE_SECS", "0.3");
    let still_pat = "still waiting for the base station on /dev/ttyDOESNOTEXIST (";
    let t = std::thread::spawn(move || run_until(short, still_pat, 3, Duration::ZERO).1);
    let (_, once) = run_until(default, "waiting for", 1, Duration::from_millis(1500));
    let repeated = t.join().expect("joined");

    assert_eq!(lines_with(&once, "waiting for"), 1, "{once}");
    let first = once.lines().find(|l| l.contains("waiting for")).unwrap_or_default();
    assert!(
        first.starts_with("penctl: waiting for the base station on /dev/ttyDOESNOTEXIST: ")
            && first.contains("No such file or directory")
            && first.contains("is it plugged in?")
            && first.contains("`penctl list`"),
        "{first}"
    );
    // The OS's words once, not twice.
    assert_eq!(first.matches("No such file or directory").count(), 1, "{first}");

    // Three repeats came (run_until waited for them), each with the seconds waited so far,
    // which never go back.
    let waited: Vec<u64> = repeated
        .lines()
        .filter(|l| l.contains(still_pat))
        .filter_map(|l| l.split(still_pat).nth(1)?.split(' ').next()?.parse().ok())
        .collect();
    assert_eq!(
        waited.len(),
        3,
        "a notice every 0.3 s, with the time waited:\n{repeated}"
    );
    assert!(waited.windows(2).all(|w| w[0] <= w[1]), "{repeated}");
    assert_eq!(lines_with(&repeated, "penctl: waiting for"), 1, "{repeated}");
}

#[test]
fn pend_says_what_it_waits_for() {
    let dir = tempfile::tempdir().expect("dir");
    let mut pend = Command::new(env!("CARGO_BIN_EXE_pend"));
    pend.args(["--serial", "/dev/ttyDOESNOTEXIST", "--socket"])
        .arg(dir.path().join("pend.sock"))
        .env("HOME", dir.path())
        .env_remove("XDG_CONFIG_HOME")
        .env("PENSCAPE_NOTICE_SECS", "0.3");
    let (status, err) = run_until(pend, "pend: still waiting for", 2, Duration::ZERO);
    assert_eq!(status.code(), Some(0), "SIGTERM ends pend cleanly: {err}");
    assert_eq!(
        lines_with(
            &err,
            "pend: waiting for the base station on /dev/ttyDOESNOTEXIST: no device found: /dev/ttyDOESNOTEXIST: \
             No such file or directory; is it plugged in?"
        ),
        1,
        "{err}"
    );
    assert!(lines_with(&err, "pend: still waiting for") >= 2, "{err}");
}

#[test]
fn a_missing_hidraw_device_is_named_once() {
    let home = tempfile::tempdir().expect("home");
    let out = penctl(home.path(), &["info", "--hid", "/dev/hidraw-does-not-exist"])
        .output()
        .expect("penctl runs");
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.starts_with(
            "penctl: cannot attach: no device found: /dev/hidraw-does-not-exist: No such file or directory"
        ),
        "{err}"
    );
    assert_eq!(err.matches("No such file or directory").count(), 1, "{err}");
    assert!(err.contains("`penctl list`"), "{err}");
}

/// A device file this user may not open: a file nobody but root may read, opened as a user.
/// As root (who may open anything) the programs run as `nobody` (setpriv), as anyone else
/// the file's mode is 000.
struct Forbidden {
    dir: tempfile::TempDir,
    root: bool,
}

impl Forbidden {
    fn new() -> Forbidden {
        let dir = tempfile::tempdir().expect("dir");
        // The folder is open to all, so only the file's own mode refuses.
        std::fs::set_permissions(dir.path(), std::fs::Permissions::from_mode(0o777)).expect("chmod");
        let file = dir.path().join("ttyFORBIDDEN");
        std::fs::write(&file, b"").expect("file");
        let root = nix::unistd::Uid::effective().is_root();
        let mode = if root { 0o600 } else { 0o000 };
        std::fs::set_permissions(&file, std::fs::Permissions::from_mode(mode)).expect("chmod");
        // pend's socket in a folder of the user's own, closed to others, as pend demands.
        let run = dir.path().join("run");
        std::fs::create_dir(&run).expect("run folder");
        std::fs::set_permissions(&run, std::fs::Permissions::from_mode(0o700)).expect("chmod");
        if root {
            let nobody = Some(nix::unistd::Uid::from_raw(65534));
            nix::unistd::chown(&run, nobody, Some(nix::unistd::Gid::from_raw(65534))).expect("chown");
        }
        Forbidden { dir, root }
    }

    fn path(&self) -> String {
        self.dir.path().join("ttyFORBIDDEN").display().to_string()
    }

    /// `program` with `args`, as a user the file refuses.
    fn command(&self, program: &str, args: &[&str]) -> Command {
        let mut c = if self.root {
            let mut c = Command::new("setpriv");
            c.args(["--reuid=65534", "--regid=65534", "--clear-groups", program]);
            c
        } else {
            Command::new(program)
        };
        c.args(args)
            .env("HOME", self.dir.path())
            .env_remove("XDG_CONFIG_HOME")
            .env("XDG_RUNTIME_DIR", self.dir.path());
        c
    }
}

impl Drop for Forbidden {
    fn drop(&mut self) {
        // Let the temporary folder go, whatever the mode left.
        let _ = std::fs::set_permissions(
            self.dir.path().join("ttyFORBIDDEN"),
            std::fs::Permissions::from_mode(0o600),
        );
    }
}

/// The fix named with a permission error: the udev rules and a group to join.
fn says_how_to_get_access(err: &str) {
    assert!(err.contains("Permission denied"), "{err}");
    assert!(err.contains("host-driver/udev/70-penscape.rules"), "{err}");
    assert!(err.contains("sudo usermod -aG"), "{err}");
    assert!(err.contains("log in again"), "{err}");
}

#[test]
fn permission_denied_is_shown_with_the_fix() {
    let f = Forbidden::new();
    let path = f.path();

    // At once, where the tool gives up after a moment.
    let out = f
        .command(env!("CARGO_BIN_EXE_penctl"), &["info", "--serial", &path])
        .output()
        .expect("penctl runs");
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.starts_with(&format!(
            "penctl: cannot attach: cannot open {path}: Permission denied; "
        )),
        "{err}"
    );
    says_how_to_get_access(&err);

    // While waiting, HID as serial.
    let mut monitor = f.command(env!("CARGO_BIN_EXE_penctl"), &["monitor", "--hid", &path]);
    monitor.env("PENSCAPE_NOTICE_SECS", "5");
    let (_, err) = run_until(monitor, "waiting for", 1, Duration::from_millis(300));
    assert_eq!(lines_with(&err, "waiting for"), 1, "{err}");
    assert!(
        err.starts_with(&format!(
            "penctl: waiting for the base station at {path}: cannot open {path}: Permission denied; "
        )),
        "{err}"
    );
    says_how_to_get_access(&err);

    let socket = f.dir.path().join("run/pend.sock").display().to_string();
    let pend = f.command(env!("CARGO_BIN_EXE_pend"), &["--serial", &path, "--socket", &socket]);
    let (_, err) = run_until(pend, "pend: waiting for", 1, Duration::ZERO);
    assert!(
        err.contains(&format!(
            "pend: waiting for the base station on {path}: cannot open {path}: Permission denied; "
        )),
        "{err}"
    );
    says_how_to_get_access(&err);
}

/// The first `n` notices a session gives (at most 30 s: a loaded machine may be slow; the
/// test checks the spacing, a lower bound, not how many fit in a time), each with when it
/// came and how many calls to `next` it took.
fn notices(device: &mut pen_host::device::Device, n: usize) -> Vec<(Duration, usize, String)> {
    use pen_host::device::DeviceEvent;
    let start = Instant::now();
    let mut said = Vec::new();
    let mut calls = 0;
    while said.len() < n {
        assert!(start.elapsed() < Duration::from_secs(30), "only {said:?}");
        calls += 1;
        match device.next(Duration::from_millis(20)) {
            Some(DeviceEvent::Waiting(m)) => said.push((start.elapsed(), calls, m)),
            Some(DeviceEvent::Found(_)) => said.push((start.elapsed(), calls, "found".into())),
            _ => {}
        }
    }
    said
}

#[test]
fn a_session_says_it_waits_at_once_then_every_interval_and_after_a_loss_only_later() {
    use pen_host::device::{Device, DeviceEvent, RETRY_EVERY};
    use pen_host::source::Source;
    use pen_host::transport::sim::{SimOptions, SimPlug};

    let plug = SimPlug::default();
    plug.set(false);
    let options = SimOptions {
        scenario: pen_sim::scenarios::by_name("hold").expect("hold"),
        seed: 1,
        speed: 0.0,
        plug: plug.clone(),
    };
    let every = Duration::from_millis(500);
    let mut device = Device::new(Source::Sim(options)).with_notice_every(every);

    let said = notices(&mut device, 3);
    assert!(RETRY_EVERY < every);
    assert_eq!(said[0].1, 1, "the first at once: {said:?}");
    assert_eq!(
        said[0].2,
        "waiting for the simulated pen: no device found: the simulated pen is unplugged"
    );
    for (at, _, m) in &said[1..] {
        assert!(m.starts_with("still waiting for the simulated pen ("), "{m}");
        assert!(*at >= every, "{at:?}: {m}");
    }
    // Not at every retry (every 200 ms) but at most once an interval.
    for pair in said.windows(2) {
        assert!(pair[1].0 - pair[0].0 >= every - Duration::from_millis(30), "{said:?}");
    }

    // Plugged in: found; unplugged: lost, which says it waits; the next notice only after
    // the interval, and as "still waiting".
    plug.set(true);
    let found = notices(&mut device, 1);
    assert_eq!(found[0].2, "found", "{found:?}");
    plug.set(false);
    let guard = Instant::now() + Duration::from_secs(10);
    let lost = loop {
        if let Some(DeviceEvent::Lost(why)) = device.next(Duration::from_millis(50)) {
            break why;
        }
        assert!(Instant::now() < guard, "the unplugging was never noticed");
    };
    assert_eq!(lost, "unplugged");
    let said = notices(&mut device, 1);
    assert!(
        said[0].0 >= every - Duration::from_millis(30),
        "not at once after the loss: {said:?}"
    );
    assert!(said[0].2.starts_with("still waiting for the simulated pen"), "{said:?}");
}
