//! Arithmetic of the board's own peripherals, kept here so that the host tests it: the crystal
//! the board turns out to have, and the 64-bit device time built on a 32-bit timer.

/// The crystals the base station supports: WeAct's Black Pill has shipped with 25 MHz and, in
/// later batches, 8 MHz. Both give the 96 MHz system clock and USB's 48 MHz through the PLL.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Crystal {
    /// 8 MHz, the later batches'.
    Mhz8,
    /// 25 MHz, WeAct's original.
    Mhz25,
}

impl Crystal {
    /// Its frequency, Hz.
    pub const fn hz(self) -> u32 {
        match self {
            Crystal::Mhz8 => 8_000_000,
            Crystal::Mhz25 => 25_000_000,
        }
    }

    /// The PLL's input divider (M) that gives the VCO a 1 MHz (25 MHz crystal) or 2 MHz (8 MHz
    /// crystal) input, and the multiplier (N) that takes it to 192 MHz: P = 2 gives 96 MHz, Q = 4
    /// gives USB's 48 MHz (RM0383 §6.3.2, VCO input 1–2 MHz, output 100–432 MHz).
    pub const fn pll(self) -> (u32, u32) {
        match self {
            Crystal::Mhz8 => (4, 96),
            Crystal::Mhz25 => (25, 192),
        }
    }
}

/// How far a measured crystal may be from its nominal frequency and still be taken for it. The
/// HSI it is measured against is factory-trimmed to ±1 % at 25 °C (DS10314, HSI oscillator
/// characteristics) and drifts a little with temperature; a crystal is within 0.01 %. 3 % leaves
/// the HSI that room and still refuses a 24 MHz crystal (4 % below 25).
pub const CRYSTAL_TOLERANCE_PERCENT: u32 = 3;

/// The crystal, from a measurement of it against the HSI: `hsi_ticks` counts of the 16 MHz HSI
/// in `hse_cycles` cycles of the crystal (as TIM11 captures the HSE divided by RTCPRE); `None`
/// when it is neither crystal (or no crystal runs: zero cycles).
pub fn crystal_from(hsi_ticks: u32, hse_cycles: u32) -> Option<Crystal> {
    const HSI_HZ: u64 = 16_000_000;
    if hsi_ticks == 0 || hse_cycles == 0 {
        return None;
    }
    let hz = HSI_HZ * hse_cycles as u64 / hsi_ticks as u64;
    [Crystal::Mhz8, Crystal::Mhz25].into_iter().find(|c| {
        let nominal = c.hz() as u64;
        hz.abs_diff(nominal) * 100 <= nominal * CRYSTAL_TOLERANCE_PERCENT as u64
    })
}

/// Device time in ticks from a 32-bit counter and a count of its half periods.
///
/// `half_periods` counts 2³¹-tick halves since start-up: the counter's overflow and its
/// midpoint (a compare at 2³¹) each add one, in the timer's interrupt. When it is even the
/// counter should be in its lower half, when odd in its upper; a counter read that disagrees
/// has passed the next boundary before the interrupt counted it, and is taken as the next half.
/// So the time is right as long as the interrupt runs within half a period (35 minutes at
/// 1 MHz) of each boundary — a 4 s flash erase that stalls it cannot lose a period.
pub const fn ticks(half_periods: u32, counter: u32) -> u64 {
    ((half_periods as u64) << 31) + ((counter ^ ((half_periods & 1) << 31)) as u64)
}

/// The base station's current budget from USB, mA, without the receivers: the Black Pill at
/// 96 MHz with its LEDs and regulator, the two TC4427s at rest and the boost converter's share
/// of the bursts, with room to spare.
pub const BASE_CURRENT_MA: u16 = 40;
/// Each receiver module's budget, mA: its OPA2365's two amplifiers (4.6 mA typical, 5 mA at
/// most each: TI OPA2365 datasheet, SBOS365) and its TLV3501 comparator (3.2 mA typical: TI
/// TLV3501 datasheet, SBOS321), rounded up to 15.
pub const RECEIVER_CURRENT_MA: u16 = 15;

/// What the device declares to USB (bMaxPower) for `receivers` receivers: the budget rounded up
/// to 10 mA, at most USB 2.0's 500 mA. Measured on the bench (issue 45): about 75 mA with four
/// receivers and 100–125 mA with six, so 100 and 130 cover them.
pub const fn usb_current_ma(receivers: usize) -> u16 {
    let n = if receivers > 8 { 8 } else { receivers as u16 };
    let ma = BASE_CURRENT_MA + RECEIVER_CURRENT_MA * n;
    let rounded = ma.div_ceil(10) * 10;
    if rounded > 500 { 500 } else { rounded }
}
