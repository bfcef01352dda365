//! Converts the reference Suzanne scene to `.s3d` for the firmware (soft3d's own converter,
//! feature `convert`, as a build-dependency) and puts the linker's memory map where
//! cortex-m-rt's `link.x` finds it (for riscv32, `memory-riscv.x`, passed to the linker with
//! `-T` since riscv-rt's `link.x` does not include it). With feature `rabbit`, also converts
//! the animated rabbit (`../shared/assets/rabbit/Rabbit.babylon`, beside the repository) to
//! `OUT_DIR/rabbit.s3d`, with its pose constants in `OUT_DIR/rabbit.rs`.

use soft3d::convert::EmitOptions;
use soft3d::convert::{build_script_convert, ConvertOptions, UvOrigin};

#[path = "../common/firmware_build.rs"]
mod firmware_build;
use firmware_build::firmware_build_with_memory;

/// Largest texture side kept in flash: Suzanne.jpg is 512x512, which is 512 KiB as RGB565;
/// 128x128 is 32 KiB.
const MAX_TEXTURE: u32 = 128;

/// Largest texture side of the rabbit (feature `rabbit`): its 0.jpg is 2048x2048; 128x128 is
/// 32 KiB as RGB565 (issue 17's benchmark frame).
const RABBIT_MAX_TEXTURE: u32 = 128;

fn main() {
    // The reference frame's model: exact f32 positions (the 14,457-pixel coverage), v = 0 at
    // the top of the image (the 2013 tutorial's Suzanne), texture downscaled for flash.
    let opts = ConvertOptions { uv_origin: UvOrigin::Top, max_texture: Some(MAX_TEXTURE), ..Default::default() };
    // FPU-less targets (thumbv6m, riscv32imc: their target ABI is not `eabihf`) draw with the
    // fixed-point vertex path, which reads 16-bit quantized positions as integers directly.
    let fpu = std::env::var("CARGO_CFG_TARGET_ABI").is_ok_and(|abi| abi == "eabihf");
    let emit = EmitOptions { float_positions: fpu, ..Default::default() };
    if std::env::var("CARGO_CFG_TARGET_ARCH").is_ok_and(|arch| arch == "riscv32") {
        // By absolute path: a bare `-Tmemory.x` finds the ARM memory.x in the package folder
        // (the linker's working directory) before the search path.
        let memory = std::path::Path::new(&std::env::var_os("OUT_DIR").expect("OUT_DIR")).join("memory.x");
        firmware_build_with_memory("memory-riscv.x", &[&format!("-T{}", memory.display())], &opts, &emit);
    } else {
        firmware_build_with_memory("memory.x", &[], &opts, &emit);
    }
    if std::env::var_os("CARGO_FEATURE_RABBIT").is_some() {
        // Babylon's UV origin (the scene's own), the same positions as Suzanne's for the
        // target: tests/qemu_frame.rs converts it alike for the host's frame.
        let manifest = std::path::PathBuf::from(std::env::var_os("CARGO_MANIFEST_DIR").expect("CARGO_MANIFEST_DIR"));
        let scene = manifest.join("../../../shared/assets/rabbit/Rabbit.babylon");
        let out = std::path::PathBuf::from(std::env::var_os("OUT_DIR").expect("OUT_DIR")).join("rabbit.s3d");
        let opts = ConvertOptions { max_texture: Some(RABBIT_MAX_TEXTURE), ..Default::default() };
        build_script_convert(&scene, &out, &opts, &emit).unwrap_or_else(|e| panic!("{e}"));
    }
}
