//! The integration tests of penmodel-render, in one binary: a module per area.
mod common;
mod land;
mod lod;
mod outputs;
mod render;
mod reproject;
mod rocks;
mod simd;
mod trees;
mod water;
