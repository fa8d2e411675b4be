//! The pen as a real kernel sees it: Debian's kernel in QEMU (hil-tests/kernel), the descriptor
//! and the firmware core's reports through uhid, evdev read back; `pend --source hid` on the
//! hidraw node with the device destroyed mid-stroke and created again; `pend --virtual-tablet`
//! refused where /dev/uinput is not there, then read back through evdev. Skipped with a
//! message where Debian's kernel package cannot be had, except under CI (`CI` set), where that
//! fails.

use std::time::{Duration, Instant};

use pen_kernel::{Accel, Guest, Kernel, Unavailable, boot, build_guest_programs, initramfs};
use pen_sim::{Simulation, scenarios};

/// The simulated pen drawing figures on the reference display, with the base station's USB
/// traffic: each pen report followed by its OS pen report. Each report as a length byte and
/// its bytes.
fn sim_reports() -> (Vec<u8>, usize) {
    let mut s = scenarios::by_name("draw-figures").expect("scenario");
    if let Some(display) = s.config.display.as_mut() {
        // Calibrated onto the 600 × 340 mm display: the OS pen is in range over it.
        display.size_mm = [600.0, 340.0];
    }
    let mut sim = Simulation::new(&s, 43);
    sim.send_os_pen();
    let seconds = s.timeline.duration_s();
    let mut out = Vec::new();
    let mut count = 0;
    for record in sim.run_for(seconds) {
        for sent in record.sent {
            out.push(sent.bytes.len() as u8);
            out.extend_from_slice(&sent.bytes);
            count += 1;
        }
    }
    (out, count)
}

/// The kernel, or why the test is skipped (never under CI: there it must run).
fn kernel_or_skip() -> Option<Kernel> {
    match Kernel::fetch() {
        Ok(k) => Some(k),
        Err(Unavailable(why)) if std::env::var_os("CI").is_some() => {
            panic!("Debian's kernel could not be had under CI: {why}")
        }
        Err(Unavailable(why)) => {
            eprintln!("SKIPPED: the real-kernel test needs Debian's kernel package (apt-get download): {why}");
            None
        }
    }
}

#[test]
fn the_real_kernel_makes_one_pen_and_delivers_every_change_in_order() {
    let Some(kernel) = kernel_or_skip() else {
        return;
    };
    let programs = build_guest_programs().expect("the guest's programs build");
    let (reports, count) = sim_reports();
    let guest = Guest {
        programs,
        data: vec![("reports.bin".into(), reports)],
        steps: vec![
            "/bin/pen-kernel-guest uhid".into(),
            "/bin/pen-kernel-guest pend-hid".into(),
            // Before virtual-tablet: the node it removes is made again, and that step uses it.
            "/bin/pen-kernel-guest uinput-refused".into(),
            "/bin/pen-kernel-guest virtual-tablet".into(),
        ],
    };
    let image = initramfs(&kernel, &guest).expect("initramfs");
    let mut accel = Accel::detect();
    let tried = Instant::now();
    let run = match boot(&kernel, &image, accel, Duration::from_secs(900)) {
        Ok(run) => run,
        // /dev/kvm opened but QEMU could not start the machine with it (a nested KVM): TCG.
        Err(e) if accel == Accel::Kvm => {
            eprintln!(
                "KVM did not start the machine ({e:#}); {:.1} s lost, booting with TCG",
                tried.elapsed().as_secs_f64()
            );
            accel = Accel::Tcg;
            boot(&kernel, &image, accel, Duration::from_secs(900)).expect("the virtual machine runs")
        }
        Err(e) => panic!("the virtual machine runs: {e:#}"),
    };
    eprintln!(
        "kernel {} ({}): booted with {} and powered off in {:.1} s; {count} reports sent",
        kernel.release,
        kernel.package,
        accel.name(),
        run.elapsed.as_secs_f64()
    );
    for line in &run.lines {
        eprintln!("  {line}");
    }
    let loaded: Vec<&str> = run.with("module").collect();
    assert_eq!(
        loaded.len(),
        kernel.modules.len(),
        "modules loaded: {loaded:?}\n{}",
        run.console
    );
    let failed: Vec<&str> = run.with("FAIL").collect();
    assert!(failed.is_empty(), "{failed:?}\n{}", run.console);
    for step in ["uhid:", "pend-hid:", "uinput-refused:", "virtual-tablet:"] {
        assert!(run.with("PASS").any(|l| l.starts_with(step)), "{step}\n{}", run.console);
    }
    // One pen from the uhid device, one virtual tablet.
    assert_eq!(run.with("DEV").count(), 2, "evdev devices");
    assert!(run.finished(), "{}", run.console);
}
