//! Projection in integers, for the fixed-point vertex path (`RenderOptions::fixed_vertices`):
//! the snapped screen position, depth and `1/w` of a vertex inside the view volume straight
//! from the integer transform's exact sums ([`FixedTransform::sums`]), with one reciprocal (a
//! table and two Newton steps) and 32 x 32-bit products. Without an FPU that replaces four
//! conversions to float, a division and five multiplications in software floats. The same
//! integers on every target, so a frame is the same bits on the host and on the MCU.
//!
//! Every path that projects a vertex of a draw comes here first (the vertex cache, the draws
//! without one, and the corners of a clipped triangle, which `primitive::draw_clipped` takes
//! from its three projected corners), so that a vertex lands on the same spot in each of its
//! triangles; points that clipping makes are projected in f32.
//!
//! # Numbers
//! - `w = sum · 2^-e` is taken as `m_w · 2^x` with `m_w` the top 32 bits of `|sum|`
//!   (truncated: under 2^-31 relative), in `2^31..2^32` ([`Coordinate`]); each other
//!   coordinate as `m_c · 2^x`, on `w`'s scale (truncated to whole units of it).
//! - `r ≈ 2^62 / m_w` ([`reciprocal`], within about 2^-30 relative, in `2^30..=2^31`; exact
//!   for a power of two). For `|c| <= w` (the vertex is inside the view volume: `m_c <= m_w`)
//!   the ratio `c / w` in 2.30 is `m_c · r / 2^32`: at most `2^30`, within about 2^-29 of the
//!   exact ratio.
//! - The snapped position (28.4) is `floor(16 · hw · (1 + x / w))`, and `16 · hw` is the
//!   integer `K = 8 · width`: `K + floor(K · (x / w))`, the product exact in 64 bits. The
//!   ratio's error moves a coordinate by under 2^-9 of a unit (`K` below 2^20).

use super::super::raster::{leading_zeros, mul_i32, mul_u32, reciprocal};
use super::Projected;
#[cfg(doc)]
use crate::math::FixedTransform;

/// The exponents `x` of the `w`s projected here (`w = m · 2^x`, `m` in `2^31..2^32`): `w`
/// between 2^-69 and 2^92, so that `1/w` is a normal float (the others take the f32 path).
const W_EXPONENTS: core::ops::RangeInclusive<i32> = -100..=60;

/// A coordinate `±m · 2^x` from an exact integer sum: `m` in `2^31..2^32`, or 0 for zero.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Coordinate {
    m: u32,
    x: i32,
    negative: bool,
}

impl Coordinate {
    /// `sum · 2^-e`, its magnitude's top 32 bits kept (no 64-bit shift by a variable amount:
    /// a library call on Armv6-M).
    #[inline(always)]
    fn new(sum: i64, e: i32) -> Self {
        let magnitude = sum.unsigned_abs();
        let (high, low) = ((magnitude >> 32) as u32, magnitude as u32);
        let (m, zeros) = if high != 0 {
            let zeros = leading_zeros(high);
            // `low >> (32 - zeros)` with `zeros = 0` would shift by 32.
            (if zeros == 0 { high } else { (high << zeros) | (low >> (32 - zeros)) }, zeros)
        } else if low != 0 {
            let zeros = leading_zeros(low);
            (low << zeros, zeros + 32)
        } else {
            return Coordinate { m: 0, x: 0, negative: false };
        };
        // `|sum| ≈ m · 2^(32 - zeros)`.
        Coordinate { m, x: 32 - zeros as i32 - e, negative: sum < 0 }
    }
}

/// `x >> t` (a left shift for negative `t`, truncated), when it fits in 32 bits; from `x`'s
/// 32-bit halves (no 64-bit shift by a variable amount: a library call on Armv6-M).
#[inline(always)]
fn shifted_u32(x: u64, t: i32) -> Option<u32> {
    let (high, low) = ((x >> 32) as u32, x as u32);
    match t {
        64.. => Some(0),
        32..=63 => Some(high >> (t - 32)),
        1..=31 => (high >> t == 0).then(|| (high << (32 - t)) | (low >> t)),
        0 => (high == 0).then_some(low),
        -31..=-1 => (high == 0 && low >> (32 + t) == 0).then(|| low << -t),
        _ => (x == 0).then_some(0),
    }
}

/// The vertex whose clip-space coordinates are `sums[i] · 2^-e[i]` (x, y, z, w), projected for
/// a frame of `8 · width` and `8 · height` (`k`), when it lies inside the view volume (`|x|`,
/// `|y|`, `|z|` at most `w`, which is positive with an exponent in [`W_EXPONENTS`]): its
/// outcode is then 0. `None` otherwise (the caller projects it in f32).
#[inline(always)]
pub(super) fn project(sums: [i64; 4], e: [i32; 4], [kx, ky]: [i32; 2]) -> Option<Projected> {
    let w = Coordinate::new(sums[3], e[3]);
    if w.negative || w.m == 0 || !W_EXPONENTS.contains(&w.x) {
        return None;
    }
    // `|c| / w = |sum| · 2^-(e + x_w) / m_w`: each coordinate's magnitude on `w`'s scale, at
    // most `m_w` inside the view volume (no leading-zero count of its own).
    let magnitude = |i: usize| shifted_u32(sums[i].unsigned_abs(), e[i] + w.x).filter(|&m| m <= w.m);
    let (mx, my, mz) = (magnitude(0)?, magnitude(1)?, magnitude(2)?);
    // A power of two (an orthographic camera's `w = 1`) exactly, so that exact ratios stay exact.
    let r = if w.m == 1 << 31 { 1 << 31 } else { reciprocal(w.m) };
    // In 2.30: `m · r < 2^63` (`m <= m_w`), below `2^30` once divided by 2^32.
    let ratio = |m: u32, i: usize| {
        let q = (mul_u32(m, r) >> 32) as i32;
        if sums[i] < 0 {
            -q
        } else {
            q
        }
    };
    let (rx, ry, rz) = (ratio(mx, 0), ratio(my, 1), ratio(mz, 2));
    // Floor divisions by 2^30 (arithmetic shifts); `|K · ratio| <= 2^50`.
    let sx = kx + (mul_i32(kx, rx) >> 30) as i32;
    let sy = ky + (mul_i32(ky, -ry) >> 30) as i32;
    // `(z/w + 1) / 2` in 2.30: 0..=2^30.
    let depth = ((rz >> 1) + (1 << 29)) as u32;
    // `1/w = r · 2^(-62 - x_w)`: `r / 2^30` in 1..=2 times `2^(-32 - x_w)`. The significand
    // rounded (half up) to 24 bits, its leading bit added into the exponent (a carry to 2^24
    // raises the exponent by one, as it should).
    let inv_w = f32::from_bits((((94 - w.x) as u32) << 23) + ((r + 64) >> 7));
    Some(Projected { x: sx, y: sy, z: unit_f32(depth), inv_w, outcode: 0 })
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
    use crate::math::{FixedTransform, Mat4, Vec3};
    use crate::test_rng::Lcg;

    /// The exact value of `sum · 2^-e` (within f64's 2^-53).
    fn exact(sum: i64, e: i32) -> f64 {
        sum as f64 * 2f64.powi(-e)
    }

    /// For random transforms (a camera's magnitudes, any scale) and points: every vertex inside
    /// the view volume is projected, within a 2^-8 unit (28.4) of the exact projection before
    /// the floor, its depth and `1/w` within 2^-23 relative; and every vertex it refuses is
    /// outside (or on the boundary, within 2^-30).
    #[test]
    fn projects_like_exact_arithmetic() {
        let mut rng = Lcg(5);
        let k = [8 * 240, 8 * 135];
        let (mut inside, mut refused) = (0, 0);
        for _ in 0..2_000 {
            let scale = 2f32.powi(rng.below(40) as i32 - 20);
            let m = crate::math::perspective_lh(0.3 + rng.unit() as f32 * 1.5, 1.3, 0.1 * scale, 100.0 * scale)
                * Mat4::from_translation(Vec3::new(0.0, 0.0, 3.0 * scale))
                * Mat4::from_rotation_y(rng.unit() as f32 * 6.0);
            let t = FixedTransform::new(&m, Vec3::splat(-scale), scale / 16384.0).unwrap();
            for _ in 0..100 {
                let q = [0; 3].map(|_| rng.below(1 << 16) as i32 - (1 << 15));
                let (sums, e) = (t.sums(q), t.exponents());
                let [x, y, z, w] = core::array::from_fn(|i| exact(sums[i], e[i]));
                let Some(p) = project(sums, e, k) else {
                    let strictly_inside = w > 0.0 && [x, y, z].iter().all(|c| c.abs() <= w * (1.0 - 2f64.powi(-30)));
                    assert!(!strictly_inside, "refused {x} {y} {z} {w}");
                    refused += 1;
                    continue;
                };
                assert!(
                    w > 0.0 && [x, y, z].iter().all(|c| c.abs() <= w * (1.0 + 2f64.powi(-30))),
                    "took {x} {y} {z} {w}"
                );
                let position = |c: f64, k: i32| f64::from(k) * (1.0 + c / w);
                for (got, exact) in [(p.x, position(x, k[0])), (p.y, position(-y, k[1]))] {
                    // The floor of a value within 2^-8 of the exact one.
                    let (lo, hi) = ((exact - 1.0 / 256.0).floor(), (exact + 1.0 / 256.0).floor());
                    assert!((lo..=hi).contains(&f64::from(got)), "{got} for {exact}");
                }
                let depth = (z / w + 1.0) / 2.0;
                assert!((f64::from(p.z) - depth).abs() <= depth * 2f64.powi(-23) + 2f64.powi(-29), "{} {depth}", p.z);
                assert!((f64::from(p.inv_w) * w - 1.0).abs() <= 2f64.powi(-23), "{} {w}", p.inv_w);
                inside += 1;
            }
        }
        assert!(inside > 50_000 && refused > 10_000, "{inside} inside, {refused} refused");
    }

    /// `shifted_u32` is the 64-bit shift, where that fits in 32 bits.
    #[test]
    fn shifts_like_the_64_bit_shift() {
        let mut rng = Lcg(9);
        for _ in 0..200_000 {
            let x = (u64::from(rng.next()) << 32 | u64::from(rng.next())) >> rng.below(64);
            let t = rng.below(200) as i32 - 100;
            let wide =
                if t >= 0 { x.checked_shr(t as u32).unwrap_or(0) } else { x.checked_shl((-t) as u32).unwrap_or(0) };
            let fits = t >= 0 || x == 0 || ((-t) < 64 && x.leading_zeros() >= (-t) as u32);
            let expected = (fits && wide <= u64::from(u32::MAX)).then_some(wide as u32);
            assert_eq!(shifted_u32(x, t), expected, "{x} by {t}");
        }
    }

    /// The coordinates of simple sums, and exact ratios at the edges of the view volume.
    #[test]
    fn exact_cases() {
        let k = [8 * 240, 8 * 240];
        assert_eq!(Coordinate::new(1 << 40, 40), Coordinate { m: 1 << 31, x: -31, negative: false });
        assert_eq!(Coordinate::new(-3, 0), Coordinate { m: 3 << 30, x: -30, negative: true });
        assert_eq!(Coordinate::new(0, 7).m, 0);
        let one = 1i64 << 40;
        let p = |x: i64, y: i64, z: i64, w: i64| project([x, y, z, w], [40; 4], k);
        let corner = p(one, -one, one, one).unwrap();
        assert_eq!((corner.x, corner.y, corner.z, corner.inv_w), (2 * k[0], 2 * k[1], 1.0, 1.0));
        let centre = p(0, 0, -one, 2 * one).unwrap();
        assert_eq!((centre.x, centre.y, centre.z, centre.inv_w), (k[0], k[1], 0.25, 0.5));
        let near = p(one, 0, -2 * one, 2 * one).unwrap();
        assert_eq!((near.x, near.z), (k[0] + k[0] / 2, 0.0));
        // Outside (by 2^-31: a coordinate keeps 32 bits), behind the eye, at it, or too far or
        // near for a normal `1/w`.
        let out = one + (one >> 31);
        for refused in [p(out, 0, 0, one), p(0, -out, 0, one), p(0, 0, out, one), p(0, 0, 0, -one), p(0, 0, 0, 0)] {
            assert!(refused.is_none());
        }
        assert!(project([0, 0, 0, 1], [0, 0, 0, 120], k).is_none());
        assert!(project([0, 0, 0, 1 << 60], [0, 0, 0, -100], k).is_none());
    }
}
