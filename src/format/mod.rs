//! The `.s3d` binary scene format, read in place: a [`Model`] is a typed view over the caller's
//! bytes (flash, `include_bytes!`, any alignment) that [`Model::parse`] validates once, so that no
//! accessor can panic or read outside the slice afterwards.
//!
//! - `layout`: the byte layout (offsets, record sizes, stored codes) and the field readers;
//!   the host converter writes with the same constants.
//! - `model`: [`Model`], its validation and its per-file records.
//! - `mesh`: [`Mesh`] and its vertex and index [`Arrays`].
//! - `texel`: [`TextureFormat`], [`Texture`] and the texel codecs.
//! - `error`: [`ParseError`].
//!
//! It does not draw, light or sample anything (the pipeline does), and it does not write files
//! (the host-only `convert` module does).

mod error;
pub(crate) mod layout;
mod mesh;
mod model;
mod texel;

pub use error::{ParseError, Part};
pub use layout::{LightKind, Wrap, MAGIC, NONE, NORMAL_ONE, QUANT_MAX, VERSION};
pub use mesh::{Arrays, Mesh, SubMesh};
pub use model::{Light, Material, Model, SceneCamera};
pub use texel::{decode_texel, encode_texel, Texture, TextureFormat};

/// `include_bytes!` of a `.s3d` file at an address that is a multiple of 4: a `&'static [u8]`
/// for [`Model::parse`]. A model parses at any address, but its RGB565 textures take the
/// span loop's fast path only with their texels at an even one (read as `u16`: one load, where
/// a byte-aligned texel is two on cores without unaligned loads such as Cortex-M0+ and
/// RISC-V), and the converter writes texels at a multiple of 4 in the file for this.
///
/// ```
/// static MODEL: &[u8] =
///     soft3d::include_model!(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/parse-raster-overflow.s3d"));
/// assert_eq!(MODEL.as_ptr() as usize % 4, 0);
/// assert!(soft3d::Model::parse(MODEL).is_ok());
/// ```
#[macro_export]
macro_rules! include_model {
    ($path:expr) => {{
        #[repr(C, align(4))]
        struct Aligned<Bytes: ?Sized>(Bytes);
        static ALIGNED: &Aligned<[u8]> = &Aligned(*include_bytes!($path));
        &ALIGNED.0
    }};
}
