//! The ultrasonic front end: the 40 kHz burst and the receivers' first arrivals.
//!
//! * TIM1 channel 1 (PA8) drives the pen transducer's gate driver with a burst of
//!   [`BURST_CYCLES`] periods at 40 kHz, in one-pulse mode with the repetition counter, so the
//!   burst length is exact and needs no interrupt. PWM mode 2 keeps the pin low at rest; the
//!   first rising edge comes 12.49 µs after the counter starts, and is subtracted.
//! * TIM1 channel 2 (PA9) drives the glasses' emitter (head tracking, issue 16) the same way,
//!   with the same compare value: the same timer makes both bursts, so both start the capture
//!   counters alike and have the same first edge. Before each burst the station names the slot's
//!   emitter; the other channel is forced inactive (driven low), so exactly one transducer sounds.
//! * TIM1's trigger output fires when its counter is enabled; TIM2 and TIM3 take it as a start
//!   (trigger mode, ITR0) and run in one-pulse mode to the end of the listening window, so their
//!   counters start at the burst in hardware, stop when the window closes, and a capture value
//!   is the time since the trigger. The window is the slot's: 5 ms for the pen alone, 1.5 m of
//!   flight (4.4 ms) while the head is tracked, when the next burst follows 20 µs after it.
//! * TIM2 (32-bit, 96 MHz, 10.4 ns per tick) captures receivers 0–3 on PA15, PB3, PB10, PA3;
//!   TIM3 (16-bit, prescaled to 8 MHz, 125 ns) captures receivers 4–7 on PA6, PA7, PB0, PB1.
//! * Each receiver's comparator output rises on the first arrival. The capture interrupt
//!   ignores edges in the first 230 µs (pickup from the burst), stores the first capture after
//!   it and disables that channel, so later echoes cannot overwrite it.

use core::sync::atomic::{AtomicU32, Ordering};

use embassy_stm32::gpio::{OutputType, Pull};
use embassy_stm32::interrupt::typelevel::{Handler, Interrupt};
use embassy_stm32::peripherals::{TIM1, TIM2, TIM3};
use embassy_stm32::time::Hertz;
use embassy_stm32::timer::input_capture::CapturePin;
use embassy_stm32::timer::low_level::{
    CountingMode, FilterValue, InputCaptureMode, InputTISelection, MasterMode, OutputCompareMode, RoundTo, SlaveMode,
    Timer, TriggerSource,
};
use embassy_stm32::timer::simple_pwm::PwmPin;
use embassy_stm32::timer::{Ch1, Ch2, Ch3, Ch4, Channel};
use embassy_stm32::{Peri, interrupt, pac};
use pen_core::ranging::{SLOW_TIMER_HZ, ns_per_tick, ticks_to_ns};
use pen_core::{Emitter, LISTEN_US, Ranging};
use pen_protocol::MAX_RECEIVERS;

/// Periods of 40 kHz per burst: long enough for the transducer to ring up, short enough to end
/// before the nearest receiver hears it.
pub const BURST_CYCLES: u16 = 8;
/// The transducer's resonance.
const BURST_HZ: u32 = 40_000;

const NO_CAPTURE: u32 = u32::MAX;
/// The first capture of each receiver since the last burst, in timer ticks.
static CAPTURES: [AtomicU32; MAX_RECEIVERS] = [const { AtomicU32::new(NO_CAPTURE) }; MAX_RECEIVERS];
/// Captures earlier than this many ticks of TIM2 / TIM3 after the trigger are the burst's own
/// electrical and acoustic pickup, not an arrival: ignored, the channel stays armed. Set once by
/// [`BoardRanging::new`] before the interrupts are enabled.
static BLANK_TICKS: [AtomicU32; 2] = [const { AtomicU32::new(0) }; 2];

/// How long after the trigger an edge is pickup from the burst, ns: the burst's first rising
/// edge (12.49 µs), its eight periods (200 µs), and ringing. A pen nearer a receiver than
/// 230 µs of flight (79 mm) is not measured by it.
const BLANK_NS: u32 = 230_000;

const CHANNELS: [Channel; 4] = [Channel::Ch1, Channel::Ch2, Channel::Ch3, Channel::Ch4];

/// The capture interrupt of one timer: `sr` and `ccr` read it, `first_receiver` is its channel 1's
/// receiver. A capture after the blanking time is the first arrival: stored, and its channel
/// disabled so that echoes cannot overwrite it. One earlier is pickup from the burst: dropped,
/// the channel left armed. The counter stops (one-pulse mode) at the end of the listening
/// window and reads 0 after it, so an edge however late is blanked too, never aliased.
///
/// Reading CCR clears its capture flag in hardware, so SR is written only for overcapture, and
/// then with 0 in the handled bit alone: SR is clear-by-writing-0, and a read-modify-write
/// would clear a capture latched between the read and the write, whose channel would then take
/// a later echo as its first arrival.
fn on_capture(regs: pac::timer::TimGp16, ccr: impl Fn(usize) -> u32, first_receiver: usize, blank: u32) {
    let sr = regs.sr().read();
    let mut overcaptured = pac::timer::regs::SrGp16(u32::MAX);
    for ch in (0..4).filter(|&ch| sr.ccif(ch)) {
        let ticks = ccr(ch);
        if sr.ccof(ch) {
            // Two edges before this interrupt ran (it was held off): CCR holds the later one,
            // and the first arrival is lost. Better no range than an echo's.
            overcaptured.set_ccof(ch, false);
            if ticks >= blank {
                regs.ccer().modify(|w| w.set_cce(ch, false));
                regs.dier().modify(|w| w.set_ccie(ch, false));
            }
            continue;
        }
        if ticks < blank {
            continue;
        }
        CAPTURES[first_receiver + ch].store(ticks, Ordering::Relaxed);
        regs.ccer().modify(|w| w.set_cce(ch, false));
        regs.dier().modify(|w| w.set_ccie(ch, false));
    }
    if overcaptured.0 != u32::MAX {
        regs.sr().write_value(overcaptured);
    }
}

/// TIM2's capture interrupt: receivers 0–3.
pub struct Tim2Captures;

impl Handler<interrupt::typelevel::TIM2> for Tim2Captures {
    unsafe fn on_interrupt() {
        // TIM2's capture registers are 32 bits wide: read through the 32-bit view; its other
        // registers are laid out as a 16-bit timer's.
        // SAFETY: TIM2 is a general-purpose timer at the same address in both views.
        let regs = unsafe { pac::timer::TimGp16::from_ptr(pac::TIM2.as_ptr()) };
        let blank = BLANK_TICKS[0].load(Ordering::Relaxed);
        on_capture(regs, |ch| pac::TIM2.ccr(ch).read(), 0, blank);
    }
}

/// TIM3's capture interrupt: receivers 4–7.
pub struct Tim3Captures;

impl Handler<interrupt::typelevel::TIM3> for Tim3Captures {
    unsafe fn on_interrupt() {
        let blank = BLANK_TICKS[1].load(Ordering::Relaxed);
        on_capture(pac::TIM3, |ch| pac::TIM3.ccr(ch).read().ccr() as u32, 4, blank);
    }
}

/// Four capture pins of one timer.
pub type CapturePins<'d, T> = (
    CapturePin<'d, T, Ch1>,
    CapturePin<'d, T, Ch2>,
    CapturePin<'d, T, Ch3>,
    CapturePin<'d, T, Ch4>,
);

/// The capture pins, kept configured for as long as the front end lives.
#[allow(
    dead_code,
    reason = "held, not read: dropping a pin would release its alternate function"
)]
pub struct Pins<'d> {
    /// PA8: TIM1 channel 1, the pen's burst.
    pub burst: PwmPin<'d, TIM1, Ch1>,
    /// PA9: TIM1 channel 2, the glasses' burst (head tracking).
    pub glasses: PwmPin<'d, TIM1, Ch2>,
    /// Receivers 0–3 on TIM2.
    pub tim2: CapturePins<'d, TIM2>,
    /// Receivers 4–7 on TIM3.
    pub tim3: CapturePins<'d, TIM3>,
}

/// The board's [`Ranging`]: TIM1 fires, TIM2 and TIM3 capture.
pub struct BoardRanging<'d> {
    burst: Timer<'d, TIM1>,
    tim2: Timer<'d, TIM2>,
    tim3: Timer<'d, TIM3>,
    /// Receivers in use: channels beyond are left disabled.
    receivers: usize,
    ns_per_tick_tim2: f32,
    ns_per_tick_tim3: f32,
    /// The burst's first rising edge after the trigger, ns.
    edge_ns: u32,
    /// TIM2's clock, Hz.
    fast_hz: u32,
    /// The listening window the capture counters stop at, µs.
    listen_us: u64,
    _pins: Pins<'d>,
}

/// TIM1's channel for each emitter.
const fn burst_channel(emitter: Emitter) -> Channel {
    match emitter {
        Emitter::Pen => Channel::Ch1,
        Emitter::Head => Channel::Ch2,
    }
}

/// A listening window in ticks of a timer at `hz`.
fn window_ticks(listen_us: u64, hz: u32) -> u32 {
    (listen_us * hz as u64 / 1_000_000) as u32
}

impl<'d> BoardRanging<'d> {
    /// Sets the timers up. The pins' pull-downs hold unconnected receivers' inputs low.
    pub fn new(
        tim1: Peri<'d, TIM1>,
        tim2: Peri<'d, TIM2>,
        tim3: Peri<'d, TIM3>,
        pins: Pins<'d>,
        receivers: usize,
    ) -> BoardRanging<'d> {
        let burst = Timer::new(tim1);
        burst.set_counting_mode(CountingMode::EdgeAlignedUp);
        burst.set_frequency(Hertz(BURST_HZ), RoundTo::Slower);
        let half = burst.get_max_compare_value() / 2;
        burst.set_output_compare_mode(Channel::Ch1, OutputCompareMode::PwmMode2);
        burst.set_compare_value(Channel::Ch1, half);
        // The glasses' channel: the same waveform when its slot comes, held low until then.
        burst.set_output_compare_mode(Channel::Ch2, OutputCompareMode::ForceInactive);
        burst.set_compare_value(Channel::Ch2, half);
        burst.set_repetition_counter(BURST_CYCLES - 1);
        // One-pulse mode: the counter stops at the update event after RCR + 1 periods.
        burst.regs_advanced().cr1().modify(|w| w.set_opm(true));
        burst.set_master_mode(MasterMode::ENABLE);
        burst.enable_channel(Channel::Ch1, true);
        burst.enable_channel(Channel::Ch2, true);
        burst.set_moe(true);
        // Load the repetition counter and prescaler without starting.
        burst.generate_update_event();
        burst.regs_advanced().sr().modify(|w| w.set_uif(false));

        let tim2 = Timer::new(tim2);
        tim2.regs_gp32().psc().write_value(0);
        tim2.regs_gp32().arr().write_value(u32::MAX);
        let mut tim3 = Timer::new(tim3);
        tim3.set_tick_freq(Hertz(SLOW_TIMER_HZ));
        tim3.regs_gp16().arr().write(|w| w.set_arr(u16::MAX));
        for ch in CHANNELS {
            tim2.set_input_ti_selection(ch, InputTISelection::Normal);
            tim2.set_input_capture_filter(ch, FilterValue::FCK_INT_N8);
            tim2.set_input_capture_mode(ch, InputCaptureMode::Rising);
            tim3.set_input_ti_selection(ch, InputTISelection::Normal);
            tim3.set_input_capture_filter(ch, FilterValue::FCK_INT_N8);
            tim3.set_input_capture_mode(ch, InputCaptureMode::Rising);
        }
        // The listening window in hardware: each capture counter runs from the burst's trigger
        // (trigger mode starts it, from 0) to the end of the window and stops there (one-pulse
        // mode: the update event clears CEN and leaves the counter at 0). However late
        // `collect()` runs — a flash erase stalls the CPU for seconds — an edge after the window
        // captures 0 and is blanked; TIM3 can no longer wrap (8.19 ms) and alias a late edge
        // to a short flight.
        let fast_hz = tim2.get_clock_frequency().0;
        tim2.regs_gp32().arr().write_value(window_ticks(LISTEN_US, fast_hz));
        tim3.regs_gp16()
            .arr()
            .write(|w| w.set_arr(window_ticks(LISTEN_US, SLOW_TIMER_HZ).min(u16::MAX as u32) as u16));
        tim2.regs_gp32().cr1().modify(|w| w.set_opm(true));
        tim3.regs_gp16().cr1().modify(|w| w.set_opm(true));
        tim2.set_slave_mode(SlaveMode::TRIGGER_MODE);
        tim2.set_trigger_source(TriggerSource::ITR0);
        tim3.set_slave_mode(SlaveMode::TRIGGER_MODE);
        tim3.set_trigger_source(TriggerSource::ITR0);
        // Load ARR and the prescaler; the counters stay stopped at 0 until the first burst.
        tim2.generate_update_event();
        tim3.generate_update_event();
        // The clock tree gives TIM2 the 96 MHz the core's FAST_TIMER_HZ assumes.
        let ns_per_tick_tim2 = ns_per_tick(fast_hz);
        let ns_per_tick_tim3 = ns_per_tick(SLOW_TIMER_HZ);
        let blank_ticks = |hz: u32| (BLANK_NS as u64 * hz as u64 / 1_000_000_000) as u32;
        BLANK_TICKS[0].store(blank_ticks(fast_hz), Ordering::Relaxed);
        BLANK_TICKS[1].store(blank_ticks(SLOW_TIMER_HZ), Ordering::Relaxed);
        // PWM mode 2 keeps the pin low until the counter reaches the compare value: the burst's
        // first rising edge, where the sound starts, comes `half` ticks of TIM1 after the
        // trigger that starts the capture counters (12.49 µs at 96 MHz, 4.3 mm of range).
        // Subtracted from every capture, so times of flight start at the sound.
        let edge_ns = (half as u64 * 1_000_000_000 / burst.get_clock_frequency().0 as u64) as u32;
        interrupt::typelevel::TIM2::unpend();
        interrupt::typelevel::TIM3::unpend();
        // SAFETY: the handlers are bound in main's `bind_interrupts!` and touch only the
        // capture registers and `CAPTURES`.
        unsafe {
            interrupt::typelevel::TIM2::enable();
            interrupt::typelevel::TIM3::enable();
        }
        BoardRanging {
            burst,
            tim2,
            tim3,
            receivers: receivers.min(MAX_RECEIVERS),
            ns_per_tick_tim2,
            ns_per_tick_tim3,
            edge_ns,
            fast_hz,
            listen_us: LISTEN_US,
            _pins: pins,
        }
    }

    fn arm(&mut self, enable: bool) {
        for (i, ch) in CHANNELS.into_iter().enumerate() {
            let on = enable && i < self.receivers;
            self.tim2.enable_channel(ch, on);
            self.tim2.enable_input_interrupt(ch, on);
            let on = enable && i + 4 < self.receivers;
            self.tim3.enable_channel(ch, on);
            self.tim3.enable_input_interrupt(ch, on);
        }
        // Stale capture and overcapture flags from the last window, all at once. Writing 0
        // clears a flag and 1 leaves it (SR is clear-by-writing-0), so the update flag and the
        // rest are written 1 rather than read and written back.
        let mut stale = pac::timer::regs::SrGp16(u32::MAX);
        for ch in 0..4 {
            stale.set_ccif(ch, false);
            stale.set_ccof(ch, false);
        }
        self.tim2.regs_gp16().sr().write_value(stale);
        self.tim3.regs_gp16().sr().write_value(stale);
    }
}

impl Ranging for BoardRanging<'_> {
    /// Channels beyond `count` stay disabled.
    fn set_receivers(&mut self, count: usize) {
        self.receivers = count.min(MAX_RECEIVERS);
    }

    /// The emitter's channel makes the burst; the other is forced low.
    fn set_emitter(&mut self, emitter: Emitter) {
        for e in [Emitter::Pen, Emitter::Head] {
            let mode = if e == emitter {
                OutputCompareMode::PwmMode2
            } else {
                OutputCompareMode::ForceInactive
            };
            self.burst.set_output_compare_mode(burst_channel(e), mode);
        }
    }

    /// The capture counters' auto-reload: they stop when the window closes.
    fn set_listen_us(&mut self, listen_us: u64) {
        if listen_us == self.listen_us {
            return;
        }
        self.listen_us = listen_us;
        let slow = window_ticks(listen_us, SLOW_TIMER_HZ).min(u16::MAX as u32) as u16;
        self.tim2
            .regs_gp32()
            .arr()
            .write_value(window_ticks(listen_us, self.fast_hz));
        self.tim3.regs_gp16().arr().write(|w| w.set_arr(slow));
    }

    fn fire(&mut self) {
        for c in &CAPTURES {
            c.store(NO_CAPTURE, Ordering::Relaxed);
        }
        // The counters stop by themselves when a window closes; should the previous window still
        // run (a slot started early), trigger mode would not restart it: stop and zero them, so
        // that every capture counts from this burst.
        for tim in [self.tim2.regs_gp16(), self.tim3.regs_gp16()] {
            tim.cr1().modify(|w| w.set_cen(false));
            tim.cnt().write(|w| w.set_cnt(0));
        }
        self.arm(true);
        // Enabling TIM1's counter starts the burst and, through its trigger output, resets the
        // capture counters at the same clock edge.
        self.burst.start();
    }

    fn collect(&mut self) -> [Option<u32>; MAX_RECEIVERS] {
        self.arm(false);
        let mut out = [None; MAX_RECEIVERS];
        for (i, slot) in out.iter_mut().enumerate().take(self.receivers) {
            let ticks = CAPTURES[i].load(Ordering::Relaxed);
            if ticks != NO_CAPTURE {
                let ns_per_tick = if i < 4 {
                    self.ns_per_tick_tim2
                } else {
                    self.ns_per_tick_tim3
                };
                *slot = ticks_to_ns(ticks, ns_per_tick).checked_sub(self.edge_ns);
            }
        }
        out
    }
}

/// Helper for main: the receivers' capture pins with pull-downs.
pub fn capture_pin<'d, T, C>(pin: Peri<'d, impl embassy_stm32::timer::TimerPin<T, C>>) -> CapturePin<'d, T, C>
where
    T: embassy_stm32::timer::GeneralInstance4Channel,
    C: embassy_stm32::timer::TimerChannel,
{
    CapturePin::new(pin, Pull::Down)
}

/// Helper for main: the burst pin.
pub fn burst_pin<'d>(pin: Peri<'d, impl embassy_stm32::timer::TimerPin<TIM1, Ch1>>) -> PwmPin<'d, TIM1, Ch1> {
    PwmPin::new(pin, OutputType::PushPull)
}

/// Helper for main: the glasses' burst pin (the head's emitter).
pub fn glasses_pin<'d>(pin: Peri<'d, impl embassy_stm32::timer::TimerPin<TIM1, Ch2>>) -> PwmPin<'d, TIM1, Ch2> {
    PwmPin::new(pin, OutputType::PushPull)
}
