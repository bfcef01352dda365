//! Why a byte slice is not a valid `.s3d` file: [`ParseError`], with the [`Part`] of the file
//! and the byte offset it is about. Finding the errors is `model`'s job.

use core::fmt;

use super::layout::{MIN_VERSION, VERSION};

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
    /// The animation section's header.
    Animation,
    /// An animated node's record.
    Node,
    /// A mesh's link to an animated node.
    Link,
    /// A morph record, a morph target record or its deltas.
    Morph,
    /// A track record or its keys.
    Track,
    /// An animation group's record, track list or name.
    Group,
    /// A skin record, its bones or its vertices' influences.
    Skin,
    /// The fog record.
    Fog,
    /// The animated camera record.
    AnimatedCamera,
    /// An animated light record.
    AnimatedLight,
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
            Part::Animation => "animation section",
            Part::Node => "animated node record",
            Part::Link => "mesh link record",
            Part::Morph => "morph target data",
            Part::Track => "animation track",
            Part::Group => "animation group",
            Part::Skin => "skin",
            Part::Fog => "fog record",
            Part::AnimatedCamera => "animated camera record",
            Part::AnimatedLight => "animated light record",
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
    /// The slice does not start with [`MAGIC`](super::MAGIC).
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
                write!(f, "unsupported .s3d version {v} at offset 4 (this reader knows {MIN_VERSION} to {VERSION})")
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
