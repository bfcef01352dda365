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
