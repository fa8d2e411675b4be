//! Link with cortex-m-rt's script and the emulated board's memory map.
use std::{env, fs, path::PathBuf};

fn main() {
    let out = PathBuf::from(env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    fs::copy("mps2-an386.x", out.join("memory.x")).expect("mps2-an386.x is readable");
    println!("cargo:rustc-link-search={}", out.display());
    println!("cargo:rerun-if-changed=mps2-an386.x");
    println!("cargo:rustc-link-arg-bins=-Tlink.x");
}
