//! The core's clock on embassy-time (1 MHz ticks from TIM5).

use embassy_time::{Instant, Timer};
use pen_core::Clock;

/// Device time since start-up.
pub struct BoardClock;

impl Clock for BoardClock {
    fn now_us(&self) -> u64 {
        Instant::now().as_micros()
    }

    async fn wait_until(&mut self, t_us: u64) {
        Timer::at(Instant::from_micros(t_us)).await
    }
}
