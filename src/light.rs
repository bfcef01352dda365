//! Lights, as the caller sets them up per frame ([`Lights`]) and as the pipeline evaluates them:
//! per vertex or per face in f32 ([`PreparedLights`]), per vertex in integers whenever the
//! lights allow it ([`FixedLights`]: cheaper than f32 even with an FPU), and per pixel in
//! integers for Phong ([`PixelLights`]). It does not sample textures or combine light with
//! colour (`texture` does).
//!
//! The light model is Babylon.js's StandardMaterial diffuse term plus an optional Blinn-Phong
//! specular term ([`Lights::specular`], off by default):
//! `colour = clamp(ambient + Σ max(0, N·L) · light.diffuse · intensity, 0, 1) · diffuse · texture`
//! with `L = -direction` (directional), `L = normalize(position - P)` (point, no falloff) and
//! hemispheric lights contributing `(0.5 + 0.5 N·up) · diffuse · intensity` (ground colour black).
//! Lighting only ever scales red, green and blue: alpha is never touched.

use heapless::Vec;

use crate::animation::Pose;
use crate::fixed::FDot14;
use crate::format::{Light, LightKind, Model};
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

    /// [`Lights::from_model`] at a pose: each of the model's lights where the pose's tracks
    /// put it ([`Pose::light`]; as stored when the pose is not set or nothing moves it).
    #[must_use]
    pub fn from_model_posed(model: &Model<'_>, pose: &Pose<'_>) -> Self {
        let mut set = Self::from_model(model);
        if let Some(animation) = model.animation() {
            for (i, light) in set.lights.iter_mut().enumerate().take(model.light_count()) {
                *light = pose.light(&animation, i, *light);
            }
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
        let sum = self.unclamped_at(p, n);
        Vec3::new(clamp01(sum.x), clamp01(sum.y), clamp01(sum.z))
    }

    /// [`PreparedLights::at`] before clamping to 0..=1: for callers that clamp anyway (the
    /// quantized vertex light). Inlined: once a vertex, where its call would cost as much as
    /// its arithmetic.
    #[inline(always)]
    #[must_use]
    pub(crate) fn unclamped_at(&self, p: Vec3, n: Vec3) -> Vec3 {
        let mut sum = self.ambient;
        for l in &self.lights {
            let k = match l.kind {
                LightKind::Directional => max(n.dot(l.vector), 0.0),
                LightKind::Point => max(n.dot(normalize_or_zero(l.vector - p)), 0.0),
                LightKind::Hemispheric => 0.5 + 0.5 * n.dot(l.vector),
            };
            sum += l.diffuse * (k * l.intensity);
        }
        sum
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
    /// Diffuse colour times intensity (at most 4).
    weight: [FDot14; 3],
}

impl<const N: usize> FixedLights<N> {
    /// Light per channel, 0..=65535 for 0..=1 (clamped), at a vertex whose stored normal is
    /// `n`: [`PreparedLights::at`] in integers, within about 2^-12 of it per light (a sixteenth
    /// of an 8-bit step).
    #[must_use]
    pub fn at(&self, n: [i16; 3]) -> [u16; 3] {
        sum_lights(self.ambient, &self.lights, n)
    }

    /// These lights when there is exactly one: [`OneFixedLight::at`] is [`FixedLights::at`]
    /// with no loop over the lights, for a loop over vertices that tests their number once.
    #[inline(always)]
    pub(crate) fn one(&self) -> Option<OneFixedLight<'_>> {
        match self.lights.as_slice() {
            [one] => Some(OneFixedLight { ambient: self.ambient, light: one }),
            _ => None,
        }
    }
}

/// [`FixedLights`] of one light (see [`FixedLights::one`]).
pub(crate) struct OneFixedLight<'l> {
    ambient: [i32; 3],
    light: &'l FixedLight,
}

impl OneFixedLight<'_> {
    /// [`FixedLights::at`].
    #[inline(always)]
    pub(crate) fn at(&self, n: [i16; 3]) -> [u16; 3] {
        sum_lights(self.ambient, core::slice::from_ref(self.light), n)
    }
}

/// `ambient` plus the light of `lights` at a vertex whose stored normal is `n`: see
/// [`FixedLights::at`].
#[inline(always)]
fn sum_lights(ambient: [i32; 3], lights: &[FixedLight], n: [i16; 3]) -> [u16; 3] {
    let mut sum = ambient;
    for l in lights {
        // `|towards| <= 2^15` (a unit vector) and each of `n`'s components at most 2^15 (not
        // checked to be a unit vector: `|n| <= 2^15·√3`): by Cauchy-Schwarz, `|dot|` is
        // below 1.86e9 < 2^31, with the roundings' `2^16` added too.
        let dot = (0..3).fold(0i32, |acc, k| acc.wrapping_add(n[k] as i32 * l.towards[k]));
        // k in 2.14, rounded: n·L is dot / 2^30 (NORMAL_ONE is 2^15 - 1: 3e-5 relative).
        let k = if l.hemispheric { (1 << 13) + ((dot + (1 << 16)) >> 17) } else { (dot.max(0) + (1 << 15)) >> 16 };
        for (s, w) in sum.iter_mut().zip(l.weight) {
            // `|k| <= 28,378` (2^14 for a unit normal) and `|w| <= 2^16`: the product stays
            // below 1.86e9 < 2^31; to 16.16.
            *s += (k * w + (1 << 11)) >> 12;
        }
    }
    sum.map(|s| s.clamp(0, 0xffff) as u16)
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
        // `|n|²` in u64: any i32 components (each square at most 2^62, their sum below 2^64),
        // so no interpolated normal, however long, overflows it.
        let n_len = isqrt(n.iter().map(|c| u64::from(c.unsigned_abs()).pow(2)).sum()) as i64;
        let n = n.map(i64::from);
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

#[cfg(test)]
mod tests {
    use super::*;

    /// Interpolated normals of any length (here the longest i32 components) light without an
    /// overflow: `|n|²` passed i64 from components of about 2^30.7.
    #[test]
    fn pixel_lights_take_any_normal() {
        let px = PixelLights::new(&two_lights());
        for n in [[i32::MAX; 3], [i32::MIN; 3], [i32::MIN, i32::MAX, 0]] {
            let light = px.at(n, [i32::MIN, 0, i32::MAX]);
            assert!(light.iter().all(|c| (0..=1 << 16).contains(c)), "{n:?}: {light:?}");
        }
        // The same direction at an ordinary length lights alike.
        let (long, short) = (px.at([0, 0, -(1 << 30)], [0; 3]), px.at([0, 0, -(1 << 16)], [0; 3]));
        assert!(long.iter().zip(short).all(|(a, b)| (a - b).abs() <= 2), "{long:?} {short:?}");
    }

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

    /// One light's fast path (`FixedLights::one`) lights every normal as `FixedLights::at`
    /// does, directional or hemispheric; with two lights there is none.
    #[test]
    fn one_fixed_light_is_the_general_sum() {
        let mut state = 0x0dd_ba11_5eed_u64;
        let mut unit = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 40) as f32 / (1u64 << 24) as f32
        };
        let rotation = Mat3::from_euler(glam::EulerRot::YXZ, 0.7, 0.2, -0.4);
        for k in 0..100 {
            let mut lights = Lights::<2>::new(Vec3::splat(unit() * 0.3));
            let dir = normalize_or_zero(Vec3::new(unit() - 0.5, unit() - 0.5, unit() - 0.5));
            let mut l = Lights::<2>::directional(dir, unit() * 4.0);
            l.diffuse = Vec3::new(unit(), unit(), unit());
            if k % 2 == 1 {
                l.kind = LightKind::Hemispheric;
            }
            lights.push(l).unwrap();
            let fixed = lights.prepared().fixed::<2>(&rotation).unwrap();
            let one = fixed.one().unwrap();
            for _ in 0..100 {
                let q = [0; 3].map(|_| ((unit() - 0.5) * 65535.0) as i16);
                assert_eq!(one.at(q), fixed.at(q), "{q:?}");
            }
            lights.push(l).unwrap();
            assert!(lights.prepared().fixed::<2>(&rotation).unwrap().one().is_none());
        }
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

    /// A directional and a point light over a little ambient.
    fn two_lights() -> Lights<2> {
        let mut lights = Lights::<2>::new(Vec3::splat(0.1));
        lights.push(Lights::<2>::directional(Vec3::new(0.5, -0.5, 1.0), 0.7)).unwrap();
        lights.push(Lights::<2>::point(Vec3::new(2.0, 3.0, -4.0), 0.5)).unwrap();
        lights
    }

    #[test]
    fn pixel_lights_match_float_lights() {
        let lights = two_lights();
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
}
