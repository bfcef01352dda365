//! The build-script half shared by the firmware examples (included with `#[path]` by their
//! `build.rs`): the memory map and linker arguments for cortex-m-rt, and Suzanne converted to
//! `OUT_DIR/suzanne.s3d` for `include_bytes!`.

use std::env;
use std::fs;
use std::path::PathBuf;

use soft3d::convert::EmitOptions;
use soft3d::convert::{build_script_convert, ConvertOptions};

/// Copies `memory.x` where cortex-m-rt's `link.x` INCLUDEs it from, passes `-Tlink.x` and
/// `extra_link_args`, and converts the Suzanne scene with the given options.
///
/// Linker arguments are passed here rather than in `.cargo/config.toml`'s `rustflags`, which a
/// RUSTFLAGS variable in the environment (CI's `-D warnings`, say) silently replaces, leaving
/// an image without a vector table.
pub fn firmware_build(extra_link_args: &[&str], convert: &ConvertOptions, emit: &EmitOptions) {
    let out = PathBuf::from(env::var_os("OUT_DIR").expect("OUT_DIR"));
    let manifest = PathBuf::from(env::var_os("CARGO_MANIFEST_DIR").expect("CARGO_MANIFEST_DIR"));
    fs::copy(manifest.join("memory.x"), out.join("memory.x")).expect("copy memory.x");
    println!("cargo:rustc-link-search={}", out.display());
    for arg in extra_link_args.iter().chain(&["-Tlink.x"]) {
        println!("cargo:rustc-link-arg-bins={arg}");
    }
    println!("cargo:rerun-if-changed=memory.x");
    println!("cargo:rerun-if-changed=build.rs");
    let scene = manifest.join("../../assets/suzanne/monkey.babylon");
    build_script_convert(&scene, &out.join("suzanne.s3d"), convert, emit).unwrap_or_else(|e| panic!("{e}"));
}
