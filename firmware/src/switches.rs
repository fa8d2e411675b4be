//! SW1–SW3 on GPIOs with pull-ups: a pressed switch pulls its line to ground. Each line has an
//! RC filter (docs/hardware.md); contact bounce is left to the core's debouncer.

use embassy_stm32::gpio::Input;
use pen_core::Switches;

/// The pen's three switches.
pub struct BoardSwitches<'d> {
    /// SW1 (tip), SW2, SW3.
    pub pins: [Input<'d>; 3],
}

impl Switches for BoardSwitches<'_> {
    fn read(&mut self) -> [bool; 3] {
        [self.pins[0].is_low(), self.pins[1].is_low(), self.pins[2].is_low()]
    }
}
