//! From capture-timer ticks to nanoseconds, as the board converts them (and the simulator
//! reproduces, bit for bit).

/// Nanoseconds per tick of a timer counting at `clock_hz`.
pub fn ns_per_tick(clock_hz: u32) -> f32 {
    1e9 / clock_hz as f32
}

/// A capture value in ns (truncated, as the arrival is somewhere within its tick).
pub fn ticks_to_ns(ticks: u32, ns_per_tick: f32) -> u32 {
    (ticks as f32 * ns_per_tick) as u32
}

/// The tick rate of the 32-bit capture timer (TIM2, receivers 0–3): the APB1 timer clock.
pub const FAST_TIMER_HZ: u32 = 96_000_000;
/// The tick rate of the 16-bit capture timer (TIM3, receivers 4–7): slow enough that 16 bits
/// span the listening window.
pub const SLOW_TIMER_HZ: u32 = 8_000_000;
