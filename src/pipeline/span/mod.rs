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
//!
//! On Armv7-M and Armv8-M Mainline (`cfg(span_asm)`, set by `build.rs`), the common variant of
//! small targets (RGB565 texture, white vertex light, RGB565 frame, `u16` depth, see
//! `run565::Run565`) runs its pixels and rows in assembly (`armv7m.rs`, `rows565.rs`); on
//! Armv6-M and Armv8-M Baseline (`cfg(span_asm_v6m)`) its runs (`armv6m.rs`). The Rust loop is
//! their checked twin: the same pixels bit for bit, which the firmware frames' comparison with
//! the host's renders checks (`scripts/qemu-check.sh`, `tests/qemu_frame.rs`); `checked-spans`
//! builds the Rust loop there too.
#![allow(unsafe_code)]

use super::fragment::Lighting;
use super::raster::{step_varyings, AffineRows, Setup, Span, SpanSink, WalkedRow, WalkedRows};
use super::varyings::{texel_coordinates, VertexLit};
use crate::fixed::{Depth30, FDot16};
use crate::format::{decode_texel, TextureFormat};
use crate::target::{BandArea, DepthBuffer, DepthCell, FrameColor};
use crate::texture::{modulate, Repeat565, Sampler};
use core::slice::IterMut;
use embedded_graphics_core::pixelcolor::Rgb565;

#[cfg(span_asm_v6m)]
mod armv6m;
#[cfg(span_asm)]
#[macro_use]
mod armv7m;
#[cfg(span_asm)]
mod rows565;
#[cfg(asm_runs)]
mod run565;

/// Where a fragment's unlit colour comes from.
pub(super) trait Base: Copy {
    /// Whether triangles with this base get a span loop inlined into their row walk (see
    /// `fragment::fragments`): the fast bases of small targets, not the general sampler.
    const WALK_ROWS: bool = true;

    /// The left shift (wrapping) of texel coordinate `v` that this base's `base` and `lit`
    /// take it with: applied once a run where varyings step linearly, so a base can move
    /// per-pixel work to the run (see `Repeat565::scale_v`).
    #[inline(always)]
    fn v_shift(&self) -> u32 {
        0
    }

    /// The colour at texel coordinates `(u, v)` (`v` shifted by [`Base::v_shift`]), or `None` for
    /// a cut-out texel.
    fn base(&self, u: i32, v: i32) -> Option<[u8; 3]>;

    /// This base as a [`Repeat565`] texture, for the span loop's assembly (see [`Run565`]);
    /// `None` (the default) for any other base.
    #[inline(always)]
    #[cfg_attr(not(asm_runs), allow(dead_code, reason = "only the span loop's assembly asks"))]
    fn as_repeat565(&self) -> Option<&Repeat565<'_>> {
        None
    }

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
    fn v_shift(&self) -> u32 {
        self.width_shift()
    }

    #[inline(always)]
    fn as_repeat565(&self) -> Option<&Repeat565<'_>> {
        Some(self)
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

/// The varyings along a run, as the span loop reads them: at the current pixel, then on to the
/// next.
pub(super) trait RunVaryings<const V: usize> {
    /// From now on, texel coordinate `v` comes shifted left by `shift` (wrapping; see
    /// [`Base::v_shift`]).
    fn shift_v(&mut self, shift: u32);
    /// The varyings at the current pixel.
    fn current(&self) -> [FDot16; V];
    /// On to the next pixel.
    fn advance(&mut self);
    /// The values at the current pixel and their steps per pixel, when they step linearly
    /// ([`Stepped`]); `None` (the default) otherwise.
    #[inline(always)]
    #[cfg_attr(not(asm_runs), allow(dead_code, reason = "only the span loop's assembly asks"))]
    fn stepped(&self) -> Option<(&[FDot16; V], &[FDot16; V])> {
        None
    }
    /// For three varyings worked out in f32 with perspective at each pixel (`raster::PixelRun`):
    /// `[s, t0, t1, t2, v0_0, v0_1, v0_2, ds, dt0, dt1, dt2]`, varying `k` at the current pixel
    /// being `(t[k] · (1 / s) + v0[k]) as i32`, then `s` and `t` stepping by `ds` and `dt`.
    /// `None` (the default) otherwise.
    #[cfg(all(span_asm, not(soft_float)))]
    #[inline(always)]
    fn perspective(&self) -> Option<[f32; 11]> {
        None
    }
}

/// Varyings stepped linearly: the values at the current pixel and their steps per pixel
/// (wrapping adds, like every varying sum).
pub(super) struct Stepped<const V: usize>(pub(super) [FDot16; V], pub(super) [FDot16; V]);

impl<const V: usize> RunVaryings<V> for Stepped<V> {
    #[inline(always)]
    fn shift_v(&mut self, shift: u32) {
        // Linear: the shifted value steps by the shifted step.
        let k = VertexLit::V;
        (self.0[k], self.1[k]) = (self.0[k].wrapping_shl(shift), self.1[k].wrapping_shl(shift));
    }
    #[inline(always)]
    fn current(&self) -> [FDot16; V] {
        self.0
    }
    #[inline(always)]
    fn advance(&mut self) {
        step_varyings(&mut self.0, &self.1);
    }
    #[inline(always)]
    fn stepped(&self) -> Option<(&[FDot16; V], &[FDot16; V])> {
        Some((&self.0, &self.1))
    }
}

/// The varyings of a run of one pixel, worked out only when read (not for a pixel that the
/// depth test rejects), texel coordinate `v` then shifted left by the second field (see
/// [`RunVaryings::shift_v`]).
#[cfg(not(soft_float))]
pub(super) struct OnDemand<F>(F, u32);

#[cfg(not(soft_float))]
impl<const V: usize, F: Fn() -> [FDot16; V]> RunVaryings<V> for OnDemand<F> {
    #[inline(always)]
    fn shift_v(&mut self, shift: u32) {
        self.1 = shift;
    }
    #[inline(always)]
    fn current(&self) -> [FDot16; V] {
        let (mut v, k) = ((self.0)(), VertexLit::V);
        v[k] = v[k].wrapping_shl(self.1);
        v
    }
    #[inline(always)]
    fn advance(&mut self) {}
}

/// A band's depth buffer as the span loop reaches the cells of a run.
pub(super) trait RunCells {
    /// The cells of a run, in order.
    type Cells<'a>: Iterator<Item: DepthCell>
    where
        Self: 'a;
    /// The cells of the `len` pixels from entry `start`, or `None` when they are not all in
    /// the buffer.
    ///
    /// # Safety
    /// `start + len` is at most the band's colour length (`rows · width`), as
    /// [`BandArea::run_start`] makes it.
    unsafe fn run_cells(&mut self, start: usize, len: usize) -> Option<Self::Cells<'_>>;

    /// The `len` plain `u16` depths from entry `start`, when the buffer holds those
    /// ([`U16Cells`]); `None` (the default) otherwise.
    ///
    /// # Safety
    /// As [`RunCells::run_cells`].
    #[inline(always)]
    unsafe fn run_u16(&mut self, start: usize, len: usize) -> Option<&mut [u16]> {
        let _ = (start, len);
        None
    }
}

/// Any depth buffer, through [`DepthBuffer::cells`] (which checks the range itself).
pub(super) struct AnyCells<'b, D>(pub(super) &'b mut D);

impl<D: DepthBuffer> RunCells for AnyCells<'_, D> {
    type Cells<'a>
        = D::Cells<'a>
    where
        Self: 'a;
    #[inline(always)]
    unsafe fn run_cells(&mut self, start: usize, len: usize) -> Option<Self::Cells<'_>> {
        self.0.cells(start, len)
    }
}

/// Plain `u16` depths (see [`DepthBuffer::as_u16`]) at least as many as the band's pixels.
pub(super) struct U16Cells<'b>(&'b mut [u16]);

impl<'b> U16Cells<'b> {
    /// `values` for a band of `pixels` pixels (its colour length), when there are enough.
    #[inline(always)]
    pub(super) fn new(values: &'b mut [u16], pixels: usize) -> Option<Self> {
        (values.len() >= pixels).then_some(U16Cells(values))
    }
}

impl RunCells for U16Cells<'_> {
    type Cells<'a>
        = IterMut<'a, u16>
    where
        Self: 'a;
    #[inline(always)]
    unsafe fn run_cells(&mut self, start: usize, len: usize) -> Option<Self::Cells<'_>> {
        // SAFETY: the same contract.
        unsafe { self.run_u16(start, len) }.map(|cells| cells.iter_mut())
    }

    #[inline(always)]
    unsafe fn run_u16(&mut self, start: usize, len: usize) -> Option<&mut [u16]> {
        #[cfg(feature = "checked-spans")]
        {
            self.0.get_mut(start..start + len)
        }
        #[cfg(not(feature = "checked-spans"))]
        {
            debug_assert!(start + len <= self.0.len());
            // SAFETY: the caller keeps `start + len` within the band's pixels (`run_cells`'s
            // contract), and `U16Cells::new` checked that there are at least that many values.
            Some(unsafe { self.0.get_unchecked_mut(start..start + len) })
        }
    }
}

/// The per-pixel work for one triangle: depth test, base colour (alpha test), light, store.
pub(super) struct Shader<'b, 's, C, D, B, Lt, const DITHER: bool> {
    /// The band's colour slice: exactly `rows · width` entries (`Band::new` checked it).
    pub(super) color: &'b mut [C],
    /// The band's depth cells.
    pub(super) depth: D,
    /// The same band's place in the frame.
    pub(super) area: BandArea,
    pub(super) base: &'s B,
    /// `base.v_shift()`, read once a triangle (not once a run through `base`).
    pub(super) v_shift: u32,
    pub(super) lighting: &'s Lt,
    pub(super) written: u32,
    pub(super) rejected: u32,
    pub(super) runs: u32,
    /// The block the runs in assembly load (`armv6m::Thumb565`) when this triangle's variant is
    /// theirs: its constants made once a triangle, not once a run, where runs are all the
    /// assembly draws (Armv6-M -67k instructions a frame; on Armv7-M, whose row routines make
    /// theirs once a triangle anyway, such a field cost 29k).
    #[cfg(span_asm_v6m)]
    asm: Option<armv6m::Thumb565>,
}

impl<'b, 's, C: FrameColor, D: RunCells, B: Base, Lt: Lighting, const DITHER: bool>
    Shader<'b, 's, C, D, B, Lt, DITHER>
{
    /// The shader for one triangle drawn into a band's `color` and `depth` (at `area` in the
    /// frame), from `base` lit by `lighting`, with nothing drawn yet.
    #[inline(always)]
    pub(super) fn new((area, color, depth): (BandArea, &'b mut [C], D), base: &'s B, lighting: &'s Lt) -> Self {
        Shader {
            area,
            color,
            depth,
            base,
            v_shift: base.v_shift(),
            lighting,
            written: 0,
            rejected: 0,
            runs: 0,
            #[cfg(span_asm_v6m)]
            asm: run565::Run565::of::<C, B, Lt, DITHER>(base).and_then(armv6m::Thumb565::of),
        }
    }
}

impl<C: FrameColor, D: RunCells, B: Base, Lt: Lighting, const V: usize, const DITHER: bool> SpanSink<V>
    for Shader<'_, '_, C, D, B, Lt, DITHER>
{
    #[inline(never)]
    fn span(&mut self, s: &Span<V>) {
        let base = self.base;
        self.run(base, (s.x, s.y, s.len), (s.z, s.dz), Stepped(s.v, s.dv));
    }
}

impl<C: FrameColor, D: RunCells, B: Base, Lt: Lighting, const DITHER: bool> Shader<'_, '_, C, D, B, Lt, DITHER> {
    /// The body of [`SpanSink::span`], for the loops that inline it: the run of `len` pixels
    /// from frame pixel `(x, y)`, depth `z` stepping by `dz`, varyings from `vary`.
    #[inline(always)]
    pub(super) fn run<const V: usize, R: RunVaryings<V>>(
        &mut self,
        base: &B,
        (x, y, len): (i32, i32, u32),
        (mut z, dz): (Depth30, i32),
        mut vary: R,
    ) {
        // The run must lie on one row of this band (the rasterizer guarantees it); checked
        // anyway.
        let Some(start) = self.area.run_start(x, y, len as usize) else {
            return;
        };
        vary.shift_v(self.v_shift);
        #[cfg(asm_runs)]
        if let Some(rejected) = self.run_in_assembly(start, len as usize, (z, dz), &vary) {
            self.written += len - rejected;
            self.rejected += rejected;
            self.runs += 1;
            return;
        }
        // SAFETY: `run_start` gave `start` only with `start + len <= rows · width`.
        let cells = unsafe { self.depth.run_cells(start, len as usize) };
        let (Some(colors), Some(cells)) = (colors_of(self.color, start, len as usize), cells) else {
            return;
        };
        let (mut rejected, mut cut) = (0, 0);
        for (k, (px, mut cell)) in colors.iter_mut().zip(cells).enumerate() {
            if !cell.passes(z) {
                rejected += 1;
                // A cut-out texel writes neither colour nor depth.
            } else if let Some(c) =
                lit_fragment::<C, B, Lt, V, DITHER>(base, self.lighting, &vary.current(), (x + k as i32, y, z))
            {
                *px = c;
                cell.store(z);
            } else {
                cut += 1;
            }
            z = z.wrapping_add_signed(dz);
            vary.advance();
        }
        self.written += len - rejected - cut;
        self.rejected += rejected;
        self.runs += 1;
    }

    /// One pixel at frame pixel `(x, y)` with depth `z` and the varyings `v` gives: a run of
    /// one, for the small triangles drawn pixel by pixel (`SmallTriangle::for_each_pixel`),
    /// whose varyings are worked out only when the depth test passes.
    #[cfg(not(soft_float))]
    #[inline(always)]
    pub(super) fn pixel<const V: usize>(
        &mut self,
        base: &B,
        (x, y): (i32, i32),
        z: Depth30,
        v: impl Fn() -> [FDot16; V],
    ) {
        self.run(base, (x, y, 1), (z, 0), OnDemand(v, 0));
    }

    /// Draws a triangle's rows (see [`WalkedRows`]): the same pixels as the runs
    /// [`SpanSink::span`] gets, walked here so that the triangle's values stay at hand from
    /// row to row, with no call per run (but for exact rows cut into several runs).
    pub(super) fn draw_rows<const V: usize>(&mut self, mut rows: WalkedRows<'_, V>)
    where
        Self: SpanSink<V>,
    {
        let dz = rows.dz;
        // Copied once a triangle: a local that no store of the loop can reach, which it need not
        // reload after each (the lighting's two constants stay behind their reference: one `ldrd`
        // a pixel, where copies are two loads).
        let base = *self.base;
        while let Some(row) = rows.next_row() {
            match row {
                WalkedRow::Run(y, x, len, z, v, dv) => self.run(&base, (x, y, len), (z, dz), Stepped(v, dv)),
                WalkedRow::Cut(y, dy, lo, hi) => rows.cut_row(self, (y, dy, lo, hi)),
                WalkedRow::Empty => {}
            }
        }
    }
}

impl<C: FrameColor, D: RunCells, B: Base, Lt: Lighting, const DITHER: bool> Shader<'_, '_, C, D, B, Lt, DITHER> {
    /// Draws an affine triangle's rows (see [`AffineRows`]): the runs [`Shader::draw_rows`]
    /// would draw for it, from a loop of their own (out of line: its registers are not shared
    /// with the set-up's or with the exact rows' cuts).
    #[inline(never)]
    pub(super) fn draw_affine_rows<const V: usize>(&mut self, mut rows: AffineRows<'_, V>) {
        #[cfg(span_asm)]
        if let Some(k) = self.run565() {
            if self.draw_affine_rows_in_assembly(&k, &mut rows).is_some() {
                return;
            }
        }
        self.draw_runs(rows.dz, || rows.next_row());
    }

    /// Draws the rows `next_row` gives, each one run (`None` after the last, `Some(None)` for a
    /// row with no pixel centre covered), depth stepping by `dz`.
    #[inline(always)]
    fn draw_runs<const V: usize, R: RunVaryings<V>>(
        &mut self,
        dz: i32,
        mut next_row: impl FnMut() -> Option<Option<RunRow<R>>>,
    ) {
        // See `draw_rows`.
        let base = *self.base;
        while let Some(row) = next_row() {
            if let Some((at, z, vary)) = row {
                self.run(&base, at, (z, dz), vary);
            }
        }
    }

    /// Draws `setup`'s rows with perspective at every pixel when its bound allows for
    /// `tolerance` and its vertices' depths `z` for that (see [`Setup::pixel_rows`]); whether
    /// it did. Out of line without an FPU,
    /// where it runs only if asked for (`RenderOptions::fixed_vertices` off): its planes and
    /// soft-float temporaries then stay out of the common path's stack frame.
    #[cfg_attr(soft_float, inline(never))]
    pub(super) fn draw_pixel_rows<const V: usize>(
        &mut self,
        setup: &Setup<V>,
        z: [f32; 3],
        tolerance: &[u32; V],
    ) -> bool {
        // Walked where the set-up put them (moving them out of the `Option` is a copy).
        let mut pixel_rows = setup.pixel_rows(z, tolerance, self.base.v_shift());
        let Some(rows) = &mut pixel_rows else {
            return false;
        };
        #[cfg(all(span_asm, not(soft_float)))]
        if let Some(k) = self.run565() {
            if self.draw_pixel_rows_in_assembly(&k, rows).is_some() {
                return true;
            }
        }
        self.draw_runs(rows.dz(), || rows.next_row());
        true
    }
}

/// A row of one run as the walks that give whole rows hand it over: frame column, row and
/// pixels, depth (2.30) at the first pixel, and the varyings along it.
pub(super) type RunRow<R> = ((i32, i32, u32), Depth30, R);

/// The lit colour of the fragment with varyings `v` at `(x, y)` with depth `z`, or `None`
/// where the texture cuts it out.
#[inline(always)]
fn lit_fragment<C: FrameColor, B: Base, Lt: Lighting, const V: usize, const DITHER: bool>(
    base: &B,
    lighting: &Lt,
    v: &[i32; V],
    (x, y, z): (i32, i32, Depth30),
) -> Option<C> {
    if !DITHER && !Lt::HIGHLIGHT && !Lt::FOG {
        // Straight to the frame's format (RGB565 stays RGB565).
        return base.lit(lighting, v);
    }
    let (u, tv) = texel_coordinates(v);
    let rgb = modulate(base.base(u, tv)?, lighting.light(v));
    let extra = lighting.highlight(v);
    let rgb: [u8; 3] = core::array::from_fn(|c| rgb[c].saturating_add(extra[c]));
    let rgb = if Lt::FOG { lighting.fog(rgb, (x, y), z) } else { rgb };
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

/// `colors` as their RGB565 values (see [`FrameColor::as_rgb565_values`]).
#[must_use]
pub(crate) fn rgb565_values(colors: &mut [Rgb565]) -> &mut [u16] {
    const { assert!(size_of::<Rgb565>() == 2 && align_of::<Rgb565>() == 2) };
    // SAFETY: `Rgb565` is two bytes aligned to two (asserted above) and holds one `u16` (its
    // `RawU16`, whose storage `into_storage` gives): that `u16` is all its bytes, and every
    // `u16` is a valid `Rgb565`. So the same memory as `u16`s, the same length, borrowed as long.
    unsafe { core::slice::from_raw_parts_mut(colors.as_mut_ptr().cast::<u16>(), colors.len()) }
}

#[cfg(test)]
mod tests {
    use super::*;
    use embedded_graphics_core::pixelcolor::raw::RawU16;
    use embedded_graphics_core::prelude::RawData;

    /// The RGB565 view writes what `Rgb565::from(RawU16::new(value))` holds, in place.
    #[test]
    fn rgb565_values_are_the_colours_storage() {
        let mut colors = [Rgb565::from(RawU16::new(0x1234)); 3];
        let values = rgb565_values(&mut colors);
        assert_eq!(values, &[0x1234; 3]);
        values[1] = 0xF81F;
        assert_eq!(RawU16::from(colors[1]).into_inner(), 0xF81F);
        assert_eq!(RawU16::from(colors[0]).into_inner(), 0x1234);
    }
}
