//! From a time of flight to the 32-bit word a receiver's PIO state machine plays.
//!
//! The base station subtracts the burst's 12.49 µs lead from every capture (docs/hardware.md),
//! so the arrival times the simulator gives (`Heard::arrival_ns`) count from the burst's first
//! rising edge on PA8 — exactly the edge the rig waits for. The state machine, after that edge,
//! counts down a delay, sets its pin to the word's level (1: an arrival; 0: this receiver heard
//! nothing), holds it for the pulse's length and drops it again:
//!
//! | bits | field | unit |
//! |---|---|---|
//! | 0–19 | delay loop count `n` | one PIO cycle (8 ns) |
//! | 20 | level | 1 = rising edge, 0 = none |
//! | 21–31 | pulse length `m` | 32 PIO cycles (256 ns) |
//!
//! The pin rises `n + 1 + LATENCY_CYCLES` cycles after the burst's edge reaches the Pico's pad
//! (the delay loop `jmp x--` runs `n + 1` times) and falls `(m + 1) · 32 + 1` cycles later. The
//! edge lands on the 8 ns grid; its phase against the burst's edge (which is asynchronous to the
//! Pico's clock) adds up to one cycle, uniformly — 2.3 ns rms, 0.8 µm of range at 343 m/s.

/// The PIO clock: the RP2040's system clock at embassy-rp's default, 125 MHz.
pub const PIO_HZ: u32 = 125_000_000;
/// One PIO cycle: the schedule's resolution.
pub const NS_PER_CYCLE: u32 = 1_000_000_000 / PIO_HZ;

/// Cycles from the burst's edge at the pad to the receiver pin's edge besides the delay loop:
/// 2 for the GPIO input synchroniser, then one each for `wait 1 pin`, `pull noblock`,
/// `irq nowait`, `out x` and `out pins` (the RP2040 datasheet, §3.4: every instruction takes one
/// cycle unless it stalls). The bench measures the remainder (pads, the STM32's input filter)
/// with the rest of the chain's constant delay, which the transducer-delay calibration absorbs.
pub const LATENCY_CYCLES: u32 = 7;

/// Bits of the delay loop count.
const DELAY_BITS: u32 = 20;
/// The level bit.
const LEVEL_BIT: u32 = DELAY_BITS;
/// Bits of the pulse length.
const PULSE_BITS: u32 = 32 - DELAY_BITS - 1;
/// PIO cycles per unit of pulse length (`jmp y-- hold [31]`).
pub const PULSE_UNIT_CYCLES: u32 = 32;

/// How long the comparator output stays high after an arrival: about the burst's 200 µs
/// envelope above the threshold (docs/hardware.md, the receiver chain). The capture timers see
/// only the rising edge; the length matters for the blanking test, where a pickup pulse must
/// still be high when the window opens.
pub const PULSE_NS: u32 = 200_000;

/// [`PULSE_NS`] in the word's units, less the hold loop's last turn.
const PULSE_UNITS: u32 = PULSE_NS.div_ceil(PULSE_UNIT_CYCLES * NS_PER_CYCLE) - 1;
const _: () = assert!(PULSE_UNITS < 1 << PULSE_BITS, "the pulse fits its field");

/// The earliest edge the state machine can make after the burst's edge, ns.
pub const MIN_ARRIVAL_NS: u32 = (1 + LATENCY_CYCLES) * NS_PER_CYCLE;
/// The latest: the delay field's largest count. 8.39 ms, past the board's 5 ms listening window
/// and TIM3's 8.19 ms wrap, so the window-bounding test can send a late edge.
pub const MAX_ARRIVAL_NS: u32 = ((1 << DELAY_BITS) - 1 + 1 + LATENCY_CYCLES) * NS_PER_CYCLE;

// Past TIM3's wrap (8.19 ms), so the window-bounding test can send a late edge.
const _: () = assert!(MAX_ARRIVAL_NS > 8_192_000);

/// Why a time of flight cannot be played.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ScheduleError {
    /// Earlier than the state machine's latency allows ([`MIN_ARRIVAL_NS`]).
    TooEarly {
        /// The arrival asked for, ns.
        arrival_ns: u32,
    },
    /// Later than the delay field holds ([`MAX_ARRIVAL_NS`]).
    TooLate {
        /// The arrival asked for, ns.
        arrival_ns: u32,
    },
}

/// The word for one receiver and one burst: an edge `arrival_ns` after the burst's edge, or
/// none (`None`: the receiver heard nothing; the word is 0, what the state machine also reads
/// from an empty FIFO).
pub fn word(arrival_ns: Option<u32>) -> Result<u32, ScheduleError> {
    let Some(arrival_ns) = arrival_ns else {
        return Ok(0);
    };
    // Nearest cycle: the error is then at most half a cycle (4 ns) on top of the phase.
    let cycles = (u64::from(arrival_ns) + u64::from(NS_PER_CYCLE / 2)) / u64::from(NS_PER_CYCLE);
    let n = cycles
        .checked_sub(u64::from(1 + LATENCY_CYCLES))
        .ok_or(ScheduleError::TooEarly { arrival_ns })?;
    if n >= 1 << DELAY_BITS {
        return Err(ScheduleError::TooLate { arrival_ns });
    }
    Ok(n as u32 | 1 << LEVEL_BIT | PULSE_UNITS << (LEVEL_BIT + 1))
}

/// When the word's edge comes after the burst's edge, ns (`None` if it makes none): the inverse
/// of [`word`] up to the 8 ns grid, from the state machine's cycle count.
pub fn edge_ns(word: u32) -> Option<u32> {
    if word & 1 << LEVEL_BIT == 0 {
        return None;
    }
    let n = word & ((1 << DELAY_BITS) - 1);
    Some((n + 1 + LATENCY_CYCLES) * NS_PER_CYCLE)
}

/// How long the word holds its pin at its level, ns.
pub fn pulse_ns(word: u32) -> u32 {
    let m = word >> (LEVEL_BIT + 1);
    ((m + 1) * PULSE_UNIT_CYCLES + 1) * NS_PER_CYCLE
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn resolution_is_eight_ns_at_125_mhz() {
        assert_eq!(NS_PER_CYCLE, 8);
    }

    #[test]
    fn no_arrival_is_the_empty_fifo_word() {
        assert_eq!(word(None), Ok(0));
        assert_eq!(edge_ns(0), None);
    }

    #[test]
    fn edges_land_within_half_a_cycle_of_the_time_asked() {
        // Every arrival over the board's 5 ms window in steps that are not multiples of 8 ns.
        let mut t = MIN_ARRIVAL_NS;
        while t < 5_000_000 {
            let w = word(Some(t)).unwrap();
            let e = edge_ns(w).unwrap();
            assert!(e.abs_diff(t) <= NS_PER_CYCLE / 2, "{t} ns played at {e} ns");
            t += 997;
        }
    }

    #[test]
    fn a_typical_flight_has_the_expected_bits() {
        // 1.5 ms: 187 500 cycles, of which 8 are the latency and the loop's last turn.
        let w = word(Some(1_500_000)).unwrap();
        assert_eq!(w & 0xF_FFFF, 187_500 - 8);
        assert_eq!(w >> 20 & 1, 1);
        assert_eq!(edge_ns(w), Some(1_500_000));
    }

    #[test]
    fn the_pulse_covers_the_burst_envelope_and_fits_its_field() {
        let w = word(Some(300_000)).unwrap();
        let p = pulse_ns(w);
        assert!((PULSE_NS..PULSE_NS + 300).contains(&p), "pulse {p} ns");
    }

    #[test]
    fn the_limits_are_exact() {
        assert_eq!(edge_ns(word(Some(MIN_ARRIVAL_NS)).unwrap()), Some(MIN_ARRIVAL_NS));
        assert_eq!(
            word(Some(MIN_ARRIVAL_NS - NS_PER_CYCLE)),
            Err(ScheduleError::TooEarly {
                arrival_ns: MIN_ARRIVAL_NS - NS_PER_CYCLE
            })
        );
        assert_eq!(edge_ns(word(Some(MAX_ARRIVAL_NS)).unwrap()), Some(MAX_ARRIVAL_NS));
        assert_eq!(
            word(Some(MAX_ARRIVAL_NS + NS_PER_CYCLE)),
            Err(ScheduleError::TooLate {
                arrival_ns: MAX_ARRIVAL_NS + NS_PER_CYCLE
            })
        );
        assert!(word(Some(u32::MAX)).is_err());
    }
}
