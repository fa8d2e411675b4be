//! From the edges a receiver should see after a burst to the 32-bit words its PIO state machine
//! plays.
//!
//! The base station subtracts the burst's 12.49 µs lead from every capture (docs/hardware.md),
//! so the arrival times the simulator gives (`Heard::arrival_ns`) count from the burst's first
//! rising edge on PA8 — exactly the edge the rig waits for. A receiver may see up to
//! [`MAX_EDGES`] pulses per burst (pickup during the burst, the arrival, an echo, a late edge):
//! the capture interrupt's defects that issue 15 names only show with several edges on one
//! input in one cycle.
//!
//! Per burst a state machine takes a **count word** (the number of pulses, 0 to [`MAX_EDGES`];
//! an empty FIFO reads as 0) and then that many **edge words**:
//!
//! | bits | field | unit |
//! |---|---|---|
//! | 0–21 | delay loop count `n` before the rise | one PIO cycle (8 ns) |
//! | 22–31 | pulse length `m` | 32 PIO cycles (256 ns) |
//!
//! The first pulse rises `n + 1 + FIRST_LATENCY_CYCLES` cycles after the burst's edge reaches
//! the Pico's pad, each later one `n + 1 + GAP_LATENCY_CYCLES` cycles after the previous pulse
//! fell; a pulse lasts `(m + 1) · 32 + 2` cycles. Rises land on the 8 ns grid (±4 ns from the
//! time asked); their phase against the burst's edge (asynchronous to the Pico's clock) adds up
//! to one cycle, uniformly — 2.3 ns rms, 0.8 µm of range at 343 m/s. Lengths land on the 256 ns
//! grid, rounded up: the board's capture timers see only the rising edges, so a length only has
//! to keep one pulse apart from the next.

/// The PIO clock: the RP2040's system clock at embassy-rp's default, 125 MHz.
pub const PIO_HZ: u32 = 125_000_000;
/// One PIO cycle: the schedule's resolution.
pub const NS_PER_CYCLE: u32 = 1_000_000_000 / PIO_HZ;

/// Pulses a receiver can see per burst. Three covers pickup + arrival + echo; with the count
/// word that is four words a cycle, and two cycles (the one playing and the next) fit the
/// joined 8-word TX FIFO.
pub const MAX_EDGES: usize = 3;
/// Words per receiver per cycle at most: the count word and the edge words.
pub const MAX_WORDS: usize = 1 + MAX_EDGES;

/// Cycles from the burst's edge at the pad to the first rise besides the delay loop: 2 for the
/// GPIO input synchroniser, then one each for `wait 1 pin`, `pull noblock`, `irq nowait`,
/// `out y` (the count), `jmp y--`, `mov isr`, `pull block`, `out x` (the delay) and `set pins`
/// (the RP2040 datasheet, §3.4: every instruction takes one cycle unless it stalls, and neither
/// pull stalls: the words are in the FIFO before the burst). The bench measures the remainder
/// (pads, the STM32's input filter) with the rest of the chain's constant delay, which the
/// transducer-delay calibration absorbs.
pub const FIRST_LATENCY_CYCLES: u32 = 11;
/// Cycles from a pulse's fall to the next rise besides the delay loop: `mov y, isr`,
/// `jmp count`, `jmp y--`, `mov isr, y`, `pull block`, `out x` and `set pins`.
pub const GAP_LATENCY_CYCLES: u32 = 7;

/// Bits of the delay loop count.
const DELAY_BITS: u32 = 22;
/// Bits of the pulse length.
const LENGTH_BITS: u32 = 32 - DELAY_BITS;
/// PIO cycles per unit of pulse length (`jmp y-- hold [31]`).
pub const PULSE_UNIT_CYCLES: u32 = 32;
/// Cycles of a pulse besides the hold loop: `out y` (the length) and `set pins, 0`.
const PULSE_FIXED_CYCLES: u32 = 2;

/// How long the comparator output stays high after an arrival: about the burst's 200 µs
/// envelope above the threshold (docs/hardware.md, the receiver chain).
pub const PULSE_NS: u32 = 200_000;

/// The earliest first rise after the burst's edge, ns.
pub const MIN_ARRIVAL_NS: u32 = (1 + FIRST_LATENCY_CYCLES) * NS_PER_CYCLE;
/// The shortest pulse (one unit), ns.
pub const MIN_PULSE_NS: u32 = (PULSE_UNIT_CYCLES + PULSE_FIXED_CYCLES) * NS_PER_CYCLE;
/// The longest pulse (the length field full), ns: 262 µs.
pub const MAX_PULSE_NS: u32 = ((1 << LENGTH_BITS) * PULSE_UNIT_CYCLES + PULSE_FIXED_CYCLES) * NS_PER_CYCLE;
/// The shortest time from a pulse's fall to the next rise, ns.
pub const MIN_GAP_NS: u32 = (1 + GAP_LATENCY_CYCLES) * NS_PER_CYCLE;
/// The latest a pulse may end after the burst's edge, ns. The state machine watches for the
/// next burst only once its last pulse is over, so the host must also keep this before the
/// board's next burst (less the ~50 µs of quiet the state machine waits for): the board's
/// shortest cycle is 6.5 ms, and the window tests lengthen it. 12 ms takes an edge past TIM3's
/// 8.19 ms wrap with room; the delay field itself would hold 33 ms.
pub const MAX_END_NS: u32 = 12_000_000;

const _: () = assert!(PULSE_NS <= MAX_PULSE_NS, "the default pulse fits its field");
const _: () = assert!(
    (MAX_END_NS / NS_PER_CYCLE) < 1 << DELAY_BITS,
    "any delay fits its field"
);

/// One pulse on a receiver input: it rises `at_ns` after the burst's first rising edge (the
/// moment the board's captures count from) and stays high `length_ns`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Edge {
    /// The rise, ns after the burst's edge.
    pub at_ns: u32,
    /// How long the line stays high, ns.
    pub length_ns: u32,
}

impl Edge {
    /// An arrival as the comparator gives it: high for the burst's envelope ([`PULSE_NS`]).
    pub const fn arrival(at_ns: u32) -> Edge {
        Edge {
            at_ns,
            length_ns: PULSE_NS,
        }
    }
}

/// A receiver's pulses in one burst, in time order, at most [`MAX_EDGES`]. Unused slots stay
/// zero, so two lists with the same pulses compare equal.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Edges {
    len: u8,
    edges: [Edge; MAX_EDGES],
}

impl Edges {
    /// Heard nothing.
    pub const NONE: Edges = Edges {
        len: 0,
        edges: [Edge { at_ns: 0, length_ns: 0 }; MAX_EDGES],
    };

    /// One arrival ([`Edge::arrival`]), or nothing.
    pub fn arrival(at_ns: Option<u32>) -> Edges {
        let mut e = Edges::NONE;
        if let Some(t) = at_ns {
            e.edges[0] = Edge::arrival(t);
            e.len = 1;
        }
        e
    }

    /// The pulses given, or `None` if there are more than [`MAX_EDGES`]. Their order and
    /// spacing are checked where they are played ([`words`]), not here.
    pub fn new(edges: &[Edge]) -> Option<Edges> {
        let mut e = Edges::NONE;
        e.edges.get_mut(..edges.len())?.copy_from_slice(edges);
        e.len = edges.len() as u8;
        Some(e)
    }

    /// The pulses.
    pub fn as_slice(&self) -> &[Edge] {
        &self.edges[..usize::from(self.len)]
    }

    /// The first rise, ns: the receiver's true first arrival when the list has no pickup.
    pub fn first_ns(&self) -> Option<u32> {
        self.as_slice().first().map(|e| e.at_ns)
    }

    /// When the last pulse falls, ns after the burst's edge (0 without pulses).
    pub fn end_ns(&self) -> u32 {
        self.as_slice()
            .last()
            .map_or(0, |e| e.at_ns.saturating_add(e.length_ns))
    }
}

/// Why a receiver's pulses cannot be played.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ScheduleError {
    /// The first rise is earlier than the state machine's latency allows ([`MIN_ARRIVAL_NS`]).
    TooEarly {
        /// The rise asked for, ns.
        at_ns: u32,
    },
    /// A pulse ends after [`MAX_END_NS`].
    TooLate {
        /// The rise asked for, ns.
        at_ns: u32,
    },
    /// A rise comes before, or less than [`MIN_GAP_NS`] after, the previous pulse's fall (the
    /// pulses must be in time order and apart).
    TooClose {
        /// The rise asked for, ns.
        at_ns: u32,
    },
    /// A length outside [`MIN_PULSE_NS`]..=[`MAX_PULSE_NS`].
    Length {
        /// The length asked for, ns.
        length_ns: u32,
    },
}

/// The words for one receiver and one burst: `[count, edge words …]`, `count + 1` of them
/// used. Without pulses this is the single word 0, which is also what the state machine reads
/// from an empty FIFO.
pub fn words(edges: &Edges) -> Result<([u32; MAX_WORDS], usize), ScheduleError> {
    let mut out = [0; MAX_WORDS];
    out[0] = u32::from(edges.len);
    // When the previous pulse fell, in cycles after the burst's edge, and the latency from
    // there to the next rise (the first pulse counts from the burst's edge).
    let (mut from, mut latency) = (0u32, FIRST_LATENCY_CYCLES);
    for (slot, edge) in out[1..].iter_mut().zip(edges.as_slice()) {
        if !(MIN_PULSE_NS..=MAX_PULSE_NS).contains(&edge.length_ns) {
            return Err(ScheduleError::Length {
                length_ns: edge.length_ns,
            });
        }
        if edge.at_ns.saturating_add(edge.length_ns) > MAX_END_NS {
            return Err(ScheduleError::TooLate { at_ns: edge.at_ns });
        }
        // Nearest cycle: the error is then at most half a cycle (4 ns) on top of the phase.
        let rise = (edge.at_ns + NS_PER_CYCLE / 2) / NS_PER_CYCLE;
        let n = rise.checked_sub(from + 1 + latency).ok_or(if from == 0 {
            ScheduleError::TooEarly { at_ns: edge.at_ns }
        } else {
            ScheduleError::TooClose { at_ns: edge.at_ns }
        })?;
        // Whole units, rounded up: a pulse is never shorter than asked.
        let length_cycles = (edge.length_ns.div_ceil(NS_PER_CYCLE)).saturating_sub(PULSE_FIXED_CYCLES);
        let units = length_cycles.div_ceil(PULSE_UNIT_CYCLES).max(1);
        *slot = n | (units - 1) << DELAY_BITS;
        from = rise + units * PULSE_UNIT_CYCLES + PULSE_FIXED_CYCLES;
        latency = GAP_LATENCY_CYCLES;
    }
    Ok((out, 1 + usize::from(edges.len)))
}

/// What a state machine plays from `words` (as [`words`] makes them): each pulse's rise and
/// fall, ns after the burst's edge, counted from the program's cycles — the inverse of
/// [`words`] up to the grids. `None` if the count word is over [`MAX_EDGES`] or the words are
/// fewer than it says.
pub fn played(words: &[u32]) -> Option<([(u32, u32); MAX_EDGES], usize)> {
    let (&count, rest) = words.split_first()?;
    let count = usize::try_from(count).ok().filter(|&c| c <= MAX_EDGES)?;
    let mut out = [(0, 0); MAX_EDGES];
    let (mut from, mut latency) = (0u32, FIRST_LATENCY_CYCLES);
    for (slot, &w) in out.iter_mut().zip(rest.get(..count)?) {
        let n = w & ((1 << DELAY_BITS) - 1);
        let m = w >> DELAY_BITS;
        let rise = from + n + 1 + latency;
        let fall = rise + (m + 1) * PULSE_UNIT_CYCLES + PULSE_FIXED_CYCLES;
        *slot = (rise * NS_PER_CYCLE, fall * NS_PER_CYCLE);
        from = fall;
        latency = GAP_LATENCY_CYCLES;
    }
    Some((out, count))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn edges(list: &[(u32, u32)]) -> Edges {
        let v: [Edge; MAX_EDGES] = core::array::from_fn(|i| {
            list.get(i)
                .map_or(Edge::default(), |&(at_ns, length_ns)| Edge { at_ns, length_ns })
        });
        Edges::new(&v[..list.len()]).unwrap()
    }

    #[test]
    fn resolution_is_eight_ns_at_125_mhz() {
        assert_eq!(NS_PER_CYCLE, 8);
    }

    #[test]
    fn no_arrival_is_the_empty_fifo_word() {
        assert_eq!(words(&Edges::NONE), Ok(([0; MAX_WORDS], 1)));
        assert_eq!(words(&Edges::arrival(None)), Ok(([0; MAX_WORDS], 1)));
        assert_eq!(played(&[0]).map(|(_, n)| n), Some(0));
    }

    #[test]
    fn a_typical_flight_has_the_expected_words() {
        // 1.5 ms: 187 500 cycles, of which 12 are the latency and the loop's last turn; the
        // 200 µs pulse is 25 000 cycles, 2 fixed, so 782 units of 32 (rounded up), field 781.
        let (w, n) = words(&Edges::arrival(Some(1_500_000))).unwrap();
        assert_eq!(n, 2);
        assert_eq!(w, [1, (187_500 - 12) | 781 << 22, 0, 0]);
        let (p, k) = played(&w[..n]).unwrap();
        assert_eq!(k, 1);
        assert_eq!(p[0].0, 1_500_000);
        assert_eq!(p[0].1 - p[0].0, (782 * 32 + 2) * 8);
    }

    #[test]
    fn three_pulses_are_exact_words_in_order() {
        // Pickup at 20 µs for 100 µs, the arrival at 1 ms, an echo at 1.6 ms.
        let e = edges(&[(20_000, 100_000), (1_000_000, PULSE_NS), (1_600_000, PULSE_NS)]);
        let (w, n) = words(&e).unwrap();
        assert_eq!(n, 4);
        // Pickup: rise at cycle 2 500 (n = 2 500 − 12), 12 500 cycles → 391 units; it falls at
        // 2 500 + 391·32 + 2 = 15 014.
        assert_eq!(w[0], 3);
        assert_eq!(w[1], (2_500 - 12) | 390 << 22);
        // The arrival at 125 000 counts from that fall: n = 125 000 − 15 014 − 8.
        assert_eq!(w[2], (125_000 - 15_014 - 8) | 781 << 22);
        // Its fall: 125 000 + 782·32 + 2 = 150 026; the echo at 200 000.
        assert_eq!(w[3], (200_000 - 150_026 - 8) | 781 << 22);
        let (p, k) = played(&w[..n]).unwrap();
        assert_eq!(k, 3);
        assert_eq!([p[0].0, p[1].0, p[2].0], [20_000, 1_000_000, 1_600_000]);
        assert_eq!(p[0].1, 15_014 * 8);
    }

    #[test]
    fn rises_land_within_half_a_cycle_and_pulses_are_never_shorter() {
        // Three pulses across the 5 ms window, at times and lengths off the grids.
        let mut t = MIN_ARRIVAL_NS;
        while t < 1_500_000 {
            let list = [
                (t, 1_003 + t % 5_000),
                (t + 1_700_003, 30_001),
                (t + 3_100_007, PULSE_NS),
            ];
            let (w, n) = words(&edges(&list)).unwrap();
            let (p, _) = played(&w[..n]).unwrap();
            for (&(at, len), &(rise, fall)) in list.iter().zip(&p) {
                assert!(rise.abs_diff(at) <= NS_PER_CYCLE / 2, "{at} ns played at {rise} ns");
                assert!(fall - rise >= len, "{len} ns long played {} ns", fall - rise);
                assert!(fall - rise < len + (PULSE_UNIT_CYCLES + 1) * NS_PER_CYCLE);
            }
            t += 9_973;
        }
    }

    #[test]
    fn the_limits_are_exact() {
        let first = |at_ns| words(&edges(&[(at_ns, PULSE_NS)]));
        assert!(first(MIN_ARRIVAL_NS).is_ok());
        assert_eq!(
            first(MIN_ARRIVAL_NS - NS_PER_CYCLE),
            Err(ScheduleError::TooEarly {
                at_ns: MIN_ARRIVAL_NS - NS_PER_CYCLE
            })
        );
        assert!(first(MAX_END_NS - PULSE_NS).is_ok());
        assert_eq!(
            first(MAX_END_NS - PULSE_NS + 1),
            Err(ScheduleError::TooLate {
                at_ns: MAX_END_NS - PULSE_NS + 1
            })
        );
        assert_eq!(first(u32::MAX), Err(ScheduleError::TooLate { at_ns: u32::MAX }));
        // Lengths.
        assert!(words(&edges(&[(10_000, MIN_PULSE_NS)])).is_ok());
        assert!(words(&edges(&[(10_000, MAX_PULSE_NS)])).is_ok());
        for bad in [0, MIN_PULSE_NS - 1, MAX_PULSE_NS + 1] {
            assert_eq!(
                words(&edges(&[(10_000, bad)])),
                Err(ScheduleError::Length { length_ns: bad })
            );
        }
        // The longest pulse's field is all ones, and the decoding agrees on its length.
        let (w, _) = words(&edges(&[(10_000, MAX_PULSE_NS)])).unwrap();
        assert_eq!(w[1] >> 22, (1 << 10) - 1);
        let (p, _) = played(&w[..2]).unwrap();
        assert_eq!(p[0].1 - p[0].0, MAX_PULSE_NS);
    }

    #[test]
    fn pulses_out_of_order_or_touching_are_refused() {
        // The shortest pulse at 10 µs falls at a known cycle; the next may rise MIN_GAP_NS on.
        let (w, _) = words(&edges(&[(10_000, MIN_PULSE_NS)])).unwrap();
        let fall = played(&w[..2]).unwrap().0[0].1;
        assert!(words(&edges(&[(10_000, MIN_PULSE_NS), (fall + MIN_GAP_NS, MIN_PULSE_NS)])).is_ok());
        let close = fall + MIN_GAP_NS - NS_PER_CYCLE;
        assert_eq!(
            words(&edges(&[(10_000, MIN_PULSE_NS), (close, MIN_PULSE_NS)])),
            Err(ScheduleError::TooClose { at_ns: close })
        );
        // Overlapping, and backwards in time.
        assert_eq!(
            words(&edges(&[(1_000_000, PULSE_NS), (1_100_000, PULSE_NS)])),
            Err(ScheduleError::TooClose { at_ns: 1_100_000 })
        );
        assert_eq!(
            words(&edges(&[(2_000_000, PULSE_NS), (1_000_000, PULSE_NS)])),
            Err(ScheduleError::TooClose { at_ns: 1_000_000 })
        );
    }

    #[test]
    fn a_list_holds_at_most_max_edges() {
        let e = [Edge::arrival(1_000_000); MAX_EDGES + 1];
        assert!(Edges::new(&e[..MAX_EDGES]).is_some());
        assert_eq!(Edges::new(&e), None);
        assert_eq!(Edges::new(&[]), Some(Edges::NONE));
    }

    #[test]
    fn malformed_words_are_not_played() {
        // A count over MAX_EDGES, or fewer edge words than the count says.
        assert_eq!(played(&[MAX_EDGES as u32 + 1, 0, 0, 0, 0]), None);
        assert_eq!(played(&[2, 0]), None);
        assert_eq!(played(&[]), None);
    }
}
