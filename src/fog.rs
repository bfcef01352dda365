//! Fog as Babylon.js's standard material computes it ([`Fog`]), and per pixel in a band
//! ([`PixelFog`]).
//!
//! Babylon.js (`fogFragmentDeclaration.fx`, `fogFragment.fx`) takes a fragment's distance `d`
//! as the length of its **view-space** position (radial, not the depth along the view axis),
//! its visibility `f` as
//!
//! | mode | `f` |
//! |---|---|
//! | linear | `(end - d) / (end - start)` |
//! | exp | `1 / 2.71828^(d · density)` |
//! | exp2 | `1 / 2.71828^((d · density)²)` |
//!
//! clamped to `0..=1`, and its colour as `f · colour + (1 - f) · fog colour`, after lighting
//! and specular, alpha untouched. soft3d finds `d` at every pixel from the pixel's centre and
//! its depth (which the span loop has anyway) through the inverse projection: exact, with no
//! varying to interpolate. Fog applies to filled triangles (not to wireframe lines or points).

#[cfg(feature = "fog")]
use crate::fixed::Depth30;
use crate::math::{clamp01, powf, Vec3};
#[cfg(feature = "fog")]
use crate::math::{sqrt, Mat4, Vec4};

/// How fog thickens with distance (numbered as Babylon.js's `Scene.FOGMODE_*`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u8)]
pub enum FogMode {
    /// `1 / e^(d · density)`.
    Exp = 1,
    /// `1 / e^((d · density)²)`.
    Exp2 = 2,
    /// From none at `start` to full at `end`.
    Linear = 3,
}

impl FogMode {
    /// The mode numbered `code` (Babylon.js's `fogMode`: 1, 2 or 3); `None` for any other
    /// (0 is Babylon.js's "no fog").
    #[must_use]
    pub fn from_code(code: u8) -> Option<Self> {
        match code {
            1 => Some(FogMode::Exp),
            2 => Some(FogMode::Exp2),
            3 => Some(FogMode::Linear),
            _ => None,
        }
    }
}

/// A scene's fog: what [`RenderOptions::fog`](crate::RenderOptions::fog) draws with (from
/// [`Model::fog`](crate::Model::fog), or set by the caller).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Fog {
    /// How it thickens.
    pub mode: FogMode,
    /// Its colour, 0..=1 a channel.
    pub color: Vec3,
    /// Density of [`FogMode::Exp`] and [`FogMode::Exp2`] (Babylon.js's default 0.1).
    pub density: f32,
    /// Where [`FogMode::Linear`] starts (Babylon.js's default 0).
    pub start: f32,
    /// Where [`FogMode::Linear`] is full (Babylon.js's default 1000).
    pub end: f32,
}

/// Babylon.js's `E` in its fog shader (not quite `e`: its GLSL says `2.71828`).
#[allow(clippy::approx_constant, reason = "Babylon.js's constant, not e")]
const BABYLON_E: f32 = 2.71828;

impl Fog {
    /// Fog of `mode` and `color` with Babylon.js's defaults (density 0.1, start 0, end 1000).
    #[must_use]
    pub fn new(mode: FogMode, color: Vec3) -> Self {
        Fog { mode, color, density: 0.1, start: 0.0, end: 1000.0 }
    }

    /// How much of a surface at view-space distance `distance` shows through, 0..=1 (1: no
    /// fog), as Babylon.js's `CalcFogFactor`. A linear fog with `end <= start` is a step at
    /// `start` (Babylon.js divides by zero there); a NaN factor counts as full fog.
    #[must_use]
    pub fn factor(&self, distance: f32) -> f32 {
        let f = match self.mode {
            FogMode::Linear if self.end <= self.start => {
                if distance <= self.start {
                    1.0
                } else {
                    0.0
                }
            }
            FogMode::Linear => (self.end - distance) / (self.end - self.start),
            FogMode::Exp => 1.0 / powf(BABYLON_E, distance * self.density),
            FogMode::Exp2 => {
                let x = distance * self.density;
                1.0 / powf(BABYLON_E, x * x)
            }
        };
        clamp01(f)
    }
}

/// One band's fog at each pixel: [`Fog`] with the map from a pixel's centre and depth to its
/// view-space position.
#[cfg(feature = "fog")]
#[derive(Clone, Copy, Debug)]
pub(crate) struct PixelFog {
    /// `(column, row, depth in Depth30 units, 1)` to homogeneous view space (the inverse
    /// projection after the viewport's inverse, pixel centres at `+0.5`).
    to_view: Mat4,
    fog: Fog,
    /// The fog colour in 8 bits a channel.
    color: [u8; 3],
}

#[cfg(feature = "fog")]
impl PixelFog {
    /// What a frame seen through `projection` (view to clip space) keeps for `fog`: `fog`
    /// and the inverse projection, `None` when the projection cannot be inverted.
    pub(crate) fn frame(fog: &Fog, projection: &Mat4) -> Option<(Fog, Mat4)> {
        let inverse = projection.inverse();
        inverse.is_finite().then_some((*fog, inverse))
    }

    /// `fog` for a frame of `width` x `height` pixels whose inverse projection (clip to view
    /// space) is `inverse` (see [`PixelFog::frame`]).
    pub(crate) fn new((fog, inverse): &(Fog, Mat4), (width, height): (u16, u16)) -> Self {
        let (hw, hh) = (f32::from(width) / 2.0, f32::from(height) / 2.0);
        // x_ndc = (c + 0.5) / hw - 1, y_ndc = 1 - (r + 0.5) / hh, z_ndc = 2 · z / 2^30 - 1.
        let viewport_inverse = Mat4::from_cols(
            Vec4::new(1.0 / hw, 0.0, 0.0, 0.0),
            Vec4::new(0.0, -1.0 / hh, 0.0, 0.0),
            Vec4::new(0.0, 0.0, 2.0 / (1u32 << 30) as f32, 0.0),
            Vec4::new(0.5 / hw - 1.0, 1.0 - 0.5 / hh, -1.0, 1.0),
        );
        let color = fog.color.to_array().map(|c| (clamp01(c) * 255.0 + 0.5) as u8);
        PixelFog { to_view: *inverse * viewport_inverse, fog: *fog, color }
    }

    /// The view-space distance of the pixel at frame column `x`, row `y` whose depth is `z`.
    #[inline]
    pub(crate) fn distance(&self, (x, y): (i32, i32), z: Depth30) -> f32 {
        let h = self.to_view * Vec4::new(x as f32, y as f32, z as f32, 1.0);
        sqrt(h.x * h.x + h.y * h.y + h.z * h.z) / h.w.abs()
    }

    /// `rgb` at that pixel seen through the fog.
    #[inline]
    pub(crate) fn blend(&self, rgb: [u8; 3], at: (i32, i32), z: Depth30) -> [u8; 3] {
        // The visibility in 1/256ths: 8-bit channels blend exactly to within rounding.
        let f = (self.fog.factor(self.distance(at, z)) * 256.0 + 0.5) as u32;
        core::array::from_fn(|c| ((u32::from(rgb[c]) * f + u32::from(self.color[c]) * (256 - f) + 128) >> 8) as u8)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    #[cfg(feature = "fog")]
    use crate::Camera;

    fn fog(mode: FogMode) -> Fog {
        Fog { mode, color: Vec3::ONE, density: 0.05, start: 2.0, end: 12.0 }
    }

    #[test]
    fn factors_follow_babylons_formulas() {
        let linear = fog(FogMode::Linear);
        assert_eq!([linear.factor(0.0), linear.factor(7.0), linear.factor(20.0)], [1.0, 0.5, 0.0]);
        let exp = fog(FogMode::Exp);
        assert!((exp.factor(10.0) - (-0.5f64).exp() as f32).abs() < 1e-5);
        let exp2 = fog(FogMode::Exp2);
        assert!((exp2.factor(10.0) - (-0.25f64).exp() as f32).abs() < 1e-5);
        let step = Fog { end: 2.0, ..linear };
        assert_eq!([step.factor(2.0), step.factor(2.5), exp.factor(f32::NAN)], [1.0, 0.0, 0.0]);
    }

    #[cfg(feature = "fog")]
    /// The distance of a pixel is the length of its view-space position: at the image centre
    /// on the far plane it is the far distance; off-centre, longer by the ray's slant.
    #[test]
    fn pixel_distances_are_view_space_lengths() {
        let camera = Camera::perspective(Vec3::ZERO, Vec3::Z, 0.8, 1.0, 1.0, 50.0).unwrap();
        let frame = PixelFog::frame(&fog(FogMode::Linear), &camera.projection).unwrap();
        let px = PixelFog::new(&frame, (100, 100));
        let far = 1u32 << 30;
        // Pixel 49's centre (49.5) is 0.01 off the axis in NDC, left and up.
        let d = px.distance((49, 49), far);
        let slant = 50.0 * (1.0 + 2.0 * (0.01 * (0.4f32).tan()).powi(2)).sqrt();
        assert!((d - slant).abs() < 1e-3 * slant, "{d} vs {slant}");
        let corner = px.distance((0, 0), far);
        let t = (0.4f32).tan() * 0.99;
        assert!((corner - 50.0 * (1.0 + 2.0 * t * t).sqrt()).abs() < 0.05, "{corner}");
    }
}
