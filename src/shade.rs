//! Lighting (per vertex or per face, f32) and texture sampling (per pixel, integers).
//!
//! The light model is Babylon.js's StandardMaterial diffuse term with specular off:
//! `colour = clamp(ambient + Σ max(0, N·L) · light.diffuse · intensity, 0, 1) · diffuse · texture`
//! with `L = -direction` (directional), `L = normalize(position - P)` (point, no falloff) and
//! hemispheric lights contributing `(0.5 + 0.5 N·up) · diffuse · intensity` (ground colour black).
//! Lighting only ever scales red, green and blue: alpha is never touched.

use heapless::Vec;

use crate::format::{Light, LightKind, Model, Texture, TextureFormat, Wrap};
use crate::math::{clamp01, max, normalize_or_zero, Mat3, Vec3};

/// Ambient light plus up to `N` lights.
#[derive(Clone, Debug, Default)]
pub struct Lights<const N: usize> {
    /// Ambient colour added to every surface (0..=1 per channel).
    pub ambient: Vec3,
    /// The lights.
    pub lights: Vec<Light, N>,
    /// Blinn-Phong specular colour (0..=1 per channel), added on top of the lit texture; zero
    /// (the default) turns specular off. Evaluated per vertex (flat: per face); not in Phong mode.
    pub specular: Vec3,
    /// Blinn-Phong exponent (Babylon's `specularPower`, default 64).
    pub shininess: f32,
}

impl<const N: usize> Lights<N> {
    /// No lights and no ambient: everything lit renders black, so prefer [`Lights::from_model`].
    #[must_use]
    pub fn new(ambient: Vec3) -> Self {
        Self { ambient, lights: Vec::new(), specular: Vec3::ZERO, shininess: 64.0 }
    }

    /// Adds a light; hands it back when all `N` places are taken.
    ///
    /// # Errors
    /// The light, when the set is full.
    pub fn push(&mut self, light: Light) -> Result<(), Light> {
        self.lights.push(light)
    }

    /// A directional light shining along `direction`.
    #[must_use]
    pub fn directional(direction: Vec3, intensity: f32) -> Light {
        Light { kind: LightKind::Directional, vector: direction, diffuse: Vec3::ONE, intensity }
    }

    /// A point light at `position` (no falloff).
    #[must_use]
    pub fn point(position: Vec3, intensity: f32) -> Light {
        Light { kind: LightKind::Point, vector: position, diffuse: Vec3::ONE, intensity }
    }

    /// The model's lights (the first `N`), no ambient. A scene without lights gets Babylon's
    /// default: a hemispheric light from +y.
    #[must_use]
    pub fn from_model(model: &Model<'_>) -> Self {
        let mut set = Self::new(Vec3::ZERO);
        for l in model.lights() {
            if set.push(l).is_err() {
                break;
            }
        }
        if set.lights.is_empty() {
            let _ =
                set.push(Light { kind: LightKind::Hemispheric, vector: Vec3::Y, diffuse: Vec3::ONE, intensity: 1.0 });
        }
        set
    }

    /// Blinn-Phong specular intensity at `p` with unit normal `n` seen from `eye`:
    /// `Σ max(0, N·H)^shininess · intensity` with `H = normalize(L + V)` (0 when specular is
    /// off). The colour is [`Lights::specular`].
    #[must_use]
    pub fn specular_at(&self, p: Vec3, n: Vec3, eye: Vec3) -> f32 {
        if self.specular == Vec3::ZERO {
            return 0.0;
        }
        let v = normalize_or_zero(eye - p);
        let mut sum = 0.0;
        for l in &self.lights {
            let to_light = match l.kind {
                LightKind::Directional => normalize_or_zero(-l.vector),
                LightKind::Point => normalize_or_zero(l.vector - p),
                // Sky light has no direction to reflect.
                LightKind::Hemispheric => continue,
            };
            if n.dot(to_light) > 0.0 {
                let h = normalize_or_zero(to_light + v);
                sum += crate::math::powf(n.dot(h).max(0.0), self.shininess) * l.intensity;
            }
        }
        sum.min(1.0)
    }

    /// Light reaching a surface at `p` with unit normal `n`, each channel clamped to 0..=1.
    #[must_use]
    pub fn at(&self, p: Vec3, n: Vec3) -> Vec3 {
        self.prepared().at(p, n)
    }

    /// The lights with their fixed directions normalised once, for lighting many vertices.
    #[must_use]
    pub fn prepared(&self) -> PreparedLights<N> {
        let mut lights = Vec::new();
        for l in &self.lights {
            let vector = match l.kind {
                LightKind::Directional => normalize_or_zero(-l.vector),
                LightKind::Point => l.vector,
                LightKind::Hemispheric => normalize_or_zero(l.vector),
            };
            let _ = lights.push(Light { vector, ..*l });
        }
        PreparedLights { ambient: self.ambient, lights }
    }
}

/// [`Lights`] ready for [`Lights::at`] per vertex: each directional light's vector is the unit
/// vector towards the light, each hemispheric light's the unit up vector.
#[derive(Clone, Debug, Default)]
pub struct PreparedLights<const N: usize> {
    ambient: Vec3,
    lights: Vec<Light, N>,
}

impl<const N: usize> PreparedLights<N> {
    /// See [`Lights::at`].
    #[must_use]
    pub fn at(&self, p: Vec3, n: Vec3) -> Vec3 {
        let mut sum = self.ambient;
        for l in &self.lights {
            let k = match l.kind {
                LightKind::Directional => max(n.dot(l.vector), 0.0),
                LightKind::Point => max(n.dot(normalize_or_zero(l.vector - p)), 0.0),
                LightKind::Hemispheric => 0.5 + 0.5 * n.dot(l.vector),
            };
            sum += l.diffuse * (k * l.intensity);
        }
        Vec3::new(clamp01(sum.x), clamp01(sum.y), clamp01(sum.z))
    }
}

impl<const N: usize> PreparedLights<N> {
    /// The same lights evaluated in integers for normals stored as `[i16; 3]` (unit =
    /// [`NORMAL_ONE`](crate::format::NORMAL_ONE)) and turned by the rotation `normals`: the
    /// vertex lighting of the fixed-point vertex path. `None` when that needs floats: point
    /// lights (they need positions), more than `M` lights, or ambient or a light beyond 4 per
    /// channel.
    #[must_use]
    pub fn fixed<const M: usize>(&self, normals: &Mat3) -> Option<FixedLights<M>> {
        let mut lights = Vec::new();
        for l in &self.lights {
            let hemispheric = match l.kind {
                LightKind::Directional => false,
                LightKind::Hemispheric => true,
                LightKind::Point => return None,
            };
            // n_world · L = n_stored · (Nᵀ L): one dot product per vertex, no normal turned.
            let towards = normals.transpose() * l.vector;
            let weight = l.diffuse * l.intensity;
            if !(towards.is_finite() && weight.abs().max_element() <= 4.0) {
                return None;
            }
            let towards = towards.to_array().map(|c| crate::math::to_i32(c * 32768.0).clamp(-32768, 32768));
            let weight = weight.to_array().map(|c| crate::math::to_i32(c * 16384.0));
            lights.push(FixedLight { hemispheric, towards, weight }).ok()?;
        }
        let in_range = self.ambient.abs().max_element() <= 4.0;
        if !in_range {
            return None;
        }
        let ambient = self.ambient.to_array().map(|c| crate::math::to_i32(c * 65536.0));
        Some(FixedLights { ambient, lights })
    }
}

/// [`PreparedLights`] for one draw's normals in integers (see [`PreparedLights::fixed`]).
#[derive(Clone, Debug, Default)]
pub struct FixedLights<const N: usize> {
    /// 16.16.
    ambient: [i32; 3],
    lights: Vec<FixedLight, N>,
}

#[derive(Clone, Copy, Debug)]
struct FixedLight {
    hemispheric: bool,
    /// `Nᵀ L` in 1.15.
    towards: [i32; 3],
    /// Diffuse colour times intensity, 2.14 (at most 4).
    weight: [i32; 3],
}

impl<const N: usize> FixedLights<N> {
    /// Light per channel, 0..=65535 for 0..=1 (clamped), at a vertex whose stored normal is
    /// `n`: [`PreparedLights::at`] in integers, within about 2^-12 of it per light (a sixteenth
    /// of an 8-bit step).
    #[must_use]
    pub fn at(&self, n: [i16; 3]) -> [u16; 3] {
        let mut sum = self.ambient;
        for l in &self.lights {
            // |n| <= 2^15 and |towards| <= 2^15 (unit vectors, by Cauchy-Schwarz): below 2^31.
            let dot = (0..3).fold(0i32, |acc, k| acc.wrapping_add(n[k] as i32 * l.towards[k]));
            // k in 2.14, rounded: n·L is dot / 2^30 (NORMAL_ONE is 2^15 - 1: 3e-5 relative).
            let k = if l.hemispheric { (1 << 13) + ((dot + (1 << 16)) >> 17) } else { (dot.max(0) + (1 << 15)) >> 16 };
            for (s, w) in sum.iter_mut().zip(l.weight) {
                // |k| <= 2^14 and |w| <= 2^16: the product stays within 2^30; to 16.16.
                *s += (k * w + (1 << 11)) >> 12;
            }
        }
        sum.map(|s| s.clamp(0, 0xffff) as u16)
    }
}

/// Lights prepared for per-pixel (Phong) lighting in integers: vectors and colours in 16.16.
#[derive(Clone, Debug, Default)]
pub struct PixelLights<const N: usize> {
    ambient: [i64; 3],
    lights: Vec<PixelLight, N>,
}

#[derive(Clone, Copy, Debug)]
struct PixelLight {
    kind: LightKind,
    /// Unit vector towards the light (directional, hemispheric) or position (point), 16.16.
    vector: [i64; 3],
    /// `diffuse · intensity`, 16.16.
    color: [i64; 3],
}

/// `round(v · 65536)` saturated to what 16.16 varyings can hold.
fn fixed16(v: f32) -> i64 {
    (v * 65536.0) as i32 as i64
}

impl<const N: usize> PixelLights<N> {
    /// Converts `lights` for per-pixel use.
    #[must_use]
    pub fn new(lights: &Lights<N>) -> Self {
        let mut out = PixelLights { ambient: lights.ambient.to_array().map(fixed16), lights: Vec::new() };
        for l in &lights.lights {
            let vector = match l.kind {
                LightKind::Directional => normalize_or_zero(-l.vector),
                LightKind::Hemispheric => normalize_or_zero(l.vector),
                LightKind::Point => l.vector,
            };
            let color = (l.diffuse * l.intensity).to_array().map(fixed16);
            let _ = out.lights.push(PixelLight { kind: l.kind, vector: vector.to_array().map(fixed16), color });
        }
        out
    }

    /// Light (16.16 per channel, clamped to 0..=1) for the interpolated normal `n` (any
    /// length, 16.16) at world position `p` (16.16): `ambient + Σ max(0, N·L) · colour`.
    #[must_use]
    pub fn at(&self, n: [i32; 3], p: [i32; 3]) -> [i32; 3] {
        let n = n.map(i64::from);
        let n_len = isqrt(dot(n, n) as u64) as i64;
        let mut sum = self.ambient;
        if n_len > 0 {
            for l in &self.lights {
                // k in 16.16.
                let k = match l.kind {
                    LightKind::Directional => dot(n, l.vector) / n_len,
                    LightKind::Hemispheric => (1 << 15) + dot(n, l.vector) / n_len / 2,
                    LightKind::Point => {
                        let d = [l.vector[0] - p[0] as i64, l.vector[1] - p[1] as i64, l.vector[2] - p[2] as i64];
                        // Keep d·d within u64: positions are < 2^31, so d < 2^32; shift if needed.
                        let shift = (64 - d.iter().map(|c| c.unsigned_abs()).max().unwrap_or(0).leading_zeros())
                            .saturating_sub(30);
                        let d = d.map(|c| c >> shift);
                        let d_len = isqrt(dot(d, d) as u64) as i64;
                        if d_len == 0 {
                            0
                        } else {
                            // (n·d) / (|n| |d|) · 65536, with n·d < 2^17 · 2^31.
                            dot(n, d) / n_len * 65536 / d_len
                        }
                    }
                }
                .max(0);
                for (s, c) in sum.iter_mut().zip(l.color) {
                    *s += (c * k) >> 16;
                }
            }
        }
        sum.map(|s| s.clamp(0, 1 << 16) as i32)
    }
}

#[inline]
fn dot(a: [i64; 3], b: [i64; 3]) -> i64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// `floor(sqrt(n))` by Newton's method from above, integers only.
#[must_use]
pub fn isqrt(n: u64) -> u64 {
    if n < 2 {
        return n;
    }
    let mut x = 1u64 << (64 - n.leading_zeros()).div_ceil(2);
    loop {
        let y = (x + n / x) / 2;
        if y >= x {
            return x;
        }
        x = y;
    }
}

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
    /// Exactly `width · height` texels, a power of two.
    texels: &'a [[u8; 2]],
    u_mask: i32,
    width_shift: u32,
}

impl<'a> Repeat565<'a> {
    /// The fast form of `sampler`, when its texture and modes allow one.
    #[must_use]
    pub fn new(sampler: &Sampler<'a>) -> Option<Self> {
        let t = &sampler.texture;
        let texels = t.texels.as_chunks::<2>().0;
        let fits = t.format == TextureFormat::Rgb565
            && sampler.filter == Filter::Nearest
            && sampler.u.mask >= 0
            && sampler.v.mask >= 0
            && texels.len() == t.width as usize * t.height as usize;
        fits.then_some(Repeat565 { texels, u_mask: sampler.u.mask, width_shift: t.width.trailing_zeros() })
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
        // Row bits above the texture wrap away with the final mask (the size is a power of
        // two), which is also what lets the compiler see that the index is in bounds.
        let at = (((v >> 16) << self.width_shift) | ((u >> 16) & self.u_mask)) as usize;
        self.texels.get(at & self.texels.len().wrapping_sub(1)).map_or(0, |b| u16::from_le_bytes(*b))
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
    fn fixed_lights_are_within_an_eighth_of_a_step_of_the_f32_ones() {
        let mut state = 0x1234_5678_9abc_def1u64;
        let mut unit = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 40) as f32 / (1u64 << 24) as f32
        };
        let mut worst = 0;
        for _ in 0..200 {
            let mut lights = Lights::<3>::new(Vec3::new(unit() * 0.3, unit() * 0.3, unit() * 0.3));
            for k in 0..3 {
                let dir = normalize_or_zero(Vec3::new(unit() - 0.5, unit() - 0.5, unit() - 0.5));
                let mut l = Lights::<3>::directional(dir, unit() * 4.0);
                l.diffuse = Vec3::new(unit(), unit(), unit());
                if k == 2 {
                    l.kind = LightKind::Hemispheric;
                    l.intensity = unit();
                }
                lights.push(l).unwrap();
            }
            let rotation = Mat3::from_euler(glam::EulerRot::YXZ, unit() * 6.0, unit() * 3.0, unit());
            let (prepared, fixed) = (lights.prepared(), lights.prepared().fixed::<3>(&rotation).unwrap());
            for _ in 0..200 {
                let n = normalize_or_zero(Vec3::new(unit() - 0.5, unit() - 0.5, unit() - 0.5));
                let q = (n * crate::format::NORMAL_ONE).to_array().map(|c| (c + 0.5 * c.signum()) as i16);
                let stored = Vec3::new(q[0] as f32, q[1] as f32, q[2] as f32) / crate::format::NORMAL_ONE;
                let want = prepared.at(Vec3::ZERO, rotation * stored).to_array().map(|c| (c * 65536.0 + 0.5) as u16);
                let got = fixed.at(q);
                for c in 0..3 {
                    worst = worst.max(got[c].abs_diff(want[c]));
                }
            }
        }
        std::println!("worst difference {worst} of 65536");
        assert!(worst <= 32, "worst {worst} of 65536");
    }

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
    fn specular_peaks_on_the_mirror_direction() {
        let mut lights = Lights::<1>::new(Vec3::ZERO);
        lights.push(Lights::<1>::directional(Vec3::new(0.0, 0.0, 1.0), 1.0)).unwrap();
        let eye = Vec3::new(0.0, 0.0, -5.0);
        assert_eq!(lights.specular_at(Vec3::ZERO, -Vec3::Z, eye), 0.0, "off by default");
        lights.specular = Vec3::ONE;
        // Light from behind the eye, normal towards both: H = N, full highlight.
        assert!((lights.specular_at(Vec3::ZERO, -Vec3::Z, eye) - 1.0).abs() < 1e-6);
        // Light and eye both along -z, so H = -z; a normal tilted 30 degrees gives cos(30°)^64.
        let n = Vec3::new(0.5, 0.0, -0.75f32.sqrt());
        let want = libm::powf(libm::cosf(30f32.to_radians()), 64.0);
        assert!((lights.specular_at(Vec3::ZERO, n, eye) - want).abs() < 1e-4);
        // Facing away from the light: none.
        assert_eq!(lights.specular_at(Vec3::ZERO, Vec3::Z, eye), 0.0);
    }

    #[test]
    fn isqrt_is_floor_sqrt() {
        for n in [0u64, 1, 2, 3, 4, 15, 16, 17, 1 << 40, (1 << 40) - 1, u64::MAX] {
            let r = isqrt(n);
            assert!(r * r <= n && (r + 1).checked_mul(r + 1).is_none_or(|s| s > n), "{n}");
        }
    }

    #[test]
    fn pixel_lights_match_float_lights() {
        let mut lights = Lights::<2>::new(Vec3::splat(0.1));
        lights.push(Lights::<2>::directional(Vec3::new(0.5, -0.5, 1.0), 0.7)).unwrap();
        lights.push(Lights::<2>::point(Vec3::new(2.0, 3.0, -4.0), 0.5)).unwrap();
        let px = PixelLights::new(&lights);
        for (n, p) in [(Vec3::new(0.0, 0.0, -1.0), Vec3::ZERO), (Vec3::new(0.3, 0.8, -0.5), Vec3::new(0.5, 0.2, 0.1))] {
            let n = normalize_or_zero(n);
            let want = lights.at(p, n);
            let got = px.at((n * 50000.0).to_array().map(|c| c as i32), (p * 65536.0).to_array().map(|c| c as i32));
            for k in 0..3 {
                assert!((got[k] as f32 / 65536.0 - want[k]).abs() < 1.0 / 512.0, "{got:?} vs {want:?}");
            }
        }
    }

    #[test]
    fn modulate_keeps_white_and_black() {
        assert_eq!(modulate([255, 128, 0], [1 << 16; 3]), [255, 128, 0]);
        assert_eq!(modulate([255, 128, 0], [0; 3]), [0, 0, 0]);
        assert_eq!(modulate([255, 255, 255], [1 << 15; 3]), [128, 128, 128]);
    }
}
