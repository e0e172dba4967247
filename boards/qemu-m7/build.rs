//! Puts `memory.x` where cortex-m-rt's `link.x` finds it, and makes sure `link.x` is used.

use std::{env, fs, path::PathBuf};

fn main() {
    let out = PathBuf::from(env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    fs::write(out.join("memory.x"), include_bytes!("memory.x")).expect("write memory.x");
    println!("cargo:rustc-link-search={}", out.display());
    println!("cargo:rerun-if-changed=memory.x");
    println!("cargo:rerun-if-changed=build.rs");

    // .cargo/config.toml passes -Tlink.x, but a RUSTFLAGS variable (CI often sets one)
    // replaces config rustflags, and without link.x the ELF silently has no vector table.
    let flags = env::var("CARGO_ENCODED_RUSTFLAGS").unwrap_or_default();
    if !flags.split('\x1f').any(|f| f.contains("-Tlink.x")) {
        println!("cargo:rustc-link-arg-bins=-Tlink.x");
    }
}
