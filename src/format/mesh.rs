//! One mesh of a [`Model`](super::Model): its record ([`Mesh`]), its sub-meshes and its vertex
//! and index arrays ([`Arrays`]), read in place. Every read is of data that `Model::parse`
//! validated; out-of-range reads give zero, never a panic.

use core::ops::Range;

use super::deform::Deforming;
use super::layout::*;
use super::model::WorldAt;
use crate::math::{Mat4, Vec3};

/// One mesh of a [`Model`](super::Model).
#[derive(Clone, Copy, Debug)]
pub struct Mesh<'a> {
    /// The whole file.
    pub(super) data: &'a [u8],
    /// Offset of this mesh's record.
    pub(super) at: usize,
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
        affine_at(self.data, self.world_at().0)
    }

    /// Where the mesh's world matrix lies in the model's bytes (see `Model::placed_draws`).
    pub(crate) fn world_at(&self) -> WorldAt {
        WorldAt(self.at + mesh::WORLD.start)
    }

    /// This mesh's index in its model.
    #[must_use]
    pub fn mesh_index(&self) -> usize {
        let table = u32_at(self.data, header::MESHES.start) as usize;
        self.at.saturating_sub(table) / mesh::LEN
    }

    /// The matrix that turns a stored position ([`Mesh::position_stored`]) into a local one.
    #[must_use]
    pub fn dequantize(&self) -> Mat4 {
        let (scale, offset) = self.dequantization();
        Mat4::from_scale_rotation_translation(scale, glam::Quat::IDENTITY, offset)
    }

    /// [`Mesh::dequantize`]'s scale and offset.
    #[must_use]
    pub fn dequantization(&self) -> (Vec3, Vec3) {
        (vec3_at(self.data, self.at + mesh::POS_SCALE.start), vec3_at(self.data, self.at + mesh::POS_OFFSET.start))
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
        // `parse` checked every section's range (and that its length fits usize); an impossible
        // one reads as empty (zeros).
        let slice = |field: Range<usize>, (count, record_len): (usize, usize)| {
            let at = self.u32_field(field) as usize;
            d.get(at..at.saturating_add(count.saturating_mul(record_len))).unwrap_or(&[])
        };
        Arrays {
            morph: None,
            positions: if self.has_f32_positions() {
                Positions::F32(slice(mesh::POSITIONS, (nv, 12)).as_chunks().0)
            } else {
                Positions::Quantized(slice(mesh::POSITIONS, (nv, POSITION_LEN)).as_chunks().0)
            },
            normals: slice(mesh::NORMALS, (nv, NORMAL_LEN)).as_chunks().0,
            uvs: self.has_uvs().then(|| slice(mesh::UVS, (nv, UV_LEN)).as_chunks().0),
            colors: self.has_colors().then(|| slice(mesh::COLORS, (nv, COLOR_LEN)).as_chunks().0),
            indices: if self.has_u32_indices() {
                Indices::U32(slice(mesh::INDICES, (ni, 4)).as_chunks().0)
            } else {
                Indices::U16(slice(mesh::INDICES, (ni, 2)).as_chunks().0)
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

/// A mesh's vertex and index arrays as slices of fixed-size records, resolved once per draw
/// (see [`Mesh::arrays`]) so that reading a vertex is one bounds check and a few loads.
/// Out-of-range reads give zero, like every accessor here.
#[derive(Clone, Copy, Debug)]
pub struct Arrays<'a> {
    /// A pose's deformation (see `Arrays::morphed`): applied to every position and normal read.
    morph: Option<&'a Deforming<'a>>,
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

impl<'a> Arrays<'a> {
    /// The 16-bit indices, when they are (the common width: a triangle loop can test it once,
    /// see [`U16Triangles`]).
    #[inline]
    #[must_use]
    pub(crate) fn u16_triangles(&self) -> Option<U16Triangles<'a>> {
        match self.indices {
            Indices::U16(x) => Some(U16Triangles(x)),
            Indices::U32(_) => None,
        }
    }

    /// These arrays with `morph`'s deltas added to every position and normal read (normals
    /// then normalised, as Babylon.js's shader does).
    #[must_use]
    pub(crate) fn morphed(self, morph: &'a Deforming<'a>) -> Self {
        Arrays { morph: Some(morph), ..self }
    }

    /// See [`Mesh::position_stored`].
    #[inline]
    #[must_use]
    pub fn position_stored(&self, i: u32) -> Vec3 {
        self.position_as::<true>(i)
    }

    /// [`Arrays::position_stored`], morphed only when `MORPHS` (a loop over a still mesh's
    /// vertices reads them with `false`: tested at each vertex, the morph cost 19 instructions
    /// a vertex, as LLVM reloads the test after every write to the vertex cache).
    #[inline]
    #[must_use]
    pub(crate) fn position_as<const MORPHS: bool>(&self, i: u32) -> Vec3 {
        let p = match self.positions {
            Positions::F32(p) => p.get(i as usize).map_or(Vec3::ZERO, |r| vec3_at(r, 0)),
            Positions::Quantized(p) => p
                .get(i as usize)
                .map_or(Vec3::ZERO, |r| Vec3::new(u16_at(r, 0) as f32, u16_at(r, 2) as f32, u16_at(r, 4) as f32)),
        };
        match self.morph.filter(|_| MORPHS) {
            Some(m) => m.position(p, i),
            None => p,
        }
    }

    /// Whether a pose's morph targets move these arrays' vertices.
    #[inline(always)]
    #[must_use]
    pub(crate) fn is_morphed(&self) -> bool {
        self.morph.is_some()
    }

    /// Vertex `i`'s stored position as integers within ±2^15, for
    /// [`FixedTransform`](crate::math::FixedTransform): stored = `offset + q·step` with
    /// `(offset, step)` from [`Arrays::int_position_frame`]. Float positions are mapped into the
    /// bounding sphere `sphere` (clamped to it).
    #[inline]
    #[must_use]
    pub fn position_int(&self, i: u32, sphere: (Vec3, f32)) -> [i32; 3] {
        // Morphed draws take the f32 transform (`Transforms::new`): no morph here.
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
        self.normal_q_as::<true>(i)
    }

    /// [`Arrays::normal_q`], morphed only when `MORPHS` (see [`Arrays::position_as`]).
    #[inline]
    #[must_use]
    pub(crate) fn normal_q_as<const MORPHS: bool>(&self, i: u32) -> [i16; 3] {
        if let Some(m) = self.morph.filter(|_| MORPHS) {
            return m.normal_q(self.normal(i));
        }
        self.stored_normal_q(i)
    }

    fn stored_normal_q(&self, i: u32) -> [i16; 3] {
        self.normals.get(i as usize).map_or([0; 3], |r| [i16_at(r, 0), i16_at(r, 2), i16_at(r, 4)])
    }

    /// See [`Mesh::normal`].
    #[inline]
    #[must_use]
    pub fn normal(&self, i: u32) -> Vec3 {
        self.normal_as::<true>(i)
    }

    /// [`Arrays::normal`], morphed only when `MORPHS` (see [`Arrays::position_as`]).
    #[inline]
    #[must_use]
    pub(crate) fn normal_as<const MORPHS: bool>(&self, i: u32) -> Vec3 {
        let q = self.stored_normal_q(i);
        let n = Vec3::new(q[0] as f32, q[1] as f32, q[2] as f32) / NORMAL_ONE;
        match self.morph.filter(|_| MORPHS) {
            Some(m) => m.normal(n, i),
            None => n,
        }
    }

    /// See [`Mesh::uv_q`].
    #[inline]
    #[must_use]
    pub fn uv_q(&self, i: u32) -> [u16; 2] {
        self.uvs.and_then(|u| u.get(i as usize)).map_or([0; 2], |r| [u16_at(r, 0), u16_at(r, 2)])
    }

    /// Whether the mesh has vertex colours (without, [`Arrays::color`] is opaque white).
    #[inline]
    #[must_use]
    pub fn has_colors(&self) -> bool {
        self.colors.is_some()
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
        let k = 3 * t;
        // One bounds check for the three (the per-triangle front end), when all are there.
        let whole = match self.indices {
            Indices::U16(x) => corners(x, k).map(|c| c.map(|r| u16::from_le_bytes(r) as u32)),
            Indices::U32(x) => corners(x, k).map(|c| c.map(u32::from_le_bytes)),
        };
        whole.unwrap_or_else(|| [self.index(k), self.index(k + 1), self.index(k + 2)])
    }
}

/// A mesh's 16-bit indices (see [`Arrays::u16_triangles`]): a loop that tested the index
/// width once reads a triangle's corners without testing it again.
#[derive(Clone, Copy, Debug)]
pub(crate) struct U16Triangles<'a>(&'a [[u8; 2]]);

impl U16Triangles<'_> {
    /// Triangle `t`'s three indices, when all are there ([`Arrays::triangle`] gives the
    /// others).
    #[inline(always)]
    pub(crate) fn triangle(&self, t: u32) -> Option<[u32; 3]> {
        corners(self.0, 3 * t).map(|c| c.map(|r| u16::from_le_bytes(r) as u32))
    }
}

/// The three entries of `x` from `k` on, when all are there.
#[inline(always)]
fn corners<T: Copy>(x: &[T], k: u32) -> Option<[T; 3]> {
    match x.get(k as usize..)? {
        [a, b, c, ..] => Some([*a, *b, *c]),
        _ => None,
    }
}
