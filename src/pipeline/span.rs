//! The span loop: the per-pixel work of a triangle (depth test, base colour, light, store)
//! over each run of pixels, and where a pixel's base colour comes from ([`Base`]). Runs come
//! from the rasterizer through `dyn` ([`SpanSink`]), or, for the fast bases, from the rows the
//! loop walks itself (`Shader::draw_rows` over `raster::WalkedRows`, with the same body
//! inlined). It does not choose the variant (`fragment` does) or find the pixels (`raster`
//! does).
//!
//! # `unsafe`
//! This is the one module where soft3d uses `unsafe`, to drop bounds checks that the set-up
//! and the band have already proved; every block names the check that proves it in a
//! `// SAFETY:` line. The feature `checked-spans` builds the checked twin instead (the same
//! code with the bounds checks kept); `.ci/run` renders every golden picture and the firmware
//! frames with both builds, and both must equal the recorded hashes bit for bit.
#![allow(unsafe_code)]

use super::fragment::Lighting;
use super::raster::{step_varyings, Span, SpanSink, WalkedRow, WalkedRows};
use super::varyings::{texel_coordinates, VertexLit};
use crate::format::{decode_texel, TextureFormat};
use crate::target::{BandArea, DepthBuffer, DepthCell, FrameColor};
use crate::texture::{modulate, Repeat565, Sampler};

/// Where a fragment's unlit colour comes from.
pub(super) trait Base: Copy {
    /// Whether triangles with this base get a span loop inlined into their row walk (see
    /// `fragment::fragments`): the fast bases of small targets, not the general sampler.
    const WALK_ROWS: bool = true;

    /// Texel coordinate `v` and its step as this base's `base` and `lit` take them: once a run,
    /// so a base can move per-pixel work to the run (see `Repeat565::scale_v`).
    #[inline(always)]
    fn run_v(&self, v: i32) -> i32 {
        v
    }

    /// The colour at texel coordinates `(u, v)` (`v` as [`Base::run_v`] gives it), or `None` for
    /// a cut-out texel.
    fn base(&self, u: i32, v: i32) -> Option<[u8; 3]>;

    /// The colour at the pixel with varyings `v` lit by `lighting`, in the frame's format.
    #[inline(always)]
    fn lit<C: FrameColor, Lt: Lighting, const V: usize>(&self, lighting: &Lt, v: &[i32; V]) -> Option<C> {
        let (u, tv) = texel_coordinates(v);
        self.base(u, tv).map(|rgb| C::from_rgb888(modulate(rgb, lighting.light(v))))
    }
}

/// Untextured: the material's diffuse colour.
#[derive(Clone, Copy)]
pub(super) struct Diffuse(pub(super) [u8; 3]);

impl Base for Diffuse {
    #[inline]
    fn base(&self, _: i32, _: i32) -> Option<[u8; 3]> {
        Some(self.0)
    }
}

impl Base for Repeat565<'_> {
    #[inline(always)]
    fn run_v(&self, v: i32) -> i32 {
        self.scale_v(v)
    }

    #[inline(always)]
    fn base(&self, u: i32, v: i32) -> Option<[u8; 3]> {
        let [r, g, b, _] = decode_texel(TextureFormat::Rgb565, &texel565(self, u, v).to_le_bytes());
        Some([r, g, b])
    }

    /// Straight from the RGB565 texel (RGB565 frames never widen it to 8 bits).
    #[inline(always)]
    fn lit<C: FrameColor, Lt: Lighting, const V: usize>(&self, lighting: &Lt, v: &[i32; V]) -> Option<C> {
        let (u, tv) = texel_coordinates(v);
        Some(lighting.lit_rgb565(texel565(self, u, tv), v))
    }
}

impl Base for Sampler<'_> {
    const WALK_ROWS: bool = false;

    #[inline(always)]
    fn base(&self, u: i32, v: i32) -> Option<[u8; 3]> {
        let t = self.sample(u, v);
        (t[3] >= 128).then_some([t[0], t[1], t[2]])
    }
}

/// The per-pixel work for one triangle: depth test, base colour (alpha test), light, store.
pub(super) struct Shader<'b, 's, C, D, B, Lt, const DITHER: bool> {
    /// The band's colour slice: exactly `rows · width` entries (`Band::new` checked it).
    pub(super) color: &'b mut [C],
    pub(super) depth: &'b mut D,
    /// The same band's place in the frame.
    pub(super) area: BandArea,
    pub(super) base: &'s B,
    pub(super) lighting: &'s Lt,
    pub(super) written: u32,
    pub(super) rejected: u32,
    pub(super) runs: u32,
}

impl<C: FrameColor, D: DepthBuffer, B: Base, Lt: Lighting, const V: usize, const DITHER: bool> SpanSink<V>
    for Shader<'_, '_, C, D, B, Lt, DITHER>
{
    #[inline(never)]
    fn span(&mut self, s: &Span<V>) {
        self.span_inline(s);
    }
}

impl<C: FrameColor, D: DepthBuffer, B: Base, Lt: Lighting, const DITHER: bool> Shader<'_, '_, C, D, B, Lt, DITHER> {
    /// The body of [`SpanSink::span`], for the loops that inline it.
    #[inline(always)]
    fn span_inline<const V: usize>(&mut self, s: &Span<V>) {
        let len = s.len as usize;
        // The run must lie on one row of this band (the rasterizer guarantees it); checked
        // anyway.
        let Some(start) = self.area.run_start(s.x, s.y, len) else {
            return;
        };
        let (Some(colors), Some(cells)) = (colors_of(self.color, start, len), self.depth.cells(start, len)) else {
            return;
        };
        // By reference: copying it into the loop (once a run) costs more than its loads.
        let base = self.base;
        let (mut z, mut v, mut dv) = (s.z, s.v, s.dv);
        (v[VertexLit::V], dv[VertexLit::V]) = (base.run_v(v[VertexLit::V]), base.run_v(dv[VertexLit::V]));
        let (mut rejected, mut cut) = (0, 0);
        for (k, (px, mut cell)) in colors.iter_mut().zip(cells).enumerate() {
            if !cell.passes(z) {
                rejected += 1;
                // A cut-out texel writes neither colour nor depth.
            } else if let Some(c) = lit_fragment::<C, B, Lt, V, DITHER>(base, self.lighting, &v, (s.x + k as i32, s.y))
            {
                *px = c;
                cell.store(z);
            } else {
                cut += 1;
            }
            z = z.wrapping_add_signed(s.dz);
            step_varyings(&mut v, &dv);
        }
        self.written += s.len - rejected - cut;
        self.rejected += rejected;
        self.runs += 1;
    }

    /// Draws a triangle's rows (see [`WalkedRows`]): the same pixels as the runs
    /// [`SpanSink::span`] gets, walked here so that the triangle's values stay at hand from
    /// row to row, with no call per run (but for exact rows cut into several runs).
    pub(super) fn draw_rows<const V: usize>(&mut self, mut rows: WalkedRows<'_, V>)
    where
        Self: SpanSink<V>,
    {
        let dz = rows.dz;
        while let Some(row) = rows.next_row() {
            match row {
                WalkedRow::Run(y, x, len, z, v, dv) => self.span_inline(&Span { y, x, len, z, dz, v, dv }),
                WalkedRow::Cut(y, dy, lo, hi) => rows.cut_row(self, (y, dy, lo, hi)),
                WalkedRow::Empty => {}
            }
        }
    }
}

/// The lit colour of the fragment with varyings `v` at `(x, y)`, or `None` where the texture
/// cuts it out.
#[inline(always)]
fn lit_fragment<C: FrameColor, B: Base, Lt: Lighting, const V: usize, const DITHER: bool>(
    base: &B,
    lighting: &Lt,
    v: &[i32; V],
    (x, y): (i32, i32),
) -> Option<C> {
    if !DITHER && !Lt::HIGHLIGHT {
        // Straight to the frame's format (RGB565 stays RGB565).
        return base.lit(lighting, v);
    }
    let (u, tv) = texel_coordinates(v);
    let rgb = modulate(base.base(u, tv)?, lighting.light(v));
    let extra = lighting.highlight(v);
    let rgb: [u8; 3] = core::array::from_fn(|c| rgb[c].saturating_add(extra[c]));
    Some(if DITHER { C::from_rgb888_dithered(rgb, x as u32, y as u32) } else { C::from_rgb888(rgb) })
}

/// The colour entries of a run that [`BandArea::run_start`] placed at `start` in the band.
#[inline(always)]
fn colors_of<C>(color: &mut [C], start: usize, len: usize) -> Option<&mut [C]> {
    #[cfg(feature = "checked-spans")]
    {
        color.get_mut(start..start + len)
    }
    #[cfg(not(feature = "checked-spans"))]
    {
        debug_assert!(start + len <= color.len());
        // SAFETY: `BandArea::run_start` gave `start` only with `start + len <= rows · width`, and
        // `Band::new` made the band's colour slice exactly `rows · width` entries long.
        Some(unsafe { color.get_unchecked_mut(start..start + len) })
    }
}

/// The RGB565 texel at texel coordinates `(u, v)` (16.16, `v` scaled by [`Repeat565::scale_v`])
/// of a [`Repeat565`] texture.
#[inline(always)]
fn texel565(texture: &Repeat565<'_>, u: i32, v: i32) -> u16 {
    let (texels, i) = texture.texels_and_index(u, v);
    #[cfg(feature = "checked-spans")]
    let texel = texels.get(i).copied().unwrap_or_default();
    #[cfg(not(feature = "checked-spans"))]
    let texel = {
        debug_assert!(i < texels.len());
        // SAFETY: `Repeat565::texels_and_index` masks `i` with bits of `texels.len() - 1`, and
        // `Repeat565::new` made that length a power of two of at least 1 (width · height, both
        // powers of two), so `i < texels.len()`.
        unsafe { *texels.get_unchecked(i) }
    };
    u16::from_le_bytes(texel)
}
