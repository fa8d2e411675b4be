//! pend's socket, as an attacker or a careless user would meet it: it refuses a directory other
//! users control and never deletes a file that is not its own dead socket.

use std::os::unix::fs::PermissionsExt;
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

/// Runs pend with `args` and `XDG_RUNTIME_DIR=runtime`, expecting it to give up by itself; kills
/// it after a generous hang guard.
fn pend_refuses(args: &[&str], runtime: &std::path::Path) -> Output {
    let mut child = Command::new(env!("CARGO_BIN_EXE_pend"))
        .args(args)
        .env("XDG_RUNTIME_DIR", runtime)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("pend starts");
    let start = Instant::now();
    while child.try_wait().expect("waits").is_none() {
        if start.elapsed() > Duration::from_secs(60) {
            let _ = child.kill();
            panic!("pend kept running instead of refusing");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    child.wait_with_output().expect("output")
}

#[test]
fn a_regular_file_at_the_socket_path_is_kept() {
    let tmp = tempfile::tempdir().expect("tempdir");
    let notes = tmp.path().join("notes.txt");
    std::fs::write(&notes, "do not lose me").expect("write");
    let out = pend_refuses(&["--sim", "--socket", notes.to_str().expect("utf-8")], tmp.path());
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("is not a socket"), "{stderr}");
    assert!(stderr.contains("notes.txt"), "{stderr}");
    assert_eq!(std::fs::read_to_string(&notes).expect("still there"), "do not lose me");
}

#[test]
fn a_default_directory_open_to_others_is_refused() {
    let tmp = tempfile::tempdir().expect("tempdir");
    let dir = tmp.path().join("penscape");
    std::fs::create_dir(&dir).expect("mkdir");
    std::fs::set_permissions(&dir, std::fs::Permissions::from_mode(0o777)).expect("chmod");
    let out = pend_refuses(&["--sim"], tmp.path());
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("mode 0777"), "{stderr}");
    assert!(!dir.join("pend.sock").exists(), "nothing bound in it");
}

#[test]
fn a_symlinked_default_directory_is_refused() {
    let tmp = tempfile::tempdir().expect("tempdir");
    let target = tmp.path().join("someone-elses");
    std::fs::create_dir(&target).expect("mkdir");
    std::fs::set_permissions(&target, std::fs::Permissions::from_mode(0o700)).expect("chmod");
    std::os::unix::fs::symlink(&target, tmp.path().join("penscape")).expect("symlink");
    let out = pend_refuses(&["--sim"], tmp.path());
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("symbolic link"), "{stderr}");
    assert!(!target.join("pend.sock").exists());
}
