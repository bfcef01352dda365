//! The `.s3d` binary scene format, read in place: a [`Model`] is a typed view over the caller's
//! bytes (flash, `include_bytes!`, any alignment) that [`Model::parse`] validates once, so that no
//! accessor can panic or read outside the slice afterwards.
//!
//! - `layout`: the byte layout (offsets, record sizes, stored codes) and the field readers;
//!   the host converter writes with the same constants.
//! - `model`: [`Model`], its validation and its per-file records.
//! - `mesh`: [`Mesh`] and its vertex and index [`Arrays`].
//! - `animation`: the animation section's validation and [`Animation`] views; `deform`: how a
//!   pose moves a mesh's vertices as [`Arrays`] reads them.
//! - `texel`: [`TextureFormat`], [`Texture`] and the texel codecs.
//! - `error`: [`ParseError`].
//!
//! It does not draw, light or sample anything (the pipeline does), and it does not write files
//! (the host-only `convert` module does).

mod animation;
mod deform;
mod error;
pub(crate) mod layout;
mod mesh;
mod model;
mod texel;

pub use animation::{Aim, AnimatedCamera, AnimatedLight, Animation, Group, Morph, Node, Skin, Track, TrackTarget};
pub(crate) use deform::Deforming;
pub use error::{ParseError, Part};
pub use layout::{LightKind, Wrap, MAGIC, NONE, NORMAL_ONE, QUANT_MAX, VERSION};
pub(crate) use mesh::U16Triangles;
pub use mesh::{Arrays, Mesh, SubMesh};
pub(crate) use model::WorldAt;
pub use model::{Light, Material, Model, SceneCamera};
pub use texel::{decode_texel, encode_texel, Texture, TextureFormat};

/// `include_bytes!` of a `.s3d` file, placed at an address aligned to 4: a `&'static [u8]` for
/// [`Model::parse`](crate::Model::parse).
///
/// Any alignment parses, but the converter stores texels at a multiple of 4 within the file,
/// and the Armv6-M span loop (Cortex-M0/M0+, e.g. the RP2040) loads them as halfwords, which
/// that architecture cannot do from an odd address: with texels there it draws with the
/// slower Rust loop instead. `include_bytes!` alone promises alignment 1.
///
/// ```
/// static SCENE: &[u8] = soft3d::include_s3d!(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/parse-raster-overflow.s3d"));
/// assert_eq!(SCENE.as_ptr() as usize % 4, 0);
/// assert_eq!(&SCENE[..4], soft3d::MAGIC);
/// ```
#[macro_export]
macro_rules! include_s3d {
    ($path:expr) => {{
        #[repr(C, align(4))]
        struct Aligned<T: ?Sized>(T);
        static ALIGNED: &Aligned<[u8]> = &Aligned(*include_bytes!($path));
        &ALIGNED.0
    }};
}
