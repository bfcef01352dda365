//! The `.s3d` byte layout, in one place: the field offsets and record sizes that the parser
//! ([`super::model`]) reads and the host converter (`convert::emit`) writes, the codes stored in
//! it, and the little-endian field readers. It owns no parsing logic and no validation.
//!
//! # Layout
//! All numbers are little-endian and read with `from_le_bytes`, so the file can sit at any
//! alignment (`include_bytes!` gives alignment 1). Offsets are byte offsets from the start of
//! the file. `f32` fields must be finite. Unused (`reserved`) bytes are written as zero.
//!
//! **Header** (48 bytes at offset 0; 52 in version 2, 56 in version 3)
//!
//! | bytes  | type     | field                                             |
//! |--------|----------|---------------------------------------------------|
//! | 0..4   | `[u8;4]` | magic `S3D\0`                                      |
//! | 4..6   | u16      | version, [`VERSION`]                               |
//! | 6..8   | u16      | flags (version 2; 0 in version 1): bit 0, the animation section is extended (camera and light animation) |
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
//! | 48..52 | u32      | version 2 and later: offset of the animation section (40 bytes, 52 extended), 0 = none |
//! | 52..56 | u32      | version 3 and later: offset of the fog record (28 bytes), 0 = none |
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
//!
//! **Fog** (28 bytes, version 3): 0 u8 mode ([`FogMode`](crate::FogMode): 1 exp, 2 exp2, 3
//! linear), 1..4 reserved, 4..16 3 x f32 colour, 16..20 f32 density (>= 0), 20..24 f32 start,
//! 24..28 f32 end. The converter writes version 3 only for a scene with fog, version 2 for an
//! animated scene without, version 1 for the rest: the lowest version that holds the scene.
//!
//! # Animation
//! Version 2 files may have one (version 1 files, which end their header at 48, have none;
//! the converter writes version 1 for a still scene, so that its files read everywhere). What the records mean is `convert::scene`'s
//! `AnimationData`: animated nodes, the meshes that follow them, morph targets, tracks, groups.
//!
//! **Animation section** (40 bytes; 52 extended): 0..2 u16 node count, 2..4 u16 link count,
//! 4..6 u16 morph count, 6..8 u16 track count, 8..10 u16 group count, 10..12 u16 weight count
//! (all meshes' morph targets, then the camera's and lights' slots below), then u32 offsets of
//! the node (12..16), link (16..20), morph (20..24), track (24..28) and group (28..32) tables,
//! 32..34 u16 skin count, 34..36 u16 palette count (all skins' bones), 36..40 u32 offset of
//! the skin table. Extended (header flag bit 0), it goes on: 40..44 u32 offset of the animated
//! camera record (0 = none), 44..46 u16 animated light count, 46..48 reserved, 48..52 u32
//! offset of the animated light table. Files written before the extension (flag clear) end the
//! section at 40 and read as before; the converter sets the flag only for a scene whose camera
//! or lights move, so every other file is the same, byte for byte, as before.
//!
//! A pose's weights ([`crate::animation::Pose`]) hold, after the morph weights, *slots*: the
//! values the camera's and the lights' tracks set, so that `pose_memory`'s weight count covers
//! them. The converter writes the camera's slots right after the morph weights and each
//! animated light's after those; every record names its own first slot, inside the weight
//! count.
//!
//! **Animated camera** (48 bytes, at most one, for the model's camera record, which must exist):
//! 0..2 u16 aim (how the point looked at follows: 0 target, the target slots are that point;
//! 1 direction, `position + (rest target - rest position)`; 2 rotation,
//! `position + distance · forward(rotation)`, forward being `(0, 0, 1)` turned by Babylon's
//! `RotationYawPitchRoll(y, x, z)`), 2..4 u16 first slot (10 slots: position x, y, z, target
//! x, y, z, fov, rotation x, y, z), then the rest values: 4..16 position, 16..28 target, 28..32
//! fov (0 < fov < pi), 32..44 Euler rotation, 44..48 distance (>= 0).
//!
//! **Animated light** (32 bytes, in increasing light order, one a light at most): 0..2 u16
//! light (an index into the light table), 2..4 u16 first slot (7 slots: vector x, y, z,
//! diffuse r, g, b, intensity), then the rest values as in the light record: 4..16 position or
//! direction, 16..28 diffuse, 28..32 intensity.
//!
//! **Node** (92 bytes): 0..2 u16 parent node ([`NONE`] or a lower index), 2..4 u16 flags (bit
//! 0: the rotation is a quaternion), 4..16 3 x f32 position, 16..32 4 x f32 rotation (Euler x,
//! y, z and 0, or quaternion x, y, z, w), 32..44 3 x f32 scaling, 44..92 the `above` matrix (as
//! a mesh's world matrix).
//!
//! **Link** (52 bytes): 0..2 u16 mesh, 2..4 u16 node, 4..52 the `below` matrix. Links are
//! in increasing mesh order (so a mesh has at most one).
//!
//! **Morph** (12 bytes, in increasing mesh order): 0..2 u16 mesh, 2..4 u16 target count (>=
//! 1), 4..6 u16 first weight (its targets' weights are `first..first + count`, inside the
//! weight count), 6..8 u16 flags (bit 0: normal deltas), 8..12 u32 offset of its target
//! records.
//!
//! **Morph target** (20 bytes): 0..4 f32 default influence, 4..8 f32 position scale, 8..12 f32
//! normal scale, 12..16 u32 offset of the position deltas, 16..20 u32 offset of the normal
//! deltas (0 without). Deltas are `vertex count` x 3 x i16; a position delta is `q * scale`
//! in *stored* units (those of [`Mesh::position_stored`](super::Mesh::position_stored), so a
//! quantized mesh's delta is divided by its `pos_scale`), a normal delta `q * scale`. With
//! 16 bits over each target's largest delta, a delta is within 1/65534 of that largest one.
//!
//! **Track** (24 bytes): 0 u8 kind (0 position, 1 rotation, 2 scaling, 3 quaternion, 4 morph
//! influence; extended: 5 camera position, 6 camera target, 7 camera rotation, 8 camera fov,
//! 9 light position or direction, 10 light diffuse, 11 light intensity), 1 u8 first
//! component, 2 u8 component count (`first + count` <= 3, or 0 and 4 for a quaternion, 0 and
//! 1 for an influence, a fov and an intensity), 3 u8 flags (bits 0-1 loop: 0 relative, 1
//! cycle, 2 constant; bit 2 keys carry tangents), 4..6 u16 target (a node, for an influence a
//! morph weight, for a camera kind 0, for a light kind a light that has an animated light
//! record), 8..12 u32 key count (>= 1), 12..16 f32 frames a second (> 0), 16..20 u32 offset of
//! the keys.
//!
//! **Key** (`8 + 4 x count`, or `8 + 12 x count` with tangents): 0..4 f32 frame (keys in
//! increasing order, equal frames allowed), 4..8 u32 flags (bit 0: step; with tangents, bit 1:
//! no in tangent, bit 2: no out tangent, their values then zeros), the values, then the in and
//! out tangents. A span is Hermite when its first key has an out tangent and its last an in
//! tangent (Babylon.js's rule), else linear.
//!
//! **Skin** (16 bytes, in increasing mesh order): 0..2 u16 mesh, 2..4 u16 bone count (>= 1),
//! 4..6 u16 first palette slot (its bones' matrices are `first..first + count` of a pose's
//! palette, inside the palette count), 8..12 u32 offset of its bone records, 12..16 u32 offset
//! of its vertices. **Bone** (52 bytes): 0..2 u16 node, 4..52 the inverse bind matrix (as a
//! mesh's world matrix). **Skinned vertex** (12 bytes, one a mesh vertex): 0..4 four u8 bone
//! indices (< the bone count), 4..12 four u16 weights (`q / 65535`).
//!
//! **Group** (24 bytes): 0..4 f32 from, 4..8 f32 to (>= from), 8..10 u16 track count, 10 u8
//! flags (bit 0: loops), 12..16 u32 offset of its track indices (u16 each, < the track count),
//! 16..18 u16 name length, 20..24 u32 offset of the name (UTF-8).

use crate::math::{Mat4, Vec3};

/// The first four bytes of every `.s3d` file.
pub const MAGIC: [u8; 4] = *b"S3D\0";
/// The newest format version this crate reads and writes (it reads versions 1 and 2 too, and
/// writes the lowest that holds a scene: see the fog record).
pub const VERSION: u16 = 3;
/// The oldest format version this crate reads.
pub const MIN_VERSION: u16 = 1;
/// A `u16` reference that points at nothing (no material, no texture).
pub const NONE: u16 = u16::MAX;

pub(crate) mod header {
    use core::ops::Range;
    pub const MAGIC: Range<usize> = 0..4;
    pub const VERSION: Range<usize> = 4..6;
    pub const FLAGS: Range<usize> = 6..8;
    /// The animation section is extended (52 bytes: camera and light animation).
    pub const FLAG_EXTENDED_ANIMATION: u16 = 1;
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
    pub const ANIMATION: Range<usize> = 48..52;
    /// The header's length in version 2.
    pub const LEN_V2: usize = 52;
    pub const FOG: Range<usize> = 52..56;
    /// The header's length in version 3.
    pub const LEN_V3: usize = 56;
}

pub(crate) mod animation {
    use core::ops::Range;
    pub const NODE_COUNT: Range<usize> = 0..2;
    pub const LINK_COUNT: Range<usize> = 2..4;
    pub const MORPH_COUNT: Range<usize> = 4..6;
    pub const TRACK_COUNT: Range<usize> = 6..8;
    pub const GROUP_COUNT: Range<usize> = 8..10;
    pub const WEIGHT_COUNT: Range<usize> = 10..12;
    pub const NODES: Range<usize> = 12..16;
    pub const LINKS: Range<usize> = 16..20;
    pub const MORPHS: Range<usize> = 20..24;
    pub const TRACKS: Range<usize> = 24..28;
    pub const GROUPS: Range<usize> = 28..32;
    pub const SKIN_COUNT: Range<usize> = 32..34;
    pub const PALETTE_COUNT: Range<usize> = 34..36;
    pub const SKINS: Range<usize> = 36..40;
    pub const LEN: usize = 40;
    pub const CAMERA: Range<usize> = 40..44;
    pub const LIGHT_COUNT: Range<usize> = 44..46;
    pub const LIGHTS: Range<usize> = 48..52;
    /// The extended section's length.
    pub const LEN_EXTENDED: usize = 52;
}

pub(crate) mod animated_camera {
    use core::ops::Range;
    pub const AIM: Range<usize> = 0..2;
    pub const FIRST_SLOT: Range<usize> = 2..4;
    pub const POSITION: Range<usize> = 4..16;
    pub const TARGET: Range<usize> = 16..28;
    pub const FOV: Range<usize> = 28..32;
    pub const ROTATION: Range<usize> = 32..44;
    pub const DISTANCE: Range<usize> = 44..48;
    pub const LEN: usize = 48;
    pub const AIM_TARGET: u16 = 0;
    pub const AIM_DIRECTION: u16 = 1;
    pub const AIM_ROTATION: u16 = 2;
    /// Slots: position, target, fov, rotation.
    pub const SLOTS: usize = 10;
    pub const SLOT_POSITION: usize = 0;
    pub const SLOT_TARGET: usize = 3;
    pub const SLOT_FOV: usize = 6;
    pub const SLOT_ROTATION: usize = 7;
}

pub(crate) mod animated_light {
    use core::ops::Range;
    pub const LIGHT: Range<usize> = 0..2;
    pub const FIRST_SLOT: Range<usize> = 2..4;
    pub const VECTOR: Range<usize> = 4..16;
    pub const DIFFUSE: Range<usize> = 16..28;
    pub const INTENSITY: Range<usize> = 28..32;
    pub const LEN: usize = 32;
    /// Slots: vector, diffuse, intensity.
    pub const SLOTS: usize = 7;
    pub const SLOT_VECTOR: usize = 0;
    pub const SLOT_DIFFUSE: usize = 3;
    pub const SLOT_INTENSITY: usize = 6;
}

pub(crate) mod node {
    use core::ops::Range;
    pub const PARENT: Range<usize> = 0..2;
    pub const FLAGS: Range<usize> = 2..4;
    pub const POSITION: Range<usize> = 4..16;
    pub const ROTATION: Range<usize> = 16..32;
    pub const SCALING: Range<usize> = 32..44;
    pub const ABOVE: Range<usize> = 44..92;
    pub const LEN: usize = 92;
    pub const FLAG_QUATERNION: u16 = 1;
}

pub(crate) mod link {
    use core::ops::Range;
    pub const MESH: Range<usize> = 0..2;
    pub const NODE: Range<usize> = 2..4;
    pub const BELOW: Range<usize> = 4..52;
    pub const LEN: usize = 52;
}

pub(crate) mod morph {
    use core::ops::Range;
    pub const MESH: Range<usize> = 0..2;
    pub const TARGET_COUNT: Range<usize> = 2..4;
    pub const FIRST_WEIGHT: Range<usize> = 4..6;
    pub const FLAGS: Range<usize> = 6..8;
    pub const TARGETS: Range<usize> = 8..12;
    pub const LEN: usize = 12;
    pub const FLAG_NORMALS: u16 = 1;
}

pub(crate) mod morph_target {
    use core::ops::Range;
    pub const INFLUENCE: Range<usize> = 0..4;
    pub const POSITION_SCALE: Range<usize> = 4..8;
    pub const NORMAL_SCALE: Range<usize> = 8..12;
    pub const POSITIONS: Range<usize> = 12..16;
    pub const NORMALS: Range<usize> = 16..20;
    pub const LEN: usize = 20;
    /// One delta: 3 x i16.
    pub const DELTA_LEN: usize = 6;
}

pub(crate) mod skin {
    use core::ops::Range;
    pub const MESH: Range<usize> = 0..2;
    pub const BONE_COUNT: Range<usize> = 2..4;
    pub const FIRST_SLOT: Range<usize> = 4..6;
    pub const BONES: Range<usize> = 8..12;
    pub const VERTICES: Range<usize> = 12..16;
    pub const LEN: usize = 16;
    pub const BONE_NODE: Range<usize> = 0..2;
    pub const BONE_INVERSE_BIND: Range<usize> = 4..52;
    pub const BONE_LEN: usize = 52;
    /// A skinned vertex: four u8 bone indices, four u16 weights.
    pub const VERTEX_LEN: usize = 12;
}

pub(crate) mod track {
    use core::ops::Range;
    pub const KIND: usize = 0;
    pub const FIRST: usize = 1;
    pub const COUNT: usize = 2;
    pub const FLAGS: usize = 3;
    pub const TARGET: Range<usize> = 4..6;
    pub const KEY_COUNT: Range<usize> = 8..12;
    pub const FPS: Range<usize> = 12..16;
    pub const KEYS: Range<usize> = 16..20;
    pub const LEN: usize = 24;
    pub const LOOP_MASK: u8 = 3;
    pub const FLAG_TANGENTS: u8 = 4;
    pub const KIND_POSITION: u8 = 0;
    pub const KIND_ROTATION: u8 = 1;
    pub const KIND_SCALING: u8 = 2;
    pub const KIND_QUATERNION: u8 = 3;
    pub const KIND_INFLUENCE: u8 = 4;
    pub const KIND_CAMERA_POSITION: u8 = 5;
    pub const KIND_CAMERA_TARGET: u8 = 6;
    pub const KIND_CAMERA_ROTATION: u8 = 7;
    pub const KIND_CAMERA_FOV: u8 = 8;
    pub const KIND_LIGHT_VECTOR: u8 = 9;
    pub const KIND_LIGHT_DIFFUSE: u8 = 10;
    pub const KIND_LIGHT_INTENSITY: u8 = 11;
}

pub(crate) mod key {
    use core::ops::Range;
    pub const FRAME: Range<usize> = 0..4;
    pub const FLAGS: Range<usize> = 4..8;
    pub const VALUES: usize = 8;
    pub const FLAG_STEP: u32 = 1;
    /// In a track with tangents: the key has no in tangent (its values are zeros).
    pub const FLAG_NO_IN_TANGENT: u32 = 2;
    /// In a track with tangents: the key has no out tangent.
    pub const FLAG_NO_OUT_TANGENT: u32 = 4;
    /// Every flag a key may have.
    pub const FLAGS_ALL: u32 = FLAG_STEP | FLAG_NO_IN_TANGENT | FLAG_NO_OUT_TANGENT;
}

pub(crate) mod group {
    use core::ops::Range;
    pub const FROM: Range<usize> = 0..4;
    pub const TO: Range<usize> = 4..8;
    pub const TRACK_COUNT: Range<usize> = 8..10;
    pub const FLAGS: usize = 10;
    pub const TRACKS: Range<usize> = 12..16;
    pub const NAME_LEN: Range<usize> = 16..18;
    pub const NAME: Range<usize> = 20..24;
    pub const LEN: usize = 24;
    pub const FLAG_LOOP: u8 = 1;
}

pub(crate) mod mesh {
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

pub(crate) mod submesh {
    use core::ops::Range;
    pub const MATERIAL: Range<usize> = 0..2;
    pub const INDEX_START: Range<usize> = 4..8;
    pub const INDEX_COUNT: Range<usize> = 8..12;
    pub const LEN: usize = 12;
}

pub(crate) mod material {
    use core::ops::Range;
    pub const RGBA: Range<usize> = 0..4;
    pub const FLAGS: usize = 4;
    pub const WRAP_U: usize = 5;
    pub const WRAP_V: usize = 6;
    pub const TEXTURE: Range<usize> = 8..10;
    pub const LEN: usize = 12;
    pub const FLAG_CULL_BACK: u8 = 1;
}

pub(crate) mod texture {
    use core::ops::Range;
    pub const WIDTH: Range<usize> = 0..2;
    pub const HEIGHT: Range<usize> = 2..4;
    pub const FORMAT: usize = 4;
    pub const DATA: Range<usize> = 8..12;
    pub const LEN: usize = 12;
}

pub(crate) mod instance {
    use core::ops::Range;
    pub const MESH: Range<usize> = 0..2;
    pub const WORLD: Range<usize> = 4..52;
    pub const LEN: usize = 52;
}

pub(crate) mod light {
    use core::ops::Range;
    pub const KIND: usize = 0;
    pub const VECTOR: Range<usize> = 4..16;
    pub const DIFFUSE: Range<usize> = 16..28;
    pub const INTENSITY: Range<usize> = 28..32;
    pub const LEN: usize = 32;
}

pub(crate) mod fog {
    use core::ops::Range;
    pub const MODE: usize = 0;
    pub const COLOR: Range<usize> = 4..16;
    pub const DENSITY: Range<usize> = 16..20;
    pub const START: Range<usize> = 20..24;
    pub const END: Range<usize> = 24..28;
    pub const LEN: usize = 28;
}

pub(crate) mod camera {
    use core::ops::Range;
    pub const POSITION: Range<usize> = 0..12;
    pub const TARGET: Range<usize> = 12..24;
    pub const FOV: Range<usize> = 24..28;
    pub const NEAR: Range<usize> = 28..32;
    pub const FAR: Range<usize> = 32..36;
    pub const LEN: usize = 36;
}

/// Size in bytes of one quantized position.
pub(crate) const POSITION_LEN: usize = 6;
/// Size in bytes of one quantized normal.
pub(crate) const NORMAL_LEN: usize = 6;
/// Size in bytes of one quantized UV.
pub(crate) const UV_LEN: usize = 4;
/// Size in bytes of one vertex colour.
pub(crate) const COLOR_LEN: usize = 4;
/// The quantized value of a normal component of 1.0.
pub const NORMAL_ONE: f32 = 32767.0;
/// The largest quantized position or UV value.
pub const QUANT_MAX: f32 = 65535.0;

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
    pub(crate) fn from_u8(v: u8) -> Option<Self> {
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
    pub(crate) fn from_u8(v: u8) -> Option<Self> {
        match v {
            0 => Some(Self::Point),
            1 => Some(Self::Directional),
            3 => Some(Self::Hemispheric),
            _ => None,
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Little-endian field readers. They never panic: a read past the end yields zero, and `parse`
// has checked beforehand that no accessor of a valid `Model` ever reads past the end.

pub(crate) fn bytes_at<const N: usize>(data: &[u8], at: usize) -> [u8; N] {
    data.get(at..at.wrapping_add(N)).and_then(|s| s.try_into().ok()).unwrap_or([0; N])
}
pub(crate) fn u16_at(data: &[u8], at: usize) -> u16 {
    u16::from_le_bytes(bytes_at(data, at))
}
pub(crate) fn i16_at(data: &[u8], at: usize) -> i16 {
    i16::from_le_bytes(bytes_at(data, at))
}
pub(crate) fn u32_at(data: &[u8], at: usize) -> u32 {
    u32::from_le_bytes(bytes_at(data, at))
}
pub(crate) fn f32_at(data: &[u8], at: usize) -> f32 {
    f32::from_le_bytes(bytes_at(data, at))
}
pub(crate) fn u8_at(data: &[u8], at: usize) -> u8 {
    data.get(at).copied().unwrap_or(0)
}
pub(crate) fn vec3_at(data: &[u8], at: usize) -> Vec3 {
    Vec3::new(f32_at(data, at), f32_at(data, at + 4), f32_at(data, at + 8))
}
/// Reads 12 floats: Babylon rows 0..3, columns 0..2, as a glam matrix.
pub(crate) fn affine_at(data: &[u8], at: usize) -> Mat4 {
    let row = |r: usize| vec3_at(data, at + r * 12);
    Mat4::from_cols(row(0).extend(0.0), row(1).extend(0.0), row(2).extend(0.0), row(3).extend(1.0))
}
