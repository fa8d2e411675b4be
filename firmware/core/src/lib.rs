//! The pen base station's hardware-independent core.
//!
//! Everything between the capture timers and the USB endpoints that does not touch hardware:
//! times of flight to ranges ([`sound`]), multilateration with outlier rejection and a quality
//! figure ([`solver`]), smoothing ([`filter`]), switch debouncing ([`debounce`]), report
//! assembly and configuration requests ([`engine`]), configuration storage ([`store`]), and the
//! measurement loop over the hardware seams ([`station`]), with a tracking gate between solver
//! and report ([`track`]). `no_std`, no allocation; the board
//! runs it, the host tests it, the simulated pen drives it.
//!
//! Numbers are `f32` (the Cortex-M4F's FPU is single precision) and only correctly rounded
//! operations are used (+, −, ×, ÷, √), in a fixed order, so the board and the host compute
//! bit-identical fixes from the same captures.
#![no_std]
#![cfg_attr(not(test), warn(clippy::unwrap_used))]

pub mod capture;
pub mod debounce;
pub mod engine;
pub mod filter;
pub mod math;
pub mod settings;
pub mod solver;
pub mod sound;
pub mod station;
pub mod store;
pub mod track;

pub use engine::{Action, Counters, Cycle, CycleResult, Engine, LISTEN_US, MIN_CYCLE_US, TICK_US};
pub use math::Vec3;
pub use settings::{DisplayFrame, Settings, default_config};
pub use solver::{Fix, NoFix};
pub use station::{Clock, Ranging, ReportSink, SharedEngine, Station, Switches};
pub use store::{ConfigStore, FlashRegion, LogStore, StoreError};
