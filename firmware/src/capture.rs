//! The ultrasonic front end: the 40 kHz burst and the receivers' first arrivals.
//!
//! * TIM1 channel 1 (PA8) drives the transducer's gate driver with a burst of
//!   [`BURST_CYCLES`] periods at 40 kHz, in one-pulse mode with the repetition counter, so the
//!   burst length is exact and needs no interrupt. PWM mode 2 keeps the pin low at rest.
//! * TIM1's trigger output fires when its counter is enabled; TIM2 and TIM3 take it as a reset
//!   (slave reset mode, ITR0), so their counters restart at the burst in hardware and a capture
//!   value is the time of flight itself.
//! * TIM2 (32-bit, 96 MHz, 10.4 ns per tick) captures receivers 0–3 on PA15, PB3, PB10, PA3;
//!   TIM3 (16-bit, prescaled to 8 MHz, 125 ns, wrapping after 8.2 ms, beyond the 5 ms window)
//!   captures receivers 4–7 on PA6, PA7, PB0, PB1.
//! * Each receiver's comparator output rises on the first arrival. The capture interrupt
//!   stores the first capture of each channel and disables that channel, so later echoes cannot
//!   overwrite it.

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
use pen_core::Ranging;
use pen_core::ranging::{SLOW_TIMER_HZ, ns_per_tick, ticks_to_ns};
use pen_protocol::MAX_RECEIVERS;

/// Periods of 40 kHz per burst: long enough for the transducer to ring up, short enough to end
/// before the nearest receiver hears it.
pub const BURST_CYCLES: u16 = 8;
/// The transducer's resonance.
const BURST_HZ: u32 = 40_000;

const NO_CAPTURE: u32 = u32::MAX;
/// The first capture of each receiver since the last burst, in timer ticks.
static CAPTURES: [AtomicU32; MAX_RECEIVERS] = [const { AtomicU32::new(NO_CAPTURE) }; MAX_RECEIVERS];

const CHANNELS: [Channel; 4] = [Channel::Ch1, Channel::Ch2, Channel::Ch3, Channel::Ch4];

/// Stores the first capture of each channel of a timer and disables the channel.
fn on_capture(regs: pac::timer::TimGp16, first_receiver: usize) {
    let sr = regs.sr().read();
    for ch in 0..4 {
        if sr.ccif(ch) {
            CAPTURES[first_receiver + ch].store(regs.ccr(ch).read().ccr() as u32, Ordering::Relaxed);
            regs.ccer().modify(|w| w.set_cce(ch, false));
            regs.dier().modify(|w| w.set_ccie(ch, false));
        }
    }
    // Flags are cleared by writing 0; the ones written as read stay as they are.
    regs.sr().modify(|w| (0..4).for_each(|ch| w.set_ccif(ch, false)));
}

/// TIM2's capture interrupt: receivers 0–3.
pub struct Tim2Captures;

impl Handler<interrupt::typelevel::TIM2> for Tim2Captures {
    unsafe fn on_interrupt() {
        // TIM2's capture registers are 32 bits wide; read through the 32-bit view.
        let regs = pac::TIM2;
        let sr = regs.sr().read();
        for (ch, capture) in CAPTURES.iter().enumerate().take(4) {
            if sr.ccif(ch) {
                capture.store(regs.ccr(ch).read(), Ordering::Relaxed);
                regs.ccer().modify(|w| w.set_cce(ch, false));
                regs.dier().modify(|w| w.set_ccie(ch, false));
            }
        }
        regs.sr().modify(|w| (0..4).for_each(|ch| w.set_ccif(ch, false)));
    }
}

/// TIM3's capture interrupt: receivers 4–7.
pub struct Tim3Captures;

impl Handler<interrupt::typelevel::TIM3> for Tim3Captures {
    unsafe fn on_interrupt() {
        on_capture(pac::TIM3, 4);
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
    /// PA8: TIM1 channel 1, the burst.
    pub burst: PwmPin<'d, TIM1, Ch1>,
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
    _pins: Pins<'d>,
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
        burst.set_repetition_counter(BURST_CYCLES - 1);
        // One-pulse mode: the counter stops at the update event after RCR + 1 periods.
        burst.regs_advanced().cr1().modify(|w| w.set_opm(true));
        burst.set_master_mode(MasterMode::ENABLE);
        burst.enable_channel(Channel::Ch1, true);
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
        tim2.set_slave_mode(SlaveMode::RESET_MODE);
        tim2.set_trigger_source(TriggerSource::ITR0);
        tim3.set_slave_mode(SlaveMode::RESET_MODE);
        tim3.set_trigger_source(TriggerSource::ITR0);
        tim2.generate_update_event();
        tim3.generate_update_event();
        tim2.start();
        tim3.start();
        // The clock tree gives TIM2 the 96 MHz the core's FAST_TIMER_HZ assumes.
        let ns_per_tick_tim2 = ns_per_tick(tim2.get_clock_frequency().0);
        let ns_per_tick_tim3 = ns_per_tick(SLOW_TIMER_HZ);
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
            _pins: pins,
        }
    }

    /// Receivers in use (from the configuration).
    pub fn set_receivers(&mut self, receivers: usize) {
        self.receivers = receivers.min(MAX_RECEIVERS);
    }

    fn arm(&mut self, enable: bool) {
        for (i, ch) in CHANNELS.into_iter().enumerate() {
            let on = enable && i < self.receivers;
            self.tim2.clear_input_interrupt(ch);
            self.tim2.enable_channel(ch, on);
            self.tim2.enable_input_interrupt(ch, on);
            let on = enable && i + 4 < self.receivers;
            self.tim3.clear_input_interrupt(ch);
            self.tim3.enable_channel(ch, on);
            self.tim3.enable_input_interrupt(ch, on);
        }
    }
}

impl Ranging for BoardRanging<'_> {
    fn fire(&mut self) {
        for c in &CAPTURES {
            c.store(NO_CAPTURE, Ordering::Relaxed);
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
                *slot = Some(ticks_to_ns(ticks, ns_per_tick));
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
