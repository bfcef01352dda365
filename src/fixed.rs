//! The fixed-point formats of the pipeline, named once so that every integer says its unit.
//!
//! Like tiny-skia's `FDot6`/`FDot16`, each is an alias of the integer that carries it, named
//! `<integer bits>.<fraction bits>`; conversions between them are the functions here, never a
//! bare shift in the middle of other code. Where a conversion narrows, it says what it does
//! with values out of range (wraps or saturates) and why that is safe.
//!
//! | format | alias | what carries it |
//! |---|---|---|
//! | 28.4 | [`FDot4`] | screen positions, snapped to 1/16 pixel |
//! | 24.8 | [`FDot8`] | affine varying planes (1/256 of a varying unit) |
//! | 16.16 | [`FDot16`] | varyings: texel coordinates, light, Phong normals and positions |
//! | 24.40 | [`Depth40`] | the per-triangle depth plane (0 = near, 2^40 = far) |
//! | 2.30 | [`Depth30`] | depth in the span loop and to the depth buffer (0..=2^30) |
//! | 2.14 | [`FDot14`] | light colours and weights of the integer vertex lights |

/// 28.4: screen coordinates in 1/16 pixel (image x right, y down).
pub type FDot4 = i32;

/// 24.8: an affine plane's value in 1/256 of a varying unit.
pub type FDot8 = i32;

/// 16.16: a varying (texel coordinate, light, normal or position component), 1.0 = 65536.
pub type FDot16 = i32;

/// 2.14: a light weight or colour of the integer vertex lights, 1.0 = 16384.
pub type FDot14 = i32;

/// 24.40: depth on a triangle's depth plane, 1.0 (the far plane) = 2^40.
pub type Depth40 = i64;

/// 2.30: depth as the span loop and the depth buffers see it, 0 (near) ..= 2^30 (far).
pub type Depth30 = u32;

/// 1.0 in [`FDot16`].
pub const FDOT16_ONE: f32 = 65536.0;

/// 1.0 in [`Depth40`], as the f32 the depth plane is scaled by.
pub const DEPTH40_ONE: f32 = (1u64 << 40) as f32;

/// The far plane in [`Depth30`]: 2^30.
pub const DEPTH30_FAR: i64 = 1 << 30;

/// `floor(p · 16)`: a screen coordinate in pixels snapped down to [`FDot4`] (saturating).
#[inline(always)]
#[must_use]
pub fn fdot4_floor(p: f32) -> FDot4 {
    crate::math::floor_to_i32(crate::math::times_16(p))
}

/// A [`Depth40`] value in [`Depth30`] units (the low 10 bits dropped, sign kept): the caller
/// range-checks the result before it becomes a [`Depth30`].
#[inline(always)]
#[must_use]
pub fn depth40_to_30(z: Depth40) -> i64 {
    z >> 10
}

/// A depth in 0..=1 (f32) in [`Depth30`], saturating at the far plane.
#[inline]
#[must_use]
pub fn depth30_from_unit(z: f32) -> Depth30 {
    ((z * DEPTH30_FAR as f32) as u32).min(DEPTH30_FAR as u32)
}

/// A depth in 0..=1 (f32) in [`Depth30`] units, truncated: `z · 2^30` clamped to `0..=2^30`
/// (NaN gives 0), as `to_i32(z · 2^30).clamp(0, 2^30)` gives it, from the bits alone (no
/// float operation or conversion: library calls without an FPU).
#[inline(always)]
#[must_use]
pub fn depth30_truncated(z: f32) -> i32 {
    let b = z.to_bits();
    // Negative (sign bit) or NaN: 0; 1 and above (infinity too): the far plane.
    if b > 0x7f80_0000 {
        return 0;
    }
    if b >= 0x3f80_0000 {
        return 1 << 30;
    }
    let e = b >> 23;
    if e < 97 {
        // Below 2^-30 (zeros and subnormals too).
        return 0;
    }
    // `z = m · 2^(e - 150)`, times 2^30: `m · 2^(e - 120)`, with `e` in 97..=126.
    let m = (b & 0x7f_ffff) | 1 << 23;
    (if e >= 120 { m << (e - 120) } else { m >> (120 - e) }) as i32
}

/// A [`FDot8`] plane value in whole [`FDot16`] varying units, rounded to nearest (wrapping:
/// the planes are built so that the sum cannot overflow, see `raster::AffinePlanes::new`).
#[inline(always)]
#[must_use]
pub fn fdot8_round(v: FDot8) -> FDot16 {
    v.wrapping_add(128) >> 8
}

/// A [`FDot8`] plane value in whole [`FDot16`] varying units, truncated towards minus infinity.
#[inline(always)]
#[must_use]
pub fn fdot8_floor(v: FDot8) -> FDot16 {
    v >> 8
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn conversions() {
        assert_eq!(fdot4_floor(1.5), 24);
        assert_eq!(fdot4_floor(-0.01), -1);
        assert_eq!(depth40_to_30(1 << 40), 1 << 30);
        assert_eq!(depth30_from_unit(1.0), 1 << 30);
        assert_eq!(depth30_from_unit(2.0), 1 << 30);
        assert_eq!(depth30_from_unit(0.5), 1 << 29);
        assert_eq!(fdot8_round(384), 2);
        assert_eq!(fdot8_round(383), 1);
        assert_eq!(fdot8_floor(-1), -1);
    }

    /// `depth30_truncated` is the float product's truncation, clamped, for every exponent and
    /// special value.
    #[test]
    fn depth30_truncated_is_the_clamped_product() {
        let mut rng = crate::test_rng::Lcg(17);
        let specials =
            [0.0, -0.0, 1.0, -1.0, 0.5, 2.0, f32::INFINITY, f32::NEG_INFINITY, f32::NAN, -f32::NAN, f32::MIN_POSITIVE];
        let random = (0..200_000).map(|_| f32::from_bits(rng.next()));
        let near_one = (0..10_000).map(|k| f32::from_bits(0x3f80_0000 - k));
        for z in specials.into_iter().chain(random).chain(near_one) {
            let expected = crate::math::to_i32(z * (1u32 << 30) as f32).clamp(0, 1 << 30);
            assert_eq!(depth30_truncated(z), expected, "{z} ({:#x})", z.to_bits());
        }
    }
}
