//! The build-script half shared by the firmware examples (included with `#[path]` by their
//! `build.rs`): the memory map and linker arguments for cortex-m-rt (or riscv-rt), and Suzanne
//! converted to `OUT_DIR/suzanne.s3d` for `include_bytes!`.

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
#[allow(dead_code)] // examples/qemu calls `firmware_build_with_memory` instead
pub fn firmware_build(extra_link_args: &[&str], convert: &ConvertOptions, emit: &EmitOptions) {
    firmware_build_with_memory("memory.x", extra_link_args, convert, emit);
}

/// [`firmware_build`] with the memory map taken from `memory` (a file beside `build.rs`),
/// copied to `OUT_DIR/memory.x`.
pub fn firmware_build_with_memory(
    memory: &str,
    extra_link_args: &[&str],
    convert: &ConvertOptions,
    emit: &EmitOptions,
) {
    let out = PathBuf::from(env::var_os("OUT_DIR").expect("OUT_DIR"));
    let manifest = PathBuf::from(env::var_os("CARGO_MANIFEST_DIR").expect("CARGO_MANIFEST_DIR"));
    fs::copy(manifest.join(memory), out.join("memory.x")).unwrap_or_else(|e| panic!("copy {memory}: {e}"));
    println!("cargo:rustc-link-search={}", out.display());
    for arg in extra_link_args.iter().chain(&["-Tlink.x"]) {
        println!("cargo:rustc-link-arg-bins={arg}");
    }
    println!("cargo:rerun-if-changed={memory}");
    println!("cargo:rerun-if-changed=build.rs");
    let scene = manifest.join("../../assets/suzanne/monkey.babylon");
    build_script_convert(&scene, &out.join("suzanne.s3d"), convert, emit).unwrap_or_else(|e| panic!("{e}"));
}
