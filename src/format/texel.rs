//! Texels: the stored formats ([`TextureFormat`]), a model's [`Texture`] view, and the codecs
//! between stored texels and RGBA8. Sampling (wraps, filters) is `crate::texture`'s job.

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

/// A texture of a [`Model`](crate::Model), texels stored bottom row first.
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
