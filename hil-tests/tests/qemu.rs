//! The firmware core compiled for thumbv7em-none-eabihf and run on QEMU's Cortex-M4F
//! (mps2-an386), fed the cycles a simulation recorded: its reports must be bit-identical to the
//! host build's. The core uses only correctly rounded arithmetic (+, −, ×, ÷, √) in a fixed
//! order, so bit-identical is the claim, not a tolerance.

use std::time::Duration;

use pen_hil::qemu;
use pen_sim::{Sent, Simulation, scenarios};

#[test]
fn the_emulated_core_sends_the_host_builds_reports() {
    let elf = qemu::build_pen_qemu().expect("pen-qemu builds");
    for (name, seconds) in [
        ("hand-sweep", 4.0),
        ("echoes", 4.0),
        ("draw-figures", 4.0),
        ("viewer", 4.0),
    ] {
        let s = scenarios::by_name(name).expect("scenario");
        let mut sim = Simulation::new(&s, 11);
        let records = sim.run_for(seconds);
        let host: Vec<Sent> = records.iter().flat_map(|r| r.sent.clone()).collect();
        let run = qemu::run(
            &elf,
            &qemu::replay(&s.config, s.head, &records),
            Duration::from_secs(300),
        )
        .unwrap_or_else(|e| panic!("{name}: {e}"));
        // Started as the ROM DFU bootloader starts an image (VTOR at its own table): the reset
        // handler took VTOR back before main pended an exception, which ran the image's handler.
        let (vtor, table, taken) = run.vector_table.expect("pen-qemu reports its vector table");
        assert_eq!(
            vtor, table,
            "{name}: VTOR {vtor:#x} is not the image's table {table:#x}"
        );
        assert!(taken, "{name}: the exception pended in main did not run");
        assert_eq!(run.cycles as usize, records.len(), "{name}: cycles replayed");
        assert_eq!(run.reports.len(), host.len(), "{name}: report count");
        if let Some(i) = host.iter().zip(&run.reports).position(|(a, b)| a != b) {
            panic!(
                "{name}: report {i} differs: host {:?}, emulated {:?}",
                host[i], run.reports[i]
            );
        }
        // The calibration loop ran: SysTick counts 40 instructions each under -icount 0 (a
        // 1 GHz virtual clock, SysTick at the board's 25 MHz).
        assert!(
            (run.instructions_per_count() - 40.0).abs() < 0.5,
            "{}",
            run.instructions_per_count()
        );
        eprintln!(
            "{name}: {} cycles, {} reports identical; fusion {:.0} instructions per cycle on average, {:.0} at most",
            run.cycles,
            run.reports.len(),
            run.mean_instructions(),
            run.worst_instructions()
        );
    }
}

/// The stack guard: the stack sits at the bottom of RAM (pen-qemu's layout is the board's,
/// firmware/stm32f411ce.x), so running it out faults instead of overwriting the statics, and the
/// board's own HardFault vector (firmware/src/hard_fault.rs) runs its handler on a fresh stack.
#[test]
fn a_stack_overflow_faults_into_the_handler_and_spares_the_statics() {
    let elf = qemu::build_pen_qemu().expect("pen-qemu builds");
    let fault = qemu::run_stack_overflow(&elf, Duration::from_secs(60)).expect("the overflow is caught");
    assert!(
        fault.stack_pointer < 0x2000_0000,
        "the fault came at {:#x}, not past the bottom of RAM",
        fault.stack_pointer
    );
    assert_ne!(fault.cfsr, 0, "no fault status recorded");
    assert_eq!(fault.canary, qemu::CANARY, "the overflow reached the statics");
}

/// Writes the replay fuzz target's seeds from real traffic: the cycles the simulated pen records
/// (capture times with the acoustics' noise, echoes and dropouts, switch samples), as the QEMU
/// replay format, into `firmware/core/fuzz/corpus/replay/sim-*` (docs/reliability.md). Run once
/// when the format or the scenarios change: `cargo test -p pen-hil --test main
/// write_replay_seeds -- --ignored`; the stable corpus test then replays them.
#[test]
#[ignore]
fn write_replay_seeds() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../firmware/core/fuzz/corpus/replay");
    // Half a second each: enough cycles to reach the solver and the tracker, small enough that
    // the corpus replays in seconds.
    for (name, seed) in [
        ("hand-sweep", 1),
        ("echoes", 2),
        ("draw-figures", 3),
        ("dead-receiver", 4),
        // Replay format 3: the glasses' slots among the pen's, the head's own filter.
        ("viewer", 5),
    ] {
        let s = scenarios::by_name(name).expect("scenario");
        let records = Simulation::new(&s, seed).run_for(0.5);
        let bytes = qemu::replay(&s.config, s.head, &records);
        std::fs::write(dir.join(format!("sim-{name}")), &bytes).expect("write a seed");
        eprintln!("sim-{name}: {} cycles, {} bytes", records.len(), bytes.len());
    }
}

/// Issue 42: a `pen-sim` copied away from the sources it was built from cannot build the
/// firmware: it says how to give the image instead of failing inside cargo.
#[test]
fn without_the_firmwares_sources_qemu_says_how_to_give_the_image() {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_pen-sim"))
        .args(["qemu", "--seconds", "0.1"])
        .env("PEN_FIRMWARE_DIR", "/nonexistent/firmware")
        .output()
        .expect("pen-sim runs");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("/nonexistent/firmware") && stderr.contains("--elf FILE"),
        "{stderr}"
    );
    assert!(!stderr.contains("panicked"), "{stderr}");
}
