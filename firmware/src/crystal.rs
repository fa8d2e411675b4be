//! Which crystal the board has, measured at start-up before the clocks are set.
//!
//! Black Pills ship with a 25 MHz crystal or, in later batches, an 8 MHz one; a PLL set for the
//! wrong one runs out of range and USB never enumerates. So the HSE is started and measured
//! against the HSI (16 MHz, which runs the core out of reset) the way RM0383 §6.2.11 describes:
//! TIM11's channel 1 takes the HSE divided by RTCPRE (HSE_RTC) as its input and captures every
//! 8th edge on the HSI's clock. The count says which crystal it is
//! ([`pen_core::board::crystal_from`]); anything else — no crystal, a 12 or 24 MHz one — is a
//! fault that `main` signals with the LED and a defmt message instead of a board that silently
//! never enumerates.

use embassy_stm32::pac;
use embassy_stm32::pac::timer::regs;
use pen_core::board::{Crystal, crystal_from};

/// HSE_RTC = HSE / RTCPRE: 1 MHz from 25 MHz, 320 kHz from 8 MHz.
const RTCPRE: u8 = 25;
/// Input-capture prescaler: one capture every 8 edges (IC1PSC = 0b11).
const EDGES_PER_CAPTURE: u32 = 8;
/// Captures summed: 32 µs (25 MHz) or 100 µs (8 MHz) of HSE_RTC, 512 or 1600 HSI ticks.
const CAPTURES: u32 = 4;
/// Polls of a ready or capture flag before giving up, 1 µs apart at the HSI's 16 MHz: 200 ms
/// (a crystal starts within 2 ms; DS10314, t_SU(HSE)).
const POLLS: u32 = 200_000;

/// Why the board cannot clock USB.
#[derive(Debug, Clone, Copy, PartialEq, Eq, defmt::Format)]
pub enum CrystalFault {
    /// The HSE never became ready: no crystal, or a dead one.
    NotRunning,
    /// It runs, at this many Hz, which is neither 8 nor 25 MHz.
    Unsupported(u32),
}

/// Waits for `ready` to hold, `POLLS` µs at most.
fn wait(ready: impl Fn() -> bool) -> bool {
    for _ in 0..POLLS {
        if ready() {
            return true;
        }
        cortex_m::asm::delay(16);
    }
    false
}

/// Starts the HSE and measures it. Call before `embassy_stm32::init`, on the HSI.
pub fn measure() -> Result<Crystal, CrystalFault> {
    let rcc = pac::RCC;
    rcc.cr().modify(|w| w.set_hseon(true));
    if !wait(|| rcc.cr().read().hserdy()) {
        rcc.cr().modify(|w| w.set_hseon(false));
        return Err(CrystalFault::NotRunning);
    }
    rcc.cfgr().modify(|w| w.set_rtcpre(RTCPRE));
    rcc.apb2enr().modify(|w| w.set_tim11en(true));
    let tim = pac::TIM11;
    // TI1 = HSE_RTC (TIM11_OR.TI1_RMP = 0b10); channel 1 an input on TI1 (CC1S = 0b01),
    // capturing every 8th rising edge (IC1PSC = 0b11); the counter at the HSI's 16 MHz.
    tim.or().write_value(0b10);
    tim.ccmr_input(0).write_value(regs::CcmrInput1ch(0b1101));
    tim.psc().write_value(0);
    tim.ccer().modify(|w| w.set_cce(0, true));
    tim.cr1().modify(|w| w.set_cen(true));

    let capture = || -> Option<u16> { wait(|| tim.sr().read().ccif(0)).then(|| tim.ccr(0).read().ccr()) };
    // HSI ticks over CAPTURES captures; `None` if the captures stop (the crystal did).
    let ticks = (|| {
        let mut last = capture()?;
        let mut ticks = 0u32;
        for _ in 0..CAPTURES {
            let next = capture()?;
            ticks += u32::from(next.wrapping_sub(last));
            last = next;
        }
        Some(ticks)
    })();
    // TIM11 and RTCPRE back as reset left them, for embassy's clock set-up.
    tim.cr1().modify(|w| w.set_cen(false));
    rcc.apb2rstr().modify(|w| w.set_tim11rst(true));
    rcc.apb2rstr().modify(|w| w.set_tim11rst(false));
    rcc.apb2enr().modify(|w| w.set_tim11en(false));
    rcc.cfgr().modify(|w| w.set_rtcpre(0));
    let Some(ticks) = ticks else {
        return Err(CrystalFault::NotRunning);
    };
    let cycles = RTCPRE as u32 * EDGES_PER_CAPTURE * CAPTURES;
    crystal_from(ticks, cycles).ok_or_else(|| {
        let hz = 16_000_000u64 * cycles as u64 / u64::from(ticks.max(1));
        CrystalFault::Unsupported(hz as u32)
    })
}

/// Signals a crystal fault for ever: the Black Pill's LED (PC13, on when low) blinks three short
/// flashes and a pause, and the reason is logged every cycle. The watchdog is not started yet,
/// so the board stays here until it is repaired or power-cycled.
pub fn fault_blink(fault: CrystalFault) -> ! {
    // On the HSI, without embassy: GPIOC clocked, PC13 a push-pull output.
    pac::RCC.ahb1enr().modify(|w| w.set_gpiocen(true));
    let gpio = pac::GPIOC;
    gpio.moder().modify(|w| w.set_moder(13, pac::gpio::vals::Moder::OUTPUT));
    let ms = |n: u32| cortex_m::asm::delay(16_000 * n);
    loop {
        defmt::error!(
            "crystal fault: {}; the firmware supports 8 and 25 MHz crystals (docs/hardware.md)",
            fault
        );
        for _ in 0..3 {
            gpio.bsrr().write(|w| w.set_br(13, true));
            ms(150);
            gpio.bsrr().write(|w| w.set_bs(13, true));
            ms(150);
        }
        ms(1000);
    }
}
