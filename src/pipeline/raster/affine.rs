//! Affine varyings: one plane per varying over a triangle's box, in integers (see
//! [`AffinePlanes`]), for triangles whose varyings `Setup::allow_affine` finds affine within
//! tolerance. It does not decide that (`raster` does) or step pixels (`span` does).

use super::Edge;
use crate::fixed::{fdot8_floor, fdot8_round, FDot16, FDot8};
use crate::math::{times_power_of_two, F32};

/// Affine varyings: `v(x, y) = base + (origin + gx·x + gy·y) / 256` in pixels from the origin
/// pixel centre, in integers (24.8 varying units: rounding adds under 2^-8 units per pixel of
/// distance, far below the 2^-16 of a texel or of full light that a unit is). Integer
/// arithmetic costs the same on every target, FPU or not, and gives the same value for a pixel
/// whichever band draws it.
#[derive(Clone, Copy, Debug)]
pub(super) struct AffinePlanes<const V: usize> {
    /// Vertex 0's values; the planes below are relative to them.
    base: [FDot16; V],
    origin: [FDot8; V],
    gx: [FDot8; V],
    gy: [FDot8; V],
    /// `gx` rounded to whole units: the per-pixel step along a row.
    step: [FDot16; V],
}

impl<const V: usize> AffinePlanes<V> {
    /// The planes through the three vertices' values: the weight of vertex 1 is `E_1 / area`
    /// and of vertex 2 is `E_2 / area` (screen-space barycentrics), computed in f32 (the same
    /// bits on every target). `None` when `origin + gx·x + gy·y` could leave i32 somewhere in
    /// `0..=width` by `0..=height` pixels from the origin (needle triangles with huge
    /// gradients): those keep per-run exact values.
    pub(super) fn new(
        edges: &[Edge; 3],
        area: F32,
        (v0, d1, d2): (&[i32; V], &[F32; V], &[F32; V]),
        (width, height): (i32, i32),
    ) -> Option<Self> {
        let inv_area = F32(1.0) / area;
        let per_pixel = |c: i32| F32::from(c * 16) * inv_area;
        let (b1x, b1y, b1o) = (per_pixel(edges[1].a), per_pixel(edges[1].b), F32::from(edges[1].c) * inv_area);
        let (b2x, b2y, b2o) = (per_pixel(edges[2].a), per_pixel(edges[2].b), F32::from(edges[2].c) * inv_area);
        // At least one pixel each way: the bound below must hold `gx` and `gy` themselves too
        // (the per-pixel step is `gx`, rounded), also for a box one column or row wide.
        let (w, h) = (u64::from(width.max(1) as u32), u64::from(height.max(1) as u32));
        let mut p = AffinePlanes { base: *v0, origin: [0; V], gx: [0; V], gy: [0; V], step: [0; V] };
        for k in 0..V {
            // Times 256 exactly (a power of two: no soft-float multiply without an FPU).
            let (d1, d2) = (times_power_of_two(d1[k].0, 256.0), times_power_of_two(d2[k].0, 256.0));
            let (d1, d2) = (F32(d1), F32(d2));
            // Relative to vertex 0's value, added back in integers: large values (e.g. world
            // positions) keep their precision. Truncating (saturating): under one unit of 2^-8
            // off. Finite: `d` is below 2^39 and the weights below 2^32.
            let (o, gx, gy) = (d1 * b1o + d2 * b2o, d1 * b1x + d2 * b2x, d1 * b1y + d2 * b2y);
            let (o, gx, gy) = (o.to_i32(), gx.to_i32(), gy.to_i32());
            // Within 2^30 in integers (a saturated value fails): `origin + gx·x + gy·y` fits i32
            // for every pixel of the box, and `gx + 128` too. `x ^ (x >> 31)` is `|x|` or
            // `|x| - 1` (one instruction): the sum is at most `1 + w + h` under the exact one,
            // still far within i32.
            let abs = |v: i32| u64::from((v ^ (v >> 31)) as u32);
            if abs(o) + abs(gx) * w + abs(gy) * h >= 1 << 30 {
                return None;
            }
            (p.origin[k], p.gx[k], p.gy[k], p.step[k]) = (o, gx, gy, fdot8_round(gx));
        }
        Some(p)
    }

    /// Varyings at column `x`, row `y` from the origin pixel, and the step per pixel.
    #[inline(always)]
    pub(super) fn at(&self, x: i32, y: i32) -> ([i32; V], [i32; V]) {
        let v = |k: usize| self.base[k].wrapping_add(fdot8_floor(self.origin[k] + self.gx[k] * x + self.gy[k] * y));
        (core::array::from_fn(v), self.step)
    }
}
