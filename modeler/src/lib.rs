//! The terrain modeler driven by the 3D pen.
//!
//! This crate will hold seed 000's modeler: a document of regions and feature figures (points,
//! polylines, closed curves) with heights and slopes, terrain generated from it by the thesis'
//! equations 1–4, the pen interaction state machine (draw, grab, pull, slope) and a CPU
//! rasteriser. The modeler engine and modeler interaction issues fill it in; until then it is
//! empty so that the workspace layout is fixed from the start.
