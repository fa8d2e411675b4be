//! The pen base station's hardware-independent core.
//!
//! Everything between the capture timers and the USB endpoints that does not touch hardware, one
//! module per stage of a measurement cycle, in order:
//!
//! 1. [`ranging`]: capture ticks to times of flight to ranges, at the speed of sound;
//! 2. [`solve`]: multilateration with outlier rejection and a quality figure;
//! 3. [`track`]: the tracking gate between a cycle's fix and the report;
//! 4. [`filter`]: smoothing that adds little lag (1€ filter);
//! 5. [`debounce`]: the switches;
//! 6. [`report`]: report assembly, and configuration requests answered;
//!
//! around them the measurement loop and its emitter schedule with the tracked head's filter
//! ([`head`]), over the hardware seams ([`station`]), the settings a
//! configuration report turns into ([`settings`]), configuration storage ([`store`]), the panic
//! record kept across a reset ([`reset`]), the arithmetic of the board's crystal and time base
//! ([`board`]), the replay format of recorded cycles ([`replay`]) and the correctly rounded
//! arithmetic ([`math`]).
//! `no_std`, no allocation; the board runs it, the host tests it, the simulated pen drives it.
//!
//! Numbers are `f32` (the Cortex-M4F's FPU is single precision) and only correctly rounded
//! operations are used (+, −, ×, ÷, √), in a fixed order, so the board and the host compute
//! bit-identical fixes from the same captures.
#![no_std]
#![cfg_attr(not(test), warn(clippy::unwrap_used))]

pub mod board;
pub mod debounce;
pub mod filter;
// The fuzz target's property, shared with the stable test that replays its corpus.
#[doc(hidden)]
pub mod fuzzing;
pub mod head;
pub mod math;
pub mod ranging;
pub mod replay;
pub mod report;
pub mod reset;
pub mod settings;
pub mod solve;
pub mod station;
pub mod store;
pub mod track;

pub use head::{Emitter, HeadSettings, Schedule};
pub use math::Vec3;
pub use report::{Action, Counters, Cycle, CycleResult, Engine, HeadCounters, LISTEN_US, MIN_CYCLE_US, Slot, TICK_US};
pub use settings::{DisplayFrame, Settings, default_config};
pub use solve::{Fix, NoFix};
pub use station::{Clock, Ranging, ReportSink, SharedEngine, Station, Switches, WakeOnPress};
pub use store::{ConfigStore, FlashRegion, LogStore, Saved, StoreError};
