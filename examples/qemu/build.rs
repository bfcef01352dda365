//! Converts the reference Suzanne scene to `.s3d` for the firmware (soft3d's own converter,
//! feature `convert`, as a build-dependency) and puts the linker's memory map where
//! cortex-m-rt's `link.x` finds it.

use std::env;
use std::fs;
use std::path::PathBuf;

use soft3d::convert::{build_script_convert, ConvertOptions, UvOrigin};
use soft3d::format::EmitOptions;

/// Largest texture side kept in flash: Suzanne.jpg is 512x512, which is 512 KiB as RGB565;
/// 128x128 is 32 KiB.
const MAX_TEXTURE: u32 = 128;

fn main() {
    let out = PathBuf::from(env::var_os("OUT_DIR").expect("OUT_DIR"));
    let manifest = PathBuf::from(env::var_os("CARGO_MANIFEST_DIR").expect("CARGO_MANIFEST_DIR"));

    // Memory map for cortex-m-rt. `-Tlink.x` is passed here rather than through
    // .cargo/config.toml's `rustflags`, which a RUSTFLAGS variable in the environment (CI's
    // `-D warnings`, say) would silently replace, leaving an image without a vector table.
    fs::copy(manifest.join("memory.x"), out.join("memory.x")).expect("copy memory.x");
    println!("cargo:rustc-link-search={}", out.display());
    println!("cargo:rustc-link-arg-bins=-Tlink.x");
    println!("cargo:rerun-if-changed=memory.x");
    println!("cargo:rerun-if-changed=build.rs");

    // The reference frame's model: exact f32 positions (the 14,457-pixel coverage), v = 0 at
    // the top of the image (the 2013 tutorial's Suzanne), texture downscaled for flash.
    let scene = manifest.join("../../assets/suzanne/monkey.babylon");
    let opts = ConvertOptions { uv_origin: UvOrigin::Top, max_texture: Some(MAX_TEXTURE), ..Default::default() };
    build_script_convert(
        &scene,
        &out.join("suzanne.s3d"),
        &opts,
        &EmitOptions { float_positions: true, ..Default::default() },
    )
    .unwrap_or_else(|e| panic!("{e}"));
}
