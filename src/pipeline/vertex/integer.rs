//! Projection in integers, for the fixed-point vertex path (`RenderOptions::fixed_vertices`):
//! the snapped screen position, depth and `1/w` of a clip-space point inside the view volume
//! from its coordinates' significands and exponents, one reciprocal (a table and two Newton
//! steps) and 32 x 32-bit products. Without an FPU that replaces a division and five
//! multiplications in software floats. The same integers on every target, so a frame is the
//! same bits on the host and on the MCU; every path that projects a point (the vertex cache,
//! the draws without one, the corners of clipped polygons) projects it through here when
//! `fixed_vertices` is on, so two triangles sharing a vertex put it at the same place.
//!
//! # Numbers
//! - `w = m_w · 2^(e_w - 150)` (a normal float, `m_w` in `2^23..2^24`), and `r ≈ 2^54 / m_w`
//!   ([`reciprocal`], within about 2^-30 relative, in `2^30..=2^31`; exact for a power of two).
//! - For `|c| <= w` (the point is inside the view volume) the ratio `c / w` in 2.30 is
//!   `m_c · r / 2^24`, shifted right by the exponents' difference: at most `2^30`.
//! - The snapped position (28.4) is `floor(16 · hw · (1 + x / w))`, and `16 · hw` is the
//!   integer `K = 8 · width`: `K + floor(K · (x / w))`, the product exact in 64 bits. The
//!   ratio's error (about 2^-29) moves a coordinate by under 2^-9 of a unit (`K` below 2^20).

use super::super::raster::{leading_zeros, mul_i32, mul_u32, reciprocal, ScreenVertex};
use super::super::varyings::MAX_VARYINGS;
use crate::math::Vec4;

/// The biased exponents of the `w`s projected here: `w` between 2^-63 and 2^64, so that `1/w`
/// is a normal float (the others take the f32 path).
const W_EXPONENTS: core::ops::RangeInclusive<u32> = 64..=190;

/// The screen position (28.4), depth (0..=1) and `1/w` of clip-space point `pos`, for a frame
/// of `8 · width` and `8 · height` (`k`), when it lies inside the view volume (`|x|`, `|y|`,
/// `|z|` at most `w`, which is positive and within [`W_EXPONENTS`]): its outcode is then 0.
/// `None` otherwise (the caller projects it in f32). No varyings.
#[inline(always)]
pub(crate) fn project(pos: Vec4, [kx, ky]: [i32; 2]) -> Option<ScreenVertex> {
    let [x, y, z, w] = pos.to_array().map(f32::to_bits);
    // A negative `w` has its sign in the exponent's place: out of range.
    let ew = w >> 23;
    if !W_EXPONENTS.contains(&ew) {
        return None;
    }
    // A power of two (an orthographic camera's `w = 1`) exactly, so that exact ratios stay exact.
    let fraction = w & 0x7f_ffff;
    let r = if fraction == 0 { 1 << 31 } else { reciprocal((fraction | 1 << 23) << 8) };
    let (rx, ry, rz) = (ratio(x, w, r)?, ratio(y, w, r)?, ratio(z, w, r)?);
    // Floor divisions by 2^30 (arithmetic shifts); `|K · ratio| <= 2^50`.
    let sx = kx + (mul_i32(kx, rx) >> 30) as i32;
    let sy = ky + (mul_i32(ky, -ry) >> 30) as i32;
    // `(z/w + 1) / 2` in 2.30: 0..=2^30.
    let depth = ((rz >> 1) + (1 << 29)) as u32;
    // `1/w = r · 2^(96 - e_w)`: `r / 2^30` in 1..=2 times `2^(126 - e_w)`. The significand
    // rounded (half up) to 24 bits, its leading bit added into the exponent (a carry to 2^24
    // raises the exponent by one, as it should).
    let inv_w = f32::from_bits(((252 - ew) << 23) + ((r + 64) >> 7));
    Some(ScreenVertex { x: sx, y: sy, z: unit_f32(depth), inv_w, varyings: [0; MAX_VARYINGS] })
}

/// `c / w` in 2.30 for the bits `c` of a coordinate and `w` of a positive normal `w`, `r` being
/// `≈ 2^54 / m_w` (see the module's numbers), when `|c| <= w`. Zero for zero and for
/// subnormals (below 2^-126 against a `w` of at least 2^-63: far below a unit).
#[inline(always)]
fn ratio(c: u32, w: u32, r: u32) -> Option<i32> {
    let magnitude = c & 0x7fff_ffff;
    // Non-negative floats order as their bits do; NaN's are above any finite `w`'s.
    if magnitude > w {
        return None;
    }
    let (e, shift) = (magnitude >> 23, (w >> 23) - (magnitude >> 23));
    if e == 0 || shift >= 31 {
        return Some(0);
    }
    // Below 2^55, so below 2^31 once divided by 2^24.
    let q = ((mul_u32((magnitude & 0x7f_ffff) | 1 << 23, r) >> 24) as u32) >> shift;
    Some(if c >> 31 != 0 { -(q as i32) } else { q as i32 })
}

/// `d / 2^30` as a float, for `d` in `0..=2^30`, the significand rounded half up.
#[inline(always)]
fn unit_f32(d: u32) -> f32 {
    if d == 0 {
        return 0.0;
    }
    let zeros = leading_zeros(d);
    let m = d << zeros;
    // `m / 2^31` in 1..2 times `2^(1 - zeros)`: as in `project`'s `1/w`.
    f32::from_bits(((127 - zeros) << 23) + (m >> 8) + ((m >> 7) & 1))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every projection is within a 2^-8 unit (28.4) of the exact one before the floor, and
    /// its depth and `1/w` within 2^-23 relative.
    #[test]
    fn projects_like_exact_arithmetic() {
        let mut rng = crate::test_rng::Lcg(5);
        let k = [8 * 240, 8 * 135];
        let mut checked = 0;
        for _ in 0..200_000 {
            let w = f32::from_bits(rng.below(100 << 23) + (80 << 23));
            // Within `-w..=w` (rounding is monotonic and `w` is a float).
            let c = [0; 3].map(|_| ((rng.unit() * 2.0 - 1.0) * w as f64) as f32);
            let pos = Vec4::new(c[0], c[1], c[2], w);
            let p = project(pos, k).expect("inside the view volume");
            let exact = |c: f32, k: i32| k as f64 * (1.0 + c as f64 / w as f64);
            let (ex, ey) = (exact(c[0], k[0]), exact(-c[1], k[1]));
            for (got, exact) in [(p.x, ex), (p.y, ey)] {
                // The floor of a value within 2^-8 of the exact one.
                let (lo, hi) = ((exact - 1.0 / 256.0).floor(), (exact + 1.0 / 256.0).floor());
                assert!((lo..=hi).contains(&f64::from(got)), "{pos:?}: {got} for {exact}");
            }
            let depth = (c[2] as f64 / w as f64 + 1.0) / 2.0;
            assert!((p.z as f64 - depth).abs() <= depth * 2f64.powi(-23) + 2f64.powi(-30), "{pos:?}: {} {depth}", p.z);
            let inv_w = 1.0 / w as f64;
            assert!((p.inv_w as f64 - inv_w).abs() <= inv_w * 2f64.powi(-23), "{pos:?}: {} {inv_w}", p.inv_w);
            checked += 1;
        }
        assert_eq!(checked, 200_000);
    }

    /// Outside the view volume, `w` not positive, or not finite: left to the f32 path.
    #[test]
    fn refuses_what_it_does_not_project() {
        let k = [8 * 240, 8 * 240];
        for pos in [
            Vec4::new(1.5, 0.0, 0.0, 1.0),
            Vec4::new(0.0, -1.5, 0.0, 1.0),
            Vec4::new(0.0, 0.0, 1.0001, 1.0),
            Vec4::new(0.0, 0.0, 0.0, -1.0),
            Vec4::new(0.0, 0.0, 0.0, 0.0),
            Vec4::new(f32::NAN, 0.0, 0.0, 1.0),
            Vec4::new(0.0, 0.0, 0.0, f32::INFINITY),
            Vec4::new(0.0, 0.0, 0.0, f32::NAN),
            Vec4::new(0.0, 0.0, 0.0, 1e-30),
        ] {
            assert!(project(pos, k).is_none(), "{pos:?}");
        }
        let edge = project(Vec4::new(1.0, -1.0, 1.0, 1.0), k).unwrap();
        assert_eq!((edge.x, edge.y, edge.z, edge.inv_w), (2 * k[0], 2 * k[1], 1.0, 1.0));
        let centre = project(Vec4::new(0.0, 0.0, -1.0, 2.0), k).unwrap();
        let near = project(Vec4::new(0.5, 0.0, -2.0, 2.0), k).unwrap();
        assert_eq!((near.x, near.z), (k[0] + k[0] / 4, 0.0));
        assert_eq!((centre.x, centre.y, centre.z, centre.inv_w), (k[0], k[1], 0.25, 0.5));
    }
}
