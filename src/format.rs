//! The `.s3d` binary scene format: parsed in place, written by the host converter.
//!
//! Both sides of the layout live in this module (the `emit` half behind the `convert`
//! feature), so the reader and the writer cannot drift apart.
//!
//! # Layout
//! All numbers are little-endian and read with `from_le_bytes`, so the file can sit at any
//! alignment (`include_bytes!` gives alignment 1). Offsets are byte offsets from the start of
//! the file. `f32` fields must be finite. Unused (`reserved`) bytes are written as zero.
//!
//! **Header** (48 bytes, at offset 0)
//!
//! | bytes  | type     | field                                             |
//! |--------|----------|---------------------------------------------------|
//! | 0..4   | `[u8;4]` | magic `S3D\0`                                      |
//! | 4..6   | u16      | version, [`VERSION`]                               |
//! | 6..8   | u16      | reserved                                           |
//! | 8..12  | u32      | file length in bytes (must equal the slice length) |
//! | 12..14 | u16      | mesh count                                         |
//! | 14..16 | u16      | material count                                     |
//! | 16..18 | u16      | texture count                                      |
//! | 18..20 | u16      | instance count                                     |
//! | 20..22 | u16      | light count                                        |
//! | 22..24 | u16      | reserved                                           |
//! | 24..28 | u32      | offset of the mesh table (`count` x 148 bytes)     |
//! | 28..32 | u32      | offset of the material table (`count` x 12 bytes)  |
//! | 32..36 | u32      | offset of the texture table (`count` x 12 bytes)   |
//! | 36..40 | u32      | offset of the instance table (`count` x 52 bytes)  |
//! | 40..44 | u32      | offset of the light table (`count` x 32 bytes)     |
//! | 44..48 | u32      | offset of the camera record (36 bytes), 0 = none   |
//!
//! **Mesh** (148 bytes). Positions, normals and UVs are quantized: a local position is
//! `pos_offset + q * pos_scale` with `q` three u16, a normal is three i16 / 32767, a UV is
//! `uv_offset + q * uv_scale` with `q` two u16.
//!
//! | bytes   | type      | field                                                        |
//! |---------|-----------|--------------------------------------------------------------|
//! | 0..48   | 12 x f32  | world matrix, Babylon row-vector rows 0..3, columns 0..2 (column 3 is 0,0,0,1) |
//! | 48..60  | 3 x f32   | `pos_offset`                                                 |
//! | 60..72  | 3 x f32   | `pos_scale` (>= 0)                                           |
//! | 72..80  | 2 x f32   | `uv_offset`                                                  |
//! | 80..88  | 2 x f32   | `uv_scale` (>= 0)                                            |
//! | 88..104 | 4 x f32   | local bounding sphere: centre x, y, z, radius (>= 0)         |
//! | 104..108| u32       | vertex count (>= 1)                                          |
//! | 108..112| u32       | index count (a multiple of 3)                                |
//! | 112..114| u16       | flags: bit 0 indices are u32 (else u16), bit 1 has UVs, bit 2 has colours, bit 3 positions are 3 x f32 (exact; `pos_offset` 0, `pos_scale` 1) |
//! | 114..116| u16       | sub-mesh count (>= 1)                                        |
//! | 116..120| u32       | offset of positions, `vertex count` x 3 x u16 (or 3 x f32, flag bit 3) |
//! | 120..124| u32       | offset of normals, `vertex count` x 3 x i16                  |
//! | 124..128| u32       | offset of UVs, `vertex count` x 2 x u16 (0 if no UVs)        |
//! | 128..132| u32       | offset of colours, `vertex count` x RGBA u8 (0 if none)      |
//! | 132..136| u32       | offset of indices, `index count` x u16 or u32, each < vertex count |
//! | 136..140| u32       | offset of the sub-mesh records (`count` x 12 bytes)          |
//! | 140..144| u32       | offset of the name (UTF-8)                                   |
//! | 144..146| u16       | name length in bytes                                         |
//! | 146..148| u16       | reserved                                                     |
//!
//! **Sub-mesh** (12 bytes): 0..2 u16 material index ([`NONE`] = default material), 2..4
//! reserved, 4..8 u32 first index, 8..12 u32 index count; both multiples of 3 and inside the
//! mesh's indices.
//!
//! **Material** (12 bytes): 0..4 RGBA u8 diffuse colour and alpha, 4 u8 flags (bit 0: cull
//! back faces), 5 u8 wrap U, 6 u8 wrap V ([`Wrap`]: 0 clamp, 1 repeat, 2 mirror), 7 reserved,
//! 8..10 u16 texture index ([`NONE`] = untextured), 10..12 reserved.
//!
//! **Texture** (12 bytes): 0..2 u16 width, 2..4 u16 height (both >= 1), 4 u8
//! [`TextureFormat`], 5..8 reserved, 8..12 u32 offset of the texels: `height` rows of `width`
//! texels, **row 0 is the bottom row of the image** (so texel `(i, j)` is at `j * width + i`
//! with `j = floor(v * height)`).
//!
//! **Instance** (52 bytes): 0..2 u16 mesh index, 2..4 reserved, 4..52 world matrix as in the mesh
//! record. An instance draws that mesh's geometry a second time with its own world matrix.
//!
//! **Light** (32 bytes): 0 u8 kind ([`LightKind`]: 0 point, 1 directional, 3 hemispheric),
//! 1..4 reserved, 4..16 3 x f32 position (point) or direction, 16..28 3 x f32 diffuse colour,
//! 28..32 f32 intensity.
//!
//! **Camera** (36 bytes): 0..12 position, 12..24 target (3 x f32 each), 24..28 f32 vertical
//! field of view in radians (0 < fov < pi), 28..32 f32 near (> 0), 32..36 f32 far (> near).

use core::fmt;
use core::ops::Range;

use crate::math::{Mat4, Vec3};

/// The first four bytes of every `.s3d` file.
pub const MAGIC: [u8; 4] = *b"S3D\0";
/// The format version this crate reads and writes.
pub const VERSION: u16 = 1;
/// A `u16` reference that points at nothing (no material, no texture).
pub const NONE: u16 = u16::MAX;

mod header {
    use core::ops::Range;
    pub const MAGIC: Range<usize> = 0..4;
    pub const VERSION: Range<usize> = 4..6;
    pub const FILE_LEN: Range<usize> = 8..12;
    pub const MESH_COUNT: Range<usize> = 12..14;
    pub const MATERIAL_COUNT: Range<usize> = 14..16;
    pub const TEXTURE_COUNT: Range<usize> = 16..18;
    pub const INSTANCE_COUNT: Range<usize> = 18..20;
    pub const LIGHT_COUNT: Range<usize> = 20..22;
    pub const MESHES: Range<usize> = 24..28;
    pub const MATERIALS: Range<usize> = 28..32;
    pub const TEXTURES: Range<usize> = 32..36;
    pub const INSTANCES: Range<usize> = 36..40;
    pub const LIGHTS: Range<usize> = 40..44;
    pub const CAMERA: Range<usize> = 44..48;
    pub const LEN: usize = 48;
}

mod mesh {
    use core::ops::Range;
    pub const WORLD: Range<usize> = 0..48;
    pub const POS_OFFSET: Range<usize> = 48..60;
    pub const POS_SCALE: Range<usize> = 60..72;
    pub const UV_OFFSET: Range<usize> = 72..80;
    pub const UV_SCALE: Range<usize> = 80..88;
    pub const BOUNDS: Range<usize> = 88..104;
    pub const VERTEX_COUNT: Range<usize> = 104..108;
    pub const INDEX_COUNT: Range<usize> = 108..112;
    pub const FLAGS: Range<usize> = 112..114;
    pub const SUBMESH_COUNT: Range<usize> = 114..116;
    pub const POSITIONS: Range<usize> = 116..120;
    pub const NORMALS: Range<usize> = 120..124;
    pub const UVS: Range<usize> = 124..128;
    pub const COLORS: Range<usize> = 128..132;
    pub const INDICES: Range<usize> = 132..136;
    pub const SUBMESHES: Range<usize> = 136..140;
    pub const NAME: Range<usize> = 140..144;
    pub const NAME_LEN: Range<usize> = 144..146;
    pub const LEN: usize = 148;
    pub const FLAG_U32_INDICES: u16 = 1;
    pub const FLAG_UVS: u16 = 2;
    pub const FLAG_COLORS: u16 = 4;
    pub const FLAG_F32_POSITIONS: u16 = 8;
}

mod submesh {
    use core::ops::Range;
    pub const MATERIAL: Range<usize> = 0..2;
    pub const INDEX_START: Range<usize> = 4..8;
    pub const INDEX_COUNT: Range<usize> = 8..12;
    pub const LEN: usize = 12;
}

mod material {
    use core::ops::Range;
    pub const RGBA: Range<usize> = 0..4;
    pub const FLAGS: usize = 4;
    pub const WRAP_U: usize = 5;
    pub const WRAP_V: usize = 6;
    pub const TEXTURE: Range<usize> = 8..10;
    pub const LEN: usize = 12;
    pub const FLAG_CULL_BACK: u8 = 1;
}

mod texture {
    use core::ops::Range;
    pub const WIDTH: Range<usize> = 0..2;
    pub const HEIGHT: Range<usize> = 2..4;
    pub const FORMAT: usize = 4;
    pub const DATA: Range<usize> = 8..12;
    pub const LEN: usize = 12;
}

mod instance {
    use core::ops::Range;
    pub const MESH: Range<usize> = 0..2;
    pub const WORLD: Range<usize> = 4..52;
    pub const LEN: usize = 52;
}

mod light {
    use core::ops::Range;
    pub const KIND: usize = 0;
    pub const VECTOR: Range<usize> = 4..16;
    pub const DIFFUSE: Range<usize> = 16..28;
    pub const INTENSITY: Range<usize> = 28..32;
    pub const LEN: usize = 32;
}

mod camera {
    use core::ops::Range;
    pub const POSITION: Range<usize> = 0..12;
    pub const TARGET: Range<usize> = 12..24;
    pub const FOV: Range<usize> = 24..28;
    pub const NEAR: Range<usize> = 28..32;
    pub const FAR: Range<usize> = 32..36;
    pub const LEN: usize = 36;
}

/// Size in bytes of one quantized position.
const POSITION_LEN: usize = 6;
/// Size in bytes of one quantized normal.
const NORMAL_LEN: usize = 6;
/// Size in bytes of one quantized UV.
const UV_LEN: usize = 4;
/// Size in bytes of one vertex colour.
const COLOR_LEN: usize = 4;
/// The quantized value of a normal component of 1.0.
pub const NORMAL_ONE: f32 = 32767.0;
/// The largest quantized position or UV value.
pub const QUANT_MAX: f32 = 65535.0;

/// What part of the file a [`ParseError`] is about.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Part {
    /// The file header.
    Header,
    /// A mesh record.
    Mesh,
    /// A sub-mesh record.
    SubMesh,
    /// A mesh's positions.
    Positions,
    /// A mesh's normals.
    Normals,
    /// A mesh's UVs.
    Uvs,
    /// A mesh's vertex colours.
    Colors,
    /// A mesh's indices.
    Indices,
    /// A mesh's name.
    Name,
    /// A material record.
    Material,
    /// A texture record or its texels.
    Texture,
    /// An instance record.
    Instance,
    /// A light record.
    Light,
    /// The camera record.
    Camera,
}

impl fmt::Display for Part {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let name = match self {
            Part::Header => "header",
            Part::Mesh => "mesh record",
            Part::SubMesh => "sub-mesh record",
            Part::Positions => "positions",
            Part::Normals => "normals",
            Part::Uvs => "UVs",
            Part::Colors => "colours",
            Part::Indices => "indices",
            Part::Name => "name",
            Part::Material => "material record",
            Part::Texture => "texture",
            Part::Instance => "instance record",
            Part::Light => "light record",
            Part::Camera => "camera record",
        };
        f.write_str(name)
    }
}

/// Why a byte slice is not a valid `.s3d` file. `offset` is the byte offset of the offending
/// field (or record) in the file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ParseError {
    /// The slice is shorter than the header or than the length the header states.
    Truncated {
        /// Bytes the header says the file has (or the header's own length).
        expected: usize,
        /// Bytes actually given.
        actual: usize,
    },
    /// The slice does not start with [`MAGIC`].
    BadMagic,
    /// A version this crate does not read.
    UnsupportedVersion(u16),
    /// A section or record lies (partly) outside the file.
    OutOfBounds {
        /// What was being read.
        part: Part,
        /// Where its reference was found.
        offset: usize,
    },
    /// A float that must be finite is NaN or infinite.
    NotFinite {
        /// What was being read.
        part: Part,
        /// Offset of the float.
        offset: usize,
    },
    /// A vertex index is not smaller than the mesh's vertex count.
    IndexOutOfRange {
        /// Offset of the index.
        offset: usize,
        /// The index found.
        index: u32,
        /// The mesh's vertex count.
        vertex_count: u32,
    },
    /// A reference to a mesh, material or texture that does not exist.
    BadReference {
        /// What refers.
        part: Part,
        /// Offset of the reference.
        offset: usize,
        /// The value found.
        index: u16,
        /// How many there are.
        count: u16,
    },
    /// Any other value outside its allowed range (a count, a size, a kind, a range).
    Invalid {
        /// What was being read.
        part: Part,
        /// Offset of the field.
        offset: usize,
    },
}

impl fmt::Display for ParseError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            ParseError::Truncated { expected, actual } => {
                write!(f, "truncated .s3d: need {expected} bytes, got {actual}")
            }
            ParseError::BadMagic => f.write_str("not an .s3d file (bad magic at offset 0)"),
            ParseError::UnsupportedVersion(v) => {
                write!(f, "unsupported .s3d version {v} at offset 4 (this reader knows {VERSION})")
            }
            ParseError::OutOfBounds { part, offset } => {
                write!(f, "{part} referenced at offset {offset} lies outside the file")
            }
            ParseError::NotFinite { part, offset } => {
                write!(f, "{part}: non-finite number at offset {offset}")
            }
            ParseError::IndexOutOfRange { offset, index, vertex_count } => {
                write!(f, "indices: index {index} at offset {offset} but only {vertex_count} vertices")
            }
            ParseError::BadReference { part, offset, index, count } => {
                write!(f, "{part}: reference {index} at offset {offset} but only {count} exist")
            }
            ParseError::Invalid { part, offset } => {
                write!(f, "{part}: invalid value at offset {offset}")
            }
        }
    }
}

#[cfg(feature = "std")]
impl std::error::Error for ParseError {}

// ---------------------------------------------------------------------------------------------
// Little-endian field readers. They never panic: a read past the end yields zero, and `parse`
// has checked beforehand that no accessor of a valid `Model` ever reads past the end.

fn bytes_at<const N: usize>(data: &[u8], at: usize) -> [u8; N] {
    data.get(at..at.wrapping_add(N)).and_then(|s| s.try_into().ok()).unwrap_or([0; N])
}
fn u16_at(data: &[u8], at: usize) -> u16 {
    u16::from_le_bytes(bytes_at(data, at))
}
fn i16_at(data: &[u8], at: usize) -> i16 {
    i16::from_le_bytes(bytes_at(data, at))
}
fn u32_at(data: &[u8], at: usize) -> u32 {
    u32::from_le_bytes(bytes_at(data, at))
}
fn f32_at(data: &[u8], at: usize) -> f32 {
    f32::from_le_bytes(bytes_at(data, at))
}
fn u8_at(data: &[u8], at: usize) -> u8 {
    data.get(at).copied().unwrap_or(0)
}
fn vec3_at(data: &[u8], at: usize) -> Vec3 {
    Vec3::new(f32_at(data, at), f32_at(data, at + 4), f32_at(data, at + 8))
}
/// Reads 12 floats: Babylon rows 0..3, columns 0..2, as a glam matrix.
fn affine_at(data: &[u8], at: usize) -> Mat4 {
    let row = |r: usize| vec3_at(data, at + r * 12);
    Mat4::from_cols(row(0).extend(0.0), row(1).extend(0.0), row(2).extend(0.0), row(3).extend(1.0))
}

// ---------------------------------------------------------------------------------------------
// Validation helpers used by `parse`.

/// Checks that `len` bytes at `start` lie in a file of `file_len` bytes and returns the range.
fn section(start: u32, len: usize, file_len: usize, part: Part, at: usize) -> Result<Range<usize>, ParseError> {
    let start = start as usize;
    match start.checked_add(len) {
        Some(end) if end <= file_len => Ok(start..end),
        _ => Err(ParseError::OutOfBounds { part, offset: at }),
    }
}

/// Checks that every f32 in `range` is finite.
fn check_finite(data: &[u8], range: Range<usize>, part: Part) -> Result<(), ParseError> {
    for at in range.step_by(4) {
        if !f32_at(data, at).is_finite() {
            return Err(ParseError::NotFinite { part, offset: at });
        }
    }
    Ok(())
}

fn check_ref(data: &[u8], at: usize, count: u16, part: Part, allow_none: bool) -> Result<(), ParseError> {
    let index = u16_at(data, at);
    if index < count || (allow_none && index == NONE) {
        Ok(())
    } else {
        Err(ParseError::BadReference { part, offset: at, index, count })
    }
}

fn invalid(part: Part, offset: usize) -> ParseError {
    ParseError::Invalid { part, offset }
}

/// Texel formats of `.s3d` textures.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u8)]
pub enum TextureFormat {
    /// 16-bit `rrrrrggggggbbbbb` (the default: opaque textures).
    Rgb565 = 0,
    /// 16-bit `rrrrrgggggbbbbba`, 1-bit alpha for cut-outs.
    Rgba5551 = 1,
    /// 3 bytes R, G, B.
    Rgb888 = 2,
    /// 4 bytes R, G, B, A.
    Rgba8888 = 3,
}

impl TextureFormat {
    /// Decodes the format byte.
    #[must_use]
    pub fn from_u8(v: u8) -> Option<Self> {
        match v {
            0 => Some(Self::Rgb565),
            1 => Some(Self::Rgba5551),
            2 => Some(Self::Rgb888),
            3 => Some(Self::Rgba8888),
            _ => None,
        }
    }

    /// Bytes per texel.
    #[must_use]
    pub const fn bytes_per_texel(self) -> usize {
        match self {
            Self::Rgb565 | Self::Rgba5551 => 2,
            Self::Rgb888 => 3,
            Self::Rgba8888 => 4,
        }
    }

    /// Whether the format stores an alpha channel.
    #[must_use]
    pub const fn has_alpha(self) -> bool {
        matches!(self, Self::Rgba5551 | Self::Rgba8888)
    }
}

/// Texture wrap modes (numbered as Babylon's `wrapU`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Wrap {
    /// Clamp to the edge texel.
    Clamp = 0,
    /// Repeat; negative coordinates repeat too.
    #[default]
    Repeat = 1,
    /// Mirror every other repetition.
    Mirror = 2,
}

impl Wrap {
    fn from_u8(v: u8) -> Option<Self> {
        match v {
            0 => Some(Self::Clamp),
            1 => Some(Self::Repeat),
            2 => Some(Self::Mirror),
            _ => None,
        }
    }
}

/// Light kinds (numbered as Babylon's light `type`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LightKind {
    /// From a position, no distance falloff.
    Point = 0,
    /// Along a direction.
    Directional = 1,
    /// Sky/ground ambient along an up direction.
    Hemispheric = 3,
}

impl LightKind {
    fn from_u8(v: u8) -> Option<Self> {
        match v {
            0 => Some(Self::Point),
            1 => Some(Self::Directional),
            3 => Some(Self::Hemispheric),
            _ => None,
        }
    }
}

// ---------------------------------------------------------------------------------------------
// The parsed model and its views.

/// A validated `.s3d` file, borrowed in place. Every accessor is infallible: [`Model::parse`]
/// checked every offset, count, index and float once.
#[derive(Clone, Copy, Debug)]
pub struct Model<'a> {
    data: &'a [u8],
}

impl<'a> Model<'a> {
    /// Validates `data` as an `.s3d` file.
    ///
    /// # Errors
    /// A [`ParseError`] naming the first problem found and its byte offset.
    pub fn parse(data: &'a [u8]) -> Result<Self, ParseError> {
        if data.len() < header::LEN {
            return Err(ParseError::Truncated { expected: header::LEN, actual: data.len() });
        }
        if data[header::MAGIC] != MAGIC {
            return Err(ParseError::BadMagic);
        }
        let version = u16_at(data, header::VERSION.start);
        if version != VERSION {
            return Err(ParseError::UnsupportedVersion(version));
        }
        let file_len = u32_at(data, header::FILE_LEN.start) as usize;
        if file_len != data.len() {
            return Err(ParseError::Truncated { expected: file_len, actual: data.len() });
        }
        let model = Model { data };
        model.validate()?;
        Ok(model)
    }

    fn count(&self, field: Range<usize>) -> u16 {
        u16_at(self.data, field.start)
    }

    fn table(
        &self,
        field: Range<usize>,
        count: Range<usize>,
        record_len: usize,
        part: Part,
    ) -> Result<Range<usize>, ParseError> {
        let n = self.count(count) as usize;
        let start = u32_at(self.data, field.start);
        section(start, n * record_len, self.data.len(), part, field.start)
    }

    fn validate(&self) -> Result<(), ParseError> {
        let d = self.data;
        let n_materials = self.count(header::MATERIAL_COUNT);
        let n_textures = self.count(header::TEXTURE_COUNT);
        let n_meshes = self.count(header::MESH_COUNT);

        let meshes = self.table(header::MESHES, header::MESH_COUNT, mesh::LEN, Part::Mesh)?;
        for at in meshes.step_by(mesh::LEN) {
            self.validate_mesh(at, n_materials)?;
        }
        let materials = self.table(header::MATERIALS, header::MATERIAL_COUNT, material::LEN, Part::Material)?;
        for at in materials.step_by(material::LEN) {
            check_ref(d, at + material::TEXTURE.start, n_textures, Part::Material, true)?;
            for wrap in [material::WRAP_U, material::WRAP_V] {
                if Wrap::from_u8(u8_at(d, at + wrap)).is_none() {
                    return Err(invalid(Part::Material, at + wrap));
                }
            }
        }
        let textures = self.table(header::TEXTURES, header::TEXTURE_COUNT, texture::LEN, Part::Texture)?;
        for at in textures.step_by(texture::LEN) {
            let format = TextureFormat::from_u8(u8_at(d, at + texture::FORMAT))
                .ok_or(invalid(Part::Texture, at + texture::FORMAT))?;
            let (w, h) = (u16_at(d, at + texture::WIDTH.start), u16_at(d, at + texture::HEIGHT.start));
            if w == 0 || h == 0 {
                return Err(invalid(Part::Texture, at));
            }
            let len = w as usize * h as usize * format.bytes_per_texel();
            section(u32_at(d, at + texture::DATA.start), len, d.len(), Part::Texture, at + texture::DATA.start)?;
        }
        let instances = self.table(header::INSTANCES, header::INSTANCE_COUNT, instance::LEN, Part::Instance)?;
        for at in instances.step_by(instance::LEN) {
            check_ref(d, at + instance::MESH.start, n_meshes, Part::Instance, false)?;
            check_finite(d, at + instance::WORLD.start..at + instance::WORLD.end, Part::Instance)?;
        }
        let lights = self.table(header::LIGHTS, header::LIGHT_COUNT, light::LEN, Part::Light)?;
        for at in lights.step_by(light::LEN) {
            if LightKind::from_u8(u8_at(d, at + light::KIND)).is_none() {
                return Err(invalid(Part::Light, at + light::KIND));
            }
            check_finite(d, at + light::VECTOR.start..at + light::LEN, Part::Light)?;
        }
        let camera_at = u32_at(d, header::CAMERA.start);
        if camera_at != 0 {
            let cam = section(camera_at, camera::LEN, d.len(), Part::Camera, header::CAMERA.start)?;
            check_finite(d, cam.clone(), Part::Camera)?;
            let c = cam.start;
            let (fov, near, far) =
                (f32_at(d, c + camera::FOV.start), f32_at(d, c + camera::NEAR.start), f32_at(d, c + camera::FAR.start));
            if !(fov > 0.0 && fov < core::f32::consts::PI && near > 0.0 && far > near) {
                return Err(invalid(Part::Camera, c + camera::FOV.start));
            }
        }
        Ok(())
    }

    fn validate_mesh(&self, at: usize, n_materials: u16) -> Result<(), ParseError> {
        let d = self.data;
        check_finite(d, at..at + mesh::BOUNDS.end, Part::Mesh)?;
        let nonneg = |r: Range<usize>| r.step_by(4).all(|o| f32_at(d, at + o) >= 0.0);
        if !nonneg(mesh::POS_SCALE) || !nonneg(mesh::UV_SCALE) || f32_at(d, at + mesh::BOUNDS.end - 4) < 0.0 {
            return Err(invalid(Part::Mesh, at + mesh::POS_SCALE.start));
        }
        let vertices = u32_at(d, at + mesh::VERTEX_COUNT.start);
        let indices = u32_at(d, at + mesh::INDEX_COUNT.start);
        let flags = u16_at(d, at + mesh::FLAGS.start);
        if vertices == 0 || !indices.is_multiple_of(3) || flags > 15 {
            return Err(invalid(Part::Mesh, at + mesh::VERTEX_COUNT.start));
        }
        let nv = vertices as usize;
        let field = |f: Range<usize>| (u32_at(d, at + f.start), at + f.start);
        let (o, r) = field(mesh::POSITIONS);
        if flags & mesh::FLAG_F32_POSITIONS != 0 {
            check_finite(d, section(o, nv * 12, d.len(), Part::Positions, r)?, Part::Positions)?;
        } else {
            section(o, nv * POSITION_LEN, d.len(), Part::Positions, r)?;
        }
        let (o, r) = field(mesh::NORMALS);
        section(o, nv * NORMAL_LEN, d.len(), Part::Normals, r)?;
        if flags & mesh::FLAG_UVS != 0 {
            let (o, r) = field(mesh::UVS);
            section(o, nv * UV_LEN, d.len(), Part::Uvs, r)?;
        }
        if flags & mesh::FLAG_COLORS != 0 {
            let (o, r) = field(mesh::COLORS);
            section(o, nv * COLOR_LEN, d.len(), Part::Colors, r)?;
        }
        let (o, r) = field(mesh::NAME);
        let name = section(o, u16_at(d, at + mesh::NAME_LEN.start) as usize, d.len(), Part::Name, r)?;
        if core::str::from_utf8(&d[name]).is_err() {
            return Err(invalid(Part::Name, r));
        }
        let index_len = if flags & mesh::FLAG_U32_INDICES != 0 { 4 } else { 2 };
        let (o, r) = field(mesh::INDICES);
        let index_range = section(o, indices as usize * index_len, d.len(), Part::Indices, r)?;
        for i_at in index_range.step_by(index_len) {
            let index = if index_len == 4 { u32_at(d, i_at) } else { u16_at(d, i_at) as u32 };
            if index >= vertices {
                return Err(ParseError::IndexOutOfRange { offset: i_at, index, vertex_count: vertices });
            }
        }
        let n_sub = u16_at(d, at + mesh::SUBMESH_COUNT.start) as usize;
        if n_sub == 0 {
            return Err(invalid(Part::Mesh, at + mesh::SUBMESH_COUNT.start));
        }
        let (o, r) = field(mesh::SUBMESHES);
        for s in section(o, n_sub * submesh::LEN, d.len(), Part::SubMesh, r)?.step_by(submesh::LEN) {
            check_ref(d, s + submesh::MATERIAL.start, n_materials, Part::SubMesh, true)?;
            let start = u32_at(d, s + submesh::INDEX_START.start);
            let count = u32_at(d, s + submesh::INDEX_COUNT.start);
            let in_range = start.checked_add(count).is_some_and(|end| end <= indices);
            if !in_range || !start.is_multiple_of(3) || !count.is_multiple_of(3) {
                return Err(invalid(Part::SubMesh, s + submesh::INDEX_START.start));
            }
        }
        Ok(())
    }

    /// The raw bytes of the file.
    #[must_use]
    pub fn bytes(&self) -> &'a [u8] {
        self.data
    }

    fn record(&self, table: Range<usize>, count: Range<usize>, len: usize, i: usize) -> Option<usize> {
        (i < self.count(count) as usize).then(|| u32_at(self.data, table.start) as usize + i * len)
    }

    /// Number of meshes.
    #[must_use]
    pub fn mesh_count(&self) -> usize {
        self.count(header::MESH_COUNT) as usize
    }

    /// Mesh `i`, or `None` if `i >= mesh_count()`.
    #[must_use]
    pub fn mesh(&self, i: usize) -> Option<Mesh<'a>> {
        let at = self.record(header::MESHES, header::MESH_COUNT, mesh::LEN, i)?;
        Some(Mesh { data: self.data, at })
    }

    /// All meshes.
    pub fn meshes(&self) -> impl Iterator<Item = Mesh<'a>> + 'a {
        let model = *self;
        (0..self.mesh_count()).filter_map(move |i| model.mesh(i))
    }

    /// Number of materials.
    #[must_use]
    pub fn material_count(&self) -> usize {
        self.count(header::MATERIAL_COUNT) as usize
    }

    /// Material `i`, or `None` if out of range (including [`NONE`]).
    #[must_use]
    pub fn material(&self, i: u16) -> Option<Material> {
        let at = self.record(header::MATERIALS, header::MATERIAL_COUNT, material::LEN, i as usize)?;
        let d = self.data;
        let texture = u16_at(d, at + material::TEXTURE.start);
        Some(Material {
            rgba: bytes_at(d, at + material::RGBA.start),
            cull_back_faces: u8_at(d, at + material::FLAGS) & material::FLAG_CULL_BACK != 0,
            wrap_u: Wrap::from_u8(u8_at(d, at + material::WRAP_U)).unwrap_or_default(),
            wrap_v: Wrap::from_u8(u8_at(d, at + material::WRAP_V)).unwrap_or_default(),
            texture: (texture != NONE).then_some(texture),
        })
    }

    /// Number of textures.
    #[must_use]
    pub fn texture_count(&self) -> usize {
        self.count(header::TEXTURE_COUNT) as usize
    }

    /// Texture `i`, or `None` if out of range.
    #[must_use]
    pub fn texture(&self, i: u16) -> Option<Texture<'a>> {
        let at = self.record(header::TEXTURES, header::TEXTURE_COUNT, texture::LEN, i as usize)?;
        let d = self.data;
        let width = u16_at(d, at + texture::WIDTH.start);
        let height = u16_at(d, at + texture::HEIGHT.start);
        let format = TextureFormat::from_u8(u8_at(d, at + texture::FORMAT))?;
        let start = u32_at(d, at + texture::DATA.start) as usize;
        let len = width as usize * height as usize * format.bytes_per_texel();
        Some(Texture { width, height, format, texels: d.get(start..start + len)? })
    }

    /// Number of instances.
    #[must_use]
    pub fn instance_count(&self) -> usize {
        self.count(header::INSTANCE_COUNT) as usize
    }

    /// Instance `i`: `(mesh index, world matrix)`.
    #[must_use]
    pub fn instance(&self, i: usize) -> Option<(usize, Mat4)> {
        let at = self.record(header::INSTANCES, header::INSTANCE_COUNT, instance::LEN, i)?;
        Some((u16_at(self.data, at) as usize, affine_at(self.data, at + instance::WORLD.start)))
    }

    /// Triangles and vertices of everything [`Model::draws`] yields (instances counted again):
    /// the entries a [`RowCache`](crate::RowCache) needs.
    #[must_use]
    pub fn draw_counts(&self) -> (usize, usize) {
        self.draws().fold((0, 0), |(t, v), (m, _)| (t + m.triangle_count() as usize, v + m.vertex_count() as usize))
    }

    /// Everything to draw: each mesh with its own world matrix, then each instance.
    pub fn draws(&self) -> impl Iterator<Item = (Mesh<'a>, Mat4)> + 'a {
        let model = *self;
        let own = self.meshes().map(|m| (m, m.world()));
        let inst = (0..self.instance_count())
            .filter_map(move |i| model.instance(i))
            .filter_map(move |(m, world)| Some((model.mesh(m)?, world)));
        own.chain(inst)
    }

    /// World-space sphere `(centre, radius)` around every draw's bounding sphere, or `None`
    /// when the model has nothing finite to draw.
    #[must_use]
    pub fn bounds(&self) -> Option<(Vec3, f32)> {
        let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
        for (mesh, world) in self.draws() {
            let (c, r) = mesh.bounding_sphere();
            let r = Vec3::splat(r * crate::math::max_axis_scale(&world));
            let c = world.transform_point3(c);
            lo = lo.min(c - r);
            hi = hi.max(c + r);
        }
        (lo.is_finite() && hi.is_finite()).then(|| ((lo + hi) * 0.5, ((hi - lo) * 0.5).length().max(1e-3)))
    }

    /// Number of lights.
    #[must_use]
    pub fn light_count(&self) -> usize {
        self.count(header::LIGHT_COUNT) as usize
    }

    /// Light `i`, or `None` if out of range.
    #[must_use]
    pub fn light(&self, i: usize) -> Option<Light> {
        let at = self.record(header::LIGHTS, header::LIGHT_COUNT, light::LEN, i)?;
        let d = self.data;
        Some(Light {
            kind: LightKind::from_u8(u8_at(d, at + light::KIND))?,
            vector: vec3_at(d, at + light::VECTOR.start),
            diffuse: vec3_at(d, at + light::DIFFUSE.start),
            intensity: f32_at(d, at + light::INTENSITY.start),
        })
    }

    /// All lights.
    pub fn lights(&self) -> impl Iterator<Item = Light> + 'a {
        let model = *self;
        (0..self.light_count()).filter_map(move |i| model.light(i))
    }

    /// The scene's camera, when the file has one.
    #[must_use]
    pub fn camera(&self) -> Option<SceneCamera> {
        let at = u32_at(self.data, header::CAMERA.start) as usize;
        (at != 0).then(|| SceneCamera {
            position: vec3_at(self.data, at + camera::POSITION.start),
            target: vec3_at(self.data, at + camera::TARGET.start),
            fov: f32_at(self.data, at + camera::FOV.start),
            near: f32_at(self.data, at + camera::NEAR.start),
            far: f32_at(self.data, at + camera::FAR.start),
        })
    }
}

/// One mesh of a [`Model`].
#[derive(Clone, Copy, Debug)]
pub struct Mesh<'a> {
    data: &'a [u8],
    at: usize,
}

/// A range of a mesh's triangles drawn with one material.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SubMesh {
    /// The material index, `None` for the default material.
    pub material: Option<u16>,
    /// First triangle.
    pub first_triangle: u32,
    /// Number of triangles.
    pub triangle_count: u32,
}

impl<'a> Mesh<'a> {
    fn u32_field(&self, f: Range<usize>) -> u32 {
        u32_at(self.data, self.at + f.start)
    }
    fn flags(&self) -> u16 {
        u16_at(self.data, self.at + mesh::FLAGS.start)
    }

    /// The mesh's name.
    #[must_use]
    pub fn name(&self) -> &'a str {
        let start = self.u32_field(mesh::NAME) as usize;
        let len = u16_at(self.data, self.at + mesh::NAME_LEN.start) as usize;
        self.data.get(start..start + len).and_then(|b| core::str::from_utf8(b).ok()).unwrap_or("")
    }

    /// The mesh's world matrix.
    #[must_use]
    pub fn world(&self) -> Mat4 {
        affine_at(self.data, self.at + mesh::WORLD.start)
    }

    /// The matrix that turns a stored position ([`Mesh::position_stored`]) into a local one.
    #[must_use]
    pub fn dequantize(&self) -> Mat4 {
        let offset = vec3_at(self.data, self.at + mesh::POS_OFFSET.start);
        let scale = vec3_at(self.data, self.at + mesh::POS_SCALE.start);
        Mat4::from_scale_rotation_translation(scale, glam::Quat::IDENTITY, offset)
    }

    /// `(offset, scale)` turning a quantized UV into a UV: `offset + q * scale`.
    #[must_use]
    pub fn uv_transform(&self) -> ([f32; 2], [f32; 2]) {
        let d = self.data;
        let a = self.at;
        (
            [f32_at(d, a + mesh::UV_OFFSET.start), f32_at(d, a + mesh::UV_OFFSET.start + 4)],
            [f32_at(d, a + mesh::UV_SCALE.start), f32_at(d, a + mesh::UV_SCALE.start + 4)],
        )
    }

    /// Local-space bounding sphere `(centre, radius)`.
    #[must_use]
    pub fn bounding_sphere(&self) -> (Vec3, f32) {
        let at = self.at + mesh::BOUNDS.start;
        (vec3_at(self.data, at), f32_at(self.data, at + 12))
    }

    /// Number of vertices.
    #[must_use]
    pub fn vertex_count(&self) -> u32 {
        self.u32_field(mesh::VERTEX_COUNT)
    }

    /// Number of triangles.
    #[must_use]
    pub fn triangle_count(&self) -> u32 {
        self.u32_field(mesh::INDEX_COUNT) / 3
    }

    /// Whether the mesh has texture coordinates.
    #[must_use]
    pub fn has_uvs(&self) -> bool {
        self.flags() & mesh::FLAG_UVS != 0
    }

    /// Whether the mesh has vertex colours.
    #[must_use]
    pub fn has_colors(&self) -> bool {
        self.flags() & mesh::FLAG_COLORS != 0
    }

    /// Whether indices are stored as u32.
    #[must_use]
    pub fn has_u32_indices(&self) -> bool {
        self.flags() & mesh::FLAG_U32_INDICES != 0
    }

    /// Whether positions are stored as exact f32 rather than quantized u16.
    #[must_use]
    pub fn has_f32_positions(&self) -> bool {
        self.flags() & mesh::FLAG_F32_POSITIONS != 0
    }

    /// The vertex and index arrays, resolved once: what a renderer reads per vertex.
    #[must_use]
    pub fn arrays(&self) -> Arrays<'a> {
        let nv = self.vertex_count() as usize;
        let ni = self.u32_field(mesh::INDEX_COUNT) as usize;
        let d = self.data;
        // `parse` checked every section's range; an impossible one reads as empty (zeros).
        let slice = |field: Range<usize>, len: usize| {
            let at = self.u32_field(field) as usize;
            d.get(at..at.saturating_add(len)).unwrap_or(&[])
        };
        Arrays {
            positions: if self.has_f32_positions() {
                Positions::F32(slice(mesh::POSITIONS, nv * 12).as_chunks().0)
            } else {
                Positions::Quantized(slice(mesh::POSITIONS, nv * POSITION_LEN).as_chunks().0)
            },
            normals: slice(mesh::NORMALS, nv * NORMAL_LEN).as_chunks().0,
            uvs: self.has_uvs().then(|| slice(mesh::UVS, nv * UV_LEN).as_chunks().0),
            colors: self.has_colors().then(|| slice(mesh::COLORS, nv * COLOR_LEN).as_chunks().0),
            indices: if self.has_u32_indices() {
                Indices::U32(slice(mesh::INDICES, ni * 4).as_chunks().0)
            } else {
                Indices::U16(slice(mesh::INDICES, ni * 2).as_chunks().0)
            },
        }
    }

    /// Stored position of vertex `i`: the quantized values as floats, or the f32 position
    /// (zero if `i` is out of range). [`Mesh::dequantize`] turns it into a local position.
    #[must_use]
    pub fn position_stored(&self, i: u32) -> Vec3 {
        self.arrays().position_stored(i)
    }

    /// Local position of vertex `i`.
    #[must_use]
    pub fn position(&self, i: u32) -> Vec3 {
        self.dequantize().transform_point3(self.position_stored(i))
    }

    /// Quantized normal of vertex `i` (components scaled by [`NORMAL_ONE`]).
    #[must_use]
    pub fn normal_q(&self, i: u32) -> [i16; 3] {
        self.arrays().normal_q(i)
    }

    /// Local normal of vertex `i` (unit length up to quantization).
    #[must_use]
    pub fn normal(&self, i: u32) -> Vec3 {
        self.arrays().normal(i)
    }

    /// Quantized UV of vertex `i` (zero when the mesh has no UVs).
    #[must_use]
    pub fn uv_q(&self, i: u32) -> [u16; 2] {
        self.arrays().uv_q(i)
    }

    /// UV of vertex `i` ((0, 0) when the mesh has no UVs).
    #[must_use]
    pub fn uv(&self, i: u32) -> [f32; 2] {
        let q = self.uv_q(i);
        let (o, s) = self.uv_transform();
        [o[0] + q[0] as f32 * s[0], o[1] + q[1] as f32 * s[1]]
    }

    /// RGBA colour of vertex `i` (opaque white when the mesh has none).
    #[must_use]
    pub fn color(&self, i: u32) -> [u8; 4] {
        self.arrays().color(i)
    }

    /// Index `k` of the index list.
    #[must_use]
    pub fn index(&self, k: u32) -> u32 {
        self.arrays().index(k)
    }

    /// The three vertex indices of triangle `t`.
    #[must_use]
    pub fn triangle(&self, t: u32) -> [u32; 3] {
        self.arrays().triangle(t)
    }

    /// The mesh's sub-meshes.
    pub fn submeshes(&self) -> impl Iterator<Item = SubMesh> + 'a {
        let d = self.data;
        let base = self.u32_field(mesh::SUBMESHES) as usize;
        let n = u16_at(d, self.at + mesh::SUBMESH_COUNT.start) as usize;
        (0..n).map(move |i| {
            let at = base + i * submesh::LEN;
            let material = u16_at(d, at + submesh::MATERIAL.start);
            SubMesh {
                material: (material != NONE).then_some(material),
                first_triangle: u32_at(d, at + submesh::INDEX_START.start) / 3,
                triangle_count: u32_at(d, at + submesh::INDEX_COUNT.start) / 3,
            }
        })
    }
}

/// A material of a [`Model`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Material {
    /// Diffuse colour and alpha, 8 bits each.
    pub rgba: [u8; 4],
    /// Whether back faces are culled.
    pub cull_back_faces: bool,
    /// Horizontal wrap.
    pub wrap_u: Wrap,
    /// Vertical wrap.
    pub wrap_v: Wrap,
    /// Texture index.
    pub texture: Option<u16>,
}

impl Default for Material {
    /// White, opaque, back faces culled, untextured (Babylon's default material).
    fn default() -> Self {
        Self { rgba: [255; 4], cull_back_faces: true, wrap_u: Wrap::Repeat, wrap_v: Wrap::Repeat, texture: None }
    }
}

/// A texture of a [`Model`], texels stored bottom row first.
#[derive(Clone, Copy, Debug)]
pub struct Texture<'a> {
    /// Width in texels.
    pub width: u16,
    /// Height in texels.
    pub height: u16,
    /// Texel format.
    pub format: TextureFormat,
    /// `width * height * format.bytes_per_texel()` bytes.
    pub texels: &'a [u8],
}

impl Texture<'_> {
    /// RGBA8 of texel `(i, j)`, `j` counted from the bottom row; transparent black if outside.
    #[must_use]
    pub fn rgba(&self, i: u32, j: u32) -> [u8; 4] {
        if i >= self.width as u32 || j >= self.height as u32 {
            return [0; 4];
        }
        let n = self.format.bytes_per_texel();
        let at = (j as usize * self.width as usize + i as usize) * n;
        decode_texel(self.format, self.texels.get(at..at + n).unwrap_or(&[0; 4]))
    }
}

/// Expands a 5- or 6-bit channel to 8 bits (`v * 255 / max`, rounded, as displays do).
const fn expand(v: u16, bits: u32) -> u8 {
    let max = (1u32 << bits) - 1;
    ((v as u32 * 255 + max / 2) / max) as u8
}

/// [`expand`] as tables, so that decoding a texel per pixel costs no division.
const fn expand_table<const N: usize>(bits: u32) -> [u8; N] {
    let mut t = [0; N];
    let mut v = 0;
    while v < N {
        t[v] = expand(v as u16, bits);
        v += 1;
    }
    t
}
const EXPAND5: [u8; 32] = expand_table(5);
const EXPAND6: [u8; 64] = expand_table(6);

/// A mesh's vertex and index arrays as slices of fixed-size records, resolved once per draw
/// (see [`Mesh::arrays`]) so that reading a vertex is one bounds check and a few loads.
/// Out-of-range reads give zero, like every accessor here.
#[derive(Clone, Copy, Debug)]
pub struct Arrays<'a> {
    positions: Positions<'a>,
    normals: &'a [[u8; NORMAL_LEN]],
    uvs: Option<&'a [[u8; UV_LEN]]>,
    colors: Option<&'a [[u8; COLOR_LEN]]>,
    indices: Indices<'a>,
}

#[derive(Clone, Copy, Debug)]
enum Positions<'a> {
    F32(&'a [[u8; 12]]),
    Quantized(&'a [[u8; POSITION_LEN]]),
}

#[derive(Clone, Copy, Debug)]
enum Indices<'a> {
    U16(&'a [[u8; 2]]),
    U32(&'a [[u8; 4]]),
}

impl Arrays<'_> {
    /// See [`Mesh::position_stored`].
    #[inline]
    #[must_use]
    pub fn position_stored(&self, i: u32) -> Vec3 {
        match self.positions {
            Positions::F32(p) => p.get(i as usize).map_or(Vec3::ZERO, |r| vec3_at(r, 0)),
            Positions::Quantized(p) => p
                .get(i as usize)
                .map_or(Vec3::ZERO, |r| Vec3::new(u16_at(r, 0) as f32, u16_at(r, 2) as f32, u16_at(r, 4) as f32)),
        }
    }

    /// Vertex `i`'s stored position as integers within ±2^15, for
    /// [`FixedTransform`](crate::math::FixedTransform): stored = `offset + q·step` with
    /// `(offset, step)` from [`Arrays::int_position_frame`]. Float positions are mapped into the
    /// bounding sphere `sphere` (clamped to it).
    #[inline]
    #[must_use]
    pub fn position_int(&self, i: u32, sphere: (Vec3, f32)) -> [i32; 3] {
        match self.positions {
            Positions::F32(p) => {
                let v = p.get(i as usize).map_or(Vec3::ZERO, |r| vec3_at(r, 0));
                let (offset, step) = self.int_position_frame(sphere);
                let k = 1.0 / step;
                [v.x - offset.x, v.y - offset.y, v.z - offset.z]
                    .map(|c| crate::math::to_i32(c * k + 0.5).clamp(-(1 << 15), 1 << 15))
            }
            Positions::Quantized(p) => p
                .get(i as usize)
                .map_or([0; 3], |r| [u16_at(r, 0), u16_at(r, 2), u16_at(r, 4)].map(|c| c as i32 - 32768)),
        }
    }

    /// `(offset, step)` of [`Arrays::position_int`]: quantized positions are shifted by 2^15;
    /// float positions are centred on the bounding sphere `(centre, radius)` and scaled so that
    /// its radius is 2^15 - 1.
    #[must_use]
    pub fn int_position_frame(&self, (centre, radius): (Vec3, f32)) -> (Vec3, f32) {
        match self.positions {
            Positions::F32(_) => (centre, crate::math::max(radius, f32::MIN_POSITIVE) / 32767.0),
            Positions::Quantized(_) => (Vec3::splat(32768.0), 1.0),
        }
    }

    /// See [`Mesh::normal_q`].
    #[inline]
    #[must_use]
    pub fn normal_q(&self, i: u32) -> [i16; 3] {
        self.normals.get(i as usize).map_or([0; 3], |r| [i16_at(r, 0), i16_at(r, 2), i16_at(r, 4)])
    }

    /// See [`Mesh::normal`].
    #[inline]
    #[must_use]
    pub fn normal(&self, i: u32) -> Vec3 {
        let q = self.normal_q(i);
        Vec3::new(q[0] as f32, q[1] as f32, q[2] as f32) / NORMAL_ONE
    }

    /// See [`Mesh::uv_q`].
    #[inline]
    #[must_use]
    pub fn uv_q(&self, i: u32) -> [u16; 2] {
        self.uvs.and_then(|u| u.get(i as usize)).map_or([0; 2], |r| [u16_at(r, 0), u16_at(r, 2)])
    }

    /// See [`Mesh::color`].
    #[inline]
    #[must_use]
    pub fn color(&self, i: u32) -> [u8; 4] {
        match self.colors {
            Some(c) => c.get(i as usize).copied().unwrap_or([0; 4]),
            None => [255; 4],
        }
    }

    /// See [`Mesh::index`].
    #[inline]
    #[must_use]
    pub fn index(&self, k: u32) -> u32 {
        match self.indices {
            Indices::U16(x) => x.get(k as usize).map_or(0, |r| u16::from_le_bytes(*r) as u32),
            Indices::U32(x) => x.get(k as usize).map_or(0, |r| u32::from_le_bytes(*r)),
        }
    }

    /// See [`Mesh::triangle`].
    #[inline]
    #[must_use]
    pub fn triangle(&self, t: u32) -> [u32; 3] {
        [self.index(3 * t), self.index(3 * t + 1), self.index(3 * t + 2)]
    }
}

/// Decodes one stored texel to RGBA8.
#[inline(always)]
#[must_use]
pub fn decode_texel(format: TextureFormat, b: &[u8]) -> [u8; 4] {
    let at = |i: usize| b.get(i).copied().unwrap_or(0);
    let v16 = u16::from_le_bytes([at(0), at(1)]);
    match format {
        TextureFormat::Rgb565 => {
            [EXPAND5[(v16 >> 11) as usize], EXPAND6[((v16 >> 5) & 63) as usize], EXPAND5[(v16 & 31) as usize], 255]
        }
        TextureFormat::Rgba5551 => [
            EXPAND5[(v16 >> 11) as usize],
            EXPAND5[((v16 >> 6) & 31) as usize],
            EXPAND5[((v16 >> 1) & 31) as usize],
            if v16 & 1 != 0 { 255 } else { 0 },
        ],
        TextureFormat::Rgb888 => [at(0), at(1), at(2), 255],
        TextureFormat::Rgba8888 => [at(0), at(1), at(2), at(3)],
    }
}

/// Encodes one RGBA8 texel (rounding to nearest).
#[must_use]
pub fn encode_texel(format: TextureFormat, c: [u8; 4]) -> [u8; 4] {
    let q = |v: u8, bits: u32| ((v as u32 * ((1 << bits) - 1) + 127) / 255) as u16;
    let lo_hi = |v: u16| {
        let b = v.to_le_bytes();
        [b[0], b[1], 0, 0]
    };
    match format {
        TextureFormat::Rgb565 => lo_hi(q(c[0], 5) << 11 | q(c[1], 6) << 5 | q(c[2], 5)),
        TextureFormat::Rgba5551 => lo_hi(q(c[0], 5) << 11 | q(c[1], 5) << 6 | q(c[2], 5) << 1 | u16::from(c[3] >= 128)),
        TextureFormat::Rgb888 => [c[0], c[1], c[2], 0],
        TextureFormat::Rgba8888 => c,
    }
}

/// A light of a [`Model`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Light {
    /// The light kind.
    pub kind: LightKind,
    /// Position (point) or direction.
    pub vector: Vec3,
    /// Diffuse colour.
    pub diffuse: Vec3,
    /// Intensity.
    pub intensity: f32,
}

/// The camera stored in a [`Model`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SceneCamera {
    /// Eye position.
    pub position: Vec3,
    /// Point looked at.
    pub target: Vec3,
    /// Vertical field of view, radians.
    pub fov: f32,
    /// Near plane distance.
    pub near: f32,
    /// Far plane distance.
    pub far: f32,
}

#[cfg(feature = "convert")]
pub use emit::{emit, to_scene, EmitError, EmitOptions, TextureChoice};

#[cfg(feature = "convert")]
mod emit {
    //! The writing half of the layout above.
    use super::*;
    use crate::convert::scene::{self, Scene};
    use std::string::String;
    use std::vec::Vec;

    /// How the converter stores textures.
    #[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
    pub enum TextureChoice {
        /// RGB565, or RGBA5551 for textures with transparent texels (cut-outs).
        #[default]
        Auto,
        /// Always this format.
        Fixed(TextureFormat),
    }

    /// Options of [`emit`].
    #[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
    pub struct EmitOptions {
        /// Texture storage.
        pub textures: TextureChoice,
        /// Store positions as exact f32 (12 bytes a vertex) instead of quantized u16 (6 bytes).
        pub float_positions: bool,
    }

    /// Why a scene cannot be written as `.s3d`.
    #[derive(Clone, Debug, PartialEq, Eq)]
    pub struct EmitError(pub String);

    impl fmt::Display for EmitError {
        fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
            f.write_str(&self.0)
        }
    }

    impl std::error::Error for EmitError {}

    /// A growing file whose fixed-size records are reserved first and filled in later.
    struct Out(Vec<u8>);

    impl Out {
        fn reserve(&mut self, len: usize) -> usize {
            let at = self.0.len();
            self.0.resize(at + len, 0);
            at
        }
        fn append(&mut self, bytes: &[u8]) -> u32 {
            let at = self.0.len();
            self.0.extend_from_slice(bytes);
            at as u32
        }
        fn put(&mut self, at: usize, bytes: &[u8]) {
            self.0[at..at + bytes.len()].copy_from_slice(bytes);
        }
        fn put_u16(&mut self, at: usize, v: u16) {
            self.put(at, &v.to_le_bytes());
        }
        fn put_u32(&mut self, at: usize, v: u32) {
            self.put(at, &v.to_le_bytes());
        }
        fn put_f32s(&mut self, at: usize, vs: &[f32]) {
            for (k, v) in vs.iter().enumerate() {
                self.put(at + 4 * k, &v.to_le_bytes());
            }
        }
        fn put_affine(&mut self, at: usize, m: &scene::Matrix) {
            let rows: [f32; 12] = core::array::from_fn(|k| m[(k / 3) * 4 + k % 3]);
            self.put_f32s(at, &rows);
        }
    }

    fn count_u16(n: usize, what: &str) -> Result<u16, EmitError> {
        u16::try_from(n)
            .ok()
            .filter(|&n| n != NONE)
            .ok_or_else(|| EmitError(std::format!("too many {what}: {n} (at most 65534)")))
    }

    /// Quantization of a set of values: `value = offset + q * scale`, `q` in 0..=65535.
    fn quantizer<const N: usize>(values: impl Iterator<Item = [f32; N]>) -> ([f32; N], [f32; N]) {
        let mut lo = [f32::INFINITY; N];
        let mut hi = [f32::NEG_INFINITY; N];
        for v in values {
            for k in 0..N {
                lo[k] = lo[k].min(v[k]);
                hi[k] = hi[k].max(v[k]);
            }
        }
        let mut scale = [0.0; N];
        for k in 0..N {
            if !lo[k].is_finite() {
                lo[k] = 0.0;
                hi[k] = 0.0;
            }
            scale[k] = (hi[k] - lo[k]) / QUANT_MAX;
            if !scale[k].is_finite() {
                // The span of two huge finite values overflows f32: take it in f64.
                scale[k] = ((hi[k] as f64 - lo[k] as f64) / QUANT_MAX as f64).min(f32::MAX as f64) as f32;
            }
        }
        (lo, scale)
    }

    fn quantize(v: f32, offset: f32, scale: f32) -> u16 {
        if scale > 0.0 {
            libm::roundf((v - offset) / scale).clamp(0.0, QUANT_MAX) as u16
        } else {
            0
        }
    }

    fn bounding_sphere(positions: &[[f32; 3]]) -> [f32; 4] {
        let (lo, scale) = quantizer(positions.iter().copied());
        let centre = Vec3::from(lo) + Vec3::from(scale) * (QUANT_MAX / 2.0);
        // In f64: squares of coordinates above ~1e19 overflow f32.
        let length = |v: [f64; 3]| libm::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
        let radius =
            positions.iter().map(|p| length([0, 1, 2].map(|k| p[k] as f64 - centre[k] as f64))).fold(0.0f64, f64::max);
        // Grow by the quantization error so the sphere holds the decoded positions too.
        let slack = length(scale.map(f64::from));
        [centre.x, centre.y, centre.z, (radius + slack).min(f32::MAX as f64) as f32]
    }

    fn check_finite_scene(scene: &Scene) -> Result<(), EmitError> {
        for m in &scene.meshes {
            let nums = m.world.iter().chain(m.positions.iter().flatten()).chain(m.normals.iter().flatten());
            let uvs = m.uvs.iter().flatten().flatten();
            if !nums.chain(uvs).all(|v| v.is_finite()) {
                return Err(EmitError(std::format!("mesh \"{}\": non-finite number", m.name)));
            }
        }
        Ok(())
    }

    /// Writes `scene` as an `.s3d` file.
    ///
    /// # Errors
    /// When a count does not fit the format, or a mesh is inconsistent (lengths, indices).
    pub fn emit(scene: &Scene, opts: &EmitOptions) -> Result<Vec<u8>, EmitError> {
        check_finite_scene(scene)?;
        let mut out = Out(Vec::new());
        out.reserve(header::LEN);
        out.put(header::MAGIC.start, &MAGIC);
        out.put_u16(header::VERSION.start, VERSION);
        let counts = [
            (header::MESH_COUNT, scene.meshes.len(), "meshes"),
            (header::MATERIAL_COUNT, scene.materials.len(), "materials"),
            (header::TEXTURE_COUNT, scene.textures.len(), "textures"),
            (header::INSTANCE_COUNT, scene.instances.len(), "instances"),
            (header::LIGHT_COUNT, scene.lights.len(), "lights"),
        ];
        for (field, n, what) in counts {
            let n = count_u16(n, what)?;
            out.put_u16(field.start, n);
        }
        let meshes = out.reserve(mesh::LEN * scene.meshes.len());
        out.put_u32(header::MESHES.start, meshes as u32);
        for (k, m) in scene.meshes.iter().enumerate() {
            emit_mesh(&mut out, meshes + k * mesh::LEN, m, scene.materials.len(), opts.float_positions)?;
        }
        let materials = out.reserve(material::LEN * scene.materials.len());
        out.put_u32(header::MATERIALS.start, materials as u32);
        for (k, m) in scene.materials.iter().enumerate() {
            emit_material(&mut out, materials + k * material::LEN, m, scene.textures.len())?;
        }
        let textures = out.reserve(texture::LEN * scene.textures.len());
        out.put_u32(header::TEXTURES.start, textures as u32);
        for (k, t) in scene.textures.iter().enumerate() {
            emit_texture(&mut out, textures + k * texture::LEN, t, opts)?;
        }
        let instances = out.reserve(instance::LEN * scene.instances.len());
        out.put_u32(header::INSTANCES.start, instances as u32);
        for (k, inst) in scene.instances.iter().enumerate() {
            if inst.mesh as usize >= scene.meshes.len() {
                return Err(EmitError(std::format!("instance {k}: mesh {} does not exist", inst.mesh)));
            }
            let at = instances + k * instance::LEN;
            out.put_u16(at + instance::MESH.start, inst.mesh);
            out.put_affine(at + instance::WORLD.start, &inst.world);
        }
        let lights = out.reserve(light::LEN * scene.lights.len());
        out.put_u32(header::LIGHTS.start, lights as u32);
        for (k, l) in scene.lights.iter().enumerate() {
            let at = lights + k * light::LEN;
            out.put(at + light::KIND, &[l.kind as u8]);
            out.put_f32s(at + light::VECTOR.start, &l.vector);
            out.put_f32s(at + light::DIFFUSE.start, &l.diffuse);
            out.put_f32s(at + light::INTENSITY.start, &[l.intensity]);
        }
        if let Some(c) = &scene.camera {
            let at = out.reserve(camera::LEN);
            out.put_u32(header::CAMERA.start, at as u32);
            out.put_f32s(at + camera::POSITION.start, &c.position);
            out.put_f32s(at + camera::TARGET.start, &c.target);
            out.put_f32s(at + camera::FOV.start, &[c.fov, c.near, c.far]);
        }
        let len = u32::try_from(out.0.len()).map_err(|_| EmitError("scene larger than 4 GiB".into()))?;
        out.put_u32(header::FILE_LEN.start, len);
        // The writer must only produce what the reader accepts.
        Model::parse(&out.0).map_err(|e| EmitError(std::format!("internal error, emitted file invalid: {e}")))?;
        Ok(out.0)
    }

    /// Decodes a parsed model back into a [`Scene`]: the inverse of [`emit`] up to
    /// quantization (a second `emit` of the result gives the same bytes).
    #[must_use]
    pub fn to_scene(model: &Model<'_>) -> Scene {
        let matrix = |m: Mat4| m.to_cols_array();
        let wrap = |w: Wrap| match w {
            Wrap::Clamp => scene::Wrap::Clamp,
            Wrap::Repeat => scene::Wrap::Repeat,
            Wrap::Mirror => scene::Wrap::Mirror,
        };
        let meshes = model
            .meshes()
            .map(|m| {
                let n = m.vertex_count();
                scene::MeshData {
                    name: m.name().into(),
                    world: matrix(m.world()),
                    positions: (0..n).map(|i| m.position(i).to_array()).collect(),
                    normals: (0..n).map(|i| m.normal(i).to_array()).collect(),
                    uvs: m.has_uvs().then(|| (0..n).map(|i| m.uv(i)).collect()),
                    colors: m.has_colors().then(|| (0..n).map(|i| m.color(i).map(|c| c as f32 / 255.0)).collect()),
                    indices: (0..3 * m.triangle_count()).map(|k| m.index(k)).collect(),
                    submeshes: m
                        .submeshes()
                        .map(|s| scene::SubMeshData {
                            material: s.material,
                            index_start: 3 * s.first_triangle,
                            index_count: 3 * s.triangle_count,
                        })
                        .collect(),
                }
            })
            .collect();
        let materials = (0..model.material_count() as u16)
            .filter_map(|i| model.material(i))
            .map(|m| scene::MaterialData {
                name: String::new(),
                diffuse: [0, 1, 2].map(|k| m.rgba[k] as f32 / 255.0),
                alpha: m.rgba[3] as f32 / 255.0,
                back_face_culling: m.cull_back_faces,
                texture: m.texture,
                wrap_u: wrap(m.wrap_u),
                wrap_v: wrap(m.wrap_v),
            })
            .collect();
        let textures = (0..model.texture_count() as u16)
            .filter_map(|i| model.texture(i))
            .map(|t| scene::TextureData {
                name: String::new(),
                width: t.width,
                height: t.height,
                // Back to rows from the top of the image.
                rgba: (0..t.height as u32)
                    .rev()
                    .flat_map(|j| (0..t.width as u32).flat_map(move |i| t.rgba(i, j)))
                    .collect(),
            })
            .collect();
        let instances = (0..model.instance_count())
            .filter_map(|i| model.instance(i))
            .map(|(mesh, world)| scene::InstanceData { mesh: mesh as u16, world: matrix(world) })
            .collect();
        let lights = model
            .lights()
            .map(|l| scene::LightData {
                kind: match l.kind {
                    LightKind::Point => scene::LightKind::Point,
                    LightKind::Directional => scene::LightKind::Directional,
                    LightKind::Hemispheric => scene::LightKind::Hemispheric,
                },
                vector: l.vector.to_array(),
                diffuse: l.diffuse.to_array(),
                intensity: l.intensity,
            })
            .collect();
        let camera = model.camera().map(|c| scene::CameraData {
            position: c.position.to_array(),
            target: c.target.to_array(),
            fov: c.fov,
            near: c.near,
            far: c.far,
        });
        Scene { meshes, materials, textures, instances, lights, camera }
    }

    fn emit_mesh(
        out: &mut Out,
        at: usize,
        m: &scene::MeshData,
        n_materials: usize,
        float_positions: bool,
    ) -> Result<(), EmitError> {
        let fail = |what: String| EmitError(std::format!("mesh \"{}\": {what}", m.name));
        let nv = m.positions.len();
        if nv == 0 || nv > u32::MAX as usize {
            return Err(fail(std::format!("{nv} vertices")));
        }
        if m.normals.len() != nv
            || m.uvs.as_ref().is_some_and(|u| u.len() != nv)
            || m.colors.as_ref().is_some_and(|c| c.len() != nv)
        {
            return Err(fail("normals/uvs/colors and positions differ in length".into()));
        }
        if !m.indices.len().is_multiple_of(3) {
            return Err(fail(std::format!("{} indices is not a multiple of 3", m.indices.len())));
        }
        if let Some((k, i)) = m.indices.iter().enumerate().find(|(_, &i)| i as usize >= nv) {
            return Err(fail(std::format!("indices[{k}] = {i} but only {nv} vertices")));
        }
        out.put_affine(at + mesh::WORLD.start, &m.world);
        let (pos_offset, pos_scale) =
            if float_positions { ([0.0; 3], [1.0; 3]) } else { quantizer(m.positions.iter().copied()) };
        out.put_f32s(at + mesh::POS_OFFSET.start, &pos_offset);
        out.put_f32s(at + mesh::POS_SCALE.start, &pos_scale);
        out.put_f32s(at + mesh::BOUNDS.start, &bounding_sphere(&m.positions));
        out.put_u32(at + mesh::VERTEX_COUNT.start, nv as u32);
        out.put_u32(at + mesh::INDEX_COUNT.start, m.indices.len() as u32);
        let wide = nv > u16::MAX as usize + 1;
        let flags = u16::from(wide) * mesh::FLAG_U32_INDICES
            + u16::from(m.uvs.is_some()) * mesh::FLAG_UVS
            + u16::from(m.colors.is_some()) * mesh::FLAG_COLORS
            + u16::from(float_positions) * mesh::FLAG_F32_POSITIONS;
        out.put_u16(at + mesh::FLAGS.start, flags);

        let name = m.name.as_bytes();
        let name = &name[..name.len().min(u16::MAX as usize)];
        let name = match core::str::from_utf8(name) {
            Ok(s) => s.as_bytes(),
            Err(e) => &name[..e.valid_up_to()],
        };
        let name_at = out.append(name);
        out.put_u32(at + mesh::NAME.start, name_at);
        out.put_u16(at + mesh::NAME_LEN.start, name.len() as u16);

        let positions: Vec<u8> = if float_positions {
            m.positions.iter().flatten().flat_map(|v| v.to_le_bytes()).collect()
        } else {
            m.positions
                .iter()
                .flat_map(|p| (0..3).flat_map(move |k| quantize(p[k], pos_offset[k], pos_scale[k]).to_le_bytes()))
                .collect()
        };
        let o = out.append(&positions);
        out.put_u32(at + mesh::POSITIONS.start, o);
        let normals: Vec<u8> = m
            .normals
            .iter()
            .flat_map(|n| n.map(|c| (libm::roundf(c.clamp(-1.0, 1.0) * NORMAL_ONE) as i16).to_le_bytes()))
            .flatten()
            .collect();
        let o = out.append(&normals);
        out.put_u32(at + mesh::NORMALS.start, o);
        if let Some(uvs) = &m.uvs {
            let (uv_offset, uv_scale) = quantizer(uvs.iter().copied());
            out.put_f32s(at + mesh::UV_OFFSET.start, &uv_offset);
            out.put_f32s(at + mesh::UV_SCALE.start, &uv_scale);
            let bytes: Vec<u8> = uvs
                .iter()
                .flat_map(|uv| (0..2).flat_map(move |k| quantize(uv[k], uv_offset[k], uv_scale[k]).to_le_bytes()))
                .collect();
            let o = out.append(&bytes);
            out.put_u32(at + mesh::UVS.start, o);
        }
        if let Some(colors) = &m.colors {
            let bytes: Vec<u8> = colors.iter().flat_map(|c| c.map(unit_to_u8)).collect();
            let o = out.append(&bytes);
            out.put_u32(at + mesh::COLORS.start, o);
        }
        let indices: Vec<u8> = if wide {
            m.indices.iter().flat_map(|i| i.to_le_bytes()).collect()
        } else {
            m.indices.iter().flat_map(|&i| (i as u16).to_le_bytes()).collect()
        };
        let o = out.append(&indices);
        out.put_u32(at + mesh::INDICES.start, o);

        let whole = [scene::SubMeshData { material: None, index_start: 0, index_count: m.indices.len() as u32 }];
        let subs = if m.submeshes.is_empty() { &whole[..] } else { &m.submeshes[..] };
        let n_sub = count_u16(subs.len(), "sub-meshes")?;
        out.put_u16(at + mesh::SUBMESH_COUNT.start, n_sub);
        let s_at = out.reserve(subs.len() * submesh::LEN);
        out.put_u32(at + mesh::SUBMESHES.start, s_at as u32);
        for (k, s) in subs.iter().enumerate() {
            let r = s_at + k * submesh::LEN;
            if s.material.is_some_and(|mi| mi as usize >= n_materials) {
                return Err(fail(std::format!("sub-mesh {k}: material {:?} does not exist", s.material)));
            }
            out.put_u16(r + submesh::MATERIAL.start, s.material.unwrap_or(NONE));
            out.put_u32(r + submesh::INDEX_START.start, s.index_start);
            out.put_u32(r + submesh::INDEX_COUNT.start, s.index_count);
        }
        Ok(())
    }

    /// 0..=1 to 0..=255, `floor(v * 255 + 0.5)` as Babylon does.
    fn unit_to_u8(v: f32) -> u8 {
        libm::floorf(v.clamp(0.0, 1.0) * 255.0 + 0.5) as u8
    }

    fn emit_material(out: &mut Out, at: usize, m: &scene::MaterialData, n_textures: usize) -> Result<(), EmitError> {
        let [r, g, b] = m.diffuse.map(unit_to_u8);
        out.put(at + material::RGBA.start, &[r, g, b, unit_to_u8(m.alpha)]);
        out.put(at + material::FLAGS, &[u8::from(m.back_face_culling) * material::FLAG_CULL_BACK]);
        let wrap = |w: scene::Wrap| match w {
            scene::Wrap::Clamp => Wrap::Clamp as u8,
            scene::Wrap::Repeat => Wrap::Repeat as u8,
            scene::Wrap::Mirror => Wrap::Mirror as u8,
        };
        out.put(at + material::WRAP_U, &[wrap(m.wrap_u), wrap(m.wrap_v)]);
        if m.texture.is_some_and(|t| t as usize >= n_textures) {
            return Err(EmitError(std::format!("material \"{}\": texture {:?} does not exist", m.name, m.texture)));
        }
        out.put_u16(at + material::TEXTURE.start, m.texture.unwrap_or(NONE));
        Ok(())
    }

    fn emit_texture(out: &mut Out, at: usize, t: &scene::TextureData, opts: &EmitOptions) -> Result<(), EmitError> {
        let (w, h) = (t.width as usize, t.height as usize);
        if w == 0 || h == 0 || t.rgba.len() != w * h * 4 {
            return Err(EmitError(std::format!("texture \"{}\": {}x{} with {} bytes", t.name, w, h, t.rgba.len())));
        }
        let format = match opts.textures {
            TextureChoice::Fixed(f) => f,
            TextureChoice::Auto if t.has_alpha() => TextureFormat::Rgba5551,
            TextureChoice::Auto => TextureFormat::Rgb565,
        };
        out.put_u16(at + texture::WIDTH.start, t.width);
        out.put_u16(at + texture::HEIGHT.start, t.height);
        out.put(at + texture::FORMAT, &[format as u8]);
        let n = format.bytes_per_texel();
        // Stored bottom row first, so that j = floor(v * height) indexes rows directly.
        let texels: Vec<u8> = t
            .rgba
            .chunks_exact(w * 4)
            .rev()
            .flat_map(|row| row.chunks_exact(4))
            .flat_map(|c| encode_texel(format, [c[0], c[1], c[2], c[3]]).into_iter().take(n))
            .collect();
        let o = out.append(&texels);
        out.put_u32(at + texture::DATA.start, o);
        Ok(())
    }
}
