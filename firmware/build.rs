//! Link with cortex-m-rt's script and this board's memory map (stm32f411ce.x, which leaves the
//! last flash sector to the configuration), and with defmt's script, which keeps log strings out
//! of flash.
use std::{env, fs, path::PathBuf};

fn main() {
    let out = PathBuf::from(env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    // Copied under the name cortex-m-rt's link.x includes. The source has another name: the
    // linker runs in the workspace root, and a memory.x there would also shadow pen-qemu's.
    fs::copy("stm32f411ce.x", out.join("memory.x")).expect("stm32f411ce.x is readable");
    println!("cargo:rustc-link-search={}", out.display());
    println!("cargo:rerun-if-changed=stm32f411ce.x");
    println!("cargo:rustc-link-arg-bins=--nmagic");
    println!("cargo:rustc-link-arg-bins=-Tlink.x");
    println!("cargo:rustc-link-arg-bins=-Tdefmt.x");
}
