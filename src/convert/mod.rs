//! Host-side conversion of Babylon.js scenes into `.s3d` files (feature `convert`, needs `std`).
//!
//! The pipeline has two steps, both run on the host (a CLI, a test, a firmware's `build.rs`),
//! never on the device:
//!
//! 1. **`.babylon` → [`Scene`]**: [`read_babylon`] / [`read_babylon_file`] read a Babylon.js
//!    scene, applying every Babylon.js rule on the way (hierarchy, rotations, `autoAnimate`
//!    first frames, texture matrices, UV origin, texture loading and resizing per
//!    [`ConvertOptions`]); what they work around is reported as [`Warning`]s, what they cannot
//!    read as a [`ConvertError`].
//! 2. **[`Scene`] → `.s3d`**: [`emit()`] writes the scene in the layout of `format`
//!    (positions quantized or exact, textures as chosen by [`EmitOptions`]), failing with an
//!    [`EmitError`]; [`to_scene`] reads a parsed [`Model`](crate::format::Model) back.
//!
//! [`build_script_convert`] chains both for a firmware's `build.rs` (cargo `rerun-if-changed`
//! and `warning` lines, atomic write), failing with a [`BuildError`].
//!
//! The in-memory [`Scene`] and its parts live in [`scene`], public so that tests and tools can
//! build scenes in code. Everything else is reached through the re-exports below; the
//! submodules are private.
//!
//! The `no_std` core (rendering, `format`'s reader) never imports this module: the
//! dependency goes one way, from the host side to the core.

mod babylon;
mod build;
mod emit;
mod emit_animation;
mod emit_view;
pub mod scene;

pub use babylon::{read_babylon, read_babylon_file, ConvertError, ConvertOptions, UvOrigin, Warning};
pub use build::{build_script_convert, BuildError};
pub use emit::{emit, to_scene, EmitError, EmitOptions, TextureChoice};
pub use scene::Scene;
