//! The hardware seams, and the measurement loop that drives the engine through them.
//!
//! The board implements these traits with timers, GPIOs and USB; the simulated pen implements
//! them with physics and a virtual clock. Both run the same [`Station::cycle`], so the simulator
//! exercises exactly the code that runs on the board.

use core::cell::RefCell;
use core::future::Future;
use core::ops::Deref;

use embassy_sync::blocking_mutex::Mutex;
use embassy_sync::blocking_mutex::raw::RawMutex;
use pen_protocol::{HeadReport, MAX_RECEIVERS, OsPenReport, PenReport, TofReport};

use crate::head::Emitter;
use crate::report::{Cycle, CycleResult, Engine, TICK_US};

/// The ultrasonic front end: a burst from the pen and the receivers' first arrivals.
pub trait Ranging {
    /// Receivers in use from now on (the configuration's count); the station tells it before
    /// every burst, so a configuration change takes effect at the next cycle. Front ends that
    /// listen to every receiver anyway need not care.
    fn set_receivers(&mut self, _count: usize) {}
    /// The emitter the next [`fire`](Self::fire) drives (the station says so before every
    /// burst). A front end with only the pen's emitter never hears of the head: the engine
    /// schedules it only while head tracking is on.
    fn set_emitter(&mut self, _emitter: Emitter) {}
    /// How long the next burst is listened to, µs (the station says so before every burst): the
    /// pen-only cycle's [`LISTEN_US`](crate::LISTEN_US), or a multiplexed slot's shorter window
    /// while the head is tracked. A front end that closes its window in hardware must close it
    /// before the next slot's burst.
    fn set_listen_us(&mut self, _listen_us: u64) {}
    /// Fires a burst; the capture time base starts with it.
    fn fire(&mut self);
    /// The first arrival at each receiver since the last burst, ns after it; `None` for a
    /// receiver that heard nothing.
    fn collect(&mut self) -> [Option<u32>; MAX_RECEIVERS];
}

/// The pen's switches.
pub trait Switches {
    /// The raw levels of SW1, SW2, SW3 (true = pressed), bounce and all.
    fn read(&mut self) -> [bool; 3];
}

/// Device time.
pub trait Clock {
    /// Microseconds since start-up.
    fn now_us(&self) -> u64;
    /// Returns at `t_us` (at once if it has passed).
    fn wait_until(&mut self, t_us: u64) -> impl Future<Output = ()>;
}

/// Where reports go: USB HID, the serial link, the simulator's byte stream.
pub trait ReportSink {
    /// Sends a pen report.
    fn pen(&mut self, report: &PenReport) -> impl Future<Output = ()>;
    /// Sends a time-of-flight diagnostics report.
    fn tof(&mut self, report: &TofReport) -> impl Future<Output = ()>;
    /// Sends the operating system's pen report that goes with the pen report just sent (USB
    /// HID only; other sinks have no OS to tell).
    fn os_pen(&mut self, report: &OsPenReport) -> impl Future<Output = ()> {
        let _ = report;
        async {}
    }
    /// Sends a head report (head tracking only; a sink of a base station without the head's
    /// emitter never gets one).
    fn head(&mut self, report: &HeadReport) -> impl Future<Output = ()> {
        let _ = report;
        async {}
    }
}

/// When to wake a suspended host: on a new press of the tip during this suspend. A pen left
/// standing on its tip must not keep the host awake, nor a press that began before the bus was
/// suspended wake it straight after.
#[derive(Debug, Clone, Copy, Default)]
pub struct WakeOnPress {
    /// The tip could have been down since the suspend began: a press counts once it was up.
    armed: bool,
}

impl WakeOnPress {
    /// A suspend begins: the tip's first release arms the wakeup.
    pub fn suspended(&mut self) {
        self.armed = false;
    }

    /// Takes a sample of the raw tip switch during suspend; true: wake the host now.
    pub fn sample(&mut self, tip: bool) -> bool {
        let wake = tip && self.armed;
        self.armed = !tip;
        wake
    }
}

/// The engine behind a mutex, shared with the USB request handlers.
pub type SharedEngine<M> = Mutex<M, RefCell<Engine>>;

/// The measurement loop over a set of hardware seams. `E` is how the station reaches the shared
/// engine: a reference on the board, a reference-counted handle in the simulator.
pub struct Station<M: RawMutex, E: Deref<Target = SharedEngine<M>>, R, S, C, K> {
    engine: E,
    /// The ultrasonic front end.
    pub ranging: R,
    /// The switches.
    pub switches: S,
    /// The clock.
    pub clock: C,
    /// Where reports go.
    pub sink: K,
}

impl<M, E, R, S, C, K> Station<M, E, R, S, C, K>
where
    M: RawMutex,
    E: Deref<Target = SharedEngine<M>>,
    R: Ranging,
    S: Switches,
    C: Clock,
    K: ReportSink,
{
    /// A station driving `engine`.
    pub fn new(engine: E, ranging: R, switches: S, clock: C, sink: K) -> Self {
        Station {
            engine,
            ranging,
            switches,
            clock,
            sink,
        }
    }

    /// The engine.
    pub fn engine(&self) -> &SharedEngine<M> {
        &self.engine
    }

    fn with<T>(&self, f: impl FnOnce(&mut Engine) -> T) -> T {
        self.engine.lock(|e| f(&mut e.borrow_mut()))
    }

    /// One measurement cycle (one slot of the schedule): fire the slot's emitter, sample the
    /// switches every tick, collect the arrivals when the listening window closes, send every
    /// report that falls due, and return when the next slot may start.
    pub async fn cycle(&mut self) -> CycleResult {
        let t0 = self.clock.now_us();
        let (slot, receivers) = self.with(|e| (e.next_slot(), e.settings().count));
        let period = slot.period_us;
        let listen = t0 + slot.listen_us;
        self.ranging.set_receivers(receivers);
        self.ranging.set_emitter(slot.emitter);
        self.ranging.set_listen_us(slot.listen_us);
        self.ranging.fire();
        let mut result = None;
        // Ticks at t0, t0 + TICK_US, … up to the end of the period, and one when the listening
        // window closes if that falls between ticks (head tracking's slots).
        let mut t = t0;
        while t < t0 + period {
            self.clock.wait_until(t).await;
            let raw = self.switches.read();
            self.with(|e| e.on_switches(t, raw));
            let mut tof = None;
            let mut head = None;
            if result.is_none() && t >= listen {
                let cycle = Cycle {
                    t0_us: t0,
                    arrival_ns: self.ranging.collect(),
                };
                match slot.emitter {
                    Emitter::Pen => {
                        let (r, streamed) = self.with(|e| (e.on_cycle(&cycle), e.tof_report()));
                        result = Some(r);
                        tof = streamed;
                    }
                    Emitter::Head => {
                        let (r, report) = self.with(|e| (e.on_head_cycle(&cycle), e.poll_head()));
                        result = Some(r);
                        head = report;
                    }
                }
            }
            while let Some(report) = self.with(|e| e.poll_report(t)) {
                self.sink.pen(&report).await;
                let os = self.with(|e| e.os_report(&report));
                self.sink.os_pen(&os).await;
            }
            if let Some(tof) = tof {
                self.sink.tof(&tof).await;
            }
            if let Some(head) = head {
                self.sink.head(&head).await;
            }
            let next = t + TICK_US;
            t = if t < listen && listen < next { listen } else { next };
        }
        self.clock.wait_until(t0 + period).await;
        match result {
            Some(r) => r,
            // The listening window always closes within the period (MIN_CYCLE_US > LISTEN_US).
            None => unreachable!("cycle period shorter than the listening window"),
        }
    }
}
