//! # soft3d
//!
//! A `no_std`, allocation-free 3D software rasterizer for microcontrollers. It draws textured,
//! lit, z-buffered triangle meshes into colour and depth slices that the caller owns, band by
//! band, from meshes stored in the compact `.s3d` format ([`Model`]) read in place from flash.
//! Start at [`Renderer`]; `docs/architecture.md` draws the module tree and the path of one
//! triangle through it.
//!
//! ## Conventions (written once, used everywhere)
//! These follow Babylon.js; `docs/conventions.md` in the repository says how Babylon.js itself
//! does each, with the references:
//! - **Handedness**: left-handed, +x right, +y up, +z forward (away from an unrotated camera).
//! - **Matrices**: row vectors, `clip = [x y z 1] · World · View · Projection`. In code we use
//!   glam's column-major [`glam::Mat4`]; a Babylon `m[16]` is exactly `Mat4::from_cols_array`,
//!   and `p · M` is `M.transpose() * p`, which glam writes as `M.transpose().mul_vec4(p)`;
//!   `math` keeps every such product in one place.
//! - **Projection**: `PerspectiveFovLH` with a vertical field of view; NDC z in [-1, 1].
//! - **Viewport**: `x_px = (x_ndc + 1) · W/2`, `y_px = (1 - y_ndc) · H/2` (y down); pixel
//!   (column c, row r) is sampled at its centre `(c + 0.5, r + 0.5)`.
//! - **Snapping**: screen positions are snapped down to the 1/16-pixel grid (28.4 fixed point, see
//!   `fixed.rs` for every fixed-point format,
//!   `floor(x · 16)`) before coverage is decided. (Flooring, not rounding, reproduces the
//!   reference coverage of the Suzanne frame: 14,457 pixels.)
//! - **Fill rule**: a pixel centre exactly on an edge belongs to the triangle for which that
//!   edge is a *left* edge, or a *bottom* horizontal edge, as seen in the picture.
//! - **Front faces**: counter-clockwise with y up (clockwise in the y-down picture). A world
//!   matrix with negative determinant flips this.
//! - **Depth**: the stored depth is NDC z mapped to [0, 1] (`(z/w + 1) / 2`), which is affine in
//!   screen space, so interpolating it linearly across the screen is exact. `u16` buffers hold
//!   it scaled to `0..=65535`; the test is LEQUAL (smaller is nearer).
//! - **Textures**: uv (0, 0) is the bottom-left of the image; image row from the top is
//!   `(1 - v) · H`.
//! - **Perspective**: texture coordinates and light are interpolated perspective-correctly.
//!   Where the triangle's (or a run of pixels') range of `1/w` proves affine stepping is
//!   within a tolerance (1/16 texel; 1/256 of full light; Phong's normals and positions
//!   1/4096), the rasterizer steps linearly instead of dividing per pixel, adding only
//!   stepping's rounding of under 2^-16 per pixel (see `pipeline/raster.rs`, `Setup::allow_affine`).
#![no_std]
#![deny(missing_docs)]
// Unchecked code lives in one module only, the span loop (`pipeline/span/`: `mod.rs`, and its assembly in `armv7m.rs` and `rows565.rs`), which allows it.
#![deny(unsafe_code)]

#[cfg(feature = "std")]
extern crate std;

pub mod animation;
mod camera;
mod fixed;
mod fog;
mod format;
mod light;
mod math;
mod pipeline;
mod target;
#[cfg(test)]
mod test_rng;
mod texture;

#[cfg(feature = "convert")]
pub mod convert;
#[cfg(feature = "embedded-graphics")]
mod eg;

// The public API, whole: what the caller sets up per frame, the model, the targets, drawing.
pub use camera::{Camera, CameraError};
pub use fog::{Fog, FogMode};
pub use format::{
    decode_texel, encode_texel, Light, LightKind, Material, Mesh, Model, ParseError, Part, SceneCamera, SubMesh,
    Texture, TextureFormat, Wrap, MAGIC, NONE, NORMAL_ONE, QUANT_MAX, VERSION,
};
pub use glam::{Mat3, Mat4, Vec2, Vec3, Vec4};
pub use light::Lights;
pub use pipeline::{
    DrawError, DrawOrder, Mode, RenderOptions, Renderer, Scratch, Shading, SortEntry, Stats, TransformedVertex,
    TriangleRows,
};
pub use target::{
    luma, Band, DepthBuffer, DepthCell, DepthValue, FrameColor, NoDepth, Rgb565Be, TargetError, GUARD_HALF_EXTENT,
    MAX_DIMENSION,
};
pub use texture::Filter;

#[cfg(feature = "embedded-graphics")]
pub use eg::present;

#[doc(hidden)]
pub mod testing;
