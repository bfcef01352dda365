//! Converts Suzanne to `.s3d` at build time (soft3d's own converter, feature `convert`, as a
//! build-dependency) and hands the RP2040 memory map and linker arguments to the linker.

use soft3d::convert::{ConvertOptions, UvOrigin};
use soft3d::convert::EmitOptions;

#[path = "../common/firmware_build.rs"]
mod firmware_build;
use firmware_build::firmware_build;

fn main() {
    // `--nmagic` stops the linker from aligning sections to page boundaries (FLASH starts at
    // 0x10000100, after boot2), as the rp-hal project template does. Suzanne: v = 0 at the top
    // of the image (the 2013 tutorial's model), texture down to 128x128 RGB565 (32 KiB of
    // flash instead of 512 KiB), power-of-two sides.
    let opts = ConvertOptions { uv_origin: UvOrigin::Top, max_texture: Some(128), power_of_two: true };
    firmware_build(&["--nmagic"], &opts, &EmitOptions::default());
}
