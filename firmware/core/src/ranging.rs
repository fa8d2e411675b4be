//! The ranging stage: capture-timer ticks to nanoseconds (as the board converts them, and the
//! simulator reproduces bit for bit), times of flight after the transducer delays, and ranges at
//! the speed of sound.

/// The speed of sound in dry air at `temperature_c` °C, m/s: 331.3·√(1 + T/273.15).
/// A wrong temperature scales every range: 0.17 % per °C.
pub fn speed_of_sound_m_s(temperature_c: f32) -> f32 {
    331.3 * crate::math::sqrt(1.0 + temperature_c / 273.15)
}

/// Time of flight in ns: the capture time after the burst minus the receiver's transducer and
/// detector delay. `None` when the arrival is earlier than the delay (a glitch, not sound).
pub fn time_of_flight_ns(arrival_ns: u32, delay_ns: u32) -> Option<u32> {
    arrival_ns.checked_sub(delay_ns)
}

/// The range in mm for a time of flight in ns at `speed_m_s` (m/s equals µm/ms, so
/// mm = ns · m/s · 10⁻⁶).
pub fn range_mm(tof_ns: u32, speed_m_s: f32) -> f32 {
    tof_ns as f32 * speed_m_s * 1e-6
}

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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn speed_of_sound_at_known_temperatures() {
        assert!((speed_of_sound_m_s(0.0) - 331.3).abs() < 1e-4);
        // 343.2 m/s at 20 °C, as the design states.
        assert!((speed_of_sound_m_s(20.0) - 343.2).abs() < 0.05);
        // 0.17 % per °C around room temperature.
        let per_degree = speed_of_sound_m_s(21.0) / speed_of_sound_m_s(20.0) - 1.0;
        assert!((per_degree - 0.0017).abs() < 0.0001, "{per_degree}");
    }

    #[test]
    fn ranges_from_captures() {
        // 1 ms at 343.2 m/s is 343.2 mm.
        assert!((range_mm(1_000_000, 343.2) - 343.2).abs() < 1e-3);
        assert_eq!(time_of_flight_ns(1_012_500, 12_500), Some(1_000_000));
        assert_eq!(time_of_flight_ns(10_000, 12_500), None);
    }
}
