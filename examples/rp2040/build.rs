//! Converts Suzanne to `.s3d` at build time (soft3d's own converter, feature `convert`, as a
//! build-dependency) and hands the RP2040 memory map and linker arguments to the linker.

use std::env;
use std::fs;
use std::path::PathBuf;

use soft3d::convert::{build_script_convert, ConvertOptions, UvOrigin};
use soft3d::format::EmitOptions;

fn main() {
    let out = PathBuf::from(env::var_os("OUT_DIR").expect("OUT_DIR"));
    let manifest = PathBuf::from(env::var_os("CARGO_MANIFEST_DIR").expect("CARGO_MANIFEST_DIR"));

    // Memory map for cortex-m-rt's link.x (which INCLUDEs memory.x from the search path).
    fs::copy(manifest.join("memory.x"), out.join("memory.x")).expect("copy memory.x");
    println!("cargo:rustc-link-search={}", out.display());
    // Linker arguments live here rather than in .cargo/config.toml's `rustflags`, which a
    // RUSTFLAGS variable in the environment (CI's `-D warnings`, say) silently replaces,
    // leaving an image without a vector table. `--nmagic` stops the linker from aligning
    // sections to page boundaries (FLASH starts at 0x10000100, after boot2), as the rp-hal
    // project template does.
    println!("cargo:rustc-link-arg-bins=--nmagic");
    println!("cargo:rustc-link-arg-bins=-Tlink.x");
    println!("cargo:rerun-if-changed=memory.x");
    println!("cargo:rerun-if-changed=build.rs");

    // Suzanne: v = 0 at the top of the image (the 2013 tutorial's model), texture down to
    // 128x128 RGB565 (32 KiB of flash instead of 512 KiB), power-of-two sides.
    let scene = manifest.join("../../assets/suzanne/monkey.babylon");
    let opts = ConvertOptions { uv_origin: UvOrigin::Top, max_texture: Some(128), power_of_two: true };
    build_script_convert(&scene, &out.join("suzanne.s3d"), &opts, &EmitOptions::default())
        .unwrap_or_else(|e| panic!("{e}"));
}
