//! embassy-time's driver on TIM5, counting in its full 32 bits.
//!
//! embassy-stm32's own driver runs every timer in 16-bit mode, its interrupt counting a half
//! period every 32.8 ms at 1 MHz. A flash erase stalls the CPU for 2–4 s (the F411 has one bank,
//! and every fetch from flash waits, interrupts included), so that driver missed dozens of half
//! periods and device time fell seconds behind. TIM5 is a 32-bit timer: here a half period is
//! 2³¹ µs, 35 minutes, so the interrupt only has to run once in that long, and a stalled one runs
//! late but loses nothing ([`pen_core::board::ticks`], tested on the host).
//!
//! 1 MHz ticks (embassy-time's `tick-hz-1_000_000`): TIM5 runs from APB1's timer clock, 96 MHz
//! (`main.rs` sets APB1 to 48 MHz, whose timers run at twice that), prescaled by 96. Channel 1
//! compares at the midpoint (2³¹) for the half-period count, channel 2 is the alarm.

use core::cell::{Cell, RefCell};
use core::sync::atomic::{AtomicU32, Ordering};
use core::task::Waker;

use critical_section::CriticalSection;
use embassy_stm32::interrupt::typelevel::{Handler, Interrupt, TIM5};
use embassy_stm32::pac;
use embassy_stm32::pac::timer::regs;
use embassy_sync::blocking_mutex::CriticalSectionMutex;
use embassy_time_driver::{Driver, TICK_HZ};
use embassy_time_queue_utils::Queue;
use pen_core::board::ticks;

/// TIM5's clock, Hz: APB1's timer clock.
pub const TIMER_HZ: u32 = 96_000_000;
const HALF: u32 = 1 << 31;
/// An alarm this close (in ticks) is armed at once; a farther one by the half period before it.
const ARM_WITHIN: u64 = 3 << 30;

struct Tim5Driver {
    /// Half periods (2³¹ ticks) since start-up; written only by the interrupt.
    half_periods: AtomicU32,
    /// The alarm's time, `u64::MAX` when none is set.
    alarm_at: CriticalSectionMutex<Cell<u64>>,
    queue: CriticalSectionMutex<RefCell<Queue>>,
}

embassy_time_driver::time_driver_impl!(static DRIVER: Tim5Driver = Tim5Driver {
    half_periods: AtomicU32::new(0),
    alarm_at: CriticalSectionMutex::new(Cell::new(u64::MAX)),
    queue: CriticalSectionMutex::new(RefCell::new(Queue::new())),
});

fn tim() -> pac::timer::TimGp32 {
    pac::TIM5
}

/// Starts the time base. Call once, right after `embassy_stm32::init` has set the clocks.
pub fn init() {
    const _: () = assert!((TIMER_HZ as u64).is_multiple_of(TICK_HZ) && TIMER_HZ as u64 / TICK_HZ <= 65_536);
    let rcc = pac::RCC;
    rcc.apb1enr().modify(|w| w.set_tim5en(true));
    rcc.apb1rstr().modify(|w| w.set_tim5rst(true));
    rcc.apb1rstr().modify(|w| w.set_tim5rst(false));
    let r = tim();
    r.psc().write_value((TIMER_HZ as u64 / TICK_HZ - 1) as u16);
    r.arr().write_value(u32::MAX);
    // Load the prescaler without an update interrupt (URS: only overflows raise one).
    r.cr1().modify(|w| w.set_urs(pac::timer::vals::Urs::COUNTER_ONLY));
    r.egr().write(|w| w.set_ug(true));
    r.ccr(0).write_value(HALF);
    r.dier().write(|w| {
        w.set_uie(true);
        w.set_ccie(0, true);
    });
    TIM5::unpend();
    // SAFETY: the handler below is bound to TIM5 in main.rs; it takes the driver's critical
    // sections, nothing else.
    unsafe { TIM5::enable() };
    r.cr1().modify(|w| w.set_cen(true));
}

/// TIM5's interrupt, bound in main.rs.
pub struct Tim5Interrupt;

impl Handler<TIM5> for Tim5Interrupt {
    unsafe fn on_interrupt() {
        DRIVER.on_interrupt();
    }
}

impl Tim5Driver {
    fn on_interrupt(&self) {
        let r = tim();
        critical_section::with(|cs| {
            let sr = r.sr().read();
            let dier = r.dier().read();
            // SR is cleared by writing 0: write 0 exactly where a flag was read, 1 elsewhere, so
            // that a flag raised since the read stays set.
            r.sr().write_value(regs::SrGp16(!sr.0));
            if sr.uif() {
                self.next_half(cs);
            }
            if sr.ccif(0) {
                self.next_half(cs);
            }
            if sr.ccif(1) && dier.ccie(1) {
                self.on_alarm(cs);
            }
        });
    }

    /// One more half period; an alarm that has come within reach is armed.
    fn next_half(&self, cs: CriticalSection) {
        let half = self.half_periods.load(Ordering::Relaxed).wrapping_add(1);
        self.half_periods.store(half, Ordering::Relaxed);
        let start = (half as u64) << 31;
        if self.alarm_at.borrow(cs).get() < start + ARM_WITHIN {
            tim().dier().modify(|w| w.set_ccie(1, true));
        }
    }

    fn on_alarm(&self, cs: CriticalSection) {
        let mut next = self.queue.borrow(cs).borrow_mut().next_expiration(self.now());
        while !self.set_alarm(cs, next) {
            next = self.queue.borrow(cs).borrow_mut().next_expiration(self.now());
        }
    }

    /// Sets the alarm for `at`; `false` when `at` has already passed (the caller takes the
    /// queue's next expiration again).
    fn set_alarm(&self, cs: CriticalSection, at: u64) -> bool {
        let r = tim();
        self.alarm_at.borrow(cs).set(at);
        let disarm = || {
            r.dier().modify(|w| w.set_ccie(1, false));
            self.alarm_at.borrow(cs).set(u64::MAX);
        };
        let now = self.now();
        if at <= now {
            disarm();
            return false;
        }
        r.ccr(1).write_value(at as u32);
        r.dier().modify(|w| w.set_ccie(1, at - now < ARM_WITHIN));
        // The compare may have been passed while it was written: then it will not fire.
        if at <= self.now() {
            disarm();
            return false;
        }
        true
    }
}

impl Driver for Tim5Driver {
    fn now(&self) -> u64 {
        // The half-period count first, then the counter: `ticks` resolves a boundary passed in
        // between.
        let half = self.half_periods.load(Ordering::Relaxed);
        core::sync::atomic::compiler_fence(Ordering::Acquire);
        ticks(half, tim().cnt().read())
    }

    fn schedule_wake(&self, at: u64, waker: &Waker) {
        critical_section::with(|cs| {
            let mut queue = self.queue.borrow(cs).borrow_mut();
            if queue.schedule_wake(at, waker) {
                let mut next = queue.next_expiration(self.now());
                while !self.set_alarm(cs, next) {
                    next = queue.next_expiration(self.now());
                }
            }
        })
    }
}
