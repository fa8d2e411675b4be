//! The firmware core on an emulated Cortex-M4F.
//!
//! Reads `cycles.bin` (a replay recorded by the simulated pen, in the format of `pen_core::replay`)
//! through semihosting, drives pen-core's station with it — the same engine, the same station
//! loop, compiled for `thumbv7em-none-eabihf` — and prints every report it sends as
//! `R <device µs> <hex>` on the host's standard output. Then it replays the cycles once more
//! straight into the engine, timing each with SysTick, and prints the cost per fix. Run with
//! `-icount shift=0`, QEMU's virtual clock advances one nanosecond per instruction, so the
//! counts are instructions. It ends with a semihosting exit: status 0, or 1 on a bad replay.
//!
//! First of all it plays the ROM DFU bootloader's part (docs/flashing.md): VTOR pointed at a
//! table that is not the image's, then a jump to the image's reset vector, as the ROM's
//! `:leave` does. The reset handler must point VTOR back at the image's table (cortex-m-rt's
//! `set-vtor`) before `main` takes an exception: `V <VTOR> <image's table> <taken>` says so, and
//! an exception taken through the foreign table ends the run with a failure.
//!
//! With a file `overflow` beside it, it then overflows its stack on purpose (the stack is at the
//! bottom of RAM, as on the board): the board's HardFault vector must catch it on a fresh stack
//! with the statics intact, `S <CFSR> <stack pointer at the fault> <canary>`.
#![no_std]
#![no_main]

use core::cell::RefCell;
use core::fmt::Write;
use core::mem::MaybeUninit;
use core::ptr::addr_of_mut;
use core::sync::atomic::{AtomicBool, AtomicU32, Ordering};

use cortex_m::peripheral::SCB;
use cortex_m::peripheral::SYST;
use cortex_m::peripheral::syst::SystClkSource;
use cortex_m_rt::{entry, exception};
use cortex_m_semihosting::{debug, hio, syscall};
use embassy_futures::block_on;
use embassy_sync::blocking_mutex::Mutex;
use embassy_sync::blocking_mutex::raw::NoopRawMutex;
use pen_core::replay::Header;
use pen_core::replay::{self, ReplayError};
use pen_core::{Clock, Cycle, Emitter, Engine, Ranging, ReportSink, SharedEngine, Station, Switches};
use pen_protocol::{FirmwareVersion, HeadReport, MAX_RECEIVERS, PenReport, Report, TofReport};

/// Switch samples a cycle may have: the longest cycle, 1 s at a 1 Hz report rate, has 2000.
const MAX_TICKS: usize = 2048;

/// After a semihosting exit QEMU has stopped; on anything else, sleep.
fn halt() -> ! {
    loop {
        cortex_m::asm::wfi();
    }
}

#[panic_handler]
fn panic(info: &core::panic::PanicInfo) -> ! {
    if let Ok(mut out) = hio::hstderr() {
        let _ = writeln!(out, "pen-qemu: {info}");
    }
    debug::exit(debug::EXIT_FAILURE);
    halt()
}

/// Set in RAM the reset handler does not clear: the bootloader's jump has been played.
const JUMPED: u32 = 0x0B00_7ED0;
#[unsafe(link_section = ".uninit.STAGE")]
static mut STAGE: MaybeUninit<u32> = MaybeUninit::uninit();

/// A vector table that is not the image's, as the ROM bootloader leaves VTOR pointing at its own:
/// every exception through it is a failure.
#[repr(C, align(128))]
struct ForeignTable([unsafe extern "C" fn(); 32]);
static FOREIGN: ForeignTable = ForeignTable([foreign_exception; 32]);

unsafe extern "C" fn foreign_exception() {
    if let Ok(mut out) = hio::hstdout() {
        let _ = writeln!(
            out,
            "E an exception was taken through the bootloader's vector table: VTOR was not set"
        );
    }
    debug::exit(debug::EXIT_FAILURE);
    halt()
}

/// Taken through the image's own table.
static PENDSV_TAKEN: AtomicBool = AtomicBool::new(false);

#[exception]
fn PendSV() {
    PENDSV_TAKEN.store(true, Ordering::SeqCst);
}

unsafe extern "C" {
    /// The image's vector table, from cortex-m-rt's link.x.
    static __vector_table: u32;
}

/// The first time: VTOR at a foreign table and a jump to the reset vector, as the ROM DFU
/// bootloader leaves the core. The second: VTOR checked and an exception taken.
fn check_vector_table(out: &mut hio::HostStream) {
    let table = core::ptr::addr_of!(__vector_table);
    // SAFETY: a word this function owns, which may hold anything at power-up.
    let stage = unsafe { addr_of_mut!(STAGE).cast::<u32>().read_volatile() };
    if stage != JUMPED {
        // SAFETY: as above.
        unsafe { addr_of_mut!(STAGE).cast::<u32>().write_volatile(JUMPED) };
        // SAFETY: VTOR takes any 128-byte aligned table; the jump restarts the image from its
        // reset vector with its initial stack pointer, as the bootloader's would.
        unsafe {
            (*SCB::PTR).vtor.write(core::ptr::addr_of!(FOREIGN) as u32);
            cortex_m::asm::bootload(table)
        }
    }
    // SAFETY: as above.
    unsafe { addr_of_mut!(STAGE).cast::<u32>().write_volatile(0) };
    // SAFETY: a read of a core register.
    let vtor = unsafe { (*SCB::PTR).vtor.read() };
    SCB::set_pendsv();
    cortex_m::asm::isb();
    let taken = PENDSV_TAKEN.load(Ordering::SeqCst);
    let _ = writeln!(out, "V {vtor:08x} {:08x} {}", table as u32, u8::from(taken));
}

// The board's HardFault vector, which moves the stack pointer to the top of the stack before
// `fault_on_fresh_stack` runs.
#[path = "../../src/hard_fault.rs"]
mod hard_fault;

/// The configurable fault status register.
const CFSR: *const u32 = 0xE000_ED28 as *const u32;

/// A static the stack must never reach: with the stack below the statics, an overflow leaves it.
static CANARY: AtomicU32 = AtomicU32::new(0xC0FF_EE11);

/// Run by the HardFault vector on a fresh stack: prints `S <CFSR> <stack pointer at the fault>
/// <canary>`. The stack-overflow run ends here with success; any other run has no final figures
/// and fails.
#[unsafe(no_mangle)]
extern "C" fn fault_on_fresh_stack(frame: u32) -> ! {
    // SAFETY: a read of a system control register.
    let cfsr = unsafe { CFSR.read_volatile() };
    if let Ok(mut out) = hio::hstdout() {
        let canary = CANARY.load(Ordering::SeqCst);
        let _ = writeln!(out, "S {cfsr:08x} {frame:08x} {canary:08x}");
    }
    debug::exit(debug::EXIT_SUCCESS);
    halt()
}

/// Recurses until the stack runs out, 256 bytes a call.
#[inline(never)]
#[allow(unconditional_recursion)] // on purpose: it ends in the fault
fn overflow(depth: u32) -> u32 {
    let frame = core::hint::black_box([depth; 64]);
    overflow(depth + 1).wrapping_add(frame[depth as usize % 64])
}

/// A file on the host, read through semihosting.
struct HostFile(usize);

impl HostFile {
    fn open(name: &str) -> Option<HostFile> {
        // Semihosting wants a NUL-terminated name and its length without the NUL.
        let mut path = [0u8; 64];
        path.get_mut(..name.len())?.copy_from_slice(name.as_bytes());
        // SAFETY: a valid pointer to a NUL-terminated name; mode 1 is "rb".
        let fd = unsafe { syscall!(OPEN, path.as_ptr(), 1, name.len()) } as isize;
        (fd >= 0).then_some(HostFile(fd as usize))
    }
}

impl replay::Source for HostFile {
    fn read_exact(&mut self, buf: &mut [u8]) -> bool {
        if buf.is_empty() {
            return true;
        }
        // SAFETY: a valid buffer of the given length; the result is the count NOT read.
        let left = unsafe { syscall!(READ, self.0, buf.as_mut_ptr(), buf.len()) };
        left == 0
    }
}

/// One recorded cycle, as `pen_core::replay` reads it.
struct CycleIn {
    emitter: Emitter,
    t0_us: u64,
    arrival_ns: [Option<u32>; MAX_RECEIVERS],
    ticks: usize,
    switches: [u8; MAX_TICKS],
}

/// The next cycle of the replay; `None` at its end; a damaged replay ends the run.
fn next_cycle(file: &mut HostFile, header: &Header, out: &mut hio::HostStream) -> Option<CycleIn> {
    let mut switches = [0u8; MAX_TICKS];
    match replay::read_cycle(file, header, &mut switches) {
        Ok(Some(head)) => Some(CycleIn {
            emitter: head.emitter,
            t0_us: head.t0_us,
            arrival_ns: head.arrival_ns,
            ticks: head.samples as usize,
            switches,
        }),
        Ok(None) => None,
        Err(e) => fail(out, replay_error(e)),
    }
}

fn replay_error(e: ReplayError) -> &'static str {
    match e {
        ReplayError::NotAReplay => "cycles.bin is not a replay",
        ReplayError::Version(_) => "cycles.bin is not a version 2 or 3 replay",
        ReplayError::BadConfig => "bad configuration in cycles.bin",
        ReplayError::BadHead => "bad head schedule in cycles.bin",
        ReplayError::BadEmitter(_) => "a cycle of cycles.bin names an emitter the run does not have",
        ReplayError::Truncated => "cycles.bin ends inside a cycle",
        ReplayError::TooManySamples(_) => "a cycle of cycles.bin has more switch samples than pen-qemu holds",
    }
}

/// The replayed hardware: one cycle's recorded captures and switch samples.
struct Replay {
    now_us: u64,
    cycle: Option<CycleIn>,
    tick: usize,
    /// Samples asked for beyond those recorded: the replay and the station disagree.
    overrun: bool,
    /// The station fired another emitter than the recorded cycle's: the schedules disagree.
    wrong_emitter: bool,
}

struct R<'a>(&'a RefCell<Replay>);

impl Ranging for R<'_> {
    fn set_emitter(&mut self, emitter: Emitter) {
        let mut r = self.0.borrow_mut();
        if r.cycle.as_ref().is_some_and(|c| c.emitter != emitter) {
            r.wrong_emitter = true;
        }
    }
    fn fire(&mut self) {}
    fn collect(&mut self) -> [Option<u32>; MAX_RECEIVERS] {
        self.0
            .borrow()
            .cycle
            .as_ref()
            .map_or([None; MAX_RECEIVERS], |c| c.arrival_ns)
    }
}

impl Switches for R<'_> {
    fn read(&mut self) -> [bool; 3] {
        let mut r = self.0.borrow_mut();
        let i = r.tick;
        r.tick += 1;
        let bits = match &r.cycle {
            Some(c) if i < c.ticks => c.switches[i],
            _ => {
                r.overrun = true;
                0
            }
        };
        [bits & 1 != 0, bits & 2 != 0, bits & 4 != 0]
    }
}

impl Clock for R<'_> {
    fn now_us(&self) -> u64 {
        self.0.borrow().now_us
    }
    async fn wait_until(&mut self, t_us: u64) {
        let mut r = self.0.borrow_mut();
        r.now_us = r.now_us.max(t_us);
    }
}

/// Prints each report as a line; buffered, as every semihosting call is a trap to the host.
struct Printer<'a> {
    replay: &'a RefCell<Replay>,
    out: hio::HostStream,
    line: [u8; 160],
}

impl Printer<'_> {
    fn print<T: Report>(&mut self, report: &T) {
        let mut bytes = [0u8; 64];
        let Ok(n) = report.encode(&mut bytes) else { return };
        let t = self.replay.borrow().now_us;
        let mut w = LineWriter {
            buf: &mut self.line,
            len: 0,
        };
        let _ = write!(w, "R {t} ");
        for b in &bytes[..n] {
            let _ = write!(w, "{b:02x}");
        }
        let _ = w.write_str("\n");
        let len = w.len;
        let _ = self.out.write_all(&self.line[..len]);
    }
}

struct LineWriter<'a> {
    buf: &'a mut [u8],
    len: usize,
}

impl Write for LineWriter<'_> {
    fn write_str(&mut self, s: &str) -> core::fmt::Result {
        let end = self.len + s.len();
        self.buf
            .get_mut(self.len..end)
            .ok_or(core::fmt::Error)?
            .copy_from_slice(s.as_bytes());
        self.len = end;
        Ok(())
    }
}

impl ReportSink for Printer<'_> {
    async fn pen(&mut self, report: &PenReport) {
        self.print(report);
    }
    async fn tof(&mut self, report: &TofReport) {
        self.print(report);
    }
    async fn head(&mut self, report: &HeadReport) {
        self.print(report);
    }
}

/// SysTick counts since `start`, on the 24-bit down-counter.
fn elapsed(start: u32) -> u32 {
    start.wrapping_sub(SYST::get_current()) & 0x00FF_FFFF
}

fn fail(out: &mut hio::HostStream, why: &str) -> ! {
    let _ = writeln!(out, "E {why}");
    debug::exit(debug::EXIT_FAILURE);
    halt()
}

#[entry]
fn main() -> ! {
    let mut out = match hio::hstdout() {
        Ok(o) => o,
        Err(()) => {
            debug::exit(debug::EXIT_FAILURE);
            halt()
        }
    };
    check_vector_table(&mut out);
    // The stack guard's test: with a file `overflow` beside it, the run overflows its stack.
    if HostFile::open("overflow").is_some() {
        core::hint::black_box(overflow(0));
    }
    let mut cp = cortex_m::Peripherals::take().unwrap_or_else(|| fail(&mut out, "peripherals taken"));
    cp.SYST.set_clock_source(SystClkSource::Core);
    cp.SYST.set_reload(0x00FF_FFFF);
    cp.SYST.clear_current();
    cp.SYST.enable_counter();

    // SysTick counts per instruction, from a loop of exactly two instructions per iteration.
    let iterations: u32 = 1_000_000;
    let start = SYST::get_current();
    // SAFETY: a register-only countdown loop.
    unsafe {
        core::arch::asm!("1:", "subs {0}, {0}, #1", "bne 1b", inout(reg) iterations => _, options(nomem, nostack));
    }
    let calibration = elapsed(start);
    let _ = writeln!(out, "C {} {}", 2 * iterations, calibration);

    let Some(file) = HostFile::open("cycles.bin") else {
        fail(&mut out, "cannot open cycles.bin")
    };
    let mut file = file;
    let header = replay::read_header(&mut file).unwrap_or_else(|e| fail(&mut out, replay_error(e)));
    let firmware = FirmwareVersion {
        major: 0,
        minor: 1,
        patch: 0,
    };
    let id = *b"penscape-sim";

    // The engine as the recorded device ran: with the glasses' emitter fitted and scheduled
    // when the run tracked the head.
    let new_engine = || {
        let mut e = Engine::new(Some(header.config), firmware, id);
        e.set_head_emitter_fitted(header.head.is_some());
        e.set_head(header.head);
        e
    };
    // Pass 1: the station, exactly as the board runs it, printing every report.
    let engine: SharedEngine<NoopRawMutex> = Mutex::new(RefCell::new(new_engine()));
    let replay = RefCell::new(Replay {
        now_us: 0,
        cycle: None,
        tick: 0,
        overrun: false,
        wrong_emitter: false,
    });
    let printer = Printer {
        replay: &replay,
        out,
        line: [0; 160],
    };
    let mut station = Station::new(&engine, R(&replay), R(&replay), R(&replay), printer);
    let mut cycles = 0u32;
    while let Some(c) = next_cycle(&mut file, &header, &mut out) {
        {
            let mut r = replay.borrow_mut();
            r.now_us = c.t0_us;
            r.tick = 0;
            r.cycle = Some(c);
        }
        block_on(station.cycle());
        let r = replay.borrow();
        if r.overrun || r.cycle.as_ref().is_some_and(|c| c.ticks != r.tick) {
            drop(r);
            fail(&mut out, "the replay's switch samples do not match the station's ticks");
        }
        if r.wrong_emitter {
            drop(r);
            fail(&mut out, "the replay's emitters do not follow the head schedule");
        }
        cycles += 1;
    }

    // Pass 2: the fusion alone, cycle by cycle, timed.
    let Some(mut file) = HostFile::open("cycles.bin") else {
        fail(&mut out, "cannot reopen cycles.bin")
    };
    let mut skip = [0u8; replay::HEADER_LEN];
    let _ = replay::Source::read_exact(&mut file, &mut skip[..header.encoded_len()]);
    let mut engine = new_engine();
    let (mut total, mut worst, mut n) = (0u64, 0u32, 0u32);
    while let Some(c) = next_cycle(&mut file, &header, &mut out) {
        let cycle = Cycle {
            t0_us: c.t0_us,
            arrival_ns: c.arrival_ns,
        };
        let start = SYST::get_current();
        let result = match c.emitter {
            Emitter::Pen => engine.on_cycle(&cycle),
            Emitter::Head => engine.on_head_cycle(&cycle),
        };
        let counts = elapsed(start);
        core::hint::black_box(result);
        total += counts as u64;
        worst = worst.max(counts);
        n += 1;
    }
    let _ = writeln!(out, "F {cycles} {n} {total} {worst}");
    debug::exit(debug::EXIT_SUCCESS);
    halt()
}
