//! The firmware core on QEMU's Cortex-M4F (`mps2-an386`), fed recorded cycles.
//!
//! A simulation records what the core was given — each cycle's captures and every switch
//! sample — as a replay file. `pen-qemu` (firmware/qemu), pen-core compiled for
//! `thumbv7em-none-eabihf`, replays it through the same station loop under QEMU and prints the
//! reports it sends; they are compared with the reports of the host build. It then times the
//! fusion of each cycle with SysTick under `-icount shift=0`, where virtual time counts
//! instructions.
//!
//! The replay format is `pen_core::replay`, which both this writer and `pen-qemu`'s reader use.

use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use pen_core::{HeadSettings, replay};
use pen_protocol::Config;
use thiserror::Error;

use pen_sim::sim::{CycleRecord, Sent};

/// Why the emulated run failed.
#[derive(Debug, Error)]
pub enum QemuError {
    /// A program could not be started.
    #[error("cannot run {program}: {source} (the test set-up installs qemu-system-arm; see README)")]
    Spawn {
        /// The program.
        program: String,
        /// Why.
        source: std::io::Error,
    },
    /// Building `pen-qemu` failed.
    #[error("building pen-qemu failed:\n{0}")]
    Build(String),
    /// The firmware's sources are not where this program was built from.
    #[error(
        "the firmware's sources are not at {0} (this program was built elsewhere): give the image with \
         --elf FILE (build it in the repository's firmware/ with `cargo build --release -p pen-qemu`), \
         or set PEN_FIRMWARE_DIR to the firmware folder"
    )]
    NoFirmware(PathBuf),
    /// QEMU did not finish in time.
    #[error("QEMU did not finish within {0:?}")]
    Timeout(Duration),
    /// The emulated program reported a failure or printed something unexpected.
    #[error("the emulated core failed: {0}")]
    Emulated(String),
    /// Files could not be written or read.
    #[error("i/o: {0}")]
    Io(std::io::Error),
}

// Not `#[from]`: that would make the error its source too, and a chain (`{:#}`) would say it
// twice.
impl From<std::io::Error> for QemuError {
    fn from(e: std::io::Error) -> QemuError {
        QemuError::Io(e)
    }
}

/// The replay file for `records`, run with `config` and, when it tracked the head from the
/// start, `head` (the scenario's).
pub fn replay(config: &Config, head: Option<HeadSettings>, records: &[CycleRecord]) -> Vec<u8> {
    let mut out = Vec::new();
    let mut push = |bytes: &[u8]| out.extend_from_slice(bytes);
    let header = replay::Header::new(*config, head);
    replay::write_header(&header, &mut push);
    for r in records {
        replay::write_cycle(
            &header,
            r.emitter,
            r.t0_us,
            &r.heard.arrival_ns,
            &r.switch_samples,
            &mut push,
        );
    }
    out
}

/// What the emulated core printed.
#[derive(Debug, Clone, PartialEq)]
pub struct QemuRun {
    /// The reports, in order.
    pub reports: Vec<Sent>,
    /// Cycles replayed through the station.
    pub cycles: u32,
    /// Cycles timed in the fusion pass.
    pub timed: u32,
    /// SysTick counts over all timed cycles.
    pub total_counts: u64,
    /// The most SysTick counts of one cycle.
    pub worst_counts: u32,
    /// Calibration: instructions executed and the SysTick counts they took.
    pub calibration: (u64, u32),
    /// After a jump to the reset vector with VTOR at a foreign table (as the ROM DFU bootloader
    /// leaves it): VTOR as `main` found it, the image's vector table, and whether an exception
    /// pended in `main` ran the image's handler.
    pub vector_table: Option<(u32, u32, bool)>,
}

impl QemuRun {
    /// Instructions per SysTick count, from the calibration loop.
    pub fn instructions_per_count(&self) -> f64 {
        self.calibration.0 as f64 / self.calibration.1.max(1) as f64
    }

    /// Mean instructions of one cycle's fusion.
    pub fn mean_instructions(&self) -> f64 {
        self.total_counts as f64 / self.timed.max(1) as f64 * self.instructions_per_count()
    }

    /// Most instructions of one cycle's fusion.
    pub fn worst_instructions(&self) -> f64 {
        self.worst_counts as f64 * self.instructions_per_count()
    }
}

/// The firmware workspace: `PEN_FIRMWARE_DIR`, or the one beside the sources this program was
/// built from.
pub fn firmware_dir() -> PathBuf {
    std::env::var_os("PEN_FIRMWARE_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../firmware")))
}

/// Builds `pen-qemu` (release, for the board's target) and returns its ELF; without the
/// firmware's sources (a copied binary), says how to give the image instead.
pub fn build_pen_qemu() -> Result<PathBuf, QemuError> {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let dir = firmware_dir();
    if !dir.join("Cargo.toml").is_file() {
        return Err(QemuError::NoFirmware(dir));
    }
    let out = Command::new(&cargo)
        .args(["build", "--release", "--locked", "-q", "-p", "pen-qemu"])
        .current_dir(&dir)
        .output()
        .map_err(|source| QemuError::Spawn {
            program: cargo.clone(),
            source,
        })?;
    if !out.status.success() {
        return Err(QemuError::Build(String::from_utf8_lossy(&out.stderr).into_owned()));
    }
    Ok(dir.join("target/thumbv7em-none-eabihf/release/pen-qemu"))
}

fn parse(stdout: &str) -> Result<QemuRun, QemuError> {
    let mut run = QemuRun {
        reports: Vec::new(),
        cycles: 0,
        timed: 0,
        total_counts: 0,
        worst_counts: 0,
        calibration: (0, 0),
        vector_table: None,
    };
    let bad = |line: &str| QemuError::Emulated(format!("unexpected output line {line:?}"));
    let mut finished = false;
    for line in stdout.lines() {
        let mut f = line.split_whitespace();
        match f.next() {
            Some("R") => {
                let t_us = f.next().and_then(|t| t.parse().ok()).ok_or_else(|| bad(line))?;
                let hex = f.next().ok_or_else(|| bad(line))?;
                let bytes = (0..hex.len())
                    .step_by(2)
                    .map(|i| hex.get(i..i + 2).and_then(|h| u8::from_str_radix(h, 16).ok()))
                    .collect::<Option<Vec<u8>>>()
                    .ok_or_else(|| bad(line))?;
                run.reports.push(Sent { t_us, bytes });
            }
            Some("C") => {
                let n: Vec<u64> = f.filter_map(|v| v.parse().ok()).collect();
                run.calibration = match n[..] {
                    [insns, counts] => (insns, counts as u32),
                    _ => return Err(bad(line)),
                };
            }
            Some("V") => {
                let mut hex = || f.next().and_then(|v| u32::from_str_radix(v, 16).ok());
                let (vtor, table) = (hex().ok_or_else(|| bad(line))?, hex().ok_or_else(|| bad(line))?);
                let taken = match f.next() {
                    Some("1") => true,
                    Some("0") => false,
                    _ => return Err(bad(line)),
                };
                run.vector_table = Some((vtor, table, taken));
            }
            Some("F") => {
                let n: Vec<u64> = f.filter_map(|v| v.parse().ok()).collect();
                let [cycles, timed, total, worst] = n[..] else {
                    return Err(bad(line));
                };
                (run.cycles, run.timed, run.total_counts, run.worst_counts) =
                    (cycles as u32, timed as u32, total, worst as u32);
                finished = true;
            }
            Some("E") => return Err(QemuError::Emulated(line[1..].trim().to_string())),
            _ => return Err(bad(line)),
        }
    }
    if finished {
        Ok(run)
    } else {
        Err(QemuError::Emulated(
            "no final figures: the program did not finish".into(),
        ))
    }
}

/// Runs `elf` under QEMU `mps2-an386` in a fresh folder holding `files`; returns whether it
/// exited with success, and its standard output and error.
fn run_with(elf: &Path, files: &[(&str, &[u8])], timeout: Duration) -> Result<(bool, String, String), QemuError> {
    let dir = std::env::temp_dir().join(format!("pen-qemu-{}-{}", std::process::id(), rand::random::<u32>()));
    std::fs::create_dir_all(&dir)?;
    for (name, bytes) in files {
        std::fs::write(dir.join(name), bytes)?;
    }
    let program = "qemu-system-arm";
    let mut child = Command::new(program)
        .args(["-M", "mps2-an386", "-nographic", "-monitor", "none", "-serial", "none"])
        .args([
            "-semihosting-config",
            "enable=on,target=native",
            "-icount",
            "shift=0",
            "-kernel",
        ])
        .arg(elf)
        .current_dir(&dir)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .map_err(|source| QemuError::Spawn {
            program: program.into(),
            source,
        })?;
    let mut stdout = child
        .stdout
        .take()
        .ok_or_else(|| QemuError::Emulated("no stdout".into()))?;
    let reader = std::thread::spawn(move || {
        let mut s = String::new();
        let _ = stdout.read_to_string(&mut s);
        s
    });
    let start = Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait()? {
            break status;
        }
        if start.elapsed() > timeout {
            let _ = child.kill();
            let _ = child.wait();
            let _ = std::fs::remove_dir_all(&dir);
            return Err(QemuError::Timeout(timeout));
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    let stdout = reader.join().unwrap_or_default();
    let mut stderr = String::new();
    if let Some(mut e) = child.stderr.take() {
        let _ = e.read_to_string(&mut stderr);
    }
    let _ = std::fs::remove_dir_all(&dir);
    Ok((status.success(), stdout, stderr))
}

/// Runs `elf` under QEMU `mps2-an386` with `replay` as its `cycles.bin`.
pub fn run(elf: &Path, replay: &[u8], timeout: Duration) -> Result<QemuRun, QemuError> {
    let (success, stdout, stderr) = run_with(elf, &[("cycles.bin", replay)], timeout)?;
    let run = parse(&stdout);
    if !success {
        return Err(match run {
            Err(e) => e,
            Ok(_) => QemuError::Emulated(format!("exit status: failure: {stderr}")),
        });
    }
    run
}

/// What the HardFault vector saw when `pen-qemu` overflowed its stack on purpose.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct StackFault {
    /// The configurable fault status register.
    pub cfsr: u32,
    /// The stack pointer when the fault came.
    pub stack_pointer: u32,
    /// The static placed above the stack, as the fault handler read it.
    pub canary: u32,
}

/// The value `pen-qemu`'s canary static starts with.
pub const CANARY: u32 = 0xC0FF_EE11;

/// Runs `elf` with a file `overflow` beside it: it overflows its stack, and its HardFault
/// vector (the board's) reports the fault from a fresh stack.
pub fn run_stack_overflow(elf: &Path, timeout: Duration) -> Result<StackFault, QemuError> {
    let (success, stdout, stderr) = run_with(elf, &[("overflow", b"")], timeout)?;
    let line = stdout
        .lines()
        .find_map(|l| l.strip_prefix("S "))
        .ok_or_else(|| QemuError::Emulated(format!("no fault reported: {stdout}{stderr}")))?;
    let hex: Vec<u32> = line
        .split_whitespace()
        .filter_map(|v| u32::from_str_radix(v, 16).ok())
        .collect();
    let [cfsr, stack_pointer, canary] = hex[..] else {
        return Err(QemuError::Emulated(format!("unexpected fault line {line:?}")));
    };
    if !success {
        return Err(QemuError::Emulated(format!("exit status: failure: {stderr}")));
    }
    Ok(StackFault {
        cfsr,
        stack_pointer,
        canary,
    })
}
