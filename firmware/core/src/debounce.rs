//! Switch debouncing.
//!
//! Contacts bounce for a few milliseconds when they close and open. The debouncer takes the
//! first edge at once — no added latency — and then ignores the switch for the debounce time,
//! so a bounce that settles within that time can never produce a second transition. If the
//! switch changed during the hold-off, the new level is taken when the hold-off ends: a click
//! shorter than the debounce time still produces its press and its release. (Isolated spikes
//! are the hardware's job: the switch lines have RC filters, docs/hardware.md.)

/// The debounced state of SW1–SW3.
#[derive(Debug, Clone, Copy)]
pub struct Debouncer {
    state: [bool; 3],
    hold_until_us: [u64; 3],
}

impl Default for Debouncer {
    fn default() -> Self {
        Self::new()
    }
}

impl Debouncer {
    /// All switches released.
    pub const fn new() -> Debouncer {
        Debouncer {
            state: [false; 3],
            hold_until_us: [0; 3],
        }
    }

    /// The debounced levels (true = pressed).
    pub fn state(&self) -> [bool; 3] {
        self.state
    }

    /// Takes a sample of the raw levels at `now_us`; returns which switches changed.
    pub fn sample(&mut self, now_us: u64, raw: [bool; 3], debounce_us: u64) -> [bool; 3] {
        let mut changed = [false; 3];
        for i in 0..3 {
            if now_us >= self.hold_until_us[i] && raw[i] != self.state[i] {
                self.state[i] = raw[i];
                self.hold_until_us[i] = now_us + debounce_us;
                changed[i] = true;
            }
        }
        changed
    }
}
