//! Pixel formats a band can hold ([`FrameColor`]): 8-bit RGB converted to RGB888, RGB565 (and
//! its big-endian form for SPI displays), 8-bit grey and 1-bit mono, exactly or with ordered
//! dithering, and lit RGB565 texels without widening. It does not hold pixels (`Band` does).

use embedded_graphics_core::pixelcolor::{BinaryColor, Gray8, GrayColor, Rgb565, Rgb888, RgbColor};

/// A pixel colour soft3d can render into, converted from 8-bit RGB without dynamic dispatch.
pub trait FrameColor: Copy {
    /// Converts from 8-bit RGB (rounding to nearest).
    fn from_rgb888(rgb: [u8; 3]) -> Self;
    /// Converts to 8-bit RGB.
    fn to_rgb888(self) -> [u8; 3];
    /// Whether [`FrameColor::from_rgb888_dithered`] depends on the position: false lets a draw
    /// asked to dither take the plain path (the same pixels, drawn faster). True unless a
    /// format says otherwise.
    const DITHERS: bool = true;
    /// Converts with ordered dithering for pixel `(x, y)` of the frame; formats with 8 bits per
    /// channel ignore the position.
    #[inline]
    fn from_rgb888_dithered(rgb: [u8; 3], x: u32, y: u32) -> Self {
        let _ = (x, y);
        Self::from_rgb888(rgb)
    }
    /// An RGB565 texel lit by `light` (16.16 per channel): [`modulate`](crate::texture::modulate)
    /// of the widened texel, converted. RGB565 formats override it with
    /// [`modulate565`](crate::texture::modulate565), which stays in RGB565 (within one step).
    #[inline(always)]
    fn from_lit_rgb565(texel: u16, light: [i32; 3]) -> Self {
        let [r, g, b, _] = crate::format::decode_texel(crate::format::TextureFormat::Rgb565, &texel.to_le_bytes());
        Self::from_rgb888(crate::texture::modulate([r, g, b], light))
    }
    /// An RGB565 texel lit by white `light` (16.16) interpolated from vertex lights in 0..=1
    /// (so within `-1/64 .. 1 + 1/64`): [`FrameColor::from_lit_rgb565`] with the light on
    /// every channel. RGB565 formats override it with `texture::modulate565_white` (within one
    /// step of that; outside that range of light, some other colour).
    #[inline(always)]
    fn from_white_lit_rgb565(texel: u16, light: i32) -> Self {
        Self::from_lit_rgb565(texel, [light; 3])
    }
    /// [`FrameColor::from_white_lit_rgb565`] of the light `biased` less 2^10 (the rounding
    /// bias the draw adds to a triangle's corners, see `texture::WHITE_LIGHT_BIAS`), given the
    /// constants RGB565 formats use for it (see `texture::modulate565_white_with`); others
    /// ignore them.
    #[doc(hidden)]
    #[inline(always)]
    fn from_white_lit_rgb565_with(texel: u16, biased: i32, constants: [u32; 2]) -> Self {
        let _ = constants;
        Self::from_white_lit_rgb565(texel, biased.wrapping_sub(crate::texture::WHITE_LIGHT_BIAS))
    }
    /// `colors` as their RGB565 values in native `u16`s, the same length, when that is what
    /// this format is ([`Rgb565`]): the span loop's assembly writes those (see
    /// `pipeline::span`). `None` (the default) for any other format.
    #[doc(hidden)]
    #[inline(always)]
    fn as_rgb565_values(colors: &mut [Self]) -> Option<&mut [u16]> {
        let _ = colors;
        None
    }
}

/// The 4x4 Bayer matrix: thresholds 0..16.
const BAYER4: [[u8; 4]; 4] = [[0, 8, 2, 10], [12, 4, 14, 6], [3, 11, 1, 9], [15, 7, 13, 5]];

/// `v` (0..=255) scaled to `0..=max` with ordered dithering: the threshold `(t + 1/2) / 16`
/// replaces rounding's 1/2, so over a 4x4 tile the average equals `v · max / 255`.
#[inline]
fn narrow_dithered(v: u8, max: u32, x: u32, y: u32) -> u8 {
    let t = BAYER4[(y & 3) as usize][(x & 3) as usize] as u32;
    ((v as u32 * max * 32 + (2 * t + 1) * 255) / (255 * 32)).min(max) as u8
}

/// `v` (0..=255) scaled to `0..=max`, rounded to nearest.
const fn narrow_exact(v: u8, max: u32) -> u8 {
    ((v as u32 * max + 127) / 255) as u8
}

/// `v` (0..=max) scaled to 0..=255, rounded to nearest.
const fn widen_exact(v: u8, max: u32) -> u8 {
    ((v as u32 * 255 + max / 2) / max) as u8
}

/// Tables of [`narrow_exact`] (`widen == false`) or [`widen_exact`] for every `v`: per-pixel
/// conversions without division.
const fn table(widen: bool, max: u32) -> [u8; 256] {
    let mut t = [0; 256];
    let mut v = 0;
    while v < 256 {
        t[v] = if widen { widen_exact(v as u8, max) } else { narrow_exact(v as u8, max) };
        v += 1;
    }
    t
}
const NARROW5: [u8; 256] = table(false, 31);
const NARROW6: [u8; 256] = table(false, 63);
const WIDEN5: [u8; 256] = table(true, 31);
const WIDEN6: [u8; 256] = table(true, 63);

/// Rec. 601 luma of 8-bit RGB, in 0..=255.
#[inline]
#[must_use]
pub fn luma(rgb: [u8; 3]) -> u8 {
    ((rgb[0] as u32 * 77 + rgb[1] as u32 * 150 + rgb[2] as u32 * 29 + 128) >> 8) as u8
}

impl FrameColor for Rgb888 {
    const DITHERS: bool = false;
    #[inline]
    fn from_rgb888(rgb: [u8; 3]) -> Self {
        Rgb888::new(rgb[0], rgb[1], rgb[2])
    }
    #[inline]
    fn to_rgb888(self) -> [u8; 3] {
        [self.r(), self.g(), self.b()]
    }
}

impl FrameColor for Rgb565 {
    #[inline]
    fn from_rgb888(rgb: [u8; 3]) -> Self {
        Rgb565::new(NARROW5[rgb[0] as usize], NARROW6[rgb[1] as usize], NARROW5[rgb[2] as usize])
    }
    #[inline]
    fn from_rgb888_dithered(rgb: [u8; 3], x: u32, y: u32) -> Self {
        Rgb565::new(
            narrow_dithered(rgb[0], 31, x, y),
            narrow_dithered(rgb[1], 63, x, y),
            narrow_dithered(rgb[2], 31, x, y),
        )
    }
    #[inline]
    fn to_rgb888(self) -> [u8; 3] {
        [WIDEN5[self.r() as usize], WIDEN6[self.g() as usize], WIDEN5[self.b() as usize]]
    }
    #[inline(always)]
    fn from_lit_rgb565(texel: u16, light: [i32; 3]) -> Self {
        Rgb565::from(embedded_graphics_core::pixelcolor::raw::RawU16::new(crate::texture::modulate565(texel, light)))
    }
    #[inline(always)]
    fn from_white_lit_rgb565(texel: u16, light: i32) -> Self {
        Rgb565::from(embedded_graphics_core::pixelcolor::raw::RawU16::new(crate::texture::modulate565_white(
            texel, light,
        )))
    }
    #[inline(always)]
    fn from_white_lit_rgb565_with(texel: u16, biased: i32, constants: [u32; 2]) -> Self {
        Rgb565::from(embedded_graphics_core::pixelcolor::raw::RawU16::new(crate::texture::modulate565_white_with(
            texel, biased, constants,
        )))
    }
    #[inline(always)]
    fn as_rgb565_values(colors: &mut [Self]) -> Option<&mut [u16]> {
        Some(crate::pipeline::rgb565_values(colors))
    }
}

impl FrameColor for Gray8 {
    const DITHERS: bool = false;
    #[inline]
    fn from_rgb888(rgb: [u8; 3]) -> Self {
        Gray8::new(luma(rgb))
    }
    #[inline]
    fn from_rgb888_dithered(rgb: [u8; 3], _: u32, _: u32) -> Self {
        // Gray8 keeps all 8 bits of luma: nothing to dither.
        Gray8::new(luma(rgb))
    }
    #[inline]
    fn to_rgb888(self) -> [u8; 3] {
        [self.luma(); 3]
    }
}

impl FrameColor for BinaryColor {
    #[inline]
    fn from_rgb888(rgb: [u8; 3]) -> Self {
        BinaryColor::from(luma(rgb) >= 128)
    }
    #[inline]
    fn from_rgb888_dithered(rgb: [u8; 3], x: u32, y: u32) -> Self {
        BinaryColor::from(narrow_dithered(luma(rgb), 1, x, y) == 1)
    }
    #[inline]
    fn to_rgb888(self) -> [u8; 3] {
        if self.is_on() {
            [255; 3]
        } else {
            [0; 3]
        }
    }
}

/// RGB565 stored big-endian in memory, as most SPI displays (ST7789, ILI9341) want it: a
/// band of these can go to the display's DMA as it is.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Rgb565Be(pub [u8; 2]);

impl FrameColor for Rgb565Be {
    #[inline]
    fn from_rgb888(rgb: [u8; 3]) -> Self {
        Self::from(Rgb565::from_rgb888(rgb))
    }
    #[inline]
    fn from_rgb888_dithered(rgb: [u8; 3], x: u32, y: u32) -> Self {
        Self::from(Rgb565::from_rgb888_dithered(rgb, x, y))
    }
    #[inline(always)]
    fn from_lit_rgb565(texel: u16, light: [i32; 3]) -> Self {
        Rgb565Be(crate::texture::modulate565(texel, light).to_be_bytes())
    }
    #[inline(always)]
    fn from_white_lit_rgb565(texel: u16, light: i32) -> Self {
        Rgb565Be(crate::texture::modulate565_white(texel, light).to_be_bytes())
    }
    #[inline(always)]
    fn from_white_lit_rgb565_with(texel: u16, biased: i32, constants: [u32; 2]) -> Self {
        Rgb565Be(crate::texture::modulate565_white_with(texel, biased, constants).to_be_bytes())
    }
    #[inline]
    fn to_rgb888(self) -> [u8; 3] {
        let v = u16::from_be_bytes(self.0);
        Rgb565::new((v >> 11) as u8, ((v >> 5) & 63) as u8, (v & 31) as u8).to_rgb888()
    }
}

impl From<Rgb565> for Rgb565Be {
    fn from(c: Rgb565) -> Self {
        let v = (c.r() as u16) << 11 | (c.g() as u16) << 5 | c.b() as u16;
        Rgb565Be(v.to_be_bytes())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dithering_keeps_the_average() {
        for v in [0u8, 1, 3, 7, 100, 128, 200, 254, 255] {
            let mut sum565 = 0u32;
            let mut sum1 = 0u32;
            for y in 0..4 {
                for x in 0..4 {
                    sum565 += Rgb565::from_rgb888_dithered([v, v, v], x, y).to_rgb888()[0] as u32;
                    sum1 += BinaryColor::from_rgb888_dithered([v, v, v], x, y).to_rgb888()[0] as u32;
                }
            }
            // Averages over a 4x4 tile land within half a quantization step of the input.
            assert!((sum565 as f32 / 16.0 - v as f32).abs() <= 255.0 / 31.0 / 2.0, "565 {v}: {sum565}");
            assert!((sum1 as f32 / 16.0 - v as f32).abs() <= 255.0 / 16.0 / 2.0 + 0.5, "mono {v}: {sum1}");
        }
        // A mid grey dithers to both neighbouring levels.
        let levels: [u8; 4] = core::array::from_fn(|x| Rgb565::from_rgb888_dithered([130, 130, 130], x as u32, 0).r());
        assert!(levels.iter().min() != levels.iter().max());
    }

    #[test]
    fn colour_conversions() {
        assert_eq!(Rgb565::from_rgb888([255, 128, 0]), Rgb565::new(31, 32, 0));
        assert_eq!(Rgb565::new(31, 63, 0).to_rgb888(), [255, 255, 0]);
        assert_eq!(Rgb565Be::from_rgb888([255, 0, 0]).0, [0xF8, 0x00]);
        assert_eq!(Gray8::from_rgb888([255, 255, 255]), Gray8::new(255));
        assert_eq!(BinaryColor::from_rgb888([200, 200, 200]), BinaryColor::On);
        assert_eq!(BinaryColor::from_rgb888([20, 20, 20]), BinaryColor::Off);
    }
}
