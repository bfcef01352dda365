//! What a vertex carries to the pixels: the varyings, by name.
//!
//! The rasterizer interpolates plain arrays (`[FDot16; V]`), so that one generic set-up and row
//! walk serves every pipeline variant; which attribute sits in which element is a *layout*,
//! named here once. Every layout starts with the texel coordinates; each variant interpolates
//! only the prefix it uses (`V` elements), so a white-lit triangle carries 3 varyings and a
//! Phong one 8.
//!
//! | variant | layout | `V` | elements |
//! |---|---|---|---|
//! | white vertex light | [`VertexLit`] | 3 | u, v, light |
//! | coloured vertex light (unlit, flat, Gouraud) | [`VertexLit`] | 5 | u, v, red, green, blue |
//! | the same with specular | [`VertexLit`] | 6 | u, v, red, green, blue, specular |
//! | per-pixel light (Phong) | [`PixelLit`] | 8 | u, v, normal x, y, z, world x, y, z |
//!
//! Units: texel coordinates in texels, light in 0..=1, normals and world positions as they
//! are — all in [`FDot16`] once projected (f32 before: clipping interpolates them in f32).
//! Computing them is `vertex`'s job; interpolating them is `raster`'s.

use crate::fixed::FDot16;

/// The most varyings a vertex carries (the Phong layout).
pub const MAX_VARYINGS: usize = 8;

/// Fractional bits of varyings in the span loop (16.16).
pub const VARYING_FRAC: u32 = 16;

/// The varyings of one vertex before projection (f32, in [`FDot16`] units).
pub(crate) type ClipVaryings = [f32; MAX_VARYINGS];

/// The varyings of one vertex after projection.
pub(crate) type ScreenVaryings = [FDot16; MAX_VARYINGS];

/// The layout of vertex-lit variants (unlit, flat, Gouraud): light interpolated from the
/// vertices, optionally a specular intensity.
pub(crate) struct VertexLit;

impl VertexLit {
    /// Texel coordinate u.
    pub const U: usize = 0;
    /// Texel coordinate v.
    pub const V: usize = 1;
    /// Light red, green, blue (white light: red alone).
    pub const LIGHT: usize = 2;
    /// Specular intensity, added after the texture is lit.
    pub const SPECULAR: usize = 5;
    /// Elements of the white-light prefix.
    pub const WHITE_LEN: usize = 3;
    /// Elements without specular.
    pub const COLOR_LEN: usize = 5;
    /// Elements with specular.
    pub const SPECULAR_LEN: usize = 6;

    /// Light per channel at a pixel.
    #[inline(always)]
    pub fn light<const V: usize>(v: &[FDot16; V]) -> [FDot16; 3] {
        [v[Self::LIGHT], v[Self::LIGHT + 1], v[Self::LIGHT + 2]]
    }

    /// White light at a pixel (one element for all three channels).
    #[inline(always)]
    pub fn white<const V: usize>(v: &[FDot16; V]) -> [FDot16; 3] {
        [v[Self::LIGHT]; 3]
    }
}

/// The layout of per-pixel lighting (Phong): normal and world position interpolated.
pub(crate) struct PixelLit;

impl PixelLit {
    /// First of the world-space normal's three elements.
    pub const NORMAL: usize = 2;
    /// First of the world position's three elements.
    pub const POSITION: usize = 5;
    /// Elements.
    pub const LEN: usize = 8;

    /// The interpolated normal and world position at a pixel.
    #[inline(always)]
    pub fn normal_and_position<const V: usize>(v: &[FDot16; V]) -> ([FDot16; 3], [FDot16; 3]) {
        let (n, p) = (Self::NORMAL, Self::POSITION);
        ([v[n], v[n + 1], v[n + 2]], [v[p], v[p + 1], v[p + 2]])
    }
}

/// Texel coordinates (u, v) at a pixel: the first two elements of every layout.
#[inline(always)]
pub(crate) fn texel_coordinates<const V: usize>(v: &[FDot16; V]) -> (FDot16, FDot16) {
    (v[VertexLit::U], v[VertexLit::V])
}

/// Whether varying `k` is a texel coordinate (their affine tolerance is in texels).
#[inline(always)]
pub(crate) fn is_texel_coordinate(k: usize) -> bool {
    k == VertexLit::U || k == VertexLit::V
}

const _: () = assert!(PixelLit::LEN == MAX_VARYINGS && VertexLit::SPECULAR_LEN <= MAX_VARYINGS);
