//! Texture sampling in integers: wraps, nearest and bilinear filters ([`Sampler`]), the fast
//! path of small targets ([`Repeat565`]), and modulating a texel by light ([`modulate`],
//! [`modulate565`]). It does not decode stored texels (`format` does) or compute light (`light`
//! does).

use crate::format::{Texture, TextureFormat, Wrap};
/// Texture filtering.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Filter {
    /// The texel under the sample point: `i = floor(u · W)`.
    #[default]
    Nearest,
    /// Blend of the four texels around `(u · W - 0.5, v · H - 0.5)`.
    Bilinear,
}

/// One wrapped axis of a texture.
#[derive(Clone, Copy, Debug)]
struct Axis {
    size: i32,
    wrap: Wrap,
    /// `size - 1` for a power-of-two size that repeats (then folding is one AND), else -1.
    mask: i32,
}

impl Axis {
    fn new(size: u16, wrap: Wrap) -> Self {
        let size = size as i32;
        let pow2_repeat = wrap == Wrap::Repeat && size & (size - 1) == 0;
        Axis { size, wrap, mask: if pow2_repeat { size - 1 } else { -1 } }
    }

    /// Folds texel coordinate `i` into `0..size`.
    #[inline(always)]
    fn fold(self, i: i32) -> i32 {
        if self.mask >= 0 {
            return i & self.mask;
        }
        match self.wrap {
            Wrap::Repeat => i.rem_euclid(self.size),
            Wrap::Clamp => i.clamp(0, self.size - 1),
            Wrap::Mirror => {
                let m = i.rem_euclid(2 * self.size);
                if m >= self.size {
                    2 * self.size - 1 - m
                } else {
                    m
                }
            }
        }
    }
}

/// Samples a texture with texel coordinates in 16.16 fixed point (`u · W · 65536`).
#[derive(Clone, Copy, Debug)]
pub struct Sampler<'a> {
    texture: Texture<'a>,
    u: Axis,
    v: Axis,
    filter: Filter,
}

impl<'a> Sampler<'a> {
    /// A sampler for `texture` with the given wrap modes and filter.
    #[must_use]
    pub fn new(texture: Texture<'a>, wrap_u: Wrap, wrap_v: Wrap, filter: Filter) -> Self {
        Sampler { u: Axis::new(texture.width, wrap_u), v: Axis::new(texture.height, wrap_v), texture, filter }
    }

    /// Texture width in texels.
    #[must_use]
    pub fn width(&self) -> u16 {
        self.texture.width
    }

    /// Texture height in texels.
    #[must_use]
    pub fn height(&self) -> u16 {
        self.texture.height
    }

    /// Whether the texture has an alpha channel (cut-outs).
    #[must_use]
    pub fn has_alpha(&self) -> bool {
        self.texture.format.has_alpha()
    }

    #[inline(always)]
    fn texel(&self, i: i32, j: i32) -> [u8; 4] {
        let (i, j) = (self.u.fold(i) as usize, self.v.fold(j) as usize);
        let t = &self.texture;
        let at = j * t.width as usize + i;
        let b = t.texels;
        match t.format {
            TextureFormat::Rgb565 | TextureFormat::Rgba5551 => match b.get(2 * at..2 * at + 2) {
                Some(s) => crate::format::decode_texel(t.format, s),
                None => [0; 4],
            },
            TextureFormat::Rgb888 => match b.get(3 * at..3 * at + 3) {
                Some(s) => [s[0], s[1], s[2], 255],
                None => [0; 4],
            },
            TextureFormat::Rgba8888 => match b.get(4 * at..4 * at + 4) {
                Some(s) => [s[0], s[1], s[2], s[3]],
                None => [0; 4],
            },
        }
    }

    /// RGBA at texel coordinates `(u, v)` in 16.16 (v counted from the bottom row).
    #[inline(always)]
    #[must_use]
    pub fn sample(&self, u: i32, v: i32) -> [u8; 4] {
        match self.filter {
            Filter::Nearest => self.texel(u >> 16, v >> 16),
            Filter::Bilinear => {
                // Half a texel back to the texel centres, and half a weight step forward so the
                // 8-bit weights below are rounded, not truncated.
                let (u, v) = (u.wrapping_sub((1 << 15) - (1 << 7)), v.wrapping_sub((1 << 15) - (1 << 7)));
                let (i, j) = (u >> 16, v >> 16);
                let (fu, fv) = (((u >> 8) & 255) as u32, ((v >> 8) & 255) as u32);
                let t00 = self.texel(i, j);
                let t10 = self.texel(i + 1, j);
                let t01 = self.texel(i, j + 1);
                let t11 = self.texel(i + 1, j + 1);
                core::array::from_fn(|k| {
                    let bottom = t00[k] as u32 * (256 - fu) + t10[k] as u32 * fu;
                    let top = t01[k] as u32 * (256 - fu) + t11[k] as u32 * fu;
                    ((bottom * (256 - fv) + top * fv + (1 << 15)) >> 16) as u8
                })
            }
        }
    }
}

/// The common texture of small targets, sampled with the fewest operations: RGB565, both
/// sizes powers of two, repeat on both axes, nearest. Samples exactly what [`Sampler`] does
/// for such a texture.
#[derive(Clone, Copy, Debug)]
pub struct Repeat565<'a> {
    /// Exactly `width · height` texels, a power of two of at most 2^16.
    texels: &'a [[u8; 2]],
    /// `width - 1`: the column bits of a texel index.
    u_mask: u32,
    /// `(height - 1) · width`: the row bits of a texel index.
    v_mask: u32,
    /// log2 of the width.
    width_shift: u32,
}

impl<'a> Repeat565<'a> {
    /// The fast form of `sampler`, when its texture and modes allow one.
    #[must_use]
    pub fn new(sampler: &Sampler<'a>) -> Option<Self> {
        let t = &sampler.texture;
        let texels = t.texels.as_chunks::<2>().0;
        // Width and height are powers of two (both masks are set) and at least 1, so is their
        // product, the length: `texels_and_index` relies on it, and on the length being at
        // most 2^16 (see `scale_v`).
        let fits = t.format == TextureFormat::Rgb565
            && sampler.filter == Filter::Nearest
            && sampler.u.mask >= 0
            && sampler.v.mask >= 0
            && texels.len() == t.width as usize * t.height as usize
            && texels.len() <= 1 << 16;
        let last = texels.len().wrapping_sub(1) as u32;
        let u_mask = u32::from(t.width).wrapping_sub(1);
        fits.then_some(Repeat565 { texels, u_mask, v_mask: last & !u_mask, width_shift: t.width.trailing_zeros() })
    }

    /// Texel coordinate `v` (16.16) in the form [`Repeat565::texels_and_index`] takes: times the
    /// width, wrapping. Its integer part is then `floor(v) · width` plus fraction bits below
    /// the row bits, which the index masks away; the wrap drops only whole multiples of
    /// `2^16 / width` rows, a multiple of the height (width · height ≤ 2^16), so rows repeat
    /// as they should. A run steps the scaled value by the scaled step (the same wrap), so
    /// this is done once a run, not once a pixel.
    #[inline(always)]
    #[must_use]
    pub(crate) fn scale_v(&self, v: i32) -> i32 {
        v.wrapping_shl(self.width_shift)
    }

    /// The shift of [`Repeat565::scale_v`]: log2 of the width.
    #[inline(always)]
    #[must_use]
    pub(crate) fn width_shift(&self) -> u32 {
        self.width_shift
    }

    /// The texels and the masks that [`Repeat565::texels_and_index`] takes an index's column and
    /// row bits with: `(texels, u_mask, v_mask)`, `u_mask | v_mask` being `texels.len() - 1`.
    #[inline(always)]
    #[cfg_attr(not(asm_runs), allow(dead_code, reason = "only the span loop's assembly asks"))]
    pub(crate) fn texels_and_masks(&self) -> (&'a [[u8; 2]], u32, u32) {
        (self.texels, self.u_mask, self.v_mask)
    }

    /// RGB at texel coordinates `(u, v)` in 16.16 (black if the texture is short).
    #[inline(always)]
    #[must_use]
    pub fn sample(&self, u: i32, v: i32) -> [u8; 3] {
        let [r, g, b, _] = crate::format::decode_texel(TextureFormat::Rgb565, &self.texel(u, v).to_le_bytes());
        [r, g, b]
    }

    /// The RGB565 texel at texel coordinates `(u, v)` in 16.16 (0 if the texture is short).
    #[inline(always)]
    #[must_use]
    pub fn texel(&self, u: i32, v: i32) -> u16 {
        let (texels, i) = self.texels_and_index(u, self.scale_v(v));
        texels.get(i).map_or(0, |b| u16::from_le_bytes(*b))
    }

    /// The texels, and the index in them of the texel at `(u, scaled_v)` (16.16, `v` scaled by
    /// [`Repeat565::scale_v`]): always below their length, which [`Repeat565::new`] made a
    /// power of two of at least 1 (width and height are powers of two), as the index has only
    /// bits of `u_mask | v_mask = length - 1`.
    #[inline(always)]
    pub(crate) fn texels_and_index(&self, u: i32, scaled_v: i32) -> (&'a [[u8; 2]], usize) {
        let at = ((scaled_v >> 16) as u32 & self.v_mask) | ((u >> 16) as u32 & self.u_mask);
        (self.texels, at as usize)
    }
}

/// `texel · light` per channel in RGB565 itself, with `light` in 16.16 clamped to 0..=0xffff as
/// [`modulate`] does: one rounding (`c · l + 2^15 >> 16` on the 5- or 6-bit channel) instead of
/// widening to 8 bits, modulating and narrowing again. Within one RGB565 step of that RGB888
/// path's result (checked exhaustively in the tests), and about a third of its instructions.
#[inline(always)]
#[must_use]
pub fn modulate565(texel: u16, light: [i32; 3]) -> u16 {
    let t = texel as u32;
    let scale = |c: u32, k: usize| (c * light[k].clamp(0, 0xffff) as u32 + (1 << 15)) >> 16;
    (scale(t >> 11, 0) << 11 | scale((t >> 5) & 63, 1) << 5 | scale(t & 31, 2)) as u16
}

/// The RGB565 fields of [`modulate565_white`] spread apart (green on top, then red, then blue)
/// with a gap above each wide enough for the field times 32.
pub(crate) const SPREAD565: u32 = 0x07E0_F81F;
/// Half of 32 in each spread field: rounds the products to nearest.
pub(crate) const SPREAD565_HALF: u32 = 16 << 21 | 16 << 11 | 16;

/// `texel · light` for white light (16.16, the same on all channels) interpolated from vertex
/// lights in 0..=1, the way the fastest MCU renderers do it: the light rounded to 1/32
/// (0..=32) multiplies all three fields at once, spread apart in one 32-bit word (no field
/// overflows into the next: 63 · 32 + 16 < 2^11). About a third of [`modulate565`]'s
/// instructions, and within one RGB565 step of it (checked exhaustively in the tests): the
/// light's rounding error is at most 1/64, which moves a 6-bit field by less than one step.
///
/// Interpolated light lies within `-1/64 .. 1 + 1/64` (interpolation is off by at most 1/256,
/// see `fragment::LitBy::affine_tolerance_light`); there this equals clamping it to 0..=1
/// first, and needs no clamp at the top: two instructions for the level on Cortex-M instead
/// of seven. Light above that range gives some other RGB565 value (a field may carry into the
/// next), never a panic.
#[inline(always)]
#[must_use]
pub(crate) fn modulate565_white(texel: u16, light: i32) -> u16 {
    modulate565_white_with(texel, light.wrapping_add(WHITE_LIGHT_BIAS), [SPREAD565, SPREAD565_HALF])
}

/// What [`modulate565_white_with`] takes added to the light: half of the 1/32 it rounds the
/// light to. Added once a triangle to its corners' light (interpolation carries a constant
/// through unchanged) instead of at every pixel.
pub(crate) const WHITE_LIGHT_BIAS: i32 = 1 << 10;

/// [`modulate565_white`] of the light `biased` less [`WHITE_LIGHT_BIAS`], given its two
/// constants, `[SPREAD565, SPREAD565_HALF]`: a loop that loads them (one instruction for both)
/// need not build each from two halves per pixel.
#[inline(always)]
#[must_use]
pub(crate) fn modulate565_white_with(texel: u16, biased: i32, [spread565, half]: [u32; 2]) -> u16 {
    debug_assert!([spread565, half] == [SPREAD565, SPREAD565_HALF]);
    // Rounded by the bias, clamped to 6 bits: one instruction (usat, shift included) on
    // Cortex-M. Light far below 0 gives 0 either way.
    let level = (biased >> 11).clamp(0, 63) as u32;
    let t = u32::from(texel);
    let spread = (t | t << 16) & spread565;
    let lit = spread.wrapping_mul(level).wrapping_add(half) >> 5 & spread565;
    (lit | lit >> 16) as u16
}

/// `c · light` per channel with `light` in 16.16 (1.0 = 65536), rounded, clamped to 255.
#[inline(always)]
#[must_use]
pub fn modulate(c: [u8; 3], light: [i32; 3]) -> [u8; 3] {
    core::array::from_fn(|k| {
        // 65535 gives what 65536 would for every 8-bit c (c·65535 + 2^15 >> 16 == c), and
        // clamping to 16 bits is one instruction (usat) on Cortex-M.
        let l = light[k].clamp(0, 0xffff) as u32;
        ((c[k] as u32 * l + (1 << 15)) >> 16) as u8
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tex(texels: &[u8], w: u16, h: u16) -> Texture<'_> {
        Texture { width: w, height: h, format: TextureFormat::Rgba8888, texels }
    }

    /// Every channel value under every light interpolation gives (-1/64 .. 1 + 1/64): white
    /// light's modulation is at most one step from the general RGB565 one, and equal at full
    /// light and above, and at none and below.
    #[test]
    fn modulate565_white_is_within_one_step_of_modulate565() {
        let mut differ = 0u32;
        for (bits, shift) in [(5u32, 11u32), (6, 5), (5, 0)] {
            let mask = ((1u32 << bits) - 1) << shift;
            for c in 0..1u32 << bits {
                // The other fields full, so a carry out of this field would show.
                let texel = ((c << shift) | (0xffff & !mask)) as u16;
                for l in (-1024..=-1).chain(0..=0x10000).chain([0x10001, 0x10000 + 1023]) {
                    let (got, want) = (modulate565_white(texel, l), modulate565(texel, [l; 3]));
                    for (s, b) in [(11, 5), (5, 6), (0, 5)] {
                        let field = |x: u16| (u32::from(x) >> s) & ((1 << b) - 1);
                        assert!(
                            field(got).abs_diff(field(want)) <= 1,
                            "texel {texel:#06x}, light {l}: {got:#06x} vs {want:#06x}"
                        );
                    }
                    differ += u32::from(got != want);
                    if l <= 0 || l >= 0xffff {
                        assert_eq!(got, want, "texel {texel:#06x}, light {l}");
                    }
                }
            }
        }
        assert!(differ > 0, "the two definitions are expected to differ somewhere");
    }

    /// Every channel value under every light: the RGB565 modulation is at most one step from
    /// narrowing the RGB888 one, and equal at full light and at none.
    #[test]
    fn modulate565_is_within_one_step_of_the_rgb888_path() {
        use crate::target::FrameColor;
        use embedded_graphics_core::pixelcolor::{Rgb565, RgbColor};
        let mut differ = 0u32;
        for (bits, shift) in [(5u32, 11u32), (6, 5), (5, 0)] {
            for c in 0..1u32 << bits {
                let texel = (c << shift) as u16;
                let wide = crate::format::decode_texel(TextureFormat::Rgb565, &texel.to_le_bytes());
                for l in (-2..=0x10001).step_by(1) {
                    let light = [l; 3];
                    let want = Rgb565::from_rgb888(modulate([wide[0], wide[1], wide[2]], light));
                    let want = [want.r(), want.g(), want.b()];
                    let got = modulate565(texel, light);
                    let got = [(got >> 11) as u8, ((got >> 5) & 63) as u8, (got & 31) as u8];
                    for k in 0..3 {
                        assert!(got[k].abs_diff(want[k]) <= 1, "c {c} << {shift}, light {l}: {got:?} vs {want:?}");
                        differ += (got[k] != want[k]) as u32;
                    }
                    if l <= 0 || l >= 0xffff {
                        assert_eq!(got, want, "c {c} << {shift}, light {l}");
                    }
                }
            }
        }
        assert!(differ > 0, "the two definitions are expected to differ somewhere");
    }

    /// Integer vertex light against the f32 one: random rotations, normals and directional and
    /// hemispheric lights of any colour and intensity up to 4.
    #[test]
    fn negative_uvs_repeat_not_mirror() {
        // A 4x1 texture with texel values 0, 1, 2, 3 in red.
        let data: [u8; 16] = [0, 0, 0, 255, 1, 0, 0, 255, 2, 0, 0, 255, 3, 0, 0, 255];
        let s = Sampler::new(tex(&data, 4, 1), Wrap::Repeat, Wrap::Repeat, Filter::Nearest);
        // u = -0.1 -> u·W = -0.4 -> floor -1 -> repeats to texel 3 (abs(u % w) would give 0).
        assert_eq!(s.sample((-0.4 * 65536.0) as i32, 0)[0], 3);
        assert_eq!(s.sample(5 << 16, 0)[0], 1);
        let m = Sampler::new(tex(&data, 4, 1), Wrap::Mirror, Wrap::Repeat, Filter::Nearest);
        assert_eq!(m.sample(4 << 16, 0)[0], 3);
        assert_eq!(m.sample(-(1 << 16), 0)[0], 0);
        let c = Sampler::new(tex(&data, 4, 1), Wrap::Clamp, Wrap::Repeat, Filter::Nearest);
        assert_eq!(c.sample(-(7 << 16), 0)[0], 0);
        assert_eq!(c.sample(9 << 16, 0)[0], 3);
        // Non-power-of-two widths wrap too.
        let odd = Sampler::new(tex(&data[..12], 3, 1), Wrap::Repeat, Wrap::Repeat, Filter::Nearest);
        assert_eq!(odd.sample(-(1 << 16), 0)[0], 2);
    }

    #[test]
    fn modulate_keeps_white_and_black() {
        assert_eq!(modulate([255, 128, 0], [1 << 16; 3]), [255, 128, 0]);
        assert_eq!(modulate([255, 128, 0], [0; 3]), [0, 0, 0]);
        assert_eq!(modulate([255, 255, 255], [1 << 15; 3]), [128, 128, 128]);
    }
}
