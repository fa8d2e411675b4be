//! The board's arithmetic: which crystal a measurement shows, and device time from a 32-bit
//! counter and its half periods.

use pen_core::board::{Crystal, crystal_from, ticks, usb_current_ma};

/// HSI ticks for `cycles` crystal cycles at `hse_hz`, with the HSI `hsi_error` off (0.01 = +1 %).
fn measure(hse_hz: f64, cycles: u32, hsi_error: f64) -> u32 {
    (16e6 * (1.0 + hsi_error) * cycles as f64 / hse_hz).round() as u32
}

#[test]
fn both_crystals_are_told_apart_over_the_hsis_spread() {
    // The board's measurement: 8 periods of HSE / 25 (RTCPRE), four times.
    let cycles = 25 * 8 * 4;
    for err in [-0.02, -0.01, 0.0, 0.01, 0.02] {
        assert_eq!(
            crystal_from(measure(25e6, cycles, err), cycles),
            Some(Crystal::Mhz25),
            "{err}"
        );
        assert_eq!(
            crystal_from(measure(8e6, cycles, err), cycles),
            Some(Crystal::Mhz8),
            "{err}"
        );
    }
}

#[test]
fn other_crystals_and_none_are_refused() {
    let cycles = 800;
    for hz in [12e6, 16e6, 24e6, 26.5e6, 7e6] {
        assert_eq!(crystal_from(measure(hz, cycles, 0.0), cycles), None, "{hz}");
    }
    // No crystal: no edge captured, or no time between.
    assert_eq!(crystal_from(0, cycles), None);
    assert_eq!(crystal_from(1000, 0), None);
}

#[test]
fn the_pll_gives_96_and_48_mhz_from_either_crystal() {
    for c in [Crystal::Mhz8, Crystal::Mhz25] {
        let (m, n) = c.pll();
        let vco_in = c.hz() / m;
        assert!((1_000_000..=2_000_000).contains(&vco_in), "{c:?}: VCO input {vco_in}");
        assert_eq!(vco_in * n, 192_000_000, "{c:?}");
        assert_eq!(vco_in * n / 2, 96_000_000);
        assert_eq!(vco_in * n / 4, 48_000_000);
    }
}

#[test]
fn time_counts_on_across_both_boundaries_and_a_late_interrupt() {
    const HALF: u32 = 1 << 31;
    // In step: half periods counted as the counter passes them.
    assert_eq!(ticks(0, 5), 5);
    assert_eq!(ticks(1, HALF + 5), HALF as u64 + 5);
    assert_eq!(ticks(2, 5), (1u64 << 32) + 5);
    // The counter has passed the midpoint, the interrupt not yet run: still monotonic.
    assert_eq!(ticks(0, HALF + 5), HALF as u64 + 5);
    // Wrapped, the overflow not yet counted.
    assert_eq!(ticks(1, 5), (1u64 << 32) + 5);
    // Every read around both boundaries, with and without the interrupt's count, in order.
    let mut last = 0;
    for (half, counter) in [
        (0, HALF - 2),
        (0, HALF - 1),
        (0, HALF),
        (1, HALF),
        (1, HALF + 1),
        (1, u32::MAX),
        (1, 0),
        (2, 0),
        (2, 1),
    ] {
        let t = ticks(half, counter);
        assert!(t >= last, "({half}, {counter:#x}): {t} after {last}");
        last = t;
    }
}

#[test]
fn the_declared_current_covers_the_measured_draw_per_receiver_count() {
    // The bench's figures (issue 45): about 75 mA with four receivers, up to 125 with six.
    assert!(usb_current_ma(4) >= 75, "{}", usb_current_ma(4));
    assert!(usb_current_ma(6) >= 125, "{}", usb_current_ma(6));
    // More receivers, more current; USB's limit never passed; whole 10 mA.
    for n in 0..8 {
        assert!(usb_current_ma(n + 1) > usb_current_ma(n));
    }
    assert!(usb_current_ma(8) <= 500 && usb_current_ma(usize::MAX) <= 500);
    assert!((0..=8).all(|n| usb_current_ma(n).is_multiple_of(10)));
    assert_eq!(
        (usb_current_ma(4), usb_current_ma(6), usb_current_ma(8)),
        (100, 130, 160)
    );
}
