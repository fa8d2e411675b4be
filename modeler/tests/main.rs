//! The integration tests of penmodel, in one binary: a module per area.
mod calibrate_window;
mod cli;
mod common;
mod demo_cli;
mod gltf_cli;
mod heightmaps_cli;
mod help_examples;
mod interaction;
mod kill_loop;
mod mouse_window;
mod ridges_cli;
mod river_cli;
mod rocks_cli;
mod trees_cli;
mod waiting_cli;
