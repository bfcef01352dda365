//! Host-side conversion of Babylon.js scenes (feature `convert`).
//!
//! [`babylon`] reads a `.babylon` file into a [`scene::Scene`], applying every Babylon.js rule
//! (hierarchy, rotations, texture matrices, UV origin) on the way.

pub mod babylon;
mod emit;
pub mod scene;

pub use emit::{emit, to_scene, EmitError, EmitOptions, TextureChoice};

pub use babylon::{read_babylon, read_babylon_file, ConvertError, ConvertOptions, UvOrigin, Warning};

use std::path::Path;
use std::string::{String, ToString};

/// Converts `input` (a `.babylon` file) into the `.s3d` file `output`, for a firmware's
/// `build.rs`: prints `cargo:rerun-if-changed` for the scene and its folder (textures) and each
/// converter warning as `cargo:warning`. The output is written to a temporary file and renamed,
/// so a failed build never leaves a partial `.s3d` behind.
///
/// ```no_run
/// // build.rs
/// use soft3d::convert::{build_script_convert, ConvertOptions, UvOrigin};
/// use soft3d::convert::EmitOptions;
/// let out = std::path::PathBuf::from(std::env::var_os("OUT_DIR").unwrap()).join("scene.s3d");
/// let opts = ConvertOptions { uv_origin: UvOrigin::Bottom, max_texture: Some(128), power_of_two: true };
/// build_script_convert("assets/scene.babylon".as_ref(), &out, &opts, &EmitOptions::default()).unwrap();
/// ```
///
/// # Errors
/// A message naming the file and what is wrong (conversion, emission or I/O).
pub fn build_script_convert(
    input: &Path,
    output: &Path,
    opts: &ConvertOptions,
    emit_opts: &EmitOptions,
) -> Result<(), String> {
    std::println!("cargo:rerun-if-changed={}", input.display());
    if let Some(dir) = input.parent() {
        std::println!("cargo:rerun-if-changed={}", dir.display());
    }
    let (scene, warnings) = read_babylon_file(input, opts).map_err(|e| e.to_string())?;
    for w in warnings {
        std::println!("cargo:warning={}: {w}", input.display());
    }
    let bytes = emit(&scene, emit_opts).map_err(|e| std::format!("{}: {e}", input.display()))?;
    let tmp = output.with_extension("s3d.tmp");
    std::fs::write(&tmp, bytes)
        .and_then(|()| std::fs::rename(&tmp, output))
        .map_err(|e| std::format!("{}: {e}", output.display()))
}
