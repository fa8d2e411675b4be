//! The simulated pen and base station.
//!
//! This crate will model what makes ultrasonic tracking hard (receiver geometry, temperature,
//! timing jitter, echoes, dropouts, switch bounce, a human hand), drive the real firmware core
//! through its hardware traits and yield the exact report bytes the device sends: in process,
//! over a pseudo-terminal, and on an emulated Cortex-M4F. The simulated-pen issue fills it in.
