//! Link with cortex-m-rt's script (memory.x comes from embassy-stm32's `memory-x` feature) and
//! defmt's, which places the log strings in the ELF rather than in flash.
fn main() {
    println!("cargo:rustc-link-arg-bins=--nmagic");
    println!("cargo:rustc-link-arg-bins=-Tlink.x");
    println!("cargo:rustc-link-arg-bins=-Tdefmt.x");
}
